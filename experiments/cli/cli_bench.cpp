/// \file
/// `hexrefine bench` runs the Google Benchmark executables built beside the hexrefine binary
/// (bench_*) and merges their JSON outputs into one Google Benchmark JSON file;
/// `hexrefine bench-compare` compares two such files benchmark by benchmark.
///
/// Choices:
/// - The executables are those named bench_* in the folder of the running hexrefine binary
///   (/proc/self/exe), run in name order. `--smoke` sets HEXREFINE_BENCH_SMOKE=1 (the benchmark
///   files then register their smallest sizes only) and --benchmark_min_time=0.01, so the whole
///   suite runs in well under a minute; `--repetitions N` passes --benchmark_repetitions=N.
/// - The merged file keeps the first executable's "context" (the machine is the same), adds
///   "hexrefine_executables" (the names run), and concatenates the "benchmarks" arrays.
/// - bench-compare keys each benchmark by its "run_name" ("name" when absent). With repetitions
///   the "median" aggregate is used; other aggregates (mean, stddev, cv) are ignored; without a
///   median, the median of the plain entries (a single entry: itself). Times are converted to
///   seconds by their "time_unit" before the ratio NEW/BASE. The flag follows cpu_time by default
///   (`--by real` for real_time): "slower" when the ratio exceeds 1 + threshold, "faster" when it
///   is below 1 - threshold, and, when both files hold >= 3 repetitions of it, the one-sided
///   Mann-Whitney U test (bench_statistics.hpp) finds the repetitions differ at 5 %; otherwise
///   "within spread". Without repetitions there is no spread to test: the ratio alone flags, as
///   "slower?" / "faster?". Benchmarks with an error are listed as errors, not compared.
/// - `bench --history FILE.jsonl` appends one line per run: commit (git, of the current folder),
///   date, machine, and per benchmark the median, minimum and maximum real and CPU seconds and
///   the number of repetitions; experiments/studies/bench_history/run.py draws it.
/// - Exit codes: bench-compare returns 0 whatever the ratios (a comparison of times is
///   information, not a verdict) and 2 for unreadable or malformed input; bench returns 1 if an
///   executable fails.
/// - `bench --instructions` and `bench-compare --gate instructions` (the CI gate on instruction
///   counts, which do not depend on the load) are cli_bench_instructions.cpp and
///   cli_bench_gate.cpp.
/// - Google Benchmark prints NaN (not JSON) for undefined statistics such as the coefficient of
///   variation of a counter that is always 0; both commands read such tokens as null.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "experiments/bench/bench_statistics.hpp"
#include "experiments/bench/process_huge_pages.hpp"
#include "experiments/cli/cli.hpp"
#include "experiments/cli/cli_bench.hpp"
#include "mesh/atomic_file.hpp"
#include "mesh/error.hpp"

namespace hexrefine {

namespace {

using nlohmann::json;

/// `text` quoted for /bin/sh (single quotes; embedded single quotes closed and escaped).
std::string shell_quote(const std::string& text) {
  std::string out = "'";
  for (char c : text) {
    if (c == '\'')
      out += "'\\''";
    else
      out += c;
  }
  return out + "'";
}

/// The bench_* executables in the folder of the running hexrefine binary, sorted by name.
std::vector<std::filesystem::path> bench_executables() {
  std::error_code ec;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec)
    throw OperationError("hexrefine bench: cannot locate the hexrefine binary: " + ec.message());
  const std::filesystem::path dir = self.parent_path();
  std::vector<std::filesystem::path> out;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("bench_", 0) != 0 || !entry.is_regular_file()) continue;
    if (access(entry.path().c_str(), X_OK) != 0) continue;
    out.push_back(entry.path());
  }
  if (ec)
    throw OperationError("hexrefine bench: cannot list " + dir.string() + ": " + ec.message());
  std::sort(out.begin(), out.end());
  if (out.empty())
    throw OperationError("hexrefine bench: no bench_* executables in " + dir.string() +
                         " (configure with -DHEXREFINE_BENCHMARKS=ON and build them)");
  return out;
}

/// Runs `command` with /bin/sh, returns its stdout; OperationError naming `what` if it fails.
std::string run_capturing(const std::string& command, const std::string& what) {
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) throw OperationError("hexrefine bench: cannot run " + what);
  std::string output;
  std::array<char, 65536> buffer{};
  size_t n;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) output.append(buffer.data(), n);
  const int status = pclose(pipe);
  if (status == -1 || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw OperationError("hexrefine bench: " + what + " failed (status " +
                         std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + ")");
  return output;
}

/// One benchmark's times in seconds as compared (median aggregate or median of the entries), and
/// the repetitions' own times (empty when the file holds aggregates only).
struct BenchTimes {
  double real_seconds = 0.0;
  double cpu_seconds = 0.0;
  std::vector<double> real_samples, cpu_samples;
  bool error = false;
  std::string error_message;
};

/// `text` with the non-JSON number tokens Google Benchmark prints for undefined statistics (NaN,
/// e.g. the coefficient of variation of a counter that is always 0; inf, -inf; any case) replaced
/// by null outside strings, so a strict JSON parser accepts it. Anything else is left as is.
std::string json_without_nan(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  bool in_string = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      out += c;
      if (c == '\\' && i + 1 < text.size()) {
        out += text[++i];
      } else if (c == '"') {
        in_string = false;
      }
      continue;
    }
    if (c == '"') {
      in_string = true;
      out += c;
      continue;
    }
    bool replaced = false;
    for (const char* token : {"-infinity", "infinity", "-inf", "inf", "-nan", "nan"}) {
      const size_t n = std::char_traits<char>::length(token);
      if (i + n > text.size()) continue;
      bool match = true;
      for (size_t k = 0; k < n && match; ++k)
        match = std::tolower(static_cast<unsigned char>(text[i + k])) == token[k];
      if (!match) continue;
      const bool word_after =
          i + n < text.size() && std::isalnum(static_cast<unsigned char>(text[i + n]));
      if (word_after) continue;
      out += "null";
      i += n - 1;
      replaced = true;
      break;
    }
    if (!replaced) out += c;
  }
  return out;
}

}  // namespace

json bench_json_file_read(const std::string& path, bool nan_allowed) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open");
  std::stringstream content;
  content << in.rdbuf();
  try {
    return json::parse(nan_allowed ? json_without_nan(content.str()) : content.str());
  } catch (const json::exception& e) {
    throw InputError(path + ": not valid JSON: " + e.what());
  }
}

std::string digits_grouped(long long n) {
  std::string digits = std::to_string(n), out;
  for (size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out += ',';
    out += digits[i];
  }
  return out;
}

namespace {

double time_unit_seconds(const std::string& unit, const std::string& file,
                         const std::string& name) {
  if (unit == "ns") return 1e-9;
  if (unit == "us") return 1e-6;
  if (unit == "ms") return 1e-3;
  if (unit == "s") return 1.0;
  throw InputError(file + ": benchmark '" + name + "': unknown time_unit '" + unit + "'");
}

double median_of(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

/// Reads a Google Benchmark JSON file into name -> times (see the file comment for the rules).
/// InputError naming the file (and the benchmark) for anything unreadable.
std::map<std::string, BenchTimes> bench_read(const std::string& path) {
  const json doc = bench_json_file_read(path, true);
  if (!doc.is_object() || !doc.contains("benchmarks") || !doc["benchmarks"].is_array())
    throw InputError(path + ": not a Google Benchmark JSON file (no \"benchmarks\" array)");

  struct Collected {
    std::vector<double> real, cpu;
    bool has_median = false;
    double median_real = 0.0, median_cpu = 0.0;
    bool error = false;
    std::string error_message;
  };
  std::map<std::string, Collected> collected;
  size_t index = 0;
  for (const json& b : doc["benchmarks"]) {
    const std::string where = path + ": benchmarks[" + std::to_string(index++) + "]";
    if (!b.is_object() || !b.contains("name") || !b["name"].is_string())
      throw InputError(where + ": entry without a \"name\" string");
    const std::string name = b.contains("run_name") && b["run_name"].is_string()
                                 ? b["run_name"].get<std::string>()
                                 : b["name"].get<std::string>();
    Collected& c = collected[name];
    if (b.value("error_occurred", false)) {
      c.error = true;
      c.error_message = b.value("error_message", std::string("error"));
      continue;
    }
    const std::string run_type = b.value("run_type", std::string("iteration"));
    if (run_type == "aggregate" && b.value("aggregate_name", std::string()) != "median") continue;
    if (!b.contains("real_time") || !b["real_time"].is_number() || !b.contains("cpu_time") ||
        !b["cpu_time"].is_number())
      throw InputError(where + " ('" + name + "'): real_time and cpu_time must be numbers");
    const double unit = time_unit_seconds(b.value("time_unit", std::string("ns")), path,
                                          b["name"].get<std::string>());
    const double real = b["real_time"].get<double>() * unit;
    const double cpu = b["cpu_time"].get<double>() * unit;
    if (!std::isfinite(real) || !std::isfinite(cpu) || real < 0.0 || cpu < 0.0)
      throw InputError(where + " ('" + name + "'): times must be finite and non-negative");
    if (run_type == "aggregate") {
      c.has_median = true;
      c.median_real = real;
      c.median_cpu = cpu;
    } else {
      c.real.push_back(real);
      c.cpu.push_back(cpu);
    }
  }

  std::map<std::string, BenchTimes> out;
  for (const auto& [name, c] : collected) {
    BenchTimes t;
    if (c.has_median) {
      t.real_seconds = c.median_real;
      t.cpu_seconds = c.median_cpu;
    } else if (!c.real.empty()) {
      t.real_seconds = median_of(c.real);
      t.cpu_seconds = median_of(c.cpu);
    } else {
      t.error = true;
    }
    if (c.error) t.error = true;
    t.error_message = c.error_message;
    t.real_samples = c.real;
    t.cpu_samples = c.cpu;
    out.emplace(name, t);
  }
  return out;
}

std::string ratio_text(double base, double now) {
  if (base <= 0.0) return "n/a";
  std::ostringstream s;
  s << std::fixed << std::setprecision(3) << now / base;
  return s.str();
}

std::string seconds_text(double seconds) {
  std::ostringstream s;
  s << std::setprecision(4) << seconds << " s";
  return s.str();
}

/// The first line of `command`'s output, or "unknown" if it fails (no git, not a checkout).
std::string first_line_or_unknown(const std::string& command) {
  FILE* pipe = popen((command + " 2>/dev/null").c_str(), "r");
  if (!pipe) return "unknown";
  std::array<char, 256> buffer{};
  std::string line;
  if (fgets(buffer.data(), buffer.size(), pipe)) line = buffer.data();
  const int status = pclose(pipe);
  while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.pop_back();
  if (status != 0 || line.empty()) return "unknown";
  return line;
}

/// Appends one history record for the merged run to `path` (JSON lines; the file is rewritten
/// atomically with the new line at the end).
void bench_history_append(const std::string& path, const json& merged, const CliArgs& a) {
  json record;
  record["commit"] = first_line_or_unknown("git rev-parse HEAD");
  record["dirty"] =
      first_line_or_unknown("git status --porcelain --untracked-files=no") != "unknown";
  const std::time_t now = std::time(nullptr);
  char date[32];
  std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  record["date"] = date;
  const json& context = merged["context"];
  record["machine"] = {{"host_name", context.value("host_name", std::string())},
                       {"num_cpus", context.value("num_cpus", 0)},
                       {"mhz_per_cpu", context.value("mhz_per_cpu", 0)},
                       // The benchmark programs inherit the tunable from this process: a history
                       // step from huge pages is told apart from a code change.
                       {"huge_pages", process_uses_huge_pages()}};
  record["smoke"] = a.flag("--smoke");
  json benchmarks = json::object();
  const std::string tmp = path + ".run.json";
  file_write_atomically(tmp, [&](std::ostream& os) { os << merged.dump() << "\n"; });
  std::map<std::string, BenchTimes> times;
  try {
    times = bench_read(tmp);
  } catch (...) {
    std::filesystem::remove(tmp);
    throw;
  }
  std::filesystem::remove(tmp);
  for (const auto& [name, t] : times) {
    if (t.error) continue;
    auto range = [](const std::vector<double>& v, double median) {
      if (v.empty()) return json::array({median, median});
      return json::array(
          {*std::min_element(v.begin(), v.end()), *std::max_element(v.begin(), v.end())});
    };
    benchmarks[name] = {{"real_median", t.real_seconds},
                        {"cpu_median", t.cpu_seconds},
                        {"real_range", range(t.real_samples, t.real_seconds)},
                        {"cpu_range", range(t.cpu_samples, t.cpu_seconds)},
                        {"repetitions", std::max<size_t>(t.real_samples.size(), 1)}};
  }
  record["benchmarks"] = benchmarks;
  std::string existing;
  {
    std::ifstream in(path, std::ios::binary);
    if (in) existing.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  if (!existing.empty() && existing.back() != '\n') existing += '\n';
  file_write_atomically(path, [&](std::ostream& os) { os << existing << record.dump() << "\n"; });
  std::cerr << "hexrefine bench: history record appended to " << path << "\n";
}

int bench_run(const CliArgs& a) {
  if (a.flag("--instructions")) return bench_instructions_run(a);
  if (a.value("--jobs"))
    throw InputError(
        "hexrefine bench: --jobs is for --instructions (the timed suite runs one "
        "benchmark at a time)");
  if (!a.positional.empty())
    throw InputError("hexrefine bench: unexpected argument '" + a.positional[0] + "'");
  std::string options = " --benchmark_format=json";
  if (const auto filter = a.value("--filter")) {
    if (filter->empty()) throw InputError("hexrefine bench: --filter needs a non-empty regex");
    options += " --benchmark_filter=" + shell_quote(*filter);
  }
  if (const auto reps = a.value("--repetitions")) {
    const long long n = cli_parse_int(*reps, "hexrefine bench --repetitions");
    if (n < 1 || n > 1000) throw InputError("hexrefine bench: --repetitions must be in 1..1000");
    options += " --benchmark_repetitions=" + std::to_string(n);
  }
  std::string environment;
  if (a.flag("--smoke")) {
    environment = "HEXREFINE_BENCH_SMOKE=1 ";
    options += " --benchmark_min_time=0.01";
  }

  json merged;
  json names = json::array();
  json benchmarks = json::array();
  for (const std::filesystem::path& exe : bench_executables()) {
    const std::string name = exe.filename().string();
    std::cerr << "hexrefine bench: running " << name << "\n";
    const std::string output =
        run_capturing(environment + shell_quote(exe.string()) + options, name);
    names.push_back(name);
    if (output.find_first_not_of(" \t\r\n") == std::string::npos) continue;  // nothing matched
    json doc;
    try {
      doc = json::parse(json_without_nan(output));
    } catch (const json::exception& e) {
      throw OperationError("hexrefine bench: " + name + " printed invalid JSON: " + e.what());
    }
    if (!doc.contains("benchmarks") || !doc["benchmarks"].is_array())
      throw OperationError("hexrefine bench: " + name + " printed no \"benchmarks\" array");
    if (merged.is_null() && doc.contains("context")) merged["context"] = doc["context"];
    for (json& b : doc["benchmarks"]) benchmarks.push_back(std::move(b));
  }
  if (benchmarks.empty())
    throw OperationError("hexrefine bench: no benchmark ran (does --filter match any?)");
  if (!merged.contains("context")) merged["context"] = json::object();
  merged["context"]["hexrefine_executables"] = names;
  merged["context"]["hexrefine_smoke"] = a.flag("--smoke");
  merged["benchmarks"] = std::move(benchmarks);

  const std::string text = merged.dump(2) + "\n";
  if (const auto history = a.value("--history")) bench_history_append(*history, merged, a);
  if (const auto out = a.value("--out")) {
    file_write_atomically(*out, [&](std::ostream& os) { os << text; });
    std::cerr << "hexrefine bench: " << merged["benchmarks"].size() << " entries written to "
              << *out << "\n";
  } else {
    std::cout << text;
  }
  return 0;
}

int bench_compare_run(const CliArgs& a) {
  if (a.value("--gate")) return bench_gate_run(a);
  if (a.positional.size() != 2)
    throw InputError("hexrefine bench-compare: expected BASE.json NEW.json");
  double threshold = 0.05;
  if (const auto t = a.value("--threshold")) {
    threshold = cli_parse_double(*t, "hexrefine bench-compare --threshold");
    if (threshold < 0.0) throw InputError("hexrefine bench-compare: --threshold must be >= 0");
  }
  const std::string by = a.value("--by").value_or("cpu");
  if (by != "cpu" && by != "real")
    throw InputError("hexrefine bench-compare: --by must be cpu or real, got '" + by + "'");

  const std::map<std::string, BenchTimes> base = bench_read(a.positional[0]);
  const std::map<std::string, BenchTimes> now = bench_read(a.positional[1]);

  size_t width = 9;
  for (const auto& [name, t] : base) width = std::max(width, name.size());
  std::cout << std::left << std::setw(static_cast<int>(width)) << "benchmark"
            << "  real_ratio  cpu_ratio  base_cpu      new_cpu       flag (" << by
            << " time, threshold " << threshold << ")\n";
  int compared = 0, slower = 0, faster = 0, errors = 0;
  std::vector<std::string> only_base, only_new;
  for (const auto& [name, b] : base) {
    const auto it = now.find(name);
    if (it == now.end()) {
      only_base.push_back(name);
      continue;
    }
    const BenchTimes& n = it->second;
    std::cout << std::left << std::setw(static_cast<int>(width)) << name << "  ";
    if (b.error || n.error) {
      ++errors;
      std::cout << "error: " << (b.error ? "BASE " : "") << (n.error ? "NEW " : "")
                << (n.error ? n.error_message : b.error_message) << "\n";
      continue;
    }
    ++compared;
    const double base_t = by == "cpu" ? b.cpu_seconds : b.real_seconds;
    const double new_t = by == "cpu" ? n.cpu_seconds : n.real_seconds;
    const std::vector<double>& base_samples = by == "cpu" ? b.cpu_samples : b.real_samples;
    const std::vector<double>& new_samples = by == "cpu" ? n.cpu_samples : n.real_samples;
    // Beyond the threshold and beyond the spread: with >= 3 repetitions on both sides the
    // samples must differ by the one-sided Mann-Whitney test at 5 %; with fewer there is no
    // spread to test against and the ratio decides (marked "?").
    const bool spread = base_samples.size() >= 3 && new_samples.size() >= 3;
    std::string flag;
    if (base_t > 0.0) {
      const double r = new_t / base_t;
      if (r > 1.0 + threshold &&
          (!spread || mann_whitney_p_greater(base_samples, new_samples) <= 0.05)) {
        flag = spread ? "slower" : "slower?";
        ++slower;
      } else if (r < 1.0 - threshold &&
                 (!spread || mann_whitney_p_greater(new_samples, base_samples) <= 0.05)) {
        flag = spread ? "faster" : "faster?";
        ++faster;
      } else if (spread && (r > 1.0 + threshold || r < 1.0 - threshold)) {
        flag = "within spread";
      }
    }
    std::cout << std::setw(10) << ratio_text(b.real_seconds, n.real_seconds) << "  " << std::setw(9)
              << ratio_text(b.cpu_seconds, n.cpu_seconds) << "  " << std::setw(12)
              << seconds_text(b.cpu_seconds) << "  " << std::setw(12) << seconds_text(n.cpu_seconds)
              << "  " << flag << "\n";
  }
  for (const auto& [name, t] : now)
    if (!base.count(name)) only_new.push_back(name);
  for (const std::string& name : only_base) std::cout << "missing in NEW: " << name << "\n";
  for (const std::string& name : only_new) std::cout << "missing in BASE: " << name << "\n";
  std::cout << "summary: " << compared << " compared, " << slower << " slower, " << faster
            << " faster, " << errors << " with errors, " << only_base.size() << " missing in NEW, "
            << only_new.size() << " missing in BASE\n";
  return 0;
}

}  // namespace

const CliCommand cli_bench_command = {
    "bench",
    "",
    "Runs the bench_* Google Benchmark executables and merges their JSON.",
    {
        {"--filter", "REGEX",
         "only the benchmarks (with --instructions: the workloads) whose name matches"},
        {"--out", "FILE.json", "write the merged JSON here (default: stdout)"},
        {"--repetitions", "N", "repeat each benchmark N times (1..1000): median and spread"},
        {"--smoke", "", "smallest sizes only, minimal time (CI)"},
        {"--history", "FILE.jsonl", "append a record of this run (commit, date, machine, medians)"},
        {"--instructions", "",
         "count each workload's instructions under Callgrind instead (the CI gate's input)"},
        {"--jobs", "N", "--instructions: Valgrind processes at once (1..64, default 2)"},
    },
    "",
    bench_run,
};

const CliCommand cli_bench_compare_command = {
    "bench-compare",
    "BASE.json NEW.json",
    "Compares two hexrefine bench files benchmark by benchmark (times: information, never "
    "fails; --gate instructions: the CI gate).",
    {
        {"--threshold", "T", "flag ratios beyond 1 +- T (default 0.05; with --gate 0.03)"},
        {"--gate", "instructions",
         "compare two bench --instructions files: exit 1 if a count grew by more than T"},
        {"--by", "cpu|real", "which time the flag follows (default cpu)"},
    },
    "",
    bench_compare_run,
};

}  // namespace hexrefine
