#include "experiments/bench/process_huge_pages.hpp"

#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

namespace hexrefine {

namespace {

constexpr const char* hugetlb_tunable = "glibc.malloc.hugetlb";

// Unused where the sanitizers compile the re-execution out.
[[maybe_unused]] bool running_under_valgrind() {
  const char* preload = std::getenv("LD_PRELOAD");
  return preload != nullptr && std::strstr(preload, "vgpreload") != nullptr;
}

}  // namespace

std::string huge_pages_mode(const std::string& enabled) {
  const size_t open = enabled.find('[');
  const size_t close = enabled.find(']', open == std::string::npos ? 0 : open);
  if (open == std::string::npos || close == std::string::npos) return {};
  return enabled.substr(open + 1, close - open - 1);
}

std::string huge_pages_kernel_mode() {
  std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
  std::stringstream text;
  text << in.rdbuf();
  return huge_pages_mode(text.str());
}

std::optional<std::string> huge_pages_tunables(const char* current) {
  if (current == nullptr || *current == '\0') return std::string(hugetlb_tunable) + "=1";
  if (std::strstr(current, hugetlb_tunable) != nullptr) return std::nullopt;
  return std::string(current) + ":" + hugetlb_tunable + "=1";
}

void process_prefer_huge_pages(char** argv) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  (void)argv;
#else
  const char* opt_out = std::getenv("HEXREFINE_HUGE_PAGES");
  if (opt_out != nullptr && std::strcmp(opt_out, "0") == 0) return;
  if (running_under_valgrind() || huge_pages_kernel_mode() != "madvise") return;
  const std::optional<std::string> tunables = huge_pages_tunables(std::getenv("GLIBC_TUNABLES"));
  if (!tunables) return;
  if (::setenv("GLIBC_TUNABLES", tunables->c_str(), 1) != 0) return;
  ::execv("/proc/self/exe", argv);
  // exec failed (no /proc, say): run on with 4 KiB pages; the tunable left set is harmless.
#endif
}

bool process_uses_huge_pages() {
  const std::string mode = huge_pages_kernel_mode();
  if (mode == "always") return true;
  const char* current = std::getenv("GLIBC_TUNABLES");
  return mode == "madvise" && current != nullptr &&
         std::strstr(current, "glibc.malloc.hugetlb=1") != nullptr;
}

}  // namespace hexrefine
