/// \file
/// instruction_workloads: the fixed-work driver of `hexrefine bench --instructions`. Each
/// workload builds its input, then does its work exactly once inside
/// hexrefine_instruction_region(), the function whose instructions Callgrind counts
/// (`--collect-atstart=no --toggle-collect=hexrefine_instruction_region`): the count is the
/// measured work alone, not the set-up, the program's start or its exit.
///
/// Why a driver of its own and not the Google Benchmark executables: their iteration count
/// follows the time a run takes (the installed Google Benchmark, 1.7.1, has no fixed
/// `--benchmark_min_time=Nx`), so their instruction count would follow the machine's load.
/// Here nothing in the measured region depends on time: one run per workload, one thread
/// (RefineOptions::threads, SmoothOptions::threads, mesh_check's threads all 1: Valgrind
/// serialises threads anyway, but a split of the work between threads would change it), no
/// timing loop, no clock read that decides anything.
///
/// The workloads are those of `hexrefine bench --smoke` at the same sizes (the 10^3 bricks, the
/// gear, rockerarm), without the two-thread variants (one thread here), with two passes of the
/// thesis' H-2 case instead of three (332,448 and 370,304 hexes: alone beyond the 3-minute
/// budget under Callgrind) and with placement and smoothing on the real mesh only (optimized
/// placement on the bricks and the gear executes 1.3 to 5.5 billion instructions per workload).
/// Every workload runs in a process of its own, so that one's heap or lazily built tables never
/// change another's count. docs/performance-gate.md has the rest.
///
/// Usage:
///   instruction_workloads --list                       the workload names, one a line
///   instruction_workloads --run NAME [--result F.json] run one; its identity and work to F.json
/// The identity: operation (refine, smooth, check, quality, topology, dual, boundary_surface,
/// read, write, command), case, size (input hexes), method (selective, sheet, or "none"),
/// placement (trilinear, optimized, untangle, or "none"), format (for read, write, command, or
/// "none"), threads (1), description. The work: counts that change only when the work does
/// (final hexes, nodes moved, bytes), so that a changed count can be told from a changed work.
///
/// Environment: HEXREFINE_SHARED_DIR locates the real meshes (bench_util.hpp). Exit codes: 0
/// done, 1 the workload failed (the message says why), 2 bad usage or a missing input.
#include <alloca.h>
#include <dlfcn.h>
#include <pthread.h>
#include <stdlib.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "algorithms/pipeline/pipeline.hpp"
#include "algorithms/placement/node_placement.hpp"
#include "algorithms/placement/smoothing.hpp"
#include "algorithms/refiners/refiner.hpp"
#include "experiments/bench/bench_util.hpp"
#include "mesh/atomic_file.hpp"
#include "mesh/boundary_surface.hpp"
#include "mesh/conformity.hpp"
#include "mesh/dual.hpp"
#include "mesh/error.hpp"
#include "mesh/generators.hpp"
#include "mesh/hex_mesh.hpp"
#include "mesh/io.hpp"
#include "mesh/quality.hpp"
#include "mesh/selection.hpp"
#include "mesh/topology.hpp"

/// The measured region: Callgrind counts the instructions between entering and leaving this
/// function (its callees included). extern "C", never inlined, never cloned (noipa: no
/// "constprop" copy under another symbol name) and no tail call out of it (the empty asm after
/// the call), so the symbol Callgrind toggles on is entered and left exactly once per workload.
extern "C" __attribute__((noinline, noipa)) void hexrefine_instruction_region(void (*body)(void*),
                                                                              void* data) {
  body(data);
  asm volatile("" ::: "memory");
}

namespace {
std::atomic<int> threads_started{0};
}  // namespace

/// Every thread this process starts passes here (the executable's definition comes first in the
/// dynamic lookup, before libc's, for std::thread in libstdc++ too) and is counted: Callgrind
/// collects in the thread that entered the measured region only, so a workload that starts a
/// thread although it was asked for one would have part of its work silently left out.
extern "C" int pthread_create(pthread_t* thread, const pthread_attr_t* attributes,
                              void* (*start)(void*), void* argument) noexcept {
  using Create = int (*)(pthread_t*, const pthread_attr_t*, void* (*)(void*), void*);
  static const Create next = reinterpret_cast<Create>(dlsym(RTLD_NEXT, "pthread_create"));
  if (!next) return EAGAIN;
  threads_started.fetch_add(1);
  return next(thread, attributes, start, argument);
}

namespace hexrefine {
namespace {

using nlohmann::json;

/// Runs `work` inside the measured region. OperationError if it started a thread (see
/// pthread_create above): its instructions would not be in the count.
///
/// The region starts at the same stack address modulo 4096 in every run: the initial stack holds
/// the arguments and the environment, so its depth follows their length (the checkout's path, the
/// scratch folder's), and copies into stack buffers take other head and tail steps at another
/// alignment (a 129-instruction difference in a 17.9-million refinement). The padding takes the
/// stack pointer down to a fixed offset within its page.
template <typename Work>
__attribute__((noinline)) void measured(Work& work) {
  const auto frame = reinterpret_cast<uintptr_t>(__builtin_frame_address(0));
  volatile char* padding = static_cast<char*>(alloca(frame % 4096 + 64));
  padding[0] = 0;
  const int before = threads_started.load();
  hexrefine_instruction_region([](void* data) { (*static_cast<Work*>(data))(); }, &work);
  const int started = threads_started.load() - before;
  if (started > 0)
    throw OperationError("the measured region started " + std::to_string(started) +
                         " thread(s): Callgrind counts the calling thread only, so the workload "
                         "must run on one (threads = 1 everywhere)");
}

/// What a workload is (its identity in the JSON) and how it runs: `run` builds the input, calls
/// measured() once and returns the work's counts; it sets `size` (the input's hexes).
struct Workload {
  std::string operation, case_name, method = "none", placement = "none", format = "none";
  std::string description;
  std::function<json(int64_t& size, const std::filesystem::path& scratch)> run;

  std::string name() const {
    std::string n = operation + "/" + case_name;
    for (const std::string* part : {&method, &placement, &format})
      if (*part != "none") n += "/" + *part;
    return n;
  }
};

HexMesh unit_brick(int n) {
  BrickParams p;
  p.dims = {n, n, n};
  p.size = {1.0, 1.0, 1.0};
  return generate_brick(p);
}

/// The inputs and their targets. Each returns the mesh and the ascending target hexes.
struct Input {
  HexMesh mesh;
  std::vector<int32_t> targets;
};

Input input_full_brick() {
  Input in{unit_brick(10), {}};
  for (int32_t h = 0; h < in.mesh.hex_count(); ++h) in.targets.push_back(h);
  return in;
}

/// Table G-1: the hexes on the left (x-min) and bottom (z-min) surfaces of a 10^3 brick.
Input input_l_shaped() {
  Input in{unit_brick(10), {}};
  for (int k = 0; k < 10; ++k)
    for (int j = 0; j < 10; ++j)
      for (int i = 0; i < 10; ++i)
        if (i == 0 || k == 0) in.targets.push_back(brick_hex({10, 10, 10}, i, j, k));
  std::sort(in.targets.begin(), in.targets.end());
  return in;
}

/// Table G-3: hexes whose centroid lies within 0.5 of the top front right vertex (1, 0, 1).
Input input_radial() {
  Input in{unit_brick(10), {}};
  in.targets = select_hexes(in.mesh, {"sphere:1,0,1,0.5"}).hexes;
  return in;
}

/// Scattered targets: each hex of a 10^3 brick with probability 0.05 (seeded: the same set on
/// every platform, mesh/selection.hpp).
Input input_random() {
  Input in{unit_brick(10), {}};
  in.targets = select_hexes(in.mesh, {"random:0.05,1"}).hexes;
  return in;
}

/// Table H-1: the gear's teeth.
Input input_gear_teeth() {
  Input in{generate_gear(GearParams{}), {}};
  in.targets = select_hexes(in.mesh, {"block:2"}).hexes;
  return in;
}

/// Table H-2's case with two passes instead of three: the left surface of a 4^3 brick.
Input input_left_surface() {
  Input in{unit_brick(4), {}};
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 4; ++j) in.targets.push_back(brick_hex({4, 4, 4}, 0, j, k));
  std::sort(in.targets.begin(), in.targets.end());
  return in;
}

HexMesh rockerarm() {
  const std::string path = bench_shared_mesh("rockerarm.mesh");
  if (!std::filesystem::exists(path))
    throw InputError(path + ": no such file (set HEXREFINE_SHARED_DIR to the shared/ folder)");
  return mesh_read(path);
}

/// The real-mesh case of bench_real_mesh under --smoke: rockerarm, hexes within 5 of the origin
/// (113 of 10,600).
Input input_rockerarm_sphere_5() {
  Input in{rockerarm(), {}};
  in.targets = select_hexes(in.mesh, {"sphere:0,0,0,5"}).hexes;
  return in;
}

/// The smoothing case: rockerarm, hexes within 3 of the origin (17 hexes; smoothing the
/// refinement of sphere:0,0,0,5 executes 6 billion instructions, 90 s under Callgrind).
Input input_rockerarm_sphere_3() {
  Input in{rockerarm(), {}};
  in.targets = select_hexes(in.mesh, {"sphere:0,0,0,3"}).hexes;
  return in;
}

PlacementMethod placement_of(const std::string& name) {
  for (PlacementMethod m :
       {PlacementMethod::trilinear, PlacementMethod::optimized, PlacementMethod::untangle})
    if (placement_method_name(m) == name) return m;
  throw InputError("unknown placement '" + name + "'");
}

json refine_work(const RefineResult& r) {
  return {{"final_hexes", r.mesh.hex_count()},
          {"final_nodes", r.mesh.point_count()},
          {"added_targets", r.stats.added_targets},
          {"placement_nodes_moved", r.stats.placement.nodes_moved}};
}

RefineOptions refine_options(const std::string& placement, int passes) {
  RefineOptions o;
  o.placement.method = placement_of(placement);
  o.passes = passes;
  o.threads = 1;
  return o;
}

/// refine(): plan, apply and place, `passes` times, on `make_input()`'s targets.
Workload refine_workload(const std::string& case_name, const std::string& description,
                         Input (*make_input)(), const std::string& method,
                         const std::string& placement, int passes = 1) {
  Workload w;
  w.operation = "refine";
  w.case_name = case_name;
  w.method = method;
  w.placement = placement;
  w.description = description;
  w.run = [=](int64_t& size, const std::filesystem::path&) {
    const Input in = make_input();
    size = in.mesh.hex_count();
    const Targets targets{in.targets};
    const RefineOptions options = refine_options(placement, passes);
    const RefineMethod& refiner = refine_method(method);
    RefineResult result;
    auto work = [&] { result = refine(refiner, in.mesh, targets, options); };
    measured(work);
    json facts = refine_work(result);
    facts["targets"] = targets.hexes.size();
    return facts;
  };
  return w;
}

/// Smoothing alone, set up as the pipeline sets it up for `refine --smooth` (algorithms/
/// pipeline.cpp): the refined hexes and two layers, boundary nodes on the input's boundary.
Workload smooth_workload() {
  Workload w;
  w.operation = "smooth";
  w.case_name = "rockerarm_sphere_3";
  w.method = "selective";
  w.placement = "optimized";
  w.description =
      "mesh_smooth (the defaults of refine --smooth) of rockerarm.mesh refined at sphere:0,0,0,3 "
      "by selective, optimized placement (the refinement outside the count)";
  w.run = [](int64_t& size, const std::filesystem::path&) {
    const Input in = input_rockerarm_sphere_3();
    size = in.mesh.hex_count();
    RefineResult refined = refine(refine_method("selective"), in.mesh, Targets{in.targets},
                                  refine_options("optimized", 1));
    SmoothOptions options = pipeline_smoothing_defaults();
    options.region_hexes = mesh_refined_hexes(refined.mesh);
    const BoundaryReference reference =
        boundary_reference_build(in.mesh, topology_build(in.mesh, TopologyParts::faces));
    options.reference = &reference;
    options.reference_nodes = in.mesh.point_count();
    options.threads = 1;
    SmoothStats stats;
    auto work = [&] { stats = mesh_smooth(refined.mesh, options); };
    measured(work);
    return json{{"region_hexes", stats.region_hexes},
                {"movable_nodes", stats.movable_nodes},
                {"nodes_moved", stats.nodes_moved},
                {"sweeps", stats.sweeps},
                {"joint_iterations", stats.joint_iterations}};
  };
  return w;
}

json check_work(const MeshCheckReport& r) {
  return {{"valid", r.valid()}, {"hexes", r.hexes}, {"boundary_faces", r.boundary_faces}};
}

/// The checker on the Selective Approach's L-shaped output against its input (transitions,
/// refinement levels, the reference comparison) and on rockerarm against itself.
std::vector<Workload> check_workloads() {
  Workload refined;
  refined.operation = "check";
  refined.case_name = "l_shaped_refined";
  refined.method = "selective";
  refined.placement = "trilinear";
  refined.description =
      "mesh_check of the selective L-shaped output (8,060 hexes) against its 10^3 input";
  refined.run = [](int64_t& size, const std::filesystem::path&) {
    const Input in = input_l_shaped();
    const RefineResult r = refine(refine_method("selective"), in.mesh, Targets{in.targets},
                                  refine_options("trilinear", 1));
    size = r.mesh.hex_count();
    MeshCheckReport report;
    auto work = [&] { report = mesh_check(r.mesh, &in.mesh, 1); };
    measured(work);
    return check_work(report);
  };
  Workload real;
  real.operation = "check";
  real.case_name = "rockerarm";
  real.description = "mesh_check of rockerarm.mesh against itself";
  real.run = [](int64_t& size, const std::filesystem::path&) {
    const HexMesh mesh = rockerarm();
    size = mesh.hex_count();
    MeshCheckReport report;
    auto work = [&] { report = mesh_check(mesh, &mesh, 1); };
    measured(work);
    return check_work(report);
  };
  Workload quality;
  quality.operation = "quality";
  quality.case_name = "rockerarm";
  quality.description = "mesh_scaled_jacobians of rockerarm.mesh";
  quality.run = [](int64_t& size, const std::filesystem::path&) {
    const HexMesh mesh = rockerarm();
    size = mesh.hex_count();
    std::vector<double> q;
    auto work = [&] { q = mesh_scaled_jacobians(mesh); };
    measured(work);
    return json{{"values", q.size()}};
  };
  return {refined, real, quality};
}

/// The derived-topology builders on a 25^3 brick (bench_topology's smallest size).
std::vector<Workload> topology_workloads() {
  Workload topology, dual, surface;
  topology.operation = "topology";
  dual.operation = "dual";
  surface.operation = "boundary_surface";
  for (Workload* w : {&topology, &dual, &surface}) w->case_name = "brick_25";
  topology.description = "topology_build of a 25^3 brick (edges, faces, adjacency)";
  dual.description = "dual_build of a 25^3 brick (sheets and chords; topology outside)";
  surface.description = "boundary_surface_build of a 25^3 brick (topology outside)";
  topology.run = [](int64_t& size, const std::filesystem::path&) {
    const HexMesh mesh = unit_brick(25);
    size = mesh.hex_count();
    HexTopology t;
    auto work = [&] { t = topology_build(mesh); };
    measured(work);
    return json{{"edges", t.edge_nodes.size()}, {"faces", t.face_nodes.size()}};
  };
  dual.run = [](int64_t& size, const std::filesystem::path&) {
    const HexMesh mesh = unit_brick(25);
    size = mesh.hex_count();
    const HexTopology t = topology_build(mesh);
    DualSheets d;
    auto work = [&] { d = dual_build(mesh, t); };
    measured(work);
    return json{{"sheets", d.sheets.size()}};
  };
  surface.run = [](int64_t& size, const std::filesystem::path&) {
    const HexMesh mesh = unit_brick(25);
    size = mesh.hex_count();
    const HexTopology t = topology_build(mesh);
    BoundarySurface s;
    auto work = [&] { s = boundary_surface_build(mesh, t); };
    measured(work);
    return json{{"faces", s.face_hex.size()}};
  };
  return {topology, dual, surface};
}

/// One of the main formats: its name in the identity, the file's extension, the write options.
struct Format {
  const char* name;
  const char* extension;
  MeshWriteOptions options;
};

std::vector<Format> formats() {
  MeshWriteOptions text, binary;
  binary.binary = true;
  return {{"medit", ".mesh", text}, {"vtk_ascii", ".vtk", text}, {"vtk_binary", ".vtk", binary},
          {"vtu", ".vtu", text},    {"gmsh", ".msh", text},      {"gmsh_binary", ".msh", binary},
          {"exodus", ".e", text},   {"abaqus", ".inp", text}};
}

int64_t file_bytes(const std::filesystem::path& path) {
  std::error_code ec;
  const auto bytes = std::filesystem::file_size(path, ec);
  return ec ? -1 : static_cast<int64_t>(bytes);
}

/// mesh_write and mesh_read of rockerarm.mesh in every main format (the file to read is written
/// outside the count).
std::vector<Workload> io_workloads() {
  std::vector<Workload> out;
  for (const Format& f : formats()) {
    Workload write, read;
    write.operation = "write";
    read.operation = "read";
    for (Workload* w : {&write, &read}) {
      w->case_name = "rockerarm";
      w->format = f.name;
    }
    write.description = std::string("mesh_write of rockerarm.mesh as ") + f.name;
    read.description = std::string("mesh_read of rockerarm.mesh written as ") + f.name;
    write.run = [f](int64_t& size, const std::filesystem::path& scratch) {
      const HexMesh mesh = rockerarm();
      size = mesh.hex_count();
      const std::string path = (scratch / (std::string("out") + f.extension)).string();
      auto work = [&] { mesh_write(path, mesh, f.options); };
      measured(work);
      return json{{"bytes", file_bytes(path)}};
    };
    read.run = [f](int64_t& size, const std::filesystem::path& scratch) {
      const std::string path = (scratch / (std::string("in") + f.extension)).string();
      mesh_write(path, rockerarm(), f.options);
      HexMesh mesh;
      auto work = [&] { mesh = mesh_read(path); };
      measured(work);
      size = mesh.hex_count();
      return json{{"bytes", file_bytes(path)}, {"nodes", mesh.point_count()}};
    };
    out.push_back(write);
    out.push_back(read);
  }
  return out;
}

/// The `hexrefine refine` command on a 10^3 brick, every hex, one thread (bench_command under
/// --smoke): read Exodus II, select, refine (selective, trilinear), check. Not the write: the
/// pipeline writes on a thread of its own (mesh/staged_write.hpp), whose instructions a count of
/// the calling thread leaves out and whose overlap with the check depends on scheduling; the
/// write workloads count mesh_write itself.
Workload command_workload() {
  Workload w;
  w.operation = "command";
  w.case_name = "full_brick_10";
  w.method = "selective";
  w.placement = "trilinear";
  w.format = "exodus";
  w.description =
      "pipeline_run_files: read a 10^3 brick (.e), refine every hex, check (no output file)";
  w.run = [](int64_t& size, const std::filesystem::path& scratch) {
    const std::string in = (scratch / "in.e").string();
    const HexMesh brick = unit_brick(10);
    size = brick.hex_count();
    mesh_write(in, brick);
    PipelineOptions options;
    options.method = "selective";
    options.select = {"all"};
    options.refine = refine_options("trilinear", 1);
    PipelineResult r;
    auto work = [&] { r = pipeline_run_files(in, "", options); };
    measured(work);
    return json{{"final_hexes", r.mesh.hex_count()}, {"valid", r.check.valid()}};
  };
  return w;
}

std::vector<Workload> workloads() {
  std::vector<Workload> out;
  struct RefineCase {
    const char* name;
    const char* description;
    Input (*input)();
  };
  const RefineCase cases[] = {
      {"full_brick_10", "10^3 unit brick, every hex (Table G-2's case)", input_full_brick},
      {"l_shaped_10", "10^3 brick, left and bottom surfaces (Table G-1)", input_l_shaped},
      {"radial_10", "10^3 brick, hexes within 0.5 of (1,0,1) (Table G-3's case)", input_radial},
      {"random_10", "10^3 brick, each hex with probability 0.05 (random:0.05,1)", input_random},
      {"gear_teeth", "the gear's teeth (Table H-1)", input_gear_teeth},
  };
  for (const RefineCase& c : cases)
    for (const char* method : {"selective", "sheet"})
      out.push_back(refine_workload(c.name, c.description, c.input, method, "trilinear"));
  for (const char* method : {"selective", "sheet"})
    out.push_back(refine_workload("left_surface_4_2_passes",
                                  "4^3 brick, left surface refined twice (Table H-2's case, two "
                                  "passes instead of three)",
                                  input_left_surface, method, "trilinear", 2));
  // Placement on a real mesh: the optimizer's work is the difference from the untangle run
  // (trilinear positions, only inverted children's nodes move). The bricks' placement runs
  // cost more than a billion instructions each and add no code path these do not take.
  const char* sphere_5 = "rockerarm.mesh, hexes within 5 of the origin (sphere:0,0,0,5)";
  for (const char* method : {"selective", "sheet"})
    out.push_back(refine_workload("rockerarm_sphere_5", sphere_5, input_rockerarm_sphere_5, method,
                                  "optimized"));
  out.push_back(refine_workload("rockerarm_sphere_5", sphere_5, input_rockerarm_sphere_5,
                                "selective", "untangle"));
  out.push_back(smooth_workload());
  for (Workload& w : check_workloads()) out.push_back(std::move(w));
  for (Workload& w : topology_workloads()) out.push_back(std::move(w));
  for (Workload& w : io_workloads()) out.push_back(std::move(w));
  out.push_back(command_workload());
  return out;
}

/// The compiler the driver (and, in one build, the code it measures) was built with: counts from
/// different compilers or optimisation levels are not comparable.
std::string compiler() {
#if defined(__clang__)
  std::string name = "clang " __clang_version__;
#elif defined(__GNUC__)
  std::string name = "gcc " __VERSION__;
#else
  std::string name = "unknown";
#endif
#if defined(__OPTIMIZE__)
  return name + " (optimized)";
#else
  return name + " (not optimized)";
#endif
}

int usage(const std::string& message) {
  std::cerr << "instruction_workloads: " << message
            << "\nusage: instruction_workloads --list | --run NAME [--result FILE.json]\n";
  return 2;
}

int run_main(int argc, char** argv) {
  // Views, not copies: the heap's layout, hence the alignment of the buffers the workload
  // copies, must not follow the length of the arguments (the result file's path).
  const std::vector<std::string_view> args(argv + 1, argv + argc);
  const std::vector<Workload> all = workloads();
  if (args.size() == 1 && args[0] == "--list") {
    for (const Workload& w : all) std::cout << w.name() << "\n";
    return 0;
  }
  if ((args.size() != 2 && args.size() != 4) || args[0] != "--run" ||
      (args.size() == 4 && args[2] != "--result"))
    return usage("expected --list or --run NAME [--result FILE.json]");
  const auto it =
      std::find_if(all.begin(), all.end(), [&](const Workload& w) { return w.name() == args[1]; });
  if (it == all.end())
    return usage("no workload named '" + std::string(args[1]) + "' (see --list)");

  // A scratch folder of a fixed name length (mkdtemp's six characters) under /tmp, so that the
  // paths the readers and writers handle are as long in every run.
  char scratch_template[] = "/tmp/hexrefine_instructions_XXXXXX";
  if (!mkdtemp(scratch_template)) throw OperationError("cannot create a folder in /tmp");
  const std::filesystem::path scratch = scratch_template;
  json work;
  int64_t size = 0;
  try {
    work = it->run(size, scratch);
  } catch (...) {
    std::error_code ec;
    std::filesystem::remove_all(scratch, ec);
    throw;
  }
  std::error_code ec;
  std::filesystem::remove_all(scratch, ec);

  const json result = {{"name", it->name()},
                       {"operation", it->operation},
                       {"case", it->case_name},
                       {"size", size},
                       {"method", it->method},
                       {"placement", it->placement},
                       {"format", it->format},
                       {"threads", 1},
                       {"description", it->description},
                       {"work", work},
                       {"compiler", compiler()}};
  if (args.size() == 4) {
    file_write_atomically(std::string(args[3]),
                          [&](std::ostream& os) { os << result.dump(2) << "\n"; });
  } else {
    std::cout << result.dump(2) << "\n";
  }
  return 0;
}

}  // namespace
}  // namespace hexrefine

int main(int argc, char** argv) {
  try {
    return hexrefine::run_main(argc, argv);
  } catch (const hexrefine::InputError& e) {
    std::cerr << "instruction_workloads: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "instruction_workloads: " << e.what() << "\n";
    return 1;
  }
}
