// The run and merge commands end to end (the hexrefine executable).

#include <gtest/gtest.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "cli_runner.hpp"
#include "experiments/runner/runner.hpp"

namespace hexrefine {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

json record(const std::string& name, int case_index, const std::string& method, int method_index) {
  return json{{"case", name},
              {"case_index", case_index},
              {"method", method},
              {"method_index", method_index},
              {"options", run_options_to_json(RefineOptions{}, false)}};
}

TEST(CliRun, BadCaseFileExitsTwoNamingFileAndPath) {
  const auto dir = test_temp_dir("cli_run_bad");
  test_file_put(
      dir / "c.json",
      R"({"cases":[{"name":"a","mesh":{"generate":"brick","dims":[2,2]},"select":["all"]}]})");
  const CliRun r = cli_run("run " + (dir / "c.json").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("c.json: /cases/0/mesh/dims: expected 3 integers"), std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(dir / "c.jsonl"));

  EXPECT_EQ(cli_run("run " + (dir / "missing.json").string()).exit_code, 2);
  EXPECT_EQ(cli_run("run").exit_code, 2);
  const CliRun shard = cli_run("run " + (dir / "c.json").string() + " --shard 3/2");
  EXPECT_EQ(shard.exit_code, 2);
  EXPECT_NE(shard.output.find("--shard"), std::string::npos);
}

TEST(CliRun, ResumeOfAFinishedRunRunsNothing) {
  const auto dir = test_temp_dir("cli_run_resume");
  test_file_put(dir / "c.json", R"({"cases":[{"name":"a","mesh":{"generate":"brick","dims":[2,2,2]},
    "select":["all"]}], "output": "out/a.jsonl"})");
  fs::create_directories(dir / "out");
  const std::string done =
      record("a", 0, "selective", 0).dump() + "\n" + record("a", 0, "sheet", 1).dump() + "\n";
  test_file_put(dir / "out" / "a.jsonl", done);
  const CliRun r = cli_run("run " + (dir / "c.json").string() + " --resume");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("0 records (2 already present, 0 refused (expected), 0 with an error) "
                          "written to"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(test_file_text(dir / "out" / "a.jsonl"), done);
}

TEST(CliReproduce, RefusesStrayArguments) {
  const CliRun r = cli_run("reproduce fast");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("unexpected argument 'fast'"), std::string::npos) << r.output;
  EXPECT_EQ(cli_run("reproduce --fast").exit_code, 2);
}

TEST(CliMerge, JoinsShardsDeduplicatedInCaseOrder) {
  const auto dir = test_temp_dir("cli_merge");
  test_file_put(dir / "s2.jsonl", record("b", 1, "selective", 0).dump() + "\n" +
                                      record("b", 1, "sheet", 1).dump() + "\n");
  test_file_put(dir / "s1.jsonl", record("c", 2, "sheet", 1).dump() + "\n" +
                                      record("a", 0, "selective", 0).dump() + "\n" +
                                      record("b", 1, "sheet", 1).dump() + "\n{\"case\":\"x");
  const CliRun r = cli_run("merge " + (dir / "all.jsonl").string() + " " +
                           (dir / "s2.jsonl").string() + " " + (dir / "s1.jsonl").string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("ignored a partial last line"), std::string::npos);
  const JsonlContent merged = jsonl_read((dir / "all.jsonl").string());
  ASSERT_EQ(merged.records.size(), 4u);
  EXPECT_EQ(merged.records[0]["case"], "a");
  EXPECT_EQ(merged.records[1]["case"], "b");
  EXPECT_EQ(merged.records[1]["method"], "selective");
  EXPECT_EQ(merged.records[2]["method"], "sheet");
  EXPECT_EQ(merged.records[3]["case"], "c");

  EXPECT_EQ(cli_run("merge " + (dir / "x.jsonl").string()).exit_code, 2);
  EXPECT_EQ(cli_run("merge " + (dir / "x.jsonl").string() + " " + (dir / "none.jsonl").string())
                .exit_code,
            2);
  test_file_put(dir / "bad.jsonl", "nonsense\n" + record("a", 0, "sheet", 1).dump() + "\n");
  const CliRun bad =
      cli_run("merge " + (dir / "x.jsonl").string() + " " + (dir / "bad.jsonl").string());
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.output.find("bad.jsonl:1: not a JSON record"), std::string::npos) << bad.output;
  EXPECT_FALSE(fs::exists(dir / "x.jsonl"));
}

}  // namespace
}  // namespace hexrefine

namespace hexrefine {
namespace {

TEST(CliRun, RunsBothMethodsOnTheSameTargetsAndChecksTheOutputs) {
  const auto dir = test_temp_dir("cli_run_real");
  const std::string abaqus = shared_mesh("abaqus_hex_2x2x2.inp");
  test_file_put(dir / "c.json", R"({"cases":[
    {"name":"full","mesh":{"generate":"brick","dims":[3,3,3]},"select":["all"],"save_mesh":true},
    {"name":"inp","mesh":{"file":")" +
                                    abaqus + R"("},"select":["all"],"methods":["selective"]},
    {"name":"bad-spec","mesh":{"generate":"brick","dims":[2,2,2]},"select":["boxx:1"],
     "methods":["sheet"]}],
    "output":"r.jsonl"})");
  const CliRun r = cli_run("run " + (dir / "c.json").string());
  // The malformed spec is bad input: recorded, the run goes on, and it exits 2 at the end.
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("4 records (0 already present, 0 refused (expected), 1 with an error)"),
            std::string::npos)
      << r.output;
  const JsonlContent c = jsonl_read((dir / "r.jsonl").string());
  ASSERT_EQ(c.records.size(), 4u);
  for (int i = 0; i < 2; ++i) {
    const json& full = c.records[i];
    EXPECT_EQ(full["method"], i == 0 ? "selective" : "sheet");
    EXPECT_FALSE(full.contains("error")) << full.dump();
    EXPECT_EQ(full["input"]["hexes"], 27);
    EXPECT_EQ(full["selection"]["hexes"], 27);
    EXPECT_EQ(full["selection"]["specs"], json({"all"}));
    EXPECT_EQ(full["refine"]["initial_hexes"], 27);
    EXPECT_EQ(full["refine"]["final_hexes"], 729);
    EXPECT_EQ(full["refine"]["final_nodes"], 1000);
    EXPECT_EQ(full["check"]["conformal"], true);
    EXPECT_EQ(full["check"]["inverted_hexes"], 0);
    EXPECT_DOUBLE_EQ(full["check"]["min_scaled_jacobian"].get<double>(), 1.0);
    EXPECT_EQ(full["check"]["scaled_jacobian_histogram"]["counts"][19], 729);
    EXPECT_TRUE(full["stage_seconds"].contains("refine"));
    EXPECT_EQ(full["input"]["generate"], "brick");
    EXPECT_EQ(full["input"]["dims"], json({3, 3, 3}));
    EXPECT_EQ(full["input"]["jitter"], 0.0);  // the generator's defaults are recorded too
    EXPECT_TRUE(fs::exists(dir / "r.meshes" / run_mesh_file_name("full", full["method"])));
  }
  const json& inp = c.records[2];
  EXPECT_EQ(inp["refine"]["final_hexes"], 216);
  EXPECT_EQ(inp["input"]["sha256"], sha256_hex(test_file_text(abaqus)));
  EXPECT_EQ(inp["check"]["conformal"], true);
  const json& bad = c.records[3];
  EXPECT_EQ(bad["error_kind"], "input");
  EXPECT_NE(bad["error"].get<std::string>().find("boxx"), std::string::npos);
}

}  // namespace
}  // namespace hexrefine

namespace hexrefine {
namespace {

/// Runs experiments/studies/thesis/report.py (matplotlib is a CI dependency, .ci/setup.sh).
CliRun plots_py(const std::string& args) {
  return shell_run(std::string("/usr/bin/python3 ") + HEXREFINE_SOURCE_DIR +
                   "/experiments/studies/thesis/report.py " + args);
}

TEST(PlotsPy, PutsOursBesideTheThesisWithRatios) {
  const auto dir = test_temp_dir("plots_py");
  auto g1 = [](const std::string& method, int final_hexes, double seconds, double min_sj) {
    json r = record("G-1", 0, method, method == "selective" ? 0 : 1);
    r["tags"] = {{"table", "G-1"}};
    r["refine"] = {{"final_hexes", final_hexes}, {"time_seconds", seconds}};
    r["check"] = {{"min_scaled_jacobian", min_sj}, {"conformal", true}, {"inverted_hexes", 0}};
    r["input"] = {{"generate", "brick"}, {"hexes", 1000}, {"initial_min_scaled_jacobian", 1.0}};
    return r;
  };
  json sweep = record("G-2/n=10", 1, "sheet", 1);
  sweep["tags"] = {{"table", "G-2"}, {"n", 10}};
  sweep["input"] = {{"generate", "brick"}, {"hexes", 1000}};
  sweep["error"] = "sheet refinement refused";
  test_file_put(dir / "r.jsonl", g1("selective", 8060, 0.0797, 0.3077).dump() + "\n" +
                                     g1("sheet", 27000, 3.242, 1.0).dump() + "\n" + sweep.dump() +
                                     "\n");
  const std::string thesis = std::string(HEXREFINE_SHARED_DIR) + "/thesis/tables.json";
  const CliRun r = plots_py((dir / "r.jsonl").string() + " --thesis " + thesis + " --out " +
                            (dir / "out").string() + " --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string md = test_file_text(dir / "out" / "tables.md");
  // Thesis G-1: sheet 27,000 hexes in 6.484 s, selective 8,060 in 0.797 s (ratios ours/thesis).
  EXPECT_NE(md.find("| Final element count | 27,000 | 27,000 | 1 | 8,060 | 8,060 | 1 |"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("| Time (s) | 6.484 | 3.242 | 0.5 | 0.797 | 0.0797 | 0.1 |"), std::string::npos)
      << md;
  EXPECT_NE(md.find("| 10 | 1,000 | 0.27 | – | – | – | 1 | – | – | – |"), std::string::npos) << md;
  EXPECT_NE(md.find("error: sheet refinement refused"), std::string::npos);
  EXPECT_TRUE(fs::exists(dir / "out" / "plots" / "G-2_time.png"));

  test_file_put(dir / "bad.jsonl", "nonsense\n{}\n");
  const CliRun bad = plots_py((dir / "bad.jsonl").string() + " --thesis " + thesis + " --out " +
                              (dir / "out").string());
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.output.find("bad.jsonl:1: not a JSON record"), std::string::npos) << bad.output;
}

}  // namespace
}  // namespace hexrefine

namespace hexrefine {
namespace {

TEST(CliRun, AnExpectedRefusalIsNotAnError) {
  // The thesis suite's H-3 with the thesis' trilinear positions: the selective templates invert
  // children in distorted parents of the stand-in plate, a refusal the case marks as expected.
  const auto dir = test_temp_dir("cli_run_expected_refusal");
  test_file_put(dir / "c.json", R"({"cases":[{"name":"H-3","mesh":{"file":")" +
                                    shared_mesh("cube_minus_sphere_conforming.mesh") +
                                    R"("},"select":["sphere:0.275,0.275,0,0.15"],
     "methods":["selective"],"options":{"placement":"trilinear"},
     "expect":{"selective":"refused"}}],"output":"r.jsonl"})");
  const CliRun r = cli_run("run " + (dir / "c.json").string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("1 records (0 already present, 1 refused (expected), 0 with an error) "
                          "written to"),
            std::string::npos)
      << r.output;
  const JsonlContent c = jsonl_read((dir / "r.jsonl").string());
  ASSERT_EQ(c.records.size(), 1u);
  EXPECT_EQ(c.records[0]["expect"], "refused");
  EXPECT_EQ(c.records[0]["error_kind"], "operation");
  EXPECT_NE(c.records[0]["error"].get<std::string>().find("inverted"), std::string::npos)
      << c.records[0].dump();
}

}  // namespace
}  // namespace hexrefine
