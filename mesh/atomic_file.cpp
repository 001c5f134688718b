#include "mesh/atomic_file.hpp"

#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "mesh/error.hpp"

namespace hexrefine {

namespace {

/// "<pid>.<n>": unique among the files this process names.
std::string process_unique_tag() {
  static std::atomic<int> counter{0};
  std::string tag = std::to_string(::getpid());
  tag += ".";
  tag += std::to_string(counter++);
  return tag;
}

}  // namespace

// The names are built by appending: GCC 12 warns (-Wrestrict, a false positive) on
// "literal" + std::string here.
std::string file_temporary_beside(const std::string& path) {
  const std::filesystem::path p(path);
  std::string name = ".";
  name += p.filename().string();
  name += ".tmp";
  name += process_unique_tag();
  return (p.parent_path() / name).string();
}

std::string file_staging_beside(const std::string& path) {
  const std::filesystem::path p(path);
  std::string name = ".staged";
  name += process_unique_tag();
  name += ".";
  name += p.filename().string();
  return (p.parent_path() / name).string();
}

void file_commit_temporary(const std::string& temporary, const std::string& path) {
  std::error_code ec;
  std::filesystem::rename(temporary, path, ec);
  if (ec) {
    std::filesystem::remove(temporary, ec);
    throw OperationError(path + ": cannot write: " + ec.message());
  }
}

void file_write_atomically(const std::string& path,
                           const std::function<void(std::ostream&)>& write) {
  const std::string tmp = file_temporary_beside(path);
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out)
      throw OperationError(path + ": cannot open for writing (folder missing or not writable)");
    try {
      write(out);
      out.flush();
    } catch (...) {
      out.close();
      std::remove(tmp.c_str());
      throw;
    }
    if (!out) {
      out.close();
      std::remove(tmp.c_str());
      throw OperationError(path + ": write failed (disk full?)");
    }
  }
  file_commit_temporary(tmp, path);
}

}  // namespace hexrefine
