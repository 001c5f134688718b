/// Google Benchmark of the two refiners on the same inputs: full refinement of n x n x n unit
/// bricks (thesis Table G-2; n = 10, 25, 50), hexes within a fixed radius of the top front right
/// vertex of a brick of fixed size (Table G-3; radius 0.5 of a unit brick, n = 10, 25, 50), the
/// L-shaped case (Table G-1), the gear's teeth (Table H-1) and the left surface of a 4^3 brick
/// refined three times (Table H-2). `sheet_one_per_pass` runs the sheet refiner in Harris' order
/// (one sheet per pass) on the smaller bricks. Wall-clock times
/// (UseRealTime). Counters: final hexes, hexes created and deleted, sheet passes, added targets,
/// per-phase seconds (of the last iteration), and `s/initial_hex` (seconds per input hex; flat
/// when the time grows linearly), `hexes_in/s` and `hexes_out/s` (initial and final hexes per
/// second), `output_MB`, `floor_s` and `floor_ratio` (the time to write the output's bytes into
/// fresh memory in the same run, and our median time over it) and `peak_rss_MB` (the benchmark's
/// peak resident memory, VmHWM, reset at its start). Sizes: 10, 25, 50; 10 only under
/// HEXREFINE_BENCH_SMOKE=1 (`hexrefine bench --smoke`); 75 (the thesis' largest brick: up to 3 GB,
/// 1 to 6 s a run) only under HEXREFINE_BENCH_LARGE=1. A refiner that throws (e.g. not implemented
/// yet) is reported as a skipped benchmark with its message.
///
/// The refiners run with the thesis' trilinear node placement (the template engine's output as
/// the baseline measured it); `selective_optimized` and `sheet_optimized` add the default
/// optimized placement, whose cost is the difference.
///
/// Run (Release): bench_refiners --benchmark_repetitions=3
///   --benchmark_out=results/benchmarks/refiners.json --benchmark_out_format=json
#include <benchmark/benchmark.h>

#include <malloc.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <exception>
#include <memory>
#include <string>

#include "algorithms/refiners/selective.hpp"
#include "algorithms/refiners/sheet.hpp"
#include "experiments/bench/bench_util.hpp"
#include "mesh/generators.hpp"
#include "mesh/hex_mesh.hpp"

namespace hexrefine {
namespace {

// Every large allocation gets fresh pages from the kernel, at every size, as in a single
// `hexrefine refine` run. Without this glibc raises its mmap threshold after the first large
// free, so the small meshes (up to 32 MB) would reuse already-faulted heap memory from the
// previous iteration while the large ones cannot: the small sizes would look cheaper per hex
// and the measured growth steeper than it is.
const int fresh_memory = [] {
  mallopt(M_MMAP_THRESHOLD, 128 * 1024);
  return 0;
}();

using RefineFunction = RefineResult (*)(const HexMesh&, const Targets&, const RefineOptions&);
const RefineFunction sheet = &sheet_refine;  // picks the overload without an observer
const RefineFunction selective = &selective_refine;

HexMesh unit_brick(int n) {
  BrickParams p;
  p.dims = {n, n, n};
  p.size = {1.0, 1.0, 1.0};
  return generate_brick(p);
}

Targets targets_all(const HexMesh& m) {
  Targets t;
  t.hexes.resize(m.hexes.size());
  for (int32_t h = 0; h < m.hex_count(); ++h) t.hexes[h] = h;
  return t;
}

// Hexes whose centroid lies within `radius` of the top front right vertex (1, 0, 1).
Targets targets_radial(const HexMesh& m, double radius) {
  Targets t;
  const Eigen::Vector3d corner(1.0, 0.0, 1.0);
  for (int32_t h = 0; h < m.hex_count(); ++h)
    if ((hex_centroid(m, h) - corner).norm() <= radius) t.hexes.push_back(h);
  return t;
}

// The L-shaped case: hexes on the left (x-min) and bottom (z-min) surfaces of a 10^3 brick.
Targets targets_l_shaped(int n) {
  Targets t;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        if (i == 0 || k == 0) t.hexes.push_back(brick_hex({n, n, n}, i, j, k));
  return t;
}

Targets targets_block(const HexMesh& m, int32_t block) {
  Targets t;
  const std::vector<int32_t>* ids = mesh_find_attribute(m, attribute_block_id);
  for (int32_t h = 0; ids && h < m.hex_count(); ++h)
    if ((*ids)[h] == block) t.hexes.push_back(h);
  return t;
}

RefineOptions trilinear_options() {
  RefineOptions o;
  o.placement.method = PlacementMethod::trilinear;
  return o;
}

void run(benchmark::State& state, RefineFunction refine, const HexMesh& mesh,
         const Targets& targets, const RefineOptions& options = trilinear_options()) {
  RefineStats last;
  bench_reset_peak_memory();
  std::vector<double> seconds;
  try {
    for (auto _ : state) {
      const auto t0 = std::chrono::steady_clock::now();
      RefineResult r = refine(mesh, targets, options);
      benchmark::DoNotOptimize(r.mesh.hexes.data());
      seconds.push_back(
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      last = std::move(r.stats);
    }
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  state.counters["initial_hexes"] = static_cast<double>(mesh.hex_count());
  state.counters["targets"] = static_cast<double>(targets.hexes.size());
  state.counters["final_hexes"] = static_cast<double>(last.final_hexes);
  state.counters["hexes_created"] = static_cast<double>(last.hexes_created);
  state.counters["hexes_deleted"] = static_cast<double>(last.hexes_deleted);
  state.counters["sheet_passes"] = static_cast<double>(last.sheet_passes);
  state.counters["added_targets"] = static_cast<double>(last.added_targets);
  for (const auto& [phase, seconds] : last.phase_seconds)
    state.counters["phase_" + phase] = seconds;
  state.counters["s/initial_hex"] = benchmark::Counter(
      static_cast<double>(mesh.hex_count()),
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  bench_set_hex_rate(state, "hexes_in/s", static_cast<double>(mesh.hex_count()));
  bench_set_hex_rate(state, "hexes_out/s", static_cast<double>(last.final_hexes));
  bench_set_peak_memory(state);
  // The floor: writing the output's bytes (hexes and nodes) into fresh memory, page faults
  // included, timed in the same process; floor_ratio = median refine time / median floor time.
  const size_t bytes = static_cast<size_t>(last.final_hexes) * sizeof(HexCell) +
                       static_cast<size_t>(last.final_nodes) * sizeof(Eigen::Vector3d);
  std::vector<double> floor;
  for (int rep = 0; rep < 3; ++rep) {
    const auto t0 = std::chrono::steady_clock::now();
    std::unique_ptr<char[]> fresh(new char[bytes]);
    std::memset(fresh.get(), 0x5a, bytes);
    benchmark::DoNotOptimize(fresh.get());
    floor.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(seconds.begin(), seconds.end());
  std::sort(floor.begin(), floor.end());
  state.counters["output_MB"] = static_cast<double>(bytes) / 1e6;
  state.counters["floor_s"] = floor[1];
  if (!seconds.empty() && floor[1] > 0)
    state.counters["floor_ratio"] = seconds[seconds.size() / 2] / floor[1];
}

void bench_full_brick(benchmark::State& state, RefineFunction refine) {
  const HexMesh mesh = unit_brick(static_cast<int>(state.range(0)));
  run(state, refine, mesh, targets_all(mesh));
}

void bench_radial(benchmark::State& state, RefineFunction refine) {
  const HexMesh mesh = unit_brick(static_cast<int>(state.range(0)));
  run(state, refine, mesh, targets_radial(mesh, 0.5));
}

void bench_l_shaped(benchmark::State& state, RefineFunction refine) {
  const HexMesh mesh = unit_brick(10);
  run(state, refine, mesh, targets_l_shaped(10));
}

void bench_gear_teeth(benchmark::State& state, RefineFunction refine) {
  const HexMesh mesh = generate_gear(GearParams{});
  run(state, refine, mesh, targets_block(mesh, gear_block_teeth));
}

// Table H-2: 4x4x4 brick, left surface refined three times (passes = 3; the selective refiner
// with the default buffer, PassBuffer::layer, as in the thesis).
void bench_left_three_passes(benchmark::State& state, RefineFunction refine) {
  const HexMesh mesh = unit_brick(4);
  Targets left;
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 4; ++j) left.hexes.push_back(brick_hex({4, 4, 4}, 0, j, k));
  std::sort(left.hexes.begin(), left.hexes.end());
  RefineOptions options = trilinear_options();
  options.passes = 3;
  run(state, refine, mesh, left, options);
}

// Harris' order, one sheet per pass with a copy and topology build of the refined region per
// pass: what a per-sheet implementation costs (the grouped rounds above do the same passes).
RefineResult sheet_one_per_pass(const HexMesh& mesh, const Targets& targets,
                                const RefineOptions& options) {
  SheetControl control;
  control.one_sheet_per_round = true;
  return sheet_refine(mesh, targets, options, control);
}

// The rounds on the whole refined region, every intermediate mesh and topology built (the
// default replays each hex configuration once as a composite template: same mesh).
RefineResult sheet_rounds(const HexMesh& mesh, const Targets& targets,
                          const RefineOptions& options) {
  SheetControl control;
  control.composites = false;
  return sheet_refine(mesh, targets, options, control);
}

// Both refiners with two threads for the template application (the same output).
RefineResult selective_2_threads(const HexMesh& mesh, const Targets& targets,
                                 const RefineOptions& options) {
  RefineOptions o = options;
  o.threads = 2;
  return selective_refine(mesh, targets, o);
}
RefineResult sheet_2_threads(const HexMesh& mesh, const Targets& targets,
                             const RefineOptions& options) {
  RefineOptions o = options;
  o.threads = 2;
  return sheet_refine(mesh, targets, o);
}

// Both refiners with the default optimized node placement.
RefineResult selective_optimized(const HexMesh& mesh, const Targets& targets,
                                 const RefineOptions& options) {
  RefineOptions o = options;
  o.placement.method = PlacementMethod::optimized;
  return selective_refine(mesh, targets, o);
}
RefineResult sheet_optimized(const HexMesh& mesh, const Targets& targets,
                             const RefineOptions& options) {
  RefineOptions o = options;
  o.placement.method = PlacementMethod::optimized;
  return sheet_refine(mesh, targets, o);
}

void sizes(benchmark::internal::Benchmark* b) {
  bench_brick_sizes(b, 10, 10);
}

BENCHMARK_CAPTURE(bench_full_brick, sheet, sheet)->Apply(sizes);
BENCHMARK_CAPTURE(bench_full_brick, selective, selective)->Apply(sizes);
BENCHMARK_CAPTURE(bench_full_brick, sheet_rounds, &sheet_rounds)->Apply(sizes);
BENCHMARK_CAPTURE(bench_full_brick, selective_2_threads, &selective_2_threads)->Apply(sizes);
BENCHMARK_CAPTURE(bench_full_brick, sheet_2_threads, &sheet_2_threads)->Apply(sizes);
BENCHMARK_CAPTURE(bench_full_brick, sheet_one_per_pass, &sheet_one_per_pass)
    ->Apply([](benchmark::internal::Benchmark* b) {
      if (bench_smoke())
        b->Arg(10);
      else
        b->Arg(10)->Arg(20)->Arg(25);
      b->Unit(benchmark::kMillisecond)->UseRealTime();
    });
BENCHMARK_CAPTURE(bench_radial, sheet, sheet)->Apply(sizes);
BENCHMARK_CAPTURE(bench_radial, selective, selective)->Apply(sizes);
BENCHMARK_CAPTURE(bench_radial, sheet_rounds, &sheet_rounds)->Apply(sizes);
BENCHMARK_CAPTURE(bench_radial, selective_optimized, &selective_optimized)->Apply(sizes);
BENCHMARK_CAPTURE(bench_radial, sheet_optimized, &sheet_optimized)->Apply(sizes);
BENCHMARK_CAPTURE(bench_l_shaped, sheet, sheet)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(bench_l_shaped, selective, selective)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(bench_gear_teeth, sheet, sheet)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(bench_gear_teeth, selective, selective)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(bench_gear_teeth, selective_optimized, &selective_optimized)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(bench_gear_teeth, sheet_optimized, &sheet_optimized)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

BENCHMARK_CAPTURE(bench_left_three_passes, sheet, sheet)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(bench_left_three_passes, selective, selective)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace hexrefine

BENCHMARK_MAIN();
