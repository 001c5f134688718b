#!/usr/bin/env python3
"""Node placement at the refiner's speed (issue 29): time and quality of the four placements
(trilinear: the thesis' positions; reference: the templates' reference positions; optimized,
the default: reference, then the worst children optimised; untangle: the thesis' positions,
inverted children untangled, the start for --smooth) on generated bricks (full refinement, the L-shaped case G-1, 3 % random
targets on 40^3 plain and jittered, 5 % on 27^3 against Tong and Zhang's 0.221, a sphere) and on
the shared real meshes, both refiners where they differ.

Per case and placement: output minimum scaled Jacobian and largest edge ratio, the refine
stage's CPU seconds (`stage_cpu_seconds.refine` of the pipeline report: planning, applying,
placing; medians of --repeats runs on one thread), the placement phase's seconds and the
children it worked on; refusals (a child inverted at fixed positions) are recorded as such.
On the large cases the placement is also timed on two threads (the output is the same).
Writes results/placement.json (the records, their seconds and the provenance) and
results/placement.md.

    python3 experiments/studies/placement/run.py [--shared ../shared/meshes] [--out results]
        [--repeats N]
"""

import json
import pathlib
import statistics
import sys
import time

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent.parent))
import harness  # noqa: E402
from records import fmt  # noqa: E402

hexrefine = None  # the Python module, imported by main() (harness.import_hexrefine)

PLACEMENTS = ["trilinear", "reference", "optimized", "untangle"]


def brick(n, jitter=0.0, seed=1):
    return hexrefine.generate("brick", dims=[n, n, n], size=[float(n)] * 3, jitter=jitter,
                              seed=seed)


def cases(shared):
    """(name, mesh factory, specs, method, timed repeats, two-thread timing)."""
    out = [
        ("brick 12^3 full", lambda: brick(12), ["all"], "selective", 3, False),
        ("G-1 (10^3 L-shaped)", lambda: brick(10), ["boundary:-1,0,0", "boundary:0,0,-1"],
         "selective", 3, False),
        ("40^3 random 3 %", lambda: brick(40), ["random:0.03,7"], "selective", 5, True),
        ("40^3 jittered 0.15, random 3 %", lambda: brick(40, 0.15, 1), ["random:0.03,31"],
         "selective", 5, True),
        ("27^3 random 5 %", lambda: brick(27), ["random:0.05,7"], "selective", 3, True),
        ("40^3 sphere r = 12", lambda: brick(40), ["sphere:20,20,20,12"], "selective", 3, True),
        ("G-1 (10^3 L-shaped)", lambda: brick(10), ["boundary:-1,0,0", "boundary:0,0,-1"],
         "sheet", 3, False),
        ("40^3 random 3 %", lambda: brick(40), ["random:0.03,7"], "sheet", 3, False),
    ]
    real = ["rockerarm.mesh", "ellipsoid.mesh", "bunny_conforming.mesh",
            "cube_minus_sphere_conforming.mesh", "sphere_conforming.mesh", "sphere_sculpt.e",
            "ecr_hanger.mesh", "ecr_cap.mesh", "ecr_dragon.mesh", "ecr_bust.mesh"]
    for name in real:
        path = str(pathlib.Path(shared) / name)
        load = (lambda p: lambda: hexrefine.read(p))(path)
        specs = [["random:0.02,2"], ["blob:200,1"]]
        if name == "rockerarm.mesh":
            specs.insert(0, ["sphere:0,0,0,5"])
        for s in specs:
            out.append((name, load, s, "selective", 3 if name == "rockerarm.mesh" else 1, False))
        out.append((name, load, specs[0], "sheet", 1, False))
    return out


def run(mesh, specs, method, placement, threads):
    try:
        _, report = hexrefine.refine(mesh, specs, method=method, placement=placement,
                                     threads=threads)
    except hexrefine.RefinementError as error:
        return {"refused": str(error).splitlines()[0][:200]}
    except ValueError as error:  # an input no refinement of can be valid
        return {"refused": "invalid input: " + " ".join(str(error).split())[:200]}
    refine = report["refine"]
    check = harness.report_output_check(report)
    return {
        "hexes": refine["final_hexes"],
        "min": check["min_scaled_jacobian"],
        "max_edge_ratio": check["max_edge_ratio"],
        "valid": check["valid"],
        "refine_cpu_s": report["stage_cpu_seconds"]["refine"],
        "refine_s": report["stage_seconds"]["refine"],
        "placement_s": refine["phase_seconds"].get("placement", 0.0),
        "active": refine["placement"]["active_hexes"],
        "parents_min": report["refined_parents"]["min_scaled_jacobian"],
        "schema_version": harness.report_schema_version(report),
    }


def main():
    global hexrefine
    parser = harness.study_arguments(harness.first_line(__doc__))
    parser.add_argument("--shared", default=str(harness.SHARED / "meshes"),
                        help="the shared meshes (default %(default)s)")
    parser.add_argument("--repeats", type=int, default=0,
                        help="timed runs per case and placement (0: the case's own, 1-5)")
    args = parser.parse_args()
    hexrefine = harness.import_hexrefine()
    records, versions = [], set()
    started = time.time()
    for name, load, specs, method, repeats, two_threads in cases(args.shared):
        mesh = load()
        repeats = args.repeats or repeats
        for placement in PLACEMENTS:
            runs = [run(mesh, specs, method, placement, 1)]
            versions.update(r.pop("schema_version") for r in runs if "schema_version" in r)
            if "refused" not in runs[0]:
                runs += [run(mesh, specs, method, placement, 1) for _ in range(repeats - 1)]
            record = {"case": name, "select": specs, "method": method, "placement": placement,
                      "input_hexes": mesh.hex_count,
                      "repeats": repeats}
            if "refused" in runs[0]:
                record.update(runs[0])
            else:
                record.update({k: runs[0][k] for k in ("hexes", "min", "max_edge_ratio", "valid",
                                                        "active", "parents_min")})
                for key in ("refine_cpu_s", "refine_s", "placement_s"):
                    record[key] = statistics.median(r[key] for r in runs)
                    record[key + "_runs"] = [r[key] for r in runs]
                if two_threads and placement in ("optimized", "reference"):
                    two = [run(mesh, specs, method, placement, 2) for _ in range(repeats)]
                    record["placement_s_2_threads"] = statistics.median(r["placement_s"] for r in two)
                    record["refine_s_2_threads"] = statistics.median(r["refine_s"] for r in two)
                    record["same_min_2_threads"] = all(r["min"] == record["min"] for r in two)
            records.append(record)
            print("%-34s %-9s %-10s %s" % (name, method, placement,
                                          record.get("refused") or "min %.4f cpu %.3f s" % (
                                              record["min"], record["refine_cpu_s"])),
                  flush=True)
    out = pathlib.Path(args.out)
    harness.write_json_atomic(out / "placement.json", dict(
        harness.provenance(schema_version=versions), records=records,
        seconds=time.time() - started))
    write_report(records, out / "placement.md")


def write_report(records, path):
    by_case = {}
    for r in records:
        by_case.setdefault((r["case"], json.dumps(r["select"]), r["method"]), {})[r["placement"]] = r
    lines = [
        "# Node placement at the refiner's speed\n",
        "Generated by `experiments/studies/placement/run.py` (records: `placement.json`). Placements: "
        "*trilinear* (the thesis' positions), *reference* (the templates' reference positions, "
        "`algorithms/templates/template_reference.hpp`), *optimized* (the default: reference, then the "
        "children within 25 % of the pass's worst optimised), *untangle* (the thesis' positions, "
        "inverted children untangled: the start for `--smooth`). *min*: output minimum scaled Jacobian; *ratio*: the refine stage's "
        "CPU seconds (plan, apply, place; median of the runs, one thread) over trilinear's; "
        "*active*: children the placement worked on. CPU seconds and medians: single timings "
        "on the 2-core machine vary.\n",
        "| case | method | trilinear min | reference min | optimized min | untangle min | "
        "trilinear CPU s | reference x | optimized x | untangle x | optimized active | "
        "largest edge ratio (optimized) |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for (case, select, method), p in by_case.items():
        def cell(placement, key):
            r = p.get(placement)
            if r is None:
                return "–"
            if "refused" in r:
                return "refused"
            return fmt(r[key])

        def ratio(placement):
            r, t = p.get(placement), p.get("trilinear")
            if not r or "refused" in r or not t or "refused" in t or not t["refine_cpu_s"]:
                return "–"
            return "%.2f" % (r["refine_cpu_s"] / t["refine_cpu_s"])

        label = case + ("" if case.startswith(("G-1", "brick", "40^3", "27^3")) else
                        " `" + " ".join(json.loads(select)) + "`")
        lines.append("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
            label, method, cell("trilinear", "min"), cell("reference", "min"),
            cell("optimized", "min"), cell("untangle", "min"), cell("trilinear", "refine_cpu_s"),
            ratio("reference"), ratio("optimized"), ratio("untangle"),
            cell("optimized", "active"), cell("optimized", "max_edge_ratio")))
    threads = [r for r in records if "placement_s_2_threads" in r]
    if threads:
        lines += ["\nPlacement phase on one and two threads (medians, seconds; the same output: "
                  "`same min`):\n",
                  "| case | placement | 1 thread | 2 threads | same min |", "|---|---|---:|---:|---|"]
        for r in threads:
            lines.append("| %s | %s | %s | %s | %s |" % (
                r["case"], r["placement"], fmt(r["placement_s"]), fmt(r["placement_s_2_threads"]),
                fmt(r["same_min_2_threads"])))
    harness.write_text_atomic(path, "\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
