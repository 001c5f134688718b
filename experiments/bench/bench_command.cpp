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
/// `bench_real_mesh`: the pipeline on a real mesh as a user runs it (rockerarm.mesh, the largest
/// boundary surface `surface:0`, 10,600 -> 205,428 hexes; `sphere:0,0,0,5` under --smoke),
/// Selective Approach, the default optimized node placement and --smooth, with one and with two
/// threads (the same mesh: node_optimizer.hpp). Counters as above plus `placement_s`,
/// `smooth_s` and `smoothed_min_sj`.
///
/// Run (Release): hexrefine bench --filter bench_command
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <exception>
#include <filesystem>
#include <string>

#include "algorithms/pipeline/pipeline.hpp"
#include "experiments/bench/bench_util.hpp"
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

void bench_real_mesh(benchmark::State& state, int threads) {
  bench_reset_peak_memory();
  PipelineOptions options;
  options.method = "selective";
  options.select = {bench_smoke() ? "sphere:0,0,0,5" : "surface:0"};
  options.smooth = true;
  options.refine.threads = threads;
  PipelineResult last;
  try {
    const HexMesh mesh = mesh_read(bench_shared_mesh("rockerarm.mesh"));
    for (auto _ : state) {
      last = pipeline_run(mesh, options);
      benchmark::DoNotOptimize(last.stats);
    }
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  state.counters["hexes_out"] = static_cast<double>(last.mesh.hex_count());
  for (const char* stage : {"refine", "check", "smooth"})
    if (last.stage_seconds.count(stage))
      state.counters[std::string(stage) + "_s"] = last.stage_seconds.at(stage);
  state.counters["placement_s"] = last.stats.placement.seconds;
  if (last.smoothed_check)
    state.counters["smoothed_min_sj"] = last.smoothed_check->min_scaled_jacobian;
  bench_set_peak_memory(state);
}

BENCHMARK_CAPTURE(bench_command, exodus, ".e", 1)->Apply(sizes);
BENCHMARK_CAPTURE(bench_command, vtu, ".vtu", 1)->Apply(sizes);
BENCHMARK_CAPTURE(bench_command, exodus_2_threads, ".e", 2)->Apply(sizes);
BENCHMARK_CAPTURE(bench_real_mesh, rockerarm, 1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(bench_real_mesh, rockerarm_2_threads, 2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace hexrefine

BENCHMARK_MAIN();
