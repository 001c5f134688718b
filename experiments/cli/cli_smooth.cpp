/// \file
/// `hexrefine smooth IN OUT [--method laplacian|optimize] [--region SPEC ...] [--sweeps N]
/// [--joint-iterations N] [--joint-rounds N]
/// [--report R.json]`: reads IN, smooths it (algorithms/placement/smoothing.hpp), writes OUT
/// (formats by extension, mesh/io.hpp) and optionally a JSON report with the minimum and mean
/// scaled Jacobian before and after, seconds, sweeps and nodes moved.
///
/// --region SPECs (mesh/selection.hpp, united) restrict the moving nodes to those of the selected
/// hexes; without --region every hex is in the region. A region that selects no hex is not an
/// error: the warning is printed and put in the report, and OUT is IN unchanged (zero sweeps).

#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>

#include "algorithms/placement/smoothing.hpp"
#include "experiments/cli/cli.hpp"
#include "experiments/cli/cli_output.hpp"
#include "mesh/atomic_file.hpp"
#include "mesh/error.hpp"
#include "mesh/io.hpp"
#include "mesh/selection.hpp"
#include "mesh/topology.hpp"

namespace hexrefine {

namespace {

int smooth_run(const CliArgs& a) {
  if (a.positional.size() != 2)
    throw InputError("hexrefine smooth: expected IN OUT (two paths), got " +
                     std::to_string(a.positional.size()) + " arguments");
  const std::string& in = a.positional[0];
  const std::string& out = a.positional[1];
  mesh_format_of(in);
  cli_output_check("hexrefine smooth", out, CliOutputKind::mesh);

  SmoothOptions options;
  if (const auto method = a.value("--method")) {
    if (*method == "laplacian")
      options.method = SmoothMethod::laplacian;
    else if (*method == "optimize")
      options.method = SmoothMethod::optimize;
    else
      throw InputError("hexrefine smooth: --method must be laplacian or optimize, got '" + *method +
                       "'");
  }
  if (const auto sweeps = a.value("--sweeps")) {
    const long long n = cli_parse_int(*sweeps, "hexrefine smooth: --sweeps");
    if (n < 0 || n > 1000000)
      throw InputError("hexrefine smooth: --sweeps must be in 0..1000000, got " + *sweeps);
    options.max_sweeps = static_cast<int>(n);
  }
  if (const auto joint = a.value("--joint-iterations")) {
    const long long n = cli_parse_int(*joint, "hexrefine smooth: --joint-iterations");
    if (n < 0 || n > 1000000)
      throw InputError("hexrefine smooth: --joint-iterations must be in 0..1000000, got " + *joint);
    options.joint_iterations = static_cast<int>(n);
  }
  if (const auto rounds = a.value("--joint-rounds"))
    options.joint_rounds =
        static_cast<int>(cli_parse_int_in(*rounds, 1, 1000, "hexrefine smooth: --joint-rounds"));
  if (const auto r = a.value("--max-edge-ratio")) {
    const double cap = cli_parse_double(*r, "hexrefine smooth: --max-edge-ratio");
    if (!(cap == 0 || (cap >= 1 && cap <= 1e6)))
      throw InputError("hexrefine smooth: --max-edge-ratio must be 0 or in 1..1e6, got '" + *r +
                       "'");
    options.max_edge_ratio = cap;
  }
  options.threads = cli_threads(a.value("--threads"));
  const std::vector<std::string> region_specs = a.all("--region");
  const std::optional<std::string> report_path = a.value("--report");
  if (report_path) cli_output_check("hexrefine smooth", *report_path, CliOutputKind::report);

  HexMesh mesh = mesh_read(in);
  std::string warning;
  if (!region_specs.empty()) {
    const HexTopology topology = topology_build(mesh);
    Selection selection = select_hexes(mesh, topology, region_specs);
    options.region_hexes = std::move(selection.hexes);
    warning = selection.warning;
    // An empty region means "all hexes" to mesh_smooth; here it means none: only measure.
    if (options.region_hexes.empty()) options.max_sweeps = 0;
  }
  const SmoothStats stats = mesh_smooth(mesh, options);
  mesh_write(out, mesh);

  if (!warning.empty()) std::cerr << "warning: " << warning << "\n";
  std::cout << "smoothed " << in << " -> " << out << " (" << smooth_method_name(options.method)
            << "): min scaled Jacobian " << stats.min_scaled_jacobian_before << " -> "
            << stats.min_scaled_jacobian_after << ", mean " << stats.mean_scaled_jacobian_before
            << " -> " << stats.mean_scaled_jacobian_after << ", " << stats.sweeps << " sweeps, "
            << stats.nodes_moved << " nodes moved\n";

  if (report_path) {
    nlohmann::json report = stats;
    report["command"] = "smooth";
    report["input"] = in;
    report["output"] = out;
    report["method"] = smooth_method_name(options.method);
    report["max_sweeps"] = options.max_sweeps;
    report["max_joint_iterations"] = options.joint_iterations;
    report["max_joint_rounds"] = options.joint_rounds;
    report["max_edge_ratio"] = options.max_edge_ratio;
    report["hexes"] = mesh.hex_count();
    report["nodes"] = mesh.point_count();
    report["region"] = region_specs;
    report["region_hexes"] =
        region_specs.empty() ? mesh.hex_count() : static_cast<int32_t>(options.region_hexes.size());
    if (!warning.empty()) report["warning"] = warning;
    file_write_atomically(*report_path, [&](std::ostream& os) { os << report.dump(2) << "\n"; });
  }
  return 0;
}

}  // namespace

const CliCommand cli_smooth_command = {
    "smooth",
    "IN OUT",
    "Smooths a hex mesh (the minimum scaled Jacobian never drops, no hex inverts).",
    {
        {"--method", "M", "laplacian or optimize (default optimize)"},
        {"--region", "SPEC", "move only the nodes of these hexes (selection specs, united)", true},
        {"--sweeps", "N",
         "at most N sweeps, 0..1000000 (default 20; optimize: N before the joint ascent and N "
         "after each round of it)"},
        {"--joint-iterations", "N",
         "optimize: at most N iterations per round of the joint ascent of the nodes around the "
         "worst hexes after the sweeps (boundary nodes on the surface), 0..1000000 (default 1000; "
         "0: the sweeps alone)"},
        {"--joint-rounds", "N",
         "optimize: at most N rounds of joint ascent and sweeps while a round raises the "
         "minimum, 1..1000 (default 3)"},
        {"--max-edge-ratio", "R",
         "give no hex an edge ratio above R or its ratio before (default 20; 0: no cap, the "
         "scaled Jacobian alone)"},
        {"--threads", "N",
         "threads for the node visits, 1..256 (same output; default: every core)"},
        {"--report", "R.json", "write the JSON report"},
    },
    "",
    smooth_run,
};

}  // namespace hexrefine
