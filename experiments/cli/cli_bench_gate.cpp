/// \file
/// `hexrefine bench-compare BASE NEW --gate instructions [--threshold T]`: the CI gate on the
/// instruction counts of `hexrefine bench --instructions` (cli_bench_instructions.cpp).
///
/// Verdict: every benchmark of BASE is looked up by name in NEW and its ratio NEW/BASE taken.
/// A ratio above 1 + T (default 0.03) is a regression; below 1 - T an improvement (printed, never
/// failing). A benchmark of BASE missing from NEW fails the gate too: a workload that was
/// removed or renamed changes the suite, which only a deliberate new baseline may do. One of NEW
/// missing from BASE is listed and not gated. Exit 1 when the gate fails (each regression named
/// with its ratio), 0 when it passes, 2 for unreadable or malformed input (naming the file and
/// the key).
///
/// Also printed, to read a change: where a benchmark's "work" (the driver's counts of what was
/// done: final hexes, nodes moved, bytes) or size differs, the keys that changed (more work, not
/// slower code); where the files were counted with another compiler or Valgrind, a note (their
/// counts are not comparable: regenerate the baseline on the CI toolchain).
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "experiments/cli/cli_bench.hpp"
#include "mesh/error.hpp"

namespace hexrefine {

namespace {

using nlohmann::json;

constexpr double gate_default_threshold = 0.03;

struct CountEntry {
  long long instructions = 0;
  json size;  ///< null when absent
  json work;  ///< null when absent
};

/// One instruction-count file: its benchmarks in file order and by name, and its context.
struct CountFile {
  std::vector<std::string> order;
  std::map<std::string, CountEntry> entries;
  json context;
};

/// Reads and validates a file of `hexrefine bench --instructions`. InputError naming the file
/// and the key (and the entry) for anything that is not one.
CountFile count_file_read(const std::string& path) {
  const json doc = bench_json_file_read(path, false);
  if (!doc.is_object())
    throw InputError(path +
                     ": expected a JSON object (an output of hexrefine bench --instructions)");
  if (!doc.contains("format"))
    throw InputError(path +
                     ": key \"format\" missing (not an output of hexrefine bench --instructions)");
  if (doc["format"] != "hexrefine-instructions")
    throw InputError(path + ": key \"format\": expected \"hexrefine-instructions\", got " +
                     doc["format"].dump());
  if (!doc.contains("version") || doc["version"] != 1)
    throw InputError(path + ": key \"version\": expected 1, got " +
                     (doc.contains("version") ? doc["version"].dump() : std::string("nothing")));
  if (!doc.contains("benchmarks")) throw InputError(path + ": key \"benchmarks\" missing");
  if (!doc["benchmarks"].is_array())
    throw InputError(path + ": key \"benchmarks\": expected an array, got " +
                     std::string(doc["benchmarks"].type_name()));
  CountFile file;
  if (doc.contains("context") && doc["context"].is_object()) file.context = doc["context"];
  size_t index = 0;
  for (const json& b : doc["benchmarks"]) {
    const std::string where = path + ": benchmarks[" + std::to_string(index++) + "]";
    if (!b.is_object()) throw InputError(where + ": expected an object");
    if (!b.contains("name")) throw InputError(where + ": key \"name\" missing");
    if (!b["name"].is_string() || b["name"].get<std::string>().empty())
      throw InputError(where + ": key \"name\": expected a non-empty string, got " +
                       b["name"].dump());
    const std::string name = b["name"].get<std::string>();
    const std::string named = where + " (\"" + name + "\")";
    if (!b.contains("instructions")) throw InputError(named + ": key \"instructions\" missing");
    const json& count = b["instructions"];
    if (!count.is_number_integer() || count.get<long long>() <= 0)
      throw InputError(named + ": key \"instructions\": expected a positive integer, got " +
                       count.dump());
    if (file.entries.count(name))
      throw InputError(named + ": key \"name\": \"" + name + "\" appears twice");
    CountEntry e;
    e.instructions = count.get<long long>();
    if (b.contains("size")) e.size = b["size"];
    if (b.contains("work")) e.work = b["work"];
    file.entries.emplace(name, std::move(e));
    file.order.push_back(name);
  }
  return file;
}

std::string percent_text(double ratio) {
  std::ostringstream s;
  s << std::showpos << std::fixed << std::setprecision(2) << (ratio - 1.0) * 100.0 << " %";
  return s.str();
}

std::string ratio_text(double ratio) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(4) << ratio;
  return s.str();
}

/// "final_hexes 8060 -> 8100, ..." for the keys of two "work" objects that differ; "" if none.
std::string work_changes(const CountEntry& base, const CountEntry& now) {
  std::string out;
  auto add = [&](const std::string& key, const json& b, const json& n) {
    if (b == n) return;
    out += (out.empty() ? "" : ", ") + key + " " + (b.is_null() ? "-" : b.dump()) + " -> " +
           (n.is_null() ? "-" : n.dump());
  };
  add("size", base.size, now.size);
  if (base.work.is_object() && now.work.is_object()) {
    for (const auto& [key, value] : base.work.items())
      add(key, value, now.work.contains(key) ? now.work[key] : json());
    for (const auto& [key, value] : now.work.items())
      if (!base.work.contains(key)) add(key, json(), value);
  }
  return out;
}

}  // namespace

int bench_gate_run(const CliArgs& a) {
  if (a.positional.size() != 2)
    throw InputError("hexrefine bench-compare: expected BASE.json NEW.json");
  const std::string gate = a.value("--gate").value_or("");
  if (gate != "instructions")
    throw InputError("hexrefine bench-compare: --gate must be 'instructions', got '" + gate + "'");
  if (a.value("--by"))
    throw InputError("hexrefine bench-compare: --by is for times, not with --gate instructions");
  double threshold = gate_default_threshold;
  if (const auto t = a.value("--threshold")) {
    threshold = cli_parse_double(*t, "hexrefine bench-compare --threshold");
    if (!(threshold >= 0.0)) throw InputError("hexrefine bench-compare: --threshold must be >= 0");
  }
  const std::string base_path = a.positional[0], new_path = a.positional[1];
  const CountFile base = count_file_read(base_path);
  const CountFile now = count_file_read(new_path);

  std::cout << "gate: instruction counts of " << new_path << " against " << base_path
            << ", threshold " << threshold * 100.0 << " %\n";
  for (const char* key : {"compiler", "valgrind"}) {
    const std::string b = base.context.value(key, std::string()),
                      n = now.context.value(key, std::string());
    if (!b.empty() && !n.empty() && b != n)
      std::cout << "note: " << key << " differs (BASE " << b << ", NEW " << n
                << "): counts are comparable for the same toolchain only\n";
  }
  size_t width = 9;
  for (const std::string& name : base.order) width = std::max(width, name.size());
  std::cout << std::left << std::setw(static_cast<int>(width)) << "benchmark" << std::right
            << std::setw(16) << "base" << std::setw(16) << "new" << std::setw(9) << "ratio"
            << "  verdict\n";
  std::vector<std::pair<std::string, double>> regressions, improvements;
  std::vector<std::string> missing_in_new, not_in_base;
  for (const std::string& name : base.order) {
    const CountEntry& b = base.entries.at(name);
    const auto it = now.entries.find(name);
    if (it == now.entries.end()) {
      missing_in_new.push_back(name);
      continue;
    }
    const CountEntry& n = it->second;
    const double ratio = static_cast<double>(n.instructions) / static_cast<double>(b.instructions);
    std::string verdict;
    if (ratio > 1.0 + threshold) {
      verdict = "REGRESSION (" + percent_text(ratio) + ")";
      regressions.emplace_back(name, ratio);
    } else if (ratio < 1.0 - threshold) {
      verdict = "improved (" + percent_text(ratio) + ")";
      improvements.emplace_back(name, ratio);
    }
    std::cout << std::left << std::setw(static_cast<int>(width)) << name << std::right
              << std::setw(16) << digits_grouped(b.instructions) << std::setw(16)
              << digits_grouped(n.instructions) << std::setw(9) << ratio_text(ratio) << "  "
              << verdict << "\n";
    const std::string changes = work_changes(b, n);
    if (!changes.empty()) std::cout << "    work changed: " << changes << "\n";
  }
  for (const std::string& name : now.order)
    if (!base.entries.count(name)) not_in_base.push_back(name);
  for (const std::string& name : missing_in_new)
    std::cout << "missing in NEW (fails the gate): " << name << "\n";
  for (const std::string& name : not_in_base)
    std::cout << "not in BASE (not gated until the baseline is updated): " << name << "\n";
  const size_t compared = base.order.size() - missing_in_new.size();
  std::cout << "summary: " << compared << " compared, " << regressions.size() << " regressions, "
            << improvements.size() << " improvements, " << missing_in_new.size()
            << " missing in NEW, " << not_in_base.size() << " not in BASE\n";
  for (const auto& [name, ratio] : improvements)
    std::cout << "improved: " << name << " ratio " << ratio_text(ratio) << " ("
              << percent_text(ratio) << ")\n";
  if (regressions.empty() && missing_in_new.empty()) {
    std::cout << "gate passed: no instruction count grew by more than " << threshold * 100.0
              << " %\n";
    return 0;
  }
  for (const auto& [name, ratio] : regressions)
    std::cout << "regression: " << name << " ratio " << ratio_text(ratio) << " ("
              << percent_text(ratio) << ", threshold " << threshold * 100.0 << " %)\n";
  std::cout << "gate FAILED: " << regressions.size() << " regressions, " << missing_in_new.size()
            << " missing in NEW (if intended, update the baseline: docs/performance-gate.md)\n";
  return 1;
}

}  // namespace hexrefine
