/// Google Benchmark of the derived-topology builders on regular bricks of n^3 hexes (n = 25, 50,
/// 100): topology_build (edges, faces, adjacency) and dual_build (sheets and chords, given the
/// topology), plus boundary_surface_build (the OpenMesh quad surface, given the topology). Times
/// are wall-clock (UseRealTime); counter `hexes/s` is hexes per wall second.
///
/// Run (Release): bench_topology --benchmark_repetitions=5
///   --benchmark_out=results/benchmarks/topology.json --benchmark_out_format=json
#include <benchmark/benchmark.h>

#include "mesh/boundary_surface.hpp"
#include "mesh/dual.hpp"
#include "mesh/hex_mesh.hpp"
#include "mesh/topology.hpp"

namespace hexrefine {
namespace {

/// Unit n x n x n brick, nodes and hexes numbered x fastest (the layout of generate_brick without
/// jitter), built here so the benchmark depends on the mesh layer only.
HexMesh brick_for_benchmark(int n) {
  HexMesh m;
  const int32_t p = n + 1;
  m.points.reserve(static_cast<size_t>(p) * p * p);
  for (int k = 0; k <= n; ++k)
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) m.points.emplace_back(i, j, k);
  auto id = [&](int i, int j, int k) { return static_cast<int32_t>(i + p * (j + p * k)); };
  m.hexes.reserve(static_cast<size_t>(n) * n * n);
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        m.hexes.push_back({id(i, j, k), id(i + 1, j, k), id(i + 1, j + 1, k), id(i, j + 1, k),
                           id(i, j, k + 1), id(i + 1, j, k + 1), id(i + 1, j + 1, k + 1),
                           id(i, j + 1, k + 1)});
  return m;
}

void set_counters(benchmark::State& state, const HexMesh& mesh) {
  state.counters["hexes"] = mesh.hex_count();
  state.counters["hexes/s"] = benchmark::Counter(static_cast<double>(mesh.hex_count()),
                                                 benchmark::Counter::kIsIterationInvariantRate);
}

void bench_topology_build(benchmark::State& state) {
  const HexMesh mesh = brick_for_benchmark(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    HexTopology t = topology_build(mesh);
    benchmark::DoNotOptimize(t.edge_hexes.data());
  }
  set_counters(state, mesh);
}

void bench_dual_build(benchmark::State& state) {
  const HexMesh mesh = brick_for_benchmark(static_cast<int>(state.range(0)));
  const HexTopology topology = topology_build(mesh);
  for (auto _ : state) {
    DualSheets d = dual_build(mesh, topology);
    benchmark::DoNotOptimize(d.sheet_hexes.data());
  }
  set_counters(state, mesh);
}

void bench_boundary_surface_build(benchmark::State& state) {
  const HexMesh mesh = brick_for_benchmark(static_cast<int>(state.range(0)));
  const HexTopology topology = topology_build(mesh);
  for (auto _ : state) {
    BoundarySurface s = boundary_surface_build(mesh, topology);
    benchmark::DoNotOptimize(s.face_hex.data());
  }
  set_counters(state, mesh);
}

BENCHMARK(bench_topology_build)
    ->Arg(25)
    ->Arg(50)
    ->Arg(100)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(bench_dual_build)
    ->Arg(25)
    ->Arg(50)
    ->Arg(100)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(bench_boundary_surface_build)
    ->Arg(25)
    ->Arg(50)
    ->Arg(100)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace hexrefine

BENCHMARK_MAIN();
