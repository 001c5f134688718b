#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "tests/cli_runner.hpp"

namespace hexrefine {
namespace {

TEST(CliSheets, AbaqusBrickHasSixSheets) {
  const auto dir = test_temp_dir("cli_sheets_abaqus");
  const std::string report = (dir / "sheets.json").string();
  const CliRun r = cli_run("sheets " + shared_mesh("abaqus_hex_2x2x2.inp") + " --report " + report);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("sheets: 6 (self-intersecting 0, closed 0)"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("(8 hexes, 27 nodes, 54 edges, 36 faces)"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("6 sheets of 4 hexes"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("chords: 12 (closed 0)"), std::string::npos) << r.output;

  std::ifstream in(report);
  ASSERT_TRUE(in.good());
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["hexes"], 8);
  EXPECT_EQ(j["sheets"], 6);
  EXPECT_EQ(j["self_intersecting_sheets"], 0);
  EXPECT_EQ(j["closed_sheets"], 0);
  EXPECT_EQ(j["chords"], 12);
  EXPECT_EQ(j["closed_chords"], 0);
  ASSERT_EQ(j["per_sheet"].size(), 6u);
  for (const auto& s : j["per_sheet"]) {
    EXPECT_EQ(s["hexes"], 4);
    EXPECT_EQ(s["edges"], 9);
    EXPECT_EQ(s["self_intersecting"], false);
    EXPECT_EQ(s["closed"], false);
  }
}

TEST(CliSheets, StructuredSphereMeshHasFifteenSheets) {
  // sphere_conforming.mesh is a 5 x 5 x 5 block mapped onto a sphere: topologically a brick.
  const auto dir = test_temp_dir("cli_sheets_sphere");
  const std::string report = (dir / "sheets.json").string();
  const CliRun r =
      cli_run("sheets " + shared_mesh("sphere_conforming.mesh") + " --report " + report);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("(125 hexes, 216 nodes, 540 edges, 450 faces)"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("15 sheets of 25 hexes"), std::string::npos) << r.output;
  std::ifstream in(report);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["sheets"], 15);
  EXPECT_EQ(j["chords"], 75);
  EXPECT_EQ(j["closed_sheets"], 0);
  EXPECT_EQ(j["self_intersecting_sheets"], 0);
  ASSERT_EQ(j["per_sheet"].size(), 15u);
  for (const auto& s : j["per_sheet"]) EXPECT_EQ(s["edges"], 36);  // 6 x 6 parallel edges
}

TEST(CliSheets, UsageErrorsExitTwo) {
  CliRun r = cli_run("sheets");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("expected one mesh file"), std::string::npos) << r.output;
  r = cli_run("sheets a.inp b.inp");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  r = cli_run("sheets " + shared_mesh("abaqus_hex_2x2x2.inp") + " --bogus");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--bogus"), std::string::npos) << r.output;
  r = cli_run("sheets " + shared_mesh("abaqus_hex_2x2x2.inp") + " --report");
  EXPECT_EQ(r.exit_code, 2) << r.output;
}

TEST(CliSheets, MissingMeshIsBadInput) {
  CliRun r = cli_run("sheets /nonexistent/mesh.mesh");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("/nonexistent/mesh.mesh"), std::string::npos) << r.output;
  const auto dir = test_temp_dir("cli_sheets_bad_input");
  const std::string bad = (dir / "bad.mesh").string();
  std::ofstream(bad) << "MeshVersionFormatted 2\nDimension 3\nVertices\n2\n0 0 0 0\n";
  r = cli_run("sheets " + bad);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(bad), std::string::npos) << r.output;
}

TEST(CliSheets, UnwritableReportFailsWithoutPartialFile) {
  const auto dir = test_temp_dir("cli_sheets_unwritable");
  const std::string report = (dir / "missing_folder" / "sheets.json").string();
  const CliRun r =
      cli_run("sheets " + shared_mesh("sphere_conforming.mesh") + " --report " + report);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find(report), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(report));
}

}  // namespace
}  // namespace hexrefine
