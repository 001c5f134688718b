#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "mesh/generators.hpp"
#include "mesh/io.hpp"
#include "tests/cli_runner.hpp"
#include "tests/fixtures.hpp"

namespace hexrefine {
namespace {

// Joins arguments with spaces (avoids long operator+ chains, which trip GCC 12's -Wrestrict).
std::string join(std::initializer_list<std::string> parts) {
  std::string out;
  for (const std::string& p : parts) {
    if (!out.empty()) out += ' ';
    out += p;
  }
  return out;
}

nlohmann::json read_json(const std::filesystem::path& p) {
  std::ifstream in(p);
  return nlohmann::json::parse(in);
}

TEST(CliRefine, LShapedCaseWritesMeshAndReport) {
  const auto dir = test_temp_dir("cli_refine_l");
  const std::string in = (dir / "b.vtk").string(), out = (dir / "o.vtk").string();
  mesh_write(in, fixture_brick(10, 10, 10));
  const CliRun r = cli_run(join({"refine", in, out,
                                 "--method selective --select boundary:-1,0,0 --select "
                                 "boundary:0,0,-1 --report",
                                 (dir / "r.json").string()}));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(mesh_read(out).hex_count(), 8060);
  const nlohmann::json j = read_json(dir / "r.json");
  EXPECT_EQ(j.at("method"), "selective");
  EXPECT_EQ(j.at("initial_hexes"), 1000);
  EXPECT_EQ(j.at("final_hexes"), 8060);
  EXPECT_TRUE(j.at("conformal").get<bool>());
  EXPECT_EQ(j.at("inverted_hexes"), 0);
  EXPECT_NEAR(j.at("min_scaled_jacobian").get<double>(), 0.3077, 1e-4);
  EXPECT_GT(j.at("mean_scaled_jacobian").get<double>(), 0.5);
  EXPECT_EQ(j.at("directional_hexes"), 10);
  EXPECT_EQ(j.at("hexes_per_template").at("1-13"), 2080);
  EXPECT_TRUE(j.at("phase_seconds").contains("directional"));
}

TEST(CliRefine, AblationWritesANonConformalMeshAndCountsTheDefects) {
  const auto dir = test_temp_dir("cli_refine_ablation");
  const std::string in = (dir / "b.vtk").string(), out = (dir / "o.vtk").string();
  mesh_write(in, fixture_brick(10, 10, 10));
  const CliRun r = cli_run(join({"refine", in, out,
                                 "--method selective --select boundary:-1,0,0 --select "
                                 "boundary:0,0,-1 --ebe-only --report",
                                 (dir / "r.json").string()}));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json j = read_json(dir / "r.json");
  EXPECT_FALSE(j.at("conformal").get<bool>());
  EXPECT_GT(j.at("check").at("non_conformal_faces").get<int>(), 0);
  EXPECT_TRUE(j.at("options").at("ebe_only").get<bool>());
  EXPECT_TRUE(std::filesystem::exists(out));
}

TEST(CliRefine, SmoothReportsQualityBeforeAndAfter) {
  const auto dir = test_temp_dir("cli_refine_smooth");
  const std::string in = (dir / "b.vtk").string(), out = (dir / "o.vtk").string();
  mesh_write(in, fixture_brick(4, 4, 4));
  const CliRun r = cli_run(join({"refine", in, out,
                                 "--method selective --select boundary:-1,0,0 --select "
                                 "boundary:0,0,-1 --smooth --report",
                                 (dir / "r.json").string()}));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json j = read_json(dir / "r.json");
  // 4^3 L-shape: 28 targets x 27 + 16 face transitions x 13 + 4 corners x 21 + 16 untouched.
  EXPECT_EQ(j.at("final_hexes"), 28 * 27 + 16 * 13 + 4 * 21 + 16);
  EXPECT_TRUE(j.at("conformal").get<bool>());
  EXPECT_TRUE(j.at("check_before_smoothing").at("valid").get<bool>());
  EXPECT_NEAR(j.at("smooth").at("min_scaled_jacobian_before").get<double>(), 0.3077, 1e-4);
  EXPECT_GE(j.at("min_scaled_jacobian").get<double>(), 0.3077 - 1e-4);
}

TEST(CliRefine, EmptySelectionWritesTheMeshUnchanged) {
  const auto dir = test_temp_dir("cli_refine_empty");
  const std::string in = (dir / "b.vtk").string(), out = (dir / "o.vtk").string();
  mesh_write(in, fixture_brick(2, 2, 2));
  const CliRun r =
      cli_run(join({"refine", in, out, "--method selective --select sphere:9,9,9,0.1"}));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("warning"), std::string::npos);
  EXPECT_EQ(mesh_read(out).hex_count(), 8);
}

TEST(CliRefine, BadUsageAndInvertedInputExitTwo) {
  const auto dir = test_temp_dir("cli_refine_bad");
  const std::string in = (dir / "b.vtk").string(), out = (dir / "o.vtk").string();
  mesh_write(in, fixture_brick(2, 2, 2));
  for (const std::string& args :
       {join({"refine", in, out, "--select all"}),
        join({"refine", in, out, "--method octree --select all"}),
        join({"refine", in, out, "--method selective"}),
        join({"refine", in, "--method selective --select all"}),
        join({"refine", in, out, "--method selective --select all --passes 0"})}) {
    const CliRun r = cli_run(args);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.output;
  }
  EXPECT_FALSE(std::filesystem::exists(out));
  const std::string inverted = shared_mesh("sphere_projected_inverted.mesh");
  const CliRun r = cli_run(join({"refine", inverted, out, "--method selective --select all"}));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("inverted hexes, first at id"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(CliRefine, InvalidInputIsReportedAsBadInput) {
  // bunny_voxel.mesh: cubes touching along edges (122 non-manifold boundary edges).
  const auto dir = test_temp_dir("cli_refine_invalid_input");
  const std::string out = (dir / "o.vtk").string();
  const CliRun r = cli_run(join({"refine", shared_mesh("bunny_voxel.mesh"), out,
                                 "--method selective --select sphere:0,0,0,1"}));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("input mesh is not valid"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(CliRefine, UnhandledConfigurationExitsOneNamingHexesAndWritesNothing) {
  // One of the random configurations (results/selective_random.md) the refiner refuses.
  const auto dir = test_temp_dir("cli_refine_refused");
  const std::string in = (dir / "b.vtk").string(), out = (dir / "o.vtk").string();
  BrickParams bp;
  bp.dims = {4, 4, 4};
  bp.size = {4, 4, 4};
  bp.jitter = 0.2;
  bp.seed = 7;
  mesh_write(in, generate_brick(bp));
  std::ofstream(dir / "t.txt") << "0 2 5 8 13 15 25 37 39 47 54";
  const CliRun r = cli_run(join(
      {"refine", in, out, "--method selective --select", "hexes:" + (dir / "t.txt").string()}));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("input hexes affected"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace hexrefine
