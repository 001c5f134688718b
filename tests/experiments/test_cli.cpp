#include "experiments/cli.hpp"

#include <gtest/gtest.h>

#include "mesh/error.hpp"

namespace hexrefine {
namespace {

TEST(Cli, ParsesValuesFlagsAndPositionals) {
  const CliArgs a = cli_parse(
      "refine",
      {"in.mesh", "--select", "all", "out.vtk", "--select", "box:0,0,0,1,1,1", "--smooth"},
      {"--select"}, {"--smooth"});
  ASSERT_EQ(a.positional.size(), 2u);
  EXPECT_EQ(a.positional[1], "out.vtk");
  EXPECT_EQ(a.all("--select").size(), 2u);
  EXPECT_TRUE(a.flag("--smooth"));
  EXPECT_FALSE(a.flag("--buffer"));
}

TEST(Cli, RefusesUnknownOptionAndMissingValue) {
  EXPECT_THROW(cli_parse("check", {"m.mesh", "--bogus"}, {"--report"}, {}), InputError);
  EXPECT_THROW(cli_parse("check", {"m.mesh", "--report"}, {"--report"}, {}), InputError);
}

TEST(Cli, ParsesNumberLists) {
  EXPECT_EQ(cli_parse_ints("10,10,10", 3, "--dims"), (std::vector<int>{10, 10, 10}));
  EXPECT_THROW(cli_parse_ints("10,10", 3, "--dims"), InputError);
  EXPECT_THROW(cli_parse_doubles("1,nan,2", 3, "--size"), InputError);
  EXPECT_THROW(cli_parse_doubles("1,x,2", 3, "--size"), InputError);
  EXPECT_DOUBLE_EQ(cli_parse_doubles("0.5,1e-3", -1, "x")[1], 1e-3);
}

}  // namespace
}  // namespace hexrefine
