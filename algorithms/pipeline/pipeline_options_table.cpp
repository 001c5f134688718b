#include "algorithms/pipeline/pipeline_options_table.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "mesh/error.hpp"

namespace hexrefine {

namespace {

using json = nlohmann::json;

/// The rows. Their order is the CLI's help order; each `set` touches only its own fields, so the
/// order in which given options are set does not matter.
/// Length: it is the table, one initializer per row; split, it would no longer read as one.
std::vector<PipelineOptionRow> rows_build() {
  using T = PipelineOptionType;
  return {
      {.key = "passes",
       .type = T::integer,
       .default_value = 1,
       .placeholder = "N",
       .help = "how many times the region is refined",
       .min = 1,
       .max = 10,
       .set = [](PipelineOptions& o, const json& v) { o.refine.passes = v.get<int>(); }},
      {.key = "buffer",
       .type = T::choice,
       .default_value = "layer",
       .placeholder = "RULE",
       .help = "selective, {passes} > 1: what joins each pass's targets: layer (one layer around "
               "the targets, the thesis' H-2), transitions (every transition's children, "
               "cumulative) or none",
       .off_help = "ablation: no buffer",
       .off_value = "none",
       .values = {"layer", "transitions", "none"},
       .set = [](PipelineOptions& o,
                 const json& v) { o.refine.buffer = pass_buffer_from_name(v.get<std::string>()); }},
      {.key = "placement",
       .type = T::choice,
       .default_text = "untangle with {smooth}, else optimized",
       .placeholder = "P",
       .help = "new nodes: trilinear (the thesis' positions), reference (the templates' reference "
               "positions, best on the unit cube, at trilinear's cost), optimized (reference, then "
               "raise the worst scaled Jacobian where a child is still poor) or untangle "
               "(trilinear, inverted children untangled: the better start for {smooth})",
       .values = {"trilinear", "reference", "optimized", "untangle"},
       .set = [](PipelineOptions& o,
                 const json& v) { o.refine.placement.method = v.get<PlacementMethod>(); }},
      {.key = "smooth",
       .type = T::flag,
       .default_value = false,
       .help = "smooth the refined region afterwards (checked again; starts from untangle unless "
               "a placement is given, and from optimized where untangle ends below plain "
               "refine's minimum, with a warning; a smoothing the checker rejects is undone, with "
               "a warning in the report)",
       .set = [](PipelineOptions& o, const json& v) { o.smooth = v.get<bool>(); }},
      {.key = "smooth_both_starts",
       .type = T::flag,
       .default_value = false,
       .help = "{smooth}: place by untangle and by optimized, smooth both, keep the higher "
               "minimum (about twice the time; results/smoothing_starts.md)",
       .needs = {{"smooth", true, ""},
                 {"placement", "untangle", "it smooths from untangle and from optimized itself"}},
       .set = [](PipelineOptions& o, const json& v) { o.smoothing_both_starts = v.get<bool>(); }},
      // The smoothing's budget: fewer sweeps and joint iterations trade quality for time
      // (results/smoothing_budget.md measures the trade on the real-mesh study).
      {.key = "smooth_sweeps",
       .type = T::integer,
       .default_value = 20,
       .placeholder = "N",
       .help = "{smooth}: at most this many sweeps over the region's nodes before the joint "
               "ascent and after each of its rounds",
       .default_note = "fewer: faster, lower minimum",
       .min = 1,
       .max = 1000000,
       .needs = {{"smooth", true, ""}},
       .set = [](PipelineOptions& o, const json& v) { o.smoothing.max_sweeps = v.get<int>(); }},
      {.key = "smooth_joint_iterations",
       .type = T::integer,
       .default_value = 1000,
       .placeholder = "N",
       .help = "{smooth}: at most this many iterations per round of the joint ascent of the nodes "
               "around the worst hexes (boundary nodes on the surface)",
       .default_note = "0: the sweeps alone",
       .min = 0,
       .max = 1000000,
       .needs = {{"smooth", true, ""}},
       .set = [](PipelineOptions& o,
                 const json& v) { o.smoothing.joint_iterations = v.get<int>(); }},
      {.key = "smooth_joint_rounds",
       .type = T::integer,
       .default_value = 3,
       .placeholder = "N",
       .help = "{smooth}: at most this many rounds of joint ascent and sweeps, each with a "
               "sharper soft minimum, while a round raises the minimum",
       .min = 1,
       .max = 1000,
       .needs = {{"smooth", true, ""}},
       .set = [](PipelineOptions& o, const json& v) { o.smoothing.joint_rounds = v.get<int>(); }},
      // One cap for both: what the placement keeps under it the smoothing must not undo.
      {.key = "max_edge_ratio",
       .type = T::real,
       .default_value = 20.0,
       .placeholder = "R",
       .help = "optimized placement and {smooth} give no hex an edge ratio above this or its "
               "ratio before",
       .default_note = "0: no cap, the scaled Jacobian alone",
       .min = 1,
       .max = 1e6,
       .zero_allowed = true,
       .set =
           [](PipelineOptions& o, const json& v) {
             o.refine.placement.max_edge_ratio = v.get<double>();
             o.smoothing.max_edge_ratio = v.get<double>();
           }},
      {.key = "ranking",
       .type = T::flag,
       .default_value = true,
       .help = "selective: its ranking system (off: an ablation)",
       .off_help = "ablation: selective without its ranking system",
       .set = [](PipelineOptions& o, const json& v) { o.refine.ranking = v.get<bool>(); }},
      {.key = "directional_order",
       .type = T::choice,
       .default_value = "by_hex",
       .placeholder = "ORDER",
       .help = "selective: by_hex (the thesis' hex after hex) or by_rank (a rank per step)",
       .values = {"by_hex", "by_rank"},
       .set = [](PipelineOptions& o,
                 const json& v) { o.refine.directional_order = v.get<DirectionalOrder>(); }},
      {.key = "propagation",
       .type = T::flag,
       .default_value = true,
       .help = "selective: its propagation scheme (off: an ablation)",
       .off_help = "ablation: selective without its propagation scheme",
       .set = [](PipelineOptions& o, const json& v) { o.refine.propagation = v.get<bool>(); }},
      {.key = "ebe_only",
       .type = T::flag,
       .default_value = false,
       .help = "ablation: element-by-element templates only",
       .set = [](PipelineOptions& o, const json& v) { o.refine.ebe_only = v.get<bool>(); }},
      {.key = "allow_inverted",
       .type = T::flag,
       .default_value = false,
       .help = "refine an input with inverted hexes (no refusal, no verdict)",
       .set = [](PipelineOptions& o, const json& v) { o.refine.allow_inverted = v.get<bool>(); }},
      {.key = "max_hexes",
       .type = T::integer,
       .default_value = int64_t{2147483647},
       .default_text = "2^31-1",
       .placeholder = "N",
       .help = "refuse before refining when n input hexes * 27^passes could exceed this",
       .min = 1,
       .max = 2147483647,
       .set = [](PipelineOptions& o, const json& v) { o.max_hexes = v.get<int64_t>(); }},
  };
}

/// A bound as the help writes it: an integer option's in full, a real's 1e6 as "1e6".
std::string bound_text(double v, bool integer) {
  if (integer || (v == std::floor(v) && std::fabs(v) < 1e6))
    return std::to_string(static_cast<int64_t>(v));
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  std::string s = text;
  const size_t plus = s.find("e+");
  if (plus != std::string::npos) {
    s.erase(plus + 1, 1);
    while (s.size() > plus + 2 && s[plus + 1] == '0') s.erase(plus + 1, 1);
  }
  return s;
}

/// "1..10", "0 or 1..1e6".
std::string range_text(const PipelineOptionRow& row) {
  const bool integer = row.type == PipelineOptionType::integer;
  return (row.zero_allowed ? "0 or " : "") + bound_text(row.min, integer) + ".." +
         bound_text(row.max, integer);
}

/// "a, b or c".
std::string values_text(const PipelineOptionRow& row) {
  std::string s;
  for (size_t i = 0; i < row.values.size(); ++i)
    s += (i == 0 ? "" : i + 1 == row.values.size() ? " or " : ", ") + std::string(row.values[i]);
  return s;
}

[[noreturn]] void row_fail(const PipelineOptionRow& row, const PipelineOptionSpelling& spelling,
                           const std::string& what) {
  throw InputError(spelling.subject(row.key) + spelling.separator() + what);
}

/// The value's check against its row (see pipeline_options_set).
void value_check(const PipelineOptionRow& row, const json& v,
                 const PipelineOptionSpelling& spelling) {
  const std::string got = ", got " + spelling.value(v);
  switch (row.type) {
    case PipelineOptionType::flag:
      if (!v.is_boolean()) row_fail(row, spelling, "must be true or false" + got);
      return;
    case PipelineOptionType::integer:
      if (!v.is_number_integer()) row_fail(row, spelling, "must be an integer" + got);
      if (v.get<double>() < row.min || v.get<double>() > row.max)
        row_fail(row, spelling, "must be in " + range_text(row) + got);
      return;
    case PipelineOptionType::real: {
      if (!v.is_number() || !std::isfinite(v.get<double>()))
        row_fail(row, spelling, "must be a finite number" + got);
      const double x = v.get<double>();
      if (!((row.zero_allowed && x == 0) || (x >= row.min && x <= row.max)))
        row_fail(row, spelling,
                 "must be " + std::string(row.zero_allowed ? "0 or in " : "in ") +
                     bound_text(row.min, false) + ".." + bound_text(row.max, false) + got);
      return;
    }
    case PipelineOptionType::choice: {
      if (v.is_string()) {
        const std::string s = v.get<std::string>();
        if (std::find(row.values.begin(), row.values.end(), s) != row.values.end()) return;
        // The spelling of values is the JSON's: a CLI user's `by-rank` is told the one meant.
        std::string underscored = s;
        std::replace(underscored.begin(), underscored.end(), '-', '_');
        if (std::find(row.values.begin(), row.values.end(), underscored) != row.values.end())
          row_fail(row, spelling,
                   "must be " + values_text(row) + got + " (did you mean " + underscored +
                       "? values are spelt with '_')");
      }
      row_fail(row, spelling, "must be " + values_text(row) + got);
    }
  }
}

}  // namespace

std::string pipeline_option_key_closest(std::string_view key) {
  std::string best;
  size_t best_distance = std::max<size_t>(2, key.size() / 3) + 1;
  for (const PipelineOptionRow& row : pipeline_option_rows()) {
    const std::string_view k = row.key;
    std::vector<size_t> d(k.size() + 1);
    for (size_t j = 0; j <= k.size(); ++j) d[j] = j;
    for (size_t i = 1; i <= key.size(); ++i) {
      size_t diagonal = d[0];
      d[0] = i;
      for (size_t j = 1; j <= k.size(); ++j) {
        const size_t above = d[j];
        d[j] = std::min({d[j] + 1, d[j - 1] + 1, diagonal + (key[i - 1] == k[j - 1] ? 0 : 1)});
        diagonal = above;
      }
    }
    if (d[k.size()] < best_distance) {
      best_distance = d[k.size()];
      best = k;
    }
  }
  return best;
}

namespace {

/// Every given key is a row's; values checked in the table's order.
void settings_check_values(const json& settings, const PipelineOptionSpelling& spelling) {
  if (!settings.is_object()) throw InputError("pipeline options: expected an object");
  for (const auto& [key, value] : settings.items())
    if (!pipeline_option_row(key)) {
      const std::string near = pipeline_option_key_closest(key);
      throw InputError(spelling.subject(key) + spelling.separator() + "is not an option" +
                       (near.empty() ? "" : " (did you mean " + spelling.name(near) + "?)"));
    }
  for (const PipelineOptionRow& row : pipeline_option_rows()) {
    const auto it = settings.find(row.key);
    if (it != settings.end() && !it->is_null()) value_check(row, *it, spelling);
  }
}

/// Each set option's needs against the resolved settings.
void settings_check_needs(const json& settings, const PipelineOptionSpelling& spelling) {
  const json resolved = pipeline_settings_resolved(settings);
  for (const PipelineOptionRow& row : pipeline_option_rows()) {
    const auto it = settings.find(row.key);
    if (it == settings.end() || it->is_null() || (it->is_boolean() && !it->get<bool>())) continue;
    for (const PipelineOptionNeed& need : row.needs) {
      const json& has = resolved.at(need.key);
      if (has == need.value) continue;
      const bool need_flag = pipeline_option_row(need.key)->type == PipelineOptionType::flag;
      row_fail(row, spelling,
               "needs " + spelling.setting(need.key, need.value) +
                   (need_flag ? "" : ", got " + spelling.setting(need.key, has)) +
                   (need.why.empty() ? "" : " (" + std::string(need.why) + ")") +
                   spelling.context());
    }
  }
}

}  // namespace

const std::vector<PipelineOptionRow>& pipeline_option_rows() {
  static const std::vector<PipelineOptionRow> rows = rows_build();
  return rows;
}

const PipelineOptionRow* pipeline_option_row(std::string_view key) {
  for (const PipelineOptionRow& row : pipeline_option_rows())
    if (row.key == key) return &row;
  return nullptr;
}

std::string PipelineOptionSpelling::name(std::string_view key) const {
  return std::string(key);
}

std::string PipelineOptionSpelling::subject(std::string_view key) const {
  return name(key);
}

std::string PipelineOptionSpelling::separator() const {
  return " ";
}

std::string PipelineOptionSpelling::setting(std::string_view key, const json& value) const {
  return name(key) + "=" + value.dump();
}

std::string PipelineOptionSpelling::value(const json& value) const {
  return value.dump();
}

std::string PipelineOptionSpelling::context() const {
  return "";
}

json pipeline_option_value_from_text(const PipelineOptionRow& row, const std::string& text,
                                     const PipelineOptionSpelling& spelling) {
  switch (row.type) {
    case PipelineOptionType::integer: {
      errno = 0;
      char* end = nullptr;
      const long long v = std::strtoll(text.c_str(), &end, 10);
      if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE)
        row_fail(row, spelling, "must be an integer, got " + spelling.value(text));
      return v;
    }
    case PipelineOptionType::real: {
      errno = 0;
      char* end = nullptr;
      const double v = std::strtod(text.c_str(), &end);
      if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE || !std::isfinite(v))
        row_fail(row, spelling, "must be a finite number, got " + spelling.value(text));
      return v;
    }
    case PipelineOptionType::choice:
      return text;
    case PipelineOptionType::flag:
      break;
  }
  throw InputError(spelling.subject(row.key) + " takes no value");
}

json pipeline_settings_resolved(const json& settings) {
  json resolved = json::object();
  for (const PipelineOptionRow& row : pipeline_option_rows()) {
    const auto it = settings.find(row.key);
    resolved[row.key] = it != settings.end() && !it->is_null() ? *it : row.default_value;
  }
  // The one default that depends on another option.
  if (resolved["placement"].is_null())
    resolved["placement"] = pipeline_default_placement(resolved["smooth"].get<bool>());
  return resolved;
}

void pipeline_options_set(PipelineOptions& options, const json& settings,
                          const PipelineOptionSpelling& spelling) {
  settings_check_values(settings, spelling);
  settings_check_needs(settings, spelling);
  for (const PipelineOptionRow& row : pipeline_option_rows()) {
    const auto it = settings.find(row.key);
    if (it != settings.end() && !it->is_null()) row.set(options, *it);
  }
  const auto placement = settings.find("placement");
  if (placement == settings.end() || placement->is_null())
    options.refine.placement.method = pipeline_default_placement(options.smooth);
}

std::string pipeline_option_text_spelt(std::string_view text,
                                       const PipelineOptionSpelling& spelling) {
  std::string out;
  size_t i = 0;
  while (i < text.size()) {
    const size_t open = text.find('{', i);
    const size_t close = open == std::string_view::npos ? open : text.find('}', open);
    if (close == std::string_view::npos) break;
    const std::string_view key = text.substr(open + 1, close - open - 1);
    const PipelineOptionRow* row = pipeline_option_row(key);
    out += text.substr(i, open - i);
    if (!row)
      out += text.substr(open, close - open + 1);
    else if (row->type == PipelineOptionType::flag)
      out += spelling.setting(key, true);
    else
      out += spelling.name(key);
    i = close + 1;
  }
  out += text.substr(std::min(i, text.size()));
  return out;
}

std::string pipeline_option_help_text(const PipelineOptionRow& row,
                                      const PipelineOptionSpelling& spelling) {
  std::string s(row.help);
  if (row.type == PipelineOptionType::integer || row.type == PipelineOptionType::real)
    s += ", " + range_text(row);
  if (row.type != PipelineOptionType::flag) {
    std::string d(row.default_text);
    if (d.empty())
      d = row.default_value.is_string() ? row.default_value.get<std::string>()
          : row.default_value.is_number()
              ? bound_text(row.default_value.get<double>(), row.type == PipelineOptionType::integer)
              : row.default_value.dump();
    s += " (default " + d + (row.default_note.empty() ? "" : "; " + std::string(row.default_note)) +
         ")";
  }
  return pipeline_option_text_spelt(s, spelling);
}

}  // namespace hexrefine
