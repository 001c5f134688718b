/// \file
/// `hexrefine bench --instructions` and `hexrefine bench-compare --gate instructions`
/// (experiments/cli/cli_bench_instructions.cpp, experiments/cli/cli_bench_gate.cpp): the gate's
/// verdicts and exit codes, malformed files, the committed baseline (every workload, with its
/// identity), and a real run of a few workloads under Callgrind, twice (the counts repeat).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "cli_runner.hpp"

namespace hexrefine {
namespace {

using nlohmann::json;

const std::string baseline_path =
    std::string(HEXREFINE_SOURCE_DIR) + "/results/bench/instructions.json";

/// An instruction-count file with benchmarks `counts` (name -> instructions), in that order.
json counts_document(const std::vector<std::pair<std::string, long long>>& counts) {
  json doc = {{"format", "hexrefine-instructions"},
              {"version", 1},
              {"context", json::object()},
              {"benchmarks", json::array()}};
  for (const auto& [name, n] : counts)
    doc["benchmarks"].push_back({{"name", name}, {"instructions", n}});
  return doc;
}

std::string put(const std::filesystem::path& dir, const std::string& name, const json& doc) {
  const std::string path = (dir / name).string();
  test_file_put(path, doc.dump(2));
  return path;
}

std::string put_text(const std::filesystem::path& dir, const std::string& name,
                     const std::string& text) {
  const std::string path = (dir / name).string();
  test_file_put(path, text);
  return path;
}

CliRun gate(const std::string& base, const std::string& now, const std::string& extra = "") {
  return cli_run("bench-compare " + base + " " + now + " --gate instructions" + extra);
}

/// The output line that starts with `prefix` ("" if none).
std::string line_starting(const std::string& output, const std::string& prefix) {
  std::istringstream lines(output);
  std::string line;
  while (std::getline(lines, line))
    if (line.rfind(prefix, 0) == 0) return line;
  return "";
}

TEST(CliBenchGate, RegressionsFailImprovementsPrintTheThresholdMoves) {
  const auto dir = test_temp_dir("cli_bench_gate_verdicts");
  const std::string base =
      put(dir, "base.json",
          counts_document(
              {{"same", 1000000}, {"within", 1000000}, {"grew", 1000000}, {"shrank", 1000000}}));
  const std::string now =
      put(dir, "new.json",
          counts_document(
              {{"same", 1000000}, {"within", 1029000}, {"grew", 1040000}, {"shrank", 900000}}));
  const CliRun r = gate(base, now);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(line_starting(r.output, "grew ").find("1.0400  REGRESSION (+4.00 %)"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(line_starting(r.output, "within ").find("REGRESSION"), std::string::npos) << r.output;
  EXPECT_NE(line_starting(r.output, "within ").find("1.0290"), std::string::npos) << r.output;
  EXPECT_NE(line_starting(r.output, "shrank ").find("0.9000  improved (-10.00 %)"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("regression: grew ratio 1.0400"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("improved: shrank ratio 0.9000"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("summary: 4 compared, 1 regressions, 1 improvements, 0 missing in NEW"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("gate FAILED"), std::string::npos) << r.output;

  // A 5 % threshold lets the 4 % growth pass; the improvement is still printed.
  const CliRun loose = gate(base, now, " --threshold 0.05");
  EXPECT_EQ(loose.exit_code, 0) << loose.output;
  EXPECT_EQ(loose.output.find("REGRESSION"), std::string::npos) << loose.output;
  EXPECT_NE(loose.output.find("improved: shrank ratio 0.9000"), std::string::npos) << loose.output;
  EXPECT_NE(loose.output.find("gate passed"), std::string::npos) << loose.output;
}

TEST(CliBenchGate, AWorkloadMissingFromNewFailsANewOneIsNotGated) {
  const auto dir = test_temp_dir("cli_bench_gate_missing");
  const std::string one = put(dir, "one.json", counts_document({{"a", 500}}));
  const std::string two = put(dir, "two.json", counts_document({{"a", 500}, {"b", 700}}));
  const CliRun added = gate(one, two);
  EXPECT_EQ(added.exit_code, 0) << added.output;
  EXPECT_NE(added.output.find("not in BASE (not gated until the baseline is updated): b"),
            std::string::npos)
      << added.output;
  const CliRun removed = gate(two, one);
  EXPECT_EQ(removed.exit_code, 1) << removed.output;
  EXPECT_NE(removed.output.find("missing in NEW (fails the gate): b"), std::string::npos)
      << removed.output;
}

TEST(CliBenchGate, NamesTheWorkThatChanged) {
  const auto dir = test_temp_dir("cli_bench_gate_work");
  json base = counts_document({{"refine/x", 1000}});
  json now = counts_document({{"refine/x", 1200}});
  base["benchmarks"][0]["work"] = {{"final_hexes", 8060}, {"final_nodes", 10000}};
  now["benchmarks"][0]["work"] = {{"final_hexes", 9000}, {"final_nodes", 10000}};
  const CliRun r = gate(put(dir, "base.json", base), put(dir, "new.json", now));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("work changed: final_hexes 8060 -> 9000\n"), std::string::npos)
      << r.output;
}

TEST(CliBenchGate, MalformedBaselinesExitTwoNamingTheFileAndTheKey) {
  const auto dir = test_temp_dir("cli_bench_gate_malformed");
  const std::string good = put(dir, "good.json", counts_document({{"a", 100}}));
  json wrong_format = counts_document({{"a", 100}});
  wrong_format["format"] = "google-benchmark";
  json wrong_version = counts_document({{"a", 100}});
  wrong_version["version"] = 2;
  json no_benchmarks = counts_document({});
  no_benchmarks.erase("benchmarks");
  json benchmarks_object = counts_document({});
  benchmarks_object["benchmarks"] = json::object();
  json no_name = counts_document({{"a", 100}});
  no_name["benchmarks"][0].erase("name");
  json no_count = counts_document({{"a", 100}});
  no_count["benchmarks"][0].erase("instructions");
  json text_count = counts_document({{"a", 100}});
  text_count["benchmarks"][0]["instructions"] = "many";
  json negative = counts_document({{"a", -100}});
  json fraction = counts_document({{"a", 100}});
  fraction["benchmarks"][0]["instructions"] = 1.5;
  const std::vector<std::pair<std::string, std::string>> cases = {
      {put_text(dir, "broken.json", "{\"format\": "), "not valid JSON"},
      {put_text(dir, "array.json", "[]"), "expected a JSON object"},
      {put_text(dir, "google.json", "{\"benchmarks\": []}"), "key \"format\" missing"},
      {put(dir, "wrong_format.json", wrong_format), "key \"format\""},
      {put(dir, "wrong_version.json", wrong_version), "key \"version\""},
      {put(dir, "no_benchmarks.json", no_benchmarks), "key \"benchmarks\" missing"},
      {put(dir, "benchmarks_object.json", benchmarks_object),
       "key \"benchmarks\": expected an array"},
      {put(dir, "no_name.json", no_name), "benchmarks[0]: key \"name\" missing"},
      {put(dir, "no_count.json", no_count), "benchmarks[0] (\"a\"): key \"instructions\" missing"},
      {put(dir, "text_count.json", text_count),
       "key \"instructions\": expected a positive integer, got \"many\""},
      {put(dir, "negative.json", negative),
       "key \"instructions\": expected a positive integer, got -100"},
      {put(dir, "fraction.json", fraction),
       "key \"instructions\": expected a positive integer, got 1.5"},
      {put(dir, "twice.json", counts_document({{"a", 1}, {"a", 2}})),
       "benchmarks[1] (\"a\"): key \"name\": \"a\" appears twice"},
      {(dir / "absent.json").string(), "cannot open"},
  };
  for (const auto& [path, key] : cases) {
    const CliRun as_base = gate(path, good);
    EXPECT_EQ(as_base.exit_code, 2) << path << ": " << as_base.output;
    EXPECT_NE(as_base.output.find(path + ": "), std::string::npos) << as_base.output;
    EXPECT_NE(as_base.output.find(key), std::string::npos) << key << " in " << as_base.output;
    const CliRun as_new = gate(good, path);
    EXPECT_EQ(as_new.exit_code, 2) << path << ": " << as_new.output;
    EXPECT_NE(as_new.output.find(path + ": "), std::string::npos) << as_new.output;
  }
  EXPECT_EQ(cli_run("bench-compare " + good + " " + good + " --gate time").exit_code, 2);
  EXPECT_EQ(gate(good, good, " --threshold -0.1").exit_code, 2);
  EXPECT_EQ(gate(good, good, " --by cpu").exit_code, 2);
  EXPECT_EQ(cli_run("bench-compare " + good + " --gate instructions").exit_code, 2);
  EXPECT_EQ(cli_run("bench --instructions --smoke").exit_code, 2);
  EXPECT_EQ(cli_run("bench --instructions --jobs 0").exit_code, 2);
  EXPECT_EQ(cli_run("bench --jobs 2").exit_code, 2);
}

json read_json(const std::string& path) {
  return json::parse(test_file_text(path));
}

/// The identity keys every benchmark of an instruction file carries, and the work counts.
void expect_identity(const json& b) {
  for (const char* key :
       {"name", "operation", "case", "method", "placement", "format", "description"}) {
    ASSERT_TRUE(b.contains(key) && b[key].is_string() && !b[key].get<std::string>().empty())
        << key << " in " << b.dump();
  }
  ASSERT_TRUE(b.contains("size") && b["size"].is_number_integer()) << b.dump();
  EXPECT_GT(b["size"].get<long long>(), 0) << b.dump();
  EXPECT_EQ(b["threads"], 1) << b.dump();
  ASSERT_TRUE(b.contains("instructions") && b["instructions"].is_number_integer()) << b.dump();
  EXPECT_GT(b["instructions"].get<long long>(), 0) << b.dump();
  EXPECT_TRUE(b.contains("work") && b["work"].is_object() && !b["work"].empty()) << b.dump();
  const std::string operation = b["operation"];
  if (operation == "refine" || operation == "smooth" || operation == "command") {
    EXPECT_TRUE(b["method"] == "selective" || b["method"] == "sheet") << b.dump();
    EXPECT_NE(b["placement"], "none") << b.dump();
  }
  if (operation == "read" || operation == "write") {
    EXPECT_NE(b["format"], "none") << b.dump();
  }
}

/// The names instruction_workloads lists (the driver beside the hexrefine binary).
std::vector<std::string> driver_workloads() {
  const std::string driver =
      (std::filesystem::path(HEXREFINE_EXE).parent_path() / "instruction_workloads").string();
  const CliRun r = shell_run(driver + " --list");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  std::vector<std::string> names;
  std::istringstream lines(r.output);
  std::string line;
  while (std::getline(lines, line))
    if (!line.empty()) names.push_back(line);
  return names;
}

TEST(CliBenchGate, TheCommittedBaselineHoldsEveryWorkloadWithItsIdentity) {
  const json baseline = read_json(baseline_path);
  EXPECT_EQ(baseline["format"], "hexrefine-instructions");
  std::vector<std::string> names;
  for (const json& b : baseline["benchmarks"]) {
    expect_identity(b);
    names.push_back(b["name"]);
  }
  // In the driver's order; a workload added or renamed needs the baseline regenerated.
  EXPECT_EQ(names, driver_workloads());
  // The coverage: both refiners on every refinement case, placement, smoothing on a
  // real mesh, the checker, and a reader and a writer of each main format.
  const std::set<std::string> name_set(names.begin(), names.end());
  for (const char* c : {"full_brick_10", "l_shaped_10", "radial_10", "random_10"})
    for (const char* method : {"selective", "sheet"})
      EXPECT_TRUE(name_set.count(std::string("refine/") + c + "/" + method + "/trilinear"))
          << c << " " << method;
  for (const char* method : {"selective", "sheet"})
    EXPECT_TRUE(name_set.count(std::string("refine/rockerarm_sphere_5/") + method + "/optimized"))
        << method;
  EXPECT_TRUE(name_set.count("smooth/rockerarm_sphere_3/selective/optimized"));
  EXPECT_TRUE(name_set.count("check/rockerarm"));
  for (const char* format : {"medit", "vtk_ascii", "vtk_binary", "vtu", "gmsh", "exodus", "abaqus"})
    for (const char* op : {"read", "write"})
      EXPECT_TRUE(name_set.count(std::string(op) + "/rockerarm/" + format)) << op << " " << format;
}

TEST(CliBenchGate, TheCommittedBaselineLoweredByTenPercentFailsUnchangedPasses) {
  const auto dir = test_temp_dir("cli_bench_gate_baseline");
  json lowered = read_json(baseline_path);
  const size_t count = lowered["benchmarks"].size();
  ASSERT_GT(count, 30u);
  for (json& b : lowered["benchmarks"])
    b["instructions"] =
        static_cast<long long>(std::floor(b["instructions"].get<long long>() * 0.9));
  const std::string lowered_path = put(dir, "lowered.json", lowered);

  const CliRun unchanged = gate(baseline_path, baseline_path);
  EXPECT_EQ(unchanged.exit_code, 0) << unchanged.output;
  EXPECT_NE(unchanged.output.find("summary: " + std::to_string(count) +
                                  " compared, 0 regressions, 0 improvements"),
            std::string::npos)
      << unchanged.output;

  const CliRun inflated = gate(lowered_path, baseline_path);
  EXPECT_EQ(inflated.exit_code, 1) << inflated.output;
  EXPECT_NE(inflated.output.find("summary: " + std::to_string(count) + " compared, " +
                                 std::to_string(count) + " regressions"),
            std::string::npos)
      << inflated.output;
  for (const json& b : lowered["benchmarks"]) {
    const std::string line =
        line_starting(inflated.output, "regression: " + b["name"].get<std::string>() + " ");
    EXPECT_NE(line.find("ratio 1.111"), std::string::npos) << b["name"] << ": " << inflated.output;
  }
}

TEST(CliBenchInstructions, TwoRunsCountTheSameWithTheIdentity) {
  const auto dir = test_temp_dir("cli_bench_instructions_runs");
  const std::string filter =
      "'^(quality/rockerarm|topology/brick_25|refine/radial_10/selective/trilinear)$'";
  std::vector<json> runs;
  for (int run = 0; run < 2; ++run) {
    const std::string out = (dir / ("run" + std::to_string(run) + ".json")).string();
    const CliRun r =
        shell_run("HEXREFINE_SHARED_DIR=" + std::string(HEXREFINE_SHARED_DIR) + " " +
                  HEXREFINE_EXE + " bench --instructions --filter " + filter + " --out " + out);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    runs.push_back(read_json(out));
  }
  ASSERT_EQ(runs[0]["benchmarks"].size(), 3u) << runs[0].dump(2);
  EXPECT_EQ(runs[0]["context"]["tool"], "callgrind");
  for (size_t i = 0; i < 3; ++i) {
    const json& a = runs[0]["benchmarks"][i];
    const json& b = runs[1]["benchmarks"][i];
    expect_identity(a);
    EXPECT_EQ(a["name"], b["name"]);
    EXPECT_EQ(a["work"], b["work"]) << a["name"];
    const double first = a["instructions"].get<double>(), second = b["instructions"].get<double>();
    EXPECT_LE(std::abs(second - first) / first, 0.001)
        << a["name"] << ": " << first << " vs " << second;
  }
  // The radial case's identity as the issue names it: case, size, method, placement.
  const json& radial = runs[0]["benchmarks"][0];
  EXPECT_EQ(radial["name"], "refine/radial_10/selective/trilinear");
  EXPECT_EQ(radial["case"], "radial_10");
  EXPECT_EQ(radial["size"], 1000);
  EXPECT_EQ(radial["method"], "selective");
  EXPECT_EQ(radial["placement"], "trilinear");
  EXPECT_EQ(gate((dir / "run0.json").string(), (dir / "run1.json").string()).exit_code, 0);
}

}  // namespace
}  // namespace hexrefine
