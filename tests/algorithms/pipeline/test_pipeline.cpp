#include "algorithms/pipeline/pipeline.hpp"

#include <gtest/gtest.h>

#include <filesystem>

#include "mesh/error.hpp"
#include "mesh/generators.hpp"
#include "mesh/io.hpp"
#include "mesh/quality.hpp"
#include "tests/cli_runner.hpp"

namespace hexrefine {
namespace {

// One target in the middle of a 5x5x5 brick of unit cubes, whose corner hex (far from the
// refined region) is distorted below the 1-13 template's 0.3077: the mesh-wide minimum is that
// untouched hex, the children's minimum the template's own value, for both refiners.
TEST(Pipeline, WriteErrorsNameTheOutputNotTheInput) {
  // The writer refuses a cell field with the wrong number of values: its InputError names the
  // output only, whether it wrote beside the check (two threads) or after it (one); nothing is
  // left in the folder but the input.
  const auto dir = test_temp_dir("pipeline_write_error");
  const std::string in = (dir / "in.vtu").string(), out = (dir / "out.vtu").string();
  BrickParams p;
  p.dims = {3, 3, 3};
  mesh_write(in, generate_brick(p));
  for (int threads : {1, 2}) {
    PipelineOptions o;
    o.select = {"all"};
    o.refine.threads = threads;
    o.write.cell_scalars = {{"q", {1.0}}};
    try {
      pipeline_run_files(in, out, o);
      FAIL() << "wrote a field of one value for 729 hexes";
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_EQ(message.rfind(out + ": cell field 'q' has 1 values", 0), 0u) << message;
    }
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir),
                            std::filesystem::directory_iterator()),
              1);
  }
}

TEST(Pipeline, ChildrenMinimumLeavesOutUntouchedInputHexes) {
  const std::array<int, 3> dims{5, 5, 5};
  HexMesh m = generate_brick({.dims = dims, .size = {5, 5, 5}});
  m.points[brick_node(dims, 0, 0, 0)] = Eigen::Vector3d(-1.5, -1.5, -1.5);
  const double corner = hex_scaled_jacobian(hex_points(m, brick_hex(dims, 0, 0, 0)));
  ASSERT_GT(corner, 0.0);
  ASSERT_LT(corner, 0.25);
  for (const char* method : {"selective", "sheet"}) {
    SCOPED_TRACE(method);
    PipelineOptions o;
    o.method = method;
    o.targets = std::vector<int32_t>{brick_hex(dims, 2, 2, 2)};
    o.refine.placement.method = PlacementMethod::trilinear;
    o.smooth = true;
    const PipelineResult r = pipeline_run(m, o);
    EXPECT_EQ(r.refined_parents, 19);  // the target, its 6 face and 12 edge neighbours
    EXPECT_DOUBLE_EQ(r.refined_parents_min_scaled_jacobian, 1.0);
    EXPECT_DOUBLE_EQ(r.check.min_scaled_jacobian, corner);
    EXPECT_NEAR(r.children_min_scaled_jacobian, 0.3077, 5e-5);
    ASSERT_TRUE(r.smoothed_children_min_scaled_jacobian);
    EXPECT_GT(*r.smoothed_children_min_scaled_jacobian, 0.4);  // smoothing lifts the children
    const nlohmann::json j = pipeline_report(r, o);
    EXPECT_DOUBLE_EQ(j["refined_parents"]["children_min_scaled_jacobian"].get<double>(),
                     r.children_min_scaled_jacobian);
    EXPECT_DOUBLE_EQ(j["refined_parents"]["smoothed_children_min_scaled_jacobian"].get<double>(),
                     *r.smoothed_children_min_scaled_jacobian);
  }
}

// A full refinement: every output hex is a child, and the children's minimum is the checker's
// (taken from it rather than computed twice), here below every template's value: the corner
// hex's children inherit its distortion.
TEST(Pipeline, FullRefinementChildrenMinimumIsTheMeshMinimum) {
  const std::array<int, 3> dims{3, 3, 3};
  HexMesh m = generate_brick({.dims = dims, .size = {3, 3, 3}});
  m.points[brick_node(dims, 0, 0, 0)] = Eigen::Vector3d(-1.5, -1.5, -1.5);
  PipelineOptions o;
  o.method = "selective";
  o.select = {"all"};
  o.refine.placement.method = PlacementMethod::trilinear;
  const PipelineResult r = pipeline_run(m, o);
  EXPECT_EQ(r.refined_parents, 27);
  EXPECT_EQ(r.mesh.hex_count(), 27 * 27);
  EXPECT_DOUBLE_EQ(r.children_min_scaled_jacobian, r.check.min_scaled_jacobian);
  EXPECT_LT(r.children_min_scaled_jacobian, 0.25);
  EXPECT_GT(r.children_min_scaled_jacobian, 0.0);
}

// Issue 28: smoothing never fails a valid refinement. On ecr_hanger.mesh the smoothing slid
// input nodes on a feature curve past the point where the curve turns, a face corner crossed
// the crease and the checker rejected the face. Input nodes now stay where their feature curve
// turns by more than the feature angle, and that smoothing is valid: 0 nodes undone, 0.1175 ->
// 0.5040 (0.4046 before the joint ascent slid boundary nodes and ran in rounds). With a feature
// angle of 89 degrees the creases no longer count as features and the input nodes slide across
// them: the surface guard (the checker's face test inside the smoothing) keeps every face it
// moves on the input surface, so the check passes with no retry. Without the guard the checker
// rejects faces (60 at first): the smoothing runs again with the rejected hexes' corners pinned,
// and with no pinned smoothing allowed the nodes around them go back to their unsmoothed
// positions; either way the mesh is returned valid, never below the unsmoothed minimum, with a
// warning and a count.
TEST(Pipeline, SmoothingTheCheckerRejectsIsUndoneNotAnError) {
  const HexMesh input = mesh_read(shared_mesh("ecr_hanger.mesh"));
  PipelineOptions o;
  o.select = {"random:0.02,1"};
  o.smooth = true;
  o.smoothing.joint_iterations = 100;  // the budget the rejected faces were counted at
  o.refine.placement.method = pipeline_default_placement(o.smooth);
  const PipelineResult at_creases = pipeline_run(input, o);
  ASSERT_TRUE(at_creases.smoothed_check);
  EXPECT_TRUE(at_creases.smoothed_check->valid());
  EXPECT_EQ(at_creases.smoothing_nodes_undone, 0);
  EXPECT_TRUE(at_creases.smoothing_warning.empty()) << at_creases.smoothing_warning;
  EXPECT_NEAR(at_creases.check.min_scaled_jacobian, 0.1175, 1e-4);
  EXPECT_NEAR(at_creases.smoothed_check->min_scaled_jacobian, 0.5040, 1e-4);

  o.smoothing.feature_angle_degrees = 89;
  const PipelineResult guarded = pipeline_run(input, o);
  ASSERT_TRUE(guarded.smoothed_check);
  EXPECT_TRUE(guarded.smoothed_check->valid());
  EXPECT_EQ(guarded.smoothing_nodes_undone, 0);
  EXPECT_TRUE(guarded.smoothing_warning.empty()) << guarded.smoothing_warning;
  EXPECT_NEAR(guarded.smoothed_check->min_scaled_jacobian, 0.4186, 1e-4);

  o.smoothing_surface_guard = false;
  const PipelineResult pinned = pipeline_run(input, o);
  ASSERT_TRUE(pinned.smoothed_check);
  EXPECT_TRUE(pinned.check.valid());
  EXPECT_TRUE(pinned.smoothed_check->valid());
  EXPECT_GE(pinned.smoothed_check->min_scaled_jacobian, pinned.check.min_scaled_jacobian);
  EXPECT_NE(pinned.smoothing_warning.find("failed the check"), std::string::npos)
      << pinned.smoothing_warning;
  // The third pinned smoothing passes (275 nodes pinned in all): nothing is undone.
  EXPECT_NE(pinned.smoothing_warning.find("smoothed again 3 times with 275 nodes of rejected "
                                          "hexes pinned"),
            std::string::npos)
      << pinned.smoothing_warning;
  EXPECT_EQ(pinned.smoothing_nodes_undone, 0);

  o.smoothing_pin_rounds = 0;
  const PipelineResult r = pipeline_run(input, o);
  ASSERT_TRUE(r.smoothed_check);
  EXPECT_TRUE(r.smoothed_check->valid());
  EXPECT_GE(r.smoothed_check->min_scaled_jacobian, r.check.min_scaled_jacobian);
  EXPECT_GT(r.smoothing_nodes_undone, 0);
  EXPECT_EQ(r.smoothing_warning.find("pinned"), std::string::npos) << r.smoothing_warning;
  EXPECT_NE(r.smoothing_warning.find("went back to their unsmoothed positions"), std::string::npos)
      << r.smoothing_warning;
  const nlohmann::json j = pipeline_report(r, o);
  EXPECT_EQ(j.at("smoothing").at("nodes_undone"), r.smoothing_nodes_undone);
  EXPECT_EQ(j.at("smoothing").at("warning"), r.smoothing_warning);
  EXPECT_EQ(j.at("options").at("placement").at("method"), "untangle");
}

// Issue 28: no refusal of a valid input with the default placement. On ecr_cap.mesh (input
// edge ratios up to 72) a ball's transitions left a child inverted after placement and its three
// retargets, and the refinement was refused. The default placement (optimized from the reference
// positions, issue 29) now needs no fallback there; `untangle` still does: the fallback moves the
// nodes around the inverted child, the parents' own input nodes included, the output is valid and
// the fallback counted.
TEST(Pipeline, PlacementFallbackMakesAFormerRefusalValid) {
  const HexMesh input = mesh_read(shared_mesh("ecr_cap.mesh"));
  ASSERT_TRUE(mesh_check(input).valid());
  PipelineOptions o;
  o.select = {"sphere:5.81974,13.5306,14.1117,6.1145"};
  const PipelineResult by_default = pipeline_run(input, o);
  EXPECT_TRUE(by_default.check.valid());
  EXPECT_EQ(by_default.stats.placement_fallback_untangled, 0);
  EXPECT_EQ(by_default.stats.final_hexes, 26837);

  o.refine.placement.method = PlacementMethod::untangle;
  const PipelineResult r = pipeline_run(input, o);
  EXPECT_TRUE(r.check.valid());
  EXPECT_EQ(r.check.inverted_hexes, 0);
  EXPECT_EQ(r.stats.placement_fallback_untangled, 5);
  EXPECT_EQ(r.stats.final_hexes, 26080);
  // The fallback's second smoothing, without the edge-ratio cap, is for validity alone: with the
  // joint ascent it bought scaled Jacobian by collapsing an edge (largest edge ratio 36,356 at
  // 100 joint iterations, 3.3e8 at 1000), which the smoothing after it, capped at each hex's
  // ratio before, then kept.
  EXPECT_NEAR(r.check.max_edge_ratio, 182.658, 1e-3);
  EXPECT_EQ(pipeline_report(r, o).at("refine").at("placement_fallback_untangled"),
            r.stats.placement_fallback_untangled);
}

// --smooth never ends below plain refine. ecr_cap.mesh surface:0, sheet: smoothed from the
// untangle start the minimum ends at 0.2503, below the 0.2749 that the optimized placement gives
// unsmoothed; the run is then placed by optimized and smoothed from there, and says so.
TEST(Pipeline, SmoothingEndingBelowPlainRefineStartsAgainFromOptimized) {
  const HexMesh input = mesh_read(shared_mesh("ecr_cap.mesh"));
  PipelineOptions o;
  o.method = "sheet";
  o.select = {"surface:0"};
  const double plain = pipeline_run(input, o).check.min_scaled_jacobian;
  EXPECT_NEAR(plain, 0.274948, 1e-6);
  o.smooth = true;
  o.refine.placement.method = pipeline_default_placement(o.smooth);
  o.smoothing_start_fallback = false;
  const PipelineResult one = pipeline_run(input, o);
  ASSERT_TRUE(one.smoothed_check);
  EXPECT_NEAR(one.smoothed_check->min_scaled_jacobian, 0.250317, 1e-6);
  EXPECT_FALSE(one.placement_used);
  o.smoothing_start_fallback = true;
  const PipelineResult r = pipeline_run(input, o);
  ASSERT_TRUE(r.smoothed_check);
  EXPECT_TRUE(r.smoothed_check->valid());
  EXPECT_GE(r.smoothed_check->min_scaled_jacobian, plain);
  ASSERT_TRUE(r.placement_used);
  EXPECT_EQ(*r.placement_used, PlacementMethod::optimized);
  EXPECT_NE(r.placement_warning.find("smoothing from untangle reached 0.250317"), std::string::npos)
      << r.placement_warning;
  EXPECT_EQ(r.stats.final_hexes, one.stats.final_hexes);
  // Both starts' refinements and smoothings are billed.
  EXPECT_GT(r.stage_cpu_seconds.at("smooth"), one.stage_cpu_seconds.at("smooth"));
  const nlohmann::json j = pipeline_report(r, o);
  EXPECT_EQ(j.at("options").at("placement").at("method"), "optimized");
  EXPECT_EQ(j.at("refine").at("placement_warning"), r.placement_warning);
}

// --smooth-both-starts keeps the better of the two smoothings. ecr_cap.mesh surface:0: with the
// sheet method the optimized start ends higher (0.2749 against untangle's 0.2503), with the
// selective one the untangle start does (results/smoothing_starts.md); both runs are billed.
TEST(Pipeline, SmoothingFromBothStartsKeepsTheHigherMinimum) {
  const HexMesh input = mesh_read(shared_mesh("ecr_cap.mesh"));
  PipelineOptions o;
  o.select = {"surface:0"};
  o.smooth = true;
  o.refine.placement.method = pipeline_default_placement(o.smooth);
  for (const char* method : {"sheet", "selective"}) {
    SCOPED_TRACE(method);
    o.method = method;
    o.smoothing_both_starts = false;
    o.smoothing_start_fallback = false;
    const PipelineResult untangle = pipeline_run(input, o);
    PipelineOptions optimized_options = o;
    optimized_options.refine.placement.method = PlacementMethod::optimized;
    const PipelineResult optimized = pipeline_run(input, optimized_options);
    o.smoothing_start_fallback = true;
    o.smoothing_both_starts = true;
    const PipelineResult both = pipeline_run(input, o);
    ASSERT_TRUE(untangle.smoothed_check && optimized.smoothed_check && both.smoothed_check);
    const double u = untangle.smoothed_check->min_scaled_jacobian;
    const double p = optimized.smoothed_check->min_scaled_jacobian;
    EXPECT_EQ(both.smoothed_check->min_scaled_jacobian, std::max(u, p));
    EXPECT_TRUE(both.smoothed_check->valid());
    EXPECT_EQ(both.placement_used.has_value(), p > u);
    EXPECT_EQ(both.placement_warning.find("smoothed from both starts") != std::string::npos, p > u)
        << both.placement_warning;
    EXPECT_EQ(both.mesh.points, (p > u ? optimized : untangle).mesh.points);
    EXPECT_GE(both.stage_cpu_seconds.at("smooth"), untangle.stage_cpu_seconds.at("smooth"));
    if (std::string(method) == "sheet") {
      EXPECT_NEAR(u, 0.250317, 1e-6);
      EXPECT_NEAR(p, 0.274948, 1e-6);
    } else {
      EXPECT_GT(u, p);
    }
  }
}

// Issue 28: --smooth never refuses a valid input for its start. On ecr_cap.mesh, two selective
// passes under the layer rule, the thesis' positions (`untangle`, the start smoothing prefers)
// leave a child of input hex 3733 that no untangling saves; the pipeline then places the
// refinement with `optimized` (reference positions first), says so, and smooths from there.
TEST(Pipeline, SmoothingStartRefusedFallsBackToOptimizedPlacement) {
  const HexMesh input = mesh_read(shared_mesh("ecr_cap.mesh"));
  PipelineOptions o;
  o.select = {"sphere:5.81974,13.5306,14.1117,4.07633"};
  o.refine.passes = 2;
  o.refine.buffer = PassBuffer::layer;
  o.smooth = true;
  o.refine.placement.method = pipeline_default_placement(o.smooth);
  const PipelineResult r = pipeline_run(input, o);
  EXPECT_TRUE(r.check.valid());
  ASSERT_TRUE(r.smoothed_check);
  EXPECT_TRUE(r.smoothed_check->valid());
  EXPECT_GE(r.smoothed_check->min_scaled_jacobian, r.check.min_scaled_jacobian);
  EXPECT_EQ(r.stats.final_hexes, 206212);
  EXPECT_NE(r.placement_warning.find("input hexes 3733"), std::string::npos) << r.placement_warning;
  EXPECT_NE(r.placement_warning.find("placed by optimized instead"), std::string::npos);
  ASSERT_TRUE(r.placement_used);
  EXPECT_EQ(*r.placement_used, PlacementMethod::optimized);
  const nlohmann::json j = pipeline_report(r, o);
  EXPECT_EQ(j.at("refine").at("placement_warning"), r.placement_warning);
  EXPECT_EQ(j.at("options").at("placement").at("method"), "optimized");
}

}  // namespace
}  // namespace hexrefine
