/// \file
/// case_execute: the runner's real executor. Builds (generate) or reads (file) the case's mesh
/// once, selects the targets once, then runs each method on the same targets and measures the
/// output: counts and statistics from the refiner, conformity and inverted hexes from
/// mesh_check, scaled Jacobians (minimum, mean, fixed-bin histogram), and, when the case asks,
/// the minimum after smoothing.

#include <time.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <numeric>

#include "algorithms/selective.hpp"
#include "algorithms/sheet.hpp"
#include "algorithms/smoothing.hpp"
#include "experiments/runner.hpp"
#include "mesh/error.hpp"
#include "mesh/topology.hpp"

#include "mesh/conformity.hpp"
#include "mesh/generators.hpp"
#include "mesh/io.hpp"
#include "mesh/quality.hpp"
#include "mesh/selection.hpp"

namespace hexrefine {

namespace {

using nlohmann::json;

template <typename T>
void param_read(const json& j, const char* key, T& value) {
  if (j.contains(key)) value = j[key].get<T>();
}

/// The case's input mesh; `input` receives the record's "input" object.
HexMesh case_mesh(const RunCase& c, json& input) {
  if (c.mesh.contains("file")) {
    const std::string path = c.mesh["path"].get<std::string>();
    input = json{{"file", c.mesh["file"]}, {"sha256", sha256_file(path)}};
    return mesh_read(path);
  }
  input = c.mesh;
  const json& m = c.mesh;
  const std::string kind = m["generate"].get<std::string>();
  if (kind == "brick") {
    BrickParams p;
    param_read(m, "dims", p.dims);
    param_read(m, "size", p.size);
    param_read(m, "jitter", p.jitter);
    param_read(m, "seed", p.seed);
    return generate_brick(p);
  }
  if (kind == "gear") {
    GearParams p;
    param_read(m, "teeth", p.teeth);
    param_read(m, "inner_radius", p.inner_radius);
    param_read(m, "root_radius", p.root_radius);
    param_read(m, "tip_radius", p.tip_radius);
    param_read(m, "thickness", p.thickness);
    param_read(m, "layers", p.layers);
    param_read(m, "body_radial", p.body_radial);
    param_read(m, "tooth_radial", p.tooth_radial);
    param_read(m, "tooth_tangential", p.tooth_tangential);
    param_read(m, "gap_tangential", p.gap_tangential);
    param_read(m, "tip_fraction", p.tip_fraction);
    return generate_gear(p);
  }
  if (kind == "cylinder") {
    CylinderParams p;
    param_read(m, "radius", p.radius);
    param_read(m, "height", p.height);
    param_read(m, "square_intervals", p.square_intervals);
    param_read(m, "radial_intervals", p.radial_intervals);
    param_read(m, "layers", p.layers);
    param_read(m, "core", p.core);
    return generate_cylinder(p);
  }
  if (kind == "twisted-ring") {
    TwistedRingParams p;
    param_read(m, "ring_radius", p.ring_radius);
    param_read(m, "section_size", p.section_size);
    param_read(m, "around", p.around);
    param_read(m, "section_intervals", p.section_intervals);
    return generate_twisted_ring(p);
  }
  if (kind == "stepped") {
    SteppedParams p;
    param_read(m, "steps", p.steps);
    param_read(m, "step_layers", p.step_layers);
    param_read(m, "depth", p.depth);
    param_read(m, "top_width", p.top_width);
    param_read(m, "tread", p.tread);
    param_read(m, "cell", p.cell);
    return generate_stepped(p);
  }
  throw InputError("runner: unknown generator '" + kind + "'");
}

/// Minimum, mean and histogram of the scaled Jacobians of `mesh`.
void quality_measure(const HexMesh& mesh, json& fields) {
  const std::vector<double> sj = mesh_scaled_jacobians(mesh);
  double min_sj = 1.0, sum = 0.0;
  for (double v : sj) {
    min_sj = std::min(min_sj, v);
    sum += v;
  }
  fields["min_scaled_jacobian"] = min_sj;
  fields["mean_scaled_jacobian"] = sj.empty() ? 1.0 : sum / static_cast<double>(sj.size());
  fields["scaled_jacobian_histogram"] = {
      {"bin_edges_from", -1.0}, {"bin_width", 0.1}, {"counts", scaled_jacobian_histogram(sj)}};
}

/// Conformity and validity of a refined mesh against its input.
void check_measure(const HexMesh& out, const HexMesh& reference, json& fields) {
  const MeshCheckReport report = mesh_check(out, &reference);
  fields["conformal"] = report.conformal;
  fields["non_conformal_faces"] = report.non_conformal_faces;
  fields["inverted_hexes"] = report.inverted_hexes;
  fields["valid"] = report.valid();
  fields["check"] = mesh_check_to_json(report);
}

/// CPU time of this process. The refiners are single-threaded, so CPU time is what the refiner
/// would take on an idle machine; wall times on a shared machine are inflated by waiting.
double process_cpu_seconds() {
  timespec ts{};
  ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

RefineResult method_run(const std::string& method, const HexMesh& mesh, const Targets& targets,
                        const RefineOptions& options) {
  if (method == "selective") return selective_refine(mesh, targets, options);
  if (method == "sheet") return sheet_refine(mesh, targets, options);
  throw InputError("runner: unknown method '" + method + "'");
}

}  // namespace

void case_execute(const RunCase& c, const std::vector<std::string>& methods, const RunEmit& emit) {
  json input;
  const HexMesh mesh = case_mesh(c, input);
  input["initial_min_scaled_jacobian"] = mesh_min_scaled_jacobian(mesh);
  const HexTopology topology = topology_build(mesh);
  const Selection selection = select_hexes(mesh, topology, c.select);
  Targets targets;
  targets.hexes = selection.hexes;
  json selection_json = {{"specs", c.select_given},
                         {"hexes", static_cast<int64_t>(targets.hexes.size())}};
  if (!selection.warning.empty()) selection_json["warning"] = selection.warning;

  for (const std::string& method : methods) {
    json fields = json::object();
    fields["input"] = input;
    fields["selection"] = selection_json;
    fields["initial_hexes"] = mesh.hex_count();
    RefineResult result;
    const auto start = std::chrono::steady_clock::now();
    const double cpu_start = process_cpu_seconds();
    try {
      result = method_run(method, mesh, targets, c.options);
    } catch (const OperationError& e) {
      fields["error"] = e.what();
      fields["error_kind"] = "operation";
      emit(method, std::move(fields));
      continue;
    }
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double cpu = process_cpu_seconds() - cpu_start;
    const RefineStats& s = result.stats;
    fields["final_hexes"] = result.mesh.hex_count();
    fields["final_nodes"] = result.mesh.point_count();
    fields["hexes_per_template"] = s.hexes_per_template;
    fields["hexes_created"] = s.hexes_created;
    fields["hexes_deleted"] = s.hexes_deleted;
    fields["added_targets"] = s.added_targets;
    fields["directional_hexes"] = s.directional_hexes;
    fields["doublets_resolved"] = s.doublets_resolved;
    fields["phase_seconds"] = s.phase_seconds;
    fields["time_seconds"] = s.time_seconds;
    fields["wall_seconds"] = wall;
    fields["cpu_seconds"] = cpu;
    fields["stats"] = refine_stats_to_json(s);
    check_measure(result.mesh, mesh, fields);
    quality_measure(result.mesh, fields);
    if (!c.save_mesh_dir.empty()) {
      const std::string name = run_mesh_file_name(c.name, method);
      MeshWriteOptions write_options;
      write_options.cell_scalars.emplace_back("scaled_jacobian",
                                              mesh_scaled_jacobians(result.mesh));
      mesh_write((std::filesystem::path(c.save_mesh_dir) / name).string(), result.mesh,
                 write_options);
      fields["mesh_file"] = (std::filesystem::path(c.save_mesh_dir).filename() / name).string();
    }
    if (c.smooth) {
      // As `refine --smooth`: the refined and transition hexes move, the untouched ones stay.
      HexMesh smoothed = result.mesh;
      SmoothOptions smooth_options;
      smooth_options.region_hexes = mesh_refined_hexes(smoothed);
      if (!smooth_options.region_hexes.empty()) {
        const SmoothStats smooth_stats = mesh_smooth(smoothed, smooth_options);
        fields["smoothed_min_scaled_jacobian"] = smooth_stats.min_scaled_jacobian_after;
        fields["smoothing"] = smooth_stats_to_json(smooth_stats);
      } else {
        fields["smoothed_min_scaled_jacobian"] = fields["min_scaled_jacobian"];
      }
    }
    emit(method, std::move(fields));
  }
}

}  // namespace hexrefine
