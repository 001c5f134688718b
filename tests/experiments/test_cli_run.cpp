// The run and merge commands end to end (the hexrefine executable).

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "cli_runner.hpp"
#include "experiments/runner.hpp"

namespace hexrefine {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

void file_put(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out << text;
}

json record(const std::string& name, int case_index, const std::string& method, int method_index) {
  return json{{"case", name},
              {"case_index", case_index},
              {"method", method},
              {"method_index", method_index},
              {"options", run_options_to_json(RefineOptions{}, false)}};
}

TEST(CliRun, BadCaseFileExitsTwoNamingFileAndPath) {
  const auto dir = test_temp_dir("cli_run_bad");
  file_put(dir / "c.json",
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
  file_put(dir / "c.json", R"({"cases":[{"name":"a","mesh":{"generate":"brick","dims":[2,2,2]},
    "select":["all"]}], "output": "out/a.jsonl"})");
  fs::create_directories(dir / "out");
  const std::string done =
      record("a", 0, "selective", 0).dump() + "\n" + record("a", 0, "sheet", 1).dump() + "\n";
  file_put(dir / "out" / "a.jsonl", done);
  const CliRun r = cli_run("run " + (dir / "c.json").string() + " --resume");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("0 records written (2 already present"), std::string::npos) << r.output;
  std::ifstream in(dir / "out" / "a.jsonl");
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_EQ(ss.str(), done);
}

TEST(CliMerge, JoinsShardsDeduplicatedInCaseOrder) {
  const auto dir = test_temp_dir("cli_merge");
  file_put(dir / "s2.jsonl",
           record("b", 1, "selective", 0).dump() + "\n" + record("b", 1, "sheet", 1).dump() + "\n");
  file_put(dir / "s1.jsonl", record("c", 2, "sheet", 1).dump() + "\n" +
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
  file_put(dir / "bad.jsonl", "nonsense\n" + record("a", 0, "sheet", 1).dump() + "\n");
  const CliRun bad =
      cli_run("merge " + (dir / "x.jsonl").string() + " " + (dir / "bad.jsonl").string());
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.output.find("bad.jsonl:1: not a JSON record"), std::string::npos) << bad.output;
  EXPECT_FALSE(fs::exists(dir / "x.jsonl"));
}

}  // namespace
}  // namespace hexrefine
