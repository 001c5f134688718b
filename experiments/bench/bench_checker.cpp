/// Google Benchmark of the checker on what it certifies: the output of a full refinement of an
/// n^3 brick (Selective Approach, trilinear placement: 27 n^3 hexes, numbered as the refiner
/// numbers them), n = 50 and 75 (10 under --smoke), one and two threads:
/// - bench_check_refined: mesh_check without a reference (`hexrefine check OUT`);
/// - bench_check_refined_against_input: mesh_check with the brick as the reference (the check a
///   `hexrefine refine` runs).
/// The refined mesh is made once per size and kept for that size's benchmarks (it is not timed).
/// CPU time is the process's (both threads of a two-thread check).
///
/// Counters (see results/bench/README.md): `hexes_in/s` (output hexes checked per second of
/// the benchmark's real time), `hexes`, `peak_rss_MB`.
///
/// Run (Release): hexrefine bench --filter bench_check_refined or
///   bench_checker --benchmark_repetitions=5 --benchmark_format=json
#include <benchmark/benchmark.h>

#include <exception>
#include <memory>
#include <string>
#include <vector>

#include "algorithms/refiners/selective.hpp"
#include "experiments/bench/bench_util.hpp"
#include "experiments/bench/process_huge_pages.hpp"
#include "mesh/conformity.hpp"
#include "mesh/generators.hpp"

namespace hexrefine {
namespace {

struct Refined {
  int n = 0;
  HexMesh input, output;
};

/// The brick n^3 and its full refinement, made on first use and kept until another size is
/// asked for (the 75^3 output holds 11.4 M hexes, about 0.7 GB).
const Refined& refined_brick(int n) {
  static std::unique_ptr<Refined> cached;
  if (cached && cached->n == n) return *cached;
  cached.reset();
  auto r = std::make_unique<Refined>();
  r->n = n;
  BrickParams p;
  p.dims = {n, n, n};
  p.size = {1.0, 1.0, 1.0};
  r->input = generate_brick(p);
  Targets all;
  for (int32_t h = 0; h < r->input.hex_count(); ++h) all.hexes.push_back(h);
  RefineOptions o;
  o.placement.method = PlacementMethod::trilinear;
  o.threads = 2;
  r->output = selective_refine(r->input, all, o).mesh;
  cached = std::move(r);
  return *cached;
}

void check(benchmark::State& state, bool against_input, int threads) {
  const Refined* r = nullptr;
  try {
    r = &refined_brick(static_cast<int>(state.range(0)));
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  bench_reset_peak_memory();
  bool valid = true;
  for (auto _ : state) {
    const MeshCheckReport report =
        mesh_check(r->output, against_input ? &r->input : nullptr, threads);
    valid = valid && report.valid();
    benchmark::DoNotOptimize(report);
  }
  if (!valid) state.SkipWithError("mesh_check reported an invalid mesh");
  state.counters["hexes"] = static_cast<double>(r->output.hex_count());
  bench_set_hex_rate(state, "hexes_in/s", static_cast<double>(r->output.hex_count()));
  bench_set_peak_memory(state);
}

/// Registers every family at one size before the next size, so each refined mesh is made once.
const int registered = [] {
  const std::vector<int> sizes = bench_smoke() ? std::vector<int>{10} : std::vector<int>{50, 75};
  for (const int n : sizes)
    for (const bool against_input : {false, true})
      for (const int threads : {1, 2}) {
        const std::string name = std::string("bench_check_refined") +
                                 (against_input ? "_against_input" : "") +
                                 (threads > 1 ? "_2_threads" : "");
        benchmark::RegisterBenchmark(name.c_str(), check, against_input, threads)
            ->Arg(n)
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime()
            ->MeasureProcessCPUTime();
      }
  return 0;
}();

}  // namespace
}  // namespace hexrefine

// Huge pages as the hexrefine command asks for them (experiments/bench/process_huge_pages.hpp): the
// checker's arrays are fresh memory each run, and on 4 KiB pages their faults are a tenth of its
// time; the counter huge_pages records whether the run had them.
int main(int argc, char** argv) {
  hexrefine::process_prefer_huge_pages(argv);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::AddCustomContext("huge_pages", hexrefine::process_uses_huge_pages() ? "1" : "0");
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
