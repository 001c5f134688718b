#pragma once
/// \file
/// The instruction-count side of `hexrefine bench` and `hexrefine bench-compare`, called by
/// cli_bench.cpp's commands: `bench --instructions` (cli_bench_instructions.cpp) and
/// `bench-compare --gate instructions` (cli_bench_gate.cpp).

#include <nlohmann/json.hpp>
#include <string>

#include "experiments/cli/cli.hpp"

namespace hexrefine {

/// The JSON document of a benchmark file, read whole. `nan_allowed`: Google Benchmark writes NaN
/// and Infinity bare, which JSON has not: they are read as null first. InputError naming the file
/// when it cannot be opened or is not JSON.
nlohmann::json bench_json_file_read(const std::string& path, bool nan_allowed);

/// n with a comma between each group of three digits ("12,703,129,263"), for counts in tables.
std::string digits_grouped(long long n);

/// `hexrefine bench --instructions [--out F.json] [--filter REGEX] [--jobs N]`: runs every
/// workload of the instruction_workloads driver (beside the hexrefine binary) under Callgrind and
/// writes each one's instruction count with its identity. Returns 0; throws InputError for bad
/// options, OperationError when Valgrind or the driver is missing or a workload fails.
int bench_instructions_run(const CliArgs& args);

/// `hexrefine bench-compare BASE NEW --gate instructions [--threshold T]`: 1 when a count of BASE
/// grew by more than T in NEW or is missing from NEW, 0 otherwise; InputError (2) naming the
/// file and the key for malformed input.
int bench_gate_run(const CliArgs& args);

}  // namespace hexrefine
