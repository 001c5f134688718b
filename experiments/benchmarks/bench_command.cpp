/// Google Benchmark of the whole `hexrefine refine` command, not only the refiner: read an input
/// file, select every hex, refine (Selective Approach, trilinear placement), check against the
/// input, write the output, on n^3 bricks (n = 25, 50, plus 75 under HEXREFINE_BENCH_LARGE; 10
/// under --smoke), to Exodus II and to VTU, with one and with two threads. Each iteration is
/// pipeline_run_files, which is what the command runs; the input is written once per benchmark
/// to a temporary folder.
///
/// Counters: `hexes_out` (output hexes), `hexes_out/s`, `bytes` (output file size),
/// `read_s`, `refine_s`, `check_s`, `write_s` (stage seconds of the last iteration: where the
/// time goes), `peak_rss_MB`.
///
/// Run (Release): hexrefine bench --filter bench_command
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <exception>
#include <filesystem>
#include <string>

#include "algorithms/pipeline.hpp"
#include "experiments/benchmarks/bench_util.hpp"
#include "mesh/generators.hpp"
#include "mesh/io.hpp"

namespace hexrefine {
namespace {

void bench_command(benchmark::State& state, const char* extension, int threads) {
  bench_reset_peak_memory();
  const int n = static_cast<int>(state.range(0));
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("hexrefine_bench_command_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string in = (dir / "in.e").string();
  const std::string out = (dir / (std::string("out") + extension)).string();
  PipelineOptions options;
  options.method = "selective";
  options.select = {"all"};
  options.refine.placement.method = PlacementMethod::trilinear;
  options.refine.threads = threads;
  PipelineResult last;
  try {
    BrickParams p;
    p.dims = {n, n, n};
    mesh_write(in, generate_brick(p));
    for (auto _ : state) {
      last = pipeline_run_files(in, out, options);
      benchmark::DoNotOptimize(last.stats);
    }
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
  }
  std::error_code ec;
  const auto bytes = std::filesystem::file_size(out, ec);
  std::filesystem::remove_all(dir, ec);
  const double hexes = static_cast<double>(last.mesh.hex_count());
  state.counters["hexes_out"] = hexes;
  bench_set_hex_rate(state, "hexes_out/s", hexes);
  state.counters["bytes"] = static_cast<double>(bytes);
  for (const char* stage : {"read", "refine", "check", "write"})
    if (last.stage_seconds.count(stage))
      state.counters[std::string(stage) + "_s"] = last.stage_seconds.at(stage);
  bench_set_peak_memory(state);
}

void sizes(benchmark::internal::Benchmark* b) {
  bench_brick_sizes(b, 10);
}

BENCHMARK_CAPTURE(bench_command, exodus, ".e", 1)->Apply(sizes);
BENCHMARK_CAPTURE(bench_command, vtu, ".vtu", 1)->Apply(sizes);
BENCHMARK_CAPTURE(bench_command, exodus_2_threads, ".e", 2)->Apply(sizes);

}  // namespace
}  // namespace hexrefine

BENCHMARK_MAIN();
