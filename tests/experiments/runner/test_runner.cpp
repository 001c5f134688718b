#include "experiments/runner/runner.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "cli_runner.hpp"
#include "experiments/runner/cases.hpp"
#include "mesh/error.hpp"

namespace hexrefine {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

/// The message of the InputError `f` throws ("" if it throws nothing or something else).
template <typename F>
std::string input_error_of(F f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  } catch (...) {
    return "(other exception)";
  }
  return "";
}

json brick_case(const std::string& name) {
  return json{
      {"name", name}, {"mesh", {{"generate", "brick"}, {"dims", {2, 2, 2}}}}, {"select", {"all"}}};
}

/// "c0", "c1", ... (built with += : "c" + std::to_string trips GCC 12's -Wrestrict false positive)
std::string fake_case_name(int i) {
  std::string name = "c";
  name += std::to_string(i);
  return name;
}

/// A plan of `n` cases "c0".."c{n-1}", both methods, built in memory.
RunPlan fake_plan(int n, const std::string& output) {
  json cases = json::array();
  for (int i = 0; i < n; ++i) cases.push_back(brick_case(fake_case_name(i)));
  RunPlan plan = run_plan_parse(json{{"cases", cases}}, "mem.json", "/nonexistent");
  plan.output = output;
  return plan;
}

/// A fake method: "final_hexes" = 27 * (case index + 1) for selective, 100 + index for sheet.
struct FakeExecutor {
  int calls = 0;
  std::vector<std::string> ran;  ///< "case:method" in order
  void operator()(const RunCase& c, const std::vector<std::string>& methods, const RunEmit& emit) {
    ++calls;
    for (const std::string& m : methods) {
      ran.push_back(c.name + ":" + m);
      emit(m, json{{"final_hexes", m == "selective" ? 27 * (c.index + 1) : 100 + c.index}});
    }
  }
};

RunSettings quiet_settings() {
  RunSettings s;
  s.quiet = true;
  s.environment.commit = "abc123";
  s.environment.cpu = "test cpu";
  s.environment.cores = 2;
  s.environment.build_type = "release";
  return s;
}

TEST(Sha256, KnownDigests) {
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  // 56 bytes: the padding spills into a second block.
  EXPECT_EQ(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(sha256_hex(std::string(1000000, 'a')),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST(Sha256, OfFileMatchesOfBytes) {
  const auto dir = test_temp_dir("runner_sha_file");
  test_file_put(dir / "m.txt", "abc");
  EXPECT_EQ(sha256_file((dir / "m.txt").string()), sha256_hex("abc"));
  EXPECT_NE(input_error_of([&] { sha256_file((dir / "missing.txt").string()); }), "");
}

TEST(RunPlan, ParsesDefaultsAndResolvesRelativePaths) {
  const auto dir = test_temp_dir("runner_parse");
  test_file_put(dir / "m.mesh", "x");
  const json root = {{"cases",
                      {brick_case("a"),
                       {{"name", "b"},
                        {"mesh", {{"file", "m.mesh"}}},
                        {"select", {"sphere:0,0,0,1", "hexes:sel.txt"}},
                        {"methods", {"sheet"}},
                        {"passes", 3},
                        {"smooth", true},
                        {"save_mesh", true},
                        {"options", {{"buffer", true}, {"ranking", false}}},
                        {"tags", {{"table", "X"}}}}}},
                     {"output", "out/r.jsonl"}};
  const RunPlan plan = run_plan_parse(root, "cases.json", dir.string());
  ASSERT_EQ(plan.cases.size(), 2u);
  const RunCase& a = plan.cases[0];
  EXPECT_EQ(a.methods, (std::vector<std::string>{"selective", "sheet"}));
  EXPECT_EQ(a.options.passes, 1);
  EXPECT_TRUE(a.options.ranking);
  EXPECT_FALSE(a.smooth);
  const RunCase& b = plan.cases[1];
  EXPECT_EQ(b.index, 1);
  EXPECT_EQ(b.mesh["file"], "m.mesh");
  EXPECT_EQ(b.mesh["path"], (dir / "m.mesh").string());
  EXPECT_EQ(b.select[1], "hexes:" + (dir / "sel.txt").string());
  EXPECT_EQ(b.select_given[1], "hexes:sel.txt");
  EXPECT_EQ(b.options.passes, 3);
  EXPECT_EQ(b.options.buffer, PassBuffer::transitions);  // the boolean of earlier case files
  EXPECT_FALSE(b.options.ranking);
  EXPECT_TRUE(b.smooth);
  EXPECT_TRUE(b.save_mesh);
  EXPECT_FALSE(a.save_mesh);
  EXPECT_EQ(b.tags["table"], "X");
  EXPECT_EQ(plan.output, (dir / "out" / "r.jsonl").string());
  // Without "output": beside the case file, named after it.
  const RunPlan p2 = run_plan_parse(json{{"cases", {brick_case("a")}}}, "sweep.json", "/d");
  EXPECT_EQ(p2.output, "/d/sweep.jsonl");
}

TEST(RunPlan, SchemaErrorsNameFileAndJsonPath) {
  auto error_of = [](const json& root) {
    return input_error_of([&] { run_plan_parse(root, "cases.json", "/nonexistent"); });
  };
  EXPECT_EQ(error_of(json::array()), "cases.json: /: expected an object");
  EXPECT_EQ(error_of(json{{"output", "x"}}), "cases.json: /: missing \"cases\"");
  EXPECT_EQ(error_of(json{{"cases", json::array()}}),
            "cases.json: /cases: expected a non-empty array");
  json c = brick_case("a");
  c["passes"] = 0;
  EXPECT_EQ(error_of(json{{"cases", {brick_case("z"), c}}}),
            "cases.json: /cases/1/passes: expected an integer >= 1");
  c = brick_case("a");
  c["methods"] = {"selective", "octree"};
  EXPECT_EQ(error_of(json{{"cases", {c}}}),
            "cases.json: /cases/0/methods/1: unknown refinement method 'octree' (expected one "
            "of: selective, sheet)");
  c = brick_case("a");
  c["mesh"]["dims"] = {2, 0.5, 2};
  EXPECT_EQ(error_of(json{{"cases", {c}}}),
            "cases.json: /cases/0/mesh/dims: expected 3 integers, got [2,0.5,2]");
  c = brick_case("a");
  c["options"] = {{"placement", "smooth"}};
  EXPECT_EQ(error_of(json{{"cases", {c}}}),
            "cases.json: /cases/0/options/placement: expected \"trilinear\", \"reference\", "
            "\"optimized\" or \"untangle\"");
  c = brick_case("a");
  c["mesh"]["radius"] = 1.0;
  EXPECT_NE(error_of(json{{"cases", {c}}})
                .find("/cases/0/mesh/radius: unknown parameter of "
                      "generator 'brick'"),
            std::string::npos);
  c = brick_case("a");
  c["optoins"] = json::object();
  EXPECT_NE(error_of(json{{"cases", {c}}}).find("cases.json: /cases/0/optoins: unknown key"),
            std::string::npos);
  c = brick_case("a");
  c["options"] = {{"ranking", 1}};
  EXPECT_EQ(error_of(json{{"cases", {c}}}),
            "cases.json: /cases/0/options/ranking: expected true or false");
  c = brick_case("a");
  c["mesh"] = {{"file", "nowhere.mesh"}};
  EXPECT_EQ(error_of(json{{"cases", {c}}}),
            "cases.json: /cases/0/mesh/file: mesh file not found: /nonexistent/nowhere.mesh");
  c = brick_case("a");
  c["mesh"] = {{"file", "x.mesh"}, {"generate", "brick"}};
  EXPECT_EQ(error_of(json{{"cases", {c}}}),
            "cases.json: /cases/0/mesh: expected exactly one of \"generate\" or \"file\"");
  c = brick_case("a");
  c.erase("select");
  EXPECT_NE(error_of(json{{"cases", {c}}}).find("/cases/0: missing \"select\""), std::string::npos);
  EXPECT_EQ(error_of(json{{"cases", {brick_case("a"), brick_case("a")}}}),
            "cases.json: /cases/1/name: case name 'a' used twice");
}

TEST(RunPlan, ReadReportsSyntaxErrorLine) {
  const auto dir = test_temp_dir("runner_read");
  test_file_put(dir / "bad.json", "{\"cases\": [\n  {\"name\": \"a\",\n   \"mesh\": }\n]}\n");
  const std::string e = input_error_of([&] { run_plan_read((dir / "bad.json").string()); });
  EXPECT_EQ(e.rfind((dir / "bad.json").string() + ":3: invalid JSON", 0), 0u) << e;
  EXPECT_NE(input_error_of([&] { run_plan_read((dir / "none.json").string()); }), "");
}

TEST(RunRecordKey, OptionsAreCanonical) {
  RefineOptions defaults;
  RefineOptions same;
  same.ranking = true;
  EXPECT_EQ(run_record_key("G-1", "selective", run_options_to_json(defaults, false)),
            run_record_key("G-1", "selective", run_options_to_json(same, false)));
  RefineOptions other;
  other.ranking = false;
  EXPECT_NE(run_record_key("G-1", "selective", run_options_to_json(defaults, false)),
            run_record_key("G-1", "selective", run_options_to_json(other, false)));
  EXPECT_NE(run_record_key("G-1", "selective", run_options_to_json(defaults, false)),
            run_record_key("G-1", "selective", run_options_to_json(defaults, true)));
  // Every RefineOptions field but threads (the output does not depend on it), and "smooth".
  EXPECT_EQ(run_options_to_json(defaults, false).size(), 9u);
  EXPECT_FALSE(run_options_to_json(defaults, false).contains("threads"));
  RefineOptions trilinear;
  trilinear.placement.method = PlacementMethod::trilinear;
  EXPECT_NE(run_record_key("G-1", "selective", run_options_to_json(defaults, false)),
            run_record_key("G-1", "selective", run_options_to_json(trilinear, false)));
}

TEST(Jsonl, AppendsAndReadsBack) {
  const auto dir = test_temp_dir("runner_jsonl");
  const std::string path = (dir / "r.jsonl").string();
  EXPECT_TRUE(jsonl_read(path).records.empty());  // missing file: no records
  for (int i = 0; i < 3; ++i)
    jsonl_append(path, json{{"case", fake_case_name(i)},
                            {"method", "sheet"},
                            {"options", json::object()},
                            {"value", i}});
  const JsonlContent c = jsonl_read(path);
  ASSERT_EQ(c.records.size(), 3u);
  EXPECT_EQ(c.records[2]["value"], 2);
  EXPECT_FALSE(c.truncated_tail);
  EXPECT_EQ(c.valid_text, test_file_text(path));
  EXPECT_EQ(std::count(c.valid_text.begin(), c.valid_text.end(), '\n'), 3);
}

TEST(Jsonl, DropsTruncatedLastLineOnly) {
  const auto dir = test_temp_dir("runner_jsonl_trunc");
  const std::string path = (dir / "r.jsonl").string();
  const std::string good = "{\"case\":\"a\",\"method\":\"sheet\",\"options\":{}}\n";
  test_file_put(path, good + "{\"case\":\"b\",\"meth");
  JsonlContent c = jsonl_read(path);
  EXPECT_EQ(c.records.size(), 1u);
  EXPECT_TRUE(c.truncated_tail);
  EXPECT_EQ(c.valid_text, good);
  // A complete record without its final newline is also treated as cut short.
  test_file_put(path, good + good.substr(0, good.size() - 1));
  c = jsonl_read(path);
  EXPECT_EQ(c.records.size(), 1u);
  EXPECT_TRUE(c.truncated_tail);
  // A bad line in the middle is bad input, named by line.
  test_file_put(path, good + "garbage\n");
  EXPECT_EQ(input_error_of([&] { jsonl_read(path); }), path + ":2: not a JSON record");
  test_file_put(path, good + "garbage\n" + good);
  EXPECT_EQ(input_error_of([&] { jsonl_read(path); }), path + ":2: not a JSON record");
  test_file_put(path, good + "{\"case\":\"a\"}\n");
  EXPECT_EQ(input_error_of([&] { jsonl_read(path); }).rfind(path + ":2: record without", 0), 0u);
}

TEST(RunPlanExecute, WritesOneRecordPerCaseAndMethod) {
  const auto dir = test_temp_dir("runner_execute");
  const std::string out = (dir / "r.jsonl").string();
  const RunPlan plan = fake_plan(3, out);
  FakeExecutor fake;
  const RunSummary s = run_plan_execute(plan, quiet_settings(), std::ref(fake));
  EXPECT_EQ(s.records_written, 6);
  EXPECT_EQ(s.records_skipped, 0);
  EXPECT_EQ(s.errors, 0);
  EXPECT_EQ(fake.calls, 3);
  const auto records = jsonl_read(out).records;
  ASSERT_EQ(records.size(), 6u);
  EXPECT_EQ(records[0]["case"], "c0");
  EXPECT_EQ(records[0]["method"], "selective");
  EXPECT_EQ(records[1]["method"], "sheet");
  EXPECT_EQ(records[1]["method_index"], 1);
  EXPECT_EQ(records[4]["case_index"], 2);
  EXPECT_EQ(records[4]["final_hexes"], 81);
  EXPECT_EQ(records[5]["final_hexes"], 102);
  EXPECT_EQ(records[0]["commit"], "abc123");
  EXPECT_EQ(records[0]["commit_dirty"], false);
  EXPECT_EQ(records[0]["machine"]["cpu"], "test cpu");
  EXPECT_EQ(records[0]["machine"]["cores"], 2);
  EXPECT_EQ(records[0]["build_type"], "release");
  EXPECT_EQ(records[0]["options"]["passes"], 1);
  EXPECT_EQ(records[0]["timestamp"].get<std::string>().size(), 20u);
  // A second run without --resume starts the file over.
  run_plan_execute(plan, quiet_settings(), std::ref(fake));
  EXPECT_EQ(jsonl_read(out).records.size(), 6u);
}

TEST(RunPlanExecute, ReportsProgressCaseByCase) {
  const auto dir = test_temp_dir("runner_progress");
  const RunPlan plan = fake_plan(3, (dir / "r.jsonl").string());
  std::ostringstream progress;
  RunSettings settings = quiet_settings();
  settings.progress = &progress;
  FakeExecutor fake;
  run_plan_execute(plan, settings, std::ref(fake));
  const std::string text = progress.str();
  EXPECT_EQ(text.rfind("[case 1 of 3] c0 (2 methods)  elapsed ", 0), 0u) << text;
  EXPECT_NE(text.find("[case 3 of 3] c2 (2 methods)"), std::string::npos) << text;
  EXPECT_NE(text.find(" s left"), std::string::npos) << text;  // an estimate once one case is done
  EXPECT_NE(text.find("done: 6 records in "), std::string::npos) << text;
}

TEST(RunPlanExecute, ResumeAfterKilledRunLosesNothingAndRepeatsNothing) {
  const auto dir = test_temp_dir("runner_resume");
  const std::string out = (dir / "r.jsonl").string();
  const RunPlan plan = fake_plan(4, out);
  FakeExecutor first;
  run_plan_execute(plan, quiet_settings(), std::ref(first));
  // Simulate a run killed while writing its 6th record: 5 whole lines and half of the 6th.
  std::string text = test_file_text(out);
  size_t pos = 0;
  for (int i = 0; i < 5; ++i) pos = text.find('\n', pos) + 1;
  const size_t sixth_end = text.find('\n', pos);
  test_file_put(out, text.substr(0, pos + (sixth_end - pos) / 2));

  RunSettings settings = quiet_settings();
  settings.resume = true;
  FakeExecutor second;
  const RunSummary s = run_plan_execute(plan, settings, std::ref(second));
  EXPECT_EQ(s.records_skipped, 5);
  EXPECT_EQ(s.records_written, 3);
  // c2's selective record survived; its sheet record (cut short) and c3's two are redone.
  EXPECT_EQ(second.ran, (std::vector<std::string>{"c2:sheet", "c3:selective", "c3:sheet"}));
  const auto records = jsonl_read(out);
  EXPECT_FALSE(records.truncated_tail);
  ASSERT_EQ(records.records.size(), 8u);
  std::set<std::string> keys;
  for (const json& r : records.records) keys.insert(run_record_key(r));
  EXPECT_EQ(keys.size(), 8u);
  // Resuming a finished run does nothing.
  FakeExecutor third;
  const RunSummary s3 = run_plan_execute(plan, settings, std::ref(third));
  EXPECT_EQ(s3.records_skipped, 8);
  EXPECT_EQ(s3.records_written, 0);
  EXPECT_EQ(third.calls, 0);
}

TEST(RunPlanExecute, ErrorsBecomeRecordsAndTheRunGoesOn) {
  const auto dir = test_temp_dir("runner_errors");
  const std::string out = (dir / "r.jsonl").string();
  const RunPlan plan = fake_plan(3, out);
  auto executor = [](const RunCase& c, const std::vector<std::string>& methods,
                     const RunEmit& emit) {
    if (c.index == 0) throw OperationError("mesh could not be built");
    for (const std::string& m : methods) {
      if (c.index == 1 && m == "sheet") throw InputError("bad spec 'boxx:1'");
      emit(m, json{{"final_hexes", 1}});
    }
  };
  const RunSummary s = run_plan_execute(plan, quiet_settings(), executor);
  EXPECT_EQ(s.records_written, 6);
  EXPECT_EQ(s.errors, 3);
  const auto records = jsonl_read(out).records;
  ASSERT_EQ(records.size(), 6u);
  EXPECT_EQ(records[0]["error"], "mesh could not be built");
  EXPECT_EQ(records[0]["error_kind"], "operation");
  EXPECT_EQ(records[1]["error"], "mesh could not be built");
  EXPECT_FALSE(records[2].contains("error"));
  EXPECT_EQ(records[3]["error"], "bad spec 'boxx:1'");
  EXPECT_EQ(records[3]["error_kind"], "input");
  EXPECT_EQ(records[5]["final_hexes"], 1);
}

TEST(RunPlan, ExpectRefusedForTheCaseOrPerMethod) {
  json all = brick_case("a"), one = brick_case("b");
  all["expect"] = "refused";
  one["expect"] = {{"sheet", "refused"}};
  const RunPlan plan = run_plan_parse(json{{"cases", {all, one, brick_case("c")}}}, "m.json", "/");
  EXPECT_EQ(plan.cases[0].refusals_expected, (std::vector<std::string>{"selective", "sheet"}));
  EXPECT_EQ(plan.cases[1].refusals_expected, std::vector<std::string>{"sheet"});
  EXPECT_TRUE(plan.cases[2].refusals_expected.empty());
  auto error_of = [&](const json& expect, std::vector<std::string> methods = {}) {
    json c = brick_case("x");
    c["expect"] = expect;
    if (!methods.empty()) c["methods"] = methods;
    return input_error_of([&] { run_plan_parse(json{{"cases", {c}}}, "m.json", "/"); });
  };
  EXPECT_NE(error_of("failed").find("m.json: /cases/0/expect: expected \"refused\""),
            std::string::npos);
  EXPECT_NE(error_of(true).find("m.json: /cases/0/expect: expected \"refused\" or an object"),
            std::string::npos);
  EXPECT_NE(error_of(json::object()).find("/cases/0/expect: expected"), std::string::npos);
  EXPECT_NE(error_of({{"sheet", "refused"}}, {"selective"})
                .find("/cases/0/expect/sheet: method 'sheet' is not one of the case's methods"),
            std::string::npos);
  EXPECT_NE(error_of({{"sheet", "ok"}}).find("/cases/0/expect/sheet: expected \"refused\""),
            std::string::npos);
}

TEST(RunPlanExecute, ExpectedRefusalsAreCountedApartFromErrors) {
  const auto dir = test_temp_dir("runner_expected_refusals");
  const std::string out = (dir / "r.jsonl").string();
  json refused = brick_case("refused"), bad = brick_case("bad-input"), missed = brick_case("ok");
  refused["expect"] = {{"selective", "refused"}};
  bad["expect"] = "refused";
  missed["expect"] = {{"sheet", "refused"}};
  RunPlan plan = run_plan_parse(json{{"cases", {refused, bad, missed}}}, "m.json", "/");
  plan.output = out;
  // "refused": selective refuses (expected), sheet refuses too (not expected: an error);
  // "bad-input": a bad input is an error even where a refusal is expected; "ok": both refine.
  auto executor = [](const RunCase& c, const std::vector<std::string>& methods,
                     const RunEmit& emit) {
    for (const std::string& m : methods) {
      if (c.name == "refused")
        emit(m, json{{"error", "cannot refine"}, {"error_kind", "operation"}});
      else if (c.name == "bad-input")
        emit(m, json{{"error", "bad spec"}, {"error_kind", "input"}});
      else
        emit(m, json{{"final_hexes", 1}});
    }
  };
  const RunSummary s = run_plan_execute(plan, quiet_settings(), executor);
  EXPECT_EQ(s.records_written, 6);
  EXPECT_EQ(s.refusals_expected, 1);
  EXPECT_EQ(s.errors, 3);
  EXPECT_EQ(s.refusals_missing, 1);
  EXPECT_EQ(run_summary_counts(s),
            "6 records (0 already present, 1 refused (expected), 3 with an error, 1 expected to "
            "be refused but refined)");
  const auto records = jsonl_read(out).records;
  ASSERT_EQ(records.size(), 6u);
  EXPECT_EQ(records[0]["expect"], "refused");
  EXPECT_FALSE(records[1].contains("expect"));
  EXPECT_EQ(records[2]["expect"], "refused");
  EXPECT_EQ(records[3]["expect"], "refused");
  EXPECT_FALSE(records[4].contains("expect"));
  EXPECT_EQ(records[5]["expect"], "refused");
  EXPECT_FALSE(records[5].contains("error"));
  for (const json& r : records) EXPECT_EQ(r["schema_version"], 1) << r.dump();
  RunSummary clean = s;
  clean.refusals_missing = 0;
  EXPECT_EQ(run_summary_counts(clean),
            "6 records (0 already present, 1 refused (expected), 3 with an error)");
}

TEST(RunShard, ParsesOneBasedAndRefusesNonsense) {
  EXPECT_EQ(run_shard_parse("1/4"), (std::pair<int, int>{0, 4}));
  EXPECT_EQ(run_shard_parse("4/4"), (std::pair<int, int>{3, 4}));
  for (const char* bad : {"0/4", "5/4", "1/0", "a/4", "1-4", "1/", "/4", "-1/4", "1/4/2"})
    EXPECT_NE(input_error_of([&] { run_shard_parse(bad); }), "") << bad;
  EXPECT_EQ(run_shard_output("/r/thesis.jsonl", 1, 3), "/r/thesis.shard-2-of-3.jsonl");
  EXPECT_EQ(run_shard_output("/r/thesis.jsonl", 0, 1), "/r/thesis.jsonl");
}

TEST(RunShard, ShardsPartitionTheCasesAndMergeRestoresTheOrder) {
  const auto dir = test_temp_dir("runner_shards");
  const std::string out = (dir / "r.jsonl").string();
  const RunPlan plan = fake_plan(7, out);
  std::vector<std::vector<json>> parts;
  std::multiset<std::string> cases_run;
  for (int k = 0; k < 3; ++k) {
    RunSettings settings = quiet_settings();
    settings.shard = k;
    settings.shard_count = 3;
    FakeExecutor fake;
    const RunSummary s = run_plan_execute(plan, settings, std::ref(fake));
    EXPECT_EQ(s.output, run_shard_output(out, k, 3));
    parts.push_back(jsonl_read(s.output).records);
    for (const json& r : parts.back()) cases_run.insert(r["case"].get<std::string>());
    for (const json& r : parts.back()) EXPECT_EQ(r["case_index"].get<int>() % 3, k);
  }
  EXPECT_EQ(parts[0].size(), 6u);  // cases 0, 3, 6
  EXPECT_EQ(parts[1].size(), 4u);  // cases 1, 4
  EXPECT_EQ(parts[2].size(), 4u);  // cases 2, 5
  EXPECT_EQ(cases_run.size(), 14u);
  for (int i = 0; i < 7; ++i) EXPECT_EQ(cases_run.count(fake_case_name(i)), 2u);

  // Merge in the wrong order, with a duplicate: case order restored, one record per key.
  std::vector<std::vector<json>> inputs = {parts[2], parts[0], parts[1], {parts[0][2]}};
  inputs.back()[0]["final_hexes"] = -7;  // a rerun of c3:selective supersedes the first
  const std::vector<json> merged = run_records_merge(inputs);
  ASSERT_EQ(merged.size(), 14u);
  for (size_t i = 0; i < merged.size(); ++i) {
    EXPECT_EQ(merged[i]["case_index"], static_cast<int>(i / 2));
    EXPECT_EQ(merged[i]["method_index"], static_cast<int>(i % 2));
  }
  EXPECT_EQ(merged[6]["case"], "c3");
  EXPECT_EQ(merged[6]["final_hexes"], -7);
  jsonl_write((dir / "merged.jsonl").string(), merged);
  EXPECT_EQ(jsonl_read((dir / "merged.jsonl").string()).records, merged);
}

TEST(RunEnvironment, DetectsCommitMachineAndBuild) {
  const RunEnvironment env = run_environment_detect();
  // The tests run from a git checkout of the source tree.
  EXPECT_EQ(env.commit.size(), 40u) << env.commit;
  EXPECT_GE(env.cores, 1);
  EXPECT_FALSE(env.cpu.empty());
  EXPECT_TRUE(env.build_type == "release" || env.build_type == "debug");
}

TEST(RunMeshFileName, ReplacesPathCharacters) {
  EXPECT_EQ(run_mesh_file_name("G-3/n=20", "selective"), "G-3_n=20.selective.vtu");
  EXPECT_EQ(run_mesh_file_name("a b:c", "sheet"), "a_b_c.sheet.vtu");
}

TEST(RealMeshStudy, IsAValidCaseFileWithEveryRegionKindArmAndTheAnisotropyCases) {
  const std::string meshes = std::string(HEXREFINE_SHARED_DIR) + "/meshes";
  std::vector<StudyMesh> files;
  for (const char* file : {"rockerarm.mesh", "sphere_sculpt.e", "sphere_projected_inverted.mesh"})
    files.push_back({meshes + "/" + file, meshes + "/" + file, file, "../shared/meshes", true});
  // The same file from a folder given with --meshes: named apart, tagged with its folder.
  files.push_back({meshes + "/sphere_sculpt.e", meshes + "/./sphere_sculpt.e", "sphere_sculpt.e",
                   "corpus", false});
  files.push_back({meshes + "/no_such.mesh", "no_such.mesh", "no_such.mesh", "corpus", false});
  std::vector<std::string> skipped;
  const json root = real_mesh_study_cases(files, "r.jsonl", INT64_MAX, &skipped);
  ASSERT_EQ(skipped.size(), 1u);
  EXPECT_NE(skipped[0].find("no_such.mesh"), std::string::npos) << skipped[0];
  const RunPlan plan = run_plan_parse(root, "study.json", "/");
  // 7 region kinds per mesh (4 meshes), rockerarm's issue ball, x 3 arms; then 9 box shapes
  // (aspect 1 once, 1.5, 2, 3, 4 long and flat) x 3 arms.
  EXPECT_EQ(plan.cases.size(), (7 * 4 + 1) * 3u + 9 * 3u);
  std::map<std::string, int> arms;
  int anisotropy = 0, invalid_inputs = 0, corpus = 0;
  for (const RunCase& c : plan.cases) {
    EXPECT_EQ(c.methods, (std::vector<std::string>{"selective", "sheet"})) << c.name;
    const std::string arm = c.tags.value("arm", "");
    ++arms[arm];
    // The arms of issue 28: trilinear and default unsmoothed, default smoothed. The default arms
    // give no placement (the case file's default: optimized, until the pipeline picks its own).
    EXPECT_EQ(c.smooth, arm == "default-smooth") << c.name;
    EXPECT_EQ(c.options.placement.method == PlacementMethod::trilinear, arm == "trilinear")
        << c.name;
    EXPECT_EQ(c.name.substr(c.name.rfind('/') + 1), arm);
    EXPECT_EQ(c.options.passes, c.tags.value("kind", "") == "two-passes" ? 2 : 1) << c.name;
    if (c.tags.value("study", "") == "real_meshes") {
      EXPECT_EQ(c.tags["source"], c.tags["folder"] == "corpus" ? "meshes" : "shared");
      if (!c.tags["input_valid"].get<bool>()) {
        ++invalid_inputs;
        EXPECT_EQ(c.tags["mesh"], "sphere_projected_inverted.mesh");
        EXPECT_FALSE(c.tags["input_defects"].empty());
      }
      if (c.tags["folder"] == "corpus") {
        ++corpus;
        EXPECT_EQ(c.mesh["file"], meshes + "/./sphere_sculpt.e");  // the case path, as given
        EXPECT_EQ(c.name.rfind("corpus:sphere_sculpt.e/", 0), 0u) << c.name;
      }
    }
    if (c.tags.value("study", "") != "anisotropy") continue;
    ++anisotropy;
    EXPECT_EQ(c.mesh["generate"], "brick") << c.name;
    EXPECT_EQ(c.mesh["dims"], json({5, 5, 5})) << c.name;
    ASSERT_EQ(c.select.size(), 1u);
    EXPECT_EQ(c.select[0].rfind("sphere:", 0), 0u) << c.name;
  }
  EXPECT_EQ(arms, (std::map<std::string, int>{
                      {"trilinear", 38}, {"default", 38}, {"default-smooth", 38}}));
  EXPECT_EQ(anisotropy, 27);
  EXPECT_EQ(invalid_inputs, 7 * 3);
  EXPECT_EQ(corpus, 7 * 3);
  EXPECT_EQ(plan.cases.back().name, "aspect-4-flat/default-smooth");
  EXPECT_EQ(plan.cases.back().mesh["size"], json({4.0, 4.0, 1.0}));

  // --max-hexes-input: rockerarm (10,600 hexes) is left out and named, the small ones stay.
  skipped.clear();
  const json small = real_mesh_study_cases({files[0], files[1]}, "r.jsonl", 1000, &skipped);
  ASSERT_EQ(skipped.size(), 1u);
  EXPECT_NE(skipped[0].find("10600 hexes"), std::string::npos) << skipped[0];
  EXPECT_EQ(small["cases"].size(), 7 * 3u + 9 * 3u);
}

TEST(ThesisSuite, IsAValidCaseFileWithBothMethodsOnEveryComparison) {
  const std::string meshes = std::string(HEXREFINE_SHARED_DIR) + "/meshes";
  for (const bool quick : {true, false}) {
    const json root = thesis_suite_cases(quick, meshes, "thesis.jsonl");
    const RunPlan plan = run_plan_parse(root, "suite.json", "/");
    const size_t sweep = quick ? 6 : 15;  // n = 5..30 or 5..75
    // G-1, 6-1, 6-2, H-1, ring, H-2 (three buffer rules), H-3, H-4, real (trilinear placement:
    // the thesis'), the same eleven with optimized placement, 6 ablations, two sweeps.
    EXPECT_EQ(plan.cases.size(), 28u + 2 * sweep);
    int g2 = 0, ablations = 0, optimized = 0;
    for (const RunCase& c : plan.cases) {
      if (c.options.placement.method == PlacementMethod::optimized) {
        ++optimized;
        EXPECT_EQ(c.tags.value("placement", ""), "optimized") << c.name;
      }
      if (c.tags.value("table", "") == "G-2") {
        ++g2;
        EXPECT_EQ(c.select, std::vector<std::string>{"all"});
      }
      if (c.tags.value("table", "") == "ablation") {
        ++ablations;
        EXPECT_EQ(c.methods, std::vector<std::string>{"selective"});
      } else {
        EXPECT_EQ(c.methods, (std::vector<std::string>{"selective", "sheet"})) << c.name;
      }
    }
    EXPECT_EQ(g2, static_cast<int>(sweep));
    EXPECT_EQ(ablations, 6);
    EXPECT_EQ(optimized, 11);
    EXPECT_EQ(plan.cases[0].name, "G-1");
    EXPECT_TRUE(plan.cases[0].save_mesh);
    EXPECT_EQ(plan.cases[1].name, "6-1");
    EXPECT_TRUE(plan.cases[1].save_mesh);
    // Pictures: the L-shaped brick, the stepped model, the gear teeth, the twisted ring and the
    // radial region (G-3 at n = 10).
    std::vector<std::string> saved;
    for (const RunCase& c : plan.cases)
      if (c.save_mesh) saved.push_back(c.name);
    EXPECT_EQ(saved, (std::vector<std::string>{"G-1", "6-1", "H-1", "ring", "G-3/n=10"}));
    // The one refusal the suite expects: H-3's selective method at the thesis' positions.
    std::vector<std::string> expected;
    for (const RunCase& c : plan.cases)
      for (const std::string& m : c.refusals_expected) expected.push_back(c.name + ":" + m);
    EXPECT_EQ(expected, std::vector<std::string>{"H-3:selective"});
    EXPECT_EQ(plan.cases[0].mesh["dims"], json({10, 10, 10}));
    EXPECT_EQ(plan.cases[0].select,
              (std::vector<std::string>{"boundary:-1,0,0", "boundary:0,0,-1"}));
    EXPECT_EQ(plan.cases.back().name, quick ? "G-3/n=30" : "G-3/n=75");
    EXPECT_EQ(plan.output, "/thesis.jsonl");
  }
  EXPECT_EQ(thesis_sweep_intervals(true), (std::vector<int>{5, 10, 15, 20, 25, 30}));
}

}  // namespace
}  // namespace hexrefine
