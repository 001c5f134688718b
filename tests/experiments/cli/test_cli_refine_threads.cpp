// `hexrefine refine --threads N`: the parallel template application, node placement, smoothing
// and the write beside the check give the same file.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "tests/cli_runner.hpp"

namespace hexrefine {
namespace {

TEST(CliRefineThreads, SameFileForAnyThreadCount) {
  const auto dir = test_temp_dir("cli_refine_threads");
  const std::string brick = (dir / "brick.mesh").string();
  ASSERT_EQ(cli_run("generate brick " + brick + " --dims 6,6,6 --jitter 0.2 --seed 3").exit_code,
            0);
  for (const char* method : {"selective", "sheet"}) {
    for (const char* select : {"all", "sphere:0,0,0,2.5", "sphere:0,0,0,2.5 --smooth"}) {
      std::string first;
      for (int threads : {1, 2, 4}) {
        const std::string out = (dir / ("out" + std::to_string(threads) + ".mesh")).string();
        const CliRun r = cli_run("refine " + brick + " " + out + " --method " + method +
                                 " --select " + select + " --threads " + std::to_string(threads));
        ASSERT_EQ(r.exit_code, 0) << method << " " << select << " " << threads << ": " << r.output;
        const std::string text = test_file_text(out);
        ASSERT_GT(text.size(), 1000u);
        if (first.empty())
          first = text;
        else
          EXPECT_EQ(text, first) << method << " " << select << " with " << threads << " threads";
      }
    }
  }
}

TEST(CliRefineThreads, BadThreadCountIsUsageError) {
  const auto dir = test_temp_dir("cli_refine_threads_bad");
  const std::string brick = (dir / "brick.mesh").string();
  ASSERT_EQ(cli_run("generate brick " + brick + " --dims 2,2,2").exit_code, 0);
  for (const char* bad : {"0", "-1", "x", "1000"}) {
    const CliRun r = cli_run("refine " + brick + " " + (dir / "o.mesh").string() +
                             " --method selective --select all --threads " + bad);
    EXPECT_EQ(r.exit_code, 2) << bad;
    EXPECT_NE(r.output.find("--threads"), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir / "o.mesh"));
  }
}

}  // namespace
}  // namespace hexrefine
