#!/usr/bin/python3
"""Tables and plots of a hexrefine run beside the thesis' numbers.

usage: experiments/studies/thesis/report.py RECORDS.jsonl --thesis tables.json --out DIR [--quiet]

Reads the JSON Lines records of `hexrefine run` / `hexrefine reproduce` and the thesis' tables
(../shared/thesis/tables.json) and writes into DIR:
  tables.md                one Markdown table per thesis table: the thesis' number, ours and the
                           ratio ours / thesis, for both methods; the ablations; fitted exponents
  plots/G-2_time.png       time vs initial hexes, linear and log-log, thesis curves overlaid
  plots/G-3_time.png       the same for the radial (corner ball) sweep
  plots/quality.png        scaled Jacobian histograms of the single-case tables
  renders/*.png            boundary quads of every saved refined mesh, coloured by template
Records whose table is unknown are listed at the end. Exit status 2 on bad input.
"""

import json
import math
import os
import pathlib
import sys

import matplotlib

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent.parent))
import harness  # noqa: E402
import records  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

SINGLE_TABLES = ["G-1", "6-1", "6-2", "H-1", "H-2", "H-3", "H-4"]
SWEEPS = ["G-2", "G-3"]
METHODS = ["sheet", "selective"]  # the thesis' column order
METHOD_COLOURS = {"selective": "tab:blue", "sheet": "tab:red"}


SCRIPT = "thesis/report.py"


def fail(message):
    harness.fail(SCRIPT, message)


def record_view(r):
    """The fields the tables read, lifted out of a record's report (algorithms/pipeline/pipeline.hpp:
    "refine" RefineStats, the refined mesh's checker report and, where smoothing ran, the
    smoothed output's: harness.report_refined_check and report_output_check; "input" the
    runner's description of the input). Error records keep "error"."""
    v = dict(r)
    if "hexes" in r.get("input", {}):
        v["initial_hexes"] = r["input"]["hexes"]
    refine = r.get("refine", {})
    check = harness.report_refined_check(r) if "check" in r else {}
    for key in ("final_hexes", "time_seconds", "directional_hexes", "doublets_resolved",
                "hexes_per_template"):
        if key in refine:
            v[key] = refine[key]
    for key in ("conformal", "inverted_hexes", "non_conformal_faces", "min_scaled_jacobian",
                "scaled_jacobian_histogram"):
        if key in check:
            v[key] = check[key]
    if "smoothing" in r:
        v["smoothed_min_scaled_jacobian"] = harness.report_output_check(r)["min_scaled_jacobian"]
    return v


savefig_atomic = harness.savefig_atomic
fmt = records.fmt


def ratio(ours, theirs):
    if ours is None or theirs is None or isinstance(ours, bool):
        return "–"
    if theirs == 0:
        return "–"
    return "%.3g" % (ours / theirs)


def by_table(records):
    groups = {}
    for r in records:
        groups.setdefault(r.get("tags", {}).get("table", ""), []).append(r)
    return groups


def record_of(records, case, method):
    for r in records:
        if r.get("case") == case and r.get("method") == method:
            return r
    return None


def outcome(r):
    """Short verdict of one record: error text, or conformal/inverted status."""
    if r is None:
        return "not run"
    if "error" in r:
        return "error: " + " ".join(r["error"].replace("|", "/").split())[:160]
    parts = ["conformal" if r.get("conformal") else
             "NOT conformal (%s faces)" % fmt(r.get("non_conformal_faces"))]
    if r.get("inverted_hexes"):
        parts.append("%s inverted" % fmt(r["inverted_hexes"]))
    return ", ".join(parts)


# One sentence (or a few) per case for every ratio that is not 1, other than times (ours run on
# 2026 hardware: the header says so once) and the optimized-placement rows (not in the thesis).
TABLE_NOTES = {
    "G-1": "Every count and the trilinear minimum match the thesis (ratio 1).",
    "6-1": "Stand-in geometry: the thesis' stepped model is not given; ours is `generate "
           "stepped`'s defaults (1,188 unit cubes), so the counts differ (0.66, 0.65). The "
           "minimum 0.3077 is the 1-13 template in a unit cube; the thesis' 0.3143 came from its "
           "own geometry.",
    "6-2": "Stand-in geometry: the quarter piston is not given; ours is ellipsoid.mesh (6,816 "
           "hexes against 1,720, initial minimum 0.574 against 0.629), so counts and minima "
           "differ; the smoothed rows are our smoother, not the thesis'.",
    "H-1": "Stand-in gear (`generate gear`'s defaults: 8,568 nearly perfect hexes, initial "
           "minimum 0.989 against 0.429): final counts 0.876 of the thesis', a lower unsmoothed "
           "minimum (a transition at a tooth tip), lifted above the thesis' by smoothing.",
    "H-2": "Selective: the thesis' pass rule (`results/buffer_rules.md`, `results/methods.md`) "
           "gives its count and minimum exactly. Sheet: 332,448 against 332,864 - the thesis' "
           "sheet run refined two layers in its first pass, a layout no rule in its text "
           "produces; our 1-13 nested three times gives 0.003831 where its layout nests it "
           "twice (0.03501).",
    "H-2/none": "An ablation of the pass rule (the descendants of the targets only), compared "
                "with the thesis' selective numbers to show what the rule changes.",
    "H-2/transitions": "An ablation of the pass rule (every transition's children carried, "
                       "cumulatively: our earlier reading), compared with the thesis' selective "
                       "numbers.",
    "H-3": "Stand-in (cube_minus_sphere_conforming.mesh, 9,919 hexes against 1,643, initial "
           "minimum 0.283 against 0.596): counts and minima are not comparable. With the "
           "thesis' trilinear positions the Selective Approach refuses (children inverted in "
           "distorted parents); with optimized placement it refines.",
    "H-4": "rockerarm.mesh (10,600 hexes) stands in for the hook (2,032): every count is 27 "
           "times the input, as in the thesis, so the count ratios are the inputs' ratio "
           "(5.22); full refinement keeps the minimum, as in the thesis (0.965 is the ratio of "
           "the inputs' minima).",
}


def single_table(name, case, thesis, records, out):
    t = thesis.get(name, {})
    rows = [
        ("Initial element count", "initial_hexes", lambda r: r.get("initial_hexes"),
         lambda m: t.get("initial_hexes")),
        ("Final element count", "final_hexes", lambda r: r.get("final_hexes"),
         lambda m: t.get(m, {}).get("final_hexes")),
        ("Time (s)", "time", lambda r: r.get("time_seconds"),
         lambda m: t.get(m, {}).get("seconds")),
        ("CPU time (s)", "cpu", lambda r: r.get("cpu_seconds"),
         lambda m: t.get(m, {}).get("seconds")),
        ("Initial minimum quality", "q0",
         lambda r: r.get("input", {}).get("initial_min_scaled_jacobian"),
         lambda m: t.get(m, {}).get("initial_min_quality")),
        ("Final minimum quality", "q1", lambda r: r.get("min_scaled_jacobian"),
         lambda m: t.get(m, {}).get("final_min_quality")),
    ]
    ours = {m: record_of(records, case, m) for m in METHODS}
    smoothed = any(r and "smoothed_min_scaled_jacobian" in r for r in ours.values())
    if smoothed or any("final_min_quality_smoothed" in t.get(m, {}) for m in METHODS):
        rows.append(("Final minimum quality (smoothed)", "qs",
                     lambda r: r.get("smoothed_min_scaled_jacobian"),
                     lambda m: t.get(m, {}).get("final_min_quality_smoothed")))
    # The case again with optimized node placement (the thesis' numbers are trilinear's): an
    # extra row, compared with the thesis' value too.
    # Its rows read the optimized records (a trilinear record may be a refusal while the
    # optimized one is not).
    optimized = {m: record_of(records, case + "/optimized", m) for m in METHODS}
    if any(optimized.values()):
        rows.append(("Final minimum quality, optimized placement", "qo",
                     lambda r: r.get("min_scaled_jacobian"),
                     lambda m: t.get(m, {}).get("final_min_quality"), optimized))
        if smoothed:
            rows.append(("Final minimum quality, optimized placement (smoothed)", "qos",
                         lambda r: r.get("smoothed_min_scaled_jacobian"),
                         lambda m: t.get(m, {}).get("final_min_quality_smoothed"), optimized))
    out.append("### Table %s — case `%s`\n" % (name, case))
    if t.get("case"):
        out.append("Thesis: %s\n" % t["case"])
    r0 = next((r for r in ours.values() if r), None)
    if r0:
        out.append("Ours: input %s; selection %s (%s hexes).\n" % (
            describe_input(r0.get("input", {})), ", ".join("`%s`" % s for s in
                                                         r0.get("selection", {}).get("specs", [])),
            fmt(r0.get("selection", {}).get("hexes"))))
    out.append("| Measurement | Sheet (thesis) | Sheet (ours) | ratio | Selective (thesis) | "
               "Selective (ours) | ratio |")
    out.append("|---|---:|---:|---:|---:|---:|---:|")
    for label, _, get_ours, get_thesis, *source in rows:
        cells = [label]
        for m in METHODS:
            r = (source[0] if source else ours)[m]
            value = get_ours(r) if r and "error" not in r else None
            cells += [fmt(get_thesis(m)), fmt(value), ratio(value, get_thesis(m))]
        out.append("| " + " | ".join(cells) + " |")
    out.append("| Output check | | %s | | | %s | |" % (outcome(ours["sheet"]),
                                                    outcome(ours["selective"])))
    if any(optimized.values()):
        out.append("| Output check, optimized placement | | %s | | | %s | |" % (
            outcome(optimized["sheet"]), outcome(optimized["selective"])))
    out.append("")
    if case in TABLE_NOTES:
        out.append("Ratios other than 1: %s\n" % TABLE_NOTES[case])


def describe_input(inp):
    if "file" in inp:
        return "`%s` (sha256 %s…)" % (os.path.basename(inp["file"]), inp.get("sha256", "")[:12])
    params = ", ".join("%s=%s" % (k, v) for k, v in sorted(inp.items())
                       if k not in ("generate", "initial_min_scaled_jacobian"))
    return "generated %s%s" % (inp.get("generate", "?"), " (" + params + ")" if params else "")


def fit_exponent(xs, ys):
    """Least-squares slope of log y over log x (time ~ hexes^slope); None with < 3 points."""
    pts = [(math.log(x), math.log(y)) for x, y in zip(xs, ys) if x and y and x > 0 and y > 0]
    if len(pts) < 3:
        return None
    mx = sum(p[0] for p in pts) / len(pts)
    my = sum(p[1] for p in pts) / len(pts)
    sxx = sum((p[0] - mx) ** 2 for p in pts)
    if sxx == 0:
        return None
    return sum((p[0] - mx) * (p[1] - my) for p in pts) / sxx


def sweep_series(name, records):
    """{method: [(n, initial_hexes, seconds or None, record)]} sorted by n."""
    series = {m: [] for m in METHODS}
    for r in records:
        m = r.get("method")
        if m not in series:
            continue
        ok = "error" not in r
        series[m].append((r.get("tags", {}).get("n"), r.get("initial_hexes"),
                          r.get("time_seconds") if ok else None, r,
                          r.get("cpu_seconds") if ok else None))
    for m in series:
        series[m].sort(key=lambda s: (s[0] is None, s[0]))
    return series


def sweep_table(name, thesis, records, out, exponents):
    t = thesis.get(name, {})
    rows = {row[0]: row for row in t.get("rows", [])}
    series = sweep_series(name, records)
    out.append("### Table %s\n" % name)
    if t.get("case"):
        out.append("Thesis: %s\n" % t["case"])
    out.append("| n | initial hexes | selective s (thesis) | selective s (ours) | ratio | "
               "selective CPU s | sheet s (thesis) | sheet s (ours) | ratio | sheet CPU s | "
               "final hexes sel / sheet | check sel / sheet |")
    out.append("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|")
    ns = sorted({s[0] for m in METHODS for s in series[m] if s[0] is not None})
    for n in ns:
        sel = next((s for s in series["selective"] if s[0] == n), None)
        sh = next((s for s in series["sheet"] if s[0] == n), None)
        th = rows.get(n)
        init = (sel or sh)[1]
        cells = [str(n), fmt(init)]
        for s, col in ((sel, 2), (sh, 3)):
            theirs = th[col] if th else None
            cells += [fmt(theirs), fmt(s[2] if s else None), ratio(s[2] if s else None, theirs),
                      fmt(s[4] if s else None)]
        cells.append("%s / %s" % (fmt(sel[3].get("final_hexes") if sel else None),
                                  fmt(sh[3].get("final_hexes") if sh else None)))
        cells.append("%s / %s" % (outcome(sel[3] if sel else None), outcome(sh[3] if sh else None)))
        out.append("| " + " | ".join(cells) + " |")
    out.append("")
    for m, col in (("selective", 2), ("sheet", 3)):
        ours = fit_exponent([s[1] for s in series[m]], [s[2] for s in series[m]])
        ours_cpu = fit_exponent([s[1] for s in series[m]], [s[4] for s in series[m]])
        rows_all = t.get("rows", [])
        theirs = fit_exponent([r[1] for r in rows_all], [r[col] for r in rows_all])
        ours_n = {s[0] for s in series[m] if s[2] is not None}
        same = [r for r in rows_all if r[0] in ours_n]
        theirs_same = fit_exponent([r[1] for r in same], [r[col] for r in same])
        exponents.append((name, m, ours, ours_cpu, theirs_same, theirs))
    return series


def sweep_plot(name, thesis, series, path):
    t = thesis.get(name, {})
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.5))
    colours = METHOD_COLOURS
    ours_max = max([s[1] for m in METHODS for s in series[m] if s[2] is not None and s[1]],
                   default=None)
    for ax, log in zip(axes, (False, True)):
        for m, col in (("selective", 2), ("sheet", 3)):
            pts = [(s[1], s[2]) for s in series[m] if s[2] is not None and s[1]]
            if pts:
                ax.plot([p[0] for p in pts], [p[1] for p in pts], "o-", color=colours[m],
                        label="%s (ours)" % m)
            cpu = [(s[1], s[4]) for s in series[m] if s[4] is not None and s[1]]
            if cpu:
                ax.plot([p[0] for p in cpu], [p[1] for p in cpu], "o:", color=colours[m],
                        markerfacecolor="none", label="%s (ours, CPU)" % m)
            # The linear panel stays within our range, else the thesis' sheet times hide ours.
            rows = [r for r in t.get("rows", [])
                    if r[1] > 0 and (log or ours_max is None or r[1] <= ours_max)]
            if rows:
                ax.plot([r[1] for r in rows], [r[col] for r in rows], "s--", color=colours[m],
                        alpha=0.5, label="%s (thesis, 2007 hardware)" % m)
        ax.set_xlabel("initial hexes")
        ax.set_ylabel("refinement time (s)")
        if log:
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_title("%s, log-log" % name)
        else:
            ax.set_title("%s, linear" % name)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    savefig_atomic(fig, path, 110)


def quality_plot(groups, path):
    cases = [(t, r) for t in SINGLE_TABLES for r in groups.get(t, [])
             if "scaled_jacobian_histogram" in r]
    if not cases:
        return False
    names = sorted({r["case"] for _, r in cases}, key=lambda c: [x["case"] for _, x in cases].index(c))
    cols = 3
    rows = (len(names) + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.2 * rows), squeeze=False)
    for ax in axes.flat:
        ax.set_visible(False)
    for ax, case in zip(axes.flat, names):
        ax.set_visible(True)
        width = None
        lowest = 0.0
        for offset, m in ((-0.5, "selective"), (0.5, "sheet")):
            r = next((x for _, x in cases if x["case"] == case and x["method"] == m), None)
            if not r:
                continue
            h = r["scaled_jacobian_histogram"]
            width = h["bin_width"]
            lefts = [h["bin_edges_from"] + i * width for i in range(len(h["counts"]))]
            ax.bar([x + width / 2 + offset * width * 0.4 for x in lefts], h["counts"],
                   width=width * 0.4, label=m, log=True, color=METHOD_COLOURS[m])
            used = [x for x, c in zip(lefts, h["counts"]) if c > 0]
            lowest = min([lowest] + used[:1]) if used else lowest
        ax.set_title(case, fontsize=9)
        ax.set_xlim(lowest - 0.1, 1.05)  # inverted hexes (negative bins) stay in view
        ax.set_xlabel("scaled Jacobian")
        ax.legend(fontsize=7)
    fig.tight_layout()
    savefig_atomic(fig, path, 100)
    return True


def ablation_table(records, groups, out):
    rows = groups.get("ablation", [])
    if not rows:
        return
    out.append("### Ablations of the Selective Approach\n")
    out.append("| base case | variant | final hexes | directional hexes | doublets resolved | "
               "time (s) | min scaled Jacobian | check |")
    out.append("|---|---|---:|---:|---:|---:|---:|---|")
    bases = []
    for r in rows:
        base = r.get("tags", {}).get("base")
        if base not in bases:
            bases.append(base)
    for base in bases:
        # The unablated run first (the base case's own selective record), then each variant.
        lines = [("baseline", record_of(records, base, "selective"))]
        lines += [(r.get("tags", {}).get("variant"), r) for r in rows
                  if r.get("tags", {}).get("base") == base]
        for variant, x in lines:
            ok = x is not None and "error" not in x
            out.append("| %s | %s | %s | %s | %s | %s | %s | %s |" % (
                base, variant, fmt(x.get("final_hexes") if ok else None),
                fmt(x.get("directional_hexes") if ok else None),
                fmt(x.get("doublets_resolved") if ok else None),
                fmt(x.get("time_seconds") if ok else None),
                fmt(x.get("min_scaled_jacobian") if ok else None), outcome(x)))
    out.append("")


def other_table(title, rows, out):
    if not rows:
        return
    out.append("### %s\n" % title)
    out.append("| case | method | initial hexes | targets | final hexes | time (s) | min scaled Jacobian | check |")
    out.append("|---|---|---:|---:|---:|---:|---:|---|")
    for r in rows:
        ok = "error" not in r
        out.append("| %s | %s | %s | %s | %s | %s | %s | %s |" % (
            r.get("case"), r.get("method"), fmt(r.get("initial_hexes")),
            fmt(r.get("selection", {}).get("hexes")), fmt(r.get("final_hexes") if ok else None),
            fmt(r.get("time_seconds") if ok else None),
            fmt(r.get("min_scaled_jacobian") if ok else None), outcome(r)))
    out.append("")


def main():
    parser = harness.study_arguments(harness.first_line(__doc__), out=None)
    parser.add_argument("records", help="the records of hexrefine run / reproduce (JSON Lines)")
    parser.add_argument("--thesis", required=True, help="the thesis' tables.json")
    parser.add_argument("--out", required=True, help="folder for tables.md, plots/, renders/")
    parser.add_argument("--quiet", action="store_true")
    args = parser.parse_args()
    recs = [record_view(r) for r in records.read_records(args.records, SCRIPT)]
    try:
        with open(args.thesis, encoding="utf-8") as f:
            thesis = json.load(f)["tables"]
    except (OSError, ValueError, KeyError) as e:
        fail("%s: %s" % (args.thesis, e))
    os.makedirs(os.path.join(args.out, "plots"), exist_ok=True)
    groups = by_table(recs)

    meta = recs[0] if recs else {}
    out = ["# Thesis tables: ours beside Parrish's\n",
           "Generated by `experiments/studies/thesis/report.py` from `%s` (%d records). Commit %s, %s build, "
           "%s (%s cores), run %s. Times are the refine stage only (plan, apply, node placement; "
           "no I/O, no check): `time_seconds` (wall clock) and `cpu_seconds` (process CPU time "
           "of that stage; the refiners are single-threaded, so on a shared, loaded machine this "
           "is the better measure). The thesis' times are from 2007-era hardware, so ratios of times compare "
           "scaling, not machines. Quality = minimum hex scaled Jacobian. Ratio = ours / thesis. "
           "The rows \"optimized placement\" are not in the thesis (it measured the templates' "
           "trilinear positions): they are compared with its trilinear minimum, so a ratio "
           "above 1 there is what the placement gains. Every other ratio that is not 1 is "
           "explained under its table (stand-in geometry, a choice, or a measured effect; "
           "the choices are listed in `results/methods.md`).\n" % (
               os.path.basename(args.records), len(recs), meta.get("commit", "?")[:12],
               meta.get("build_type", "?"), meta.get("machine", {}).get("cpu", "?"),
               meta.get("machine", {}).get("cores", "?"), meta.get("timestamp", "?"))]
    for name in SINGLE_TABLES:
        cases = []
        for r in groups.get(name, []):
            if r["case"] not in cases and not r["case"].endswith("/optimized"):
                cases.append(r["case"])
        for case in cases:
            single_table(name, case, thesis, groups[name], out)
    exponents = []
    for name in SWEEPS:
        if name in groups:
            series = sweep_table(name, thesis, groups[name], out, exponents)
            sweep_plot(name, thesis, series, os.path.join(args.out, "plots", name + "_time.png"))
            out.append("![%s time](plots/%s_time.png)\n" % (name, name))
    if exponents:
        out.append("### Fitted scaling exponents (time ∝ initial hexes^k, least squares in log-log)\n")
        out.append("| sweep | method | k (ours) | k (ours, CPU) | k (thesis, same n) | "
                   "k (thesis, n = 5..75) |")
        out.append("|---|---|---:|---:|---:|---:|")
        for name, m, ours, ours_cpu, theirs_same, theirs in exponents:
            out.append("| %s | %s | %s | %s | %s | %s |" % (
                name, m, fmt(ours, 3), fmt(ours_cpu, 3), fmt(theirs_same, 3), fmt(theirs, 3)))
        out.append("")
    ablation_table(recs, groups, out)
    other_table("Other regions of the real meshes", groups.get("real", []), out)
    known = set(SINGLE_TABLES) | set(SWEEPS) | {"ablation", "real"}
    other_table("Other cases", [r for t, rs in groups.items() if t not in known for r in rs], out)
    if quality_plot(groups, os.path.join(args.out, "plots", "quality.png")):
        out.append("### Scaled Jacobian histograms\n\n![quality](plots/quality.png)\n")

    # A saved mesh is rendered; without it (a --resume run that kept its record, on a clone
    # where the meshes, which are not committed, were never written) the committed render of
    # the same record stays listed.
    renders = []
    mesh_dir = os.path.dirname(os.path.abspath(args.records))
    for r in recs:
        if "mesh_file" in r:
            src = os.path.join(mesh_dir, r["mesh_file"])
            png = os.path.splitext(os.path.basename(src))[0] + ".png"
            if os.path.exists(src) or os.path.exists(os.path.join(args.out, "renders", png)):
                renders.append((r, src, png))
    if renders:
        import render_mesh  # noqa: E402  (meshio: only where there is a mesh to draw)

        os.makedirs(os.path.join(args.out, "renders"), exist_ok=True)
        out.append("### Refined meshes (boundary quads coloured by template)\n")
        for r, src, png in renders:
            if os.path.exists(src):
                render_mesh.render(src, os.path.join(args.out, "renders", png),
                                   title="%s, %s: %s hexes" % (r["case"], r["method"],
                                                               fmt(r.get("final_hexes"))))
            out.append("![%s %s](renders/%s)" % (r["case"], r["method"], png))
        out.append("")

    path = os.path.join(args.out, "tables.md")
    harness.write_text_atomic(path, "\n".join(out) + "\n")
    if not args.quiet:
        print("thesis/report.py: wrote %s and plots to %s" % (path, os.path.join(args.out, "plots")))


if __name__ == "__main__":
    main()
