#include "experiments/cli/cli.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <set>
#include <thread>

#include "mesh/error.hpp"
#include "tests/cli_runner.hpp"

namespace hexrefine {
namespace {

TEST(Cli, ParsesValuesFlagsAndPositionals) {
  const CliArgs a = cli_parse(cli_refine_command, {"in.mesh", "--select", "all", "out.vtk",
                                                   "--select", "box:0,0,0,1,1,1", "--smooth"});
  ASSERT_EQ(a.positional.size(), 2u);
  EXPECT_EQ(a.positional[1], "out.vtk");
  EXPECT_EQ(a.all("--select").size(), 2u);
  EXPECT_TRUE(a.flag("--smooth"));
  EXPECT_FALSE(a.flag("--buffer"));
}

TEST(Cli, RefusesUnknownOptionAndMissingValueSuggestingTheClosest) {
  try {
    cli_parse(cli_refine_command, {"in", "out", "--metod", "sheet"});
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("did you mean --method?"), std::string::npos) << e.what();
  }
  try {
    cli_parse(cli_check_command, {"m.mesh", "--bogus"});
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).find("did you mean"), std::string::npos) << e.what();
  }
  EXPECT_THROW(cli_parse(cli_check_command, {"m.mesh", "--report"}), InputError);
  EXPECT_EQ(cli_closest("--threds", {"--threads", "--report"}), "--threads");
  EXPECT_EQ(cli_closest("--x", {"--threads", "--report"}), "");
}

TEST(Cli, ParsesNumberLists) {
  EXPECT_EQ(cli_parse_ints("10,10,10", 3, "--dims"), (std::vector<int>{10, 10, 10}));
  EXPECT_THROW(cli_parse_ints("10,10", 3, "--dims"), InputError);
  EXPECT_THROW(cli_parse_doubles("1,nan,2", 3, "--size"), InputError);
  EXPECT_THROW(cli_parse_doubles("1,x,2", 3, "--size"), InputError);
  EXPECT_DOUBLE_EQ(cli_parse_doubles("0.5,1e-3", -1, "x")[1], 1e-3);
  EXPECT_EQ(cli_parse_int_in("7", 1, 10, "--passes"), 7);
  EXPECT_THROW(cli_parse_int_in("11", 1, 10, "--passes"), InputError);
}

TEST(Cli, ThreadsDefaultToEveryCoreAndTakeOnly1To256) {
  const unsigned cores = std::thread::hardware_concurrency();
  EXPECT_EQ(cli_threads(std::nullopt), static_cast<int>(std::clamp<unsigned>(cores, 1, 256)));
  EXPECT_EQ(cli_threads(std::string("3")), 3);
  EXPECT_EQ(cli_threads(std::string("256")), 256);
  for (const char* bad : {"0", "257", "two"})
    EXPECT_THROW(cli_threads(std::string(bad)), InputError);
}

TEST(Cli, EveryCommandExplainsItselfAndTheUsageListsEveryOption) {
  const CliRun top = cli_run("--help");
  EXPECT_EQ(top.exit_code, 0);
  std::set<std::string> names;
  for (const CliCommand* c : cli_commands()) {
    EXPECT_TRUE(names.insert(c->name).second) << c->name;
    const CliRun help = cli_run(c->name + " --help");
    EXPECT_EQ(help.exit_code, 0) << c->name;
    EXPECT_NE(help.output.find("usage: hexrefine " + c->name), std::string::npos) << help.output;
    for (const CliOption& o : c->options) {
      EXPECT_FALSE(o.help.empty()) << c->name << " " << o.name;
      EXPECT_NE(help.output.find(o.name), std::string::npos) << c->name << " " << o.name;
      EXPECT_NE(top.output.find(o.name), std::string::npos) << c->name << " " << o.name;
    }
  }
  EXPECT_EQ(names.size(), 13u);
  // The options the README documents are in the usage.
  for (const char* o : {"--threads", "--max-hexes", "--binary", "--placement", "--verbose"})
    EXPECT_NE(top.output.find(o), std::string::npos) << o;
  // generate's options come from the generator table.
  const CliRun generate = cli_run("generate --help");
  for (const char* o : {"--dims", "--jitter", "--tip-fraction", "--section-intervals", "--cell"})
    EXPECT_NE(generate.output.find(o), std::string::npos) << o;
  const CliRun unknown = cli_run("refin in out");
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_NE(unknown.output.find("did you mean refine?"), std::string::npos) << unknown.output;
}

TEST(CliTemplates, ListsTheLibraryWithItsQualityAloneAtTheThesisAndTheReferencePositions) {
  const auto dir = test_temp_dir("cli_templates");
  const std::string report = (dir / "t.json").string();
  const CliRun r = cli_run("templates --report " + report);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("1-13"), std::string::npos);
  EXPECT_NE(r.output.find("face rule"), std::string::npos);
  const nlohmann::json all = nlohmann::json::parse(test_file_text(report));
  const nlohmann::json& j = all["templates"];
  ASSERT_EQ(j.size(), 8u);
  EXPECT_EQ(j[1]["template"], "1-13");
  EXPECT_NEAR(j[1]["min_scaled_jacobian_alone"].get<double>(), 4.0 / 13.0, 1e-12);
  EXPECT_NEAR(j[1]["min_scaled_jacobian_reference"].get<double>(), 0.5, 1e-4);
  EXPECT_GE(j[1]["min_scaled_jacobian_own_rule"].get<double>(),
            j[1]["min_scaled_jacobian_reference"].get<double>());
  EXPECT_EQ(j[1]["children"], 13);
  EXPECT_EQ(j[7]["template"], "1-9");
  EXPECT_EQ(j[7]["sets"], nlohmann::json({"sheet_directional"}));
  EXPECT_EQ(j[0]["sets"], nlohmann::json({"element_by_element", "sheet_directional"}));
  for (const auto& t : j) EXPECT_GE(t["min_scaled_jacobian_reference"].get<double>(), 0.4);
  EXPECT_GT(all["directional_configurations"]["count"].get<int64_t>(), 0);
  // --optimize checks its output path before computing anything.
  EXPECT_EQ(cli_run("templates --optimize " + (dir / "no" / "t.inc").string()).exit_code, 2);
}

}  // namespace
}  // namespace hexrefine
