#!/usr/bin/env python3
"""The table of results/smoothing/README.md: refine --smooth on the brick cases (run here, their
reports written to results/smoothing/*.json) and the smoothed records of the thesis suite
(results/thesis.jsonl: 6-2 and H-1, trilinear and optimized placement).

    python3 experiments/studies/smoothing/run.py [--hexrefine build/experiments/hexrefine] \
        [--out results/smoothing] [--thesis results/thesis.jsonl]

Prints the table's rows (markdown) on stdout.
"""

import json
import os
import pathlib
import subprocess
import sys
import tempfile

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent.parent))
import harness  # noqa: E402

BRICKS = {
    "G-1": (["--dims", "10,10,10"], ["boundary:-1,0,0", "boundary:0,0,-1"]),
    "G-3_n20": (["--dims", "20,20,20"], ["sphere:1,0,1,0.5"]),
}


def fail(message):
    harness.fail("smoothing/run.py", message, status=1)


def run(cmd):
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        fail("%s failed (exit %d): %s" % (" ".join(cmd), done.returncode, done.stderr.strip()))


def row(name, report):
    sm = report["smoothing"]["stats"]
    return "| %s | {:,} | %.4f | %.4f | %.4f | %.4f | %.4f | {:,} | {:,} | %d | %.3f | %.3f |".format(
        harness.report_refined_check(report)["hexes"] if "check" in report
        else sm.get("hexes", 0),
        sm["region_hexes"], sm["nodes_moved"]) % (
        name, report["refined_parents"]["min_scaled_jacobian"],
        sm["min_scaled_jacobian_before"], sm["min_scaled_jacobian_after"],
        sm["mean_scaled_jacobian_before"], sm["mean_scaled_jacobian_after"], sm["sweeps"],
        report["stage_seconds"]["refine"], sm["seconds"])


def main():
    parser = harness.study_arguments(harness.first_line(__doc__),
                                     out=harness.RESULTS / "smoothing", hexrefine=True)
    parser.add_argument("--thesis", default=None, help="thesis.jsonl (default: beside --out)")
    args = parser.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for case, (dims, specs) in BRICKS.items():
            brick = os.path.join(tmp, case + ".vtu")
            run([args.hexrefine, "generate", "brick", brick] + dims)
            for method in ("selective", "sheet"):
                report_path = os.path.join(args.out, "%s.%s.json" % (case, method))
                cmd = [args.hexrefine, "refine", brick, os.path.join(tmp, "out.vtu"), "--method",
                       method, "--smooth", "--report", report_path]
                for spec in specs:
                    cmd += ["--select", spec]
                run(cmd)
                with open(report_path) as f:
                    rows.append(row("%s.%s" % (case, method), json.load(f)))
    thesis = args.thesis or os.path.join(os.path.dirname(os.path.abspath(args.out)), "thesis.jsonl")
    with open(thesis) as f:
        records = [json.loads(line) for line in f if line.strip()]
    for placement in ("trilinear", "optimized"):
        for table in ("6-2", "H-1"):
            for r in records:
                if (r.get("tags", {}).get("table") == table and r.get("smoothing")
                        and r["options"]["placement"]["method"] == placement):
                    suffix = "" if placement == "trilinear" else "/optimized"
                    rows.append(row("%s%s.%s (thesis.jsonl)" % (table, suffix, r["method"]), r))
    print("\n".join(rows))


if __name__ == "__main__":
    main()
