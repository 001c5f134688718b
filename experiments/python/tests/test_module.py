"""Tests of the Python module over the C++ library: the thesis counts through Python, round trips
numpy <-> HexMesh <-> files <-> meshio, the errors for bad arrays and specs, and an ablation loop
written the way a user writes one. Run by ctest (label python) with PYTHONPATH on the build tree."""

import json
import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest

import hexrefine

SHARED = pathlib.Path(os.environ.get("HEXREFINE_SHARED_DIR", "../shared"))
L_SHAPE = ["boundary:-1,0,0", "boundary:0,0,-1"]


def unit_cube():
    points = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                       [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], dtype=float)
    return points, np.arange(8, dtype=np.int64).reshape(1, 8)


@pytest.fixture(scope="module")
def brick10():
    return hexrefine.generate("brick", dims=[10, 10, 10], size=[1.0, 1.0, 1.0])


# --- the thesis' G-1 through Python --------------------------------------------------------------

@pytest.mark.parametrize("method,hexes", [("selective", 8060), ("sheet", 27000)])
def test_g1_counts_match_the_thesis(brick10, method, hexes):
    refined, report = hexrefine.refine(brick10, L_SHAPE, method=method, placement="trilinear")
    assert refined.hex_count == hexes
    assert report["refine"]["final_hexes"] == hexes
    assert report["check"]["valid"] and report["check"]["conformal"]
    assert report["check"]["non_conformal_faces"] == 0
    assert report["method"] == method
    # Every output hex names its input hex; the untouched ones keep level 0.
    parents = refined.attributes["parent_hex"]
    assert parents.shape == (hexes,)
    assert parents.min() >= 0 and parents.max() < brick10.hex_count
    assert set(refined.attributes) >= {"parent_hex", "template_tag", "refinement_level"}


def test_g1_selective_min_scaled_jacobian_is_the_thesis_value(brick10):
    refined, report = hexrefine.refine(brick10, L_SHAPE, placement="trilinear")
    q = hexrefine.quality(refined)
    assert q.shape == (8060,)
    assert q.min() == pytest.approx(4.0 / 13.0, abs=1e-9)  # 0.3077, the 1-13 template's corner
    assert report["check"]["min_scaled_jacobian"] == pytest.approx(q.min(), abs=1e-12)


def test_optimized_placement_beats_trilinear_on_g1(brick10):
    trilinear, _ = hexrefine.refine(brick10, L_SHAPE, placement="trilinear")
    optimized, report = hexrefine.refine(brick10, L_SHAPE)
    assert optimized.hex_count == trilinear.hex_count
    np.testing.assert_array_equal(optimized.hexes, trilinear.hexes)  # placement moves, never adds
    assert hexrefine.quality(optimized).min() > hexrefine.quality(trilinear).min() + 0.05
    assert report["options"]["placement"]["method"] == "optimized"


def test_refine_accepts_ids_as_array_list_and_specs_alike(brick10):
    ids = hexrefine.select(brick10, L_SHAPE)
    assert ids.dtype == np.int32 and np.all(np.diff(ids) > 0)
    assert len(ids) == 190  # two 10 x 10 layers sharing a 10-hex edge row
    by_spec, _ = hexrefine.refine(brick10, L_SHAPE, placement="trilinear")
    by_array, _ = hexrefine.refine(brick10, ids, placement="trilinear")
    by_list, _ = hexrefine.refine(brick10, [int(i) for i in ids[::-1]], placement="trilinear")
    np.testing.assert_array_equal(by_spec.hexes, by_array.hexes)
    np.testing.assert_array_equal(by_spec.hexes, by_list.hexes)


# --- round trips ---------------------------------------------------------------------------------

def test_arrays_round_trip_through_hexmesh():
    points, hexes = unit_cube()
    mesh = hexrefine.HexMesh(points, hexes, {"block_id": np.array([7])})
    np.testing.assert_array_equal(mesh.points, points)
    np.testing.assert_array_equal(mesh.hexes, hexes)
    assert mesh.hexes.dtype == np.int32 and mesh.points.dtype == np.float64
    assert mesh.attributes["block_id"].tolist() == [7]
    assert hexrefine.quality(mesh).tolist() == [1.0]
    assert hexrefine.quality(mesh, "volume").tolist() == [pytest.approx(1.0)]


@pytest.mark.parametrize("extension,binary", [(".vtu", False), (".vtk", False), (".vtk", True),
                                              (".mesh", False), (".e", False), (".msh", False),
                                              (".msh", True)])
def test_refined_mesh_round_trips_through_files(brick10, tmp_path, extension, binary):
    refined, _ = hexrefine.refine(brick10, "sphere:0,0,0,0.35")
    path = str(tmp_path / ("refined" + extension))
    hexrefine.write(refined, path, binary=binary)
    back = hexrefine.read(path)
    assert back.hex_count == refined.hex_count and back.point_count == refined.point_count
    np.testing.assert_array_equal(back.hexes, refined.hexes)
    np.testing.assert_allclose(back.points, refined.points, rtol=0, atol=1e-12)
    assert hexrefine.check(back)["valid"]


def test_refined_mesh_round_trips_through_meshio(brick10):
    meshio = pytest.importorskip("meshio")
    refined, _ = hexrefine.refine(brick10, "sphere:0,0,0,0.35", method="sheet")
    m = hexrefine.to_meshio(refined)
    assert isinstance(m, meshio.Mesh) and m.cells[0].type == "hexahedron"
    back = hexrefine.from_meshio(m)
    np.testing.assert_array_equal(back.hexes, refined.hexes)
    np.testing.assert_array_equal(back.points, refined.points)
    for name, values in refined.attributes.items():
        np.testing.assert_array_equal(back.attributes[name], values)


def test_from_meshio_refuses_other_volume_cells():
    meshio = pytest.importorskip("meshio")
    m = meshio.Mesh(np.eye(4, 3), [("tetra", np.array([[0, 1, 2, 3]]))])
    with pytest.raises(ValueError, match="tetra"):
        hexrefine.from_meshio(m)


def test_real_mesh_refines_valid_with_both_methods():
    path = SHARED / "meshes" / "rockerarm.mesh"
    if not path.exists():
        pytest.skip("shared meshes not present")
    mesh = hexrefine.read(str(path))
    targets = hexrefine.select(mesh, "random:0.02,7")
    assert len(targets) > 0
    for method in hexrefine.methods():
        refined, report = hexrefine.refine(mesh, targets, method=method)
        check = hexrefine.check(refined, mesh)
        assert check["valid"] and check["inverted_hexes"] == 0, method
        assert check["geometry_preserved"], method
        assert report["check"]["min_scaled_jacobian"] > 0, method
        assert refined.hex_count > mesh.hex_count, method


def test_threads_give_the_same_placed_and_smoothed_mesh():
    path = SHARED / "meshes" / "rockerarm.mesh"
    if not path.exists():
        pytest.skip("shared meshes not present")
    mesh = hexrefine.read(str(path))
    one, report_one = hexrefine.refine(mesh, "sphere:0,0,0,5", smooth=True, threads=1,
                                       placement="optimized")
    two, report_two = hexrefine.refine(mesh, "sphere:0,0,0,5", smooth=True, threads=2,
                                       placement="optimized")
    np.testing.assert_array_equal(one.points, two.points)  # bit for bit
    # The serial values (rockerarm issue-sphere, selective: reference positions, the worst
    # children optimised, one stretched to the default edge-ratio cap of 20; smoothed: sweeps,
    # then three rounds of joint ascent and sweeps, steered along the cap), no hex stretched
    # past the cap.
    # The report's check is the output's (smoothed); the refined mesh's before smoothing is
    # smoothing.refined_check (schema_version 2, docs/report.md).
    assert report_one["smoothing"]["refined_check"]["min_scaled_jacobian"] == 0.11023223760640442
    assert report_two["check"]["min_scaled_jacobian"] == 0.5457535571145382
    assert 19.9 < report_one["smoothing"]["refined_check"]["max_edge_ratio"] <= 20 * (1 + 1e-9)
    assert 19 < report_two["check"]["max_edge_ratio"] <= 20 * (1 + 1e-9)
    assert "check" not in report_two["smoothing"]
    # Without the cap, the scaled Jacobian alone: higher minima by collapsed edges.
    _, uncapped = hexrefine.refine(mesh, "sphere:0,0,0,5", max_edge_ratio=0)
    assert uncapped["check"]["min_scaled_jacobian"] == 0.11783137589340247
    assert uncapped["check"]["max_edge_ratio"] > 1000
    with pytest.raises(ValueError, match="max_edge_ratio"):
        hexrefine.refine(mesh, "sphere:0,0,0,5", max_edge_ratio=0.5)
    # smooth=True without a placement starts from untangle (issue 28, decision 2): the trilinear
    # positions with the inverted children untangled, then smoothing (here as high as from
    # optimized: with the default budget both end at the same worst hex).
    _, report = hexrefine.refine(mesh, "sphere:0,0,0,5", smooth=True)
    assert report["options"]["placement"]["method"] == "untangle"
    assert report["check"]["min_scaled_jacobian"] == 0.5457535571145382
    assert report["smoothing"]["nodes_undone"] == 0 and "warning" not in report["smoothing"]
    assert (report["smoothing"]["max_sweeps"], report["smoothing"]["max_joint_iterations"],
            report["smoothing"]["max_joint_rounds"]) == (20, 1000, 3)
    _, one_round = hexrefine.refine(mesh, "sphere:0,0,0,5", smooth=True, smooth_joint_rounds=1)
    assert one_round["check"]["min_scaled_jacobian"] == 0.5003094177402794
    assert one_round["smoothing"]["stats"]["joint_rounds"] == 1
    # A smaller budget: faster, lower (refine --smooth-sweeps 2 --smooth-joint-iterations 0).
    _, budget = hexrefine.refine(mesh, "sphere:0,0,0,5", smooth=True, smooth_sweeps=2,
                                 smooth_joint_iterations=0)
    assert budget["check"]["min_scaled_jacobian"] == 0.1972858580749072
    assert budget["smoothing"]["stats"]["joint_iterations"] == 0
    with pytest.raises(ValueError, match="smooth_sweeps"):
        hexrefine.refine(mesh, "sphere:0,0,0,5", smooth=True, smooth_sweeps=0)
    with pytest.raises(ValueError, match="smooth_joint_iterations needs smooth=True"):
        hexrefine.refine(mesh, "sphere:0,0,0,5", smooth_joint_iterations=5)
    with pytest.raises(ValueError, match="smooth_joint_rounds needs smooth=True"):
        hexrefine.refine(mesh, "sphere:0,0,0,5", smooth_joint_rounds=2)
    with pytest.raises(ValueError, match="smooth_joint_rounds must be in 1..1000"):
        hexrefine.refine(mesh, "sphere:0,0,0,5", smooth=True, smooth_joint_rounds=0)
    # Both starts (refine --smooth-both-starts): the higher of the untangle start (the budget run
    # above) and the optimized one, and the report names the start kept.
    _, optimized = hexrefine.refine(mesh, "sphere:0,0,0,5", smooth=True, placement="optimized",
                                    smooth_sweeps=2, smooth_joint_iterations=0)
    _, both = hexrefine.refine(mesh, "sphere:0,0,0,5", smooth=True, smooth_sweeps=2,
                               smooth_joint_iterations=0, smooth_both_starts=True)
    from_optimized = optimized["check"]["min_scaled_jacobian"]
    assert from_optimized != 0.1972858580749072
    assert both["check"]["min_scaled_jacobian"] == max(0.1972858580749072, from_optimized)
    kept = "optimized" if from_optimized > 0.1972858580749072 else "untangle"
    assert both["options"]["placement"]["method"] == kept
    assert ("smoothed from both starts" in both["refine"].get("placement_warning", "")) == (
        kept == "optimized")
    assert both["check"]["valid"]
    with pytest.raises(ValueError, match="smooth_both_starts needs smooth=True"):
        hexrefine.refine(mesh, "sphere:0,0,0,5", smooth_both_starts=True)
    with pytest.raises(ValueError, match="smooth_both_starts needs placement='untangle', got "
                                         "placement='optimized'"):
        hexrefine.refine(mesh, "sphere:0,0,0,5", smooth=True, placement="optimized",
                         smooth_both_starts=True)


# --- errors --------------------------------------------------------------------------------------

def test_wrong_shapes_are_refused():
    points, hexes = unit_cube()
    with pytest.raises(ValueError, match=r"points: expected .* \(n, 3\)"):
        hexrefine.HexMesh(points[:, :2], hexes)
    with pytest.raises(ValueError, match=r"hexes: expected .* \(m, 8\)"):
        hexrefine.HexMesh(points, hexes[:, :6])
    with pytest.raises(ValueError, match="hexes: expected an integer array"):
        hexrefine.HexMesh(points, hexes.astype(float))
    with pytest.raises(ValueError, match="attribute 'block_id'"):
        hexrefine.HexMesh(points, hexes, {"block_id": np.array([1, 2])})


def test_out_of_range_ids_name_the_hex_and_node():
    points, hexes = unit_cube()
    bad = hexes.copy()
    bad[0, 5] = 8
    with pytest.raises(ValueError, match=r"hex 0, node 5: id 8 out of range 0\.\.7"):
        hexrefine.HexMesh(points, bad)
    bad[0, 5] = -1
    with pytest.raises(ValueError, match="hex 0, node 5"):
        hexrefine.HexMesh(points, bad)


def test_repeated_node_and_nan_are_refused():
    points, hexes = unit_cube()
    bad = hexes.copy()
    bad[0, 6] = 0
    with pytest.raises(ValueError, match="hex 0"):
        hexrefine.HexMesh(points, bad)
    nan = points.copy()
    nan[3, 1] = np.nan
    with pytest.raises(ValueError, match="point 3 has a NaN"):
        hexrefine.HexMesh(nan, hexes)


def test_bad_specs_options_and_files_are_value_errors(brick10, tmp_path):
    with pytest.raises(ValueError, match="sphere"):
        hexrefine.select(brick10, "sphere:1,2")
    with pytest.raises(ValueError, match="out of range"):
        hexrefine.refine(brick10, np.array([1000]))
    with pytest.raises(ValueError, match="placement"):
        hexrefine.refine(brick10, [0], placement="random")
    with pytest.raises(ValueError):
        hexrefine.refine(brick10, [0], method="octree")
    with pytest.raises(ValueError, match="metric"):
        hexrefine.quality(brick10, "aspect")
    with pytest.raises(ValueError, match="brick"):
        hexrefine.generate("brik")
    bad = tmp_path / "bad.mesh"
    bad.write_text("MeshVersionFormatted 2\nDimension 3\nVertices\n2\n0 0 0 0\n")
    with pytest.raises(ValueError, match="bad.mesh"):
        hexrefine.read(str(bad))


def test_ablation_without_propagation_reports_non_conformal_faces(brick10):
    # An ablation switch is not a refusal: the output comes back and the checker counts the faces
    # the directional cells leave non-conformal without the propagation scheme.
    ids = hexrefine.select(brick10, "random:0.05,0")
    refined, report = hexrefine.refine(brick10, ids, propagation=False, placement="trilinear")
    assert report["options"]["propagation"] is False
    assert report["check"]["non_conformal_faces"] == 1512
    assert not report["check"]["valid"]
    assert refined.hex_count == 5794


# --- an ablation loop the way a user writes one --------------------------------------------------

def test_ablation_loop_over_seeded_random_targets(brick10):
    rows = []
    for seed in range(3):
        targets = hexrefine.select(brick10, f"random:0.05,{seed}")
        for ranking in (True, False):
            for propagation in (True, False):
                refined, report = hexrefine.refine(brick10, targets, ranking=ranking,
                                                   propagation=propagation,
                                                   placement="trilinear")
                rows.append({"seed": seed, "ranking": ranking, "propagation": propagation,
                             "hexes": refined.hex_count,
                             "non_conformal": report["check"]["non_conformal_faces"]})
    assert len(rows) == 12
    by_key = {(r["seed"], r["ranking"], r["propagation"]): r for r in rows}
    for seed in range(3):
        # Propagation is what makes the output conformal; ranking is what keeps it small.
        assert by_key[seed, True, True]["non_conformal"] == 0
        assert by_key[seed, False, True]["non_conformal"] == 0
        assert by_key[seed, True, False]["non_conformal"] > 0
        assert by_key[seed, False, True]["hexes"] > by_key[seed, True, True]["hexes"]
    assert [by_key[s, True, True]["hexes"] for s in range(3)] == [5892, 4937, 6864]
    # The records are plain JSON: what a user saves beside a plot.
    assert json.loads(json.dumps(rows)) == rows


def test_run_yields_the_records_of_the_command_line(tmp_path):
    cases = {"cases": [{"name": "g1", "mesh": {"generate": "brick", "dims": [10, 10, 10]},
                        "select": L_SHAPE, "methods": ["selective", "sheet"],
                        "options": {"placement": "trilinear"}}]}
    records = hexrefine.run(cases, str(tmp_path / "out.jsonl"))
    assert [r["method"] for r in records] == ["selective", "sheet"]
    assert [r["refine"]["final_hexes"] for r in records] == [8060, 27000]
    assert all(r["check"]["valid"] for r in records)
    lines = (tmp_path / "out.jsonl").read_text().splitlines()
    assert len(lines) == 2


def test_refine_keywords_are_the_options_table(brick10, tmp_path):
    """refine's keywords, their defaults and checks are the pipeline's one table: the same
    settings as keywords and as a case's options give the same options and the same mesh."""
    import inspect
    keys = [row["key"] for row in hexrefine.refine_options()]
    assert keys[:4] == ["passes", "buffer", "placement", "smooth"] and "max_edge_ratio" in keys
    signature = inspect.signature(hexrefine.refine)
    assert list(signature.parameters)[:4] == ["mesh", "targets", "method", "threads"]
    for row in hexrefine.refine_options():
        assert signature.parameters[row["key"]].default == row["default"]
        assert row["key"] + " (" in hexrefine.refine.__doc__
    settings = {"passes": 2, "buffer": "transitions", "ranking": False,
                "directional_order": "by_rank", "max_edge_ratio": 0, "placement": "trilinear"}
    refined, report = hexrefine.refine(brick10, L_SHAPE, **settings)
    cases = {"cases": [{"name": "same", "mesh": {"generate": "brick", "dims": [10, 10, 10]},
                        "select": L_SHAPE, "methods": ["selective"], "options": settings}]}
    record, = hexrefine.run(cases, str(tmp_path / "out.jsonl"))
    options = dict(report["options"])
    del options["threads"]
    assert record["options"] == options
    assert record["refine"]["final_hexes"] == refined.hex_count
    # numpy scalars are the values they hold; None is the default.
    _, same = hexrefine.refine(brick10, L_SHAPE, passes=np.int64(2), buffer="transitions",
                               ranking=np.bool_(False), directional_order="by_rank",
                               max_edge_ratio=np.float64(0), placement="trilinear",
                               smooth_sweeps=None)
    assert same["options"] == report["options"]
    with pytest.raises(TypeError, match="did you mean smooth_sweeps"):
        hexrefine.refine(brick10, L_SHAPE, smooth_sweep=2)
    with pytest.raises(ValueError, match=r"directional_order must be by_hex or by_rank, got "
                                         r"'by-rank' \(did you mean by_rank\?"):
        hexrefine.refine(brick10, L_SHAPE, directional_order="by-rank")
    with pytest.raises(ValueError, match="passes must be an integer, got '2'"):
        hexrefine.refine(brick10, L_SHAPE, passes="2")


def test_ablation_example_runs_and_writes_its_records(tmp_path):
    script = pathlib.Path(os.environ.get("HEXREFINE_SOURCE_DIR", ".")) / "experiments" / \
        "studies" / "ablation" / "run.py"
    out = tmp_path / "ablation.json"
    subprocess.run([sys.executable, str(script), "--quick", "--seeds", "2", "--placement",
                    "trilinear", "--json", str(out)], check=True, capture_output=True)
    records = json.loads(out.read_text())["records"]
    assert len(records) == 8  # 1 mesh x 2 seeds x 4 variants
    full = [r for r in records if r["variant"] == "full"]
    assert all(r["non_conformal_faces"] == 0 and r["valid"] for r in full)
    assert all(r["non_conformal_faces"] > 0 for r in records if not r["propagation"])
