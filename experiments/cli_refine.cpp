/// \file
/// `hexrefine refine IN OUT --method selective|sheet --select SPEC [--select SPEC ...]
/// [--passes N] [--buffer] [--smooth] [--no-ranking] [--no-propagation] [--ebe-only]
/// [--allow-inverted] [--max-hexes N] [--threads N] [--report R.json]`
///
/// OUT (its format and folder) and R are checked before IN is read (cli_output.hpp). The refined
/// mesh's size is bounded before refining: each pass splits a hex into at most 27, so IN's n hexes
/// give at most n * 27^passes; above --max-hexes N (default and maximum 2^31 - 1, the int32 hex
/// ids) the command refuses with exit 1 before any work. The bound is reached by
/// `--select all` and is pessimistic for a small selection (a sheet or a propagation may cross
/// the whole mesh, so no smaller bound holds for every input).
/// Reads IN, selects the targets (mesh/selection.hpp), refines them, smooths the refined region
/// with --smooth (algorithms/smoothing.hpp), checks the result against
/// the input with the project's checker (mesh/conformity.hpp) and writes OUT and the report.
/// Exit codes: 2 bad usage or input (inverted input hexes unless --allow-inverted: "N inverted
/// hexes, first at id K"; an input the checker finds invalid, when the result is invalid too); 1
/// the refiner cannot handle the configuration (the message names the hexes; nothing is written),
/// or, with the default switches, the checker finds the result non-conformal or inverted (nothing
/// is written either). With an ablation switch (--no-ranking,
/// --no-propagation, --ebe-only) the result may be non-conformal by design: it is written and the
/// checker's counts go to the report. A selection that matches nothing: a warning, the mesh is
/// written unchanged, exit 0.

#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <limits>
#include <optional>
#include <sstream>

#include "algorithms/selective.hpp"
#include "algorithms/sheet.hpp"
#include "algorithms/smoothing.hpp"
#include "experiments/cli.hpp"
#include "experiments/cli_output.hpp"
#include "mesh/atomic_file.hpp"
#include "mesh/conformity.hpp"
#include "mesh/error.hpp"
#include "mesh/io.hpp"
#include "mesh/quality.hpp"
#include "mesh/selection.hpp"
#include "mesh/topology.hpp"

namespace hexrefine {

namespace {

const char* refine_usage =
    "usage: hexrefine refine IN OUT --method selective|sheet --select SPEC [--select SPEC ...]\n"
    "       [--passes N] [--buffer] [--smooth] [--no-ranking] [--no-propagation] [--ebe-only]\n"
    "       [--allow-inverted] [--max-hexes N] [--threads N] [--report R.json]\n";

/// n * 27^passes, saturated at INT64_MAX.
int64_t refine_hex_bound(int64_t hexes, int passes) {
  int64_t bound = hexes;
  for (int p = 0; p < passes; ++p)
    bound = bound > std::numeric_limits<int64_t>::max() / 27 ? std::numeric_limits<int64_t>::max()
                                                             : bound * 27;
  return bound;
}

}  // namespace

int cli_refine(const std::vector<std::string>& args) {
  const CliArgs a = cli_parse(
      "refine", args, {"--method", "--select", "--passes", "--report", "--max-hexes", "--threads"},
      {"--buffer", "--smooth", "--no-ranking", "--no-propagation", "--ebe-only",
       "--allow-inverted"});
  if (a.positional.size() != 2)
    throw InputError(std::string("hexrefine refine: expected IN and OUT\n") + refine_usage);
  const std::string in = a.positional[0], out = a.positional[1];
  const std::string method = a.value("--method").value_or("");
  if (method != "selective" && method != "sheet")
    throw InputError("hexrefine refine: --method must be selective or sheet, got '" + method +
                     "'\n" + refine_usage);
  const std::vector<std::string> specs = a.all("--select");
  if (specs.empty())
    throw InputError(std::string("hexrefine refine: at least one --select SPEC\n") + refine_usage);
  RefineOptions options;
  if (const auto p = a.value("--passes")) {
    const long long n = cli_parse_int(*p, "--passes");
    if (n < 1 || n > 10) throw InputError("hexrefine refine: --passes must be in 1..10, got " + *p);
    options.passes = static_cast<int>(n);
  }
  options.buffer = a.flag("--buffer");
  options.ranking = !a.flag("--no-ranking");
  options.propagation = !a.flag("--no-propagation");
  options.ebe_only = a.flag("--ebe-only");
  options.allow_inverted = a.flag("--allow-inverted");
  if (const auto t = a.value("--threads")) {
    const long long n = cli_parse_int(*t, "--threads");
    if (n < 1 || n > 256)
      throw InputError("hexrefine refine: --threads must be in 1..256, got " + *t);
    options.threads = static_cast<int>(n);
  }
  const bool ablation = !options.ranking || !options.propagation || options.ebe_only;
  int64_t max_hexes = std::numeric_limits<int32_t>::max();
  if (const auto m = a.value("--max-hexes")) {
    const long long n = cli_parse_int(*m, "--max-hexes");
    if (n < 1 || n > max_hexes)
      throw InputError("hexrefine refine: --max-hexes must be in 1.." + std::to_string(max_hexes) +
                       " (int32 hex ids), got " + *m);
    max_hexes = n;
  }
  cli_output_check("hexrefine refine", out, CliOutputKind::mesh);
  const std::optional<std::string> report_path = a.value("--report");
  if (report_path) cli_output_check("hexrefine refine", *report_path, CliOutputKind::report);

  const HexMesh input = mesh_read(in);
  const int64_t bound = refine_hex_bound(input.hex_count(), options.passes);
  if (bound > max_hexes) {
    const double exact = static_cast<double>(input.hex_count()) * std::pow(27.0, options.passes);
    std::ostringstream estimate;
    if (bound < std::numeric_limits<int64_t>::max())
      estimate << bound;
    else
      estimate << std::setprecision(3) << exact;
    throw OperationError("hexrefine refine: " + in + " has " + std::to_string(input.hex_count()) +
                         " hexes; " + std::to_string(options.passes) + " passes can give up to " +
                         std::to_string(input.hex_count()) + " x 27^" +
                         std::to_string(options.passes) + " = " + estimate.str() +
                         " hexes, above the limit of " + std::to_string(max_hexes) +
                         " hexes (--max-hexes; at most 2^31 - 1, the int32 hex ids); nothing "
                         "refined or written: use fewer passes");
  }
  if (!options.allow_inverted) {
    int64_t inverted = 0;
    int32_t first = -1;
    for (int32_t h = 0; h < input.hex_count(); ++h)
      if (hex_scaled_jacobian(hex_points(input, h)) <= 0) {
        if (first < 0) first = h;
        ++inverted;
      }
    if (inverted)
      throw InputError(in + ": " + std::to_string(inverted) + " inverted hexes, first at id " +
                       std::to_string(first) + " (use --allow-inverted to refine anyway)");
  }
  // The input's topology is needed for the selection only: gone before the refinement.
  const Selection selection = [&] {
    const HexTopology topology = topology_build(input);
    return select_hexes(input, topology, specs);
  }();

  RefineResult result;
  if (selection.hexes.empty()) {
    std::cerr << "hexrefine refine: warning: " << selection.warning
              << "; writing the mesh unchanged\n";
    result.mesh = input;
    result.stats.method = method;
    result.stats.initial_hexes = result.stats.final_hexes = input.hex_count();
    result.stats.final_nodes = input.point_count();
  } else {
    const Targets targets{selection.hexes};
    const auto t0 = std::chrono::steady_clock::now();
    result = method == "selective" ? selective_refine(input, targets, options)
                                   : sheet_refine(input, targets, options);
    result.stats.time_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }

  // The checker compares the refined mesh with the input (the refiner's result decides the exit
  // code). --smooth then moves the refined and transition hexes' nodes (algorithms/smoothing.hpp);
  // boundary nodes slide within planar faces, so the smoothed mesh no longer subdivides the
  // input's boundary faces exactly: it is checked on its own (coincident-face conformity,
  // inversion) and both verdicts go to the report.
  const MeshCheckReport refined_check = mesh_check(result.mesh, &input);
  if (!ablation && !options.allow_inverted && !refined_check.valid()) {
    // An input that already fails the checker (e.g. a voxel mesh whose cubes touch along
    // edges) is bad input, not a refiner failure.
    const MeshCheckReport input_check = mesh_check(input);
    if (!input_check.valid()) {
      std::string why;
      for (const std::string& d : mesh_check_defects(input_check)) why += "\n  " + d;
      throw InputError(in + ": the input mesh is not valid, so no refinement of it can be:" + why);
    }
    std::string why;
    for (const std::string& d : mesh_check_defects(refined_check)) why += "\n  " + d;
    throw OperationError("hexrefine refine: the " + method +
                         " refiner produced an invalid mesh; nothing written:" + why);
  }
  nlohmann::json smooth_report;
  MeshCheckReport check = refined_check;
  if (a.flag("--smooth")) {
    SmoothOptions so;
    so.region_hexes = mesh_refined_hexes(result.mesh);
    if (!so.region_hexes.empty()) {
      smooth_report = smooth_stats_to_json(mesh_smooth(result.mesh, so));
      check = mesh_check(result.mesh);
      if (!ablation && !options.allow_inverted && !check.valid()) {
        std::string why;
        for (const std::string& d : mesh_check_defects(check)) why += "\n  " + d;
        throw OperationError("hexrefine refine: smoothing left an invalid mesh; nothing written:" +
                             why);
      }
    }
  }
  mesh_write(out, result.mesh);

  nlohmann::json report = refine_stats_to_json(result.stats);
  report["options"] = {{"passes", options.passes},     {"buffer", options.buffer},
                       {"ranking", options.ranking},   {"propagation", options.propagation},
                       {"ebe_only", options.ebe_only}, {"allow_inverted", options.allow_inverted}};
  report["input"] = in;
  report["output"] = out;
  report["selected_hexes"] = selection.hexes.size();
  report["conformal"] = check.conformal;
  report["inverted_hexes"] = check.inverted_hexes;
  report["min_scaled_jacobian"] = check.min_scaled_jacobian;
  report["mean_scaled_jacobian"] = check.mean_scaled_jacobian;
  report["check"] = mesh_check_to_json(check);
  if (!smooth_report.is_null()) {
    report["smooth"] = smooth_report;
    report["check_before_smoothing"] = mesh_check_to_json(refined_check);
  }
  if (report_path)
    file_write_atomically(*report_path, [&](std::ostream& os) { os << report.dump(2) << "\n"; });

  std::cout << method << ": " << result.stats.initial_hexes << " -> " << result.stats.final_hexes
            << " hexes, " << (check.conformal ? "conformal" : "NOT conformal") << ", "
            << check.inverted_hexes << " inverted, min scaled Jacobian "
            << check.min_scaled_jacobian << ", " << result.stats.time_seconds << " s\n";
  for (const std::string& d : mesh_check_defects(check)) std::cout << "  " << d << "\n";
  return 0;
}

}  // namespace hexrefine
