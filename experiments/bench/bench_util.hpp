#pragma once
/// \file
/// Shared pieces of the benchmark executables: the size lists (smoke / default / large), the peak
/// memory counter and the path of the shared meshes.
///
/// Environment:
/// - HEXREFINE_BENCH_SMOKE=1 (set by `hexrefine bench --smoke`): only the smallest size of each
///   family is registered, so the whole suite runs in seconds.
/// - HEXREFINE_BENCH_LARGE=1: adds the thesis' 75^3 brick (up to 3 GB and 1 to 6 s per refiner
///   run).
/// - HEXREFINE_SHARED_DIR: the shared/ folder (default: ../../../shared from the executable,
///   i.e. beside the source tree when the build folder is <source>/build).

#include <benchmark/benchmark.h>
#include <malloc.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

namespace hexrefine {

inline bool bench_env_flag(const char* name) {
  const char* v = std::getenv(name);
  return v != nullptr && std::strcmp(v, "") != 0 && std::strcmp(v, "0") != 0;
}

inline bool bench_smoke() {
  return bench_env_flag("HEXREFINE_BENCH_SMOKE");
}
inline bool bench_large() {
  return bench_env_flag("HEXREFINE_BENCH_LARGE");
}

/// Registers the brick sizes n (hexes per axis): `smoke` alone under HEXREFINE_BENCH_SMOKE, else
/// 25 and 50 (after `extra_small` if > 0), plus 75 under HEXREFINE_BENCH_LARGE. Milliseconds,
/// wall-clock time (the refiners are single-threaded, so CPU time is also reported and is the
/// better measure on a loaded machine).
inline void bench_brick_sizes(benchmark::internal::Benchmark* b, int smoke, int extra_small = 0) {
  if (bench_smoke()) {
    b->Arg(smoke);
  } else {
    if (extra_small > 0) b->Arg(extra_small);
    b->Arg(25)->Arg(50);
    if (bench_large()) b->Arg(75);
  }
  b->Unit(benchmark::kMillisecond)->UseRealTime();
}

/// Resets the process' peak resident set size (Linux >= 4.0: "5" to /proc/self/clear_refs), so
/// that the peak read at the end of a benchmark is that benchmark's own, not an earlier one's.
/// The reset sets the peak to the current resident size, so free heap memory is first returned
/// to the system (malloc_trim): without it, memory an earlier benchmark freed but glibc kept
/// would count towards this one's peak. Silently does nothing where unsupported (the counter
/// then is the process peak so far).
inline void bench_reset_peak_memory() {
  malloc_trim(0);
  std::ofstream clear("/proc/self/clear_refs");
  if (clear) clear << "5";
}

/// VmHWM (peak resident set size) of this process from /proc/self/status, in bytes; 0 if
/// unavailable.
inline double bench_peak_memory_bytes() {
  std::ifstream status("/proc/self/status");
  std::string key;
  while (status >> key) {
    if (key == "VmHWM:") {
      double kb = 0.0;
      status >> kb;
      return kb * 1024.0;
    }
    status.ignore(1 << 20, '\n');
  }
  return 0.0;
}

/// Sets counter "peak_rss_MB" (MB = 1e6 bytes) from VmHWM; call at the end of a benchmark.
inline void bench_set_peak_memory(benchmark::State& state) {
  state.counters["peak_rss_MB"] = bench_peak_memory_bytes() / 1e6;
}

/// Counter `name` = `hexes` per second of the benchmark's time (per iteration).
inline void bench_set_hex_rate(benchmark::State& state, const std::string& name, double hexes) {
  state.counters[name] = benchmark::Counter(
      hexes, benchmark::Counter::kIsRate | benchmark::Counter::kIsIterationInvariant);
}

/// Path of a mesh in shared/meshes (see HEXREFINE_SHARED_DIR above).
inline std::string bench_shared_mesh(const std::string& name) {
  if (const char* dir = std::getenv("HEXREFINE_SHARED_DIR"))
    return std::string(dir) + "/meshes/" + name;
  std::error_code ec;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
  return (self.parent_path() / "../../../shared/meshes" / name).lexically_normal().string();
}

}  // namespace hexrefine
