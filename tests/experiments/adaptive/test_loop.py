"""Tests of experiments/adaptive/loop.py and run.py: two steps of the loop on the L-shape, the
marking rules, the DOF counts, and the command's records and errors."""

import json
import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest
from mpi4py import MPI

import loop
import poisson
import problems

RUN = pathlib.Path(__file__).resolve().parents[3] / "experiments" / "adaptive" / "run.py"


@pytest.mark.parametrize("method", ["selective", "sheet"])
def test_two_steps_on_a_small_lshape_decrease_the_error_and_keep_every_mesh_valid(method):
    records = loop.run_loop(MPI.COMM_WORLD, problems.PROBLEMS["lshape"], method,
                            loop.LoopOptions(max_steps=3))
    assert [r["step"] for r in records] == [0, 1, 2]
    # 192 hexes, 325 nodes; Doerfler 0.3 marks the 4 hexes at the singular edge in the middle
    # z layers, refined 1-27 with transitions around them.
    assert [r["hexes"] for r in records[:2]] == [192, 536]
    assert [r["dofs"] for r in records[:2]] == [325, 705]
    assert records[0]["error_h1"] == pytest.approx(0.1368, abs=2e-4)
    for before, after in zip(records, records[1:]):
        assert after["error_h1"] < 0.9 * before["error_h1"]
        assert after["error_l2"] < before["error_l2"]
        assert after["dofs"] > before["dofs"]
    for r in records:
        assert r["valid"] and r["min_scaled_jacobian"] > 0.3
        assert 2 < r["effectivity"] < 5
        assert r["solver_iterations"] <= 15
        assert set(r["seconds"]) >= {"solve", "estimate", "mark", "refine"}


def test_doerfler_marks_the_fewest_hexes_and_ties_together():
    eta2 = np.array([1.0, 4.0, 2.0, 3.0])
    np.testing.assert_array_equal(loop.mark_doerfler(eta2, 0.5), [1, 3])  # 4 + 3 >= 5
    np.testing.assert_array_equal(loop.mark_doerfler(eta2, 0.4), [1])     # 4 >= 4
    np.testing.assert_array_equal(loop.mark_doerfler(eta2, 1.0), [0, 1, 2, 3])
    # Equal by symmetry (to rounding): all or none.
    np.testing.assert_array_equal(loop.mark_doerfler(np.array([1.0, 1 + 1e-12, 1.0, 0.5]), 0.3),
                                  [0, 1, 2])
    with pytest.raises(ValueError):
        loop.mark_doerfler(eta2, 0.0)
    np.testing.assert_array_equal(loop.mark_fraction(eta2, 0.5), [1, 3])
    np.testing.assert_array_equal(loop.mark_fraction(eta2, 0.1), [1])


def test_dofs_of_counts_the_q1_and_q2_nodes():
    mesh = problems.structured_hex_mesh([0, 0, 0], [1, 1, 1], [2, 3, 4])
    assert loop.dofs_of(mesh, 1) == 3 * 4 * 5
    assert loop.dofs_of(mesh, 2) == 5 * 7 * 9
    lshape = problems.lshape_mesh()
    assert lshape.hex_count == 192 and loop.dofs_of(lshape, 1) == 325
    assert loop.dofs_of(lshape, 2) == (17 * 17 - 8 * 8) * 9


def test_q2_on_the_smooth_problem_converges_faster_than_q1():
    problem = problems.PROBLEMS["smooth"]
    mesh = problem.initial_mesh()
    dmesh = poisson.mesh_to_dolfinx(MPI.COMM_WORLD, mesh.points, mesh.hexes)
    q2 = poisson.solve(dmesh, problem, poisson.SolverOptions(degree=2))
    assert q2.dofs == loop.dofs_of(mesh, 2) == 7**3
    h1_q2, _ = poisson.errors(q2, problem, poisson.SolverOptions(degree=2))
    assert h1_q2 < 0.3 * 0.5836  # Q1 on the same mesh: 0.5836


def run(*arguments):
    environment = dict(os.environ)
    return subprocess.run([sys.executable, str(RUN), *arguments], capture_output=True, text=True,
                          env=environment)


def test_the_command_writes_a_record_per_method_and_step(tmp_path):
    out = tmp_path / "lshape.jsonl"
    meshes = tmp_path / "meshes"
    result = run("--problem", "lshape", "--methods", "uniform,selective", "--max-dofs", "1000",
                 "--out", str(out), "--save-meshes", str(meshes))
    assert result.returncode == 0, result.stderr
    records = [json.loads(line) for line in out.read_text().splitlines()]
    # uniform: 325 dofs, then 6,253 > 1,000; selective: 325, 705, then 2,199 > 1,000.
    assert [(r["method"], r["step"], r["dofs"]) for r in records] == [
        ("uniform", 0, 325), ("selective", 0, 325), ("selective", 1, 705)]
    assert records[-1]["next_dofs"] > 1000
    keys = {"problem", "method", "step", "hexes", "dofs", "error_h1", "error_l2", "estimate",
            "min_scaled_jacobian", "valid", "seconds", "solver_iterations", "mesh_file"}
    for r in records:
        assert keys <= set(r)
        assert set(r["seconds"]) >= {"solve", "estimate", "mark", "refine"}
        assert pathlib.Path(r["mesh_file"]).is_file() and r["mesh_file"].endswith(".vtu")
    assert "lshape selective step 1: 536 hexes, 705 dofs" in result.stdout
    assert not list(tmp_path.glob("*.tmp*"))


@pytest.mark.parametrize("arguments,message", [
    (["--methods", "selective,bogus"], "unknown method 'bogus'"),
    (["--theta", "1.5"], "--theta and --fraction must be in (0, 1]"),
    (["--max-dofs", "0"], "must be positive"),
])
def test_the_command_refuses_bad_usage_with_exit_2(tmp_path, arguments, message):
    result = run("--problem", "lshape", "--out", str(tmp_path / "x.jsonl"), *arguments)
    assert result.returncode == 2
    assert message in result.stderr
    assert not (tmp_path / "x.jsonl").exists()
