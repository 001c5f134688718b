/// \file
/// experiments/cli/cli_output.hpp and the size guard of `hexrefine refine`: an output that cannot
/// be written (unknown extension, missing folder, a folder in its place) is refused with exit 2
/// before the input is read, by refine, smooth, convert and generate; a refinement whose size
/// bound (hexes x 27^passes) exceeds --max-hexes (default 2^31 - 1) is refused with exit 1
/// before refining. Nothing is written in any refusal.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "cli_runner.hpp"
#include "mesh/io.hpp"

namespace hexrefine {
namespace {

namespace fs = std::filesystem;

bool output_has(const CliRun& r, const std::string& text) {
  return r.output.find(text) != std::string::npos;
}

int folder_entries(const fs::path& dir) {
  int n = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++n;
  return n;
}

// The input does not exist: a refusal that names the output, not the input, shows that the
// output was checked first.
TEST(CliOutputChecks, EveryMeshCommandChecksItsOutputBeforeReading) {
  const auto dir = test_temp_dir("cli_output_checks");
  const std::string in = (dir / "missing_input.mesh").string();
  const std::string no_folder = (dir / "no_such_folder" / "o.mesh").string();
  const std::string stl = (dir / "o.stl").string();
  const std::string report = (dir / "no_such_folder" / "r.json").string();
  const std::string ok = (dir / "o.vtk").string();
  fs::create_directories(dir / "taken.vtk");
  struct Case {
    std::string args, message;
  };
  const Case cases[] = {
      {"refine " + in + " " + no_folder + " --method selective --select all",
       "hexrefine refine: cannot write " + no_folder + ": folder "},
      {"refine " + in + " " + stl + " --method sheet --select all", stl + ": unknown mesh format"},
      {"refine " + in + " " + ok + " --method sheet --select all --report " + report,
       "hexrefine refine: cannot write " + report + ": folder "},
      {"smooth " + in + " " + no_folder, "hexrefine smooth: cannot write " + no_folder},
      {"smooth " + in + " " + stl, stl + ": unknown mesh format"},
      {"smooth " + in + " " + ok + " --report " + report,
       "hexrefine smooth: cannot write " + report},
      {"convert " + in + " " + no_folder, "hexrefine convert: cannot write " + no_folder},
      {"convert " + in + " " + stl, stl + ": unknown mesh format"},
      {"generate brick " + no_folder + " --dims 2,2,2",
       "hexrefine generate brick: cannot write " + no_folder},
      {"generate gear " + stl, stl + ": unknown mesh format"},
      {"generate cylinder " + (dir / "taken.vtk").string(),
       "hexrefine generate cylinder: cannot write " + (dir / "taken.vtk").string() +
           ": it is a folder"},
  };
  for (const Case& c : cases) {
    const CliRun r = cli_run(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args << "\n" << r.output;
    EXPECT_TRUE(output_has(r, c.message)) << c.args << "\n" << r.output;
    EXPECT_FALSE(output_has(r, "missing_input.mesh")) << c.args << "\n" << r.output;
  }
  EXPECT_EQ(folder_entries(dir), 1);  // taken.vtk only: no output, temporary or probe file
}

TEST(CliOutputChecks, WritableOutputsStillWork) {
  const auto dir = test_temp_dir("cli_output_checks_ok");
  const std::string cube = (dir / "cube.mesh").string();
  ASSERT_EQ(cli_run("generate brick " + cube + " --dims 1,1,1").exit_code, 0);
  // A relative output path (its folder is the working directory).
  const CliRun r = shell_run("cd " + dir.string() + " && " + std::string(HEXREFINE_EXE) +
                             " convert cube.mesh cube.vtk");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(mesh_read((dir / "cube.vtk").string()).hex_count(), 1);
  EXPECT_EQ(folder_entries(dir), 2);
}

TEST(CliRefineSizeGuard, TenFullPassesOfOneCubeAreRefusedBeforeRefining) {
  const auto dir = test_temp_dir("cli_refine_size_guard");
  const std::string cube = (dir / "cube.mesh").string(), out = (dir / "out.mesh").string();
  ASSERT_EQ(cli_run("generate brick " + cube + " --dims 1,1,1").exit_code, 0);
  const CliRun r = cli_run("refine " + cube + " " + out + " --method selective --select all " +
                           "--passes 10 --report " + (dir / "r.json").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  // 27^10 = 205,891,132,094,649.
  EXPECT_TRUE(output_has(r, "1 x 27^10 = 205891132094649 hexes, above the limit of 2147483647"))
      << r.output;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_FALSE(fs::exists(dir / "r.json"));
  // The sheet refiner's command is guarded the same way.
  const std::string brick = (dir / "brick.mesh").string();
  ASSERT_EQ(cli_run("generate brick " + brick + " --dims 2,2,2").exit_code, 0);
  const CliRun sheet =
      cli_run("refine " + brick + " " + out + " --method sheet --select all --passes 10");
  EXPECT_EQ(sheet.exit_code, 1) << sheet.output;
  EXPECT_TRUE(output_has(sheet, "8 x 27^10 = 1647129056757192 hexes")) << sheet.output;
  EXPECT_FALSE(fs::exists(out));
  // 36^3 = 46,656 hexes x 27^10 = 9.61e18 is beyond int64: the bound saturates and the message
  // gives it in floating point.
  const std::string big = (dir / "big.mesh").string();
  ASSERT_EQ(cli_run("generate brick " + big + " --dims 36,36,36").exit_code, 0);
  const CliRun saturated =
      cli_run("refine " + big + " " + out + " --method selective --select all --passes 10");
  EXPECT_EQ(saturated.exit_code, 1) << saturated.output;
  EXPECT_TRUE(output_has(saturated, "46656 x 27^10 = 9.61e+18 hexes")) << saturated.output;
  EXPECT_FALSE(fs::exists(out));
}

TEST(CliRefineSizeGuard, MaxHexesSetsTheLimitAndNormalRefinementPasses) {
  const auto dir = test_temp_dir("cli_refine_max_hexes");
  const std::string cube = (dir / "cube.mesh").string(), out = (dir / "out.mesh").string();
  ASSERT_EQ(cli_run("generate brick " + cube + " --dims 1,1,1").exit_code, 0);
  // 27^2 = 729 > 700: refused; 27 <= 700: refined to exactly 27 hexes.
  const CliRun two = cli_run("refine " + cube + " " + out +
                             " --method selective --select all --passes 2 " + "--max-hexes 700");
  EXPECT_EQ(two.exit_code, 1) << two.output;
  EXPECT_TRUE(output_has(two, "1 x 27^2 = 729 hexes, above the limit of 700")) << two.output;
  EXPECT_FALSE(fs::exists(out));
  const CliRun one = cli_run("refine " + cube + " " + out +
                             " --method selective --select all --passes 1 --max-hexes 700");
  EXPECT_EQ(one.exit_code, 0) << one.output;
  EXPECT_EQ(mesh_read(out).hex_count(), 27);
  // The default limit lets three full passes of one cube through (19,683 hexes).
  const CliRun three =
      cli_run("refine " + cube + " " + out + " --method sheet --select all --passes 3");
  EXPECT_EQ(three.exit_code, 0) << three.output;
  EXPECT_EQ(mesh_read(out).hex_count(), 19683);
  for (const std::string bad : {"0", "2147483648", "x"}) {
    const CliRun r =
        cli_run("refine " + cube + " " + out + " --method sheet --select all --max-hexes " + bad);
    EXPECT_EQ(r.exit_code, 2) << bad << "\n" << r.output;
    EXPECT_TRUE(output_has(r, "--max-hexes")) << r.output;
  }
}

}  // namespace
}  // namespace hexrefine
