#pragma once
/// \file
/// The `hexrefine` command line. Every command is declared once (CliCommand: synopsis, summary,
/// options with one line of help each) and that declaration drives parsing, `hexrefine COMMAND
/// --help`, the top-level usage and the suggestion for a misspelt option. A command's run
/// function takes the parsed arguments and returns the exit code (0 done, 1 the operation
/// failed, 2 bad usage or bad input); errors are thrown as InputError / OperationError and
/// mapped to exit codes by cli_main.

#include <optional>
#include <string>
#include <vector>

namespace hexrefine {

/// Parsed arguments of one command: positionals, `--name VALUE` options (repeatable) and flags.
struct CliArgs {
  std::vector<std::string> positional;
  std::vector<std::pair<std::string, std::string>> values;
  std::vector<std::string> flags;

  bool flag(const std::string& name) const;
  std::optional<std::string> value(const std::string& name) const;
  std::vector<std::string> all(const std::string& name) const;
};

/// One option of a command.
struct CliOption {
  std::string name;   ///< "--method"
  std::string value;  ///< placeholder of its value ("NAME"); empty for a flag
  std::string help;   ///< one line: meaning, default, range
  bool repeatable = false;
};

struct CliCommand {
  std::string name;         ///< "refine"
  std::string positionals;  ///< "IN OUT"
  std::string summary;      ///< one line
  std::vector<CliOption> options;
  std::string details;  ///< more help after the options (exit codes, formats), may be empty
  int (*run)(const CliArgs& args) = nullptr;
  /// Help made at run time, after `details` (e.g. `generate`'s kinds from the generator table).
  std::string (*more_help)() = nullptr;
  /// The command parses its own options (their set depends on a positional, as `generate KIND`):
  /// run gets every argument as a positional.
  bool parses_itself = false;
};

/// Splits `args` by the command's options; anything else starting with "--" is an InputError
/// naming the command and, when one is close, the known option meant ("did you mean
/// --method?"). `--help` and `-h` are not parsed here (cli_main answers them).
CliArgs cli_parse(const CliCommand& command, const std::vector<std::string>& args);

/// "usage: hexrefine NAME POSITIONALS [options]" then one line per option, then the details.
std::string cli_help(const CliCommand& command);

/// Every command, in the order of the top-level usage.
const std::vector<const CliCommand*>& cli_commands();

/// The known word closest to `word` (edit distance at most a third of its length, at least 2),
/// or "" if none is.
std::string cli_closest(const std::string& word, const std::vector<std::string>& known);

/// "1,2,3" -> {1,2,3}; exactly `count` numbers (count < 0: any), finite; InputError naming `what`.
std::vector<double> cli_parse_doubles(const std::string& text, int count, const std::string& what);
std::vector<int> cli_parse_ints(const std::string& text, int count, const std::string& what);
double cli_parse_double(const std::string& text, const std::string& what);
long long cli_parse_int(const std::string& text, const std::string& what);
/// cli_parse_int within [lo, hi]; InputError "`what` must be in lo..hi, got 'text'".
long long cli_parse_int_in(const std::string& text, long long lo, long long hi,
                           const std::string& what);

/// The thread count of --threads: the value given (1..256), else every core the system reports
/// (at most 256, at least 1). The output does not depend on it (parallel.hpp), only the time.
int cli_threads(const std::optional<std::string>& value);

int cli_main(int argc, char** argv);

// The commands (each defined in its cli_*.cpp).
extern const CliCommand cli_generate_command;
extern const CliCommand cli_check_command;
extern const CliCommand cli_convert_command;
extern const CliCommand cli_sheets_command;
extern const CliCommand cli_refine_command;
extern const CliCommand cli_smooth_command;
extern const CliCommand cli_run_command;
extern const CliCommand cli_reproduce_command;
extern const CliCommand cli_study_command;
extern const CliCommand cli_merge_command;
extern const CliCommand cli_templates_command;
extern const CliCommand cli_bench_command;
extern const CliCommand cli_bench_compare_command;

}  // namespace hexrefine
