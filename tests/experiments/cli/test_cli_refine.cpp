#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "mesh/generators.hpp"
#include "mesh/io.hpp"
#include "mesh/quality.hpp"
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

TEST(CliRefine, DirectionalOrderAndBufferRuleOptions) {
  const auto dir = test_temp_dir("cli_refine_order");
  const std::string in = (dir / "b.mesh").string(), out = (dir / "o.mesh").string();
  mesh_write(in, fixture_brick(4, 4, 4));
  // Table H-2 with the thesis' defaults (hex after hex, the layer buffer): 370,304 hexes.
  CliRun r = cli_run(join({"refine", in, out,
                           "--method selective --select boundary:-1,0,0 --passes 3 "
                           "--placement trilinear --directional-order by-rank --report",
                           (dir / "r.json").string()}));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  nlohmann::json j = read_json(dir / "r.json");
  EXPECT_EQ(j.at("refine").at("final_hexes"), 370304);
  EXPECT_EQ(j.at("options").at("directional_order"), "by_rank");
  EXPECT_EQ(j.at("options").at("buffer"), "layer");
  r = cli_run(join({"refine", in, out,
                    "--method selective --select boundary:-1,0,0 --passes 3 --placement "
                    "trilinear --no-buffer --report",
                    (dir / "r.json").string()}));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  j = read_json(dir / "r.json");
  EXPECT_EQ(j.at("refine").at("final_hexes"), 332448);
  EXPECT_EQ(j.at("options").at("directional_order"), "by_hex");
  EXPECT_EQ(j.at("options").at("buffer"), "none");
  EXPECT_EQ(
      cli_run(join({"refine", in, out, "--method selective --select all --buffer wide"})).exit_code,
      2);
  EXPECT_EQ(cli_run(join({"refine", in, out,
                          "--method selective --select all --directional-order sideways"}))
                .exit_code,
            2);
}

TEST(CliRefine, LShapedCaseWritesMeshAndReport) {
  const auto dir = test_temp_dir("cli_refine_l");
  const std::string in = (dir / "b.vtk").string(), out = (dir / "o.vtk").string();
  mesh_write(in, fixture_brick(10, 10, 10));
  const CliRun r = cli_run(join({"refine", in, out,
                                 "--method selective --select boundary:-1,0,0 --select "
                                 "boundary:0,0,-1 --placement trilinear --report",
                                 (dir / "r.json").string()}));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(mesh_read(out).hex_count(), 8060);
  const nlohmann::json j = read_json(dir / "r.json");
  EXPECT_EQ(j.at("method"), "selective");
  EXPECT_EQ(j.at("input"), in);
  EXPECT_EQ(j.at("options").at("placement").at("method"), "trilinear");
  EXPECT_EQ(j.at("selection").at("hexes"), 190);
  const nlohmann::json& refine = j.at("refine");
  EXPECT_EQ(refine.at("initial_hexes"), 1000);
  EXPECT_EQ(refine.at("final_hexes"), 8060);
  EXPECT_EQ(refine.at("directional_hexes"), 10);
  EXPECT_EQ(refine.at("hexes_per_template").at("1-13"), 2080);
  EXPECT_TRUE(refine.at("phase_seconds").contains("directional"));
  const nlohmann::json& check = j.at("check");
  EXPECT_TRUE(check.at("conformal").get<bool>());
  EXPECT_EQ(check.at("inverted_hexes"), 0);
  EXPECT_NEAR(check.at("min_scaled_jacobian").get<double>(), 0.3077, 1e-4);
  EXPECT_GT(check.at("mean_scaled_jacobian").get<double>(), 0.5);
  for (const char* stage : {"read", "select", "refine", "check", "write", "total"})
    EXPECT_TRUE(j.at("stage_seconds").contains(stage)) << stage;
  EXPECT_GT(j.at("peak_memory_mb").get<double>(), 0);
  EXPECT_FALSE(j.contains("smoothing"));
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
  EXPECT_FALSE(j.at("check").at("conformal").get<bool>());
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
                                 "boundary:0,0,-1 --placement trilinear --smooth --report",
                                 (dir / "r.json").string()}));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json j = read_json(dir / "r.json");
  // 4^3 L-shape: 28 targets x 27 + 16 face transitions x 13 + 4 corners x 21 + 16 untouched.
  EXPECT_EQ(j.at("refine").at("final_hexes"), 28 * 27 + 16 * 13 + 4 * 21 + 16);
  EXPECT_TRUE(j.at("check").at("valid").get<bool>());
  EXPECT_NEAR(j.at("check").at("min_scaled_jacobian").get<double>(), 0.3077, 1e-4);
  const nlohmann::json& smoothing = j.at("smoothing");
  EXPECT_TRUE(smoothing.at("check").at("valid").get<bool>());
  EXPECT_NEAR(smoothing.at("stats").at("min_scaled_jacobian_before").get<double>(), 0.3077, 1e-4);
  EXPECT_GE(smoothing.at("check").at("min_scaled_jacobian").get<double>(), 0.3077 - 1e-4);
  EXPECT_TRUE(j.at("stage_seconds").contains("smooth"));
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
        join({"refine", in, out, "--method selective --select all --passes 0"}),
        join({"refine", in, out, "--method selective --select all --max-edge-ratio 0.5"}),
        join({"refine", in, out, "--method selective --select all --max-edge-ratio wide"})}) {
    const CliRun r = cli_run(args);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.output;
    if (args.find("--max-edge-ratio") != std::string::npos) {
      EXPECT_NE(r.output.find("--max-edge-ratio"), std::string::npos) << r.output;
    }
  }
  EXPECT_FALSE(std::filesystem::exists(out));
  const std::string inverted = shared_mesh("sphere_projected_inverted.mesh");
  const CliRun r = cli_run(join({"refine", inverted, out, "--method selective --select all"}));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  // The input hexes and their scaled Jacobians are named.
  EXPECT_NE(r.output.find("76 input hexes have a scaled Jacobian <= 0"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("33 (-0.944"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(CliRefine, InvalidInputIsReportedAsBadInput) {
  // bunny_voxel.mesh: cubes touching along edges (122 non-manifold boundary edges).
  const auto dir = test_temp_dir("cli_refine_invalid_input");
  const std::string out = (dir / "o.vtk").string();
  const CliRun r = cli_run(join({"refine", shared_mesh("bunny_voxel.mesh"), out,
                                 "--method selective --select sphere:0,0,0,1"}));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("the input mesh fails the check (before any refinement)"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(CliRefine, DistortedParentsAreUntangledNotRefused) {
  // One of the random configurations (results/selective_random.md) whose trilinear children
  // invert inside strongly jittered hexes: the default placement untangles them; with the
  // thesis' trilinear placement the result is invalid, so the command names the input hexes and
  // writes nothing.
  const auto dir = test_temp_dir("cli_refine_refused");
  const std::string in = (dir / "b.vtk").string(), out = (dir / "o.vtk").string();
  BrickParams bp;
  bp.dims = {4, 4, 4};
  bp.size = {4, 4, 4};
  bp.jitter = 0.2;
  bp.seed = 7;
  mesh_write(in, generate_brick(bp));
  std::ofstream(dir / "t.txt") << "0 2 5 8 13 15 25 37 39 47 54";
  const std::string select = "--method selective --select hexes:" + (dir / "t.txt").string();
  // Two threads: the output is written beside the check and refused after it; one: the check
  // refuses before anything is written. Either way no file is left.
  for (const char* threads : {"--threads 2", "--threads 1"}) {
    const CliRun trilinear =
        cli_run(join({"refine", in, out, select, "--placement trilinear", threads}));
    EXPECT_EQ(trilinear.exit_code, 1) << trilinear.output;
    EXPECT_NE(trilinear.output.find("inverted hexes"), std::string::npos) << trilinear.output;
    EXPECT_NE(trilinear.output.find("refined from input hexes"), std::string::npos)
        << trilinear.output;
    std::vector<std::string> left;
    for (const auto& e : std::filesystem::directory_iterator(dir))
      left.push_back(e.path().filename().string());
    std::sort(left.begin(), left.end());
    EXPECT_EQ(left, (std::vector<std::string>{"b.vtk", "t.txt"})) << threads;
  }
  const CliRun optimized = cli_run(join({"refine", in, out, select}));
  EXPECT_EQ(optimized.exit_code, 0) << optimized.output;
  EXPECT_NE(optimized.output.find(", conformal, 0 inverted"), std::string::npos)
      << optimized.output;
}

// Issue 28, decision 2: without --placement, --smooth starts from untangle and a plain refine
// from optimized; a placement given is kept either way, and the report names the one used.
TEST(CliRefine, SmoothWithoutPlacementStartsFromUntangle) {
  const auto dir = test_temp_dir("cli_refine_default_placement");
  const std::string in = (dir / "b.mesh").string(), out = (dir / "o.mesh").string();
  mesh_write(in, fixture_brick(4, 4, 4));
  const std::string report = (dir / "r.json").string();
  const std::string base = "--method selective --select sphere:2,2,2,0.9 --report " + report;
  struct Case {
    std::string flags, placement;
  };
  for (const Case& c : {Case{"", "optimized"}, Case{"--smooth", "untangle"},
                        Case{"--smooth --placement optimized", "optimized"},
                        Case{"--placement untangle", "untangle"}}) {
    SCOPED_TRACE(c.flags);
    const CliRun r = cli_run(join({"refine", in, out, base, c.flags}));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const nlohmann::json j = read_json(report);
    EXPECT_EQ(j.at("options").at("placement").at("method"), c.placement);
    EXPECT_EQ(j.contains("smoothing"), c.flags.find("--smooth") != std::string::npos);
    if (j.contains("smoothing")) {
      EXPECT_EQ(j.at("smoothing").at("nodes_undone"), 0);
      EXPECT_FALSE(j.at("smoothing").contains("warning"));
    }
  }
}

TEST(CliRefine, SmoothingBudgetTradesQualityForTime) {
  // Rockerarm refined around the sphere, one thread: the default budget (20 sweeps, 100
  // joint iterations, 3 rounds) ends at 0.5249, one round at 0.4894; two sweeps and no joint
  // ascent stop at 0.1973, still above the unsmoothed 0.0439, and the report names the budget
  // used.
  const auto dir = test_temp_dir("cli_refine_smoothing_budget");
  const std::string out = (dir / "o.vtu").string(), report = (dir / "r.json").string();
  const std::string base = join({"refine", shared_mesh("rockerarm.mesh"), out,
                                 "--method selective --select sphere:0,0,0,5 --threads 1 --smooth "
                                 "--report",
                                 report});
  struct Case {
    std::string flags;
    int sweeps, joint, rounds;
    double smoothed;
  };
  for (const Case& c :
       {Case{"", 20, 1000, 3, 0.5457535571145382},
        Case{"--smooth-joint-rounds 1", 20, 1000, 1, 0.5003094177402794},
        Case{"--smooth-sweeps 2 --smooth-joint-iterations 0", 2, 0, 3, 0.1972858580749072}}) {
    SCOPED_TRACE(c.flags);
    const CliRun r = cli_run(join({base, c.flags}));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const nlohmann::json j = read_json(report);
    const nlohmann::json& smoothing = j.at("smoothing");
    EXPECT_EQ(smoothing.at("max_sweeps"), c.sweeps);
    EXPECT_EQ(smoothing.at("max_joint_iterations"), c.joint);
    EXPECT_EQ(smoothing.at("max_joint_rounds"), c.rounds);
    // Every round raised the minimum here (none without the joint ascent).
    EXPECT_EQ(smoothing.at("stats").at("joint_rounds").get<int>(), c.joint == 0 ? 0 : c.rounds);
    EXPECT_LE(smoothing.at("stats").at("joint_iterations").get<int>(), c.joint * c.rounds);
    EXPECT_NEAR(smoothing.at("check").at("min_scaled_jacobian").get<double>(), c.smoothed, 1e-9);
    EXPECT_NEAR(j.at("check").at("min_scaled_jacobian").get<double>(), 0.0439162437334775, 1e-9);
    EXPECT_TRUE(smoothing.at("check").at("valid").get<bool>());
    // With the joint ascent skipped, only the first round of sweeps runs.
    if (c.joint == 0) {
      EXPECT_LE(smoothing.at("stats").at("sweeps").get<int>(), c.sweeps);
    }
  }
  for (const std::string bad :
       {"--smooth-sweeps 0", "--smooth-sweeps x", "--smooth-joint-iterations -1",
        "--smooth-joint-rounds 0", "--smooth-joint-rounds 1001"})
    EXPECT_EQ(cli_run(join({base, bad})).exit_code, 2) << bad;
  const CliRun unsmoothed = cli_run(join({"refine", shared_mesh("rockerarm.mesh"), out,
                                          "--method selective --select sphere:0,0,0,5 "
                                          "--smooth-sweeps 2"}));
  EXPECT_EQ(unsmoothed.exit_code, 2);
  EXPECT_NE(unsmoothed.output.find("--smooth-sweeps needs --smooth"), std::string::npos)
      << unsmoothed.output;
  // The restart from optimized (the smoothing from untangle ended below plain refine) and both
  // starts write their output once, checked, and report the start kept (ecr_cap surface:0,
  // sheet: 0.2749 from optimized, 0.2503 from untangle).
  for (const char* both : {"", "--smooth-both-starts"}) {
    SCOPED_TRACE(both);
    const std::string cap_out = (dir / "cap.vtu").string(),
                      cap_report = (dir / "cap.json").string();
    std::filesystem::remove(cap_out);
    const CliRun run =
        cli_run(join({"refine", shared_mesh("ecr_cap.mesh"), cap_out,
                      "--method sheet --select surface:0 --smooth --report", cap_report, both}));
    ASSERT_EQ(run.exit_code, 0) << run.output;
    EXPECT_NE(run.output.find("warning: smooth"), std::string::npos) << run.output;
    const nlohmann::json j = read_json(cap_report);
    EXPECT_EQ(j.at("options").at("placement").at("method"), "optimized");
    EXPECT_EQ(j.at("smoothing").at("both_starts").get<bool>(), std::string(both) != "");
    EXPECT_NEAR(j.at("smoothing").at("check").at("min_scaled_jacobian").get<double>(), 0.274948,
                1e-6);
    EXPECT_GT(j.at("stage_seconds").at("write").get<double>(), 0);
    const HexMesh written = mesh_read(cap_out);
    EXPECT_EQ(written.hex_count(), j.at("smoothing").at("check").at("hexes").get<int64_t>());
    EXPECT_NEAR(mesh_min_scaled_jacobian(written), 0.274948, 1e-6);
  }
  // --smooth-both-starts: only with --smooth, and it chooses the placements itself.
  const std::string rocker = join(
      {"refine", shared_mesh("rockerarm.mesh"), out, "--method selective --select sphere:0,0,0,5"});
  const CliRun both_unsmoothed = cli_run(join({rocker, "--smooth-both-starts"}));
  EXPECT_EQ(both_unsmoothed.exit_code, 2);
  EXPECT_NE(both_unsmoothed.output.find("--smooth-both-starts needs --smooth"), std::string::npos)
      << both_unsmoothed.output;
  const CliRun both_placed =
      cli_run(join({rocker, "--smooth --smooth-both-starts --placement optimized"}));
  EXPECT_EQ(both_placed.exit_code, 2);
  EXPECT_NE(both_placed.output.find("takes no --placement but untangle"), std::string::npos)
      << both_placed.output;
}

}  // namespace
}  // namespace hexrefine
