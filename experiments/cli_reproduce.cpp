/// \file
/// The two commands that regenerate results/ from the code as it is:
/// - `hexrefine reproduce [--quick] [--resume] [--quiet] [--no-plots]`: the thesis suite
///   (cases.hpp) to results/thesis.jsonl, tables and plots by experiments/plots.py. The full
///   suite goes to results/, the quick one (sweeps up to n = 30) to results/quick/, so one never
///   overwrites the other.
/// - `hexrefine study [--quick] [--resume] [--quiet] [--no-plots]`: the real-mesh study
///   (real_mesh_study_cases) over every mesh of ../shared/meshes to results/real_meshes.jsonl,
///   report and histograms by experiments/real_meshes_report.py; --quick: only the meshes of at
///   most 200 hexes, to results/quick/.
/// Each writes its case file beside its records, runs it through the runner and then the
/// script; a failing script names the rerun command.

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <iostream>

#include "experiments/cases.hpp"
#include "experiments/cli.hpp"
#include "experiments/runner.hpp"
#include "mesh/atomic_file.hpp"
#include "mesh/error.hpp"
#include "mesh/io.hpp"

namespace hexrefine {

namespace {

namespace fs = std::filesystem;

/// Single-quotes `s` for /bin/sh.
std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

fs::path results_dir(bool quick) {
  const fs::path dir = fs::path(run_source_dir()) / "results" / (quick ? "quick" : "");
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw OperationError(dir.string() + ": cannot create: " + ec.message());
  return dir;
}

fs::path meshes_dir() {
  const fs::path meshes = fs::path(run_shared_dir()) / "meshes";
  if (!fs::is_directory(meshes))
    throw InputError(meshes.string() +
                     ": shared meshes folder not found (expected beside the source tree, as "
                     "../shared/meshes)");
  return meshes;
}

/// Writes `cases` to `case_file`, runs it, then `script ARGS` unless --no-plots.
int suite_run(const CliArgs& a, const nlohmann::json& cases, const fs::path& case_file,
              const std::string& script, const std::string& script_args) {
  file_write_atomically(case_file.string(),
                        [&](std::ostream& out) { out << cases.dump(2) << "\n"; });
  const RunPlan plan = run_plan_read(case_file.string());
  RunSettings settings;
  settings.resume = a.flag("--resume");
  settings.quiet = a.flag("--quiet");
  settings.progress = (!settings.quiet && ::isatty(2)) ? &std::cerr : nullptr;
  settings.environment = run_environment_detect();
  const RunSummary s = run_plan_execute(plan, settings, case_execute);
  if (!settings.quiet)
    std::cout << "hexrefine: " << run_summary_counts(s) << " to " << s.output << "\n";
  if (a.flag("--no-plots")) return 0;
  const std::string cmd =
      "/usr/bin/python3 " +
      shell_quote((fs::path(run_source_dir()) / "experiments" / script).string()) + " " +
      shell_quote(s.output) + " " + script_args + (settings.quiet ? " --quiet" : "");
  const int rc = std::system(cmd.c_str());
  if (rc != 0)
    throw OperationError("experiments/" + script + " failed (exit status " + std::to_string(rc) +
                         "); the records are in " + s.output + ", rerun: " + cmd);
  return 0;
}

int reproduce_run(const CliArgs& a) {
  if (!a.positional.empty())
    throw InputError("hexrefine reproduce: unexpected argument '" + a.positional[0] + "'");
  const bool quick = a.flag("--quick");
  const fs::path results = results_dir(quick);
  const std::string meshes = meshes_dir().lexically_relative(results).string();
  return suite_run(
      a, thesis_suite_cases(quick, meshes, "thesis.jsonl"), results / "cases.json", "plots.py",
      "--thesis " + shell_quote((fs::path(run_shared_dir()) / "thesis" / "tables.json").string()) +
          " --out " + shell_quote(results.string()));
}

int study_run(const CliArgs& a) {
  if (!a.positional.empty())
    throw InputError("hexrefine study: unexpected argument '" + a.positional[0] + "'");
  const bool quick = a.flag("--quick");
  const fs::path results = results_dir(quick);
  const fs::path meshes = meshes_dir();
  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(meshes)) {
    const std::string name = entry.path().filename().string();
    try {
      mesh_format_of(name);
    } catch (const InputError&) {
      continue;  // README and other files
    }
    if (quick && mesh_read(entry.path().string()).hex_count() > 200) continue;
    files.push_back(name);
  }
  std::sort(files.begin(), files.end());
  return suite_run(
      a,
      real_mesh_study_cases(files, meshes.string(), meshes.lexically_relative(results).string(),
                            "real_meshes.jsonl"),
      results / "real_meshes.cases.json", "real_meshes_report.py",
      "--out " + shell_quote(results.string()));
}

}  // namespace

const CliCommand cli_reproduce_command = {
    "reproduce",
    "",
    "Runs the thesis suite and regenerates results/ (tables, plots, records).",
    {
        {"--quick", "", "stop the G-2 and G-3 sweeps at n = 30 and write results/quick/"},
        {"--resume", "", "keep the records already written"},
        {"--quiet", "", "no progress lines"},
        {"--no-plots", "", "records only: skip experiments/plots.py"},
    },
    "",
    reproduce_run,
};

const CliCommand cli_study_command = {
    "study",
    "",
    "Runs the real-mesh study (every shared mesh x region kind x method x placement, smoothed) "
    "and writes results/real_meshes.md.",
    {
        {"--quick", "", "only the meshes of at most 200 hexes, to results/quick/"},
        {"--resume", "", "keep the records already written"},
        {"--quiet", "", "no progress lines"},
        {"--no-plots", "", "records only: skip experiments/real_meshes_report.py"},
    },
    "",
    study_run,
};

}  // namespace hexrefine
