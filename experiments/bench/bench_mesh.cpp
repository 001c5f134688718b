/// Google Benchmark of the mesh layer's per-mesh passes: the checker (mesh_check with a
/// reference: the mesh itself, so every reference comparison runs and passes; one and two
/// threads), the quality pass
/// (mesh_scaled_jacobians) on n^3 bricks (n = 25, 50; 10 under --smoke) and on the shared
/// rockerarm mesh (10,600 hexes), and writing a brick (25^3; 10^3 under --smoke) in each format
/// to a temporary folder.
///
/// Counters (see results/bench/README.md): `hexes_in/s` (hexes processed per second),
/// `hexes_out/s` (hexes written per second, writers), `bytes` (file size) and `bytes_per_second`
/// (writers), `peak_rss_MB` (peak resident memory of the benchmark, VmHWM).
///
/// Run (Release): hexrefine bench --filter 'bench_(check|quality|write)' or
///   bench_mesh --benchmark_repetitions=3 --benchmark_format=json
#include <benchmark/benchmark.h>

#include <exception>
#include <filesystem>
#include <string>

#include "experiments/bench/bench_util.hpp"
#include "mesh/conformity.hpp"
#include "mesh/generators.hpp"
#include "mesh/hex_mesh.hpp"
#include "mesh/io.hpp"
#include "mesh/quality.hpp"

namespace hexrefine {
namespace {

HexMesh unit_brick(int n) {
  BrickParams p;
  p.dims = {n, n, n};
  p.size = {1.0, 1.0, 1.0};
  return generate_brick(p);
}

void check_mesh(benchmark::State& state, const HexMesh& mesh, int threads = 1) {
  bool ok = true;
  for (auto _ : state) {
    const MeshCheckReport report = mesh_check(mesh, &mesh, threads);
    ok = ok && report.valid();
    benchmark::DoNotOptimize(report);
  }
  if (!ok) state.SkipWithError("mesh_check reported an invalid mesh");
  state.counters["hexes"] = static_cast<double>(mesh.hex_count());
  bench_set_hex_rate(state, "hexes_in/s", static_cast<double>(mesh.hex_count()));
  bench_set_peak_memory(state);
}

void quality_mesh(benchmark::State& state, const HexMesh& mesh) {
  for (auto _ : state) {
    std::vector<double> q = mesh_scaled_jacobians(mesh);
    benchmark::DoNotOptimize(q.data());
  }
  state.counters["hexes"] = static_cast<double>(mesh.hex_count());
  bench_set_hex_rate(state, "hexes_in/s", static_cast<double>(mesh.hex_count()));
  bench_set_peak_memory(state);
}

void bench_check_brick(benchmark::State& state) {
  bench_reset_peak_memory();
  const HexMesh mesh = unit_brick(static_cast<int>(state.range(0)));
  check_mesh(state, mesh);
}

void bench_check_brick_2_threads(benchmark::State& state) {
  bench_reset_peak_memory();
  const HexMesh mesh = unit_brick(static_cast<int>(state.range(0)));
  check_mesh(state, mesh, 2);
}

void bench_quality_brick(benchmark::State& state) {
  bench_reset_peak_memory();
  const HexMesh mesh = unit_brick(static_cast<int>(state.range(0)));
  quality_mesh(state, mesh);
}

/// Runs `body` on the rockerarm mesh, or skips with the reader's message if it is missing.
template <typename Body>
void on_rockerarm(benchmark::State& state, Body body) {
  bench_reset_peak_memory();
  HexMesh mesh;
  try {
    mesh = mesh_read(bench_shared_mesh("rockerarm.mesh"));
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  body(state, mesh);
}

void bench_check_rockerarm(benchmark::State& state) {
  on_rockerarm(state, [](benchmark::State& s, const HexMesh& m) { check_mesh(s, m); });
}
void bench_quality_rockerarm(benchmark::State& state) {
  on_rockerarm(state, quality_mesh);
}

/// Writes a brick to `<temp>/hexrefine_bench_<pid>/brick<extension>` each iteration.
void bench_write(benchmark::State& state, const char* extension, bool binary) {
  bench_reset_peak_memory();
  const HexMesh mesh = unit_brick(static_cast<int>(state.range(0)));
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("hexrefine_bench_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / (std::string("brick") + extension)).string();
  MeshWriteOptions options;
  options.binary = binary;
  try {
    for (auto _ : state) mesh_write(path, mesh, options);
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
  }
  std::error_code ec;
  const auto bytes = std::filesystem::file_size(path, ec);
  std::filesystem::remove_all(dir, ec);
  const double size = ec ? 0.0 : static_cast<double>(bytes);
  state.SetBytesProcessed(static_cast<int64_t>(size * static_cast<double>(state.iterations())));
  state.counters["bytes"] = size;
  state.counters["hexes"] = static_cast<double>(mesh.hex_count());
  bench_set_hex_rate(state, "hexes_in/s", static_cast<double>(mesh.hex_count()));
  bench_set_hex_rate(state, "hexes_out/s", static_cast<double>(mesh.hex_count()));
  bench_set_peak_memory(state);
}

void brick_sizes(benchmark::internal::Benchmark* b) {
  bench_brick_sizes(b, 10);
}

void write_size(benchmark::internal::Benchmark* b) {
  b->Arg(bench_smoke() ? 10 : 25)->Unit(benchmark::kMillisecond)->UseRealTime();
}

void single(benchmark::internal::Benchmark* b) {
  b->Unit(benchmark::kMillisecond)->UseRealTime();
}

BENCHMARK(bench_check_brick)->Apply(brick_sizes);
BENCHMARK(bench_check_brick_2_threads)->Apply(brick_sizes);
BENCHMARK(bench_quality_brick)->Apply(brick_sizes);
BENCHMARK(bench_check_rockerarm)->Apply(single);
BENCHMARK(bench_quality_rockerarm)->Apply(single);
BENCHMARK_CAPTURE(bench_write, medit, ".mesh", false)->Apply(write_size);
BENCHMARK_CAPTURE(bench_write, vtk_ascii, ".vtk", false)->Apply(write_size);
BENCHMARK_CAPTURE(bench_write, vtk_binary, ".vtk", true)->Apply(write_size);
BENCHMARK_CAPTURE(bench_write, vtu, ".vtu", false)->Apply(write_size);
BENCHMARK_CAPTURE(bench_write, gmsh, ".msh", false)->Apply(write_size);
BENCHMARK_CAPTURE(bench_write, exodus, ".e", false)->Apply(write_size);
BENCHMARK_CAPTURE(bench_write, abaqus, ".inp", false)->Apply(write_size);

}  // namespace
}  // namespace hexrefine

BENCHMARK_MAIN();
