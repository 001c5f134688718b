#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <iostream>

#include "experiments/cases.hpp"
#include "experiments/cli.hpp"
#include "experiments/runner.hpp"
#include "mesh/atomic_file.hpp"
#include "mesh/error.hpp"

namespace hexrefine {

namespace {

namespace fs = std::filesystem;

/// Single-quotes `s` for /bin/sh.
std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

}  // namespace

/// `hexrefine reproduce [--quick] [--resume] [--quiet] [--no-plots]`: writes the suite's case
/// file, runs it and regenerates tables and plots with experiments/plots.py. The full suite goes
/// to results/, the quick one (sweeps up to n = 30) to results/quick/, so one never overwrites
/// the other.
namespace {

int reproduce_run(const CliArgs& a) {
  if (!a.positional.empty())
    throw InputError("hexrefine reproduce: unexpected argument '" + a.positional[0] + "'");
  const bool quick = a.flag("--quick");
  const fs::path source(run_source_dir());
  const fs::path results = quick ? source / "results" / "quick" : source / "results";
  std::error_code ec;
  fs::create_directories(results, ec);
  if (ec) throw OperationError(results.string() + ": cannot create: " + ec.message());
  const fs::path meshes = fs::path(run_shared_dir()) / "meshes";
  if (!fs::is_directory(meshes))
    throw InputError(meshes.string() +
                     ": shared meshes folder not found (expected beside the "
                     "source tree, as ../shared/meshes)");

  const std::string meshes_relative = meshes.lexically_relative(results).string();
  const nlohmann::json cases = thesis_suite_cases(quick, meshes_relative, "thesis.jsonl");
  const std::string cases_path = (results / "cases.json").string();
  file_write_atomically(cases_path, [&](std::ostream& out) { out << cases.dump(2) << "\n"; });

  const RunPlan plan = run_plan_read(cases_path);
  RunSettings settings;
  settings.resume = a.flag("--resume");
  settings.quiet = a.flag("--quiet");
  settings.progress = (!settings.quiet && ::isatty(2)) ? &std::cerr : nullptr;
  settings.environment = run_environment_detect();
  const RunSummary s = run_plan_execute(plan, settings, case_execute);
  if (!settings.quiet)
    std::cout << "hexrefine reproduce: " << s.records_written << " records (" << s.records_skipped
              << " already present, " << s.errors << " with an error) to " << s.output << "\n";

  if (a.flag("--no-plots")) return 0;
  const std::string cmd =
      "/usr/bin/python3 " + shell_quote((source / "experiments" / "plots.py").string()) + " " +
      shell_quote(s.output) + " --thesis " +
      shell_quote((fs::path(run_shared_dir()) / "thesis" / "tables.json").string()) + " --out " +
      shell_quote(results.string()) + (settings.quiet ? " --quiet" : "");
  const int rc = std::system(cmd.c_str());
  if (rc != 0)
    throw OperationError("experiments/plots.py failed (exit status " + std::to_string(rc) +
                         "); the records are in " + s.output + ", rerun: " + cmd);
  return 0;
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

}  // namespace hexrefine
