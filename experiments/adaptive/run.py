#!/usr/bin/python3
"""The adaptive finite-element loop SOLVE -> ESTIMATE -> MARK -> REFINE on dolfinx over hexrefine.

usage: /usr/bin/python3 experiments/adaptive/run.py --problem lshape
           --methods uniform,selective,sheet --max-dofs N --out OUT.jsonl [--save-meshes DIR]
           [--theta 0.3 | --fraction F] [--estimator residual|oracle] [--degree 1|2]
           [--pc gamg|hypre] [--rtol 1e-10] [--placement P] [--smooth] [--max-steps N]
           [--singular-quadrature-degree 20] [--estimator-size volume|diameter] [--no-laplacian]
       mpirun -n 2 /usr/bin/python3 experiments/adaptive/run.py ...   (the same, solved on 2 ranks)

Problems (problems.py): lshape, rockerarm, fichera, smooth. Methods (loop.py): uniform (every hex
1-27); selective, sheet, selective-trilinear, selective-smooth (untangle placement + smoothing),
each rebuilt by levels (hierarchy.py: graded, no transition split by a transition again); and
selective-direct, sheet-direct (the marked hexes of the current mesh refined as they are).
--placement and --smooth apply to the methods that do not set their own.

Writes one JSON record per (method, step) to OUT (a temporary file renamed at the end) with:
problem, method, step, hexes, dofs, error_h1 (|u - u_h|_H1), error_l2, estimate (the residual
estimator's (sum eta_K^2)^(1/2)), effectivity (estimate / error_h1), min_scaled_jacobian and
mean_scaled_jacobian (the mesh's, from hexrefine's checker), valid (the checker's verdict on the
mesh: the refinement report's check.valid), solver_iterations (CG), marked (hexes marked at this
step), level_targets (graded: the targets of each level's refinement), next_dofs (the DOFs of the
mesh the step's refinement made; above the budget the loop stops), seconds and cpu_seconds
(solve: transfer to dolfinx + assembly + CG; estimate; mark; refine: the refinement of this
step's marks; error: the true errors), solve_seconds, refine_method, placement, smooth,
estimator, marking, theta, fraction, degree, pc, rtol, quadrature_degree, ranks, max_dofs,
commit (this repository's),
mesh_file (with --save-meshes: the step's mesh as .vtu with the cell fields indicator, error_h1,
marked and, for graded and uniform methods, level), refine_error (when hexrefine refused the
refinement and the loop ended).
Prints a progress line per step. Exit 2 on bad usage, 1 if a solve or refinement fails.

hexrefine is imported from PYTHONPATH, else from the build tree (build/experiments/python).
"""

import argparse
import json
import os
import pathlib
import subprocess
import sys
import time

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
try:
    import hexrefine  # noqa: F401
except ImportError:
    sys.path.insert(0, str(HERE.parents[1] / "build" / "experiments" / "python"))
    try:
        import hexrefine  # noqa: F401,F811
    except ImportError:
        sys.stderr.write("run.py: cannot import hexrefine: build it (cmake --build build) or set "
                         "PYTHONPATH to build/experiments/python\n")
        sys.exit(2)

from mpi4py import MPI  # noqa: E402

import loop  # noqa: E402
import poisson  # noqa: E402
import problems  # noqa: E402


def parse_arguments(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--problem", required=True, choices=sorted(problems.PROBLEMS))
    parser.add_argument("--methods", default="uniform,selective,sheet",
                        help="comma-separated: " + ", ".join(loop.VARIANTS))
    parser.add_argument("--max-dofs", type=int, default=200000)
    parser.add_argument("--max-steps", type=int, default=50)
    parser.add_argument("--out", required=True, help="the records (JSONL)")
    parser.add_argument("--save-meshes", metavar="DIR")
    marking = parser.add_mutually_exclusive_group()
    marking.add_argument("--theta", type=float, default=0.3, help="Doerfler's bulk parameter")
    marking.add_argument("--fraction", type=float, help="mark this fraction of the hexes instead")
    parser.add_argument("--estimator", choices=["residual", "oracle"], default="residual")
    parser.add_argument("--degree", type=int, choices=[1, 2], default=1)
    parser.add_argument("--pc", choices=["gamg", "hypre"], default="gamg")
    parser.add_argument("--rtol", type=float, default=1e-10)
    parser.add_argument("--estimator-size", choices=["volume", "diameter"], default="volume",
                        help="h_K: |K|^(1/3) or the largest vertex distance")
    parser.add_argument("--no-laplacian", action="store_true",
                        help="drop div grad u_h from the element residual")
    parser.add_argument("--singular-quadrature-degree", type=int, default=20,
                        help="for the errors on the hexes touching the singular set (6: the "
                        "issue's baselines)")
    parser.add_argument("--placement", choices=["optimized", "trilinear", "untangle"])
    parser.add_argument("--smooth", action="store_true")
    args = parser.parse_args(argv)
    args.methods = [m for m in args.methods.split(",") if m]
    for m in args.methods:
        if m not in loop.VARIANTS:
            parser.error("unknown method '%s' (one of %s)" % (m, ", ".join(loop.VARIANTS)))
    if not args.methods:
        parser.error("--methods: no method given")
    if args.max_dofs < 1 or args.max_steps < 1:
        parser.error("--max-dofs and --max-steps must be positive")
    if not 0 < args.theta <= 1 or (args.fraction is not None and not 0 < args.fraction <= 1):
        parser.error("--theta and --fraction must be in (0, 1]")
    if not 0 < args.rtol < 1:
        parser.error("--rtol must be in (0, 1)")
    return args


def progress(record):
    print("%s %s step %d: %d hexes, %d dofs, H1 %.4g, L2 %.4g, estimate %.4g (eff %.2f), "
          "%d CG its, min SJ %.3f, %s, marked %d, %.1f s (cpu %.1f)" % (
              record["problem"], record["method"], record["step"], record["hexes"],
              record["dofs"], record["error_h1"], record["error_l2"], record["estimate"],
              record["effectivity"], record["solver_iterations"], record["min_scaled_jacobian"],
              "valid" if record["valid"] else "INVALID", record["marked"],
              sum(record["seconds"].values()), sum(record["cpu_seconds"].values())),
          flush=True)
    if "refine_error" in record:
        print("  refinement refused: " + record["refine_error"], flush=True)


def source_commit():
    """The repository's commit (short), for the records; 'unknown' outside a git checkout."""
    try:
        out = subprocess.run(["git", "-C", str(HERE), "rev-parse", "--short", "HEAD"],
                             capture_output=True, text=True, timeout=10)
        return out.stdout.strip() or "unknown"
    except (OSError, subprocess.SubprocessError):
        return "unknown"


def main(argv):
    args = parse_arguments(argv)
    comm = MPI.COMM_WORLD
    commit = source_commit() if comm.rank == 0 else None
    problem = problems.PROBLEMS[args.problem]
    options = loop.LoopOptions(max_dofs=args.max_dofs, max_steps=args.max_steps,
                               marking="fraction" if args.fraction else "doerfler",
                               theta=args.theta, fraction=args.fraction or 0.1,
                               estimator=args.estimator, placement=args.placement,
                               smooth=args.smooth, save_meshes=args.save_meshes)
    solver = poisson.SolverOptions(degree=args.degree, pc=args.pc, rtol=args.rtol,
                                   singular_quadrature_degree=args.singular_quadrature_degree,
                                   estimator_size=args.estimator_size,
                                   estimator_laplacian=not args.no_laplacian)
    temporary = "%s.tmp%d" % (args.out, os.getpid())
    out = None
    if comm.rank == 0:
        os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
        out = open(temporary, "w")

    def on_record(record):
        record["commit"] = commit
        out.write(json.dumps(record, sort_keys=True) + "\n")
        out.flush()
        progress(record)

    start = time.perf_counter()
    try:
        for method in args.methods:
            loop.run_loop(comm, problem, method, options, solver, on_record)
    except BaseException:
        if out is not None:
            out.close()
            os.unlink(temporary)
        raise
    if comm.rank == 0:
        out.close()
        os.replace(temporary, args.out)
        print("wrote %s (%.1f s)" % (args.out, time.perf_counter() - start), flush=True)
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv[1:]))
    except (RuntimeError, ValueError) as e:
        sys.stderr.write("run.py: %s\n" % e)
        sys.exit(1)
