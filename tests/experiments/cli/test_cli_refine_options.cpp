// The three front ends of the pipeline's options table (algorithms/pipeline/
// pipeline_options_table.hpp) agree: the same settings through `refine`'s arguments, a case
// file and the table give the same PipelineOptions; `refine --help` lists every row.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "algorithms/pipeline/pipeline_options_table.hpp"
#include "experiments/cli/cli.hpp"
#include "experiments/runner/runner.hpp"
#include "mesh/error.hpp"

namespace hexrefine {
namespace {

using json = nlohmann::json;

/// The PipelineOptions fields the table sets, as one comparable object.
json options_fingerprint(const PipelineOptions& o) {
  return json{{"refine", o.refine},
              {"smooth", o.smooth},
              {"smoothing",
               {o.smoothing.max_sweeps, o.smoothing.joint_iterations, o.smoothing.joint_rounds,
                o.smoothing.max_edge_ratio, o.smoothing.layers}},
              {"smoothing_both_starts", o.smoothing_both_starts},
              {"max_hexes", o.max_hexes}};
}

/// `refine`'s options from its arguments (space-separated, after IN OUT).
PipelineOptions cli_options_of(const std::string& args) {
  std::vector<std::string> words = {"in.mesh",  "out.mesh", "--method",  "selective",
                                    "--select", "all",      "--threads", "1"};
  std::istringstream in(args);
  for (std::string w; in >> w;) words.push_back(w);
  return cli_refine_options(cli_parse(cli_refine_command, words));
}

/// A case's options as case_execute sets them.
PipelineOptions case_options_of(const json& case_fields) {
  json c = {{"name", "a"}, {"mesh", {{"generate", "brick"}}}, {"select", {"all"}}};
  c.update(case_fields);
  const RunPlan plan = run_plan_parse(json{{"cases", {c}}}, "cases.json", "/n");
  PipelineOptions o;
  pipeline_options_set(o, plan.cases[0].settings, PipelineOptionSpelling());
  // What the record's key is made of agrees with what runs.
  EXPECT_EQ(json(plan.cases[0].options), json(o.refine));
  EXPECT_EQ(plan.cases[0].smooth, o.smooth);
  return o;
}

PipelineOptions table_options_of(const json& settings) {
  PipelineOptions o;
  pipeline_options_set(o, settings, PipelineOptionSpelling());
  return o;
}

TEST(CliRefineOptions, TheCliACaseFileAndTheTableGiveTheSameOptions) {
  struct Example {
    std::string cli;
    json case_fields;
    json settings;
  };
  const std::vector<Example> examples = {
      {"", json::object(), json::object()},
      {"--passes 2 --buffer transitions --placement untangle --smooth --smooth-both-starts "
       "--smooth-sweeps 5 --smooth-joint-iterations 10 --smooth-joint-rounds 2 "
       "--max-edge-ratio 0 --no-ranking --directional-order by_rank --no-propagation --ebe-only "
       "--allow-inverted --max-hexes 1000",
       {{"passes", 2},
        {"smooth", true},
        {"options",
         {{"buffer", "transitions"},
          {"placement", "untangle"},
          {"smooth_both_starts", true},
          {"smooth_sweeps", 5},
          {"smooth_joint_iterations", 10},
          {"smooth_joint_rounds", 2},
          {"max_edge_ratio", 0},
          {"ranking", false},
          {"directional_order", "by_rank"},
          {"propagation", false},
          {"ebe_only", true},
          {"allow_inverted", true},
          {"max_hexes", 1000}}}},
       {{"passes", 2},
        {"buffer", "transitions"},
        {"placement", "untangle"},
        {"smooth", true},
        {"smooth_both_starts", true},
        {"smooth_sweeps", 5},
        {"smooth_joint_iterations", 10},
        {"smooth_joint_rounds", 2},
        {"max_edge_ratio", 0},
        {"ranking", false},
        {"directional_order", "by_rank"},
        {"propagation", false},
        {"ebe_only", true},
        {"allow_inverted", true},
        {"max_hexes", 1000}}},
      // The negation of a choice, the placement's default with smoothing, a real's text.
      {"--no-buffer --smooth --max-edge-ratio 2.5",
       {{"smooth", true}, {"options", {{"buffer", "none"}, {"max_edge_ratio", 2.5}}}},
       {{"buffer", "none"}, {"smooth", true}, {"max_edge_ratio", 2.5}}},
  };
  for (const Example& e : examples) {
    SCOPED_TRACE(e.cli);
    const json table = options_fingerprint(table_options_of(e.settings));
    EXPECT_EQ(options_fingerprint(cli_options_of(e.cli)), table);
    EXPECT_EQ(options_fingerprint(case_options_of(e.case_fields)), table);
  }
  // The second example differs from the defaults in every row.
  const json defaults = options_fingerprint(table_options_of(json::object()));
  for (const PipelineOptionRow& row : pipeline_option_rows()) {
    PipelineOptions one = table_options_of(examples[1].settings);
    row.set(one, row.default_value.is_null() ? json("optimized") : row.default_value);
    EXPECT_NE(options_fingerprint(one), options_fingerprint(table_options_of(examples[1].settings)))
        << row.key;
  }
  EXPECT_NE(options_fingerprint(table_options_of(examples[1].settings)), defaults);
}

TEST(CliRefineOptions, ErrorsNameTheOptionTheCliWay) {
  auto error_of = [](const std::string& args) {
    try {
      cli_options_of(args);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(error_of("--passes 0"), "hexrefine refine: --passes must be in 1..10, got '0'");
  EXPECT_EQ(error_of("--passes x"), "hexrefine refine: --passes must be an integer, got 'x'");
  EXPECT_EQ(error_of("--max-edge-ratio 0.5"),
            "hexrefine refine: --max-edge-ratio must be 0 or in 1..1e6, got '0.5'");
  EXPECT_EQ(error_of("--max-edge-ratio wide"),
            "hexrefine refine: --max-edge-ratio must be a finite number, got 'wide'");
  EXPECT_EQ(error_of("--smooth-joint-rounds 2"),
            "hexrefine refine: --smooth-joint-rounds needs --smooth");
  EXPECT_EQ(error_of("--placement random"),
            "hexrefine refine: --placement must be trilinear, reference, optimized or untangle, "
            "got 'random'");
  EXPECT_EQ(error_of("--directional-order by-hex"),
            "hexrefine refine: --directional-order must be by_hex or by_rank, got 'by-hex' (did "
            "you mean by_hex? values are spelt with '_')");
  EXPECT_EQ(error_of("--buffer wide"),
            "hexrefine refine: --buffer must be layer, transitions or none, got 'wide'");
}

TEST(CliRefineOptions, HelpListsEveryRowTheCliWay) {
  const std::string help = cli_help(cli_refine_command);
  for (const PipelineOptionRow& row : pipeline_option_rows()) {
    std::string name(row.key);
    for (char& c : name)
      if (c == '_') c = '-';
    const std::string shown = row.type == PipelineOptionType::flag && row.default_value == true
                                  ? "  --no-" + name + " "
                                  : "  --" + name + " ";
    EXPECT_NE(help.find(shown), std::string::npos) << shown << "\n" << help;
    if (!row.off_value.empty()) {
      EXPECT_NE(help.find("  --no-" + name + " "), std::string::npos);
    }
  }
  EXPECT_NE(help.find("--smooth-sweeps N  "), std::string::npos) << help;
  EXPECT_NE(help.find("1..1000000 (default 20; fewer: faster, lower minimum)"), std::string::npos);
  EXPECT_NE(help.find("--no-buffer  "), std::string::npos);
  EXPECT_NE(help.find("ablation: no buffer, the same as --buffer none"), std::string::npos);
  EXPECT_NE(help.find("(default untangle with --smooth, else optimized)"), std::string::npos);
}

}  // namespace
}  // namespace hexrefine
