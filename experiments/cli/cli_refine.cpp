/// \file
/// `hexrefine refine IN OUT --method M --select SPEC ...`: the refinement pipeline
/// (algorithms/pipeline/pipeline.hpp) from a file to a file.
///
/// OUT (its format and folder) and R are checked before IN is read (cli_output.hpp). The refined
/// mesh's size is bounded before refining: each pass splits a hex into at most 27, so IN's n hexes
/// give at most n * 27^passes; above --max-hexes N (default and maximum 2^31 - 1, the int32 hex
/// ids) the command refuses with exit 1 before any work. The bound is reached by `--select all`
/// and is pessimistic for a small selection (a sheet or a propagation may cross the whole mesh, so
/// no smaller bound holds for every input).
/// Exit codes: 2 bad usage or input (inverted input hexes unless --allow-inverted; an input the
/// checker finds invalid, when the result is invalid too); 1 the refiner cannot handle the
/// configuration, no valid node placement exists, or, with the default switches, the checker finds
/// the result invalid (the message names the defects and the input hexes; nothing is written).
/// With an ablation switch (--no-ranking, --no-propagation, --ebe-only) the result may be
/// non-conformal by design: it is written and the checker's counts go to the report. A selection
/// that matches nothing: a warning, the mesh is written unchanged, exit 0.

#include <unistd.h>

#include <iostream>
#include <limits>
#include <optional>

#include "algorithms/pipeline/pipeline.hpp"
#include "experiments/cli/cli.hpp"
#include "experiments/cli/cli_output.hpp"
#include "experiments/bench/process_huge_pages.hpp"
#include "mesh/atomic_file.hpp"
#include "mesh/error.hpp"

namespace hexrefine {

namespace {

std::string methods_list() {
  std::string s;
  for (const RefineMethod& m : refine_methods()) s += (s.empty() ? "" : "|") + std::string(m.name);
  return s;
}

int refine_run(const CliArgs& a) {
  if (a.positional.size() != 2)
    throw InputError("hexrefine refine: expected IN and OUT (hexrefine refine --help)");
  const std::string in = a.positional[0], out = a.positional[1];
  PipelineOptions o;
  const std::optional<std::string> method = a.value("--method");
  if (!method) throw InputError("hexrefine refine: --method " + methods_list() + " is required");
  o.method = std::string(refine_method(*method).name);
  o.select = a.all("--select");
  if (o.select.empty())
    throw InputError("hexrefine refine: at least one --select SPEC (e.g. --select all)");
  if (const auto p = a.value("--passes"))
    o.refine.passes = static_cast<int>(cli_parse_int_in(*p, 1, 10, "--passes"));
  if (const auto buffer = a.value("--buffer")) o.refine.buffer = pass_buffer_from_name(*buffer);
  if (a.flag("--no-buffer")) o.refine.buffer = PassBuffer::none;
  o.refine.ranking = !a.flag("--no-ranking");
  if (const auto order = a.value("--directional-order")) {
    if (*order == "by-rank")
      o.refine.directional_order = DirectionalOrder::by_rank;
    else if (*order == "by-hex")
      o.refine.directional_order = DirectionalOrder::by_hex;
    else
      throw InputError("--directional-order: expected by-rank or by-hex, got '" + *order + "'");
  }
  o.refine.propagation = !a.flag("--no-propagation");
  o.refine.ebe_only = a.flag("--ebe-only");
  o.refine.allow_inverted = a.flag("--allow-inverted");
  o.refine.threads = cli_threads(a.value("--threads"));
  if (const auto p = a.value("--placement")) {
    if (*p == "trilinear")
      o.refine.placement.method = PlacementMethod::trilinear;
    else if (*p == "optimized")
      o.refine.placement.method = PlacementMethod::optimized;
    else if (*p == "untangle")
      o.refine.placement.method = PlacementMethod::untangle;
    else if (*p == "reference")
      o.refine.placement.method = PlacementMethod::reference;
    else
      throw InputError(
          "hexrefine refine: --placement must be trilinear, reference, optimized or untangle, "
          "got '" +
          *p + "'");
  }
  o.smooth = a.flag("--smooth");
  if (!a.value("--placement")) o.refine.placement.method = pipeline_default_placement(o.smooth);
  if (const auto r = a.value("--max-edge-ratio")) {
    const double cap = cli_parse_double(*r, "hexrefine refine: --max-edge-ratio");
    if (!(cap == 0 || (cap >= 1 && cap <= 1e6)))
      throw InputError("hexrefine refine: --max-edge-ratio must be 0 or in 1..1e6, got '" + *r +
                       "'");
    o.refine.placement.max_edge_ratio = cap;
    o.smoothing.max_edge_ratio = cap;
  }
  // The smoothing's budget: fewer sweeps and joint iterations trade quality for time
  // (results/smoothing_budget.md measures the trade on the real-mesh study).
  for (const char* option :
       {"--smooth-sweeps", "--smooth-joint-iterations", "--smooth-joint-rounds"})
    if (a.value(option) && !o.smooth)
      throw InputError(std::string("hexrefine refine: ") + option + " needs --smooth");
  o.smoothing_both_starts = a.flag("--smooth-both-starts");
  if (o.smoothing_both_starts && !o.smooth)
    throw InputError("hexrefine refine: --smooth-both-starts needs --smooth");
  if (o.smoothing_both_starts && o.refine.placement.method != PlacementMethod::untangle)
    throw InputError(
        "hexrefine refine: --smooth-both-starts smooths from untangle and from optimized: it "
        "takes no --placement but untangle");
  if (const auto n = a.value("--smooth-sweeps"))
    o.smoothing.max_sweeps =
        static_cast<int>(cli_parse_int_in(*n, 1, 1000000, "hexrefine refine: --smooth-sweeps"));
  if (const auto n = a.value("--smooth-joint-iterations"))
    o.smoothing.joint_iterations = static_cast<int>(
        cli_parse_int_in(*n, 0, 1000000, "hexrefine refine: --smooth-joint-iterations"));
  if (const auto n = a.value("--smooth-joint-rounds"))
    o.smoothing.joint_rounds =
        static_cast<int>(cli_parse_int_in(*n, 1, 1000, "hexrefine refine: --smooth-joint-rounds"));
  if (const auto m = a.value("--max-hexes"))
    o.max_hexes = cli_parse_int_in(*m, 1, std::numeric_limits<int32_t>::max(), "--max-hexes");
  if (a.flag("--verbose")) o.verbose = &std::cerr;
  // A progress line on long stages only where someone watches it.
  else if (::isatty(STDERR_FILENO))
    o.progress = &std::cerr;
  cli_output_check("hexrefine refine", out, CliOutputKind::mesh);
  {
    MeshWriteOptions write = cli_mesh_write_options(a, "hexrefine refine", out);
    write.cell_scalars = std::move(o.write.cell_scalars);
    o.write = std::move(write);
  }
  const std::optional<std::string> report_path = a.value("--report");
  if (report_path) cli_output_check("hexrefine refine", *report_path, CliOutputKind::report);

  const PipelineResult r = pipeline_run_files(in, out, o);
  if (!r.selection_warning.empty())
    std::cerr << "hexrefine refine: warning: " << r.selection_warning
              << "; the mesh was written unchanged\n";
  if (!r.placement_warning.empty())
    std::cerr << "hexrefine refine: warning: " << r.placement_warning << "\n";
  if (!r.smoothing_warning.empty())
    std::cerr << "hexrefine refine: warning: " << r.smoothing_warning << "\n";
  if (report_path) {
    nlohmann::json report = pipeline_report(r, o);
    report["input"] = in;
    report["output"] = out;
    report["huge_pages"] = process_uses_huge_pages();
    file_write_atomically(*report_path, [&](std::ostream& os) { os << report.dump(2) << "\n"; });
  }
  const MeshCheckReport& final_check = r.smoothed_check ? *r.smoothed_check : r.check;
  std::cout << o.method << ": " << r.stats.initial_hexes << " -> " << r.stats.final_hexes
            << " hexes, " << (final_check.conformal ? "conformal" : "NOT conformal") << ", "
            << final_check.inverted_hexes << " inverted, min scaled Jacobian "
            << r.check.min_scaled_jacobian;
  if (r.smoothing) std::cout << " (smoothed " << final_check.min_scaled_jacobian << ")";
  std::cout << ", largest edge ratio " << final_check.max_edge_ratio << ", refine "
            << r.stage_seconds.at("refine") << " s, total " << r.stage_seconds.at("total")
            << " s\n";
  for (const std::string& d : mesh_check_defects(final_check)) std::cout << "  " << d << "\n";
  return 0;
}

}  // namespace

const CliCommand cli_refine_command = {
    "refine",
    "IN OUT",
    "Refines the selected hexes of IN, places the new nodes, checks the result against IN and "
    "writes OUT.",
    {
        {"--method", "M",
         "refinement method: selective (Parrish's Selective Approach) or sheet "
         "(Harris-style sheet refinement); required"},
        {"--select", "SPEC",
         "targets, united: all, hexes:FILE, box:..., sphere:cx,cy,cz,r, "
         "boundary:nx,ny,nz[,deg], block:ID[,ID]",
         true},
        {"--passes", "N", "refine the region N times, 1..10 (default 1)"},
        {"--buffer", "RULE",
         "selective, passes > 1: layer (default: one layer around the targets, the thesis' "
         "H-2), transitions (every transition's children, cumulative) or none"},
        {"--no-buffer", "", "ablation: the same as --buffer none"},
        {"--placement", "P",
         "new nodes: trilinear (the thesis' positions), reference (the templates' reference "
         "positions, best on the unit cube, at trilinear's cost), optimized (the default without "
         "--smooth: reference, then raise the worst scaled Jacobian where a child is still poor, "
         "untangle) or untangle (trilinear, inverted children untangled: the default with "
         "--smooth, the better start for it)"},
        {"--smooth", "",
         "smooth the refined region afterwards (checked again; starts from --placement untangle "
         "unless a placement is given, and from optimized where untangle ends below plain "
         "refine's minimum, with a warning; a smoothing the checker rejects is undone, with a "
         "warning in the report)"},
        {"--smooth-both-starts", "",
         "--smooth: place by untangle and by optimized, smooth both, keep the higher minimum "
         "(about twice the time; results/smoothing_starts.md)"},
        {"--smooth-sweeps", "N",
         "--smooth: at most N sweeps over the region's nodes before the joint ascent and N after "
         "each of its rounds, 1..1000000 (default 20; fewer: faster, lower minimum)"},
        {"--smooth-joint-iterations", "N",
         "--smooth: at most N iterations per round of the joint ascent of the nodes around the "
         "worst hexes (boundary nodes on the surface), 0..1000000 (default 1000; 0: the sweeps "
         "alone)"},
        {"--smooth-joint-rounds", "N",
         "--smooth: at most N rounds of joint ascent and sweeps, each with a sharper soft "
         "minimum, while a round raises the minimum, 1..1000 (default 3)"},
        {"--max-edge-ratio", "R",
         "optimized placement and --smooth give no hex an edge ratio above R or its ratio before "
         "(default 20; 0: no cap, the scaled Jacobian alone)"},
        {"--no-ranking", "", "ablation: selective without its ranking system"},
        {"--directional-order", "ORDER",
         "selective: by-hex (default: the thesis' hex after hex) or by-rank (a rank per step)"},
        {"--no-propagation", "", "ablation: selective without its propagation scheme"},
        {"--ebe-only", "", "ablation: element-by-element templates only"},
        {"--allow-inverted", "", "refine an input with inverted hexes (no refusal, no verdict)"},
        {"--max-hexes", "N", "refuse when n*27^passes could exceed N (default 2^31-1)"},
        {"--binary", "", "binary instead of text output (.vtk: BINARY; .msh: Gmsh 4.1 binary)"},
        {"--ascii", "", "VTU output as text instead of appended binary data (.vtu only)"},
        {"--compress", "", "VTU output zlib-compressed (.vtu only)"},
        {"--threads", "N",
         "threads for the template application, node placement, smoothing, the check and the "
         "write, 1..256 (same output; default: every core)"},
        {"--report", "R.json", "write the JSON report (stats, checks, stage times)"},
        {"--verbose", "", "print each stage's time on stderr as it ends"},
    },
    "exit codes: 0 written, 1 the refinement failed (nothing written), 2 bad usage or input\n",
    refine_run,
};

}  // namespace hexrefine
