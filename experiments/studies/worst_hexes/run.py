#!/usr/bin/env python3
"""Where the worst hexes of the smoothed real-mesh cases that miss issue 28's quality target sit.

The real-mesh study (`hexrefine study`, results/real_meshes.jsonl) counts the smoothed cases
whose minimum scaled Jacobian stays below 0.5 x the refined parents' minimum. Two remedies the
field offers act on different hexes: pillowing the boundary turns a hex with two or three faces on
one smooth surface into an interior one, and does nothing for a transition hex inside the region
or with one face on the surface. This script reruns each such case (`hexrefine refine ...
--smooth`, the record's method, targets, passes, buffer and edge-ratio cap, one thread), lists its
ten worst hexes (`hexrefine check OUT --worst 10`: boundary faces, template, input hex) and
tabulates them; then runs it again without the edge-ratio cap (`--max-edge-ratio 0`) to see
whether the cap is what holds its children.

Writes OUT/worst_hexes.json (every case: the command, the recorded and the rerun minimum, the
ten worst hexes, the smoothed children's minimum with and without the cap) and
OUT/worst_hexes.md (the tables). About fifteen minutes on the 2-core machine.

    python3 experiments/studies/worst_hexes/run.py [--records results/real_meshes.jsonl]
        [--meshes DIR ...] [--out results] [--hexrefine build/experiments/hexrefine]
        [--report-only]

--report-only rewrites OUT/worst_hexes.md from OUT/worst_hexes.json without rerunning.

Meshes are found by file name in the --meshes folders (default ../shared/meshes; the study's
public corpus is read from the folder it was given, /work/corpus here, not committed).
"""

import collections
import json
import pathlib
import subprocess
import sys
import tempfile

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent.parent))
import harness  # noqa: E402
from real_mesh_cases import find_mesh, mesh_folders, rerun_arguments, smoothed_refine_argv  # noqa: E402,E501

EPS = 1e-12  # as real_meshes/report.py
TEMPLATE_NAMES = {0: "untouched", 1: "1-27", 2: "1-13", 3: "1-5", 4: "1-4", 5: "1-3",
                  6: "1-3-adj1", 7: "1-3-adj2", 8: "directional", 9: "sheet", 10: "1-9"}


def failing_cases(records):
    """The smoothed records (arm default-smooth) of mesh files below 0.5 x their refined
    parents' minimum, measured as real_meshes/report.py does: the smoothed mesh's check, all its
    hexes."""
    out = []
    for r in records:
        if r.get("tags", {}).get("arm") != "default-smooth" or r.get("error"):
            continue
        smoothing = r.get("smoothing")
        parents = r.get("refined_parents", {})
        if not smoothing or parents.get("hexes", 0) == 0 or "file" not in r.get("input", {}):
            continue  # nothing refined, or a generated input (the anisotropic boxes)
        smoothed = harness.report_output_check(r)["min_scaled_jacobian"]
        if smoothed < 0.5 * parents["min_scaled_jacobian"] - EPS:
            out.append(r)
    return out


def children_min(report_path):
    """The smoothed children's minimum scaled Jacobian of a `refine --report` file."""
    return json.loads(pathlib.Path(report_path).read_text())["refined_parents"].get(
        "smoothed_children_min_scaled_jacobian")


def without_cap(argv):
    """`argv` with `--max-edge-ratio 0` (no cap) in place of any cap it gives."""
    out, skip = [], False
    for a in argv:
        if skip:
            skip = False
        elif a == "--max-edge-ratio":
            skip = True
        else:
            out.append(a)
    return out + ["--max-edge-ratio", "0"]


def band(count):
    return str(count) if count < 3 else "3+"


def tables(cases):
    lines = []
    ran = [c for c in cases if "worst" in c]
    lines.append("| boundary faces of the worst hex | 0 | 1 | 2 | 3+ |")
    lines.append("|---|---:|---:|---:|---:|")
    for label, subset in (("all %d cases" % len(ran), ran),
                          ("selective", [c for c in ran if c["method"] == "selective"]),
                          ("sheet", [c for c in ran if c["method"] == "sheet"])):
        count = collections.Counter(band(c["worst"][0]["boundary_faces"]) for c in subset)
        lines.append("| %s | %s |" % (label, " | ".join(str(count[b]) for b in
                                                        ("0", "1", "2", "3+"))))
    every = [w for c in ran for w in c["worst"]]
    two = sum(1 for w in every if w["boundary_faces"] >= 2)
    none = sum(1 for c in ran if all(w["boundary_faces"] < 2 for w in c["worst"]))
    lines.append("")
    lines.append("Over the ten worst hexes of every case (%d hexes): %d with two or more boundary "
                 "faces (%.1f %%); %d of %d cases have none among their ten worst." % (
                     len(every), two, 100.0 * two / max(1, len(every)), none, len(ran)))
    lines.append("")
    lines.append("| the worst hex's template tag | cases |")
    lines.append("|---|---:|")
    origin = collections.Counter(c["worst"][0]["template"] for c in ran)
    for name, count in origin.most_common():
        lines.append("| %s | %d |" % (name, count))
    lines.append("")
    lines.append("Every tag but *untouched* is a child of a refined hex: 1-13, 1-5, 1-4 and "
                 "directional children are the Selective Approach's transitions; *sheet* tags "
                 "every child of the sheet refiner's region, transition or not. "
                 "*untouched*: an input hex the refinement did not touch, whose own scaled "
                 "Jacobian is below half the refined parents' minimum (the target's whole-mesh "
                 "figure counts it; its children-only row in real_meshes.md does not).")
    lines.append("")
    lines.append("| mesh | region | method | recorded smoothed / parents | worst hex: boundary faces, "
                 "template |")
    lines.append("|---|---|---|---:|---|")
    for c in sorted(ran, key=lambda c: c["ratio"])[:15]:
        w = c["worst"][0]
        lines.append("| %s | %s | %s | %.3f | %d, %s |" % (c["mesh"], c["kind"], c["method"],
                                                         c["ratio"], w["boundary_faces"],
                                                         w["template"]))
    return lines


def main():
    args = rerun_arguments(harness.first_line(__doc__)).parse_args()
    out_dir = pathlib.Path(args.out)
    if args.report_only:
        write_report(json.loads((out_dir / "worst_hexes.json").read_text()), out_dir)
        return
    folders = mesh_folders(args)
    records = [json.loads(line) for line in open(args.records)]
    cases = []
    with tempfile.TemporaryDirectory() as tmp:
        for i, r in enumerate(failing_cases(records)):
            name = pathlib.Path(r["input"]["file"]).name
            mesh = find_mesh(r, folders)
            parents = r["refined_parents"]["min_scaled_jacobian"]
            recorded = harness.report_output_check(r)["min_scaled_jacobian"]
            case = {"mesh": name, "kind": r["tags"]["kind"], "case": r["case"],
                    "method": r["method"], "parents_min": parents, "recorded_min": recorded,
                    "ratio": recorded / parents}
            cases.append(case)
            if mesh is None:
                case["skipped"] = "mesh not found in " + ", ".join(folders)
                continue
            out = pathlib.Path(tmp) / "out.vtu"
            argv = smoothed_refine_argv(args.hexrefine, mesh, out, r)
            case["argv"] = ["hexrefine", "refine", name, "OUT.vtu"] + argv[4:]
            refine_report = pathlib.Path(tmp) / "refine.json"
            refine = subprocess.run(argv + ["--report", str(refine_report)], capture_output=True,
                                    text=True)
            if refine.returncode != 0:
                case["error"] = refine.stdout[-500:] + refine.stderr[-500:]
                continue
            case["children_min"] = children_min(refine_report)
            # The same run without the edge-ratio cap: where the smoothed children then reach
            # more, the cap (issue 28, decision 1) is what holds them.
            # (to a file of its own: `out` is the capped output the check below lists)
            uncapped_argv = without_cap(argv)
            uncapped_argv[uncapped_argv.index(str(out))] = str(pathlib.Path(tmp) / "uncapped.vtu")
            uncapped = subprocess.run(uncapped_argv + ["--report", str(refine_report)],
                                      capture_output=True, text=True)
            if uncapped.returncode == 0:
                case["uncapped_children_min"] = children_min(refine_report)
            else:
                case["uncapped_error"] = uncapped.stdout[-500:] + uncapped.stderr[-500:]
            report = pathlib.Path(tmp) / "check.json"
            check = subprocess.run([args.hexrefine, "check", str(out), "--worst", "10",
                                    "--threads", "1", "--report", str(report)],
                                   capture_output=True, text=True)
            if check.returncode != 0:
                case["error"] = "check: " + check.stdout[-500:]
                continue
            j = json.load(open(report))
            case["rerun_min"] = j["min_scaled_jacobian"]
            case["worst"] = [{"hex": w["hex"], "scaled_jacobian": w["scaled_jacobian"],
                              "boundary_faces": w["boundary_faces"],
                              "template": w.get("template", TEMPLATE_NAMES.get(
                                  w["attributes"].get("template_tag", -1), "?")),
                              "parent_hex": w["attributes"].get("parent_hex")}
                             for w in j["worst_hexes"]]
            print("%d %s %s %s: %.3f, worst hex %d boundary faces, %s" % (
                i, name, case["kind"], r["method"], case["ratio"],
                case["worst"][0]["boundary_faces"], case["worst"][0]["template"]),
                file=sys.stderr, flush=True)
    # The reports this study reads are the records' (its reruns' reports give only the
    # children's minimum).
    result = dict(harness.provenance(args.hexrefine,
                                     {harness.report_schema_version(r) for r in records}),
                  records=args.records, mesh_folders=folders, cases=cases)
    harness.write_json_atomic(out_dir / "worst_hexes.json", result)
    write_report(result, out_dir)


def cap_paragraph(cases):
    """How many misses the edge-ratio cap holds: their smoothed children without the cap."""
    both = [c for c in cases if c.get("children_min") is not None and
            c.get("uncapped_children_min") is not None and c["parents_min"] > 0]
    if not both:
        return "No rerun without the edge-ratio cap is recorded."
    higher = [c for c in both if c["uncapped_children_min"] > c["children_min"] + 1e-4]
    lower = [c for c in both if c["uncapped_children_min"] < c["children_min"] - 1e-4]
    reach = [c for c in both if c["uncapped_children_min"] >= 0.5 * c["parents_min"] - EPS
             and c["children_min"] < 0.5 * c["parents_min"] - EPS]
    return ("Each miss was also run without the edge-ratio cap (`--max-edge-ratio 0`, the scaled "
            "Jacobian alone; issue 28's decision 1 keeps the cap for every quality figure): its "
            "smoothed children end higher on %d of %d and lower on %d (the uncapped run takes "
            "another path, its placement uncapped too, so it bounds nothing), and reach 0.5 x "
            "the parents (where they did not with the cap) on %d: %s." % (
                len(higher), len(both), len(lower), len(reach),
                ", ".join("%s %s %s %.3f -> %.3f" % (
                    c["mesh"], c["kind"], c["method"], c["children_min"] / c["parents_min"],
                    c["uncapped_children_min"] / c["parents_min"]) for c in reach) or "none"))


def write_report(result, out_dir):
    cases, commit = result["cases"], result["commit"]
    reproduced = [c for c in cases if "rerun_min" in c]
    mismatches = [c for c in reproduced if abs(c["rerun_min"] - c["recorded_min"]) > 1e-9]
    md = ["# Where the worst smoothed hexes sit",
          "",
          "From `experiments/studies/worst_hexes/run.py` (`worst_hexes.json`), %s, commit `%s`: every "
          "smoothed case of `real_meshes.jsonl` whose minimum scaled Jacobian stays below 0.5 x "
          "the refined parents' minimum (%d cases; %d rerun, %d skipped for a mesh not at hand, "
          "%d failed), rerun with `--smooth` and listed with `hexrefine check OUT --worst 10`. "
          "The rerun minimum equals the recorded one in %d of %d reruns." % (
              result["date"][:10], commit[:10], len(cases), len(reproduced),
              sum(1 for c in cases if "skipped" in c), sum(1 for c in cases if "error" in c),
              len(reproduced) - len(mismatches), len(reproduced)),
          "",
          "Reruns whose minimum differs from the record (the code changed since the study's "
          "commit; the boundary-face and template tables use the rerun, the last table the "
          "recorded ratio): " + (", ".join(
              "%s %s %s %.4g -> %.4g" % (c["mesh"], c["kind"], c["method"], c["recorded_min"],
                                         c["rerun_min"]) for c in mismatches) or "none") + ".",
          "",
          cap_paragraph(reproduced),
          "",
          "Pillowing the boundary (issue 28, item 4) helps a hex with two or three faces on one "
          "smooth surface; the tables say how many of the misses that is.",
          ""] + tables(cases)
    harness.write_text_atomic(out_dir / "worst_hexes.md", "\n".join(md) + "\n")


if __name__ == "__main__":
    main()
