#include <unistd.h>

#include <iostream>

#include "experiments/cli/cli.hpp"
#include "experiments/runner/runner.hpp"
#include "mesh/error.hpp"

namespace hexrefine {

namespace {

/// Prints the run's summary (expected refusals apart from errors); error records are data (a
/// refiner may refuse a case), so they do not fail the run, but a case whose input was bad (e.g.
/// a selection spec) makes it exit 2.
int run_summary_report(const std::string& command, const RunSummary& s, bool quiet) {
  if (!quiet)
    std::cout << "hexrefine " << command << ": " << run_summary_counts(s) << " written to "
              << s.output << "\n";
  int64_t input_errors = 0;
  for (const nlohmann::json& r : jsonl_read(s.output).records)
    if (r.value("error_kind", "") == "input") ++input_errors;
  if (input_errors > 0)
    throw InputError(s.output + ": " + std::to_string(input_errors) +
                     " records failed on bad input (see their \"error\")");
  return 0;
}

}  // namespace

namespace {

int run_run(const CliArgs& a) {
  if (a.positional.size() != 1)
    throw InputError(
        "hexrefine run: expected one case file (usage: hexrefine run CASES.json "
        "[--resume] [--quiet] [--shard K/N] [--output OUT.jsonl])");
  RunSettings settings;
  settings.resume = a.flag("--resume");
  settings.quiet = a.flag("--quiet");
  if (const auto shard = a.value("--shard")) {
    const auto [k, n] = run_shard_parse(*shard);
    settings.shard = k;
    settings.shard_count = n;
  }
  if (const auto out = a.value("--output")) settings.output = *out;
  const RunPlan plan = run_plan_read(a.positional[0]);
  settings.progress = (!settings.quiet && ::isatty(2)) ? &std::cerr : nullptr;
  settings.environment = run_environment_detect();
  const RunSummary s = run_plan_execute(plan, settings, case_execute);
  return run_summary_report("run", s, settings.quiet);
}

}  // namespace

const CliCommand cli_run_command = {
    "run",
    "CASES.json",
    "Runs a case file: every (case, method) through the refinement pipeline, one JSON record each.",
    {
        {"--resume", "", "keep the records already in the output and run the rest"},
        {"--quiet", "", "no progress lines"},
        {"--shard", "K/N", "run only the cases i with i % N == K - 1 (1 <= K <= N)"},
        {"--output", "OUT.jsonl", "records to this file instead of the case file's \"output\""},
    },
    "",
    run_run,
};

}  // namespace hexrefine
