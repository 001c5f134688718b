// The start policies (algorithms/pipeline/smoothing_start.hpp) on hand-built values: starts in,
// the choice out; and on a small mesh, the pipeline keeps what the policy chooses from the
// starts it runs one by one.

#include "algorithms/pipeline/smoothing_start.hpp"

#include <gtest/gtest.h>

#include <limits>

#include "mesh/generators.hpp"
#include "mesh/quality.hpp"

namespace hexrefine {
namespace {

/// A start whose smoothing ended at `smoothed` (before any recovery) from a refined mesh at
/// `refined`; with `recovered`, the smoothed mesh's check found `recovered`.
SmoothingStart start_of(double refined, std::optional<double> smoothed,
                        std::optional<double> recovered = std::nullopt) {
  SmoothingStart s;
  s.check.min_scaled_jacobian = refined;
  if (smoothed) {
    s.smoothing.emplace();
    s.smoothing->min_scaled_jacobian_before = refined;
    s.smoothing->min_scaled_jacobian_after = *smoothed;
  }
  if (recovered) {
    s.smoothed_check.emplace();
    s.smoothed_check->min_scaled_jacobian = *recovered;
  }
  return s;
}

TEST(SmoothingStart, FallbackIsWantedOnlyBelowTheOptimizedPlacementUnsmoothed) {
  EXPECT_TRUE(smoothing_start_fallback_wanted(0.250317, 0.274948));
  EXPECT_FALSE(smoothing_start_fallback_wanted(0.274948, 0.274948));  // not below: kept
  EXPECT_FALSE(smoothing_start_fallback_wanted(0.5458, 0.1102));
  // No optimized placement to compare with (refused, or not a fallback case).
  EXPECT_FALSE(smoothing_start_fallback_wanted(-0.5, -std::numeric_limits<double>::infinity()));
}

TEST(SmoothingStart, FallbackKeepsTheOptimizedStartWhereWantedAndChecked) {
  const SmoothingStart untangle = start_of(0.0439, 0.250317);
  const SmoothingStart optimized = start_of(0.274948, 0.31);
  const SmoothingStartChoice choice =
      smoothing_start_choose_fallback(untangle, &optimized, 0.274948);
  EXPECT_TRUE(choice.optimized);
  EXPECT_EQ(choice.placement_warning,
            "smoothing from untangle reached 0.250317, below the 0.274948 of the optimized "
            "placement unsmoothed; placed by optimized and smoothed from there");
}

TEST(SmoothingStart, FallbackKeepsTheUntangleStartWhenTheOptimizedOneFailedOrIsNotWanted) {
  const SmoothingStart untangle = start_of(0.0439, 0.250317);
  const SmoothingStart optimized = start_of(0.274948, 0.31);
  // The optimized start failed a check (or was not made): the untangle start, silently.
  const SmoothingStartChoice failed = smoothing_start_choose_fallback(untangle, nullptr, 0.274948);
  EXPECT_FALSE(failed.optimized);
  EXPECT_EQ(failed.placement_warning, "");
  // Not below the optimized placement unsmoothed: kept whatever the optimized start reached.
  const SmoothingStartChoice above = smoothing_start_choose_fallback(untangle, &optimized, 0.2);
  EXPECT_FALSE(above.optimized);
  EXPECT_EQ(above.placement_warning, "");
}

TEST(SmoothingStart, BothStartsKeepTheHigherOutputMinimumUntangleOnATie) {
  const SmoothingStart untangle = start_of(0.0439, 0.2503, 0.2503);
  const SmoothingStart higher = start_of(0.2749, 0.2749, 0.2749);
  const SmoothingStart lower = start_of(0.11, 0.2, 0.2);
  const SmoothingStart tie = start_of(0.11, 0.2503, 0.2503);
  const SmoothingStartChoice kept_optimized = smoothing_start_choose_both(untangle, &higher, "");
  EXPECT_TRUE(kept_optimized.optimized);
  EXPECT_EQ(kept_optimized.placement_warning,
            "smoothed from both starts: 0.2749 from optimized, 0.2503 from untangle; kept "
            "optimized");
  EXPECT_FALSE(smoothing_start_choose_both(untangle, &lower, "").optimized);
  EXPECT_FALSE(smoothing_start_choose_both(untangle, &tie, "").optimized);
  EXPECT_EQ(smoothing_start_choose_both(untangle, &tie, "").placement_warning, "");
}

TEST(SmoothingStart, BothStartsCompareTheRecoveredMinimumNotTheSmoothingsOwn) {
  // The untangle start's smoothing reached 0.6 but its recovery undid it down to 0.3: the
  // optimized start's 0.4 is higher. Without a smoothing the refined mesh's check counts.
  const SmoothingStart untangle = start_of(0.1, 0.6, 0.3);
  const SmoothingStart optimized = start_of(0.2, 0.4, 0.4);
  EXPECT_EQ(smoothing_start_output_min(untangle), 0.3);
  EXPECT_EQ(smoothing_start_output_min(start_of(0.2, std::nullopt)), 0.2);
  EXPECT_TRUE(smoothing_start_choose_both(untangle, &optimized, "").optimized);
}

TEST(SmoothingStart, BothStartsKeepTheUntangleStartWhenTheOptimizedOneFailed) {
  const SmoothingStart untangle = start_of(0.0439, 0.2503, 0.2503);
  const SmoothingStartChoice failed =
      smoothing_start_choose_both(untangle, nullptr, "the sheet refiner left an invalid mesh");
  EXPECT_FALSE(failed.optimized);
  EXPECT_EQ(failed.placement_warning,
            "the optimized start failed (the sheet refiner left an invalid mesh); kept the "
            "untangle start");
  // Not made (the untangle start was refused and placed by optimized already): no warning.
  EXPECT_EQ(smoothing_start_choose_both(untangle, nullptr, "").placement_warning, "");
}

TEST(SmoothingStart, KeepTakesTheChosenStartWithItsPlacementAndWarning) {
  SmoothingStart untangle = start_of(0.0439, 0.2503);
  untangle.placement_warning = "the untangle start's own";
  SmoothingStart optimized = start_of(0.2749, 0.2749);
  const SmoothingStart kept_untangle = smoothing_start_keep({}, untangle, optimized);
  EXPECT_EQ(kept_untangle.check.min_scaled_jacobian, 0.0439);
  EXPECT_FALSE(kept_untangle.placement_used);
  EXPECT_EQ(kept_untangle.placement_warning, "the untangle start's own");
  const SmoothingStart kept_optimized = smoothing_start_keep({true, "why"}, untangle, optimized);
  EXPECT_EQ(kept_optimized.check.min_scaled_jacobian, 0.2749);
  ASSERT_TRUE(kept_optimized.placement_used);
  EXPECT_EQ(*kept_optimized.placement_used, PlacementMethod::optimized);
  EXPECT_EQ(kept_optimized.placement_warning, "why");
}

// A small mesh: a row of three targets in a jittered 3x3x3 brick, where the optimized start
// smoothed ends a little higher than the untangle one (both methods). The pipeline with both
// starts keeps what smoothing_start_choose_both picks from the two starts run one by one, and
// with the fallback what smoothing_start_choose_fallback picks.
TEST(SmoothingStart, ThePipelineKeepsWhatThePoliciesChooseOnASmallMesh) {
  BrickParams p;
  p.dims = {3, 3, 3};
  p.size = {3, 3, 3};
  p.jitter = 0.35;
  p.seed = 2;
  const HexMesh input = generate_brick(p);
  for (const char* method : {"selective", "sheet"}) {
    SCOPED_TRACE(method);
    PipelineOptions o;
    o.method = method;
    o.select = {"box:0,0,0,3,1,1"};
    o.smooth = true;
    o.refine.placement.method = PlacementMethod::untangle;
    o.smoothing_start_fallback = false;
    const PipelineResult untangle = pipeline_run(input, o);
    PipelineOptions optimized_options = o;
    optimized_options.refine.placement.method = PlacementMethod::optimized;
    const PipelineResult optimized = pipeline_run(input, optimized_options);
    ASSERT_TRUE(untangle.smoothing && optimized.smoothing);
    // The starts as the policies see them (smoothed at once: no recovery on a brick).
    auto value = [](const PipelineResult& r) {
      return start_of(r.check.min_scaled_jacobian, r.smoothing->min_scaled_jacobian_after,
                      r.smoothed_check->min_scaled_jacobian);
    };
    const SmoothingStart untangle_value = value(untangle), optimized_value = value(optimized);

    o.smoothing_both_starts = true;
    const PipelineResult both = pipeline_run(input, o);
    const SmoothingStartChoice both_choice =
        smoothing_start_choose_both(untangle_value, &optimized_value, "");
    EXPECT_TRUE(both_choice.optimized);  // the case the policy is here for
    EXPECT_EQ(both.placement_used.has_value(), both_choice.optimized);
    EXPECT_EQ(both.placement_warning, both_choice.placement_warning);
    EXPECT_EQ(both.mesh.points, (both_choice.optimized ? optimized : untangle).mesh.points);

    o.smoothing_both_starts = false;
    o.smoothing_start_fallback = true;
    const PipelineResult fallback = pipeline_run(input, o);
    PipelineOptions plain_options = optimized_options;
    plain_options.smooth = false;
    const double plain_min = mesh_min_scaled_jacobian(pipeline_run(input, plain_options).mesh);
    const SmoothingStartChoice fallback_choice =
        smoothing_start_choose_fallback(untangle_value, &optimized_value, plain_min);
    EXPECT_EQ(fallback.placement_used.has_value(), fallback_choice.optimized);
    EXPECT_EQ(fallback.placement_warning, fallback_choice.placement_warning);
    EXPECT_EQ(fallback.mesh.points, (fallback_choice.optimized ? optimized : untangle).mesh.points);
  }
}

}  // namespace
}  // namespace hexrefine
