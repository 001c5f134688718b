// `hexrefine study` end to end with a folder of meshes (--meshes), and its report script
// (experiments/studies/real_meshes/report.py) on synthetic records.

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <set>

#include "cli_runner.hpp"
#include "experiments/runner/runner.hpp"

namespace hexrefine {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

TEST(CliStudy, StudiesEveryReadableMeshOfAGivenFolderAndTagsItsFolder) {
  const auto dir = test_temp_dir("cli_study_meshes");
  const fs::path meshes = dir / "my meshes";
  fs::create_directories(meshes);
  ASSERT_EQ(
      cli_run("generate brick '" + (meshes / "brick.mesh").string() + "' --dims 3,3,3").exit_code,
      0);
  test_file_put(meshes / "broken.mesh", "MeshVersionFormatted 1\nnonsense\n");
  test_file_put(meshes / "notes.txt", "not a mesh\n");
  const fs::path out = dir / "out";
  const CliRun r = cli_run("study --meshes '" + meshes.string() + "' --no-shared --out '" +
                           out.string() + "' --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.output;

  const JsonlContent records = jsonl_read((out / "real_meshes.jsonl").string());
  // brick.mesh: 7 region kinds x 3 arms; the anisotropy boxes: 9 shapes x 3 arms; both methods.
  ASSERT_EQ(records.records.size(), (7 * 3 + 9 * 3) * 2u);
  std::map<std::string, int> arms;
  for (const json& rec : records.records) {
    const json& tags = rec["tags"];
    if (tags["study"] != "real_meshes") continue;
    EXPECT_EQ(tags["mesh"], "brick.mesh");
    EXPECT_EQ(tags["folder"], meshes.string());
    EXPECT_EQ(tags["source"], "meshes");
    EXPECT_EQ(tags["input_valid"], true);
    ++arms[tags["arm"].get<std::string>()];
    EXPECT_EQ(rec["options"]["smooth"], tags["arm"] == "default-smooth");
    // A brick: no placement refuses, so every record is a refinement with its check.
    EXPECT_FALSE(rec.contains("error")) << rec.dump().substr(0, 400);
    EXPECT_TRUE(rec["check"]["valid"].get<bool>());
  }
  EXPECT_EQ(arms, (std::map<std::string, int>{
                      {"trilinear", 14}, {"default", 14}, {"default-smooth", 14}}));
  // The unreadable file is named in the case file and the report, not studied.
  const json cases = json::parse(test_file_text(out / "real_meshes.cases.json"));
  EXPECT_NE(cases["description"].get<std::string>().find("broken.mesh"), std::string::npos);
  EXPECT_EQ(cases["cases"][0]["mesh"]["file"],
            (fs::weakly_canonical(meshes) / "brick.mesh").string());
  const std::string md = test_file_text(out / "real_meshes.md");
  EXPECT_NE(md.find("| brick.mesh | " + meshes.string() + " | 27 | 1 | yes | 42 | 0 (0) |"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("Left out: "), std::string::npos);
  EXPECT_TRUE(fs::exists(out / "plots" / "real_meshes_quality.png"));
}

TEST(CliStudy, BadMeshesFolderExitsTwoNamingIt) {
  const auto dir = test_temp_dir("cli_study_bad");
  const std::string missing = (dir / "no such folder").string();
  const CliRun r = cli_run("study --meshes '" + missing + "' --no-shared --out '" +
                           (dir / "out").string() + "' --quiet");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--meshes " + missing + ": not a readable folder"), std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(dir / "out" / "real_meshes.jsonl"));
  // A file is not a folder either.
  test_file_put(dir / "a.mesh", "x");
  const CliRun f = cli_run("study --meshes '" + (dir / "a.mesh").string() +
                           "' --no-shared --out '" + (dir / "out").string() + "' --quiet");
  EXPECT_EQ(f.exit_code, 2) << f.output;
  EXPECT_NE(f.output.find("a.mesh: not a readable folder"), std::string::npos) << f.output;
  EXPECT_EQ(cli_run("study --max-hexes-input 0 --out '" + (dir / "out").string() + "'").exit_code,
            2);
}

/// One record of the study as the runner writes it, with the fields the report reads.
json study_record(const std::string& mesh, const std::string& kind, const std::string& arm,
                  const std::string& method, double parents, double min, double smoothed = -1) {
  json r = {{"case", mesh + "/" + kind + "/" + arm},
            {"method", method},
            {"commit", "0123456789abcdef"},
            {"tags",
             {{"study", "real_meshes"},
              {"mesh", mesh},
              {"folder", mesh == "c.mesh" ? "/corpus" : "../shared/meshes"},
              {"source", mesh == "c.mesh" ? "meshes" : "shared"},
              {"kind", kind},
              {"arm", arm},
              {"input_valid", true}}},
            {"options",
             {{"smooth", arm == "default-smooth"},
              {"placement",
               {{"method", arm == "trilinear"        ? "trilinear"
                           : arm == "default-smooth" ? "untangle"
                                                     : "optimized"}}}}},
            {"input", {{"hexes", 6000}, {"initial_min_scaled_jacobian", 0.8}}}};
  const json histogram = {{"bin_edges_from", -1.0}, {"bin_width", 0.1}, {"counts", {0, 0, 5}}};
  r["check"] = {{"min_scaled_jacobian", min},
                {"valid", true},
                {"hexes", 100},
                {"max_edge_ratio", 3.0},
                {"scaled_jacobian_histogram", histogram}};
  r["refined_parents"] = {{"hexes", 10}, {"min_scaled_jacobian", parents}};
  r["stage_cpu_seconds"] = {{"refine", 1.0}};
  if (smoothed >= 0) {
    r["smoothing"] = {{"check",
                       {{"min_scaled_jacobian", smoothed},
                        {"valid", true},
                        {"max_edge_ratio", 4.0},
                        {"scaled_jacobian_histogram", histogram}}}};
    r["refined_parents"]["smoothed_children_min_scaled_jacobian"] = smoothed;
    r["stage_cpu_seconds"]["smooth"] = smoothed > 0.3 ? 2.0 : 7.0;
  }
  return r;
}

TEST(RealMeshesReport, CountsTheTargetsOfIssue28PerArm) {
  const auto dir = test_temp_dir("real_meshes_report");
  std::string text;
  for (const char* mesh : {"a.mesh", "c.mesh"}) {
    text += study_record(mesh, "sphere", "trilinear", "selective", 0.8, 0.2).dump() + "\n";
    text += study_record(mesh, "sphere", "default", "selective", 0.8, 0.3).dump() + "\n";
  }
  // a.mesh smoothed: 0.5 / 0.8 (met, smoothing twice the refinement); c.mesh: 0.1 / 0.8 (not
  // met, 7 x the refinement), with a warning.
  text +=
      study_record("a.mesh", "sphere", "default-smooth", "selective", 0.8, 0.3, 0.5).dump() + "\n";
  json warned = study_record("c.mesh", "sphere", "default-smooth", "selective", 0.8, 0.3, 0.1);
  warned["smoothing"]["warning"] = "a move was undone";
  text += warned.dump() + "\n";
  // A refusal of a valid input by the default arm, and one of an invalid input (not counted).
  json refused = study_record("a.mesh", "blob-1", "default", "sheet", 0.8, 0.3);
  refused["error"] = "node placement: no placement of the new nodes | hex 7";
  text += refused.dump() + "\n";
  json invalid = study_record("bad.mesh", "sphere", "default", "sheet", 0.8, 0.3);
  invalid["tags"]["input_valid"] = false;
  invalid["error"] = "the input mesh is not valid";
  text += invalid.dump() + "\n";
  json failed = study_record("a.mesh", "blob-1", "default-smooth", "sheet", 0.8, 0.3);
  failed["error"] = "smoothing left an invalid mesh; nothing written";
  text += failed.dump() + "\n";
  test_file_put(dir / "r.jsonl", text);

  const CliRun r =
      shell_run(std::string("/usr/bin/python3 ") + HEXREFINE_SOURCE_DIR +
                "/experiments/studies/real_meshes/report.py " + (dir / "r.jsonl").string() +
                " --out " + (dir / "out").string() + " --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string md = test_file_text(dir / "out" / "real_meshes.md");
  for (const char* row : {
           "| 0 refusals of valid inputs (the checker passes them), default placement, "
           "unsmoothed | 1 refused of 3 | **no** |",
           "| 0 refusals of valid inputs (the checker passes them), default placement with "
           "`--smooth` | 0 refused of 3 | yes |",
           "| smoothing never fails: every smoothed case of a valid input returns a mesh | 2 of 3 "
           "(1 smoothing failures) | **no** |",
           "| (smoothed cases whose report carries a smoothing warning, `smoothing.warning`) | 1 "
           "of 2 | counted |",
           "| smoothed >= 0.5 x the refined parents' minimum scaled Jacobian, every case | 1 met, "
           "1 not met | **no** |",
           "every case of >= 5,000 input hexes | 1 met of 2 (worst 7 x) | **no** |",
           "| >= 10 meshes | 3 meshes (2 valid inputs), 1 from outside ../shared | **no** |",
           "| unsmoothed default output min >= 0.3 x parents' min | 2 of 2 | retired (issue 28 "
           "decision 3): reported only |",
           "*default-smooth*: untangle (3 runs)",
           "| a.mesh | blob-1 | sheet | default (optimized) | node placement: no placement of the "
           "new nodes / hex 7 |",
           "| c.mesh | /corpus | 6,000 | 0.8 | yes | 3 | 0 (0) | 0.125 | 0.125 | 7 |",
       })
    EXPECT_NE(md.find(row), std::string::npos) << row << "\n" << md;
  EXPECT_EQ(md.find("bad.mesh | sphere | sheet | default"), std::string::npos) << md;

  test_file_put(dir / "none.jsonl", "{\"tags\": {}}\n");
  const CliRun none = shell_run(std::string("/usr/bin/python3 ") + HEXREFINE_SOURCE_DIR +
                                "/experiments/studies/real_meshes/report.py " +
                                (dir / "none.jsonl").string() + " --out " + (dir / "out").string());
  EXPECT_EQ(none.exit_code, 2);
  EXPECT_NE(none.output.find("no records of the real-mesh study"), std::string::npos)
      << none.output;
}

// The README's main command must leave a clone's tracked files alone: --quick writes the build
// folder's results/quick/, and nothing under the source tree changes (git status stays the same).
TEST(CliStudy, QuickWritesTheBuildFolderAndLeavesTrackedFilesAlone) {
  const auto dir = test_temp_dir("cli_study_quick");
  const fs::path meshes = dir / "meshes";
  fs::create_directories(meshes);
  ASSERT_EQ(
      cli_run("generate brick '" + (meshes / "brick.mesh").string() + "' --dims 2,2,2").exit_code,
      0);
  const std::string status_cmd = std::string("git -C '") + HEXREFINE_SOURCE_DIR +
                                 "' status --porcelain --untracked-files=all 2>/dev/null";
  auto git_status = [&] {
    std::string text;
    if (FILE* p = ::popen(status_cmd.c_str(), "r")) {
      char buffer[4096];
      size_t n;
      while ((n = ::fread(buffer, 1, sizeof buffer, p)) > 0) text.append(buffer, n);
      ::pclose(p);
    }
    return text;
  };
  const std::string before = git_status();
  const fs::path records =
      fs::path(HEXREFINE_BINARY_DIR) / "results" / "quick" / "real_meshes.jsonl";
  fs::remove(records);
  const CliRun r =
      cli_run("study --quick --meshes '" + meshes.string() + "' --no-shared --quiet --no-plots");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(jsonl_read(records.string()).records.size(), (7 * 3 + 9 * 3) * 2u);
  EXPECT_EQ(git_status(), before);
}

}  // namespace
}  // namespace hexrefine
