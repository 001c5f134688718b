#!/usr/bin/python3
"""The adaptive study: regenerates results/adaptive.* (records, plots, pictures, report) in one go.

usage: /usr/bin/python3 experiments/adaptive/study.py [--max-dofs 200000] [--jobs 2] [--large]
                                                      [--results results] [--work build/adaptive]
                                                      [--report-only]

Runs run.py (a process per problem and method, --jobs at a time):
- every problem (lshape, rockerarm, fichera) with every method of loop.VARIANTS to the budget
  (uniform on rockerarm to 2 x the budget: its first refinement, 304,881 DOFs, is above
  200,000) -> results/adaptive.jsonl;
- the issue's baselines: lshape with the oracle indicator (the exact error per hex), the direct
  loop and the issue's quadrature (degree 6 everywhere) -> results/adaptive.oracle.jsonl;
- lshape with uniform, selective and sheet under `mpirun -n 2` -> results/adaptive.mpi.jsonl;
- with --large: lshape uniform and selective to 4,000,000 DOFs -> results/adaptive.large.jsonl
  (about an hour; not part of the default study).
then writes the plots (results/adaptive.<problem>.png, adaptive.iterations.png), pictures of
refined meshes (adaptive.<problem>.mesh.png), results/adaptive.study.json (times, load, commit)
and results/adaptive.md. --report-only rewrites the plots and report from the records.
"""

import argparse
import json
import math
import os
import pathlib
import resource
import subprocess
import sys
import time

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(ROOT / "experiments" / "studies"))

PROBLEMS = ["lshape", "rockerarm", "fichera"]
METHODS = ["uniform", "selective", "sheet", "selective-trilinear", "selective-smooth",
           "selective-direct", "sheet-direct"]
COLOURS = {"uniform": "black", "selective": "#1f77b4", "sheet": "#d62728",
           "selective-trilinear": "#2ca02c", "selective-smooth": "#9467bd",
           "selective-direct": "#17becf", "sheet-direct": "#ff7f0e"}
STYLES = {"uniform": "--", "selective-direct": ":", "sheet-direct": ":"}
#: The issue's baselines (L-shape, 192 hexes, Q1, CG + GAMG): uniform and the oracle loops.
BASELINES = {
    "uniform": ([325, 6253, 149221], [0.134, 0.0656, 0.0318]),
    "selective-direct": ([325, 765, 1907, 4769, 14381, 46599, 152939],
                         [0.134, 0.093, 0.0725, 0.0571, 0.0413, 0.0301, 0.0222]),
    "sheet-direct": ([849, 3681, 5727, 13367, 30555, 298311],
                     [0.090, 0.068, 0.0567, 0.0411, 0.0325, 0.0178]),
}
PHASES = ["solve", "estimate", "mark", "refine"]
#: The estimator variants run on lshape to this budget (the default variant's records are the
#: main study's, cut there).
ESTIMATOR_BUDGET = 60000
ESTIMATOR_ERROR = 0.04


# --- running -------------------------------------------------------------------------------------

def jobs_of(args, work):
    """(name, command, output, processes) of every run, the longest first."""
    run = [sys.executable, str(HERE / "run.py")]
    jobs = []
    for problem in PROBLEMS:
        for method in METHODS:
            budget = args.max_dofs
            if problem == "rockerarm" and method == "uniform":
                budget = 2 * args.max_dofs
            out = work / ("%s.%s.jsonl" % (problem, method))
            command = run + ["--problem", problem, "--methods", method, "--max-dofs",
                             str(budget), "--out", str(out)]
            if method == "selective" and problem in ("lshape", "rockerarm"):
                command += ["--save-meshes", os.path.relpath(work / "meshes", ROOT)]
            jobs.append(("%s %s" % (problem, method), command, out, 1))
    for variant, flags in (("diameter", ["--estimator-size", "diameter"]),
                           ("no-laplacian", ["--no-laplacian"])):
        out = work / ("estimator.%s.jsonl" % variant)
        jobs.append(("lshape estimator %s" % variant, run + [
            "--problem", "lshape", "--methods", "selective,selective-direct", "--max-dofs",
            str(ESTIMATOR_BUDGET), "--out", str(out)] + flags, out, 1))
    out = work / "oracle.jsonl"
    jobs.append(("lshape oracle", run + ["--problem", "lshape", "--methods",
                                         "uniform,selective-direct,sheet-direct", "--estimator",
                                         "oracle", "--singular-quadrature-degree", "6",
                                         "--max-dofs", str(args.max_dofs), "--out", str(out)],
                 out, 1))
    out = work / "mpi.jsonl"
    jobs.append(("lshape mpirun -n 2", ["mpirun", "-n", "2"] + run + [
        "--problem", "lshape", "--methods", "uniform,selective,sheet", "--max-dofs",
        str(args.max_dofs), "--out", str(out)], out, 2))
    if args.large:
        out = work / "large.jsonl"
        jobs.insert(0, ("lshape large", run + ["--problem", "lshape", "--methods",
                                               "uniform,selective", "--max-dofs", "4000000",
                                               "--out", str(out)], out, 1))
    return jobs


def run_jobs(jobs, slots, work):
    """Runs the jobs, `slots` processes at a time (a job of 2 processes takes 2); stops at the
    first failure. Returns {name: wall seconds}."""
    environment = dict(os.environ)
    if os.geteuid() == 0:  # Open MPI refuses root without these.
        environment.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    pending, running, seconds = list(jobs), [], {}
    while pending or running:
        while pending and sum(j[3] for j, _, _, _ in running) + pending[0][3] <= max(
                slots, pending[0][3]):
            job = pending.pop(0)
            log = open(work / ("%s.log" % job[0].replace(" ", "_")), "w")
            print("start %s" % job[0], flush=True)
            process = subprocess.Popen(job[1], stdout=log, stderr=subprocess.STDOUT,
                                       env=environment, cwd=ROOT)
            running.append((job, process, log, time.perf_counter()))
            if sum(j[3] for j, _, _, _ in running) >= slots:
                break
        time.sleep(0.5)
        for entry in list(running):
            job, process, log, start = entry
            if process.poll() is None:
                continue
            running.remove(entry)
            log.close()
            seconds[job[0]] = time.perf_counter() - start
            print("done  %s (%.0f s, exit %d)" % (job[0], seconds[job[0]], process.returncode),
                  flush=True)
            if process.returncode != 0:
                for _, other, _, _ in running:
                    other.kill()
                sys.exit("study.py: %s failed (exit %d), see %s" % (
                    job[0], process.returncode, log.name))
    return seconds


def read_jsonl(path):
    with open(path) as f:
        return [json.loads(line) for line in f if line.strip()]


def write_atomic(path, text):
    tmp = "%s.tmp%d" % (path, os.getpid())
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)


def write_jsonl(path, records):
    write_atomic(path, "".join(json.dumps(r, sort_keys=True) + "\n" for r in records))


# --- measures -------------------------------------------------------------------------------------

def rate(records, last=4):
    """The least-squares slope of -log(error_h1) against log(dofs) over the last `last` steps."""
    r = records[-last:]
    if len(r) < 2:
        return None
    x = [math.log(p["dofs"]) for p in r]
    y = [math.log(p["error_h1"]) for p in r]
    mx, my = sum(x) / len(x), sum(y) / len(y)
    sxx = sum((a - mx)**2 for a in x)
    return -sum((a - mx) * (b - my) for a, b in zip(x, y)) / sxx if sxx > 0 else None


def dofs_at_error(records, error):
    """DOFs where the error_h1 curve reaches `error`: log-log interpolation between the steps
    around the first one at or below it; None if it never does."""
    for before, after in zip([None] + records[:-1], records):
        if after["error_h1"] <= error:
            if before is None or before["error_h1"] <= error:
                return float(after["dofs"])
            t = (math.log(before["error_h1"]) - math.log(error)) / (
                math.log(before["error_h1"]) - math.log(after["error_h1"]))
            return math.exp(math.log(before["dofs"]) +
                            t * (math.log(after["dofs"]) - math.log(before["dofs"])))
    return None


def first_step_at_error(records, error):
    for r in records:
        if r["error_h1"] <= error:
            return r
    return None


def by_method(records, problem):
    out = {}
    for r in records:
        if r["problem"] == problem:
            out.setdefault(r["method"], []).append(r)
    return {m: sorted(rs, key=lambda r: r["step"]) for m, rs in out.items()}


def fmt(value, digits=3):
    if value is None:
        return "-"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int):
        return "{:,}".format(value)
    if value == 0:
        return "0"
    if abs(value) >= 1e5 or abs(value) < 1e-3:
        return "%.*g" % (digits, value)
    return "%.*g" % (digits, value)


def cpu(records, phase):
    return sum(r["cpu_seconds"].get(phase, 0.0) for r in records)


# --- plots ----------------------------------------------------------------------------------------

def plot_errors(records, problem, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    curves = by_method(records, problem)
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.6))
    for ax, key, name in ((axes[0], "error_h1", "H1-seminorm error"),
                          (axes[1], "error_l2", "L2 error")):
        for method in METHODS:
            if method not in curves:
                continue
            rs = curves[method]
            ax.loglog([r["dofs"] for r in rs], [r[key] for r in rs], STYLES.get(method, "-"),
                      marker="o", markersize=3.5, color=COLOURS[method], label=method)
        dofs = [r["dofs"] for rs in curves.values() for r in rs]
        errors = [r[key] for rs in curves.values() for r in rs]
        slope = 1 / 3 if key == "error_h1" else 2 / 3
        x0, x1 = min(dofs), max(dofs)
        y0 = min(errors) * (x1 / x0)**slope * 1.2
        ax.loglog([x0, x1], [y0, y0 * (x1 / x0)**-slope], color="grey", linewidth=0.8)
        ax.text(x1, y0 * (x1 / x0)**-slope, " DOFs^-%s" % ("1/3" if slope < 0.5 else "2/3"),
                color="grey", fontsize=8, va="center")
        ax.set_xlabel("DOFs")
        ax.set_ylabel(name)
        ax.grid(True, which="both", linewidth=0.3)
        ax.set_title("%s: %s" % (problem, name), fontsize=10)
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    tmp = str(path) + ".tmp.png"
    fig.savefig(tmp, dpi=100)
    plt.close(fig)
    os.replace(tmp, path)


def plot_iterations(records, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    markers = {"lshape": "o", "rockerarm": "s", "fichera": "^"}
    fig, ax = plt.subplots(figsize=(7, 4.6))
    for method in METHODS:
        for problem in PROBLEMS:
            rs = [r for r in records if r["method"] == method and r["problem"] == problem]
            if rs:
                ax.scatter([max(r["min_scaled_jacobian"], 1e-4) for r in rs],
                           [r["solver_iterations"] for r in rs], s=14 + 0 * len(rs),
                           marker=markers[problem], color=COLOURS[method],
                           label=method if problem == "lshape" else None)
    ax.set_xscale("log")
    ax.set_xlabel("minimum scaled Jacobian of the mesh (values below 1e-4 drawn at 1e-4)")
    ax.set_ylabel("CG iterations (GAMG, rtol 1e-10)")
    ax.set_title("Solver iterations against mesh quality (o lshape, s rockerarm, ^ fichera)",
                 fontsize=10)
    ax.grid(True, which="both", linewidth=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    tmp = str(path) + ".tmp.png"
    fig.savefig(tmp, dpi=100)
    plt.close(fig)
    os.replace(tmp, path)


def render_levels(mesh_file, path, title, elev, azim):
    """The boundary quads of a saved mesh coloured by refinement level (render_mesh.py's
    boundary extraction)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import meshio
    import numpy as np
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    import render_mesh

    mesh = meshio.read(mesh_file)
    hexes, level = render_mesh.hexes_and_field(mesh, "level")
    quads, owner = render_mesh.boundary_quads(hexes)
    points = np.asarray(mesh.points, dtype=float)
    levels = level[owner].astype(int)
    cmap = plt.get_cmap("viridis", max(int(levels.max()) + 1, 2))
    fig = plt.figure(figsize=(7, 6))
    ax = fig.add_subplot(111, projection="3d")
    ax.add_collection3d(Poly3DCollection(points[quads], facecolors=cmap(levels),
                                         edgecolors="#303030", linewidths=0.1))
    lo, hi = points.min(axis=0), points.max(axis=0)
    centre, half = (lo + hi) / 2, (hi - lo).max() / 2
    for setter, c in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre):
        setter(c - half, c + half)
    ax.set_box_aspect((1, 1, 1))
    ax.view_init(elev=elev, azim=azim)
    ax.set_axis_off()
    mappable = plt.cm.ScalarMappable(cmap=cmap, norm=plt.Normalize(-0.5, cmap.N - 0.5))
    fig.colorbar(mappable, ax=ax, shrink=0.6, ticks=range(cmap.N), label="refinement level")
    ax.set_title(title, fontsize=10)
    fig.tight_layout()
    tmp = str(path) + ".tmp.png"
    fig.savefig(tmp, dpi=110)
    plt.close(fig)
    os.replace(tmp, path)


# --- report ---------------------------------------------------------------------------------------

def reference_uniform(curves, budget):
    """The finest uniform step within `budget`, else uniform's finest (rockerarm: beyond it)."""
    rs = curves.get("uniform", [])
    inside = [r for r in rs if r["dofs"] <= budget]
    if len(inside) >= 2:
        return inside[-1]
    return rs[-1] if rs else None


def equal_error(curves, a, b):
    """(error, dofs of a, dofs of b) at the finest error both curves reach."""
    if a not in curves or b not in curves:
        return None
    error = max(min(r["error_h1"] for r in curves[a]), min(r["error_h1"] for r in curves[b]))
    da, db = dofs_at_error(curves[a], error), dofs_at_error(curves[b], error)
    if da is None or db is None:
        return None
    return error, da, db


def report(results, records, oracle, mpi, large, study, estimators):
    budget = study["max_dofs"]
    lines = []
    add = lines.append
    add("# Adaptive finite elements on hexrefine's meshes: error against DOFs")
    add("")
    add("Generated by `/usr/bin/python3 experiments/adaptive/study.py` (issue 30) from the records "
        "`adaptive.jsonl` (every problem and method, %s-DOF budget), `adaptive.oracle.jsonl`, "
        "`adaptive.mpi.jsonl`%s and `adaptive.study.json` (times, load, commit). One command per "
        "loop: `/usr/bin/python3 experiments/adaptive/run.py --problem P --methods M --max-dofs N "
        "--out OUT.jsonl [--save-meshes DIR]`." % (
            fmt(budget), ", `adaptive.large.jsonl`" if large else ""))
    add("")
    add("Study: %.0f s wall, %.0f s CPU (all processes), commit `%s`, %s; the 2-core machine was "
        "shared with other engineers' builds (load average %.1f at the start, %.1f at the end), "
        "so wall times are inflated: CPU seconds are the measure here." % (
            study["wall_seconds"], study["cpu_seconds"], study["commit"], study["date"],
            study["load_start"], study["load_end"]))
    add("")
    summary = {p: by_method(records, p) for p in PROBLEMS}

    # The answer.
    add("## The answer")
    add("")
    add(answer(summary, budget))
    add("")

    add("## Set-up")
    add("")
    add("- **Problems** (`experiments/adaptive/problems.py`), Dirichlet data from the exact "
        "solution on the whole boundary:")
    add("  - `lshape`: the thesis' L-shape as a PDE, ((-1,1)^2 minus the quadrant x > 0, y < 0) "
        "x (0,1), 192 hexes, u = r^(2/3) sin(2 theta/3), f = 0: the gradient is singular along "
        "the re-entrant edge. theta in [0, 3 pi/2], with nodes a rounding error inside the cut "
        "quadrant clamped to the nearer face (tested).")
    add("  - `rockerarm`: `rockerarm.mesh` (10,600 hexes, 12,751 nodes, minimum scaled Jacobian "
        "0.54), u = atan(2 (|x - c| - 30)), c = (25, 15, 0) outside the part: a spherical layer "
        "of width about 0.5 (hexes are about 1.3 across) cutting the arm obliquely, f = -Laplacian "
        "u in closed form.")
    add("  - `fichera`: the Fichera corner (-1,1)^3 minus [0,1)^3, 189 hexes, u = |x|^(1/2), "
        "f = -3/4 |x|^(-3/2): a point singularity at the re-entrant vertex.")
    add("- **Solve**: Q1 on the trilinear hexes (dolfinx 0.5.2), CG with one GAMG V-cycle, "
        "relative tolerance 1e-10; stiffness by 2x2x2 Gauss. Errors |u - u_h|_H1 and "
        "||u - u_h||_L2 against the exact solution: Gauss degree 6 (4 points a direction), and "
        "degree 20 (11 points) on the hexes touching the singular edge or vertex, where degree 6 "
        "underestimates the L-shape's H1 error by 2 % (0.1341 against 0.1368 on the first mesh; "
        "the issue's baselines were made with the former).")
    add("- **Estimate**: eta_K^2 = h_K^2 ||f + div grad u_h||_K^2 + 1/2 sum_F h_F ||[grad u_h . "
        "n]||_F^2 over the interior faces F of K, with h_K = |K|^(1/3) (the cube root of the "
        "hex's volume) and h_F the mean of h_K over the two hexes sharing F. div grad u_h is "
        "computed exactly (UFL differentiates through the trilinear map's inverse Jacobian): on "
        "hexes that are not boxes a Q1 function's Laplacian is not zero. Estimate = (sum "
        "eta_K^2)^(1/2); effectivity = estimate / H1 error. Variants (the hex's diameter as "
        "h_K; no div grad u_h) below.")
    add("- **Mark**: Doerfler, theta = 0.3: the fewest hexes whose eta_K^2 sum to 30 % of the "
        "total, plus the hexes tied with the last one (to 1e-6 relative: symmetric hexes together, "
        "the same marks on 1 and 2 ranks).")
    add("- **Refine**: `hexrefine.refine` (default placement `optimized` unless the method says "
        "otherwise). A mesh whose DOFs exceed the budget is not solved; the loop also ends when "
        "hexrefine refuses a refinement.")
    add("  - *graded* (`selective`, `sheet`, `selective-trilinear`, `selective-smooth`; "
        "`experiments/adaptive/hierarchy.py`): the marks are kept as points with the level they "
        "want, and the mesh is rebuilt from the initial one level by level, T_l = C_1 + ring(C_2) "
        "+ ring(ring(C_3)) (C_j: the level-l full children holding a mark that wants j more "
        "levels; ring: the hexes sharing a node): every level's transitions then sit in full "
        "1-27 children of the level before, so a transition is never split by a transition "
        "again; a marked transition hex refines its regular parent (red-green's rule). Levels "
        "whose targets did not change are reused.")
    add("  - *direct* (`selective-direct`, `sheet-direct`): the marked hexes of the current mesh "
        "are refined as they are, the loop as the issue first wrote it; transitions are refined "
        "by transitions again.")
    add("  - `selective-trilinear`: the thesis' trilinear placement; `selective-smooth`: the "
        "`untangle` placement then smoothing (the better start, results/smooth_start.md); "
        "`uniform`: every hex 1-27 (the `all` selection).")
    add("- Rates: least-squares slopes of log(H1 error) against log(DOFs) over a loop's last four "
        "steps (uniform: its last three). The optimal Q1 rate in DOFs is 1/3 (h ~ DOFs^(-1/3)).")
    add("")

    add("## Targets")
    add("")
    add(targets_table(summary, large, study, records, budget))
    add("")

    for problem in PROBLEMS:
        curves = summary[problem]
        reference = reference_uniform(curves, budget)
        add("## %s" % problem)
        add("")
        add("![%s: error against DOFs](adaptive.%s.png)" % (problem, problem))
        add("")
        if reference:
            add("Reference: uniform's finest mesh%s, %s DOFs, H1 error %s. *reaches it*: the first "
                "step at or below that error (DOFs, and as a fraction of uniform's)." % (
                    " (beyond the budget: uniform's first refinement is above it)"
                    if reference["dofs"] > budget else " within the budget",
                    fmt(reference["dofs"]), fmt(reference["error_h1"])))
            add("")
        add("| method | steps | final DOFs | final H1 error | rate | reaches uniform's finest "
            "error at | min scaled Jacobian | CG its | all valid | effectivity | CPU s solve / "
            "estimate / mark / refine | end |")
        add("|---|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---|")
        for row in summary_rows_for(curves, reference):
            add(row)
        add("")
        add("At equal error (log-log interpolation at the finest error both reach):")
        add("")
        add("| pair | H1 error | DOFs | DOFs | ratio |")
        add("|---|---:|---:|---:|---:|")
        for a, b in (("sheet", "selective"), ("uniform", "selective"), ("uniform", "sheet"),
                     ("selective-trilinear", "selective"), ("selective-smooth", "selective"),
                     ("selective-direct", "selective"), ("sheet-direct", "sheet")):
            e = equal_error(curves, a, b)
            if e:
                add("| %s / %s | %s | %s | %s | %s |" % (a, b, fmt(e[0]), fmt(int(round(e[1]))),
                                                         fmt(int(round(e[2]))),
                                                         fmt(e[1] / e[2])))
        add("")
        add(growth_sentence(curves, problem))
        add("")
        picture = results / ("adaptive.%s.mesh.png" % problem)
        if picture.exists():
            add("![%s: the selective loop's last mesh](%s)" % (problem, picture.name))
            add("")

    add("## Solver iterations against mesh quality")
    add("")
    add("![CG iterations against minimum scaled Jacobian](adaptive.iterations.png)")
    add("")
    add("| problem | method | min scaled Jacobian (first .. last step) | CG iterations (first .. "
        "last) |")
    add("|---|---|---|---|")
    for problem in PROBLEMS:
        for method in METHODS:
            rs = summary[problem].get(method)
            if rs:
                add("| %s | %s | %s .. %s | %d .. %d |" % (
                    problem, method, fmt(rs[0]["min_scaled_jacobian"]),
                    fmt(rs[-1]["min_scaled_jacobian"]), rs[0]["solver_iterations"],
                    rs[-1]["solver_iterations"]))
    add("")

    add("## MPI: `mpirun -n 2`")
    add("")
    add(mpi_section(records, mpi))
    add("")

    add("## Estimator variants")
    add("")
    add(estimator_section(records, estimators))
    add("")

    add("## The issue's baselines, reproduced")
    add("")
    add(oracle_section(oracle))
    add("")

    if large:
        add("## Larger budget (4,000,000 DOFs, `study.py --large`)")
        add("")
        add(large_section(large))
        add("")

    add("## Every step")
    add("")
    add("| problem | method | step | hexes | DOFs | H1 error | L2 error | estimate | effectivity | "
        "min SJ | CG its | marked | valid | CPU s solve / estimate / mark / refine |")
    add("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---|")
    for problem in PROBLEMS:
        for method in METHODS:
            for r in summary[problem].get(method, []):
                add("| %s | %s | %d | %s | %s | %s | %s | %s | %s | %s | %d | %s | %s | %s |" % (
                    problem, method, r["step"], fmt(r["hexes"]), fmt(r["dofs"]),
                    fmt(r["error_h1"], 4), fmt(r["error_l2"], 4), fmt(r["estimate"], 4),
                    fmt(r["effectivity"], 3), fmt(r["min_scaled_jacobian"]),
                    r["solver_iterations"], fmt(r["marked"]), fmt(r["valid"]),
                    " / ".join("%.2f" % r["cpu_seconds"][p] for p in PHASES)))
    add("")
    return "\n".join(lines)


def summary_rows_for(curves, reference):
    rows = []
    for method in METHODS:
        rs = curves.get(method)
        if not rs:
            continue
        last = rs[-1]
        reached = first_step_at_error(rs, reference["error_h1"]) if reference else None
        end = ("refused at step %d" % last["step"] if "refine_error" in last else
               "budget (next %s)" % fmt(last["next_dofs"]))
        effectivity = [r["effectivity"] for r in rs]
        rows.append("| %s | %d | %s | %s | %s | %s | %s | %s | %s | %s..%s | %s | %s |" % (
            method, len(rs), fmt(last["dofs"]), fmt(last["error_h1"]),
            fmt(rate(rs, 3 if method == "uniform" else 4)),
            "%s (%s x)" % (fmt(reached["dofs"]), fmt(reached["dofs"] / reference["dofs"]))
            if reached else "not reached",
            fmt(min(r["min_scaled_jacobian"] for r in rs)),
            "%d..%d" % (min(r["solver_iterations"] for r in rs),
                        max(r["solver_iterations"] for r in rs)),
            fmt(all(r["valid"] for r in rs)), fmt(min(effectivity), 2), fmt(max(effectivity), 2),
            " / ".join("%.1f" % cpu(rs, p) for p in PHASES), end))
    return rows


def growth_sentence(curves, problem):
    parts = []
    for method in ("uniform", "selective", "sheet"):
        rs = curves.get(method)
        if not rs:
            continue
        factors = [b["dofs"] / a["dofs"] for a, b in zip(rs, rs[1:])]
        if rs[-1].get("next_dofs"):
            factors.append(rs[-1]["next_dofs"] / rs[-1]["dofs"])
        if factors:
            parts.append("%s %s" % (method, ", ".join("%.1f" % f for f in factors)))
    return ("DOF growth per step (the last one the refinement that ended the loop at the budget): "
            + "; ".join(parts) + ".")


def targets_table(summary, large, study, records, budget):
    lshape = summary["lshape"]
    reference = reference_uniform(lshape, budget)
    rows = ["| target | measured | met |", "|---|---|---|"]
    sel = lshape.get("selective", [])
    reached = first_step_at_error(sel, reference["error_h1"]) if reference else None
    if reached:
        ratio = reached["dofs"] / reference["dofs"]
        interpolated = dofs_at_error(sel, reference["error_h1"]) / reference["dofs"]
        rows.append("| lshape, residual estimator: selective reaches uniform's finest error "
                    "(%s DOFs, %s) with <= 0.35 x its DOFs | %s DOFs at step %d: %s x "
                    "(interpolated %s x) | %s |" % (
                        fmt(reference["dofs"]), fmt(reference["error_h1"]), fmt(reached["dofs"]),
                        reached["step"], fmt(ratio), fmt(interpolated), fmt(ratio <= 0.35)))
    if large:
        curves = by_method(large, "lshape")
        uni, lsel = curves.get("uniform", []), curves.get("selective", [])
        if uni and lsel:
            hit = first_step_at_error(lsel, uni[-1]["error_h1"])
            rows.append("| 4,000,000-DOF budget: <= 0.2 x uniform's DOFs | uniform %s DOFs, "
                        "error %s; selective %s | %s |" % (
                            fmt(uni[-1]["dofs"]), fmt(uni[-1]["error_h1"]),
                            "%s DOFs: %s x" % (fmt(hit["dofs"]), fmt(hit["dofs"] /
                                                                      uni[-1]["dofs"]))
                            if hit else "not reached", fmt(bool(hit) and hit["dofs"] /
                                                           uni[-1]["dofs"] <= 0.2)))
    else:
        rows.append("| 4,000,000-DOF budget: <= 0.2 x uniform's DOFs | not in the default study "
                    "(`study.py --large`) | - |")
    r = rate(sel)
    rows.append("| lshape selective: fitted rate >= 0.27 (last four steps; optimal 1/3) | %s | "
                "%s |" % (fmt(r), fmt(r is not None and r >= 0.27)))
    ratios = []
    for problem in PROBLEMS:
        e = equal_error(summary[problem], "sheet", "selective")
        if e:
            ratios.append("%s %s" % (problem, fmt(e[1] / e[2])))
    rows.append("| sheet / selective DOF ratio at equal error is reported | %s | yes |" %
                ", ".join(ratios))
    invalid = [r for r in records if not r["valid"]]
    refused = [r for r in records if "refine_error" in r]
    rows.append("| every mesh in every loop is valid | %d meshes, %d invalid; refinements "
                "refused: %s | %s |" % (
                    len(records), len(invalid),
                    ", ".join("%s %s step %d" % (r["problem"], r["method"], r["step"])
                              for r in refused) or "none", fmt(not invalid)))
    rows.append("| default study in <= 15 minutes on the 2-core machine | %.0f s wall (%d "
                "processes at a time, load average %.1f at the start), %.0f s CPU | %s |" % (
                    study["wall_seconds"], study["jobs"], study.get("load_start", float("nan")),
                    study["cpu_seconds"], fmt(study["wall_seconds"] <= 900)))
    return "\n".join(rows)


def answer(summary, budget):
    """The paragraphs answering the issue's question, every number from the records."""
    out = []
    sentences = []
    for problem in PROBLEMS:
        curves = summary[problem]
        reference = reference_uniform(curves, budget)
        if not reference:
            continue
        parts = []
        for method in ("selective", "sheet"):
            rs = curves.get(method, [])
            hit = first_step_at_error(rs, reference["error_h1"])
            if hit:
                parts.append("%s with %s DOFs (%s x)" % (method, fmt(hit["dofs"]),
                                                         fmt(hit["dofs"] / reference["dofs"])))
            elif rs:
                interpolated = dofs_at_error(curves["uniform"], rs[-1]["error_h1"])
                parts.append("%s not within the budget (its last mesh, %s DOFs, has %s, which "
                             "uniform refinement would need about %s DOFs for)" % (
                                 method, fmt(rs[-1]["dofs"]), fmt(rs[-1]["error_h1"]),
                                 fmt(int(round(interpolated, -3))) if interpolated else "-"))
        e = equal_error(curves, "sheet", "selective")
        sentences.append("on `%s` uniform refinement's finest error, %s at %s DOFs%s, is reached "
                         "by %s%s" % (
                             problem, fmt(reference["error_h1"]), fmt(reference["dofs"]),
                             " (beyond the budget)" if reference["dofs"] > budget else "",
                             " and ".join(parts),
                             "; at the finest error both reach (%s) sheet refinement needs %s x "
                             "selective's DOFs" % (fmt(e[0]), fmt(e[1] / e[2])) if e else ""))
    out.append("**For the same accuracy**: " + "; ".join(sentences) + ".")

    graded = {m: [r for p in PROBLEMS for r in summary[p].get(m, [])]
              for m in ("selective", "sheet", "selective-trilinear", "selective-smooth")}
    all_graded = [r for rs in graded.values() for r in rs]
    direct = [r for p in PROBLEMS for m in ("selective-direct", "sheet-direct")
              for r in summary[p].get(m, [])]
    uniform = [r for p in PROBLEMS for r in summary[p].get("uniform", [])]
    if all_graded and direct and uniform:
        placement = []
        for problem in PROBLEMS:
            for m in ("selective-trilinear", "selective-smooth"):
                e = equal_error(summary[problem], m, "selective")
                if e:
                    placement.append("%s %s %s x" % (problem, m, fmt(e[1] / e[2])))
        worst = {p: min((r["min_scaled_jacobian"] for m in graded for r in
                         summary[p].get(m, [])), default=None) for p in PROBLEMS}
        out.append(
            "**Transition elements**, each made once inside a full child of the level before (the "
            "graded loops), cost neither iterations nor accuracy that the numbers show: the "
            "minimum scaled Jacobian stays at or above %s (%s), CG needs %d to %d iterations "
            "(uniform: %d to %d, growing with the mesh alone), the effectivity index stays "
            "between %s and %s, and placements that change the transitions' quality change the "
            "DOFs needed for an error by a few percent (at equal error, against the default "
            "placement: %s)." % (
                fmt(min(r["min_scaled_jacobian"] for r in all_graded)),
                ", ".join("%s %s" % (p, fmt(v)) for p, v in worst.items() if v is not None),
                min(r["solver_iterations"] for r in all_graded),
                max(r["solver_iterations"] for r in all_graded),
                min(r["solver_iterations"] for r in uniform),
                max(r["solver_iterations"] for r in uniform),
                fmt(min(r["effectivity"] for r in all_graded), 2),
                fmt(max(r["effectivity"] for r in all_graded), 2), ", ".join(placement)))
        refused = sorted({"%s %s" % (r["problem"], r["method"]) for r in direct
                          if "refine_error" in r})
        ratios, more = [], 0
        for problem in PROBLEMS:
            for a, b in (("selective-direct", "selective"), ("sheet-direct", "sheet")):
                e = equal_error(summary[problem], a, b)
                if e:
                    ratios.append("%s %s %s x" % (problem, a, fmt(e[1] / e[2])))
                    more += e[1] > e[2]
        lshape_direct = summary["lshape"].get("selective-direct", [])
        lshape_graded = summary["lshape"].get("selective", [])
        out.append(
            "What does cost is splitting transitions by transitions again, which refining the "
            "marked hexes of the current mesh as they are does (the direct loops, the loop as the "
            "issue first wrote it): the minimum scaled Jacobian falls to %s, CG needs up to %d "
            "iterations, on `lshape` the effectivity index of the direct selective loop rises to "
            "%s (graded: at most %s), and at equal error the direct loops need more DOFs than "
            "their graded counterparts in %d of %d cases (%s)%s." % (
                fmt(min(r["min_scaled_jacobian"] for r in direct)),
                max(r["solver_iterations"] for r in direct),
                fmt(max((r["effectivity"] for r in lshape_direct), default=None), 2),
                fmt(max((r["effectivity"] for r in lshape_graded), default=None), 2),
                more, len(ratios), ", ".join(ratios) or "-",
                "; hexrefine refused a refinement in " + ", ".join(refused) if refused else ""))

    growth = []
    for problem in PROBLEMS:
        rs = summary[problem].get("sheet", [])
        uni = summary[problem].get("uniform", [])
        if not rs or not uni:
            continue
        steps = [(b["dofs"] / a["dofs"], a["step"]) for a, b in zip(rs, rs[1:])]
        if rs[-1].get("next_dofs"):
            steps.append((rs[-1]["next_dofs"] / rs[-1]["dofs"], rs[-1]["step"]))
        factor, step = max(steps)
        sel = summary[problem].get("selective", [])
        sel_steps = [b["dofs"] / a["dofs"] for a, b in zip(sel, sel[1:])]
        if sel and sel[-1].get("next_dofs"):
            sel_steps.append(sel[-1]["next_dofs"] / sel[-1]["dofs"])
        uniform_factor = uni[-1]["next_dofs"] / uni[-1]["dofs"] if uni[-1].get(
            "next_dofs") else None
        growth.append("on `%s` its largest step (the refinement of step %d) multiplies the DOFs "
                      "by %s where uniform refinement multiplies them by %s and selective by at "
                      "most %s" % (problem, step, fmt(factor), fmt(uniform_factor),
                                   fmt(max(sel_steps)) if sel_steps else "-"))
    if growth:
        out.append("**Where sheet refinement grows to near-uniform**: whole sheets follow the "
                   "marked hexes through the mesh, so the DOFs per step grow with the sheets' "
                   "length, not the marked region's size: " + "; ".join(growth) + ".")
    return "\n\n".join(out)


def mpi_section(records, mpi):
    if not mpi:
        return "Not run."
    serial = {(r["method"], r["step"]): r for r in records if r["problem"] == "lshape"}
    rows = ["The loop under `mpirun -n 2` (rank 0 holds the hexrefine mesh, marks and refines; "
            "dolfinx's partitioner redistributes every new mesh for the solve, the indicators "
            "return to rank 0 by hex id) against the serial records of the same methods:", "",
            "| method | steps (2 ranks / 1) | same DOFs every step | largest relative difference: "
            "H1 error | L2 error | estimate | CG iterations (2 ranks) |", "|---|---|---|---:|---:|"
            "---:|---|"]
    for method in ("uniform", "selective", "sheet"):
        rs = [r for r in mpi if r["method"] == method]
        pairs = [(r, serial.get((method, r["step"]))) for r in rs]
        pairs = [(a, b) for a, b in pairs if b is not None]
        if not pairs:
            continue
        count = len([r for r in records if r["problem"] == "lshape" and r["method"] == method])

        def worst(key):
            return max(abs(a[key] - b[key]) / abs(b[key]) for a, b in pairs)

        rows.append("| %s | %d / %d | %s | %.1e | %.1e | %.1e | %s |" % (
            method, len(rs), count, fmt(all(a["dofs"] == b["dofs"] for a, b in pairs)),
            worst("error_h1"), worst("error_l2"), worst("estimate"),
            ", ".join(str(a["solver_iterations"]) for a, _ in pairs)))
    return "\n".join(rows)


def estimator_section(records, estimators):
    rows = ["`lshape` to %s DOFs with h_K = |K|^(1/3) and div grad u_h (the default, the main "
            "study's records), h_K = the hex's diameter (largest vertex distance), and the element "
            "residual without div grad u_h (`adaptive.estimators.jsonl`):" % fmt(ESTIMATOR_BUDGET),
            "", "| estimator | method | steps | last DOFs | last H1 error | DOFs for H1 error %s | "
            "effectivity | min scaled Jacobian |" % fmt(ESTIMATOR_ERROR),
            "|---|---|---:|---:|---:|---:|---|---:|"]
    variants = [("volume, with div grad u_h", [r for r in records if r["problem"] == "lshape"]),
                ("diameter, with div grad u_h", [r for r in estimators
                                                 if r["estimator_size"] == "diameter"]),
                ("volume, without div grad u_h", [r for r in estimators
                                                  if not r["estimator_laplacian"]])]
    for name, rs in variants:
        for method in ("selective", "selective-direct"):
            curve = sorted([r for r in rs if r["method"] == method and
                            r["dofs"] <= ESTIMATOR_BUDGET], key=lambda r: r["step"])
            if not curve:
                continue
            at = dofs_at_error(curve, ESTIMATOR_ERROR)
            rows.append("| %s | %s | %d | %s | %s | %s | %s..%s | %s |" % (
                name, method, len(curve), fmt(curve[-1]["dofs"]), fmt(curve[-1]["error_h1"]),
                fmt(int(round(at))) if at else "not reached",
                fmt(min(r["effectivity"] for r in curve), 2),
                fmt(max(r["effectivity"] for r in curve), 2),
                fmt(min(r["min_scaled_jacobian"] for r in curve))))
    return "\n".join(rows)


def oracle_section(oracle):
    if not oracle:
        return "Not run."
    rows = ["The issue's numbers against ours with its settings: the oracle indicator (the exact "
            "H1 error per hex), Doerfler 0.3, the direct loop, default placement, degree-6 "
            "quadrature everywhere.", "",
            "| loop | DOFs (issue) | DOFs (here) | H1 error (issue) | H1 error (here) |",
            "|---|---|---|---|---|"]
    for method, (dofs, errors) in BASELINES.items():
        rs = [r for r in oracle if r["method"] == method]
        rows.append("| %s | %s | %s | %s | %s |" % (
            method, " / ".join(fmt(d) for d in dofs), " / ".join(fmt(r["dofs"]) for r in rs),
            " / ".join(fmt(e) for e in errors), " / ".join(fmt(r["error_h1"]) for r in rs)))
    rs = [r for r in oracle if r["method"] == "selective-direct"]
    if rs:
        rows.append("")
        rows.append("The oracle's direct selective loop: minimum scaled Jacobian %s, CG "
                    "iterations %s.%s" % (
                        " / ".join(fmt(r["min_scaled_jacobian"]) for r in rs),
                        " / ".join(str(r["solver_iterations"]) for r in rs),
                        " Its last refinement was refused: " + rs[-1]["refine_error"][:160]
                        if "refine_error" in rs[-1] else ""))
    return "\n".join(rows)


def large_section(large):
    curves = by_method(large, "lshape")
    commits = sorted({r.get("commit", "unknown") for r in large})
    rows = ["Run on its own (`study.py --large`, not part of the default study; records from "
            "commit %s): lshape, uniform and selective, to 4,000,000 DOFs." % ", ".join(commits),
            "", "| method | step | DOFs | H1 error | min SJ | CG its | CPU s solve / estimate / "
            "mark / refine |", "|---|---:|---:|---:|---:|---:|---|"]
    for method, rs in curves.items():
        for r in rs:
            rows.append("| %s | %d | %s | %s | %s | %d | %s |" % (
                method, r["step"], fmt(r["dofs"]), fmt(r["error_h1"], 4),
                fmt(r["min_scaled_jacobian"]), r["solver_iterations"],
                " / ".join("%.1f" % r["cpu_seconds"][p] for p in PHASES)))
    uni, sel = curves.get("uniform", []), curves.get("selective", [])
    if uni and sel:
        hit = first_step_at_error(sel, uni[-1]["error_h1"])
        rows.append("")
        rows.append("Uniform's finest error here, %s at %s DOFs, is reached by selective %s; "
                    "selective's rate over its last four steps: %s (uniform's last three: %s)." % (
                        fmt(uni[-1]["error_h1"]), fmt(uni[-1]["dofs"]),
                        "at step %d with %s DOFs (%s x)" % (hit["step"], fmt(hit["dofs"]),
                                                           fmt(hit["dofs"] / uni[-1]["dofs"]))
                        if hit else "not within the budget", fmt(rate(sel)), fmt(rate(uni, 3))))
    return "\n".join(rows)


# --- main -----------------------------------------------------------------------------------------

def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--max-dofs", type=int, default=200000)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--large", action="store_true")
    parser.add_argument("--results", default=str(ROOT / "results"))
    parser.add_argument("--work", default=str(ROOT / "build" / "adaptive"))
    parser.add_argument("--report-only", action="store_true")
    args = parser.parse_args()
    results, work = pathlib.Path(args.results), pathlib.Path(args.work)
    results.mkdir(parents=True, exist_ok=True)
    work.mkdir(parents=True, exist_ok=True)

    if not args.report_only:
        start, load_start = time.perf_counter(), os.getloadavg()[0]
        jobs = jobs_of(args, work)
        seconds = run_jobs(jobs, args.jobs, work)
        usage = resource.getrusage(resource.RUSAGE_CHILDREN)
        records = []
        for problem in PROBLEMS:
            for method in METHODS:
                records += read_jsonl(work / ("%s.%s.jsonl" % (problem, method)))
        write_jsonl(results / "adaptive.jsonl", records)
        write_jsonl(results / "adaptive.oracle.jsonl", read_jsonl(work / "oracle.jsonl"))
        write_jsonl(results / "adaptive.estimators.jsonl",
                    read_jsonl(work / "estimator.diameter.jsonl") +
                    read_jsonl(work / "estimator.no-laplacian.jsonl"))
        write_jsonl(results / "adaptive.mpi.jsonl", read_jsonl(work / "mpi.jsonl"))
        if args.large:
            write_jsonl(results / "adaptive.large.jsonl", read_jsonl(work / "large.jsonl"))
        commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"],
                                capture_output=True, text=True).stdout.strip()
        study = {"max_dofs": args.max_dofs, "jobs": args.jobs, "large": args.large,
                 "wall_seconds": time.perf_counter() - start,
                 "cpu_seconds": usage.ru_utime + usage.ru_stime,
                 "load_start": load_start, "load_end": os.getloadavg()[0],
                 "commit": commit or "unknown", "date": time.strftime("%Y-%m-%d"),
                 "job_wall_seconds": seconds}
        write_atomic(results / "adaptive.study.json", json.dumps(study, indent=1) + "\n")
        # The pictures: the last mesh of the selective loops that saved theirs.
        for problem, view in (("lshape", (25, -45)), ("rockerarm", (20, -60))):
            rs = [r for r in records if r["problem"] == problem and r["method"] == "selective"]
            if rs and rs[-1].get("mesh_file"):
                render_levels(ROOT / rs[-1]["mesh_file"], results / ("adaptive.%s.mesh.png" % problem),
                              "%s, selective (graded), step %d: %s hexes, refinement level" % (
                                  problem, rs[-1]["step"], fmt(rs[-1]["hexes"])), *view)

    records = read_jsonl(results / "adaptive.jsonl")
    oracle = read_jsonl(results / "adaptive.oracle.jsonl")
    estimators = read_jsonl(results / "adaptive.estimators.jsonl")
    mpi = read_jsonl(results / "adaptive.mpi.jsonl")
    large_path = results / "adaptive.large.jsonl"
    large = read_jsonl(large_path) if large_path.exists() else []
    with open(results / "adaptive.study.json") as f:
        study = json.load(f)
    for problem in PROBLEMS:
        plot_errors(records, problem, results / ("adaptive.%s.png" % problem))
    plot_iterations(records, results / "adaptive.iterations.png")
    write_atomic(results / "adaptive.md", report(results, records, oracle, mpi, large, study, estimators))
    print("wrote %s" % (results / "adaptive.md"))


if __name__ == "__main__":
    main()
