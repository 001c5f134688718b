#include <filesystem>
#include <iostream>

#include "experiments/cli/cli.hpp"
#include "experiments/runner/runner.hpp"
#include "mesh/error.hpp"

namespace hexrefine {

namespace {

int merge_run(const CliArgs& a) {
  if (a.positional.size() < 2)
    throw InputError("hexrefine merge: expected OUT.jsonl and at least one IN.jsonl");
  std::vector<std::vector<nlohmann::json>> inputs;
  for (size_t i = 1; i < a.positional.size(); ++i) {
    const std::string& path = a.positional[i];
    if (!std::filesystem::exists(path)) throw InputError(path + ": no such file");
    JsonlContent content = jsonl_read(path);
    if (content.truncated_tail && !a.flag("--quiet"))
      std::cerr << "warning: " << path << ": ignored a partial last line (killed run?)\n";
    inputs.push_back(std::move(content.records));
  }
  const std::vector<nlohmann::json> merged = run_records_merge(inputs);
  jsonl_write(a.positional[0], merged);
  if (!a.flag("--quiet"))
    std::cout << "hexrefine merge: " << merged.size() << " records to " << a.positional[0] << "\n";
  return 0;
}

}  // namespace

const CliCommand cli_merge_command = {
    "merge",
    "OUT.jsonl IN.jsonl [IN.jsonl ...]",
    "Merges JSONL record files (one record per key, later files win), sorted by case and method.",
    {
        {"--quiet", "", "no summary line"},
    },
    "",
    merge_run,
};

}  // namespace hexrefine
