/// \file
/// algorithms/placement/node_joint_ascent.hpp: the joint ascent raises the minimum where
/// node-by-node sweeps stop, never lowers it, moves only free nodes, and gives the same mesh on any
/// number of threads.

#include "algorithms/placement/node_joint_ascent.hpp"

#include <gtest/gtest.h>

#include "algorithms/pipeline/pipeline.hpp"
#include "fixtures.hpp"
#include "mesh/io.hpp"
#include "mesh/quality.hpp"
#include "mesh/selection.hpp"
#include "mesh/topology.hpp"
#include "tests/cli_runner.hpp"

namespace hexrefine {
namespace {

/// Every interior node of `m` free, every hex a candidate.
NodeProblem interior_problem(const HexMesh& m) {
  const HexTopology topology = topology_build(m, TopologyParts::faces);
  std::vector<uint8_t> on_boundary(m.points.size(), 0);
  for (int32_t f : topology_boundary_faces(topology))
    for (int32_t n : topology.face_nodes[f]) on_boundary[n] = 1;
  NodeProblem problem;
  for (int32_t n = 0; n < m.point_count(); ++n)
    if (!on_boundary[n]) {
      problem.nodes.push_back(n);
      problem.slides.push_back(NodeSlide{});
    }
  std::vector<int32_t> all(m.hexes.size());
  for (int32_t h = 0; h < m.hex_count(); ++h) all[h] = h;
  node_problem_connect(problem, m, all);
  return problem;
}

/// The real-mesh study's sphere region of the shared sphere mesh, selective, optimized placement
/// by the sweeps alone (no joint ascent in placement or smoothing).
PipelineOptions sphere_case(const HexMesh& input) {
  PipelineOptions o;
  o.method = "selective";
  o.targets = select_hexes(input, {"sphere:-4.70965e-05,-2.09346e-06,-5.62482e-05,0.259609"}).hexes;
  o.refine.placement.joint_iterations = 0;
  o.smoothing.joint_iterations = 0;
  return o;
}

/// That case refined, unsmoothed: its worst hexes are 1-13 children of flat boundary parents
/// (0.25 x 0.125 x 0.25), each held at 0.360161 (their reference positions; 0.384111 from the
/// thesis' positions optimised) by four corners that depend on different nodes.
HexMesh refined_sphere() {
  const HexMesh m = mesh_read(shared_mesh("sphere_conforming.mesh"));
  return pipeline_run(m, sphere_case(m)).mesh;
}

TEST(NodeJointAscent, RaisesTheMinimumWhereTheSweepsStop) {
  const HexMesh input = mesh_read(shared_mesh("sphere_conforming.mesh"));
  PipelineOptions o = sphere_case(input);
  o.smooth = true;
  const PipelineResult sweeps = pipeline_run(input, o);
  ASSERT_TRUE(sweeps.smoothed_check);
  // The sweeps cannot move any node of those children without lowering one of the four, in
  // placement (new nodes) or in smoothing (every node of the region).
  EXPECT_NEAR(sweeps.check.min_scaled_jacobian, 0.360161, 1e-6);
  EXPECT_NEAR(sweeps.smoothed_check->min_scaled_jacobian, 0.360161, 1e-6);
  o.smoothing.joint_iterations = 100;
  const PipelineResult smoothed = pipeline_run(input, o);
  ASSERT_TRUE(smoothed.smoothed_check);
  EXPECT_TRUE(smoothed.smoothed_check->valid());
  EXPECT_GT(smoothed.smoothed_check->min_scaled_jacobian, 0.50);
  ASSERT_TRUE(smoothed.smoothing);
  EXPECT_GT(smoothed.smoothing->joint_iterations, 10);
  // In placement the input's nodes stay: less room, still a long way up (the worst band's
  // children: 1-5 children of the same parents end at 0.4346).
  o.refine.placement.joint_iterations = 100;
  o.smooth = false;
  const PipelineResult placed = pipeline_run(input, o);
  EXPECT_TRUE(placed.check.valid());
  EXPECT_GT(placed.check.min_scaled_jacobian, 0.43);
  EXPECT_GT(placed.stats.placement.joint_iterations, 10);
}

TEST(NodeJointAscent, MovesOnlyFreeNodesAndNeverLowersTheMinimum) {
  const HexMesh start = refined_sphere();
  HexMesh m = start;
  NodeProblem problem = interior_problem(m);
  // Half the interior nodes slide instead (on no geometry: they must simply stay).
  for (size_t i = 0; i < problem.slides.size(); i += 2) problem.slides[i].kind = SlideKind::patch;
  const JointAscentStats stats = nodes_ascend_jointly(m, problem, JointAscentOptions{});
  EXPECT_NEAR(stats.min_before, 0.360161, 1e-6);
  EXPECT_GE(stats.min_after, stats.min_before);
  EXPECT_GE(mesh_min_scaled_jacobian(m), mesh_min_scaled_jacobian(start));
  // Its variables: free nodes only, those around the worst hexes (378 of the 384 free).
  EXPECT_LE(stats.free_nodes, static_cast<int64_t>(problem.nodes.size() / 2));
  EXPECT_GT(stats.free_nodes, static_cast<int64_t>(problem.nodes.size() / 4));
  int moved = 0;
  std::vector<uint8_t> free(m.points.size(), 0);
  for (size_t i = 0; i < problem.nodes.size(); ++i)
    free[problem.nodes[i]] = problem.slides[i].kind == SlideKind::free;
  for (int32_t n = 0; n < m.point_count(); ++n) {
    if (!free[n]) {
      EXPECT_EQ(m.points[n], start.points[n]) << "node " << n;
    }
    moved += m.points[n] != start.points[n];
  }
  EXPECT_GT(moved, 0);
  EXPECT_EQ(m.hexes, start.hexes);
}

/// A 4 x 4 x 2 brick with a curved bottom, z = bottom_curvature x y (every bottom quad is a
/// bilinear patch of that surface exactly), whose 9 inner bottom nodes slide on the bottom quads
/// around them and whose 9 inner nodes of the middle layer are free; bottom node (2, 2, 0) (moved
/// along the surface) and the node above it were pushed 0.4 along x and y: the hexes around them
/// are sheared.
constexpr double bottom_curvature = 0.05;
struct ShearedBrick {
  HexMesh mesh;
  NodeProblem problem;
};
ShearedBrick sheared_brick() {
  ShearedBrick b{fixture_brick(4, 4, 2), {}};
  const auto id = [](int i, int j, int k) { return i + 5 * (j + 5 * k); };
  for (int j = 0; j <= 4; ++j)
    for (int i = 0; i <= 4; ++i) b.mesh.points[id(i, j, 0)].z() = bottom_curvature * i * j;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i)
      b.problem.geometry.patches.push_back(
          Quad{b.mesh.points[id(i, j, 0)], b.mesh.points[id(i + 1, j, 0)],
               b.mesh.points[id(i + 1, j + 1, 0)], b.mesh.points[id(i, j + 1, 0)]});
  std::vector<std::pair<int32_t, NodeSlide>> movable;
  for (int k = 0; k < 2; ++k)
    for (int j = 1; j < 4; ++j)
      for (int i = 1; i < 4; ++i) {
        NodeSlide slide;
        if (k == 0) {
          slide.kind = SlideKind::patches;
          slide.first = static_cast<int32_t>(b.problem.geometry.items.size());
          for (int jj : {j - 1, j})
            for (int ii : {i - 1, i}) b.problem.geometry.items.push_back(ii + 4 * jj);
          slide.count = 4;
        }
        movable.push_back({id(i, j, k), slide});
      }
  std::sort(movable.begin(), movable.end(),
            [](const auto& x, const auto& y) { return x.first < y.first; });
  for (const auto& [node, slide] : movable) {
    b.problem.nodes.push_back(node);
    b.problem.slides.push_back(slide);
  }
  std::vector<int32_t> all(b.mesh.hexes.size());
  for (int32_t h = 0; h < b.mesh.hex_count(); ++h) all[h] = h;
  node_problem_connect(b.problem, b.mesh, all);
  for (int k : {0, 1}) b.mesh.points[id(2, 2, k)] += Eigen::Vector3d(0.4, 0.4, 0);
  b.mesh.points[id(2, 2, 0)].z() = bottom_curvature * 2.4 * 2.4;
  return b;
}

TEST(NodeJointAscent, SlidingNodesMoveOnTheirSlidesWhenAsked) {
  JointAscentOptions options;
  options.band = 2;
  options.max_edge_ratio = 0;
  ShearedBrick held = sheared_brick();
  const HexMesh start = held.mesh;
  const JointAscentStats without = nodes_ascend_jointly(held.mesh, held.problem, options);
  EXPECT_EQ(without.free_nodes, 9);
  EXPECT_EQ(without.sliding_nodes, 0);
  for (size_t i = 0; i < held.problem.nodes.size(); ++i)
    if (held.problem.slides[i].kind != SlideKind::free) {
      EXPECT_EQ(held.mesh.points[held.problem.nodes[i]], start.points[held.problem.nodes[i]]);
    }

  options.slide = true;
  ShearedBrick slid = sheared_brick();
  const JointAscentStats with = nodes_ascend_jointly(slid.mesh, slid.problem, options);
  EXPECT_EQ(with.free_nodes, 9);
  EXPECT_EQ(with.sliding_nodes, 9);
  EXPECT_DOUBLE_EQ(with.min_before, without.min_before);
  EXPECT_LT(with.min_before, 0.8);
  // Only the sliding bottom node can take the shear out of the bottom layer.
  EXPECT_GT(with.min_after, without.min_after + 0.1);
  EXPECT_GT(with.min_after, 0.95);
  // On the curved bottom, within the four quads around each: a tangent step alone would leave it.
  int moved = 0;
  for (size_t i = 0; i < slid.problem.nodes.size(); ++i) {
    if (slid.problem.slides[i].kind == SlideKind::free) continue;
    const Eigen::Vector3d p = slid.mesh.points[slid.problem.nodes[i]];
    moved += p != start.points[slid.problem.nodes[i]];
    EXPECT_NEAR(p.z(), bottom_curvature * p.x() * p.y(), 1e-12) << "node " << i;
    const int32_t home_i = slid.problem.nodes[i] % 5, home_j = slid.problem.nodes[i] / 5 % 5;
    EXPECT_LE(std::abs(p.x() - home_i), 1 + 1e-12) << "node " << i;
    EXPECT_LE(std::abs(p.y() - home_j), 1 + 1e-12) << "node " << i;
    SlideState state;
    EXPECT_LT((slide_project(slid.problem.slides[i], slid.problem.geometry, p, state) - p).norm(),
              1e-12)
        << "node " << i;
  }
  EXPECT_GT(moved, 0);
  EXPECT_GE(mesh_min_scaled_jacobian(slid.mesh), with.min_after);
}

TEST(NodeJointAscent, AHexAtItsEdgeRatioCapDoesNotStopTheAscent) {
  // A cap just below the largest edge ratio of the start: the most stretched hexes start at
  // their own cap (hex_edge_ratio_cap), as after sweeps that pushed them there. A step that nears
  // a cap is steered along it by the cap samples (a step past it is still infeasible), so the
  // ascent rises all the same, and no hex ends past its cap. Without them it stops there.
  HexMesh m = refined_sphere();
  const HexMesh start = m;
  const NodeProblem problem = interior_problem(m);
  double largest = 0;
  for (int32_t h = 0; h < m.hex_count(); ++h)
    largest = std::max(largest, hex_edge_ratio(hex_points(m, h)));
  JointAscentOptions options;
  options.max_edge_ratio = 0.99 * largest;
  HexMesh walled = m;
  const JointAscentStats wall = nodes_ascend_jointly(walled, problem, options);
  EXPECT_LT(wall.min_after, wall.min_before + 0.001);  // stopped at the cap
  options.cap_samples = true;
  const JointAscentStats stats = nodes_ascend_jointly(m, problem, options);
  EXPECT_NEAR(stats.min_before, 0.360161, 1e-6);
  EXPECT_GT(stats.min_after, stats.min_before + 0.02);
  EXPECT_GT(stats.iterations, 10);
  for (int32_t h = 0; h < m.hex_count(); ++h)
    EXPECT_LE(hex_edge_ratio(hex_points(m, h)),
              hex_edge_ratio_cap(hex_points(start, h), options.max_edge_ratio))
        << "hex " << h;
}

TEST(NodeJointAscent, PerfectBrickAndInvertedStartAreLeftAlone) {
  HexMesh brick = fixture_brick(3, 3, 3);
  const HexMesh perfect = brick;
  JointAscentStats stats = nodes_ascend_jointly(brick, interior_problem(brick), {});
  EXPECT_EQ(stats.min_before, 1.0);
  EXPECT_EQ(stats.min_after, 1.0);
  EXPECT_EQ(brick.points, perfect.points);
  // The centre node pushed through a face: an inverted hex, which the joint ascent leaves to
  // the untangling of the node-by-node optimizer.
  HexMesh folded = fixture_brick(3, 3, 3);
  const NodeProblem problem = interior_problem(folded);
  folded.points[problem.nodes[0]] += Eigen::Vector3d(-1.5, -1.5, -1.5);
  const HexMesh before = folded;
  stats = nodes_ascend_jointly(folded, problem, {});
  EXPECT_LE(stats.min_before, 0.0);
  EXPECT_EQ(stats.iterations, 0);
  EXPECT_EQ(folded.points, before.points);
}

TEST(NodeJointAscent, SameMeshOnAnyThreadCount) {
  // Over 4,096 objective hexes, so that the evaluations do run on several threads.
  const HexMesh input = mesh_read(shared_mesh("rockerarm.mesh"));
  PipelineOptions o;
  o.method = "selective";
  o.targets = select_hexes(input, {"sphere:0,0,0,5"}).hexes;
  o.refine.placement.joint_iterations = 0;
  const HexMesh refined = pipeline_run(input, o).mesh;
  const NodeProblem problem = interior_problem(refined);
  std::optional<HexMesh> first;
  for (int threads : {1, 2}) {
    HexMesh m = refined;
    JointAscentOptions options;
    options.band = 2;  // every free node
    options.max_seeds = 1 << 30;
    options.max_iterations = 15;
    options.max_edge_ratio = 0;  // the scaled Jacobian alone: room to move from the start
    options.threads = threads;
    const JointAscentStats stats = nodes_ascend_jointly(m, problem, options);
    EXPECT_GT(stats.hexes, 4096);
    EXPECT_GT(stats.min_after, stats.min_before);
    if (!first)
      first = m;
    else
      EXPECT_EQ(m.points, first->points);
  }
}

}  // namespace
}  // namespace hexrefine
