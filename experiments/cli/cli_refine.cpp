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
///
/// The pipeline's options (--passes ... --max-hexes) are not written here: their flags, help
/// lines and checks come from the one table of algorithms/pipeline/pipeline_options_table.hpp,
/// spelt the CLI's way (`--max-edge-ratio`, `--no-ranking`; values as the table spells them,
/// `by_rank`). This file adds what is the CLI's own: what to refine, the output and --threads.

#include <unistd.h>

#include <algorithm>
#include <iostream>
#include <optional>

#include "algorithms/pipeline/pipeline.hpp"
#include "algorithms/pipeline/pipeline_options_table.hpp"
#include "experiments/bench/process_huge_pages.hpp"
#include "experiments/cli/cli.hpp"
#include "experiments/cli/cli_output.hpp"
#include "mesh/atomic_file.hpp"
#include "mesh/error.hpp"

namespace hexrefine {

namespace {

std::string methods_list() {
  std::string s;
  for (const RefineMethod& m : refine_methods()) s += (s.empty() ? "" : "|") + std::string(m.name);
  return s;
}

/// A key as the CLI writes it: `_` becomes `-`.
std::string key_dashed(std::string_view key) {
  std::string s(key);
  std::replace(s.begin(), s.end(), '_', '-');
  return s;
}

/// The table's options as `refine` spells them: `--max-edge-ratio R`, a flag that is on by
/// default as `--no-ranking`, messages after "hexrefine refine: ".
class CliRefineSpelling : public PipelineOptionSpelling {
 public:
  std::string name(std::string_view key) const override { return "--" + key_dashed(key); }
  std::string subject(std::string_view key) const override {
    return "hexrefine refine: " + name(key);
  }
  std::string setting(std::string_view key, const nlohmann::json& value) const override {
    if (value.is_boolean()) {
      if (value.get<bool>()) return name(key);
      return pipeline_option_row(key)->default_value == true ? "--no-" + key_dashed(key)
                                                             : "no " + name(key);
    }
    return name(key) + " " + (value.is_string() ? value.get<std::string>() : value.dump());
  }
  std::string value(const nlohmann::json& value) const override {
    // Appended in steps: a chain of operator+ trips GCC 12's -Wrestrict false positive.
    std::string text = "'";
    text += value.is_string() ? value.get<std::string>() : value.dump();
    text += "'";
    return text;
  }
};

/// The table's options as `refine`'s flags and help lines, in the table's order.
std::vector<CliOption> refine_table_options() {
  const CliRefineSpelling spelling;
  std::vector<CliOption> out;
  for (const PipelineOptionRow& row : pipeline_option_rows()) {
    const std::string negation = "--no-" + key_dashed(row.key);
    if (row.type == PipelineOptionType::flag) {
      if (row.default_value == true)
        out.push_back({negation, "", pipeline_option_text_spelt(row.off_help, spelling)});
      else
        out.push_back({spelling.name(row.key), "", pipeline_option_help_text(row, spelling)});
      continue;
    }
    out.push_back({spelling.name(row.key), std::string(row.placeholder),
                   pipeline_option_help_text(row, spelling)});
    if (!row.off_value.empty())
      out.push_back({negation, "",
                     pipeline_option_text_spelt(row.off_help, spelling) + ", the same as " +
                         spelling.setting(row.key, std::string(row.off_value))});
  }
  return out;
}

/// The settings the arguments give (pipeline_options_table.hpp): a flag's presence, a value's
/// text as the row's type; a negation after its option (`--no-buffer` over `--buffer`).
nlohmann::json refine_settings(const CliArgs& a) {
  const CliRefineSpelling spelling;
  nlohmann::json settings = nlohmann::json::object();
  for (const PipelineOptionRow& row : pipeline_option_rows()) {
    const std::string key(row.key), negation = "--no-" + key_dashed(row.key);
    if (row.type == PipelineOptionType::flag) {
      if (row.default_value == true ? a.flag(negation) : a.flag(spelling.name(key)))
        settings[key] = !row.default_value.get<bool>();
      continue;
    }
    if (const auto text = a.value(spelling.name(key)))
      settings[key] = pipeline_option_value_from_text(row, *text, spelling);
    if (!row.off_value.empty() && a.flag(negation)) settings[key] = std::string(row.off_value);
  }
  return settings;
}

}  // namespace

PipelineOptions cli_refine_options(const CliArgs& a) {
  PipelineOptions o;
  const std::optional<std::string> method = a.value("--method");
  if (!method) throw InputError("hexrefine refine: --method " + methods_list() + " is required");
  o.method = std::string(refine_method(*method).name);
  o.select = a.all("--select");
  if (o.select.empty())
    throw InputError("hexrefine refine: at least one --select SPEC (e.g. --select all)");
  pipeline_options_set(o, refine_settings(a), CliRefineSpelling());
  o.refine.threads = cli_threads(a.value("--threads"));
  return o;
}

namespace {

int refine_run(const CliArgs& a) {
  if (a.positional.size() != 2)
    throw InputError("hexrefine refine: expected IN and OUT (hexrefine refine --help)");
  const std::string in = a.positional[0], out = a.positional[1];
  PipelineOptions o = cli_refine_options(a);
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
  const MeshCheckReport& final_check = r.output_check();
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

/// `refine`'s options: what to refine, the table's options, then the output's.
std::vector<CliOption> refine_cli_options() {
  std::vector<CliOption> out = {
      {"--method", "M",
       "refinement method: selective (Parrish's Selective Approach) or sheet "
       "(Harris-style sheet refinement); required"},
      {"--select", "SPEC",
       "targets, united: all, hexes:FILE, box:..., sphere:cx,cy,cz,r, "
       "boundary:nx,ny,nz[,deg], block:ID[,ID]",
       true},
  };
  for (CliOption& option : refine_table_options()) out.push_back(std::move(option));
  for (CliOption option : std::vector<CliOption>{
           {"--binary", "", "binary instead of text output (.vtk: BINARY; .msh: Gmsh 4.1 binary)"},
           {"--ascii", "", "VTU output as text instead of appended binary data (.vtu only)"},
           {"--compress", "", "VTU output zlib-compressed (.vtu only)"},
           {"--threads", "N",
            "threads for the template application, node placement, smoothing, the check and the "
            "write, 1..256 (same output; default: every core)"},
           {"--report", "R.json", "write the JSON report (stats, checks, stage times)"},
           {"--verbose", "", "print each stage's time on stderr as it ends"},
       })
    out.push_back(std::move(option));
  return out;
}

}  // namespace

const CliCommand cli_refine_command = {
    "refine",
    "IN OUT",
    "Refines the selected hexes of IN, places the new nodes, checks the result against IN and "
    "writes OUT.",
    refine_cli_options(),
    "exit codes: 0 written, 1 the refinement failed (nothing written), 2 bad usage or input\n",
    refine_run,
};

}  // namespace hexrefine
