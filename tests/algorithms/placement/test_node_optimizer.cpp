/// \file
/// algorithms/placement/node_optimizer.hpp: sweeps visited level by level replay the serial
/// worst-first Gauss-Seidel sweep bit for bit, on any number of threads.

#include "algorithms/placement/node_optimizer.hpp"

#include <gtest/gtest.h>

#include <optional>

#include "algorithms/pipeline/pipeline.hpp"
#include "fixtures.hpp"
#include "mesh/io.hpp"
#include "mesh/quality.hpp"
#include "tests/cli_runner.hpp"

namespace hexrefine {
namespace {

struct SerialReference {
  const char* select;
  /// Output minimum after placement and after --smooth, as the serial sweeps gave them
  /// (results/real_meshes.jsonl, commit 5ca0aee, before the level schedule).
  double placed_min, smoothed_min;
};

TEST(NodeOptimizer, LevelsReplayTheSerialSweepOnAnyThreadCount) {
  const HexMesh m = mesh_read(shared_mesh("rockerarm.mesh"));
  // sphere:0,0,0,5 has narrow levels (the threads rarely share one); surface:0 has over a
  // thousand levels of 64 or more nodes per smoothing, which the threads do share.
  for (const SerialReference& c :
       {SerialReference{"sphere:0,0,0,5", 0.11783137589340247, 0.45020364353631998},
        SerialReference{"surface:0", 0.16949084993081842, 0.37237227111799165}}) {
    SCOPED_TRACE(c.select);
    PipelineOptions o;
    o.method = "selective";
    o.select = {c.select};
    o.smooth = true;
    // The sweeps alone, no edge-ratio cap (placement from the reference positions).
    o.refine.placement.joint_iterations = 0;
    o.smoothing.joint_iterations = 0;
    o.refine.placement.max_edge_ratio = 0;
    o.smoothing.max_edge_ratio = 0;
    std::optional<HexMesh> first;
    for (int threads : {1, 2}) {
      SCOPED_TRACE(threads);
      o.refine.threads = threads;
      const PipelineResult r = pipeline_run(m, o);
      EXPECT_EQ(r.check.min_scaled_jacobian, c.placed_min);
      ASSERT_TRUE(r.smoothed_check);
      EXPECT_EQ(r.smoothed_check->min_scaled_jacobian, c.smoothed_min);
      if (!first)
        first = r.mesh;
      else
        EXPECT_EQ(r.mesh.points, first->points);
    }
  }
}

// A second round after the joint ascent starts from the nodes it moved: the first sweep visits
// only the flagged nodes, and a node no neighbour of which moves is never visited.
TEST(NodeOptimizer, InitiallyActiveNodesAreTheOnlyOnesTheFirstSweepVisits) {
  HexMesh brick = fixture_brick(3, 3, 3);
  // The two interior nodes of the brick's middle row, each pushed off its place.
  const int32_t a = 1 + 4 * 1 + 16 * 1, b = 2 + 4 * 1 + 16 * 1;
  brick.points[a] += Eigen::Vector3d(0.3, 0.2, 0.1);
  brick.points[b] += Eigen::Vector3d(-0.2, 0.3, 0.1);
  NodeProblem problem;
  problem.nodes = {a, b};
  problem.slides.resize(2);
  std::vector<int32_t> all(brick.hexes.size());
  for (int32_t h = 0; h < brick.hex_count(); ++h) all[h] = h;
  node_problem_connect(problem, brick, all);
  NodeOptimizerOptions o;
  o.initially_active = {0, 0};
  HexMesh none = brick;
  EXPECT_EQ(nodes_optimize(none, problem, o).nodes_moved, 0);
  EXPECT_EQ(none.points, brick.points);
  o.initially_active = {1, 0};  // a moves, which wakes b (they share hexes)
  HexMesh one = brick;
  EXPECT_EQ(nodes_optimize(one, problem, o).nodes_moved, 2);
  EXPECT_GT(mesh_min_scaled_jacobian(one), mesh_min_scaled_jacobian(brick));
}

}  // namespace
}  // namespace hexrefine
