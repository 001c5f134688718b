#!/usr/bin/python3
"""The real-mesh study's report (hexrefine study, which runs it after the records).

usage: experiments/studies/real_meshes/report.py RECORDS.jsonl --out DIR [--quiet]

Reads the records of `hexrefine study` (one per mesh x region kind x arm x method; the arms of
issue 28: `trilinear` unsmoothed, `default` unsmoothed, `default-smooth`, each run by the
pipeline, algorithms/pipeline/pipeline.hpp, and checked against its input) and writes into DIR:
  real_meshes.md                  the targets of issue 28 (met and not met), the refusals of
                                  valid inputs with their messages, a summary per mesh and per
                                  arm, the anisotropy cases and every case
  plots/real_meshes_quality.png   histograms of the outputs' scaled Jacobians per method and arm
                                  (all cases summed; the smoothed arm's smoothed outputs)
A record's arm is its tag "arm"; the placement it used is its options.placement.method (the
pipeline picks the default's). The input counts as valid when the checker passed it (tag
"input_valid", stamped by the case generator). Exit status 2 on bad input.
"""

import collections
import json
import os
import pathlib
import sys

import matplotlib

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent.parent))
import harness  # noqa: E402
import records  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

METHODS = ["selective", "sheet"]
ARMS = ["trilinear", "default", "default-smooth"]
EPS = 1e-12


SCRIPT = "real_meshes/report.py"


def fail(message):
    harness.fail(SCRIPT, message)


def fmt(value, digits=3):
    return records.fmt(value, digits)


def median(values):
    values = sorted(values)
    if not values:
        return None
    n = len(values)
    return values[n // 2] if n % 2 else (values[n // 2 - 1] + values[n // 2]) / 2


def share_below(histogram, limit=0.2):
    """Share of the hexes of a check's histogram below `limit` (a bin edge)."""
    counts = histogram["counts"]
    total = sum(counts)
    if total == 0:
        return 0.0
    edge = histogram["bin_edges_from"]
    below = sum(c for i, c in enumerate(counts)
                if edge + (i + 1) * histogram["bin_width"] <= limit + 1e-9)
    return below / total


def seconds(r, stage):
    """A stage's CPU seconds (one thread: the better measure on a shared machine), else wall."""
    cpu = r.get("stage_cpu_seconds", {})
    return cpu[stage] if stage in cpu else r.get("stage_seconds", {}).get(stage, 0.0)


def summarise(r):
    """The numbers of one record; a refusal keeps only its identification and message."""
    t = r["tags"]
    options = r.get("options", {})
    placement = options.get("placement", {})
    s = {"mesh": t["mesh"], "folder": t.get("folder", "../shared/meshes"),
         "source": t.get("source", "shared"), "kind": t["kind"], "arm": t.get("arm"),
         "method": r["method"], "error": r.get("error"),
         "placement": placement.get("method", "?") if isinstance(placement, dict) else placement,
         "smooth": options.get("smooth", False),
         "input_valid": t.get("input_valid", True),
         "input_hexes": r.get("input", {}).get("hexes"),
         "input_min": r.get("input", {}).get("initial_min_scaled_jacobian")}
    if s["error"]:
        return s
    # The runner stamps the case's options; where the pipeline placed by `optimized` instead of
    # the untangle start (refused, or smoothed below plain refine), refine.placement_warning
    # says so.
    s["placement_warning"] = r.get("refine", {}).get("placement_warning")
    check = harness.report_refined_check(r)
    parents = r["refined_parents"]
    s["parents"] = parents["min_scaled_jacobian"]
    s["parents_count"] = parents["hexes"]
    s["min"] = check["min_scaled_jacobian"]
    s["valid"] = check["valid"]
    s["hexes"] = check["hexes"]
    s["below"] = share_below(check["scaled_jacobian_histogram"])
    smoothing = r.get("smoothing")
    final = harness.report_output_check(r)
    s["histogram"] = final["scaled_jacobian_histogram"]
    s["smoothed"] = final["min_scaled_jacobian"] if smoothing else None
    s["smoothed_valid"] = final["valid"]
    s["warning"] = smoothing.get("warning") if smoothing else None
    # Longest over shortest edge, largest over the mesh (older records: not measured).
    s["edge_ratio"] = check.get("max_edge_ratio")
    s["smoothed_edge_ratio"] = final.get("max_edge_ratio") if smoothing else None
    # The children of the refined parents alone: the mesh-wide minimum also holds untouched input
    # hexes, which can be worse than every refined parent.
    s["children"] = parents.get("children_min_scaled_jacobian", s["min"])
    s["children_smoothed"] = parents.get("smoothed_children_min_scaled_jacobian")
    s["refine_s"] = seconds(r, "refine")
    s["smooth_s"] = seconds(r, "smooth") if smoothing else None
    s["ratio"] = s["smoothed"] / s["parents"] if s["smoothed"] is not None and s["parents"] > 0 \
        else None
    return s


def smoothing_failed(s):
    """An error of the smoothed arm that names smoothing (not the refinement before it)."""
    return bool(s["error"]) and s["arm"] == "default-smooth" and "smooth" in s["error"].lower()


def first_line(message, width=160):
    return message.replace("|", "/").replace("\n", " ").strip()[:width]


def mesh_label(s):
    return s["mesh"] if s["source"] == "shared" else "%s (%s)" % (s["mesh"], s["folder"])


def left_out_of(records_path):
    """The meshes `hexrefine study` left out, from the case file beside the records."""
    path = os.path.join(os.path.dirname(os.path.abspath(records_path)),
                        "real_meshes.cases.json")
    try:
        with open(path, encoding="utf-8") as f:
            description = json.load(f).get("description", "")
    except (OSError, ValueError):
        return ""
    marker = "Left out: "
    if marker not in description:
        return ""
    # "PATH: REASON; ..." -> "FILE (REASON)": the folders are in the per-mesh table.
    entries = []
    for entry in description[description.index(marker) + len(marker):].split("; "):
        path, _, reason = entry.partition(": ")
        entries.append("%s (%s)" % (os.path.basename(path),
                                    reason.replace(", above the limit of", " >")))
    return "; ".join(entries)


def targets_section(rows):
    out = ["\n## Targets (issue 28)\n", "| target | measured | met |", "|---|---|---|"]

    def row(target, measured, met):
        out.append("| %s | %s | %s |" % (target, measured,
                                         met if isinstance(met, str) else ("yes" if met else
                                                                           "**no**")))

    valid = [s for s in rows if s["input_valid"]]
    for arm, what in (("default", "default placement, unsmoothed"),
                      ("default-smooth", "default placement with `--smooth`")):
        mine = [s for s in valid if s["arm"] == arm]
        refused = [s for s in mine if s["error"] and not smoothing_failed(s)]
        row("0 refusals of valid inputs (the checker passes them), %s" % what,
            "%d refused of %d" % (len(refused), len(mine)), not refused)
    trilinear = [s for s in valid if s["arm"] == "trilinear"]
    row("(trilinear, the thesis' placement: refusals counted, allowed)",
        "%d refused of %d" % (sum(1 for s in trilinear if s["error"]), len(trilinear)),
        "reported only")
    smoothed = [s for s in valid if s["arm"] == "default-smooth"]
    returned = [s for s in smoothed if not s["error"]]
    row("smoothing never fails: every smoothed case of a valid input returns a mesh",
        "%d of %d (%d smoothing failures)" % (len(returned), len(smoothed),
                                              sum(1 for s in smoothed if smoothing_failed(s))),
        len(returned) == len(smoothed))
    row("(smoothed cases whose report carries a smoothing warning, `smoothing.warning`)",
        "%d of %d" % (sum(1 for s in returned if s["warning"]), len(returned)), "counted")
    lower = [s for s in returned if s["smoothed"] is not None and s["smoothed"] < s["min"] - EPS]
    row("`--smooth` never below its unsmoothed minimum", "%d of %d" % (
        len(returned) - len(lower), len(returned)), not lower)
    # Against plain refine: the default arm (optimized, unsmoothed) of the same case and method.
    plain = {(s["folder"], s["mesh"], s["kind"], s["method"]): s["min"] for s in valid
             if s["arm"] == "default" and not s["error"]}
    paired = [s for s in returned if s["smoothed"] is not None and
              (s["folder"], s["mesh"], s["kind"], s["method"]) in plain]
    below_plain = [s for s in paired if s["smoothed"] < plain[
        (s["folder"], s["mesh"], s["kind"], s["method"])] - EPS]
    restarted = sum(1 for s in returned if (s.get("placement_warning") or "").startswith(
        "smoothing from untangle"))
    row("`--smooth` never below plain refine (the default placement, unsmoothed, same targets)",
        "%d of %d (%d smoothed from optimized after untangle ended below it)%s" % (
            len(paired) - len(below_plain), len(paired), restarted,
            "" if not below_plain else "; below: " + "; ".join(
                "%s %s %s %s < %s" % (s["mesh"], s["kind"], s["method"], fmt(s["smoothed"]),
                                      fmt(plain[(s["folder"], s["mesh"], s["kind"], s["method"])]))
                for s in below_plain[:6])), not below_plain)
    refined = [s for s in returned if s["parents_count"] > 0 and s["smoothed"] is not None]
    met = [s for s in refined if s["smoothed"] >= 0.5 * s["parents"] - EPS]
    row("smoothed >= 0.5 x the refined parents' minimum scaled Jacobian, every case",
        "%d met, %d not met" % (len(met), len(refined) - len(met)), len(met) == len(refined))
    children = [s for s in refined if s["children_smoothed"] is not None]
    met_c = [s for s in children if s["children_smoothed"] >= 0.5 * s["parents"] - EPS]
    row("the same over the children alone (untouched input hexes left out)",
        "%d met, %d not met" % (len(met_c), len(children) - len(met_c)),
        len(met_c) == len(children))
    issue = [s for s in returned if s["kind"] == "issue-sphere"]
    row("rockerarm `sphere:0,0,0,5` smoothed >= 0.5",
        ", ".join("%s %s" % (s["method"], fmt(s["smoothed"], 4)) for s in issue) or "–",
        all(s["smoothed"] >= 0.5 - EPS for s in issue) if issue else "not in this run")
    sized = [s for s in returned if (s["input_hexes"] or 0) >= 5000 and s["smooth_s"] is not None]
    fast = [s for s in sized if s["smooth_s"] <= 5 * s["refine_s"]]
    worst = max((s["smooth_s"] / s["refine_s"] for s in sized if s["refine_s"] > 0),
                default=None)
    row("smoothing time <= 5 x the refinement's (CPU seconds, one thread), every case of >= "
        "5,000 input hexes", "%d met of %d (worst %s x)" % (len(fast), len(sized), fmt(worst)),
        len(fast) == len(sized) if sized else "not in this run")
    meshes = {(s["folder"], s["mesh"]) for s in rows}
    outside = {m for m in meshes if any(s["source"] != "shared" for s in rows
                                        if (s["folder"], s["mesh"]) == m)}
    valid_meshes = {(s["folder"], s["mesh"]) for s in valid}
    row(">= 10 meshes", "%d meshes (%d valid inputs), %d from outside ../shared" % (
        len(meshes), len(valid_meshes), len(outside)), len(valid_meshes) >= 10)
    done = [s for s in rows if not s["error"]]
    row("every output valid (checked against its input; smoothed ones after smoothing)",
        "%d of %d" % (sum(1 for s in done if s["valid"] and s["smoothed_valid"]), len(done)),
        all(s["valid"] and s["smoothed_valid"] for s in done))
    # Decision 1: quality under the edge-ratio cap, max(20, the thesis placement's output).
    trilinear_ratio = {(s["folder"], s["mesh"], s["kind"], s["method"]): s["edge_ratio"]
                       for s in done if s["arm"] == "trilinear" and s["edge_ratio"] is not None}
    for arm, key in (("default", "edge_ratio"), ("default-smooth", "smoothed_edge_ratio")):
        mine = [s for s in done if s["arm"] == arm and s[key] is not None]
        compared = [s for s in mine if (s["folder"], s["mesh"], s["kind"], s["method"])
                    in trilinear_ratio]
        # 1e-6: the placement's guard compares edge lengths the scaled-Jacobian kernel read, the
        # checker computes them again (20.0000053 at most over the study).
        over = [s for s in compared if s[key] > max(20.0, trilinear_ratio[
            (s["folder"], s["mesh"], s["kind"], s["method"])]) * (1 + 1e-6)]
        row("edge-ratio cap held, %s: largest edge ratio <= max(20, the trilinear output's)" % (
            "default placement" if arm == "default" else "`--smooth`"),
            "%d of %d (%d without a trilinear output to compare)%s" % (
                len(compared) - len(over), len(compared), len(mine) - len(compared),
                "" if not over else "; over: " + "; ".join(
                    "%s %s %s %s" % (s["mesh"], s["kind"], s["method"], fmt(s[key]))
                    for s in over[:6])), not over)
    # Decision 3: retired as requirements, kept as figures.
    plain = [s for s in done if s["arm"] == "default" and s["parents_count"] > 0]
    retired = "retired (issue 28 decision 3): reported only"
    row("unsmoothed default output min >= 0.3 x parents' min", "%d of %d" % (
        sum(1 for s in plain if s["min"] >= 0.3 * s["parents"] - EPS), len(plain)), retired)
    row("the same over the children alone", "%d of %d" % (
        sum(1 for s in plain if s["children"] >= 0.3 * s["parents"] - EPS), len(plain)), retired)
    row("rockerarm `sphere:0,0,0,5` unsmoothed (default) >= 0.16",
        ", ".join("%s %s" % (s["method"], fmt(s["min"], 4)) for s in plain
                  if s["kind"] == "issue-sphere") or "–", retired)

    used = {}
    for s in rows:
        if not s["error"] or s["placement"] != "?":
            used.setdefault(s["arm"], {}).setdefault(s["placement"], 0)
            used[s["arm"]][s["placement"]] += 1
    out.append("\nPlacement each arm used (the records' `options.placement.method`): " + "; ".join(
        "*%s*: %s" % (arm, ", ".join("%s (%d runs)" % kv for kv in sorted(used[arm].items())))
        for arm in ARMS if arm in used) + "; of the *default-smooth* runs, %d were placed by "
        "optimized instead of the untangle start (refused: %d; smoothed below plain refine: %d; "
        "`refine.placement_warning`)" % tuple(
            sum(1 for s in rows if s["arm"] == "default-smooth" and not s["error"] and cond(
                s.get("placement_warning") or "")) for cond in (
                lambda w: bool(w), lambda w: w.startswith("the untangle start was refused"),
                lambda w: w.startswith("smoothing from untangle"))) +
        ". *Valid input*: the checker passes it (tag "
        "`input_valid`); refusals of invalid inputs are the right answer and are not counted.")
    return out


def refusals_section(rows):
    bad = [s for s in rows if s["error"] and s["input_valid"]]
    out = ["\n## Refusals and failures on valid inputs\n"]
    if not bad:
        out.append("None.")
        return out
    out += ["| mesh | region | method | arm (placement) | message |", "|---|---|---|---|---|"]
    for s in bad:
        out.append("| %s | %s | %s | %s (%s) | %s |" % (mesh_label(s), s["kind"], s["method"],
                                                        s["arm"], s["placement"],
                                                        first_line(s["error"])))
    return out


def per_mesh_section(rows):
    out = ["\n## Per mesh\n",
           "*refused*: errors on a valid input in the default arms (trilinear's in brackets); "
           "*smoothed / parents*: the smoothed output's minimum over the refined parents', worst "
           "and median over the cases; *smooth / refine*: CPU time ratio, worst.\n",
           "| mesh | folder | input hexes | input min SJ | input valid | runs | refused | "
           "smoothed / parents worst | median | smooth / refine worst |",
           "|---|---|---:|---:|---|---:|---:|---:|---:|---:|"]
    order = []
    for s in rows:
        if (s["folder"], s["mesh"]) not in order:
            order.append((s["folder"], s["mesh"]))
    for key in order:
        g = [s for s in rows if (s["folder"], s["mesh"]) == key]
        first = g[0]
        refused = sum(1 for s in g if s["error"] and s["input_valid"] and s["arm"] != "trilinear")
        tri = sum(1 for s in g if s["error"] and s["input_valid"] and s["arm"] == "trilinear")
        ratios = [s["ratio"] for s in g if not s["error"] and s["ratio"] is not None
                  and s["parents_count"] > 0]
        times = [s["smooth_s"] / s["refine_s"] for s in g if not s["error"]
                 and s["smooth_s"] is not None and s["refine_s"] > 0]
        out.append("| %s | %s | %s | %s | %s | %d | %d (%d) | %s | %s | %s |" % (
            first["mesh"], first["folder"], fmt(first["input_hexes"]), fmt(first["input_min"]),
            "yes" if first["input_valid"] else "no", len(g), refused, tri,
            fmt(min(ratios, default=None)), fmt(median(ratios)), fmt(max(times, default=None))))
    return out


def per_arm_section(rows):
    out = ["\n## Summary per method and arm\n",
           "| method | arm | runs | refused | output min / parents (median) | smoothed / parents "
           "(median) | worst output min | worst smoothed min | share below 0.2 (mean) | largest "
           "edge ratio | refine s (sum) | smooth s (sum) |",
           "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for m in METHODS:
        for arm in ARMS:
            g = [s for s in rows if s["method"] == m and s["arm"] == arm]
            if not g:
                continue
            ok = [s for s in g if not s["error"]]
            plain = [s["min"] / s["parents"] for s in ok if s["parents"] > 0]
            smooth = [s["ratio"] for s in ok if s["ratio"] is not None]
            edges = [s["smoothed_edge_ratio"] if s["smoothed_edge_ratio"] is not None
                     else s["edge_ratio"] for s in ok]
            edges = [e for e in edges if e is not None]
            out.append("| %s | %s | %d | %d | %s | %s | %s | %s | %s | %s | %s | %s |" % (
                m, arm, len(g), len(g) - len(ok), fmt(median(plain)), fmt(median(smooth)),
                fmt(min((s["min"] for s in ok), default=None), 4),
                fmt(min((s["smoothed"] for s in ok if s["smoothed"] is not None), default=None),
                    4),
                fmt(sum(s["below"] for s in ok) / len(ok)) if ok else "–",
                fmt(max(edges, default=None)), fmt(sum(s["refine_s"] for s in ok)),
                fmt(sum(s["smooth_s"] or 0.0 for s in ok))))
    return out


def anisotropy_section(records_):
    """The anisotropy cases: output minimum per aspect ratio, orientation, arm, method."""
    cell = {}
    for r in records_:
        t = r["tags"]
        if r.get("error"):
            value = "refused"
        else:
            value = fmt(harness.report_output_check(r)["min_scaled_jacobian"], 3)
        cell[(t["aspect"], t["orientation"], t.get("arm"), r["method"])] = value
    keys = sorted({(a, o) for (a, o, _, _) in cell}, key=lambda k: (k[1] != "long", k[0]))
    out = ["\n## Anisotropic parents: what the parents' scaled Jacobian does not see\n",
           "One target hex in the middle of a 5x5x5 brick of boxes: *long* boxes 1 x 1 x a (the "
           "neighbours above and below the target hold a transition template in their small "
           "face), *flat* boxes a x a x 1. Every parent has scaled Jacobian 1. Output minimum "
           "per arm (the smoothed arm: after smoothing). Placement moves only new nodes: the "
           "input's nodes, half the corners of a transition child, stay, and with them the "
           "child's long edge. Smoothing moves the input's nodes too.\n",
           "| aspect a | boxes | " + " | ".join("%s %s" % (m, a) for m in METHODS for a in ARMS) +
           " |", "|---:|---|" + "---:|" * (len(METHODS) * len(ARMS))]
    for a, o in keys:
        out.append("| %s | %s | %s |" % (fmt(a), o, " | ".join(
            cell.get((a, o, arm, m), "–") for m in METHODS for arm in ARMS)))
    return out


def every_case_section(rows):
    out = ["\n## Every case\n",
           "One row per mesh, region and method; the three arms side by side. *parents*: the "
           "minimum over the input hexes refined (default arm); *children smoothed*: the "
           "smoothed arm's minimum over the refined parents' children alone; *edge ratio*: the "
           "largest, trilinear / default / smoothed; *smooth / refine*: CPU seconds of the "
           "smoothed arm's two stages.\n",
           "| mesh | region | method | output hexes | parents min | trilinear min | default min "
           "| smoothed min | smoothed / parents | children smoothed | edge ratio | refine s | "
           "smooth s | smooth / refine |",
           "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|"]
    by = {}
    order = []
    for s in rows:
        key = (s["folder"], s["mesh"], s["kind"], s["method"])
        if key not in by:
            order.append(key)
        by.setdefault(key, {})[s["arm"]] = s

    def value(s, field, digits=4):
        if s is None:
            return "–"
        if s["error"]:
            return "refused" if not smoothing_failed(s) else "smoothing failed"
        return fmt(s[field], digits)

    for key in order:
        arms = by[key]
        t, d, sm = arms.get("trilinear"), arms.get("default"), arms.get("default-smooth")
        ref = next((s for s in (d, sm, t) if s and not s["error"]), None)
        edge = " / ".join(value(s, f, 3) for s, f in ((t, "edge_ratio"), (d, "edge_ratio"),
                                                      (sm, "smoothed_edge_ratio")))
        ratio = None
        if sm and not sm["error"] and sm["smooth_s"] is not None and sm["refine_s"] > 0:
            ratio = sm["smooth_s"] / sm["refine_s"]
        smoothed = value(sm, "smoothed")
        if sm and not sm["error"] and sm["warning"]:
            smoothed += " (warning)"
        out.append("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
            mesh_label(ref or t or d or sm), key[2], key[3],
            fmt(ref["hexes"]) if ref else "–", fmt(ref["parents"], 4) if ref else "–",
            value(t, "min"), value(d, "min"), smoothed, value(sm, "ratio", 3),
            value(sm, "children_smoothed"), edge,
            fmt(sm["refine_s"]) if sm and not sm["error"] else "–",
            fmt(sm["smooth_s"]) if sm and not sm["error"] else "–", fmt(ratio)))
    return out


def quality_plot(rows, path):
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.2), sharey=True)
    for ax, m in zip(axes, METHODS):
        for offset, arm in enumerate(ARMS):
            g = [s for s in rows if s["method"] == m and s["arm"] == arm and not s["error"]]
            if not g:
                continue
            h = g[0]["histogram"]
            counts = [sum(s["histogram"]["counts"][i] for s in g) for i in range(len(h["counts"]))]
            total = sum(counts) or 1
            width = h["bin_width"]
            lefts = [h["bin_edges_from"] + i * width for i in range(len(counts))]
            ax.bar([x + width * (0.15 + 0.28 * offset) for x in lefts],
                   [c / total for c in counts], width * 0.28, label=arm)
        ax.set_title(m)
        ax.set_xlabel("scaled Jacobian (outputs of all cases; smoothed arm after smoothing)")
        ax.set_xlim(-0.1, 1.0)
        ax.set_yscale("log")
        ax.legend()
    axes[0].set_ylabel("share of output hexes")
    fig.tight_layout()
    harness.savefig_atomic(fig, path, 110)


def study_commits(study):
    """The commits the records were run at, with their counts where there are several (a
    `--resume` rerun of some cases)."""
    counts = collections.Counter((r.get("commit", "?")[:12], bool(r.get("commit_dirty")))
                                 for r in study)
    names = ["%s%s" % (c, " with uncommitted changes" if dirty else "") for c, dirty in counts]
    if len(counts) == 1:
        return names[0]
    order = sorted(counts, key=lambda k: -counts[k])
    return ", ".join("%s: %d records" % ("%s%s" % (c, " with uncommitted changes" if d else ""),
                                        counts[(c, d)]) for c, d in order)


def main():
    parser = harness.study_arguments(harness.first_line(__doc__), out=None)
    parser.add_argument("records", help="the study's records (JSON Lines)")
    parser.add_argument("--out", required=True, help="folder for real_meshes.md and plots/")
    parser.add_argument("--quiet", action="store_true")
    args = parser.parse_args()
    every = records.read_records(args.records, SCRIPT)
    study = [r for r in every if r.get("tags", {}).get("study") == "real_meshes"]
    anisotropy = [r for r in every if r.get("tags", {}).get("study") == "anisotropy"]
    if not study:
        fail("%s: no records of the real-mesh study" % args.records)
    try:
        rows = [summarise(r) for r in study]
    except (KeyError, TypeError) as e:
        fail("%s: a study record lacks %s" % (args.records, e))
    os.makedirs(os.path.join(args.out, "plots"), exist_ok=True)

    left_out = left_out_of(args.records)
    out = ["# Real meshes: both refiners, three arms\n",
           "Generated by `hexrefine study` from `%s` (%d records, commit %s). Every mesh of "
           "`../shared/meshes` and of the `--meshes` folders x region kind (sphere, two grown "
           "blobs, the largest boundary surface, two scattered sets, two passes with the buffer; "
           "rockerarm also the issue's `sphere:0,0,0,5`) x method x arm: *trilinear* (the "
           "thesis' placement, unsmoothed), *default* (no placement given, unsmoothed) and "
           "*default-smooth* (no placement given, `--smooth`), each a run of its own, each "
           "output checked against its input. Quality is the scaled Jacobian; *parents* is the "
           "minimum over the input hexes that were refined.%s\n" % (
               os.path.basename(args.records), len(study), study_commits(study),
               (" Left out: " + left_out + ".") if left_out else "")]
    out += targets_section(rows)
    out += refusals_section(rows)
    out += per_mesh_section(rows)
    out += per_arm_section(rows)
    if anisotropy:
        out += anisotropy_section(anisotropy)
    out += every_case_section(rows)
    path = os.path.join(args.out, "real_meshes.md")
    harness.write_text_atomic(path, "\n".join(out) + "\n")

    plot = os.path.join(args.out, "plots", "real_meshes_quality.png")
    quality_plot(rows, plot)
    if not args.quiet:
        print("wrote %s and %s" % (path, plot))


if __name__ == "__main__":
    main()
