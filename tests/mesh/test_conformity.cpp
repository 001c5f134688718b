#include "mesh/conformity.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>

#include "mesh/error.hpp"
#include "mesh/hex_convention.hpp"
#include "tests/fixtures.hpp"

namespace hexrefine {
namespace {

/// Axis-aligned boxes (lo, hi) as hexes; nodes at equal coordinates are merged.
HexMesh mesh_from_boxes(const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& boxes) {
  HexMesh m;
  std::map<std::array<double, 3>, int32_t> ids;
  for (const auto& [lo, hi] : boxes) {
    HexCell c;
    for (int v = 0; v < 8; ++v) {
      std::array<double, 3> x;
      for (int k = 0; k < 3; ++k) x[k] = hex_corner[v][k] ? hi[k] : lo[k];
      const auto [it, added] = ids.try_emplace(x, m.point_count());
      if (added) m.points.emplace_back(x[0], x[1], x[2]);
      c[v] = it->second;
    }
    m.hexes.push_back(c);
  }
  return m;
}

/// 2x1x1 brick whose hex at x in [1,2] is replaced by its 1-8 octree split.
HexMesh brick_with_one_octree_split() {
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> boxes = {
      {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 1, 1)}};
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) {
        const Eigen::Vector3d lo(1 + 0.5 * i, 0.5 * j, 0.5 * k);
        boxes.push_back({lo, lo + Eigen::Vector3d::Constant(0.5)});
      }
  return mesh_from_boxes(boxes);
}

TEST(Conformity, BrickIsClean) {
  const HexMesh m = fixture_brick(3, 2, 2);
  const MeshCheckReport r = mesh_check(m);
  EXPECT_EQ(r.hexes, 12);
  EXPECT_EQ(r.nodes, 36);
  EXPECT_TRUE(r.conformal);
  EXPECT_TRUE(r.valid());
  EXPECT_EQ(r.non_conformal_faces, 0);
  EXPECT_EQ(r.hanging_nodes, 0);
  EXPECT_EQ(r.inverted_hexes, 0);
  EXPECT_EQ(r.first_inverted_hex, -1);
  EXPECT_EQ(r.doublets, 0);
  EXPECT_EQ(r.nonmanifold_faces, 0);
  EXPECT_EQ(r.nonmanifold_boundary_edges, 0);
  EXPECT_EQ(r.duplicate_nodes, 0);
  EXPECT_EQ(r.unused_nodes, 0);
  EXPECT_EQ(r.boundary_faces, 2 * (3 * 2 + 3 * 2 + 2 * 2));
  EXPECT_DOUBLE_EQ(r.min_scaled_jacobian, 1.0);
  EXPECT_DOUBLE_EQ(r.mean_scaled_jacobian, 1.0);
  EXPECT_DOUBLE_EQ(r.max_edge_ratio, 1.0);
  EXPECT_NEAR(r.volume, 12.0, 1e-12);
  EXPECT_NEAR(r.boundary_area, 32.0, 1e-12);
  EXPECT_FALSE(r.reference_compared);
}

TEST(Conformity, LargestEdgeRatioSeesACollapsingEdgeTheScaledJacobianDoesNot) {
  // One unit cube, its corner 6 drawn down onto corner 2 until edge 2-6 is 1e-3 long: the hex
  // stays positive (scaled Jacobian > 0), and its edge ratio is the edges 5-6 and 6-7 (about
  // sqrt(2)) over 1e-3.
  HexMesh m = fixture_brick(1, 1, 1);
  m.points[m.hexes[0][6]] = m.points[m.hexes[0][2]] + Eigen::Vector3d(0, 0, 1e-3);
  const MeshCheckReport r = mesh_check(m);
  EXPECT_GT(r.min_scaled_jacobian, 0);
  const double longest = (m.points[m.hexes[0][6]] - m.points[m.hexes[0][5]]).norm();
  EXPECT_NEAR(r.max_edge_ratio, longest / 1e-3, 1e-6);
  EXPECT_GT(r.max_edge_ratio, 1000);
}

TEST(Conformity, TwoHexesSharingTwoFacesAreADoublet) {
  HexMesh m = fixture_brick(1, 1, 1);
  m.points.emplace_back(-1, -1, 0);  // 8
  m.points.emplace_back(-1, -1, 1);  // 9
  // Brick node ids run x fastest: hex 0 is {0,1,3,2,4,5,7,6}. The new hex shares hex 0's +x face
  // {1,3,7,5} (as its -x face) and +y face {2,6,7,3} (as its -y face).
  m.hexes.push_back({3, 2, 8, 1, 7, 6, 9, 5});
  const MeshCheckReport r = mesh_check(m);
  EXPECT_EQ(r.doublets, 1);
  EXPECT_EQ(r.nonmanifold_faces, 0);
  EXPECT_FALSE(r.conformal);
  EXPECT_FALSE(r.valid());
}

TEST(Conformity, OctreeSplitBesideUnsplitHexIsNonConformal) {
  const HexMesh m = brick_with_one_octree_split();
  ASSERT_EQ(m.hex_count(), 9);
  ASSERT_EQ(m.point_count(), 31);
  const HexMesh reference = fixture_brick(2, 1, 1);
  for (const HexMesh* ref : {static_cast<const HexMesh*>(nullptr), &reference}) {
    const MeshCheckReport r = mesh_check(m, ref);
    SCOPED_TRACE(ref ? "with reference" : "without reference");
    // The unsplit hex's +x face and the four small faces behind it.
    EXPECT_EQ(r.non_conformal_faces, 5);
    // Four edge midpoints and the face centre of the interface.
    EXPECT_EQ(r.hanging_nodes, 5);
    EXPECT_EQ(r.boundary_faces, 6 + 24);
    EXPECT_EQ(r.nonmanifold_boundary_edges, 0);  // two sheets touching: still a closed surface
    EXPECT_EQ(r.doublets, 0);
    EXPECT_EQ(r.inverted_hexes, 0);
    EXPECT_FALSE(r.conformal);
    EXPECT_NEAR(r.volume, 2.0, 1e-12);
    EXPECT_NEAR(r.boundary_area, 12.0, 1e-12);  // the interface counted from both sides
  }
  const MeshCheckReport r = mesh_check(m, &reference);
  EXPECT_TRUE(r.reference_compared);
  EXPECT_TRUE(r.reference_planar_faced);
  EXPECT_NEAR(r.volume_relative_error, 0.0, 1e-15);
  EXPECT_NEAR(r.boundary_area_relative_error, 0.2, 1e-12);
  EXPECT_FALSE(r.geometry_preserved);
}

TEST(Conformity, ConformingOctreeSplitMatchesReference) {
  // Whole 1x1x1 reference split 2x2x2: conformal, geometry preserved exactly.
  const HexMesh reference = fixture_brick(1, 1, 1);
  const HexMesh m = fixture_brick(2, 2, 2, 0.5);
  const MeshCheckReport r = mesh_check(m, &reference);
  EXPECT_TRUE(r.conformal);
  EXPECT_TRUE(r.valid());
  EXPECT_EQ(r.non_conformal_faces, 0);
  EXPECT_TRUE(r.reference_planar_faced);
  EXPECT_LT(r.volume_relative_error, 1e-15);
  EXPECT_LT(r.boundary_area_relative_error, 1e-15);
  EXPECT_TRUE(r.geometry_preserved);
  EXPECT_DOUBLE_EQ(r.reference_volume, 1.0);
  EXPECT_DOUBLE_EQ(r.reference_boundary_area, 6.0);
}

TEST(Conformity, BoundaryNodeMovedOffReferenceSurface) {
  const HexMesh reference = fixture_brick(1, 1, 1);
  HexMesh m = fixture_brick(2, 2, 2, 0.5);
  // Centre node of the x = 1 face (i=2, j=1, k=1 in the 3x3x3 node grid) pushed outward.
  const int32_t centre = 2 + 3 * (1 + 3 * 1);
  ASSERT_DOUBLE_EQ(m.points[centre].x(), 1.0);
  m.points[centre].x() = 1.1;
  const MeshCheckReport r = mesh_check(m, &reference);
  EXPECT_EQ(r.non_conformal_faces, 4);  // the four faces around the moved node
  EXPECT_EQ(r.hanging_nodes, 0);
  EXPECT_FALSE(r.conformal);
  // Each of the four 0.5 x 0.5 faces bulges by 0.1 at one corner: 4 x 0.1 x 0.25 / 4.
  EXPECT_NEAR(r.volume_relative_error, 0.025, 1e-12);
  EXPECT_GT(r.boundary_area_relative_error, 1e-4);
  EXPECT_FALSE(r.geometry_preserved);
  EXPECT_FALSE(r.valid());
  // Without a reference the bulge is indistinguishable from true boundary.
  EXPECT_TRUE(mesh_check(m).conformal);
}

TEST(Conformity, FacesAcrossReferenceFacesAreOnTheSurface) {
  // Smoothing slides an input boundary node over the input's faces: the top edge x = 1 of a
  // 2x1x1 brick moved to x = 1.3 leaves the top and side faces of both hexes across two
  // reference faces each, on the same planes: conformal, and the planar geometry preserved.
  const HexMesh reference = fixture_brick(2, 1, 1);
  HexMesh m = reference;
  int moved = 0;
  for (Eigen::Vector3d& x : m.points)
    if (x.x() == 1 && x.z() == 1) {
      x.x() = 1.3;
      ++moved;
    }
  ASSERT_EQ(moved, 2);
  const MeshCheckReport r = mesh_check(m, &reference);
  EXPECT_EQ(r.non_conformal_faces, 0);
  EXPECT_TRUE(r.conformal);
  EXPECT_TRUE(r.geometry_preserved);
  EXPECT_TRUE(r.valid());
  // Off the surface is still off it: the same edge raised by 0.05 (a bulge, not a slide).
  HexMesh bulge = m;
  for (Eigen::Vector3d& x : bulge.points)
    if (x.x() == 1.3) x.z() = 1.05;
  EXPECT_EQ(mesh_check(bulge, &reference).non_conformal_faces, 6);
}

TEST(Conformity, GapThroughAOneHexPlateIsNonConformalThoughItsCornersAreOnTheSurface) {
  // Two hexes of a thin plate that should share the face x = 1 but have their own nodes there:
  // the two faces of the gap have every corner on the reference surface (top, bottom, sides),
  // but they stand across it.
  const HexMesh reference = fixture_brick(2, 1, 1);
  HexMesh m;
  for (int h = 0; h < 2; ++h)
    for (int v = 0; v < 8; ++v) {
      m.points.push_back(reference.points[reference.hexes[h][v]]);
      m.hexes.resize(h + 1);
      m.hexes[h][v] = static_cast<int32_t>(m.points.size()) - 1;
    }
  for (Eigen::Vector3d& x : m.points) x.z() *= 0.1;
  HexMesh plate = reference;
  for (Eigen::Vector3d& x : plate.points) x.z() *= 0.1;
  const MeshCheckReport r = mesh_check(m, &plate);
  EXPECT_EQ(r.non_conformal_faces, 2);
  EXPECT_FALSE(r.conformal);
  // The two hexes share no node: two bodies, so their four coincident node pairs are interface
  // nodes; against the one-body reference their faces at x = 1 are off its boundary all the same.
  EXPECT_EQ(r.bodies, 2);
  EXPECT_EQ(r.interface_nodes, 4);
  EXPECT_EQ(r.duplicate_nodes, 0);
}

TEST(Conformity, NonPlanarReferenceOnlyReportsGeometryErrors) {
  HexMesh reference = fixture_brick(1, 1, 1);
  reference.points[6].z() = 1.2;  // warps the top, +x and +y faces
  HexMesh m = fixture_brick(1, 1, 1);
  m.points[6].z() = 1.3;
  const MeshCheckReport r = mesh_check(m, &reference);
  EXPECT_FALSE(r.reference_planar_faced);
  EXPECT_GT(r.volume_relative_error, 1e-3);
  EXPECT_TRUE(r.geometry_preserved);
  EXPECT_EQ(r.non_conformal_faces, 3);  // the three faces at the moved corner leave the surface
}

TEST(Conformity, SlantedSplitOfWarpedHexStaysOnReference) {
  // Reference: unit cube with corner 6 raised, so its +x, +y and +z faces are warped. Split it
  // into two hexes by the parameter-space plane u = 0.3 + 0.4 v: the new nodes lie on the
  // reference's straight edges, but the children's boundary faces are not parameter rectangles,
  // so their centroids leave the warped patches by a fraction of the warp.
  HexMesh reference = fixture_brick(1, 1, 1);
  reference.points[7].z() = 1.4;  // brick ids run x fastest: node 7 is corner (1,1,1)
  const std::array<Eigen::Vector3d, 8> r = hex_points(reference, 0);
  auto map = [&](double u, double v, double w) {
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    for (int c = 0; c < 8; ++c)
      x += r[c] * ((hex_corner[c][0] ? u : 1 - u) * (hex_corner[c][1] ? v : 1 - v) *
                   (hex_corner[c][2] ? w : 1 - w));
    return x;
  };
  HexMesh m;
  for (int w = 0; w <= 1; ++w)
    for (int v = 0; v <= 1; ++v)
      for (const double u : {0.0, 0.3 + 0.4 * v, 1.0}) m.points.push_back(map(u, v, w));
  auto id = [](int i, int v, int w) { return static_cast<int32_t>(i + 3 * (v + 2 * w)); };
  for (int i = 0; i < 2; ++i)
    m.hexes.push_back({id(i, 0, 0), id(i + 1, 0, 0), id(i + 1, 1, 0), id(i, 1, 0), id(i, 0, 1),
                       id(i + 1, 0, 1), id(i + 1, 1, 1), id(i, 1, 1)});
  const MeshCheckReport report = mesh_check(m, &reference);
  EXPECT_EQ(report.inverted_hexes, 0);
  EXPECT_EQ(report.non_conformal_faces, 0);
  EXPECT_TRUE(report.conformal);
  EXPECT_FALSE(report.reference_planar_faced);
  // The children's faces are new bilinear patches through points of the warped ones, so the
  // volume changes (by 1.2%); for a warped reference that is reported, not a failure.
  EXPECT_GT(report.volume_relative_error, 1e-3);
  EXPECT_TRUE(report.geometry_preserved);
}

TEST(Conformity, FaceSharedByThreeHexes) {
  HexMesh m = fixture_brick(1, 1, 2);  // hexes 0 and 1 share the face z = 1, nodes {4, 5, 7, 6}
  for (int v = 4; v < 8; ++v) m.points.emplace_back(m.points[v] + Eigen::Vector3d(0.3, 0, 2));
  m.hexes.push_back({4, 5, 7, 6, 12, 13, 15, 14});  // a third hex on that face
  const MeshCheckReport r = mesh_check(m);
  EXPECT_EQ(r.nonmanifold_faces, 1);
  EXPECT_EQ(r.doublets, 0);
  EXPECT_FALSE(r.conformal);
  EXPECT_EQ(r.inverted_hexes, 0);
}

TEST(Conformity, InvertedHexIsCountedAndLocated) {
  HexMesh m = fixture_brick(3, 1, 1);
  HexCell& c = m.hexes[1];
  for (int v = 0; v < 4; ++v) std::swap(c[v], c[v + 4]);  // inside out
  const MeshCheckReport r = mesh_check(m);
  EXPECT_EQ(r.inverted_hexes, 1);
  EXPECT_EQ(r.first_inverted_hex, 1);
  EXPECT_DOUBLE_EQ(r.min_scaled_jacobian, -1.0);
  EXPECT_NEAR(r.mean_scaled_jacobian, 1.0 / 3.0, 1e-15);
  EXPECT_TRUE(r.conformal);  // same faces, only the orientation is wrong
  EXPECT_FALSE(r.valid());
  EXPECT_NEAR(r.volume, 1.0, 1e-12);  // 1 + (-1) + 1
  const std::vector<std::string> defects = mesh_check_defects(r);
  ASSERT_EQ(defects.size(), 1u);
  EXPECT_EQ(defects[0], "1 inverted hexes, first at id 1");
}

TEST(Conformity, DuplicateAndUnusedNodes) {
  HexMesh m = fixture_brick(1, 1, 1);
  m.points.emplace_back(0, 0, 0);          // duplicate of node 0, unused
  m.points.emplace_back(5, 5, 5);          // unused
  m.points.emplace_back(1, 1, 1 + 1e-14);  // duplicate of node 6 within 1e-12 x diagonal, unused
  const MeshCheckReport r = mesh_check(m);
  EXPECT_EQ(r.duplicate_nodes, 2);
  EXPECT_EQ(r.unused_nodes, 3);
  EXPECT_TRUE(r.conformal);  // loose nodes do not break conformity
}

TEST(Conformity, DuplicateNodesMatchBruteForce) {
  // Random points, a structured grid (points on any cell walls the search might use) and
  // near-copies within and beyond the tolerance; compared with the O(n^2) definition.
  HexMesh m = fixture_brick(12, 12, 12, 0.25);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> coordinate(0.0, 3.0), unit(-1.0, 1.0);
  for (int i = 0; i < 1500; ++i)
    m.points.emplace_back(coordinate(random), coordinate(random), coordinate(random));
  const double tolerance = mesh_check_duplicate_tolerance * std::sqrt(27.0);
  const int32_t originals = m.point_count();
  for (int i = 0; i < 600; ++i) {
    const Eigen::Vector3d& p = m.points[random() % originals];
    const Eigen::Vector3d offset(unit(random), unit(random), unit(random));
    const double scale = (i % 3 == 0) ? 0.0 : (i % 3 == 1 ? 0.5 : 2.0) * tolerance;
    m.points.push_back(p + scale * offset.normalized());
  }
  int64_t expected = 0;
  for (int32_t i = 0; i < m.point_count(); ++i)
    for (int32_t j = 0; j < i; ++j)
      if ((m.points[i] - m.points[j]).norm() <= tolerance) {
        ++expected;
        break;
      }
  ASSERT_GT(expected, 350);
  ASSERT_LT(expected, 600);
  EXPECT_EQ(mesh_check(m).duplicate_nodes, expected);
}

TEST(Conformity, DuplicateNodesStraddlingASearchCellWall) {
  // White-box: mirrors the cell size and origin of the duplicate search (mesh/conformity.cpp) to
  // put a near pair on both sides of a cell wall in x and y.
  HexMesh m;
  for (int i = 0; i < 8; ++i) m.points.emplace_back(i & 1, (i >> 1) & 1, (i >> 2) & 1);
  const double cell = 1.6180339887 / std::cbrt(10.0);
  const double wall = -0.3819660113 * cell + cell;
  const double tolerance = mesh_check_duplicate_tolerance * std::sqrt(3.0);
  m.points.emplace_back(wall - 0.3 * tolerance, wall - 0.3 * tolerance, 0.5);
  m.points.emplace_back(wall + 0.3 * tolerance, wall + 0.3 * tolerance, 0.5);
  EXPECT_EQ(mesh_check(m).duplicate_nodes, 1);
  m.points.back() = Eigen::Vector3d(wall + 0.8 * tolerance, wall + 0.8 * tolerance, 0.5);
  EXPECT_EQ(mesh_check(m).duplicate_nodes, 0);  // 1.6 sqrt(2) x tolerance apart
}

TEST(Conformity, CrackOfDuplicatedNodesLeavesCoincidentFaces) {
  HexMesh m = fixture_brick(2, 2, 1);
  // Hex 0 gets its own copies of its four nodes on x = 1. It still shares its nodes at x = 0,
  // y = 1 with hex 2, so the mesh stays one body and the crack is a gap: the faces at x = 1 and
  // the faces hex 0 shared with hex 2 (two of their nodes split), from both sides.
  for (int v : {1, 2, 5, 6}) {
    m.points.push_back(m.points[m.hexes[0][v]]);
    m.hexes[0][v] = m.point_count() - 1;
  }
  const MeshCheckReport r = mesh_check(m);
  EXPECT_EQ(r.bodies, 1);
  EXPECT_EQ(r.duplicate_nodes, 4);
  EXPECT_EQ(r.non_conformal_faces, 4);
  EXPECT_EQ(r.hanging_nodes, 0);  // coincident corners are duplicates, not T-junctions
  EXPECT_FALSE(r.conformal);
  // Cut right through (a row of two hexes, hex 1 with its own nodes on x = 1) the mesh falls
  // into two bodies glued face on face: an interface, not a defect.
  HexMesh cut = fixture_brick(2, 1, 1);
  for (int v : {0, 3, 4, 7}) {
    cut.points.push_back(cut.points[cut.hexes[1][v]]);
    cut.hexes[1][v] = cut.point_count() - 1;
  }
  const MeshCheckReport c = mesh_check(cut);
  EXPECT_EQ(c.bodies, 2);
  EXPECT_EQ(c.interface_faces, 1);
  EXPECT_EQ(c.interface_nodes, 4);
  EXPECT_EQ(c.duplicate_nodes, 0);
  EXPECT_EQ(c.non_conformal_faces, 0);
  EXPECT_TRUE(c.valid());
}

TEST(Conformity, RefusesBadIds) {
  HexMesh m = fixture_brick(1, 1, 1);
  m.hexes[0][3] = 99;
  EXPECT_THROW(mesh_check(m), InputError);
}

TEST(Conformity, BadIdsAreNamedByTheLowestHexOnAnyThreadCount) {
  HexMesh m = fixture_brick(41, 41, 41);  // 68,921 hexes: two chunks of the id validation
  m.hexes[68000][2] = m.hexes[68000][5];
  m.hexes[100][3] = m.point_count();
  for (int threads : {1, 2}) {
    try {
      mesh_check(m, nullptr, threads);
      ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()), "mesh: hex 100 refers to node " +
                                           std::to_string(m.point_count()) + ", expected 0.." +
                                           std::to_string(m.point_count() - 1));
    }
  }
}

TEST(Conformity, DuplicateNodesOnAnyThreadCount) {
  // 29,791 grid nodes (eight chunks of the search) and 300 copies of distinct nodes: at distance
  // 0 and 0.5 x the tolerance they are duplicates, at 2 x it they are not.
  HexMesh m = fixture_brick(30, 30, 30);
  const double tolerance = mesh_check_duplicate_tolerance * std::sqrt(3.0 * 30 * 30);
  for (int i = 0; i < 300; ++i) {
    const double scale = (i % 3 == 0) ? 0.0 : (i % 3 == 1 ? 0.5 : 2.0) * tolerance;
    m.points.push_back(m.points[97 * i] + scale * Eigen::Vector3d(1, 2, 2) / 3.0);
  }
  EXPECT_EQ(mesh_check(m, nullptr, 1).duplicate_nodes, 200);
  EXPECT_EQ(mesh_check(m, nullptr, 2).duplicate_nodes, 200);
}

TEST(Conformity, WholeReportIsTheSameOnAnyThreadCount) {
  // A 100 x 100 x 1 slab (20,400 boundary faces: its boundary edges are sorted in two halves on
  // two threads) with hexes (10, 11) and (11, 10) removed: hexes (10, 10) and (11, 11) then
  // touch along one edge only, which four boundary faces share, and the hole's eight walls are
  // off the slab's own surface.
  const HexMesh reference = fixture_brick(100, 100, 1);
  HexMesh m = reference;
  m.hexes.erase(m.hexes.begin() + fixture_brick_hex(100, 100, 10, 11, 0));  // the higher id first
  m.hexes.erase(m.hexes.begin() + fixture_brick_hex(100, 100, 11, 10, 0));
  const MeshCheckReport one = mesh_check(m, &reference, 1);
  EXPECT_EQ(one.hexes, 9998);
  EXPECT_EQ(one.boundary_faces, 20404);
  EXPECT_EQ(one.nonmanifold_boundary_edges, 1);
  EXPECT_EQ(one.non_conformal_faces, 8);
  EXPECT_NEAR(one.volume, 9998.0, 1e-9);
  for (int threads : {2, 3}) {
    const nlohmann::json a = one, b = mesh_check(m, &reference, threads);
    EXPECT_EQ(a.dump(), b.dump()) << threads << " threads";
  }
}

TEST(Conformity, DuplicateNodesInACrowdedCell) {
  // 3,000 extra points packed into a ball 1e-4 wide inside a 10^3 brick (a refined region is far
  // denser than the box's mean, so one search cell holds them all and is swept in x), among them
  // 100 copies at 0.5 x the tolerance of a point of the ball (duplicates), 100 at 2 x it (not),
  // and 50 copies that differ only in y (same x: the sweep must still compare them).
  HexMesh m = fixture_brick(10, 10, 10);
  const double tolerance = mesh_check_duplicate_tolerance * std::sqrt(3.0 * 10 * 10);
  std::mt19937 random(5);
  std::uniform_real_distribution<double> u(-5e-5, 5e-5);
  const int32_t ball = m.point_count();
  for (int i = 0; i < 3000; ++i)
    m.points.push_back(Eigen::Vector3d(5.3 + u(random), 4.7 + u(random), 5.1 + u(random)));
  for (int i = 0; i < 100; ++i) {
    m.points.push_back(m.points[ball + i] + 0.5 * tolerance * Eigen::Vector3d(1, 2, 2) / 3.0);
    m.points.push_back(m.points[ball + 1000 + i] +
                       2.0 * tolerance * Eigen::Vector3d(1, 2, 2) / 3.0);
  }
  for (int i = 0; i < 50; ++i)
    m.points.push_back(m.points[ball + 2000 + i] + Eigen::Vector3d(0, 0.5 * tolerance, 0));
  EXPECT_EQ(mesh_check(m, nullptr, 1).duplicate_nodes, 150);
  EXPECT_EQ(mesh_check(m, nullptr, 2).duplicate_nodes, 150);
}

TEST(Conformity, EmptyMesh) {
  const MeshCheckReport r = mesh_check(HexMesh{});
  EXPECT_EQ(r.hexes, 0);
  EXPECT_TRUE(r.conformal);
  EXPECT_DOUBLE_EQ(r.min_scaled_jacobian, 1.0);
}

TEST(Conformity, JsonCarriesEveryCount) {
  const MeshCheckReport r = mesh_check(brick_with_one_octree_split(), nullptr);
  const nlohmann::json j = r;
  EXPECT_EQ(j["hexes"], 9);
  // The hexes of the five non-conformal faces (the split hex's children and its neighbour),
  // the lowest first; the histogram holds every hex.
  EXPECT_FALSE(r.defect_hexes.empty());
  EXPECT_TRUE(std::is_sorted(r.defect_hexes.begin(), r.defect_hexes.end()));
  int64_t histogram_total = 0;
  for (int64_t c : r.scaled_jacobian_histogram) histogram_total += c;
  EXPECT_EQ(histogram_total, 9);
  EXPECT_EQ(r.scaled_jacobian_histogram[19], 9);  // all cubes
  EXPECT_EQ(j["non_conformal_faces"], 5);
  EXPECT_EQ(j["hanging_nodes"], 5);
  EXPECT_EQ(j["conformal"], false);
  EXPECT_EQ(j["valid"], false);
  for (const char* key :
       {"nodes", "inverted_hexes", "doublets", "nonmanifold_faces", "nonmanifold_boundary_edges",
        "duplicate_nodes", "unused_nodes", "boundary_faces", "min_scaled_jacobian",
        "mean_scaled_jacobian", "max_edge_ratio", "volume", "boundary_area", "first_inverted_hex",
        "reference_compared"})
    EXPECT_TRUE(j.contains(key)) << key;
}

TEST(ScaledJacobianHistogram, FixedBins) {
  const std::vector<int64_t> h =
      scaled_jacobian_histogram({1.0, 0.95, 0.3077, 0.0, -0.05, -1.0, -3.0, 2.0});
  ASSERT_EQ(h.size(), 20u);
  EXPECT_EQ(h[19], 3);  // 1.0, 0.95 and 2.0 (clamped)
  EXPECT_EQ(h[13], 1);  // 0.3077 in [0.3, 0.4)
  EXPECT_EQ(h[10], 1);  // 0.0 in [0, 0.1)
  EXPECT_EQ(h[9], 1);   // -0.05 in [-0.1, 0)
  EXPECT_EQ(h[0], 2);   // -1.0 and -3.0 (clamped)
  int64_t total = 0;
  for (int64_t v : h) total += v;
  EXPECT_EQ(total, 8);
}

}  // namespace
}  // namespace hexrefine
