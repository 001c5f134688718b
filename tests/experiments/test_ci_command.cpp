/// \file
/// The README promises that `.ci/run` calls exactly its test command and that its "Limits and
/// errors" section is results/limits.md; both copies are edited by hand, so check them.

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <sstream>
#include <string>

namespace hexrefine {
namespace {

std::string source_file(const std::string& relative) {
  std::ifstream in(std::string(HEXREFINE_SOURCE_DIR) + "/" + relative, std::ios::binary);
  EXPECT_TRUE(in.good()) << relative;
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(CiCommand, CiRunCallsExactlyTheReadmeTestCommand) {
  std::istringstream readme(source_file("README.md"));
  std::string line, command;
  int commands = 0;
  // The test command is the README's one-line command that runs ctest.
  while (std::getline(readme, line))
    if (line.rfind("bash .ci/setup.sh && ", 0) == 0 && line.find("ctest ") != std::string::npos)
      command = line, ++commands;
  ASSERT_EQ(commands, 1);
  EXPECT_NE(command.find(" && tests/fuzz/run_fuzzers.sh 30"), std::string::npos) << command;
  std::istringstream ci(source_file(".ci/run"));
  std::string last;
  while (std::getline(ci, line))
    if (!line.empty()) last = line;
  EXPECT_EQ(last, command);
}

TEST(CiCommand, ReadmeLimitsSectionIsResultsLimits) {
  const std::string readme = source_file("README.md");
  const size_t at = readme.find("## Limits and errors");
  ASSERT_NE(at, std::string::npos);
  EXPECT_EQ(readme.substr(at), source_file("results/limits.md"));
}

}  // namespace
}  // namespace hexrefine
