"""Tests of experiments/adaptive/poisson.py: the Q1 rate under uniform refinement, the residual
estimator on a solution in the Q1 space, the transfer to dolfinx, and the L-shape's exact solution
at the nodes a rounding error off its faces."""

import math

import numpy as np
import pytest
import ufl
from mpi4py import MPI

import hexrefine
import poisson
import problems

COMM = MPI.COMM_WORLD


def solve_on(mesh, problem, options=poisson.SolverOptions()):
    return poisson.solve(poisson.mesh_to_dolfinx(COMM, mesh.points, mesh.hexes), problem, options)


def test_uniform_refinement_of_a_smooth_solution_converges_at_the_q1_rate():
    problem = problems.PROBLEMS["smooth"]
    mesh = problem.initial_mesh()
    h1, l2, dofs = [], [], []
    for _ in range(3):
        solution = solve_on(mesh, problem)
        e_h1, e_l2 = poisson.errors(solution, problem)
        h1.append(e_h1)
        l2.append(e_l2)
        dofs.append(solution.dofs)
        mesh, _ = hexrefine.refine(mesh, "all")
    assert dofs == [4**3, 10**3, 28**3]
    # A 1-27 step divides h by 3: the H1 error by 3 (Q1), the L2 error by 9.
    for coarse, fine in zip(h1, h1[1:]):
        assert coarse / fine == pytest.approx(3.0, rel=0.1)
    for coarse, fine in zip(l2, l2[1:]):
        assert coarse / fine == pytest.approx(9.0, rel=0.15)
    assert h1[0] == pytest.approx(0.5836, rel=1e-3)


def q1_problem(exact):
    return problems.Problem("q1", "a function of the Q1 space", lambda: None, exact, lambda x: 0.0)


@pytest.mark.parametrize("case", ["trilinear on a brick", "linear on graded transitions"])
def test_the_estimator_is_zero_for_a_solution_in_the_q1_space(case):
    if case == "trilinear on a brick":
        # 1, x, y, z, xy, yz, zx, xyz span Q1 on axis-aligned bricks; each is harmonic, so f = 0.
        mesh = problems.structured_hex_mesh([0, 0, 0], [2, 1, 1], [4, 3, 2])
        problem = q1_problem(lambda x: 1 + x[0] - 2 * x[1] + 3 * x[2] + x[0] * x[1] -
                             x[1] * x[2] + 2 * x[0] * x[1] * x[2])
    else:
        # On non-affine hexes (the optimized placement moves the transitions' nodes) only the
        # linear functions stay in the isoparametric Q1 space.
        brick = problems.structured_hex_mesh([0, 0, 0], [1, 1, 1], [3, 3, 3])
        mesh, report = hexrefine.refine(brick, [0, 13])
        assert report["refine"]["placement"]["nodes_moved"] > 0
        problem = q1_problem(lambda x: 1 + x[0] - 2 * x[1] + 3 * x[2])
    solution = solve_on(mesh, problem)
    eta2 = poisson.indicators(solution, problem)
    assert eta2.shape == (mesh.hex_count,)
    assert eta2.max() < 1e-18
    e_h1, e_l2 = poisson.errors(solution, problem)
    # CG stops at a relative residual of 1e-10 (poisson.SolverOptions.rtol): the error is the
    # solver's, of that order (1.8e-9 in H1 on the graded transitions), not the space's.
    assert e_h1 < 1e-8 and e_l2 < 1e-8
    # The same estimator is not zero where u is not in the space.
    other = q1_problem(lambda x: x[0]**2 - x[1]**2)
    assert poisson.indicators(solve_on(mesh, other), other).sum() > 1e-3


def test_cells_reach_dolfinx_in_its_vertex_order_and_come_back_by_hex_id():
    mesh = problems.lshape_mesh(cells_per_unit=2)
    dmesh = poisson.mesh_to_dolfinx(COMM, mesh.points, mesh.hexes)
    # Positive volumes (a wrong vertex order gives twisted, zero-volume hexes) summing to 3.
    volume = poisson.gather_by_original_cell(dmesh, poisson._cell_values(
        dmesh, lambda w: w * ufl.dx), mesh.hex_count)
    assert volume.sum() == pytest.approx(3.0, rel=1e-12)
    np.testing.assert_allclose(volume, hexrefine.quality(mesh, "volume"), rtol=1e-12)


def test_lshape_exact_solution_clamps_nodes_a_rounding_error_off_its_faces():
    x = ufl.SpatialCoordinate(ufl.Mesh(ufl.VectorElement("Lagrange", ufl.hexahedron, 1)))
    u = problems.lshape_exact(x)

    def value(p):
        return float(u(tuple(p)))

    # u = 0 on both re-entrant faces: y = 0, x > 0 (theta = 0) and x = 0, y < 0 (theta = 3 pi/2),
    # also a rounding error off them. A plain mod(atan2(y, x), 2 pi) gives the first node theta
    # near 2 pi and u = r^(2/3) sin(4 pi/3) = -0.55 instead of 0.
    for node in ([0.5, -1e-17, 0.3], [0.5, 0.0, 0.3], [0.5, -0.0, 0.3], [1e-17, -0.5, 0.3],
                 [0.0, -0.5, 0.3], [-1e-17, -0.5, 0.3], [0.0, 0.0, 0.3]):
        assert value(node) == pytest.approx(0.0, abs=1e-12), node
    assert value([0.0, 0.5, 0.3]) == pytest.approx(0.5**(2 / 3) * math.sin(math.pi / 3))
    assert value([-0.5, -0.5, 0.3]) == pytest.approx(
        math.sqrt(0.5)**(2 / 3) * math.sin(2 / 3 * 1.25 * math.pi))
    assert value([0.5, 0.5, 0.3]) == pytest.approx(math.sqrt(0.5)**(2 / 3) * math.sin(math.pi / 6))
