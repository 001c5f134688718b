#pragma once
/// \file
/// The `hexrefine` command line. Each command takes the arguments after its name and returns the
/// exit code (0 done, 1 the operation failed, 2 bad usage or bad input); errors are thrown as
/// InputError / OperationError and mapped to exit codes by cli_main.

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

/// Splits `args`; `value_options` take one value, `flag_options` none; anything else starting
/// with "--" is an InputError naming `command`.
CliArgs cli_parse(const std::string& command, const std::vector<std::string>& args,
                  const std::vector<std::string>& value_options,
                  const std::vector<std::string>& flag_options);

/// "1,2,3" -> {1,2,3}; exactly `count` numbers (count < 0: any), finite; InputError naming `what`.
std::vector<double> cli_parse_doubles(const std::string& text, int count, const std::string& what);
std::vector<int> cli_parse_ints(const std::string& text, int count, const std::string& what);
double cli_parse_double(const std::string& text, const std::string& what);
long long cli_parse_int(const std::string& text, const std::string& what);

int cli_main(int argc, char** argv);

int cli_generate(const std::vector<std::string>& args);
int cli_check(const std::vector<std::string>& args);
int cli_convert(const std::vector<std::string>& args);
int cli_sheets(const std::vector<std::string>& args);
int cli_refine(const std::vector<std::string>& args);
int cli_smooth(const std::vector<std::string>& args);
int cli_run(const std::vector<std::string>& args);
int cli_reproduce(const std::vector<std::string>& args);
int cli_merge(const std::vector<std::string>& args);
int cli_bench(const std::vector<std::string>& args);
int cli_bench_compare(const std::vector<std::string>& args);

}  // namespace hexrefine
