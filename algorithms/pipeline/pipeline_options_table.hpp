#pragma once
/// \file
/// The pipeline's options, declared once: one row per option (its key, type, default, help,
/// check and how it sets PipelineOptions), from which every front end derives its own spelling:
/// the CLI's `refine` flags and help lines (experiments/cli/cli_refine.cpp), the keywords of the
/// Python `hexrefine.refine` (experiments/python/module.cpp, hexrefine/__init__.py) and the keys
/// of a case file (experiments/runner/runner_plan.cpp). A front end turns what it was given into
/// *settings*, one JSON object {key: value}, and pipeline_options_set checks and applies them, so
/// a check or a default is written here and nowhere else.
///
/// Spellings, chosen once:
/// - A key is snake_case (`max_edge_ratio`); the CLI writes it with `-` for `_`
///   (`--max-edge-ratio`), a flag that is on by default as its negation (`--no-ranking`), and a
///   choice with an off value also as a negation (`--no-buffer` = `--buffer none`).
/// - A value is spelt as the report and the case files write it (the JSON of the enums):
///   `by_rank`, `by_hex`, never `by-rank`. The CLI once spelt the directional order `by-rank` and
///   `by-hex`; that spelling is refused (exit 2) with the one meant (docs/cli.md).
///
/// Not in the table, because each front end has its own shape for them: what is refined (the
/// CLI's --method and --select, Python's `method` and `targets`, a case's "methods" list and
/// "select") and `threads` (the output is the same for any count; the CLI uses every core, as
/// all its commands, Python one thread, the runner one thread per case).
///
/// Values as settings: a flag is a JSON boolean, an integer a JSON integer, a real any JSON
/// number, a choice a string; null stands for "not given". The CLI's text values become settings
/// through pipeline_option_value_from_text.

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "algorithms/pipeline/pipeline.hpp"

namespace hexrefine {

enum class PipelineOptionType {
  flag,     ///< on or off (a JSON boolean)
  integer,  ///< an integer in [min, max]
  real,     ///< a finite number in [min, max], or 0 where zero_allowed
  choice,   ///< one of `values`
};

/// What an option needs of another when it is set (given, and for a flag: true): `key` must
/// resolve (given or by default) to `value`; `why` (may be empty) says why, in the message.
struct PipelineOptionNeed {
  std::string_view key;
  nlohmann::json value;
  std::string_view why;
};

/// One option. Help texts may name another option as `{key}`: each front end writes it in its
/// own spelling (pipeline_option_help_text).
struct PipelineOptionRow {
  std::string_view key{};  ///< snake_case, unique
  PipelineOptionType type = PipelineOptionType::flag;
  /// The value when not given; null where it depends on other options (default_text says how).
  nlohmann::json default_value{};
  std::string_view default_text{};  ///< the default in words where default_value is null
  std::string_view placeholder{};   ///< the CLI's name of the value ("N", "R"); empty for a flag
  std::string_view help{};          ///< one line: meaning (range and default are added)
  /// The note after the default ("0: no cap"), may be empty.
  std::string_view default_note{};
  /// A flag on by default, or a choice with an off_value: the help of its negation (the CLI's
  /// `--no-KEY`), which sets false or off_value.
  std::string_view off_help{};
  std::string_view off_value{};  ///< choice: the value the negation sets ("none"); else empty
  double min = 0, max = 0;       ///< integer, real: the range, inclusive
  bool zero_allowed = false;     ///< real: 0 is allowed besides [min, max] (an off value)
  std::vector<std::string_view> values{};  ///< choice: the values allowed, in the help's order
  std::vector<PipelineOptionNeed> needs{};
  /// Sets the PipelineOptions field(s) of this option from a checked value.
  void (*set)(PipelineOptions& options, const nlohmann::json& value) = nullptr;
};

/// Every option, in the order of the CLI's help.
const std::vector<PipelineOptionRow>& pipeline_option_rows();

/// The row of `key`, or nullptr.
const PipelineOptionRow* pipeline_option_row(std::string_view key);

/// The key meant by an unknown `key` (the row key at the least edit distance, at most a third
/// of its length and at least 2), or "".
std::string pipeline_option_key_closest(std::string_view key);

/// How a front end names options, settings and values in messages and help. The base class is
/// the table's own spelling (keys as they are, values as JSON): what the table's tests use.
class PipelineOptionSpelling {
 public:
  virtual ~PipelineOptionSpelling() = default;
  /// The option as the front end writes it: "--smooth-sweeps", "smooth_sweeps".
  virtual std::string name(std::string_view key) const;
  /// The option as the subject of a message: "hexrefine refine: --passes", "cases.json:
  /// /cases/2/passes". Default: name(key).
  virtual std::string subject(std::string_view key) const;
  /// Between the subject and the rest of a message: " " ("--passes must be ...") or ": "
  /// ("/cases/2/passes: must be ...").
  virtual std::string separator() const;
  /// An option set to a value: "--smooth", "--placement untangle", "smooth=True", "\"smooth\":
  /// true". Default: key=JSON.
  virtual std::string setting(std::string_view key, const nlohmann::json& value) const;
  /// A value as given, after "got": "'0'" on the CLI (its text), the JSON elsewhere.
  virtual std::string value(const nlohmann::json& value) const;
  /// Appended to a message about two options (a need): e.g. the case the options belong to.
  virtual std::string context() const;
};

/// The CLI's text of a value of `row` as a setting: an integer, a finite number or the text of a
/// choice (checked by pipeline_options_set). InputError "SUBJECT must be an integer, got
/// 'text'" where it is no number. Not for flags (a flag's setting is true or false).
nlohmann::json pipeline_option_value_from_text(const PipelineOptionRow& row,
                                               const std::string& text,
                                               const PipelineOptionSpelling& spelling);

/// Checks `settings` (a JSON object {key: value}; null values are not given) and sets
/// `options`: each value against its row (type, range, allowed values; InputError
/// "SUBJECT must be in 1..10, got 0", "SUBJECT must be by_rank or by_hex, got 'by-rank' (did you
/// mean by_rank?)"), in the table's order; then each set option's needs against the settings
/// with the defaults filled in ("SUBJECT needs --smooth"); then every given option's fields,
/// and the placement's default (pipeline_default_placement) where none is given. An unknown key
/// is an InputError naming it (and the key meant, when one is close). Fields of no row (method,
/// select, targets, threads, ...) are left as they are. The result for {} is PipelineOptions'
/// own defaults but for the placement, which is pipeline_default_placement(false).
void pipeline_options_set(PipelineOptions& options, const nlohmann::json& settings,
                          const PipelineOptionSpelling& spelling);

/// `settings` with every row's default filled in where a key is absent or null (the placement's
/// from "smooth"): what the needs are checked against.
nlohmann::json pipeline_settings_resolved(const nlohmann::json& settings);

/// The row's help line in `spelling`: help with {key} references spelt, then the range
/// ("1..10"), the values (choices) and the default ("(default 20; 0: no cap)").
std::string pipeline_option_help_text(const PipelineOptionRow& row,
                                      const PipelineOptionSpelling& spelling);

/// A help or message text with every `{key}` spelt by `spelling`: a flag as the setting that
/// turns it on (spelling.setting(key, true)), any other option by its name.
std::string pipeline_option_text_spelt(std::string_view text,
                                       const PipelineOptionSpelling& spelling);

}  // namespace hexrefine
