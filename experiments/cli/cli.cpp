#include "experiments/cli/cli.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <new>
#include <sstream>
#include <thread>

#include "mesh/error.hpp"

namespace hexrefine {

namespace {

/// "[--name VALUE]" or "--name VALUE ..." as the usage shows an option.
std::string option_synopsis(const CliOption& o) {
  std::string s = o.name;
  if (!o.value.empty()) s += " " + o.value;
  if (o.repeatable) s += " ...";
  return "[" + s + "]";
}

/// The top-level usage: every command with every option, wrapped.
std::string usage_text() {
  std::ostringstream out;
  out << "usage: hexrefine COMMAND ...   (hexrefine COMMAND --help: the command's options)\n";
  for (const CliCommand* c : cli_commands()) {
    std::string line = "  " + c->name + (c->positionals.empty() ? "" : " " + c->positionals);
    const std::string indent(4 + c->name.size(), ' ');
    for (const CliOption& o : c->options) {
      const std::string item = option_synopsis(o);
      if (line.size() + 1 + item.size() > 100) {
        out << line << "\n";
        line = indent;
      }
      line += " " + item;
    }
    out << line << "\n";
  }
  out << "exit codes: 0 done, 1 the operation failed, 2 bad usage or bad input\n";
  return out.str();
}

size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

}  // namespace

const std::vector<const CliCommand*>& cli_commands() {
  static const std::vector<const CliCommand*> commands = {
      &cli_generate_command,     &cli_check_command,     &cli_convert_command,
      &cli_sheets_command,       &cli_refine_command,    &cli_smooth_command,
      &cli_run_command,          &cli_reproduce_command, &cli_study_command,
      &cli_merge_command,        &cli_templates_command, &cli_bench_command,
      &cli_bench_compare_command};
  return commands;
}

std::string cli_closest(const std::string& word, const std::vector<std::string>& known) {
  std::string best;
  size_t best_distance = std::max<size_t>(2, word.size() / 3) + 1;
  for (const std::string& k : known) {
    const size_t d = edit_distance(word, k);
    if (d < best_distance) {
      best_distance = d;
      best = k;
    }
  }
  return best;
}

bool CliArgs::flag(const std::string& name) const {
  return std::find(flags.begin(), flags.end(), name) != flags.end();
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

CliArgs cli_parse(const CliCommand& command, const std::vector<std::string>& args) {
  CliArgs out;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a.size() <= 2 || a.compare(0, 2, "--") != 0) {
      out.positional.push_back(a);
      continue;
    }
    const auto it = std::find_if(command.options.begin(), command.options.end(),
                                 [&](const CliOption& o) { return o.name == a; });
    if (it == command.options.end()) {
      std::vector<std::string> known;
      for (const CliOption& o : command.options) known.push_back(o.name);
      const std::string near = cli_closest(a, known);
      throw InputError("hexrefine " + command.name + ": unknown option " + a +
                       (near.empty() ? "" : " (did you mean " + near + "?)") + "; hexrefine " +
                       command.name + " --help lists the options");
    }
    if (it->value.empty()) {
      out.flags.push_back(a);
    } else {
      if (i + 1 >= args.size())
        throw InputError("hexrefine " + command.name + ": option " + a + " needs a value (" +
                         it->value + ")");
      out.values.emplace_back(a, args[++i]);
    }
  }
  return out;
}

std::string cli_help(const CliCommand& c) {
  std::ostringstream out;
  out << "usage: hexrefine " << c.name << (c.positionals.empty() ? "" : " " + c.positionals)
      << (c.options.empty() ? "" : " [options]") << "\n"
      << c.summary << "\n";
  if (!c.options.empty()) {
    out << "options:\n";
    size_t width = 0;
    for (const CliOption& o : c.options)
      width = std::max(width, o.name.size() + (o.value.empty() ? 0 : o.value.size() + 1));
    for (const CliOption& o : c.options) {
      const std::string head = o.name + (o.value.empty() ? "" : " " + o.value);
      out << "  " << head << std::string(width - head.size() + 2, ' ') << o.help
          << (o.repeatable ? " (repeatable)" : "") << "\n";
    }
  }
  if (!c.details.empty()) out << c.details;
  if (c.more_help) out << c.more_help();
  return out.str();
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

long long cli_parse_int_in(const std::string& text, long long lo, long long hi,
                           const std::string& what) {
  const long long v = cli_parse_int(text, what);
  if (v < lo || v > hi)
    throw InputError(what + " must be in " + std::to_string(lo) + ".." + std::to_string(hi) +
                     ", got '" + text + "'");
  return v;
}

int cli_threads(const std::optional<std::string>& value) {
  if (value) return static_cast<int>(cli_parse_int_in(*value, 1, 256, "--threads"));
  return static_cast<int>(std::clamp<unsigned>(std::thread::hardware_concurrency(), 1, 256));
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
    std::cout << usage_text();
    return args.empty() ? 2 : 0;
  }
  const std::string name = args[0];
  args.erase(args.begin());
  const CliCommand* command = nullptr;
  std::vector<std::string> names;
  for (const CliCommand* c : cli_commands()) {
    if (c->name == name) command = c;
    names.push_back(c->name);
  }
  if (!command) {
    const std::string near = cli_closest(name, names);
    std::cerr << "hexrefine: unknown command '" << name << "'"
              << (near.empty() ? "" : " (did you mean " + near + "?)") << "\n"
              << usage_text();
    return 2;
  }
  if (std::find_if(args.begin(), args.end(),
                   [](const std::string& a) { return a == "--help" || a == "-h"; }) != args.end()) {
    std::cout << cli_help(*command);
    return 0;
  }
  try {
    CliArgs parsed;
    if (command->parses_itself)
      parsed.positional = args;
    else
      parsed = cli_parse(*command, args);
    return command->run(parsed);
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
