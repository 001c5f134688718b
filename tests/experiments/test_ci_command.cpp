/// \file
/// The README promises that `.ci/run` calls exactly its test command (both edited by hand, so
/// check them); it is the front door (at most 200 lines, linking every page of docs/), and the
/// links of the README and docs/ resolve; docs/cli.md names every command and option.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "experiments/cli/cli.hpp"

namespace hexrefine {
namespace {

namespace fs = std::filesystem;

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

TEST(Docs, ReadmeIsTheFrontDoorAndEveryLinkOfTheDocsResolves) {
  const std::string readme = source_file("README.md");
  EXPECT_LE(std::count(readme.begin(), readme.end(), '\n'), 200);
  const std::vector<std::string> pages = {"docs/cli.md",
                                          "docs/formats.md",
                                          "docs/placement-and-smoothing.md",
                                          "docs/report.md",
                                          "docs/python.md",
                                          "docs/architecture.md",
                                          "docs/experiments.md",
                                          "docs/adding-a-refinement-method.md"};
  for (const std::string& page : pages)
    EXPECT_NE(readme.find("](" + page + ")"), std::string::npos) << "README links " << page;
  // Relative links ](path) and ](path#anchor) of the README and every page name existing files.
  std::vector<std::string> files = pages;
  files.push_back("README.md");
  for (const std::string& file : files) {
    const std::string text = source_file(file);
    const fs::path folder = fs::path(HEXREFINE_SOURCE_DIR) / fs::path(file).parent_path();
    for (size_t at = text.find("]("); at != std::string::npos; at = text.find("](", at + 2)) {
      const size_t end = text.find_first_of(")#", at + 2);
      const std::string target = text.substr(at + 2, end - at - 2);
      // Not a link: code such as a lambda's capture list followed by its parameters.
      if (target.empty() || target.find_first_of(" &,") != std::string::npos) continue;
      if (target.find("://") != std::string::npos) continue;
      EXPECT_TRUE(fs::exists(folder / target)) << file << " links " << target;
    }
  }
}

TEST(Docs, CliPageNamesEveryCommandAndOption) {
  const std::string page = source_file("docs/cli.md");
  for (const CliCommand* c : cli_commands()) {
    EXPECT_NE(page.find("## " + c->name + "\n"), std::string::npos) << c->name;
    for (const CliOption& o : c->options) EXPECT_NE(page.find(o.name), std::string::npos) << o.name;
  }
  for (const char* spec : {"all", "hexes:FILE", "box:", "sphere:", "boundary:", "block:", "random:",
                           "blob:", "surface:"})
    EXPECT_NE(page.find(std::string("`") + spec), std::string::npos) << spec;
}

}  // namespace
}  // namespace hexrefine
