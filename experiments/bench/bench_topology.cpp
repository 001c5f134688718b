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
#include "mesh/generators.hpp"
#include "mesh/hex_mesh.hpp"
#include "mesh/topology.hpp"

namespace hexrefine {
namespace {

/// Unit n x n x n brick without jitter (nodes and hexes numbered x fastest).
HexMesh brick_for_benchmark(int n) {
  BrickParams p;
  p.dims = {n, n, n};
  p.size = {static_cast<double>(n), static_cast<double>(n), static_cast<double>(n)};
  return generate_brick(p);
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
