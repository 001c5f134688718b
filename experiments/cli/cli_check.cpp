/// \file
/// `hexrefine check MESH [--reference REF] [--report R.json] [--sheets] [--worst K] [--threads N]`:
/// reads a hex mesh, runs the conformity and validity checks of mesh/conformity.hpp (against REF,
/// the mesh before refinement, if given), counts the dual sheets with --sheets, lists the K hexes
/// of lowest scaled Jacobian with their boundary faces and cell attributes (which template and
/// which input hex a refinement made them from) with --worst, prints a summary and
/// writes the JSON report (with the wall and CPU time of each stage and the peak memory;
/// --verbose prints the wall time and the peak per stage).
/// Exit codes: 0 valid (conformal, no inverted hex, geometry preserved when compared), 1 defects
/// found (listed in the summary; the report is still written), 2 bad usage or unreadable input.

#include <chrono>
#include <cstdio>
#include <ctime>
#include <iostream>
#include <optional>

#include "algorithms/pipeline/pipeline.hpp"
#include "algorithms/templates/template_library.hpp"
#include "experiments/bench/process_huge_pages.hpp"
#include "experiments/cli/cli.hpp"
#include "mesh/atomic_file.hpp"
#include "mesh/conformity.hpp"
#include "mesh/dual.hpp"
#include "mesh/error.hpp"
#include "mesh/io.hpp"
#include "mesh/topology.hpp"
#include "mesh/worst_hexes.hpp"

namespace hexrefine {

namespace {

/// CPU seconds of this process so far, all threads.
double process_cpu_seconds() {
  timespec ts{};
  ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

std::string format_number(double value) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", value);
  return buf;
}

}  // namespace

namespace {

int check_run(const CliArgs& a) {
  if (a.positional.size() != 1)
    throw InputError(
        "hexrefine check: expected exactly one MESH argument (usage: hexrefine check "
        "MESH [--reference REF] [--report R.json] [--sheets] [--worst K] [--threads N])");
  const std::string path = a.positional[0];
  const int threads = cli_threads(a.value("--threads"));
  // Parsed before the mesh is read: a bad K fails at once, not after the check.
  std::optional<int> worst_count;
  if (const auto k = a.value("--worst"))
    worst_count = static_cast<int>(cli_parse_int_in(*k, 1, 1000, "hexrefine check: --worst"));
  std::ostream* verbose = a.flag("--verbose") ? &std::cerr : nullptr;
  nlohmann::json stage_seconds = nlohmann::json::object();
  nlohmann::json stage_cpu_seconds = nlohmann::json::object();
  auto start = std::chrono::steady_clock::now();
  double cpu_start = process_cpu_seconds();
  auto stage_end = [&](const char* stage) {
    const auto now = std::chrono::steady_clock::now();
    const double seconds = std::chrono::duration<double>(now - start).count();
    const double cpu = process_cpu_seconds();
    stage_seconds[stage] = seconds;
    stage_cpu_seconds[stage] = cpu - cpu_start;
    cpu_start = cpu;
    if (verbose)
      *verbose << "hexrefine: " << stage << " " << format_number(seconds) << " s (peak so far "
               << static_cast<int64_t>(process_peak_memory_mb()) << " MB)\n";
    start = now;
  };
  // The checker matches the faces anyway: the reader's own matching is left out, and a
  // non-manifold mesh is refused below as mesh_read refuses it.
  const HexMesh mesh = mesh_read(path, MeshReadOptions{.manifold_test = false});
  std::optional<HexMesh> reference;
  if (const auto reference_path = a.value("--reference")) reference = mesh_read(*reference_path);
  stage_end("read");

  const MeshCheckReport report = mesh_check(mesh, reference ? &*reference : nullptr, threads);
  if (report.nonmanifold_faces > 0) mesh_require_manifold(mesh, path);
  stage_end("check");
  nlohmann::json json = report;
  json["file"] = path;
  if (reference) json["reference_file"] = *a.value("--reference");
  // The dual needs the full topology (edges, node -> hexes): several times the check's time and
  // memory on a large mesh, so only on request.
  std::optional<int64_t> sheets, self_intersecting;
  if (a.flag("--sheets")) {
    const HexTopology topology = topology_build(mesh);
    const DualSheets dual = dual_build(mesh, topology);
    sheets = dual.sheet_count();
    self_intersecting = 0;
    for (const SheetInfo& s : dual.sheets) *self_intersecting += s.self_intersecting;
    json["sheets"] = *sheets;
    json["self_intersecting_sheets"] = *self_intersecting;
    stage_end("sheets");
  }
  std::vector<WorstHex> worst;
  if (worst_count) {
    worst = mesh_worst_hexes(mesh, *worst_count, threads);
    nlohmann::json list = nlohmann::json::array();
    for (const WorstHex& w : worst) {
      nlohmann::json attributes = nlohmann::json::object();
      for (const HexAttribute& attribute : mesh.attributes)
        attributes[attribute.name] = attribute.values[w.hex];
      nlohmann::json entry = {{"hex", w.hex},
                              {"scaled_jacobian", w.scaled_jacobian},
                              {"boundary_faces", w.boundary_faces},
                              {"attributes", attributes}};
      if (const std::vector<int32_t>* tag = mesh_find_attribute(mesh, attribute_template_tag))
        entry["template"] = template_tag_name(static_cast<TemplateTag>((*tag)[w.hex]));
      list.push_back(entry);
    }
    json["worst_hexes"] = list;
    stage_end("worst");
  }
  json["stage_seconds"] = stage_seconds;
  json["stage_cpu_seconds"] = stage_cpu_seconds;
  json["peak_memory_mb"] = process_peak_memory_mb();
  json["huge_pages"] = process_uses_huge_pages();

  std::ostream& out = std::cout;
  out << path << ": " << report.hexes << " hexes, " << report.nodes << " nodes, "
      << report.boundary_faces << " boundary faces\n";
  out << "  scaled Jacobian: min " << format_number(report.min_scaled_jacobian) << ", mean "
      << format_number(report.mean_scaled_jacobian) << "; largest edge ratio "
      << format_number(report.max_edge_ratio) << "\n";
  out << "  volume " << format_number(report.volume) << ", boundary area "
      << format_number(report.boundary_area) << "\n";
  if (sheets)
    out << "  dual: " << *sheets << " sheets, " << *self_intersecting << " self-intersecting\n";
  if (report.reference_compared)
    out << "  against reference: volume relative error "
        << format_number(report.volume_relative_error) << ", boundary area relative error "
        << format_number(report.boundary_area_relative_error)
        << (report.reference_planar_faced ? " (planar-faced: must be preserved)"
                                          : " (reference not planar-faced: reported only)")
        << "\n";
  for (const WorstHex& w : worst) {
    out << "  worst: hex " << w.hex << ", scaled Jacobian " << format_number(w.scaled_jacobian)
        << ", " << w.boundary_faces << " boundary face" << (w.boundary_faces == 1 ? "" : "s");
    if (const std::vector<int32_t>* tag = mesh_find_attribute(mesh, attribute_template_tag))
      out << ", template " << template_tag_name(static_cast<TemplateTag>((*tag)[w.hex]));
    if (const std::vector<int32_t>* parent = mesh_find_attribute(mesh, attribute_parent_hex))
      out << ", from input hex " << (*parent)[w.hex];
    out << "\n";
  }
  // Several bodies are a valid mesh (glued or contact parts): named, never listed as defects.
  if (report.bodies > 1)
    out << "  " << report.bodies << " bodies, " << report.interface_faces
        << " interface face pairs, " << report.interface_nodes
        << " interface nodes (coincident between bodies, unmerged: not a defect)\n";
  if (report.duplicate_nodes > 0)
    out << "  note: " << report.duplicate_nodes << " duplicate nodes\n";
  if (report.unused_nodes > 0) out << "  note: " << report.unused_nodes << " unused nodes\n";
  if (report.self_contact_faces > 0)
    out << "  note: " << report.self_contact_faces
        << " boundary faces touch another part of the boundary (self-contact: no node joins "
           "them; not a defect)\n";
  const std::vector<std::string> defects = mesh_check_defects(report);
  if (defects.empty()) {
    out << "  valid: conformal, no inverted hex\n";
  } else {
    out << "  INVALID:\n";
    for (const std::string& d : defects) out << "    " << d << "\n";
  }

  if (const auto report_path = a.value("--report"))
    file_write_atomically(*report_path, [&](std::ostream& os) { os << json.dump(2) << "\n"; });
  return report.valid() ? 0 : 1;
}

}  // namespace

const CliCommand cli_check_command = {
    "check",
    "MESH",
    "Checks a hex mesh: conformity, hanging nodes, doublets, inverted hexes, quality, dual sheets.",
    {
        {"--reference", "REF",
         "the mesh before refinement: compare boundary, volume and area with it"},
        {"--report", "R.json", "write the JSON report"},
        {"--sheets", "", "also count the dual sheets (builds the full topology: slower)"},
        {"--worst", "K",
         "list the K hexes (1..1000) of lowest scaled Jacobian: boundary faces, template, "
         "input hex"},
        {"--threads", "N", "threads for the check, 1..256 (same report; default: every core)"},
        {"--verbose", "", "print each stage's time on stderr as it ends"},
    },
    "exit codes: 0 valid, 1 defects found (the report is still written), 2 bad usage or input\n",
    check_run,
};

}  // namespace hexrefine
