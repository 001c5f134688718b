"""Tests of experiments/adaptive/hierarchy.py: graded rebuilding keeps every transition a single
template inside a full child (the minimum scaled Jacobian stays the 1-13 template's 4/13 with the
trilinear placement, where refining the marked hexes directly nests the 1-13 down to 0.0038),
marks of transition hexes refine their parents, the cache, and the reference coordinates."""

import numpy as np
import pytest

import hexrefine
import hierarchy
import problems


def brick(n=4):
    return problems.structured_hex_mesh([0, 0, 0], [1, 1, 1], [n, n, n])


def hex_nearest(mesh, point):
    centroids = mesh.points[mesh.hexes].mean(axis=1)
    return int(np.argmin(np.linalg.norm(centroids - point, axis=1)))


def test_graded_rebuild_never_nests_transitions_where_direct_refinement_does():
    # Each step marks the hex nearest (0.49, 0.49, 0.49), a corner of the previous step's
    # refined hex: its transitions are next to the new target.
    point = np.full(3, 0.49)
    graded = hierarchy.GradedRefinement(brick(), {"method": "selective",
                                                  "placement": "trilinear"})
    direct = brick()
    counts, minimum, direct_minimum, targets = [], [], [], []
    for _ in range(4):
        graded.mark([hex_nearest(graded.mesh, point)])
        mesh, report, levels, _ = graded.rebuild()
        assert report["check"]["valid"]
        counts.append(mesh.hex_count)
        minimum.append(hexrefine.quality(mesh).min())
        targets.append(levels)
        direct, _ = hexrefine.refine(direct, [hex_nearest(direct, point)],
                                     placement="trilinear")
        direct_minimum.append(hexrefine.quality(direct).min())
    assert counts == [210, 1272, 3368, 8658]
    # Targets per level: the marked hex, then rings of one and two hexes around it (module doc).
    assert targets == [[1], [27, 1], [64, 27, 1], [64, 125, 27, 1]]
    assert minimum == pytest.approx([4 / 13] * 4, abs=1e-9)
    # Direct: the 1-13 nested twice and three times (results/buffer_rules.md's 0.03501, 0.003831).
    assert direct_minimum == pytest.approx([4 / 13, 0.03501, 0.003831, 0.003831], abs=5e-5)


def test_a_marked_transition_hex_refines_its_regular_parent():
    graded = hierarchy.GradedRefinement(brick(3), {"method": "selective",
                                                   "placement": "trilinear"})
    graded.mark([13])  # the middle hex of 3 x 3 x 3: its 26 neighbours become transitions
    mesh, _, levels, _ = graded.rebuild()
    assert levels == [1]
    parents = mesh.attributes["parent_hex"]
    transition = int(np.flatnonzero(parents == 4)[0])  # a child of the face neighbour 4
    assert graded.current.level[transition] == 0 and not graded.current.regular[transition]
    graded.mark([transition])
    mesh, _, levels, refined = graded.rebuild()
    assert levels == [2]  # hexes 13 and 4 at level 0, nothing at level 1
    assert refined == 1
    np.testing.assert_array_equal(graded.base.targets, [4, 13])
    assert hexrefine.quality(mesh).min() == pytest.approx(4 / 13, abs=1e-9)
    # The same marks again change nothing: every level comes from the cache.
    calls = graded.refine_calls
    graded.mark([])
    again, _, _, refined = graded.rebuild()
    assert refined == 0 and graded.refine_calls == calls
    np.testing.assert_array_equal(again.hexes, mesh.hexes)


def test_reference_coordinates_invert_the_trilinear_map():
    rng = np.random.default_rng(7)
    corners = hierarchy.HEX_CORNERS[None] * [2.0, 1.0, 0.5] + rng.uniform(-0.1, 0.1, (5, 8, 3))
    xi = rng.uniform(0, 1, (5, 3))
    c = hierarchy.HEX_CORNERS
    shape = np.where(c[None] == 1, xi[:, None, :], 1 - xi[:, None, :]).prod(axis=2)
    points = np.einsum("ni,nik->nk", shape, corners)
    np.testing.assert_allclose(hierarchy.hex_reference_coordinates(corners, points), xi,
                               atol=1e-12)


def test_children_grid_cells_follow_the_split_also_after_smoothing():
    mesh = problems.structured_hex_mesh([0, 0, 0], [3, 1, 1], [3, 1, 1])
    for smooth in (False, True):
        refined, report = hexrefine.refine(mesh, [0, 1], smooth=smooth, placement="untangle")
        parents = refined.attributes["parent_hex"].astype(np.int64)
        children = np.flatnonzero(np.isin(parents, [0, 1]))
        centroids = refined.points[refined.hexes[children]].mean(axis=1)
        xi = hierarchy.hex_reference_coordinates(mesh.points[mesh.hexes[parents[children]]],
                                                 centroids)
        cells = hierarchy.hex_children_grid_cells(parents[children], xi)
        for parent in (0, 1):
            assert sorted(cells[parents[children] == parent]) == list(range(27))
        if not smooth:
            rounded = np.floor(3 * xi).astype(int)
            np.testing.assert_array_equal(cells, (rounded[:, 0] * 3 + rounded[:, 1]) * 3 +
                                          rounded[:, 2])
        else:
            # Smoothing moved the children (their centroids are off the thirds' centres).
            assert np.abs(3 * xi - np.floor(3 * xi) - 0.5).max() > 0.01
