#include "algorithms/refiners/sheet.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "algorithms/refiners/selective.hpp"
#include "algorithms/templates/template_engine.hpp"
#include "mesh/conformity.hpp"
#include "mesh/dual.hpp"
#include "mesh/error.hpp"
#include "mesh/generators.hpp"
#include "mesh/hex_convention.hpp"
#include "mesh/topology.hpp"
#include "tests/algorithms/refiners/refiner_suite.hpp"
#include "tests/fixtures.hpp"

namespace hexrefine {
namespace {

uint16_t edge_bits(std::initializer_list<int> edges) {
  uint16_t m = 0;
  for (int e : edges) m |= static_cast<uint16_t>(1u << e);
  return m;
}

// Boundary faces of `m` (from its topology) that do not lie on the surface of the box [lo, hi]:
// a hanging node or mismatched face templates leave such an open interior face. Adds the area
// of all boundary faces to `area`.
int interior_open_faces(const HexMesh& m, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                        double& area) {
  const HexTopology t = topology_build(m);
  const double tol = 1e-9;
  int open = 0;
  for (int32_t f : topology_boundary_faces(t)) {
    const auto& q = t.face_nodes[f];
    bool on_plane = false;
    for (int k = 0; k < 3 && !on_plane; ++k)
      for (double side : {lo[k], hi[k]}) {
        bool all = true;
        for (int32_t v : q) all = all && std::abs(m.points[v][k] - side) < tol;
        on_plane = on_plane || all;
      }
    open += !on_plane;
    const Eigen::Vector3d a = m.points[q[0]], b = m.points[q[1]], c = m.points[q[2]],
                          d = m.points[q[3]];
    area += 0.5 * ((b - a).cross(c - a).norm() + (c - a).cross(d - a).norm());
  }
  return open;
}

// What a conformal, valid mesh of the box [lo, hi] satisfies, checked from its topology:
// no non-manifold face, no open interior face, the boundary faces cover the box surface exactly
// once, no two points coincide, no unused point, and every corner Jacobian is positive.
void expect_conformal_box(const HexMesh& m, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  const HexTopology t = topology_build(m);
  ASSERT_TRUE(t.nonmanifold_faces.empty());
  const double tol = 1e-9;
  double area = 0;
  EXPECT_EQ(interior_open_faces(m, lo, hi, area), 0);
  const Eigen::Vector3d s = hi - lo;
  EXPECT_NEAR(area, 2 * (s.x() * s.y() + s.y() * s.z() + s.z() * s.x()), 1e-6);
  std::vector<std::array<double, 3>> pts;
  for (const auto& p : m.points) pts.push_back({p.x(), p.y(), p.z()});
  std::sort(pts.begin(), pts.end());
  int duplicates = 0;
  for (size_t i = 1; i < pts.size(); ++i) {
    bool same = true;
    for (int k = 0; k < 3; ++k) same = same && std::abs(pts[i][k] - pts[i - 1][k]) < tol;
    duplicates += same;
  }
  EXPECT_EQ(duplicates, 0);
  // Every point is used (no orphan node left by a template).
  std::vector<uint8_t> used(m.points.size(), 0);
  for (const auto& c : m.hexes)
    for (int32_t v : c) used[v] = 1;
  EXPECT_EQ(std::count(used.begin(), used.end(), 0), 0);
  int inverted = 0;
  for (const auto& c : m.hexes)
    for (int v = 0; v < 8; ++v) {
      Eigen::Vector3d d[3];
      for (int k = 0; k < 3; ++k) {
        const int e = hex_vertex_edges[v][k];
        const int w = hex_edges[e][0] == v ? hex_edges[e][1] : hex_edges[e][0];
        d[k] = (m.points[c[w]] - m.points[c[v]]) * (hex_corner[w][k] > hex_corner[v][k] ? 1 : -1);
      }
      inverted += d[0].cross(d[1]).dot(d[2]) <= 0;
    }
  EXPECT_EQ(inverted, 0);
}

// The project's independent checker (mesh/conformity.hpp) against the input mesh.
void expect_checker_valid(const HexMesh& out, const HexMesh& input) {
  const MeshCheckReport c = mesh_check(out, &input);
  EXPECT_TRUE(c.conformal);
  EXPECT_TRUE(c.valid());
  for (const std::string& d : mesh_check_defects(c)) ADD_FAILURE() << d;
}

void expect_conformal_brick(const HexMesh& m, int nx, int ny, int nz) {
  expect_conformal_box(m, Eigen::Vector3d::Zero(), Eigen::Vector3d(nx, ny, nz));
}

// The thesis' L-shaped case: hexes on the x-min and z-min surfaces of a 10x10x10 brick.
Targets l_shaped_targets(int n) {
  Targets t;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        if (i == 0 || k == 0) t.hexes.push_back(fixture_brick_hex(n, n, i, j, k));
  return t;
}

TEST(HexAxisPattern, DirectionalTemplatesByParallelSplitEdges) {
  EXPECT_EQ(hex_axis_pattern(0, 0), SheetPattern::none);
  EXPECT_EQ(hex_axis_pattern(edge_bits({1, 3, 8}), 0), SheetPattern::none);  // other axes only
  EXPECT_EQ(hex_axis_pattern(edge_bits({0}), 0), SheetPattern::one_to_five);
  EXPECT_EQ(hex_axis_pattern(edge_bits({0, 2}), 0), SheetPattern::one_to_four);  // face -z
  EXPECT_EQ(hex_axis_pattern(edge_bits({0, 4}), 0), SheetPattern::one_to_four);  // face -y
  EXPECT_EQ(hex_axis_pattern(edge_bits({0, 6}), 0), SheetPattern::multiply_connected);
  EXPECT_EQ(hex_axis_pattern(edge_bits({8, 10}), 2), SheetPattern::multiply_connected);
  EXPECT_EQ(hex_axis_pattern(edge_bits({9, 10}), 2), SheetPattern::one_to_four);  // face +x
  EXPECT_EQ(hex_axis_pattern(edge_bits({1, 3, 5}), 1), SheetPattern::multiply_connected);
  EXPECT_EQ(hex_axis_pattern(edge_bits({1, 3, 5, 7}), 1), SheetPattern::one_to_three);
  EXPECT_TRUE(hex_is_multiply_connected(edge_bits({0, 2, 4, 1, 3})));
  EXPECT_FALSE(hex_is_multiply_connected(edge_bits({0, 2, 1, 3})));  // a face: 1-4, 1-4
}

TEST(HexSplitMask, BothEndsMarked) {
  const HexMesh m = fixture_brick(1, 1, 1);
  std::vector<uint8_t> marked(8, 0);
  for (int v : {0, 1, 3}) marked[m.hexes[0][v]] = 1;  // local edges e0 (0-1) and e3 (0-3)
  EXPECT_EQ(hex_split_mask(m, marked, 0), edge_bits({0, 3}));
}

TEST(SheetMark, SingleTargetNeedsNoGrowth) {
  const HexMesh m = fixture_brick(3, 3, 3);
  const HexTopology t = topology_build(m);
  const SheetMarking mk = sheet_mark(m, t, {{fixture_brick_hex(3, 3, 1, 1, 1)}});
  EXPECT_EQ(mk.added_targets, 0);
  EXPECT_EQ(std::count(mk.node_marked.begin(), mk.node_marked.end(), 1), 8);
  EXPECT_EQ(std::count(mk.hex_target.begin(), mk.hex_target.end(), 1), 1);
}

TEST(SheetMark, TwoTargetsAcrossAnEdgeAddTheTwoCornerHexes) {
  // In a 2x2x1 brick, targets (0,0) and (1,1): hexes (1,0) and (0,1) share a face with each,
  // so three of their z-parallel edges are split (multiply connected): both are added.
  const HexMesh m = fixture_brick(2, 2, 1);
  const HexTopology t = topology_build(m);
  const SheetMarking mk =
      sheet_mark(m, t, {{fixture_brick_hex(2, 2, 0, 0, 0), fixture_brick_hex(2, 2, 1, 1, 0)}});
  EXPECT_EQ(mk.added_targets, 2);
  EXPECT_EQ(std::count(mk.hex_target.begin(), mk.hex_target.end(), 1), 4);
}

TEST(SheetMark, LShapedCaseGrowsToTheWholeBrick) {
  // Thesis Table G-1: Harris' sheet refinement refines the whole 10x10x10 brick.
  const HexMesh m = fixture_brick(10, 10, 10);
  const HexTopology t = topology_build(m);
  const Targets targets = l_shaped_targets(10);
  ASSERT_EQ(targets.hexes.size(), 190u);
  const SheetMarking mk = sheet_mark(m, t, targets);
  EXPECT_EQ(mk.added_targets, 810);
  EXPECT_EQ(std::count(mk.hex_target.begin(), mk.hex_target.end(), 1), 1000);
}

TEST(SheetRefine, SharedRefinerSuite) {
  const std::vector<int64_t> sizes =
      refiner_suite_run([](const HexMesh& m, const Targets& t, const RefineOptions& o) {
        return sheet_refine(m, t, o);
      });
  ASSERT_EQ(sizes.size(), 6u);
  EXPECT_EQ(sizes[2], 27000);  // L-shaped: grown to the whole brick (thesis G-1)
  EXPECT_EQ(sizes[4], 55272);  // gear teeth: the selective refiner's count (thesis H-1)
}

TEST(SheetRefine, RejectsInvalidTargets) {
  const HexMesh m = fixture_brick(2, 2, 2);
  EXPECT_THROW(sheet_refine(m, {{8}}, {}), InputError);
  EXPECT_THROW(sheet_refine(m, {{3, 1}}, {}), InputError);
  EXPECT_THROW(sheet_refine(m, {{1, 1}}, {}), InputError);
  RefineOptions zero;
  zero.passes = 0;
  EXPECT_THROW(sheet_refine(m, {{1}}, zero), InputError);
}

TEST(SheetRefine, NoTargetsLeavesTheMeshUnchanged) {
  const HexMesh m = fixture_brick(2, 2, 2);
  const RefineResult r = sheet_refine(m, {}, {});
  EXPECT_EQ(r.mesh.hexes, m.hexes);
  EXPECT_EQ(r.mesh.point_count(), m.point_count());
  EXPECT_EQ(r.stats.hexes_created, 0);
  EXPECT_EQ(r.stats.sheet_passes, 0);
  ASSERT_NE(mesh_find_attribute(r.mesh, attribute_template_tag), nullptr);
}

class FullBrick : public ::testing::TestWithParam<int> {};

TEST_P(FullBrick, TwentySevenPerHexThroughThreeRounds) {
  const int n = GetParam();
  const HexMesh m = fixture_brick(n, n, n);
  std::vector<int64_t> round_hexes;
  const RefineResult r =
      sheet_refine(m, targets_all_hexes(m), {}, [&](const HexMesh& inter, int round) {
        EXPECT_EQ(round, static_cast<int>(round_hexes.size()));
        round_hexes.push_back(inter.hex_count());
        expect_conformal_brick(inter, n, n, n);  // conformal after every round
      });
  const int64_t n3 = int64_t(n) * n * n;
  EXPECT_EQ(round_hexes, (std::vector<int64_t>{3 * n3, 9 * n3, 27 * n3}));
  EXPECT_EQ(r.mesh.hex_count(), 27 * n3);
  EXPECT_EQ(r.mesh.point_count(), (3 * n + 1) * (3 * n + 1) * (3 * n + 1));
  EXPECT_EQ(r.stats.hexes_created, 39 * n3);
  EXPECT_EQ(r.stats.hexes_deleted, 13 * n3);
  EXPECT_EQ(r.stats.sheet_passes, 3 * n);  // every dual sheet of the brick once
  EXPECT_EQ(r.stats.added_targets, 0);
  EXPECT_EQ(r.stats.self_intersection_cases, 0);
  EXPECT_EQ(r.stats.final_hexes, 27 * n3);
  EXPECT_EQ(r.stats.hexes_per_template.at("sheet"), 27 * n3);
  for (const char* phase : {"marking", "growth", "sheets", "total"})
    EXPECT_EQ(r.stats.phase_seconds.count(phase), 1u) << phase;
  const auto& level = *mesh_find_attribute(r.mesh, attribute_refinement_level);
  EXPECT_TRUE(std::all_of(level.begin(), level.end(), [](int32_t l) { return l == 1; }));
  // Every child is a cube of side 1/3.
  for (int32_t h = 0; h < r.mesh.hex_count(); h += 7) {
    const auto p = hex_points(r.mesh, h);
    EXPECT_NEAR((p[6] - p[0]).norm(), std::sqrt(3.0) / 3, 1e-12);
  }
  expect_conformal_brick(r.mesh, n, n, n);
  expect_checker_valid(r.mesh, m);
  EXPECT_NEAR(mesh_check(r.mesh).min_scaled_jacobian, 1.0, 1e-12);
}

INSTANTIATE_TEST_SUITE_P(Sizes, FullBrick, ::testing::Values(1, 2, 3, 5));

TEST(SheetRefine, LShapedCaseRefinesTheWholeBrick) {
  const HexMesh m = fixture_brick(10, 10, 10);
  const RefineResult r = sheet_refine(m, l_shaped_targets(10), {});
  EXPECT_EQ(r.mesh.hex_count(), 27000);  // thesis Table G-1
  EXPECT_EQ(r.stats.added_targets, 810);
  EXPECT_EQ(r.stats.hexes_created, 39000);
  EXPECT_EQ(r.stats.hexes_deleted, 13000);
  expect_conformal_brick(r.mesh, 10, 10, 10);
  expect_checker_valid(r.mesh, m);
  EXPECT_NEAR(mesh_check(r.mesh).min_scaled_jacobian, 1.0, 1e-12);  // Table G-1: 1.0
}

TEST(SheetRefine, PassesRefineTheDescendantsOfTheTargetsAgain) {
  // Thesis Table H-2's set-up: 4x4x4 brick, left surface. One pass: 16 targets x 27, their 16
  // face neighbours x 13 (1-4 then three 1-4s), 32 untouched = 672.
  const HexMesh m = fixture_brick(4, 4, 4);
  Targets left;
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 4; ++j) left.hexes.push_back(fixture_brick_hex(4, 4, 0, j, k));
  std::sort(left.hexes.begin(), left.hexes.end());
  const RefineResult one = sheet_refine(m, left, {});
  EXPECT_EQ(one.mesh.hex_count(), 16 * 27 + 16 * 13 + 32);
  RefineOptions two_passes;
  two_passes.passes = 2;
  const RefineResult two = sheet_refine(m, left, two_passes);
  // The second pass refines the 432 children of the targets again, with their new transitions:
  // a regression value of this implementation (three passes give 332,448; thesis Table H-2
  // reports 332,864 for Harris' implementation).
  EXPECT_EQ(two.mesh.hex_count(), 13632);
  const auto& level = *mesh_find_attribute(two.mesh, attribute_refinement_level);
  EXPECT_EQ(*std::max_element(level.begin(), level.end()), 2);
  expect_checker_valid(two.mesh, m);
}

TEST(SheetRefine, AttributesInheritedAndUntouchedHexesKept) {
  HexMesh m = fixture_brick(3, 1, 1);
  m.attributes.push_back({"block_id", {7, 8, 9}});
  // Targets 0 and 2 with hex 1 between: all nodes of hex 1 are target nodes, so as in Harris'
  // node marking all its edges are split and it is fully refined too (not counted as added).
  const RefineResult r = sheet_refine(m, {{0, 2}}, {});
  EXPECT_EQ(r.stats.added_targets, 0);
  EXPECT_EQ(r.mesh.hex_count(), 81);
  const auto& block = *mesh_find_attribute(r.mesh, "block_id");
  EXPECT_EQ(block.front(), 7);
  EXPECT_EQ(block[27], 8);
  EXPECT_EQ(block.back(), 9);
  expect_conformal_brick(r.mesh, 3, 1, 1);
}

TEST(SheetRefine, FaceTransitionIsOneToThirteenThroughTwoDirections) {
  // Target 0 of a 3x1x1 brick: hex 1 shares a face with it (1-4 in y, then the three children
  // on that face 1-4 in z: 3 * 4 + 1 = 13, like the 1-13 template); hex 2 is untouched.
  const HexMesh m = fixture_brick(3, 1, 1);
  std::vector<int64_t> round_hexes;
  const RefineResult r = sheet_refine(m, {{0}}, {}, [&](const HexMesh& inter, int) {
    round_hexes.push_back(inter.hex_count());
    expect_conformal_brick(inter, 3, 1, 1);
  });
  EXPECT_EQ(r.mesh.hex_count(), 27 + 13 + 1);
  // Rounds x, y, z: the target's slabs (3), then y (9 + hex 1's 1-4), then z.
  EXPECT_EQ(round_hexes, (std::vector<int64_t>{3 + 1 + 1, 9 + 4 + 1, 41}));
  EXPECT_EQ(r.stats.added_targets, 0);
  EXPECT_EQ(r.stats.hexes_per_template.at("untouched"), 1);
  expect_conformal_brick(r.mesh, 3, 1, 1);
}

TEST(SheetRefine, EdgeTransitionIsOneToFive) {
  // Target (0,0,0) of a 2x2x1 brick: hexes (1,0,0) and (0,1,0) are face transitions (13 each),
  // hex (1,1,0) shares only the z-edge at (1,1): a 1-5 in z.
  const HexMesh m = fixture_brick(2, 2, 1);
  const RefineResult r = sheet_refine(m, {{0}}, {});
  EXPECT_EQ(r.mesh.hex_count(), 27 + 13 + 13 + 5);
  EXPECT_EQ(r.stats.added_targets, 0);
  expect_conformal_brick(r.mesh, 2, 2, 1);
}

// n^3 brick with interior nodes jittered (generate_brick: boundary nodes stay on the box, so
// expect_conformal_box applies).
HexMesh jittered_brick(int n, double amount, uint32_t seed) {
  BrickParams p;
  p.dims = {n, n, n};
  p.size = {double(n), double(n), double(n)};
  p.jitter = amount;
  p.seed = seed;
  return generate_brick(p);
}

// Checks one refinement: conformal and valid, counts consistent, and the added targets are
// exactly those of the growth on the original mesh, after which no transition is multiply
// connected.
void expect_sheet_case(const HexMesh& m, int n, const Targets& targets, const std::string& what) {
  SCOPED_TRACE(what);
  int rounds = 0;
  const RefineResult r = sheet_refine(m, targets, {}, [&](const HexMesh& inter, int) {
    ++rounds;  // the mesh is conformal after every round, not only at the end
    expect_conformal_box(inter, Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(n));
  });
  EXPECT_GE(rounds, targets.hexes.empty() ? 0 : 3);
  expect_conformal_box(r.mesh, Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(n));
  expect_checker_valid(r.mesh, m);
  EXPECT_EQ(r.mesh.hex_count(), m.hex_count() + r.stats.hexes_created - r.stats.hexes_deleted);
  const HexTopology t = topology_build(m);
  const SheetMarking mk = sheet_mark(m, t, targets);
  EXPECT_EQ(r.stats.added_targets, mk.added_targets);
  for (int32_t h = 0; h < m.hex_count(); ++h) {
    if (!mk.hex_target[h]) {
      EXPECT_FALSE(hex_is_multiply_connected(hex_split_mask(m, mk.node_marked, h)));
    }
  }
  // Every (grown) target becomes 27 hexes, so the mesh grows by at least 26 per target.
  const int64_t targets_after = std::count(mk.hex_target.begin(), mk.hex_target.end(), 1);
  EXPECT_GE(r.mesh.hex_count(), m.hex_count() + 26 * targets_after);
}

TEST(SheetRefine, OneSheetPerPassGivesTheSameMeshConformalAfterEveryPass) {
  // Harris' order (one sheet piece per pass) against the grouped rounds: the same counts, and
  // the mesh is conformal after every single sheet pass.
  for (uint32_t seed : {3u, 7u, 12u}) {
    SCOPED_TRACE(seed);
    const int n = 4;
    const HexMesh m = jittered_brick(n, 0.2, seed);
    std::mt19937 rng(seed);
    std::bernoulli_distribution pick(0.15);
    Targets t;
    for (int32_t h = 0; h < m.hex_count(); ++h)
      if (pick(rng)) t.hexes.push_back(h);
    const RefineResult grouped = sheet_refine(m, t, {});
    SheetControl one;
    one.one_sheet_per_round = true;
    int passes = 0;
    one.observer = [&](const HexMesh& inter, int) {
      ++passes;
      double area = 0;
      EXPECT_EQ(
          interior_open_faces(inter, Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(n), area),
          0);
    };
    const RefineResult single = sheet_refine(m, t, {}, one);
    EXPECT_EQ(passes, single.stats.sheet_passes);
    EXPECT_EQ(single.stats.sheet_passes, grouped.stats.sheet_passes);
    EXPECT_GT(passes, 3);
    EXPECT_EQ(single.mesh.hex_count(), grouped.mesh.hex_count());
    EXPECT_EQ(single.stats.hexes_created, grouped.stats.hexes_created);
    // Same nodes too; their positions may differ in transition hexes, where the order of the
    // directions changes where the 1-4 / 1-5 transition nodes of later passes land.
    EXPECT_EQ(single.mesh.point_count(), grouped.mesh.point_count());
    expect_checker_valid(single.mesh, m);
  }
}

TEST(SheetRefine, RadialRegionsAroundACorner) {
  // Hexes whose centroid lies within a fixed radius of the corner (n, n, n), as thesis Table
  // G-3 (brick size fixed at 1, interval n growing).
  for (int n : {3, 4, 5, 6, 8}) {
    const HexMesh m = fixture_brick(n, n, n, 1.0);
    Targets t;
    for (int32_t h = 0; h < m.hex_count(); ++h)
      if ((hex_centroid(m, h) - Eigen::Vector3d::Constant(n)).norm() < 0.45 * n)
        t.hexes.push_back(h);
    ASSERT_FALSE(t.hexes.empty());
    expect_sheet_case(m, n, t, "radial n=" + std::to_string(n));
  }
}

TEST(SheetRefine, RandomTargetsOnJitteredBricks) {
  int cases = 0, grown = 0;
  for (int n : {4, 6}) {
    for (uint32_t seed = 1; seed <= 100; ++seed) {
      const HexMesh m = jittered_brick(n, 0.2, seed);
      std::mt19937 rng(1000 + seed);
      std::bernoulli_distribution pick(seed % 3 == 0 ? 0.3 : 0.08);
      Targets t;
      for (int32_t h = 0; h < m.hex_count(); ++h)
        if (pick(rng)) t.hexes.push_back(h);
      const RefineResult r = sheet_refine(m, t, {});
      grown += r.stats.added_targets > 0;
      expect_sheet_case(m, n, t, "n=" + std::to_string(n) + " seed=" + std::to_string(seed));
      ++cases;
      if (HasFailure()) return;
    }
  }
  EXPECT_EQ(cases, 200);
  EXPECT_GT(grown, 50);  // the random sets do exercise the growth
}

TEST(ExpectConformalBox, DetectsAHangingFace) {
  // The check above must be able to fail: one hex of two split into slabs across the shared
  // face's edges leaves hanging nodes.
  const HexMesh m = fixture_brick(2, 1, 1);
  const HexTopology t = topology_build(m);
  int8_t across_y = -1;  // an orientation splitting the y-parallel edges
  for (int i = 0; i < 48 && across_y < 0; ++i)
    if (cube_symmetry_edge_mask(cube_symmetries()[i], template_split_edges(template_1_3())) ==
        edge_bits({1, 3, 5, 7}))
      across_y = static_cast<int8_t>(i);
  RefinementPlan plan;
  plan.uses.push_back({HexId{0}, &template_1_3(), across_y});
  HexMesh broken = plan_apply(m, t, plan).mesh;
  ASSERT_EQ(broken.hex_count(), 4);
  double area = 0;
  // The three slabs' faces on one side, the whole face on the other.
  EXPECT_EQ(interior_open_faces(broken, Eigen::Vector3d::Zero(), Eigen::Vector3d(2, 1, 1), area),
            4);
  EXPECT_NEAR(area, 10.0 + 2.0, 1e-12);
}

TEST(SheetRefine, CompositesGiveTheRoundByRoundMesh) {
  // The composite replay against the rounds on the whole region: the same outcome (result or
  // refusal), counts, node count and a valid conformal mesh; on an unjittered brick the same
  // points (up to rounding).
  SheetControl rounds;
  rounds.composites = false;
  int compared = 0, refused = 0;
  auto compare = [&](const HexMesh& m, const Targets& t, bool same_points,
                     const std::string& what) {
    SCOPED_TRACE(what);
    std::string error_a, error_b;
    RefineResult a, b;
    try {
      a = sheet_refine(m, t, refine_options_trilinear());
    } catch (const OperationError& e) {
      error_a = e.what();
    }
    try {
      b = sheet_refine(m, t, {}, rounds);
    } catch (const OperationError& e) {
      error_b = e.what();
    }
    ASSERT_EQ(error_a.empty(), error_b.empty()) << error_a << " | " << error_b;
    if (!error_a.empty()) {
      ++refused;
      return;
    }
    EXPECT_EQ(a.mesh.hex_count(), b.mesh.hex_count());
    EXPECT_EQ(a.mesh.point_count(), b.mesh.point_count());
    EXPECT_EQ(a.stats.hexes_created, b.stats.hexes_created);
    EXPECT_EQ(a.stats.hexes_deleted, b.stats.hexes_deleted);
    EXPECT_EQ(a.stats.sheet_passes, b.stats.sheet_passes);
    EXPECT_EQ(a.stats.added_targets, b.stats.added_targets);
    EXPECT_TRUE(mesh_check(a.mesh).valid());
    if (same_points) {
      auto sorted = [](std::vector<Eigen::Vector3d> p) {
        for (auto& x : p)
          for (int k = 0; k < 3; ++k) x[k] = std::round(x[k] * 1e9) / 1e9;
        std::sort(p.begin(), p.end(), [](const auto& x, const auto& y) {
          return std::lexicographical_compare(x.data(), x.data() + 3, y.data(), y.data() + 3);
        });
        return p;
      };
      EXPECT_EQ(sorted(a.mesh.points), sorted(b.mesh.points));
    }
    ++compared;
  };
  for (uint32_t seed = 1; seed <= 30; ++seed) {
    const HexMesh plain = fixture_brick(5, 5, 5);
    const HexMesh jittered = jittered_brick(5, 0.2, seed);
    std::mt19937 rng(seed);
    std::bernoulli_distribution pick(0.05 + 0.01 * (seed % 10));
    Targets t;
    for (int32_t h = 0; h < plain.hex_count(); ++h)
      if (pick(rng)) t.hexes.push_back(h);
    compare(plain, t, true, "brick seed " + std::to_string(seed));
    compare(jittered, t, false, "jittered seed " + std::to_string(seed));
  }
  TwistedRingParams p;
  p.section_intervals = 2;
  const HexMesh ring = generate_twisted_ring(p);
  for (uint32_t seed = 1; seed <= 20; ++seed) {
    std::mt19937 rng(seed);
    std::bernoulli_distribution pick(0.1 + 0.02 * (seed % 10));
    Targets t;
    for (int32_t h = 0; h < ring.hex_count(); ++h)
      if (pick(rng)) t.hexes.push_back(h);
    compare(ring, t, false, "ring seed " + std::to_string(seed));
  }
  EXPECT_EQ(compared + refused, 80);
  EXPECT_GT(compared, 60);
}

TEST(SheetRefine, InvertedInputIsRefusedByBothPaths) {
  // An inside-out input hex is bad input (refine_input_validate), whether the rounds run as
  // composites or one by one; allow_inverted refines it anyway.
  HexMesh m = fixture_brick(2, 1, 1);
  for (int v = 0; v < 4; ++v) std::swap(m.hexes[1][v], m.hexes[1][v + 4]);
  Targets all{{0, 1}};
  EXPECT_THROW(sheet_refine(m, all, {}), InputError);
  SheetControl rounds;
  rounds.composites = false;
  EXPECT_THROW(sheet_refine(m, all, {}, rounds), InputError);
  RefineOptions allow;
  allow.allow_inverted = true;
  EXPECT_EQ(sheet_refine(m, all, allow).mesh.hex_count(), 54);
}

// Runs the selective refiner, or skips while it is not implemented on this branch.
#define SELECTIVE_OR_SKIP(result, ...)                                             \
  RefineResult result;                                                             \
  try {                                                                            \
    result = selective_refine(__VA_ARGS__);                                        \
  } catch (const OperationError& e) {                                              \
    if (std::string(e.what()).find("not implemented") != std::string::npos)        \
      GTEST_SKIP() << "selective refiner not implemented yet: comparison pending"; \
    throw;                                                                         \
  }

TEST(SheetVsSelective, FullBrickSameCountAndQuality) {
  const HexMesh m = fixture_brick(4, 4, 4);
  const RefineResult sheet = sheet_refine(m, targets_all_hexes(m), {});
  SELECTIVE_OR_SKIP(selective, m, targets_all_hexes(m), RefineOptions{});
  EXPECT_EQ(sheet.mesh.hex_count(), selective.mesh.hex_count());
  EXPECT_NEAR(mesh_check(sheet.mesh).min_scaled_jacobian,
              mesh_check(selective.mesh).min_scaled_jacobian, 1e-12);
}

Targets gear_teeth(const HexMesh& gear) {
  Targets t;
  const auto& block = *mesh_find_attribute(gear, attribute_block_id);
  for (int32_t h = 0; h < gear.hex_count(); ++h)
    if (block[h] == gear_block_teeth) t.hexes.push_back(h);
  return t;
}

TEST(SheetRefine, GearTeeth) {
  GearParams p;
  p.teeth = 6;  // a smaller gear than the thesis' (24 teeth) keeps the test fast
  const HexMesh gear = generate_gear(p);
  const RefineResult r = sheet_refine(gear, gear_teeth(gear), {});
  // The teeth stand on the body with no multiply-connected transition (thesis Table H-1).
  EXPECT_EQ(r.stats.added_targets, 0);
  EXPECT_EQ(r.stats.self_intersection_cases, 0);
  expect_checker_valid(r.mesh, gear);
  EXPECT_EQ(r.mesh.hex_count(), gear.hex_count() + r.stats.hexes_created - r.stats.hexes_deleted);
}

TEST(SheetVsSelective, GearTeethSameCount) {
  GearParams p;
  p.teeth = 6;
  const HexMesh gear = generate_gear(p);
  const RefineResult sheet = sheet_refine(gear, gear_teeth(gear), {});
  SELECTIVE_OR_SKIP(selective, gear, gear_teeth(gear), RefineOptions{});
  EXPECT_EQ(sheet.mesh.hex_count(), selective.mesh.hex_count());
}

}  // namespace
}  // namespace hexrefine
