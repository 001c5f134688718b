/// \file
/// A `hexrefine run` killed with SIGKILL midway loses no finished record: `--resume` completes
/// the run and every (case, method) has exactly one record, none lost and none repeated.

#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "cli_runner.hpp"

extern char** environ;

namespace hexrefine {
namespace {

namespace fs = std::filesystem;

/// Complete lines of `p` (a killed writer may leave a partial last line without '\n').
std::vector<std::string> file_complete_lines(const fs::path& p) {
  const std::string text = test_file_text(p);
  std::vector<std::string> lines;
  size_t start = 0;
  for (size_t nl = text.find('\n'); nl != std::string::npos; nl = text.find('\n', start)) {
    lines.push_back(text.substr(start, nl - start));
    start = nl + 1;
  }
  return lines;
}

TEST(CliRunKill, KilledRunResumesWithoutLosingOrRepeatingRecords) {
  const auto dir = test_temp_dir("run_kill");
  // Case 0 is tiny so its records appear at once; cases 1-5 take long enough (a 14^3 brick,
  // 2,744 hexes -> 74,088) that the kill lands in the middle of the run.
  std::string cases = R"({"output": "out.jsonl", "cases": [)";
  cases += R"({"name": "c0", "mesh": {"generate": "brick", "dims": [1, 1, 1]}, "select": ["all"]})";
  for (int i = 1; i <= 5; ++i)
    cases += R"(, {"name": "c)" + std::to_string(i) +
             R"(", "mesh": {"generate": "brick", "dims": [14, 14, 14], "jitter": 0.2, "seed": )" +
             std::to_string(i) + R"(}, "select": ["all"]})";
  cases += "]}";
  std::ofstream(dir / "cases.json") << cases;
  const fs::path out = dir / "out.jsonl";

  const std::string exe = HEXREFINE_EXE, file = (dir / "cases.json").string();
  std::vector<char*> argv = {const_cast<char*>(exe.c_str()), const_cast<char*>("run"),
                             const_cast<char*>(file.c_str()), const_cast<char*>("--quiet"),
                             nullptr};
  pid_t pid = 0;
  ASSERT_EQ(posix_spawn(&pid, exe.c_str(), nullptr, nullptr, argv.data(), environ), 0);
  // Wait for the first finished record (or the end of the run), then kill without warning.
  bool exited = false;
  int status = 0;
  for (int i = 0; i < 60000 && file_complete_lines(out).empty(); ++i) {
    if (waitpid(pid, &status, WNOHANG) == pid) {
      exited = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ASSERT_FALSE(exited) << "the run ended before its first record";
  ASSERT_EQ(kill(pid, SIGKILL), 0);
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFSIGNALED(status));
  const std::vector<std::string> before = file_complete_lines(out);
  ASSERT_GE(before.size(), 1u);
  ASSERT_LT(before.size(), 12u) << "the kill came after the last record: nothing to resume";

  const CliRun resumed = cli_run("run " + file + " --resume --quiet");
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  const std::vector<std::string> after = file_complete_lines(out);
  // The records written before the kill are kept as they were, at the start of the file.
  ASSERT_GE(after.size(), before.size());
  for (size_t i = 0; i < before.size(); ++i) EXPECT_EQ(after[i], before[i]) << "record " << i;
  std::map<std::pair<std::string, std::string>, int> seen;
  for (const std::string& line : after) {
    const nlohmann::json r = nlohmann::json::parse(line);  // every line is a whole record
    ++seen[{r.at("case").get<std::string>(), r.at("method").get<std::string>()}];
    EXPECT_FALSE(r.contains("error")) << line.substr(0, 200);
  }
  EXPECT_EQ(after.size(), 12u);
  for (const char* name : {"c0", "c1", "c2", "c3", "c4", "c5"})
    for (const char* method : {"selective", "sheet"})
      EXPECT_EQ((seen[{name, method}]), 1) << name << " " << method;
}

}  // namespace
}  // namespace hexrefine
