#include "experiments/bench/process_huge_pages.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "tests/cli_runner.hpp"
#include "tests/fixtures.hpp"

namespace hexrefine {
namespace {

TEST(ProcessHugePages, ModeIsTheBracketedWord) {
  EXPECT_EQ(huge_pages_mode("always [madvise] never\n"), "madvise");
  EXPECT_EQ(huge_pages_mode("[always] madvise never"), "always");
  EXPECT_EQ(huge_pages_mode("always madvise [never]"), "never");
  EXPECT_EQ(huge_pages_mode(""), "");                // no sysfs file
  EXPECT_EQ(huge_pages_mode("always madvise"), "");  // no selection
}

TEST(ProcessHugePages, TunableIsAppendedOnce) {
  EXPECT_EQ(huge_pages_tunables(nullptr).value(), "glibc.malloc.hugetlb=1");
  EXPECT_EQ(huge_pages_tunables("").value(), "glibc.malloc.hugetlb=1");
  EXPECT_EQ(huge_pages_tunables("glibc.malloc.arena_max=2").value(),
            "glibc.malloc.arena_max=2:glibc.malloc.hugetlb=1");
  // Already set, by the user (any value, 0 included) or by the parent that re-executed us.
  EXPECT_FALSE(huge_pages_tunables("glibc.malloc.hugetlb=1").has_value());
  EXPECT_FALSE(huge_pages_tunables("glibc.malloc.arena_max=2:glibc.malloc.hugetlb=0").has_value());
}

bool sanitized_build() {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  return true;
#else
  return false;
#endif
}

// The command re-executes itself with the tunable where the kernel's mode is "madvise", and its
// report says whether it got huge pages; HEXREFINE_HUGE_PAGES=0 opts out. The expectation is
// computed from this machine's kernel mode, so the test holds on any machine, and on the CI's
// (Debian: "madvise") it asserts the re-execution happened.
TEST(ProcessHugePages, CommandReportsWhetherItUsesHugePages) {
  const auto dir = test_temp_dir("process_huge_pages");
  const std::string mode = huge_pages_kernel_mode();
  const std::string mesh = shared_mesh("abaqus_hex_2x2x2.inp");
  for (const bool opt_out : {false, true}) {
    SCOPED_TRACE(opt_out ? "HEXREFINE_HUGE_PAGES=0" : "default");
    const auto report = dir / (opt_out ? "off.json" : "on.json");
    const CliRun run =
        shell_run(std::string(opt_out ? "HEXREFINE_HUGE_PAGES=0 " : "") + "env -u GLIBC_TUNABLES " +
                  HEXREFINE_EXE + " check " + mesh + " --report " + report.string());
    ASSERT_EQ(run.exit_code, 0) << run.output;
    std::ifstream in(report);
    const nlohmann::json j = nlohmann::json::parse(in);
    const bool expected = mode == "always" || (mode == "madvise" && !opt_out && !sanitized_build());
    EXPECT_EQ(j.at("huge_pages"), expected) << "kernel mode '" << mode << "'";
    EXPECT_EQ(j.at("hexes"), 8);  // the re-executed command did the work
  }
}

}  // namespace
}  // namespace hexrefine
