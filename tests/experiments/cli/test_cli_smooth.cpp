#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_runner.hpp"
#include "mesh/generators.hpp"
#include "mesh/io.hpp"
#include "mesh/quality.hpp"

namespace hexrefine {
namespace {

// An n x n x n brick (default 5) with jittered interior nodes (jitter 0.35, `seed`), written
// as VTK; returns its path.
std::string write_jittered_brick(const std::filesystem::path& dir, int n = 5, int seed = 7) {
  BrickParams p;
  p.dims = {n, n, n};
  p.jitter = 0.35;
  p.seed = seed;
  const std::string path = (dir / "jittered.vtk").string();
  mesh_write(path, generate_brick(p));
  return path;
}

nlohmann::json read_json(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

TEST(CliSmooth, SmoothsWritesMeshAndReport) {
  const auto dir = test_temp_dir("cli_smooth_ok");
  const std::string in = write_jittered_brick(dir);
  const HexMesh input = mesh_read(in);
  for (const char* method : {"laplacian", "optimize"}) {
    const std::string out = (dir / (std::string(method) + ".vtu")).string();
    const std::string report = (dir / (std::string(method) + ".json")).string();
    const CliRun r =
        cli_run("smooth " + in + " " + out + " --method " + method + " --report " + report);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find(method), std::string::npos) << r.output;
    const HexMesh m = mesh_read(out);
    EXPECT_TRUE(m.hexes == input.hexes);
    const nlohmann::json j = read_json(report);
    EXPECT_EQ(j.at("method").get<std::string>(), method);
    EXPECT_EQ(j.at("hexes").get<int>(), 125);
    EXPECT_EQ(j.at("region_hexes").get<int>(), 125);
    EXPECT_DOUBLE_EQ(j.at("min_scaled_jacobian_before").get<double>(),
                     mesh_min_scaled_jacobian(input));
    // Shortest round-trip reals in the file: the mesh read back has the reported minimum.
    EXPECT_NEAR(j.at("min_scaled_jacobian_after").get<double>(), mesh_min_scaled_jacobian(m),
                1e-12);
    EXPECT_GT(j.at("min_scaled_jacobian_after").get<double>(),
              j.at("min_scaled_jacobian_before").get<double>() + 0.05);
    EXPECT_GT(j.at("mean_scaled_jacobian_after").get<double>(),
              j.at("mean_scaled_jacobian_before").get<double>());
    EXPECT_GE(j.at("sweeps").get<int>(), 1);
    EXPECT_LE(j.at("sweeps").get<int>(), 20);
    EXPECT_GT(j.at("nodes_moved").get<int>(), 0);
    EXPECT_GE(j.at("seconds").get<double>(), 0.0);
  }
}

TEST(CliSmooth, SameFileForAnyThreadCount) {
  // A 20^3 jittered brick (8,000 hexes), three sweeps: nine of the optimizer's levels hold the
  // 64 nodes or more at which the threads share them (counted once with a print).
  const auto dir = test_temp_dir("cli_smooth_threads");
  const std::string in = write_jittered_brick(dir, 20, 11);
  std::string first;
  for (const char* threads : {"1", "2", "3"}) {
    const std::string out = (dir / (std::string("out") + threads + ".vtu")).string();
    const CliRun r = cli_run("smooth " + in + " " + out + " --sweeps 3 --threads " + threads);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const std::string text = test_file_text(out);
    if (first.empty())
      first = text;
    else
      EXPECT_EQ(text, first) << threads << " threads";
  }
  EXPECT_NE(mesh_read((dir / "out1.vtu").string()).points, mesh_read(in).points);  // it moved
  const CliRun bad = cli_run("smooth " + in + " " + (dir / "o.vtu").string() + " --threads 0");
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("--threads"), std::string::npos) << bad.output;
}

TEST(CliSmooth, RegionAndSweepsLimitTheMoves) {
  const auto dir = test_temp_dir("cli_smooth_region");
  const std::string in = write_jittered_brick(dir);
  const HexMesh input = mesh_read(in);
  const std::string out = (dir / "out.vtk").string();
  const std::string report = (dir / "r.json").string();
  // The brick spans [0,1]^3 (spacing 0.2). Hexes with centroid x <= 0.2: the first layer (25
  // hexes); its nodes have x <= 0.2 + 0.35 * 0.2 = 0.27.
  const CliRun r = cli_run("smooth " + in + " " + out +
                           " --region box:-1,-1,-1,0.2,2,2 --sweeps 1 --joint-iterations 0" +
                           " --report " + report);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json j = read_json(report);
  EXPECT_EQ(j.at("region_hexes").get<int>(), 25);
  EXPECT_EQ(j.at("sweeps").get<int>(), 1);
  EXPECT_GT(j.at("nodes_moved").get<int>(), 0);
  const HexMesh m = mesh_read(out);
  for (int32_t n = 0; n < m.point_count(); ++n)
    if (input.points[n].x() > 0.3) {
      EXPECT_TRUE(m.points[n] == input.points[n]) << "node " << n;
    }
}

TEST(CliSmooth, EmptyRegionWarnsAndLeavesTheMesh) {
  const auto dir = test_temp_dir("cli_smooth_empty");
  const std::string in = write_jittered_brick(dir);
  const std::string out = (dir / "out.vtk").string();
  const std::string report = (dir / "r.json").string();
  const CliRun r =
      cli_run("smooth " + in + " " + out + " --region sphere:50,50,50,1 --report " + report);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("warning"), std::string::npos) << r.output;
  const nlohmann::json j = read_json(report);
  EXPECT_EQ(j.at("region_hexes").get<int>(), 0);
  EXPECT_EQ(j.at("sweeps").get<int>(), 0);
  EXPECT_EQ(j.at("nodes_moved").get<int>(), 0);
  EXPECT_TRUE(j.contains("warning"));
  EXPECT_TRUE(mesh_read(out).points == mesh_read(in).points);
}

TEST(CliSmooth, BadUsageExitsTwoAndWritesNothing) {
  const auto dir = test_temp_dir("cli_smooth_bad");
  const std::string in = write_jittered_brick(dir);
  const std::string out = (dir / "out.vtk").string();
  const struct {
    std::string args;
    const char* message;
  } cases[] = {
      {"smooth " + in, "IN OUT"},
      {"smooth " + in + " " + out + " --method newton", "--method"},
      {"smooth " + in + " " + out + " --sweeps -1", "--sweeps"},
      {"smooth " + in + " " + out + " --sweeps many", "--sweeps"},
      {"smooth " + in + " " + out + " --joint-iterations -3", "--joint-iterations"},
      {"smooth " + in + " " + out + " --max-edge-ratio 0.9", "--max-edge-ratio"},
      {"smooth " + in + " " + out + " --max-edge-ratio -", "--max-edge-ratio"},
      {"smooth " + in + " " + out + " --region box:1,2", "box"},
      {"smooth " + in + " " + out + " --bogus", "--bogus"},
      {"smooth " + in + " " + (dir / "out.stl").string(), "out.stl"},
      {"smooth " + (dir / "missing.vtk").string() + " " + out, "missing.vtk"},
  };
  for (const auto& c : cases) {
    const CliRun r = cli_run(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args << "\n" << r.output;
    EXPECT_NE(r.output.find(c.message), std::string::npos) << c.args << "\n" << r.output;
    EXPECT_FALSE(std::filesystem::exists(out)) << c.args;
  }
}

}  // namespace
}  // namespace hexrefine
