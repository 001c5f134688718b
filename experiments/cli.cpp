#include "experiments/cli.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <map>
#include <new>
#include <sstream>

#include "mesh/error.hpp"

namespace hexrefine {

namespace {

const char* usage_text =
    "usage: hexrefine COMMAND ...\n"
    "  generate brick OUT --dims NX,NY,NZ [--size LX,LY,LZ] [--jitter F --seed S]\n"
    "  generate gear|cylinder|twisted-ring|stepped OUT [options]\n"
    "  check MESH [--reference REF] [--report R.json]\n"
    "  convert IN OUT [--binary]\n"
    "  sheets MESH [--report R.json]\n"
    "  refine IN OUT --method selective|sheet --select SPEC [--select SPEC ...] [--passes N]\n"
    "         [--buffer] [--smooth] [--no-ranking] [--no-propagation] [--ebe-only]\n"
    "         [--allow-inverted] [--report R.json]\n"
    "  smooth IN OUT [--method laplacian|optimize] [--region SPEC ...] [--sweeps N]\n"
    "         [--report R.json]\n"
    "  run CASES.json [--resume] [--quiet] [--shard K/N] [--output OUT.jsonl]\n"
    "  reproduce [--quick] [--resume] [--quiet] [--no-plots]\n"
    "  merge OUT.jsonl IN.jsonl [IN.jsonl ...]\n"
    "  bench [--filter REGEX] [--out FILE.json] [--smoke] [--repetitions N]\n"
    "  bench-compare BASE.json NEW.json [--threshold 0.05] [--by cpu|real]\n"
    "exit codes: 0 done, 1 the operation failed, 2 bad usage or bad input\n";

}  // namespace

bool CliArgs::flag(const std::string& name) const {
  for (const std::string& f : flags)
    if (f == name) return true;
  return false;
}

std::optional<std::string> CliArgs::value(const std::string& name) const {
  std::optional<std::string> out;
  for (const auto& [k, v] : values)
    if (k == name) out = v;
  return out;
}

std::vector<std::string> CliArgs::all(const std::string& name) const {
  std::vector<std::string> out;
  for (const auto& [k, v] : values)
    if (k == name) out.push_back(v);
  return out;
}

CliArgs cli_parse(const std::string& command, const std::vector<std::string>& args,
                  const std::vector<std::string>& value_options,
                  const std::vector<std::string>& flag_options) {
  CliArgs out;
  auto is_in = [](const std::vector<std::string>& v, const std::string& s) {
    for (const std::string& x : v)
      if (x == s) return true;
    return false;
  };
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a.size() > 2 && a.compare(0, 2, "--") == 0) {
      if (is_in(value_options, a)) {
        if (i + 1 >= args.size())
          throw InputError("hexrefine " + command + ": option " + a + " needs a value");
        out.values.emplace_back(a, args[++i]);
      } else if (is_in(flag_options, a)) {
        out.flags.push_back(a);
      } else {
        throw InputError("hexrefine " + command + ": unknown option " + a);
      }
    } else {
      out.positional.push_back(a);
    }
  }
  return out;
}

double cli_parse_double(const std::string& text, const std::string& what) {
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE || !std::isfinite(v))
    throw InputError(what + ": expected a finite number, got '" + text + "'");
  return v;
}

long long cli_parse_int(const std::string& text, const std::string& what) {
  errno = 0;
  char* end = nullptr;
  const long long v = std::strtoll(text.c_str(), &end, 10);
  if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE)
    throw InputError(what + ": expected an integer, got '" + text + "'");
  return v;
}

std::vector<double> cli_parse_doubles(const std::string& text, int count, const std::string& what) {
  std::vector<double> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) out.push_back(cli_parse_double(item, what));
  if (count >= 0 && static_cast<int>(out.size()) != count)
    throw InputError(what + ": expected " + std::to_string(count) +
                     " comma-separated numbers, got '" + text + "'");
  return out;
}

std::vector<int> cli_parse_ints(const std::string& text, int count, const std::string& what) {
  std::vector<int> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    const long long v = cli_parse_int(item, what);
    if (v < -2147483647LL || v > 2147483647LL) throw InputError(what + ": integer out of range");
    out.push_back(static_cast<int>(v));
  }
  if (count >= 0 && static_cast<int>(out.size()) != count)
    throw InputError(what + ": expected " + std::to_string(count) +
                     " comma-separated integers, got '" + text + "'");
  return out;
}

int cli_main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
    std::cout << usage_text;
    return args.empty() ? 2 : 0;
  }
  const std::string command = args[0];
  args.erase(args.begin());
  static const std::map<std::string, int (*)(const std::vector<std::string>&)> commands = {
      {"generate", cli_generate},
      {"check", cli_check},
      {"convert", cli_convert},
      {"sheets", cli_sheets},
      {"refine", cli_refine},
      {"smooth", cli_smooth},
      {"run", cli_run},
      {"reproduce", cli_reproduce},
      {"merge", cli_merge},
      {"bench", cli_bench},
      {"bench-compare", cli_bench_compare},
  };
  const auto it = commands.find(command);
  if (it == commands.end()) {
    std::cerr << "hexrefine: unknown command '" << command << "'\n" << usage_text;
    return 2;
  }
  try {
    return it->second(args);
  } catch (const InputError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const OperationError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  } catch (const std::bad_alloc&) {
    std::cerr << "error: out of memory\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace hexrefine
