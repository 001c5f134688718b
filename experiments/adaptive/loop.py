"""The adaptive loop SOLVE -> ESTIMATE -> MARK -> REFINE over hexrefine's conformal refinement, and
the refinement variants the study compares.

One step on the current mesh: solve (poisson.solve, with the transfer to dolfinx), estimate (the
residual indicators eta_K^2, or the exact error per hex for the oracle), measure the true errors,
mark (Doerfler bulk marking: the fewest hexes whose indicators sum to theta of the total; or a fixed
fraction of the hexes, largest indicators first), refine with hexrefine: uniform every hex (the
`all` selection); graded variants rebuild the mesh by levels for the marks so far (hierarchy.py);
direct variants refine the marked hexes of the current mesh. The loop ends when the refined mesh has more DOFs than the budget
(it is not solved), when hexrefine refuses a refinement, or after max_steps steps.

Under MPI every rank runs the loop: the hexrefine mesh lives on rank 0, which marks and refines
(hexrefine is a serial library); dolfinx redistributes each new mesh for the solve and the
indicators come back to rank 0 by hex id. Only rank 0 gets records.
"""

import dataclasses
import gc
import os
import time

import numpy as np

import hexrefine
import hierarchy
import poisson

#: The refinement variants: hexrefine.refine's method and options, whether every hex is a target
#: (uniform) and whether the mesh is rebuilt by levels (hierarchy.py; graded) or the marked hexes
#: of the current mesh are refined (direct: the loop as first specified, whose transitions are
#: refined by transitions again). 'selective-smooth' starts the smoothing from the untangle
#: placement, the better start measured in results/smooth_start.md.
VARIANTS = {
    "uniform": {"method": "selective", "uniform": True},
    "selective": {"method": "selective", "graded": True},
    "sheet": {"method": "sheet", "graded": True},
    "selective-trilinear": {"method": "selective", "placement": "trilinear", "graded": True},
    "selective-smooth": {"method": "selective", "placement": "untangle", "smooth": True,
                         "graded": True},
    "selective-direct": {"method": "selective", "graded": False},
    "sheet-direct": {"method": "sheet", "graded": False},
}


@dataclasses.dataclass
class LoopOptions:
    """max_dofs: the budget (a mesh with more DOFs is not solved); marking: 'doerfler' (theta) or
    'fraction' (fraction); estimator: 'residual' or 'oracle' (the exact error per hex);
    placement/smooth: hexrefine.refine's, for variants that do not set their own (None: the
    library's default placement); save_meshes: a folder for every step's mesh (.vtu)."""
    max_dofs: int = 200000
    max_steps: int = 50
    marking: str = "doerfler"
    theta: float = 0.3
    fraction: float = 0.1
    estimator: str = "residual"
    placement: str = None
    smooth: bool = False
    save_meshes: str = None


def mark_doerfler(indicators, theta, tie=1e-6):
    """The fewest hex ids (ascending) whose indicators (eta_K^2, >= 0) sum to at least theta (in
    (0, 1]) of the total, the largest first, plus every hex whose indicator is within `tie`
    (relative) of the smallest one taken: hexes equal by symmetry are marked together, and a
    solve on 2 ranks (indicators equal to solver tolerance) marks the same hexes as on one."""
    if not 0.0 < theta <= 1.0:
        raise ValueError("theta must be in (0, 1], got %r" % theta)
    order = np.argsort(-indicators, kind="stable")
    cumulative = np.cumsum(indicators[order])
    count = int(np.searchsorted(cumulative, theta * cumulative[-1] * (1 - 1e-14))) + 1
    cut = indicators[order[min(count, len(order)) - 1]]
    return np.flatnonzero(indicators >= cut * (1 - tie))


def mark_fraction(indicators, fraction):
    """The ceil(fraction x count) hex ids (ascending) with the largest indicators."""
    if not 0.0 < fraction <= 1.0:
        raise ValueError("fraction must be in (0, 1], got %r" % fraction)
    count = int(np.ceil(fraction * len(indicators)))
    return np.sort(np.argsort(-indicators, kind="stable")[:count])


def dofs_of(mesh, degree):
    """The Q1 or Q2 DOF count of a hexrefine mesh (every node, boundary included): nodes, plus
    for Q2 one per edge, face and hex."""
    if degree == 1:
        return mesh.point_count
    hexes = mesh.hexes.astype(np.int64)
    edges = hexes[:, [0, 1, 2, 3, 4, 5, 6, 7, 0, 1, 2, 3]], hexes[:, [1, 2, 3, 0, 5, 6, 7, 4, 4,
                                                                      5, 6, 7]]
    edge_keys = np.sort(np.stack([edges[0].ravel(), edges[1].ravel()], axis=1), axis=1)
    faces = hexes[:, [0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4, 1, 2, 6, 5, 2, 3, 7, 6, 3, 0, 4, 7]]
    face_keys = np.sort(faces.reshape(-1, 4), axis=1)
    return (mesh.point_count + len(np.unique(edge_keys, axis=0)) +
            len(np.unique(face_keys, axis=0)) + mesh.hex_count)


class _Clock:
    """Wall and process CPU seconds of named phases (CPU: this process, all its threads)."""

    def __init__(self):
        self.wall, self.cpu = {}, {}

    def start(self):
        self._wall, self._cpu = time.perf_counter(), time.process_time()

    def stop(self, name):
        self.wall[name] = self.wall.get(name, 0.0) + time.perf_counter() - self._wall
        self.cpu[name] = self.cpu.get(name, 0.0) + time.process_time() - self._cpu


def _refine_options(variant, options):
    spec = VARIANTS[variant]
    kwargs = {"method": spec["method"]}
    placement = spec.get("placement", options.placement)
    if placement is not None:
        kwargs["placement"] = placement
    kwargs["smooth"] = spec.get("smooth", options.smooth)
    return kwargs


def run_loop(comm, problem, variant, options=LoopOptions(), solver=poisson.SolverOptions(),
             on_record=None):
    """Runs the adaptive loop of `variant` (a key of VARIANTS) on `problem` on every rank of
    `comm`; returns the records (rank 0; other ranks get []) and calls on_record(record) on rank
    0 after each step. The record keys are listed in run.py's doc."""
    if variant not in VARIANTS:
        raise ValueError("unknown method '%s' (one of %s)" % (variant, ", ".join(VARIANTS)))
    root = comm.rank == 0
    refine_kwargs = _refine_options(variant, options)
    uniform = VARIANTS[variant].get("uniform", False)
    mesh, check, graded = None, None, None
    if root:
        mesh = problem.initial_mesh()
        check = hexrefine.check(mesh)
        if VARIANTS[variant].get("graded", False):
            graded = hierarchy.GradedRefinement(mesh, refine_kwargs)
    records = []
    for step in range(options.max_steps):
        clock = _Clock()
        clock.start()
        dmesh = poisson.mesh_to_dolfinx(comm, mesh.points if root else None,
                                        mesh.hexes if root else None)
        solution = poisson.solve(dmesh, problem, solver)
        clock.stop("solve")

        clock.start()
        if options.estimator == "oracle":
            local = poisson.cell_errors(solution, problem, solver)
        else:
            local = poisson.indicators(solution, problem, solver)
        eta2 = poisson.gather_by_original_cell(dmesh, local, mesh.hex_count if root else 0)
        clock.stop("estimate")

        clock.start()
        error_h1, error_l2 = poisson.errors(solution, problem, solver)
        cell_error = None
        if options.save_meshes:
            cell_error = (eta2 if options.estimator == "oracle" else
                          poisson.gather_by_original_cell(
                              dmesh, poisson.cell_errors(solution, problem, solver),
                              mesh.hex_count if root else 0))
        clock.stop("error")

        record, stop, next_mesh, next_check = None, True, None, None
        if root:
            clock.start()
            if uniform:
                marked = np.arange(mesh.hex_count)
            elif options.marking == "fraction":
                marked = mark_fraction(eta2, options.fraction)
            else:
                marked = mark_doerfler(eta2, options.theta)
            clock.stop("mark")

            clock.start()
            refine_error, levels = None, None
            hex_levels = graded.current.level if graded is not None else None
            try:
                if graded is not None:
                    graded.mark(marked)
                    next_mesh, report, levels, _ = graded.rebuild()
                else:
                    next_mesh, report = hexrefine.refine(mesh, "all" if uniform else marked,
                                                         **refine_kwargs)
                next_check = report["check"]
            except hexrefine.RefinementError as e:
                refine_error = str(e)
            clock.stop("refine")

            estimate = float(np.sqrt(eta2.sum()))
            record = {
                "problem": problem.name,
                "method": variant,
                "step": step,
                "hexes": mesh.hex_count,
                "dofs": solution.dofs,
                "error_h1": error_h1,
                "error_l2": error_l2,
                "estimate": estimate,
                "effectivity": estimate / error_h1 if error_h1 > 0 else None,
                "min_scaled_jacobian": check["min_scaled_jacobian"],
                "mean_scaled_jacobian": check["mean_scaled_jacobian"],
                "valid": bool(check["valid"]),
                "solver_iterations": solution.iterations,
                "marked": int(len(marked)),
                "graded": graded is not None,
                "level_targets": levels,
                "next_dofs": None if next_mesh is None else dofs_of(next_mesh, solver.degree),
                "seconds": {k: clock.wall.get(k, 0.0)
                            for k in ("solve", "estimate", "mark", "refine", "error")},
                "cpu_seconds": {k: clock.cpu.get(k, 0.0)
                                for k in ("solve", "estimate", "mark", "refine", "error")},
                "solve_seconds": solution.seconds,
                "refine_method": refine_kwargs["method"],
                "placement": refine_kwargs.get("placement", "default"),
                "smooth": refine_kwargs["smooth"],
                "estimator": options.estimator,
                "marking": ("uniform" if uniform else options.marking),
                "theta": options.theta if options.marking == "doerfler" else None,
                "fraction": options.fraction if options.marking == "fraction" else None,
                "degree": solver.degree,
                "pc": solver.pc,
                "rtol": solver.rtol,
                "quadrature_degree": [solver.quadrature_degree,
                                      solver.singular_quadrature_degree],
                "estimator_size": solver.estimator_size,
                "estimator_laplacian": solver.estimator_laplacian,
                "ranks": comm.size,
                "max_dofs": options.max_dofs,
            }
            if refine_error is not None:
                record["refine_error"] = refine_error
            if options.save_meshes:
                os.makedirs(options.save_meshes, exist_ok=True)
                path = os.path.join(options.save_meshes,
                                    "%s.%s.%02d.vtu" % (problem.name, variant, step))
                flags = np.zeros(mesh.hex_count)
                flags[marked] = 1.0
                fields = {"indicator": np.sqrt(eta2).tolist(),
                          "error_h1": np.sqrt(cell_error).tolist(), "marked": flags.tolist()}
                if hex_levels is not None:
                    fields["level"] = hex_levels.astype(float).tolist()
                elif uniform:
                    fields["level"] = [float(step)] * mesh.hex_count
                hexrefine.write(mesh, path, compress=True, cell_data=fields)
                record["mesh_file"] = path
            stop = (next_mesh is None or record["next_dofs"] > options.max_dofs)
            records.append(record)
            if on_record is not None:
                on_record(record)
        stop = comm.bcast(stop, root=0)
        # The step's dolfinx mesh, spaces and forms hold cycles; free them before the next
        # (larger) mesh is built rather than when the collector gets to them.
        del dmesh, solution
        gc.collect()
        if stop:
            break
        if root:
            mesh, check = next_mesh, next_check
    return records
