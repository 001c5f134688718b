#!/usr/bin/python3
"""The real-mesh study's report (hexrefine study).

usage: real_meshes_report.py RECORDS.jsonl --out DIR [--quiet]

Reads the records of `hexrefine study` (one per mesh x region kind x placement x method, each
refined, checked, smoothed and checked again by the pipeline, algorithms/pipeline.hpp) and
writes into DIR:
  real_meshes.md                  the targets of the real-mesh issue, a summary per method and
                                  placement, and every case
  plots/real_meshes_quality.png   histograms of the outputs' scaled Jacobians per method and
                                  placement (all cases summed), unsmoothed
Exit status 2 on bad input.
"""

import argparse
import os

import matplotlib

import records

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

METHODS = ["selective", "sheet"]
PLACEMENTS = ["trilinear", "optimized"]


def fail(message):
    records.fail("real_meshes_report.py", message)


def fmt(value, digits=3):
    return records.fmt(value, digits)


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


def summarise(r):
    """The numbers of one record, or None fields for a refusal."""
    s = {"mesh": r["tags"]["mesh"], "kind": r["tags"]["kind"], "placement": r["tags"]["placement"],
         "method": r["method"], "error": r.get("error")}
    if s["error"]:
        return s
    check = r["check"]
    s["parents"] = r["refined_parents"]["min_scaled_jacobian"]
    s["parents_count"] = r["refined_parents"]["hexes"]
    s["min"] = check["min_scaled_jacobian"]
    s["valid"] = check["valid"]
    s["hexes"] = check["hexes"]
    s["input_hexes"] = r["input"]["hexes"]
    s["below"] = share_below(check["scaled_jacobian_histogram"])
    s["histogram"] = check["scaled_jacobian_histogram"]
    smoothing = r.get("smoothing")
    s["smoothed"] = smoothing["check"]["min_scaled_jacobian"] if smoothing else s["min"]
    s["smoothed_valid"] = smoothing["check"]["valid"] if smoothing else s["valid"]
    # Longest over shortest edge, largest over the mesh (older records: not measured).
    s["edge_ratio"] = check.get("max_edge_ratio")
    s["smoothed_edge_ratio"] = smoothing["check"].get("max_edge_ratio") if smoothing \
        else s["edge_ratio"]
    # The children of the refined parents alone: the mesh-wide minimum also holds untouched input
    # hexes, which can be worse than every refined parent.
    parents = r["refined_parents"]
    s["children"] = parents.get("children_min_scaled_jacobian", s["min"])
    s["children_smoothed"] = parents.get("smoothed_children_min_scaled_jacobian", s["children"])
    stages = r["stage_seconds"]
    s["refine_s"] = stages.get("refine", 0.0)
    s["placement_s"] = r["refine"]["placement"]["seconds"]
    s["smooth_s"] = stages.get("smooth", 0.0)
    return s


def anisotropy_section(records_):
    """The anisotropy cases: output minimum per aspect ratio, orientation, placement, method."""
    cell = {}
    for r in records_:
        t = r["tags"]
        if r.get("error"):
            value = "refused"
        else:
            smoothed = r["smoothing"]["check"]["min_scaled_jacobian"] if r.get("smoothing") \
                else r["check"]["min_scaled_jacobian"]
            value = "%s (%s)" % (fmt(r["check"]["min_scaled_jacobian"], 3), fmt(smoothed, 3))
        cell[(t["aspect"], t["orientation"], t["placement"], r["method"])] = value
    keys = sorted({(a, o) for (a, o, _, _) in cell}, key=lambda k: (k[1] != "long", k[0]))
    out = ["\n## Anisotropic parents: what the parents' scaled Jacobian does not see\n",
           "One target hex in the middle of a 5x5x5 brick of boxes: *long* boxes 1 x 1 x a (the "
           "neighbours above and below the target hold a transition template in their small "
           "face), *flat* boxes a x a x 1. Every parent has scaled Jacobian 1, so the target "
           "above asks for 0.3 on all of them; the output minimum unsmoothed (smoothed in "
           "brackets). Placement moves only new nodes: the input's nodes, half the corners "
           "of a transition child, stay, and with them the child's long edge. Smoothing moves "
           "the input's nodes too.\n",
           "| aspect a | boxes | selective trilinear | selective optimized | sheet trilinear | "
           "sheet optimized |", "|---:|---|---:|---:|---:|---:|"]
    for a, o in keys:
        out.append("| %s | %s | %s |" % (fmt(a), o, " | ".join(
            cell.get((a, o, p, m), "–") for m in METHODS for p in PLACEMENTS)))
    return "\n".join(out)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("records")
    parser.add_argument("--out", required=True)
    parser.add_argument("--quiet", action="store_true")
    args = parser.parse_args()
    every = records.read_records(args.records, "real_meshes_report.py")
    study = [r for r in every if r.get("tags", {}).get("study") == "real_meshes"]
    anisotropy = [r for r in every if r.get("tags", {}).get("study") == "anisotropy"]
    if not study:
        fail("%s: no records of the real-mesh study" % args.records)
    rows = [summarise(r) for r in study]
    os.makedirs(os.path.join(args.out, "plots"), exist_ok=True)

    out = ["# Real meshes: both refiners, both placements, smoothed\n",
           "Generated by `hexrefine study` from `%s` (%d records, commit %s). Every shared mesh "
           "of `../shared/meshes` x region kind (sphere, two grown blobs, the largest boundary "
           "surface, two scattered sets, two passes with the buffer; rockerarm also the issue's "
           "`sphere:0,0,0,5`) x method x node placement, each output checked against its input, "
           "smoothed (`--smooth`: the refined region and two layers) and checked again. Quality "
           "is the scaled Jacobian; *parents* is the minimum over the input hexes that were "
           "refined.\n" % (os.path.basename(args.records), len(study),
                           study[0].get("commit", "?")[:12])]

    # Targets of the real-mesh issue.
    valid_inputs = [s for s in rows if not (s["error"] and "scaled Jacobian <= 0" in s["error"])
                    and not (s["error"] and "not valid" in s["error"])]
    refused = [s for s in valid_inputs if s["error"]]
    optimized = [s for s in rows if not s["error"] and s["placement"] == "optimized"]
    ratio_ok = [s for s in optimized if s["min"] >= 0.3 * s["parents"] - 1e-12]
    smooth_ok = [s for s in optimized if s["smoothed"] >= 0.5 * s["parents"] - 1e-12]
    children_ok = [s for s in optimized if s["children"] >= 0.3 * s["parents"] - 1e-12]
    children_smooth_ok = [s for s in optimized
                          if s["children_smoothed"] >= 0.5 * s["parents"] - 1e-12]
    smooth_never_lower = [s for s in rows if not s["error"] and s["smoothed"] >= s["min"] - 1e-12]
    fast = [s for s in optimized if s["smooth_s"] <= 5 * s["refine_s"]]
    # The issue's time target is for rockerarm-sized cases (10,600 input hexes): on the small
    # meshes both phases take milliseconds and their ratio says little.
    sized = [s for s in optimized if s["input_hexes"] >= 5000]
    sized_fast = [s for s in sized if s["smooth_s"] <= 5 * s["refine_s"]]
    issue = [s for s in optimized if s["kind"] == "issue-sphere" and s["method"] == "selective"]
    done = [s for s in rows if not s["error"]]
    # Edge-ratio cap (NodeOptimizerOptions::max_edge_ratio, 20): an optimized output's largest
    # edge ratio against max(20, the trilinear output's of the same case).
    trilinear_ratio = {(s["mesh"], s["kind"], s["method"]): s["edge_ratio"] for s in done
                       if s["placement"] == "trilinear"}
    capped = [s for s in optimized if s["edge_ratio"] is not None
              and (s["mesh"], s["kind"], s["method"]) in trilinear_ratio]
    def cap_of(s):
        return max(20.0, trilinear_ratio[(s["mesh"], s["kind"], s["method"])]) * (1 + 1e-9)
    capped_ok = [s for s in capped if s["edge_ratio"] <= cap_of(s)]
    capped_smooth_ok = [s for s in capped if s["smoothed_edge_ratio"] <= cap_of(s)]
    out.append("\n## Targets\n")
    out.append("| target | measured |\n|---|---|")
    # The target is the default (optimized) placement's; the thesis' trilinear positions invert
    # children of distorted parents, which the pipeline refuses: counted beside it.
    for placement in ("optimized", "trilinear"):
        mine = [s for s in valid_inputs if s["placement"] == placement]
        bad = [s for s in refused if s["placement"] == placement]
        out.append("| 0 refusals on every valid mesh (conformal, every scaled Jacobian > 0), %s "
                   "placement | %d refused of %d such records%s |" % (
                       placement, len(bad), len(mine),
                       "" if not bad else " (" + "; ".join(
                           "%s %s %s" % (s["mesh"], s["kind"], s["method"]) for s in bad[:6]) +
                       ("; ..." if len(bad) > 6 else "") + ")"))
    out.append("| optimized, unsmoothed: output min >= 0.3 x parents' min | %d of %d |" % (
        len(ratio_ok), len(optimized)))
    out.append("| the same over the children alone (untouched input hexes left out) | %d of %d |" % (
        len(children_ok), len(optimized)))
    out.append("| rockerarm `sphere:0,0,0,5` (selective, optimized) >= 0.16 | %s |" % (
        ", ".join(fmt(s["min"], 4) for s in issue) or "–"))
    out.append("| `--smooth`: >= 0.5 x parents' min (optimized) | %d of %d |" % (
        len(smooth_ok), len(optimized)))
    out.append("| the same over the children alone (untouched input hexes left out) | %d of %d |" % (
        len(children_smooth_ok), len(optimized)))
    out.append("| `--smooth` never below the unsmoothed mesh | %d of %d |" % (
        len(smooth_never_lower), len(done)))
    out.append("| `--smooth` at most 5x the refinement time (optimized) | %d of %d |" % (
        len(fast), len(optimized)))
    out.append("| the same on the rockerarm-sized inputs (5,000 hexes or more) | %d of %d |" % (
        len(sized_fast), len(sized)))
    out.append("| no edge collapsed (added here): optimized output's largest edge ratio <= max(20, "
               "the trilinear output's; with two passes, pass 2 starts from pass 1's placed "
               "nodes, not the trilinear ones) | %d of %d%s |" % (
                   len(capped_ok), len(capped), "" if len(capped_ok) == len(capped) else
                   " (over: " + "; ".join("%s %s %s %s" % (s["mesh"], s["kind"], s["method"],
                                                          fmt(s["edge_ratio"], 3))
                                          for s in capped if s not in capped_ok) + ")"))
    out.append("| the same after `--smooth` | %d of %d |" % (len(capped_smooth_ok), len(capped)))
    # Where trilinear placement is not refused: does smoothing end higher from its positions?
    smoothed_of = {(s["mesh"], s["kind"], s["method"], s["placement"]): s for s in done}
    pairs = [(s, smoothed_of[(s["mesh"], s["kind"], s["method"], "trilinear")])
             for s in optimized if (s["mesh"], s["kind"], s["method"], "trilinear") in smoothed_of]
    out.append("| (observed) `--smooth` from the trilinear positions instead of the optimized ones, "
               "where trilinear is valid: higher / lower / equal; >= 0.5 x parents' min | "
               "%d / %d / %d of %d; %d (from optimized: %d) |" % (
                   sum(t["smoothed"] > o["smoothed"] + 1e-6 for o, t in pairs),
                   sum(t["smoothed"] < o["smoothed"] - 1e-6 for o, t in pairs),
                   sum(abs(t["smoothed"] - o["smoothed"]) <= 1e-6 for o, t in pairs), len(pairs),
                   sum(t["smoothed"] >= 0.5 * t["parents"] - 1e-12 for _, t in pairs),
                   sum(o["smoothed"] >= 0.5 * o["parents"] - 1e-12 for o, _ in pairs)))
    out.append("| every output written valid (checked against its input) | %d of %d |" % (
        sum(1 for s in done if s["valid"] and s["smoothed_valid"]), len(done)))

    out.append("\n## Summary per method and placement\n")
    out.append("| method | placement | cases | refused | min output / parents (median) | "
               "worst output min | share below 0.2 (mean) | smoothed worst min | largest edge "
               "ratio (smoothed) | refine s (sum) | placement s (sum) | smooth s (sum) |")
    out.append("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for m in METHODS:
        for p in PLACEMENTS:
            g = [s for s in rows if s["method"] == m and s["placement"] == p]
            ok = [s for s in g if not s["error"]]
            ratios = sorted(s["min"] / s["parents"] for s in ok if s["parents"] > 0)
            ratios_e = [s["edge_ratio"] for s in ok if s["edge_ratio"] is not None]
            ratios_se = [s["smoothed_edge_ratio"] for s in ok
                         if s["smoothed_edge_ratio"] is not None]
            out.append("| %s | %s | %d | %d | %s | %s | %s | %s | %s (%s) | %s | %s | %s |" % (
                m, p, len(g), len(g) - len(ok),
                fmt(ratios[len(ratios) // 2]) if ratios else "–",
                fmt(min((s["min"] for s in ok), default=None), 4),
                fmt(sum(s["below"] for s in ok) / len(ok)) if ok else "–",
                fmt(min((s["smoothed"] for s in ok), default=None), 4),
                fmt(max(ratios_e, default=None), 3), fmt(max(ratios_se, default=None), 3),
                fmt(sum(s["refine_s"] for s in ok)), fmt(sum(s["placement_s"] for s in ok)),
                fmt(sum(s["smooth_s"] for s in ok))))

    if anisotropy:
        out.append(anisotropy_section(anisotropy))

    out.append("\n## Every case\n")
    out.append("*children*: the minimum over the hexes made by refining the parents, unsmoothed "
               "and smoothed; *output* and *smoothed*: over the whole mesh.\n")
    out.append("| mesh | region | method | placement | output hexes | parents min | output min "
               "| children min | smoothed min | children smoothed | below 0.2 | edge ratio "
               "(smoothed) | refine s | of it placement s | smooth s |")
    out.append("|---|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for s in rows:
        if s["error"]:
            out.append("| %s | %s | %s | %s | refused: %s | | | | | | | | | | |" % (
                s["mesh"], s["kind"], s["method"], s["placement"],
                s["error"].replace("|", "/").replace("\n", " ")[:140]))
            continue
        out.append("| %s | %s | %s | %s | %s | %s | %s%s | %s | %s | %s | %s | %s (%s) | %s | %s "
                   "| %s |" % (
            s["mesh"], s["kind"], s["method"], s["placement"], fmt(s["hexes"]),
            fmt(s["parents"], 4), fmt(s["min"], 4), "" if s["valid"] else " INVALID",
            fmt(s["children"], 4), fmt(s["smoothed"], 4), fmt(s["children_smoothed"], 4),
            "%.1f%%" % (100 * s["below"]), fmt(s["edge_ratio"], 3),
            fmt(s["smoothed_edge_ratio"], 3), fmt(s["refine_s"]),
            fmt(s["placement_s"]), fmt(s["smooth_s"])))
    path = os.path.join(args.out, "real_meshes.md")
    with open(path + ".tmp", "w", encoding="utf-8") as f:
        f.write("\n".join(out) + "\n")
    os.replace(path + ".tmp", path)

    fig, axes = plt.subplots(1, 2, figsize=(12, 4.2), sharey=True)
    for ax, m in zip(axes, METHODS):
        for offset, p in enumerate(PLACEMENTS):
            g = [s for s in rows if s["method"] == m and s["placement"] == p and not s["error"]]
            if not g:
                continue
            h = g[0]["histogram"]
            counts = [sum(s["histogram"]["counts"][i] for s in g) for i in range(len(h["counts"]))]
            total = sum(counts) or 1
            width = h["bin_width"]
            lefts = [h["bin_edges_from"] + i * width for i in range(len(counts))]
            ax.bar([x + width * (0.3 + 0.4 * offset) for x in lefts],
                   [c / total for c in counts], width * 0.4, label=p)
        ax.set_title(m)
        ax.set_xlabel("scaled Jacobian (unsmoothed outputs, all cases)")
        ax.set_xlim(-0.1, 1.0)
        ax.set_yscale("log")
        ax.legend()
    axes[0].set_ylabel("share of output hexes")
    fig.tight_layout()
    plot = os.path.join(args.out, "plots", "real_meshes_quality.png")
    fig.savefig(plot + ".tmp.png", dpi=110)
    plt.close(fig)
    os.replace(plot + ".tmp.png", plot)
    if not args.quiet:
        print("wrote %s and %s" % (path, plot))


if __name__ == "__main__":
    main()
