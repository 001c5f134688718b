/// \file
/// The two commands that regenerate results/ from the code as it is:
/// - `hexrefine reproduce [--quick] [--out DIR] [--resume] [--quiet] [--no-plots]`: the thesis
///   suite (cases.hpp) to results/thesis.jsonl, tables and plots by
///   experiments/studies/thesis/report.py. The full suite goes to results/ (regenerating the
///   committed results is what it is for); the quick one (sweeps up to n = 30) to the build
///   folder's results/quick/, so that the README's main command leaves a clone's tracked files
///   untouched (`git status` stays clean); the committed results/quick/ is regenerated only on
///   purpose, with `--quick --out results/quick`.
/// - `hexrefine study [--meshes DIR]... [--no-shared] [--max-hexes-input N] [--out DIR] [--quick]
///   [--resume] [--quiet] [--no-plots]`: the real-mesh study (real_mesh_study_cases) over every
///   mesh of ../shared/meshes and of each --meshes folder to results/real_meshes.jsonl, report
///   and histograms by experiments/studies/real_meshes/report.py; --quick: only the meshes of at
///   most 200 hexes, to the build folder's results/quick/ (as reproduce's). The case file names the
///   shared meshes relative to itself (a clean clone beside ../shared runs it) and the --meshes
///   ones by absolute path (a user's folder).
/// Each writes its case file beside its records, runs it through the runner and then the
/// script; a failing script names the rerun command.

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <optional>

#include "experiments/cli/cli.hpp"
#include "experiments/runner/cases.hpp"
#include "experiments/runner/runner.hpp"
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

/// The build folder the binary was configured in (HEXREFINE_BINARY_DIR), where quick runs write.
std::string build_dir() {
#ifdef HEXREFINE_BINARY_DIR
  return HEXREFINE_BINARY_DIR;
#else
  return (fs::path(run_source_dir()) / "build").string();
#endif
}

/// Where a run writes: --out DIR when given (InputError naming it when it cannot be made),
/// else the build folder's results/quick/ for --quick, else the source tree's results/.
fs::path results_dir(const CliArgs& a, const std::string& command, bool quick) {
  fs::path dir;
  const std::optional<std::string> out = a.value("--out");
  if (out)
    dir = fs::absolute(*out).lexically_normal();
  else
    dir = quick ? fs::path(build_dir()) / "results" / "quick"
                : fs::path(run_source_dir()) / "results";
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec && out)
    throw InputError("hexrefine " + command + ": --out " + *out +
                     ": cannot create: " + ec.message());
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
  const fs::path results = results_dir(a, "reproduce", quick);
  const std::string meshes = meshes_dir().lexically_relative(results).string();
  return suite_run(
      a, thesis_suite_cases(quick, meshes, "thesis.jsonl"), results / "cases.json",
      "studies/thesis/report.py",
      "--thesis " + shell_quote((fs::path(run_shared_dir()) / "thesis" / "tables.json").string()) +
          " --out " + shell_quote(results.string()));
}

/// The mesh files of `dir` (by extension, mesh_format_of), sorted by name.
std::vector<std::string> mesh_files_of(const fs::path& dir) {
  std::vector<std::string> files;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (!entry.is_regular_file(ec)) continue;
    try {
      mesh_format_of(name);
    } catch (const InputError&) {
      continue;  // README, manifests and other files
    }
    files.push_back(name);
  }
  if (ec) throw InputError("hexrefine study: --meshes " + dir.string() + ": " + ec.message());
  std::sort(files.begin(), files.end());
  return files;
}

int study_run(const CliArgs& a) {
  if (!a.positional.empty())
    throw InputError("hexrefine study: unexpected argument '" + a.positional[0] + "'");
  const bool quick = a.flag("--quick");
  int64_t max_hexes = INT64_MAX;
  if (const auto v = a.value("--max-hexes-input"))
    max_hexes = cli_parse_int_in(*v, 1, INT64_MAX, "--max-hexes-input");
  if (quick) max_hexes = std::min<int64_t>(max_hexes, 200);
  const fs::path results = results_dir(a, "study", quick);
  const fs::path case_file = results / "real_meshes.cases.json";

  std::vector<StudyMesh> meshes;
  if (!a.flag("--no-shared")) {
    // As the case file sees it: relative to its folder, so a clean clone beside ../shared runs.
    const fs::path shared = fs::absolute(meshes_dir()).lexically_normal();
    for (const std::string& file : mesh_files_of(shared))
      meshes.push_back(StudyMesh{(shared / file).string(),
                                 (shared.lexically_relative(results) / file).string(), file,
                                 "../shared/meshes", true});
  }
  std::vector<fs::path> seen;
  for (const std::string& given : a.all("--meshes")) {
    std::error_code ec;
    if (!fs::is_directory(given, ec))
      throw InputError("hexrefine study: --meshes " + given + ": not a readable folder" +
                       (fs::exists(given, ec) ? "" : " (no such file or folder)"));
    const fs::path dir = fs::weakly_canonical(given, ec);
    if (std::find(seen.begin(), seen.end(), dir) != seen.end()) continue;  // given twice
    seen.push_back(dir);
    // Absolute in the case file: the folder is the user's, outside the source tree.
    for (const std::string& file : mesh_files_of(given))
      meshes.push_back(
          StudyMesh{(fs::path(given) / file).string(), (dir / file).string(), file, given, false});
  }
  if (meshes.empty())
    throw InputError(
        "hexrefine study: no mesh to study (--no-shared and no --meshes folder "
        "holding a mesh file)");

  std::vector<std::string> skipped;
  nlohmann::json cases = real_mesh_study_cases(meshes, "real_meshes.jsonl", max_hexes, &skipped);
  if (!skipped.empty()) {
    std::string left_out = " Left out: ";
    for (size_t i = 0; i < skipped.size(); ++i) left_out += (i ? "; " : "") + skipped[i];
    cases["description"] = cases["description"].get<std::string>() + "." + left_out;
    if (!a.flag("--quiet"))
      for (const std::string& s : skipped) std::cerr << "hexrefine study: left out " << s << "\n";
  }
  return suite_run(a, cases, case_file, "studies/real_meshes/report.py",
                   "--out " + shell_quote(results.string()));
}

}  // namespace

const CliCommand cli_reproduce_command = {
    "reproduce",
    "",
    "Runs the thesis suite and regenerates results/ (tables, plots, records).",
    {
        {"--quick", "",
         "stop the G-2 and G-3 sweeps at n = 30 and write the build folder's results/quick/"},
        {"--out", "DIR",
         "write the case file, records, tables and plots to DIR (default results/, or with "
         "--quick build/results/quick/; --quick --out results/quick regenerates the committed "
         "quick results)"},
        {"--resume", "", "keep the records already written"},
        {"--quiet", "", "no progress lines"},
        {"--no-plots", "", "records only: skip experiments/studies/thesis/report.py"},
    },
    "",
    reproduce_run,
};

const CliCommand cli_study_command = {
    "study",
    "",
    "Runs the real-mesh study (every mesh x region kind x method x arm: trilinear, default "
    "placement, default placement with --smooth) and writes results/real_meshes.md.",
    {
        {"--meshes", "DIR",
         "study every mesh file of DIR too, read from DIR as given (tagged with its folder)", true},
        {"--no-shared", "", "leave out ../shared/meshes (only the --meshes folders)"},
        {"--max-hexes-input", "N", "leave out the meshes of more than N hexes (named on stderr)"},
        {"--out", "DIR",
         "write the case file, records and report to DIR (default results/, or with --quick "
         "build/results/quick/)"},
        {"--quick", "",
         "only the meshes of at most 200 hexes, to the build folder's results/quick/"},
        {"--resume", "", "keep the records already written"},
        {"--quiet", "", "no progress lines"},
        {"--no-plots", "", "records only: skip experiments/studies/real_meshes/report.py"},
    },
    "Exit status 2 when a --meshes folder cannot be read. Each unreadable mesh file is left out "
    "and named.",
    study_run,
};

}  // namespace hexrefine
