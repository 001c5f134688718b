// `hexrefine refine --method sheet` end to end: the thesis' L-shaped case, and a twisted ring the
// sheet refiner refuses (exit 1, message naming the sheet and the hexes, no output written).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/cli_runner.hpp"

namespace hexrefine {
namespace {

TEST(CliRefineSheet, LShapedCaseGrowsToTheWholeBrick) {
  const auto dir = test_temp_dir("cli_refine_sheet_l");
  const std::string in = (dir / "brick.vtk").string(), out = (dir / "out.vtk").string(),
                    report = (dir / "report.json").string();
  ASSERT_EQ(cli_run("generate brick " + in + " --dims 10,10,10").exit_code, 0);
  const CliRun run = cli_run("refine " + in + " " + out +
                             " --method sheet --select boundary:-1,0,0 --select boundary:0,0,-1"
                             " --report " +
                             report);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  std::ifstream f(report);
  const nlohmann::json j = nlohmann::json::parse(f);
  const nlohmann::json& refine = j.at("refine");
  EXPECT_EQ(refine.at("final_hexes"), 27000);  // thesis Table G-1
  EXPECT_EQ(refine.at("added_targets"), 810);
  EXPECT_EQ(refine.at("hexes_created"), 39000);
  EXPECT_EQ(refine.at("hexes_deleted"), 13000);
  EXPECT_TRUE(std::filesystem::exists(out));
}

TEST(CliRefineSheet, SelfIntersectingTransitionIsRefusedWithExitOne) {
  const auto dir = test_temp_dir("cli_refine_sheet_ring");
  const std::string in = (dir / "ring.vtk").string(), out = (dir / "out.vtk").string(),
                    ids = (dir / "tube.txt").string();
  ASSERT_EQ(cli_run("generate twisted-ring " + in + " --section-intervals 3 --around 8").exit_code,
            0);
  std::ofstream(ids) << "1 10 19 28 37 46 55 64\n";  // section cell 1 of every layer
  const CliRun run = cli_run("refine " + in + " " + out + " --method sheet --select hexes:" + ids);
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("crosses itself in hexes 2, 63"), std::string::npos) << run.output;
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace hexrefine
