#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_runner.hpp"

namespace hexrefine {
namespace {

/// Writes `text` to `dir/name` and returns the path.
std::string write_file(const std::filesystem::path& dir, const std::string& name,
                       const std::string& text) {
  const std::string path = (dir / name).string();
  std::ofstream(path) << text;
  return path;
}

/// One plain Google Benchmark entry.
std::string entry(const std::string& name, double real, double cpu, const std::string& unit) {
  return "{\"name\": \"" + name + "\", \"run_name\": \"" + name +
         "\", \"run_type\": \"iteration\", \"iterations\": 1, \"real_time\": " +
         std::to_string(real) + ", \"cpu_time\": " + std::to_string(cpu) + ", \"time_unit\": \"" +
         unit + "\"}";
}

/// One aggregate entry of benchmark `name` (aggregate "median", "mean", ...).
std::string aggregate(const std::string& name, const std::string& kind, double real, double cpu) {
  return "{\"name\": \"" + name + "_" + kind + "\", \"run_name\": \"" + name +
         "\", \"run_type\": \"aggregate\", \"aggregate_name\": \"" + kind +
         "\", \"iterations\": 3, \"real_time\": " + std::to_string(real) +
         ", \"cpu_time\": " + std::to_string(cpu) + ", \"time_unit\": \"ms\"}";
}

std::string document(const std::vector<std::string>& entries) {
  std::string out = "{\"context\": {}, \"benchmarks\": [";
  for (size_t i = 0; i < entries.size(); ++i) out += (i ? ", " : "") + entries[i];
  return out + "]}";
}

/// The output line that starts with `name` followed by a space ("" if none).
std::string line_of(const std::string& output, const std::string& name) {
  size_t pos = 0;
  while (pos < output.size()) {
    const size_t end = output.find('\n', pos);
    const std::string line = output.substr(pos, end - pos);
    if (line.rfind(name + " ", 0) == 0) return line;
    if (end == std::string::npos) break;
    pos = end + 1;
  }
  return "";
}

TEST(CliBenchCompare, RatiosFlagsAndMissingEntries) {
  const auto dir = test_temp_dir("cli_bench_compare");
  const std::string base = write_file(
      dir, "base.json",
      document({entry("same/10", 100, 100, "ms"), entry("slow/10", 100, 100, "ms"),
                entry("fast/10", 100, 100, "ms"), entry("gone/10", 1, 1, "ms"),
                entry("units/10", 2000, 2000, "us"), entry("small/10", 100, 100, "ms")}));
  const std::string now =
      write_file(dir, "new.json",
                 document({entry("same/10", 103, 102, "ms"), entry("slow/10", 150, 200, "ms"),
                           entry("fast/10", 50, 80, "ms"), entry("added/10", 1, 1, "ms"),
                           entry("units/10", 3, 3, "ms"), entry("small/10", 100, 104, "ms")}));
  const CliRun r = cli_run("bench-compare " + base + " " + now);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // real ratio, cpu ratio, flag on cpu time beyond 5 %.
  const std::string same = line_of(r.output, "same/10");
  EXPECT_NE(same.find("1.030"), std::string::npos) << same;
  EXPECT_NE(same.find("1.020"), std::string::npos) << same;
  EXPECT_EQ(same.find("slower"), std::string::npos) << same;
  const std::string slow = line_of(r.output, "slow/10");
  EXPECT_NE(slow.find("1.500"), std::string::npos) << slow;
  EXPECT_NE(slow.find("2.000"), std::string::npos) << slow;
  EXPECT_NE(slow.find("slower"), std::string::npos) << slow;
  const std::string fast = line_of(r.output, "fast/10");
  EXPECT_NE(fast.find("0.500"), std::string::npos) << fast;
  EXPECT_NE(fast.find("0.800"), std::string::npos) << fast;
  EXPECT_NE(fast.find("faster"), std::string::npos) << fast;
  // 2000 us -> 3 ms: times are compared in seconds.
  EXPECT_NE(line_of(r.output, "units/10").find("1.500"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("missing in NEW: gone/10"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("missing in BASE: added/10"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("summary: 5 compared, 2 slower, 1 faster, 0 with errors, 1 missing in "
                          "NEW, 1 missing in BASE"),
            std::string::npos)
      << r.output;

  // A tighter threshold flags the 4 % change; --by real flags on real time (1.03 > 1.02).
  const CliRun tight = cli_run("bench-compare " + base + " " + now + " --threshold 0.03");
  ASSERT_EQ(tight.exit_code, 0) << tight.output;
  EXPECT_NE(line_of(tight.output, "small/10").find("slower"), std::string::npos) << tight.output;
  EXPECT_EQ(line_of(tight.output, "same/10").find("slower"), std::string::npos) << tight.output;
  const CliRun real = cli_run("bench-compare " + base + " " + now + " --threshold 0.02 --by real");
  ASSERT_EQ(real.exit_code, 0) << real.output;
  EXPECT_NE(line_of(real.output, "same/10").find("slower"), std::string::npos) << real.output;
  EXPECT_EQ(line_of(real.output, "small/10").find("slower"), std::string::npos) << real.output;
}

TEST(CliBenchCompare, UsesTheMedianAggregateWhenRepetitionsExist) {
  const auto dir = test_temp_dir("cli_bench_compare_median");
  // Repetitions 10, 30, 20 ms: median 20; the mean aggregate (a decoy, 1000) must be ignored.
  const std::string base = write_file(
      dir, "base.json",
      document({entry("rep/5", 10, 10, "ms"), entry("rep/5", 30, 30, "ms"),
                entry("rep/5", 20, 20, "ms"), aggregate("rep/5", "mean", 1000, 1000),
                aggregate("rep/5", "median", 20, 20), aggregate("rep/5", "stddev", 5, 5)}));
  // No aggregates: the median of the plain entries (40, 10, 30 -> 30).
  const std::string now =
      write_file(dir, "new.json",
                 document({entry("rep/5", 40, 40, "ms"), entry("rep/5", 10, 10, "ms"),
                           entry("rep/5", 30, 30, "ms")}));
  const CliRun r = cli_run("bench-compare " + base + " " + now);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string line = line_of(r.output, "rep/5");
  EXPECT_NE(line.find("1.500  "), std::string::npos) << r.output;
  // 1.5 times the median, but the repetitions overlap (10 and 30 on both sides): U = 6 of 9,
  // p = 0.35, so not a regression.
  EXPECT_NE(line.find("within spread"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("summary: 1 compared, 0 slower"), std::string::npos) << r.output;
}

TEST(CliBenchCompare, FlagsOnlyChangesBeyondTheSpreadOfRepetitions) {
  const auto dir = test_temp_dir("cli_bench_compare_spread");
  const std::string base =
      write_file(dir, "base.json",
                 document({entry("apart/5", 100, 100, "ms"), entry("apart/5", 101, 101, "ms"),
                           entry("apart/5", 99, 99, "ms"), entry("noisy/5", 100, 100, "ms"),
                           entry("noisy/5", 110, 110, "ms"), entry("noisy/5", 90, 90, "ms"),
                           entry("single/5", 100, 100, "ms")}));
  const std::string now =
      write_file(dir, "new.json",
                 document({entry("apart/5", 110, 110, "ms"), entry("apart/5", 111, 111, "ms"),
                           entry("apart/5", 109, 109, "ms"), entry("noisy/5", 95, 95, "ms"),
                           entry("noisy/5", 150, 150, "ms"), entry("noisy/5", 120, 120, "ms"),
                           entry("single/5", 110, 110, "ms")}));
  const CliRun r = cli_run("bench-compare " + base + " " + now);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // Every new repetition above every base one: U = 9, p = 1/20 = 0.05.
  EXPECT_NE(line_of(r.output, "apart/5").find("  slower"), std::string::npos) << r.output;
  // Median ratio 1.2 but U = 7: p = 4/20.
  EXPECT_NE(line_of(r.output, "noisy/5").find("within spread"), std::string::npos) << r.output;
  // One run each: no spread to test, the ratio flags with a question mark.
  EXPECT_NE(line_of(r.output, "single/5").find("slower?"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("summary: 3 compared, 2 slower"), std::string::npos) << r.output;
}

TEST(CliBenchCompare, AcceptsTheNaNGoogleBenchmarkPrints) {
  // Google Benchmark prints NaN for the cv aggregate of a counter that is always 0.
  const auto dir = test_temp_dir("cli_bench_compare_nan");
  const std::string base = write_file(
      dir, "base.json",
      "{\"benchmarks\": [{\"name\": \"n/1_median\", \"run_name\": \"n/1\", \"run_type\": "
      "\"aggregate\", \"aggregate_name\": \"median\", \"real_time\": 4, \"cpu_time\": 4, "
      "\"time_unit\": \"ms\", \"zero\": 0}, {\"name\": \"n/1_cv\", \"run_name\": \"n/1\", "
      "\"run_type\": \"aggregate\", \"aggregate_name\": \"cv\", \"real_time\": 0.1, "
      "\"cpu_time\": 0.1, \"time_unit\": \"ms\", \"zero\": NaN, \"other\": -inf}]}");
  const std::string now = write_file(dir, "new.json", document({entry("n/1", 2, 2, "ms")}));
  const CliRun r = cli_run("bench-compare " + base + " " + now);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(line_of(r.output, "n/1").find("0.500"), std::string::npos) << r.output;
  EXPECT_NE(line_of(r.output, "n/1").find("faster"), std::string::npos) << r.output;
}

TEST(CliBenchCompare, ErrorEntriesAreListedNotCompared) {
  const auto dir = test_temp_dir("cli_bench_compare_error");
  const std::string base = write_file(dir, "base.json", document({entry("e/1", 1, 1, "ms")}));
  const std::string now = write_file(
      dir, "new.json",
      "{\"benchmarks\": [{\"name\": \"e/1\", \"run_name\": \"e/1\", \"run_type\": "
      "\"iteration\", \"error_occurred\": true, \"error_message\": \"not implemented\"}]}");
  const CliRun r = cli_run("bench-compare " + base + " " + now);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("error: NEW not implemented"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("0 compared, 0 slower, 0 faster, 1 with errors"), std::string::npos)
      << r.output;
}

TEST(CliBenchCompare, BadInputExitsTwoNamingTheFile) {
  const auto dir = test_temp_dir("cli_bench_compare_bad");
  const std::string good = write_file(dir, "good.json", document({entry("a/1", 1, 1, "ms")}));
  const std::string broken = write_file(dir, "broken.json", "{\"benchmarks\": [");
  const std::string no_array = write_file(dir, "no_array.json", "{\"context\": {}}");
  const std::string no_time = write_file(
      dir, "no_time.json", "{\"benchmarks\": [{\"name\": \"a/1\", \"real_time\": \"fast\"}]}");
  const std::string bad_unit =
      write_file(dir, "bad_unit.json", document({entry("a/1", 1, 1, "h")}));
  const std::string missing = (dir / "missing.json").string();
  for (const std::string& bad : {broken, no_array, no_time, bad_unit, missing}) {
    const CliRun r = cli_run("bench-compare " + good + " " + bad);
    EXPECT_EQ(r.exit_code, 2) << bad << ": " << r.output;
    EXPECT_NE(r.output.find(bad), std::string::npos) << r.output;
  }
  EXPECT_EQ(cli_run("bench-compare " + good).exit_code, 2);
  EXPECT_EQ(cli_run("bench-compare " + good + " " + good + " --threshold -1").exit_code, 2);
  EXPECT_EQ(cli_run("bench-compare " + good + " " + good + " --threshold x").exit_code, 2);
  EXPECT_EQ(cli_run("bench-compare " + good + " " + good + " --by wall").exit_code, 2);
  // Identical files: every ratio 1, nothing flagged.
  const CliRun same = cli_run("bench-compare " + good + " " + good);
  ASSERT_EQ(same.exit_code, 0) << same.output;
  EXPECT_NE(same.output.find("summary: 1 compared, 0 slower, 0 faster"), std::string::npos)
      << same.output;
}

TEST(CliBench, BadUsageExitsTwo) {
  EXPECT_EQ(cli_run("bench --bogus").exit_code, 2);
  EXPECT_EQ(cli_run("bench extra").exit_code, 2);
  EXPECT_EQ(cli_run("bench --repetitions 0").exit_code, 2);
  EXPECT_EQ(cli_run("bench --filter").exit_code, 2);
}

TEST(CliBench, HistoryGetsOneRecordPerRun) {
  const auto dir = test_temp_dir("cli_bench_history");
  const std::string history = (dir / "history.jsonl").string();
  for (int run = 0; run < 2; ++run) {
    const CliRun r = cli_run(
        "bench --smoke --filter 'bench_check_rockerarm' --repetitions 3 "
        "--history " +
        history + " --out " + (dir / "out.json").string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  std::ifstream in(history);
  std::string line;
  int records = 0;
  while (std::getline(in, line)) {
    const nlohmann::json j = nlohmann::json::parse(line);
    ++records;
    EXPECT_TRUE(j.contains("commit") && j.contains("date") && j.contains("machine")) << line;
    EXPECT_TRUE(j["machine"].contains("huge_pages") && j["machine"]["huge_pages"].is_boolean())
        << line;
    EXPECT_EQ(j["smoke"], true);
    const nlohmann::json& b = j["benchmarks"]["bench_check_rockerarm/real_time"];
    EXPECT_EQ(b["repetitions"], 3) << line;
    EXPECT_LE(b["real_range"][0].get<double>(), b["real_median"].get<double>());
    EXPECT_GE(b["real_range"][1].get<double>(), b["real_median"].get<double>());
  }
  EXPECT_EQ(records, 2);
}

}  // namespace
}  // namespace hexrefine
