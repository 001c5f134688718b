#pragma once
/// \file
/// Runs the hexrefine executable from a test and captures its exit code and output.

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace hexrefine {

struct CliRun {
  int exit_code = -1;
  std::string output;  ///< stdout and stderr together
};

/// Runs a shell command line (stderr joined to stdout) and returns its exit code and output.
inline CliRun shell_run(const std::string& command) {
  CliRun r;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return r;
  std::array<char, 4096> buf{};
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), pipe)) > 0) r.output.append(buf.data(), n);
  const int status = pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return r;
}

/// Runs `hexrefine ARGS` (ARGS is passed to the shell as written) and returns its exit code and
/// combined output.
inline CliRun cli_run(const std::string& args) {
  return shell_run(std::string(HEXREFINE_EXE) + " " + args);
}

/// A fresh empty folder under the system temp dir, unique per test name.
inline std::filesystem::path test_temp_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("hexrefine_test_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

/// The whole content of a file, byte for byte ("" if it cannot be read).
inline std::string test_file_text(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Writes `text` to a file (replacing it), byte for byte.
inline void test_file_put(const std::filesystem::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out << text;
}

/// Path of a file in ../shared/meshes.
inline std::string shared_mesh(const std::string& name) {
  return std::string(HEXREFINE_SHARED_DIR) + "/meshes/" + name;
}

}  // namespace hexrefine
