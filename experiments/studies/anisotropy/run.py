#!/usr/bin/env python3
"""What a parent's aspect ratio leaves the smoothed transitions (issue 28, item 4).

Issue 28 asks the smoothed children to reach 0.5 x the refined parents' minimum scaled Jacobian
on every case. The scaled Jacobian of a perfect box is 1 whatever its aspect, but a transition
template inside a flat box needs slanted children whose angles the box's thickness bounds. This
measures that bound where nothing else interferes: perfect bricks of N x N x N boxes, each box
1 x 1 x 1/a (edge ratio a), refined by both methods with `--smooth` (the default budget, the
edge-ratio cap on), targets a ball through the thickness and a grown blob. Every parent is a
perfect box (scaled Jacobian 1), so the smoothed children's minimum is the ratio itself.

The same bricks refined twice (`--passes 2`, the layer buffer, as the study's two-pass cases) for
the aspects of the study's two-pass misses: the second pass refines the first pass's children,
transitions included, whose own aspect the first pass made (a cube's 1-3 sheet transition child
is a 3:1 box).

Then, with --worst (results/worst_hexes.json), every miss of the real-mesh study is set against
it: the edge ratio of the input hex its worst smoothed child came from, and what a perfect brick
of that aspect (the tabulated aspect at or below it: a less flat brick does better) reaches with
the same method and the same number of passes. A miss whose ten worst hexes are all untouched
input hexes is checked against the input: where its worst is the input's own worst hex at its
input scaled Jacobian, the case's ratio is the input's, which no smoothing of the refinement
changes.

Writes OUT/anisotropy.json and OUT/anisotropy.md. About five minutes on the 2-core machine.

    python3 experiments/studies/anisotropy/run.py [--out results] [--worst results/worst_hexes.json]
        [--meshes DIR ...] [--hexrefine build/experiments/hexrefine] [--report-only]
        [--bricks anisotropy.json]
"""

import json
import pathlib
import subprocess
import sys
import tempfile

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent.parent))
import harness  # noqa: E402
from real_mesh_cases import mesh_folders  # noqa: E402
ASPECTS = [1, 1.5, 2, 3, 4, 6, 8, 12, 16]
# Two passes: the aspects of the study's two-pass misses (1 to 4.5) and a margin; the figures
# fall to a few hundredths by 6 in one pass already.
TWO_PASS_ASPECTS = [1, 1.5, 2, 3, 4, 6]
N = 12
METHODS = ["selective", "sheet"]
HEX_EDGES = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5),
             (2, 6), (3, 7)]


def targets(aspect, passes=1):
    """Target sets; two passes take a smaller ball (0.2: the study's two-pass ball is 0.1 of the
    diagonal, against 0.15 in one pass) so the second pass stays a few hundred thousand hexes."""
    thickness = 1.0 / aspect
    radius = 0.3 if passes == 1 else 0.2
    return {"ball": "sphere:0.5,0.5,%r,%r" % (thickness / 2, radius), "blob": "blob:40,7"}


def brick_runs(hexrefine, tmp, versions):
    """Every brick, method and target set refined with --smooth; the schema versions of their
    reports go into `versions` (a set)."""
    runs = []
    plan = [(a, 1) for a in ASPECTS] + [(a, 2) for a in TWO_PASS_ASPECTS]
    for aspect, passes in plan:
        brick = pathlib.Path(tmp) / ("brick_%s.e" % aspect)
        if not brick.exists():
            subprocess.run([hexrefine, "generate", "brick", str(brick), "--dims",
                            "%d,%d,%d" % (N, N, N), "--size", "1,1,%r" % (1.0 / aspect)],
                           check=True, capture_output=True)
        for method in METHODS:
            for kind, spec in targets(aspect, passes).items():
                report = pathlib.Path(tmp) / "r.json"
                argv = [hexrefine, "refine", str(brick), str(pathlib.Path(tmp) / "o.vtu"),
                        "--method", method, "--select", spec, "--passes", str(passes),
                        "--smooth", "--threads", "1", "--report", str(report)]
                p = subprocess.run(argv, capture_output=True, text=True)
                row = {"aspect": aspect, "passes": passes, "method": method, "targets": kind,
                       "select": spec}
                if p.returncode != 0:
                    row["error"] = (p.stdout + p.stderr)[-400:]
                else:
                    j = json.loads(report.read_text())
                    versions.add(harness.report_schema_version(j))
                    parents = j["refined_parents"]
                    output = harness.report_output_check(j)
                    row.update({"parents": parents["hexes"],
                                "parents_min": parents["min_scaled_jacobian"],
                                "children_min": parents["children_min_scaled_jacobian"],
                                "smoothed_children_min":
                                    parents["smoothed_children_min_scaled_jacobian"],
                                "valid": output["valid"],
                                "max_edge_ratio": output["max_edge_ratio"]})
                runs.append(row)
                print(aspect, passes, method, kind, row.get("smoothed_children_min"),
                      file=sys.stderr, flush=True)
    return runs


def edge_ratio(points, cell):
    import numpy as np
    lengths = [np.linalg.norm(points[cell[a]] - points[cell[b]]) for a, b in HEX_EDGES]
    return max(lengths) / min(lengths)


def miss_rows(worst_path, folders):
    """Per case of worst_hexes.json: the worst smoothed hex's parent and its edge ratio."""
    import numpy as np
    hexrefine = harness.import_hexrefine()
    data = json.loads(pathlib.Path(worst_path).read_text())
    rows, meshes = [], {}
    for case in data["cases"]:
        worst = case.get("worst") or []
        child = next((w for w in worst if w.get("template") != "untouched"), None)
        row = {"mesh": case["mesh"], "kind": case["kind"], "method": case["method"],
               "ratio": case["ratio"], "parents_min": case["parents_min"],
               "passes": 2 if case["kind"] == "two-passes" else 1}
        if case.get("uncapped_children_min") is not None and case["parents_min"] > 0:
            row["uncapped_children_ratio"] = case["uncapped_children_min"] / case["parents_min"]
        if case["mesh"] not in meshes:
            path = next((pathlib.Path(f) / case["mesh"] for f in folders
                         if (pathlib.Path(f) / case["mesh"]).exists()), None)
            if path is None:
                meshes[case["mesh"]] = None
            else:
                m = hexrefine.read(str(path))
                meshes[case["mesh"]] = (np.asarray(m.points), np.asarray(m.hexes),
                                        np.asarray(hexrefine.quality(m)))
        mesh = meshes[case["mesh"]]
        if child is None:
            row["parent_edge_ratio"] = None
            if worst and mesh is not None:
                # The case's worst hex is untouched: is it the input's own, as the input had it?
                w = worst[0]
                row["untouched_input_hex"] = w["parent_hex"]
                row["untouched_input_sj"] = float(mesh[2][w["parent_hex"]])
                row["untouched_unchanged"] = abs(w["scaled_jacobian"] - row["untouched_input_sj"]) \
                    <= 1e-9 and row["untouched_input_sj"] <= float(mesh[2].min()) + 1e-12
            rows.append(row)
            continue
        row["parent_hex"] = child["parent_hex"]
        row["child_min"] = child["scaled_jacobian"]
        # The worst child's own ratio: where an untouched input hex is the case's worst, the
        # case's ratio is that hex's, which no refinement or smoothing made.
        row["child_ratio"] = child["scaled_jacobian"] / case["parents_min"]
        row["parent_edge_ratio"] = (edge_ratio(mesh[0], mesh[1][child["parent_hex"]])
                                    if mesh is not None else None)
        rows.append(row)
    return rows


def brick_figure(runs, method, aspect, passes=1):
    """The lower of the two target sets' smoothed children minimum for the tabulated aspect at or
    below `aspect` with `passes` passes (None below the first)."""
    below = [a for a in (ASPECTS if passes == 1 else TWO_PASS_ASPECTS) if a <= aspect + 1e-12]
    if not below:
        return None
    values = [r["smoothed_children_min"] for r in runs if r["aspect"] == below[-1]
              and r.get("passes", 1) == passes and r["method"] == method and "error" not in r]
    return (below[-1], min(values)) if values else None


def brick_figure_between(runs, method, aspect, passes=1):
    """The perfect brick's figure at `aspect` interpolated linearly in log(aspect) between the
    tabulated aspects around it (the lower of the two target sets at each); the first or last
    tabulated figure outside their range (None without runs)."""
    import math
    table = ASPECTS if passes == 1 else TWO_PASS_ASPECTS
    figures = []
    for a in table:
        values = [r["smoothed_children_min"] for r in runs if r["aspect"] == a
                  and r.get("passes", 1) == passes and r["method"] == method and "error" not in r]
        if values:
            figures.append((a, min(values)))
    if not figures:
        return None
    if aspect <= figures[0][0]:
        return figures[0][1]
    for (a0, f0), (a1, f1) in zip(figures, figures[1:]):
        if aspect <= a1:
            t = (math.log(aspect) - math.log(a0)) / (math.log(a1) - math.log(a0))
            return f0 + t * (f1 - f0)
    return figures[-1][1]


def write_report(result, out_dir):
    runs = result["runs"]
    md = ["# Parent aspect ratio and the smoothed transitions", "",
          "From `experiments/studies/anisotropy/run.py` (`anisotropy.json`), %s, commit `%s`: perfect "
          "bricks of %d x %d x %d boxes 1 x 1 x 1/a (each box's edge ratio a, its scaled Jacobian "
          "1), refined with `hexrefine refine BRICK OUT --method M --select S --smooth --threads 1`"
          " (the default smoothing budget, the edge-ratio cap on). Every parent is a perfect box, "
          "so the smoothed children's minimum is their ratio to the parents' minimum, the figure "
          "issue 28 asks to be >= 0.5." % (result["date"][:10], result["commit"][:10], N, N, N),
          "", "| aspect a | selective, ball | selective, blob | sheet, ball | sheet, blob |",
          "|---:|---:|---:|---:|---:|"]
    def table(aspects, passes):
        rows = []
        for aspect in aspects:
            cells = []
            for method in METHODS:
                for kind in ["ball", "blob"]:
                    r = next((x for x in runs if x["aspect"] == aspect and x["method"] == method
                              and x["targets"] == kind and x.get("passes", 1) == passes), None)
                    if r is None or "error" in r:
                        cells.append("error" if r else "-")
                    else:
                        cells.append("%.3f (%.3f)" % (r["smoothed_children_min"],
                                                      r["children_min"]))
            rows.append("| %g | %s |" % (aspect, " | ".join(cells)))
        return rows
    md += table(ASPECTS, 1)
    md += ["", "Smoothed (unsmoothed) children's minimum scaled Jacobian. Targets: *ball* "
           "`sphere:0.5,0.5,t/2,0.3` (t = 1/a, the brick's thickness: the ball cuts through it, "
           "the transitions run across the boxes' long sides), *blob* `blob:40,7`. All outputs "
           "valid: %s." % ("yes" if all(r.get("valid") for r in runs) else "NO"), ""]
    if any(r.get("passes", 1) == 2 for r in runs):
        md += ["## Two passes", "",
               "The same bricks, `--passes 2` (the layer buffer, as the study's two-pass cases), "
               "the ball of radius 0.2 (`sphere:0.5,0.5,t/2,0.2`) and the same blob. The second "
               "pass refines the first pass's children, its transitions included, whose shapes the "
               "first pass made: a cube's sheet transition child is a 3:1 box, a selective one a "
               "slanted hex, so two passes on perfect cubes already lose what one pass on flat "
               "boxes loses.", "",
               "| aspect a | selective, ball | selective, blob | sheet, ball | sheet, blob |",
               "|---:|---:|---:|---:|---:|"] + table(TWO_PASS_ASPECTS, 2) + [""]
    misses = result.get("misses")
    if misses:
        explained = {1: 0, 2: 0}
        between = {1: 0, 2: 0}
        total = {1: 0, 2: 0}
        inputs_own = 0
        unexplained, cap_held = [], []
        lines = []
        for m in sorted(misses, key=lambda m: m["ratio"]):
            er = m.get("parent_edge_ratio")
            passes = m.get("passes", 1)
            fig = brick_figure(runs, m["method"], er, passes) if er is not None else None
            child = m.get("child_ratio")
            at_bound = fig is not None and child is not None and child >= fig[1] - 1e-12
            near = brick_figure_between(runs, m["method"], er, passes) if er is not None else None
            if er is not None:
                total[passes] += 1
                explained[passes] += at_bound
                between[passes] += near is not None and child is not None and \
                    child >= near - 1e-12
            if m.get("untouched_unchanged"):
                inputs_own += 1
                verdict = "the input's own worst hex (%d, %.3f), unchanged" % (
                    m["untouched_input_hex"], m["untouched_input_sj"])
            else:
                verdict = "yes" if at_bound else "no"
                if not at_bound:
                    unexplained.append(m)
                    uncapped = m.get("uncapped_children_ratio")
                    if uncapped is not None and uncapped >= 0.5 - 1e-12:
                        cap_held.append(m)
            uncapped = m.get("uncapped_children_ratio")
            lines.append("| %s | %s | %s | %.3f | %s | %s | %s | %s | %s | %s |" % (
                m["mesh"], m["kind"], m["method"], m["ratio"],
                "%.3f" % child if child is not None else "-",
                "%.1f" % er if er is not None else "untouched input hex",
                "%.3f (a = %g%s)" % (fig[1], fig[0], ", 2 passes" if passes == 2 else "")
                if fig else "-", "%.3f" % near if near is not None else "-", verdict,
                "%.3f" % uncapped if uncapped is not None else "-"))
        md += ["## The real-mesh study's misses against it", "",
               "Every case of `worst_hexes.json` (the smoothed cases below 0.5 x the refined "
               "parents, %d): the worst smoothed child among the case's ten worst hexes (an untouched "
               "input hex can be the case's worst: *smoothed / parents* is then its ratio, no "
               "refinement's), the edge ratio of the input hex that child came from, "
               "and the perfect brick's figure with the same method and number of passes at the "
               "tabulated aspect at or below it (the lower of its two target sets). *At or above*: "
               "the worst child reaches what a perfect brick of a less flat box reaches, so its "
               "miss is the parent's aspect, not the real mesh's geometry or the smoother. A case "
               "whose ten worst hexes are all untouched is checked against its input: its worst "
               "hex is then the input's own worst, at the input's scaled Jacobian, and the case's "
               "ratio is the input's minimum over the refined parents' minimum, which no "
               "smoothing of the refinement changes." % len(misses), "",
               "Of %d misses: %d are the input's own worst hex, unchanged; of the single-pass "
               "ones with a worst child, %d of %d are at or above the perfect brick's figure for "
               "their parent's aspect; of the two-pass ones, %d of %d are at or above the two-pass "
               "brick's. Against the brick's figure interpolated at the parent's own edge ratio "
               "(linear in log a between the tabulated aspects: an estimate, not a measurement), "
               "%d of %d and %d of %d." % (len(misses), inputs_own, explained[1], total[1],
                                           explained[2], total[2], between[1], total[1],
                                           between[2], total[2]), "",
               "Not at or above the brick's figure: %d; of these, %d reach 0.5 x the parents when "
               "the same case runs without the edge-ratio cap (*no cap*: the smoothed children's "
               "minimum over the parents' with `--max-edge-ratio 0`, from worst_hexes.json; a run "
               "on another path, placement uncapped too, so a pointer, not a bound), which points "
               "at the cap of issue 28's decision 1: %s." % (
                   len(unexplained), len(cap_held),
                   ", ".join("%s %s %s" % (m["mesh"], m["kind"], m["method"]) for m in cap_held)
                   or "none"), "",
               "| mesh | targets | method | smoothed / parents | worst child / parents | worst "
               "child's parent edge ratio | perfect brick | interpolated | at or above | no cap |",
               "|---|---|---|---:|---:|---:|---:|---:|---|---:|"] + lines
    harness.write_text_atomic(out_dir / "anisotropy.md", "\n".join(md) + "\n")


def main():
    ap = harness.study_arguments(harness.first_line(__doc__), hexrefine=True, report_only=True)
    ap.add_argument("--worst", default=None, help="worst_hexes.json of the real-mesh study")
    ap.add_argument("--meshes", action="append", default=None,
                    help="folders holding the study's meshes (default ../shared/meshes)")
    ap.add_argument("--bricks", default=None,
                    help="an anisotropy.json whose brick runs (and their commit and date) to keep, "
                    "the bricks not being run again: they do not depend on the study (with "
                    "--worst: the misses are set against them anew)")
    args = ap.parse_args()
    out_dir = pathlib.Path(args.out)
    if args.report_only:
        write_report(json.loads((out_dir / "anisotropy.json").read_text()), out_dir)
        return
    if args.bricks:
        # The kept bricks' provenance is theirs: the runs are not made again.
        kept = json.loads(pathlib.Path(args.bricks).read_text())
        if kept.get("bricks") != {"n": N, "aspects": ASPECTS}:
            sys.exit("%s: its bricks are not this script's (n %d, aspects %s)" % (
                args.bricks, N, ASPECTS))
        stamp = {key: kept.get(key) for key in harness.PROVENANCE_KEYS}
        runs = kept["runs"]
    else:
        versions = set()
        with tempfile.TemporaryDirectory() as tmp:
            runs = brick_runs(args.hexrefine, tmp, versions)
        stamp = harness.provenance(args.hexrefine, versions)
    result = dict(stamp, bricks={"n": N, "aspects": ASPECTS}, runs=runs)
    if args.worst:
        folders = mesh_folders(args)
        result["misses"] = miss_rows(args.worst, folders)
        result["worst"] = args.worst
    harness.write_json_atomic(out_dir / "anisotropy.json", result)
    write_report(result, out_dir)


if __name__ == "__main__":
    main()
