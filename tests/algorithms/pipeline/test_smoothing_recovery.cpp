// The smoothing recovery's decisions and undo steps (algorithms/pipeline/smoothing_recovery.hpp)
// on hand-built values and a small brick.

#include "algorithms/pipeline/smoothing_recovery.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "mesh/generators.hpp"
#include "mesh/quality.hpp"

namespace hexrefine {
namespace {

using Step = SmoothingRecoveryStep;

/// The steps the recovery takes when every check rejects the smoothed mesh, as its loop takes
/// them (a pinned smoothing starts the undo rounds again), until it accepts or fails.
std::vector<Step> steps_while_rejected(int pin_rounds_allowed, bool defects_listed,
                                       int accepted_at = -1) {
  std::vector<Step> steps;
  int pin_rounds = 0;
  for (int round = 0, check = 0;; ++round, ++check) {
    const Step step = smoothing_recovery_step(check == accepted_at, round, pin_rounds,
                                              pin_rounds_allowed, defects_listed);
    steps.push_back(step);
    if (step == Step::accept || step == Step::fail) return steps;
    if (step == Step::pin) {
      ++pin_rounds;
      round = -1;
    }
  }
}

TEST(SmoothingRecovery, PinsFirstThenUndoesAroundTheDefectsThenEverything) {
  EXPECT_EQ(steps_while_rejected(3, true),
            (std::vector<Step>{Step::pin, Step::pin, Step::pin, Step::undo_around,
                               Step::undo_around, Step::undo_around, Step::undo_all, Step::fail}));
  EXPECT_EQ(steps_while_rejected(0, true),
            (std::vector<Step>{Step::undo_around, Step::undo_around, Step::undo_around,
                               Step::undo_all, Step::fail}));
  EXPECT_EQ(steps_while_rejected(-1, true), steps_while_rejected(0, true));  // <= 0: no pins
  // No defect hex listed: nothing to pin.
  EXPECT_EQ(steps_while_rejected(3, false), steps_while_rejected(0, true));
  EXPECT_EQ(smoothing_undo_rounds, 4);
}

TEST(SmoothingRecovery, AcceptsAsSoonAsTheVerdictAllows) {
  EXPECT_EQ(steps_while_rejected(3, true, 0), std::vector<Step>{Step::accept});
  EXPECT_EQ(steps_while_rejected(3, true, 3),
            (std::vector<Step>{Step::pin, Step::pin, Step::pin, Step::accept}));
  EXPECT_EQ(steps_while_rejected(1, true, 3),
            (std::vector<Step>{Step::pin, Step::undo_around, Step::undo_around, Step::accept}));
  // After the whole smoothing is undone the check is the refined mesh's, which passed.
  EXPECT_EQ(smoothing_recovery_step(true, smoothing_undo_rounds, 3, 3, true), Step::accept);
}

TEST(SmoothingRecovery, WarningsSayWhatTheCheckFoundAndWhatWasDone) {
  MeshCheckReport check;
  check.inverted_hexes = 2;
  check.first_inverted_hex = 7;
  const std::vector<std::string> defects = mesh_check_defects(check);
  ASSERT_EQ(defects.size(), 1u);
  EXPECT_EQ(smoothing_recovery_warning_first(check),
            "the smoothed mesh failed the check (" + defects[0] + ")");
  check.non_conformal_faces = 3;
  const std::vector<std::string> two = mesh_check_defects(check);
  ASSERT_EQ(two.size(), 2u);
  EXPECT_EQ(smoothing_recovery_warning_first(check),
            "the smoothed mesh failed the check (" + two[0] + "; " + two[1] + ")");

  EXPECT_EQ(smoothing_recovery_warning_last(0, 0, 0), "");
  EXPECT_EQ(smoothing_recovery_warning_last(1, 8, 0),
            "; smoothed again 1 time with 8 nodes of rejected hexes pinned");
  EXPECT_EQ(smoothing_recovery_warning_last(3, 275, 0),
            "; smoothed again 3 times with 275 nodes of rejected hexes pinned");
  EXPECT_EQ(smoothing_recovery_warning_last(0, 0, 12),
            "; 12 smoothed nodes went back to their unsmoothed positions");
  EXPECT_EQ(smoothing_recovery_warning_last(2, 16, 12),
            "; smoothed again 2 times with 16 nodes of rejected hexes pinned; 12 smoothed nodes "
            "went back to their unsmoothed positions");
}

TEST(SmoothingRecovery, PinsAreTheRejectedHexesCornersAscendingAndUnique) {
  const std::array<int, 3> dims{2, 1, 1};
  const HexMesh m = generate_brick({.dims = dims, .size = {2, 1, 1}});
  std::vector<int32_t> pinned;
  smoothing_pins_add(pinned, m, {brick_hex(dims, 1, 0, 0)});
  EXPECT_EQ(pinned.size(), 8u);
  smoothing_pins_add(pinned, m, {brick_hex(dims, 0, 0, 0), brick_hex(dims, 1, 0, 0)});
  EXPECT_EQ(pinned.size(), 12u);  // the two hexes share a face
  EXPECT_TRUE(std::is_sorted(pinned.begin(), pinned.end()));
  EXPECT_EQ(std::adjacent_find(pinned.begin(), pinned.end()), pinned.end());
}

// A 4x4x4 brick of unit cubes whose 27 interior nodes were "smoothed" (moved a little): undoing
// around the corner hex puts back the interior nodes of the hexes that share a node with it (the
// 2x2x2 block at the corner: 8 nodes); with the unsmoothed minimum at 1 (unit cubes) every hex
// left with a moved corner is below it, so every moved node goes back.
TEST(SmoothingRecovery, UndoAroundTheDefectsOnABrick) {
  const std::array<int, 3> dims{4, 4, 4};
  const HexMesh unsmoothed = generate_brick({.dims = dims, .size = {4, 4, 4}});
  HexMesh smoothed = unsmoothed;
  for (int k = 1; k < 4; ++k)
    for (int j = 1; j < 4; ++j)
      for (int i = 1; i < 4; ++i)
        smoothed.points[brick_node(dims, i, j, k)] += Eigen::Vector3d(0.1, 0.05, 0.02);
  const std::vector<int32_t> defects{brick_hex(dims, 0, 0, 0)};

  HexMesh around = smoothed;
  EXPECT_EQ(mesh_smoothing_undo_around(around, unsmoothed.points, defects, 0.0), 8);
  EXPECT_EQ(around.points[brick_node(dims, 2, 2, 2)], unsmoothed.points[brick_node(dims, 2, 2, 2)]);
  EXPECT_EQ(around.points[brick_node(dims, 3, 3, 3)], smoothed.points[brick_node(dims, 3, 3, 3)]);
  EXPECT_EQ(mesh_smoothing_undo_around(around, unsmoothed.points, defects, 0.0), 0);  // done

  HexMesh below = smoothed;
  EXPECT_EQ(mesh_smoothing_undo_around(below, unsmoothed.points, defects, 1.0), 27);
  EXPECT_EQ(below.points, unsmoothed.points);
  EXPECT_DOUBLE_EQ(mesh_min_scaled_jacobian(below), 1.0);

  HexMesh all = smoothed;
  EXPECT_EQ(mesh_smoothing_undo_all(all, unsmoothed.points), 27);
  EXPECT_EQ(all.points, unsmoothed.points);
}

}  // namespace
}  // namespace hexrefine
