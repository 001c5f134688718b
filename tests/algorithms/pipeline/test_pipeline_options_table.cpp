#include "algorithms/pipeline/pipeline_options_table.hpp"

#include <gtest/gtest.h>

#include <set>
#include <string>

#include "mesh/error.hpp"

namespace hexrefine {
namespace {

using json = nlohmann::json;

/// The PipelineOptions fields the table sets, as one comparable object.
json options_fingerprint(const PipelineOptions& o) {
  return json{{"refine", o.refine},
              {"smooth", o.smooth},
              {"smoothing",
               {o.smoothing.max_sweeps, o.smoothing.joint_iterations, o.smoothing.joint_rounds,
                o.smoothing.max_edge_ratio, o.smoothing.layers}},
              {"smoothing_both_starts", o.smoothing_both_starts},
              {"max_hexes", o.max_hexes}};
}

/// The settings that satisfy `row`'s needs ({"smooth": true, ...}).
json needs_of(const PipelineOptionRow& row) {
  json settings = json::object();
  for (const PipelineOptionNeed& need : row.needs) settings[std::string(need.key)] = need.value;
  return settings;
}

PipelineOptions options_of(const json& settings) {
  PipelineOptions o;
  pipeline_options_set(o, settings, PipelineOptionSpelling());
  return o;
}

/// The message of the InputError `settings` give ("" if none).
std::string error_of(const json& settings) {
  try {
    options_of(settings);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(PipelineOptionsTable, RowsAreCompleteAndTheirDefaultsPassTheirChecks) {
  std::set<std::string> keys;
  for (const PipelineOptionRow& row : pipeline_option_rows()) {
    SCOPED_TRACE(std::string(row.key));
    EXPECT_TRUE(keys.insert(std::string(row.key)).second);
    EXPECT_EQ(std::string(row.key).find_first_not_of("abcdefghijklmnopqrstuvwxyz_"),
              std::string::npos);
    EXPECT_NE(row.set, nullptr);
    EXPECT_FALSE(row.help.empty());
    EXPECT_EQ(row.type == PipelineOptionType::flag, row.placeholder.empty());
    EXPECT_EQ(row.type == PipelineOptionType::choice, !row.values.empty());
    // A default is a value (or, null, said in words) and passes the row's own check.
    EXPECT_TRUE(!row.default_value.is_null() || !row.default_text.empty());
    json with_needs = needs_of(row);
    with_needs[std::string(row.key)] = row.default_value;
    if (!row.default_value.is_null()) {
      EXPECT_EQ(error_of(with_needs), "");
    }
    for (const PipelineOptionNeed& need : row.needs)
      EXPECT_NE(pipeline_option_row(need.key), nullptr) << need.key;
    if (!row.off_value.empty()) {
      EXPECT_EQ(error_of({{row.key, row.off_value}}), "");
    }
  }
  EXPECT_EQ(pipeline_option_row("no_such_option"), nullptr);
}

TEST(PipelineOptionsTable, DefaultsGiveThePipelinesOwnDefaults) {
  // Nothing given: PipelineOptions' defaults, the placement by pipeline_default_placement.
  const json none = options_fingerprint(options_of(json::object()));
  PipelineOptions plain;
  plain.refine.placement.method = pipeline_default_placement(false);
  EXPECT_EQ(none, options_fingerprint(plain));
  // Each default given explicitly changes nothing (beside what its needs set).
  for (const PipelineOptionRow& row : pipeline_option_rows()) {
    if (row.default_value.is_null()) continue;
    json with_default = needs_of(row);
    with_default[std::string(row.key)] = row.default_value;
    EXPECT_EQ(options_fingerprint(options_of(with_default)),
              options_fingerprint(options_of(needs_of(row))))
        << row.key;
  }
  // null is "not given".
  EXPECT_EQ(options_fingerprint(options_of({{"passes", nullptr}, {"placement", nullptr}})), none);
  // The placement's default follows smooth.
  EXPECT_EQ(options_of({{"smooth", true}}).refine.placement.method, PlacementMethod::untangle);
  EXPECT_EQ(pipeline_settings_resolved({{"smooth", true}})["placement"], "untangle");
  EXPECT_EQ(pipeline_settings_resolved(json::object())["placement"], "optimized");
}

TEST(PipelineOptionsTable, EachRowSetsItsFields) {
  const PipelineOptions o = options_of({{"passes", 3},
                                        {"buffer", "transitions"},
                                        {"placement", "untangle"},
                                        {"smooth", true},
                                        {"smooth_both_starts", true},
                                        {"smooth_sweeps", 7},
                                        {"smooth_joint_iterations", 0},
                                        {"smooth_joint_rounds", 2},
                                        {"max_edge_ratio", 0},
                                        {"ranking", false},
                                        {"directional_order", "by_rank"},
                                        {"propagation", false},
                                        {"ebe_only", true},
                                        {"allow_inverted", true},
                                        {"max_hexes", 1000}});
  EXPECT_EQ(o.refine.passes, 3);
  EXPECT_EQ(o.refine.buffer, PassBuffer::transitions);
  EXPECT_EQ(o.refine.placement.method, PlacementMethod::untangle);
  EXPECT_TRUE(o.smooth);
  EXPECT_TRUE(o.smoothing_both_starts);
  EXPECT_EQ(o.smoothing.max_sweeps, 7);
  EXPECT_EQ(o.smoothing.joint_iterations, 0);
  EXPECT_EQ(o.smoothing.joint_rounds, 2);
  EXPECT_EQ(o.refine.placement.max_edge_ratio, 0);
  EXPECT_EQ(o.smoothing.max_edge_ratio, 0);
  EXPECT_FALSE(o.refine.ranking);
  EXPECT_EQ(o.refine.directional_order, DirectionalOrder::by_rank);
  EXPECT_FALSE(o.refine.propagation);
  EXPECT_TRUE(o.refine.ebe_only);
  EXPECT_TRUE(o.refine.allow_inverted);
  EXPECT_EQ(o.max_hexes, 1000);
  // Fields of no row are left alone.
  EXPECT_EQ(o.method, "selective");
  EXPECT_EQ(o.refine.threads, 1);
  EXPECT_EQ(o.smoothing.layers, 2);
  // Every row was given above.
  EXPECT_EQ(pipeline_option_rows().size(), 15u);
}

TEST(PipelineOptionsTable, EachRowRejectsABadValueNamingTheOption) {
  for (const PipelineOptionRow& row : pipeline_option_rows()) {
    SCOPED_TRACE(std::string(row.key));
    std::vector<json> bad;
    switch (row.type) {
      case PipelineOptionType::flag:
        bad = {1, "yes"};
        break;
      case PipelineOptionType::integer:
        bad = {row.min - 1, row.max + 1, 1.5, "2", true};
        break;
      case PipelineOptionType::real:
        bad = {row.min - 0.5, row.max * 2, "x", false};
        break;
      case PipelineOptionType::choice:
        bad = {"nonsense", 1};
        break;
    }
    for (const json& value : bad) {
      const std::string e = error_of({{row.key, value}});
      EXPECT_EQ(e.rfind(std::string(row.key) + " must be ", 0), 0u) << value << ": " << e;
      EXPECT_NE(e.find("got " + value.dump()), std::string::npos) << e;
    }
  }
  EXPECT_EQ(error_of({{"passes", 11}}), "passes must be in 1..10, got 11");
  EXPECT_EQ(error_of({{"max_edge_ratio", 0.5}}), "max_edge_ratio must be 0 or in 1..1e6, got 0.5");
  EXPECT_EQ(error_of({{"placement", "random"}}),
            "placement must be trilinear, reference, optimized or untangle, got \"random\"");
}

TEST(PipelineOptionsTable, ValuesAreSpeltWithUnderscoresAndTheDashedOneIsToldSo) {
  EXPECT_EQ(error_of({{"directional_order", "by-rank"}}),
            "directional_order must be by_hex or by_rank, got \"by-rank\" (did you mean by_rank? "
            "values are spelt with '_')");
  EXPECT_EQ(options_of({{"directional_order", "by_rank"}}).refine.directional_order,
            DirectionalOrder::by_rank);
}

TEST(PipelineOptionsTable, NeedsAreCheckedAgainstTheResolvedSettings) {
  for (const char* key : {"smooth_sweeps", "smooth_joint_iterations", "smooth_joint_rounds"}) {
    EXPECT_EQ(error_of({{key, 2}}), std::string(key) + " needs smooth=true");
    EXPECT_EQ(error_of({{key, 2}, {"smooth", false}}), std::string(key) + " needs smooth=true");
    EXPECT_EQ(error_of({{key, 2}, {"smooth", true}}), "");
  }
  EXPECT_EQ(error_of({{"smooth_both_starts", true}}), "smooth_both_starts needs smooth=true");
  // Off is not set: it needs nothing.
  EXPECT_EQ(error_of({{"smooth_both_starts", false}}), "");
  // The placement resolves to untangle with smooth; a placement given must be untangle.
  EXPECT_EQ(error_of({{"smooth_both_starts", true}, {"smooth", true}}), "");
  EXPECT_EQ(error_of({{"smooth_both_starts", true}, {"smooth", true}, {"placement", "untangle"}}),
            "");
  EXPECT_EQ(error_of({{"smooth_both_starts", true}, {"smooth", true}, {"placement", "optimized"}}),
            "smooth_both_starts needs placement=\"untangle\", got placement=\"optimized\" (it "
            "smooths from untangle and from optimized itself)");
  // Each value is checked before any need.
  EXPECT_EQ(error_of({{"smooth_sweeps", 0}}), "smooth_sweeps must be in 1..1000000, got 0");
}

TEST(PipelineOptionsTable, UnknownKeysAreNamedWithTheOneMeant) {
  EXPECT_EQ(error_of({{"smooth_sweep", 2}}),
            "smooth_sweep is not an option (did you mean smooth_sweeps?)");
  EXPECT_EQ(error_of({{"colour", 2}}), "colour is not an option");
  EXPECT_THROW(options_of(json::array()), InputError);
}

/// A front end's spelling, as the CLI's: --key, values quoted as text.
class DashedSpelling : public PipelineOptionSpelling {
 public:
  std::string name(std::string_view key) const override {
    std::string s(key);
    for (char& c : s)
      if (c == '_') c = '-';
    return "--" + s;
  }
  std::string subject(std::string_view key) const override { return "cmd: " + name(key); }
  std::string setting(std::string_view key, const json& v) const override {
    return v.is_boolean() ? name(key) : name(key) + " " + v.get<std::string>();
  }
  std::string value(const json& v) const override {
    return "'" + (v.is_string() ? v.get<std::string>() : v.dump()) + "'";
  }
  std::string context() const override { return " (here)"; }
};

TEST(PipelineOptionsTable, FrontEndsSpellMessagesAndHelp) {
  const DashedSpelling cli;
  const PipelineOptionRow& sweeps = *pipeline_option_row("smooth_sweeps");
  EXPECT_EQ(pipeline_option_value_from_text(sweeps, "12", cli), 12);
  try {
    pipeline_option_value_from_text(sweeps, "x", cli);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "cmd: --smooth-sweeps must be an integer, got 'x'");
  }
  const PipelineOptionRow& ratio = *pipeline_option_row("max_edge_ratio");
  EXPECT_EQ(pipeline_option_value_from_text(ratio, "1e6", cli), 1e6);
  EXPECT_THROW(pipeline_option_value_from_text(ratio, "inf", cli), InputError);
  EXPECT_EQ(pipeline_option_value_from_text(*pipeline_option_row("buffer"), "none", cli), "none");
  PipelineOptions o;
  try {
    pipeline_options_set(o, {{"smooth_sweeps", 3}}, cli);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "cmd: --smooth-sweeps needs --smooth (here)");
  }
  EXPECT_EQ(pipeline_option_help_text(sweeps, cli),
            "--smooth: at most this many sweeps over the region's nodes before the joint ascent "
            "and after each of its rounds, 1..1000000 (default 20; fewer: faster, lower "
            "minimum)");
  EXPECT_EQ(pipeline_option_help_text(*pipeline_option_row("placement"), cli).substr(0, 10),
            "new nodes:");
  EXPECT_NE(pipeline_option_help_text(*pipeline_option_row("placement"), cli)
                .find("(default untangle with --smooth, else optimized)"),
            std::string::npos);
  EXPECT_EQ(pipeline_option_help_text(ratio, PipelineOptionSpelling()),
            "optimized placement and smooth=true give no hex an edge ratio above this or its "
            "ratio before, 0 or 1..1e6 (default 20; 0: no cap, the scaled Jacobian alone)");
  EXPECT_EQ(pipeline_option_text_spelt("{passes} and {nothing}", cli), "--passes and {nothing}");
}

}  // namespace
}  // namespace hexrefine
