#!/usr/bin/env python3
"""The edge-ratio cap of node placement and smoothing (NodeOptimizerOptions::max_edge_ratio) swept
over the real-mesh study's cases, through the Python module: every optimized-placement case of
results/real_meshes.jsonl whose output has at most --max-output-hexes hexes, refined and smoothed
with caps 0 (none: the scaled Jacobian alone), 10, 20 (the default) and 30. Per case and cap:
the refined parents' minimum scaled Jacobian, the output's unsmoothed and smoothed, and their
largest edge ratio (longest over shortest edge of a hex). Writes results/edge_ratio_cap.json and
results/edge_ratio_cap.md. About five minutes on one core.

    PYTHONPATH=build/experiments/python /usr/bin/python3 experiments/edge_ratio_cap.py --out results
"""

import argparse
import json
import math
import os
import pathlib
import sys

import hexrefine

CAPS = [0, 10, 20, 30]
ROOT = pathlib.Path(__file__).resolve().parent.parent


def fail(message):
    print("edge_ratio_cap.py: " + message, file=sys.stderr)
    sys.exit(2)


def fmt(value, digits=3):
    if value is None:
        return "–"
    if isinstance(value, int):
        return "{:,}".format(value)
    return "%.*g" % (digits, value)


def study_cases(path, max_output_hexes):
    """The optimized (default-arm), refined cases of the real-mesh study (the records name their
    options)."""
    cases = []
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except OSError as error:
        fail("cannot read %s: %s" % (path, error))
    for number, line in enumerate(lines, 1):
        try:
            r = json.loads(line)
        except json.JSONDecodeError as error:
            fail("%s line %d: %s" % (path, number, error))
        tags = r.get("tags", {})
        # Records before issue 28 tag placement "optimized"; since, the unsmoothed default arm.
        if tags.get("study") != "real_meshes" or (tags.get("placement") != "optimized"
                                                  and tags.get("arm") != "default"):
            continue
        if r.get("error") or r["check"]["hexes"] > max_output_hexes:
            continue
        if r["refined_parents"]["hexes"] == 0:
            continue
        mesh_file = ROOT / "experiments" / r["input"]["file"] if not os.path.isabs(
            r["input"]["file"]) else pathlib.Path(r["input"]["file"])
        cases.append({"mesh": tags["mesh"], "kind": tags["kind"], "method": r["method"],
                      "file": str(mesh_file.resolve()), "specs": r["selection"]["specs"],
                      "passes": r["options"]["passes"], "buffer": r["options"]["buffer"]})
    return cases


def study_cases_with_meshes():
    """The command line (--out, --records, --max-output-hexes), the study's cases, and each case
    with its input mesh (read once per file): what this script and smooth_start.py share."""
    parser = argparse.ArgumentParser()
    parser.add_argument("--out", default="results")
    parser.add_argument("--records", default=str(ROOT / "results" / "real_meshes.jsonl"))
    parser.add_argument("--max-output-hexes", type=int, default=60000)
    args = parser.parse_args()
    cases = study_cases(pathlib.Path(args.records), args.max_output_hexes)
    if not cases:
        fail("%s: no optimized real-mesh cases to run" % args.records)
    meshes = {}
    pairs = []
    for case in cases:
        if case["file"] not in meshes:
            meshes[case["file"]] = hexrefine.read(case["file"])
        pairs.append((case, meshes[case["file"]]))
    return args, cases, pairs


def main():
    args, cases, pairs = study_cases_with_meshes()
    records = []
    for case, mesh in pairs:
        for cap in CAPS:
            _, report = hexrefine.refine(mesh, case["specs"], method=case["method"],
                                         passes=case["passes"], buffer=case["buffer"],
                                         smooth=True, max_edge_ratio=cap)
            check = report["check"]
            smoothed = report.get("smoothing", {}).get("check", check)
            records.append(dict(case, cap=cap,
                                parents_min=report["refined_parents"]["min_scaled_jacobian"],
                                min=check["min_scaled_jacobian"],
                                smoothed_min=smoothed["min_scaled_jacobian"],
                                edge_ratio=check["max_edge_ratio"],
                                smoothed_edge_ratio=smoothed["max_edge_ratio"],
                                valid=check["valid"] and smoothed["valid"],
                                refine_s=report["stage_seconds"]["refine"],
                                smooth_s=report["stage_seconds"].get("smooth", 0.0)))
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    tmp = out / "edge_ratio_cap.json.tmp"
    tmp.write_text(json.dumps(records, indent=1) + "\n", encoding="utf-8")
    os.replace(tmp, out / "edge_ratio_cap.json")

    lines = ["# Edge-ratio cap: what the scaled Jacobian gains by collapsing edges\n",
             "Generated by `experiments/edge_ratio_cap.py` (records: `edge_ratio_cap.json`): the "
             "%d optimized-placement cases of the real-mesh study with at most %s output hexes, "
             "refined and smoothed (`--smooth`) with `--max-edge-ratio` 0 (no cap: the scaled "
             "Jacobian alone), 10, 20 (the default) and 30. No move of placement or smoothing "
             "gives a hex an edge ratio above max(cap, its ratio before). *ratio*: output minimum "
             "scaled Jacobian over the refined parents' minimum, geometric mean over the cases; "
             "*edge ratio*: largest longest-over-shortest edge of a hex in the output.\n" % (
                 len(cases), fmt(args.max_output_hexes)),
             "| cap | unsmoothed >= 0.3 x parents | smoothed >= 0.5 x parents | ratio unsmoothed "
             "| ratio smoothed | edge ratio, median over cases (smoothed) | edge ratio, largest "
             "(smoothed) | all valid |",
             "|---:|---:|---:|---:|---:|---:|---:|---|"]
    for cap in CAPS:
        rs = [r for r in records if r["cap"] == cap]
        geo = lambda key: math.exp(sum(math.log(max(r[key], 1e-12) / r["parents_min"])
                                       for r in rs) / len(rs))
        median = lambda key: sorted(r[key] for r in rs)[len(rs) // 2]
        lines.append("| %s | %d of %d | %d of %d | %s | %s | %s (%s) | %s (%s) | %s |" % (
            cap if cap else "none", sum(r["min"] >= 0.3 * r["parents_min"] - 1e-12 for r in rs),
            len(rs), sum(r["smoothed_min"] >= 0.5 * r["parents_min"] - 1e-12 for r in rs),
            len(rs), fmt(geo("min")), fmt(geo("smoothed_min")), fmt(median("edge_ratio")),
            fmt(median("smoothed_edge_ratio")), fmt(max(r["edge_ratio"] for r in rs)),
            fmt(max(r["smoothed_edge_ratio"] for r in rs)),
            "yes" if all(r["valid"] for r in rs) else "NO"))
    lines.append("\n## Every case\n")
    lines.append("| mesh | region | method | cap | parents min | output min | smoothed min | "
                 "edge ratio (smoothed) |")
    lines.append("|---|---|---|---:|---:|---:|---:|---:|")
    for r in records:
        lines.append("| %s | %s | %s | %s | %s | %s | %s | %s (%s) |" % (
            r["mesh"], r["kind"], r["method"], r["cap"] if r["cap"] else "none",
            fmt(r["parents_min"], 4), fmt(r["min"], 4), fmt(r["smoothed_min"], 4),
            fmt(r["edge_ratio"], 3), fmt(r["smoothed_edge_ratio"], 3)))
    tmp = out / "edge_ratio_cap.md.tmp"
    tmp.write_text("\n".join(lines) + "\n", encoding="utf-8")
    os.replace(tmp, out / "edge_ratio_cap.md")
    print("wrote %s and edge_ratio_cap.json (%d records)" % (out / "edge_ratio_cap.md",
                                                             len(records)))


if __name__ == "__main__":
    main()
