#pragma once
/// \file
/// Stage 6 of the pipeline (algorithms/pipeline/pipeline.cpp): the smoothing recovery. Smoothing
/// never fails a valid refinement: the smoothed mesh is checked against the input (and written
/// beside that check); should the checker reject it, it is smoothed again from the refined mesh
/// with the corners of the rejected hexes pinned (PipelineOptions::smoothing_pin_rounds times at
/// most), then the smoothed nodes around the defects go back to their unsmoothed positions, round
/// by round, and after smoothing_undo_rounds rounds all of them do. The refined mesh passed the
/// same check, so the last resort is valid. Each decision is a pure function of what the check
/// found (smoothing_recovery_step; tests/algorithms/pipeline/test_smoothing_recovery.cpp). Why
/// and on which meshes: docs/placement-and-smoothing.md, "Smoothing never fails".

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "algorithms/pipeline/pipeline_stage.hpp"
#include "algorithms/pipeline/smoothing_start.hpp"
#include "mesh/conformity.hpp"
#include "mesh/hex_mesh.hpp"

namespace hexrefine {

/// At most this many rounds of undoing the smoothing around the defects the checker finds; the
/// last of them undoes the whole smoothing.
inline constexpr int smoothing_undo_rounds = 4;

/// What the recovery does after a check of the smoothed mesh.
enum class SmoothingRecoveryStep {
  accept,       ///< the verdict allows the smoothed mesh: it is the output
  fail,         ///< the whole smoothing was undone and the check still fails (OperationError)
  pin,          ///< smooth again from the refined mesh with the rejected hexes' corners pinned
  undo_around,  ///< put the nodes of the defect hexes, a ring around them, and any hex left
                ///< below the unsmoothed minimum back to their unsmoothed positions
  undo_all,     ///< put every smoothed node back
};

/// The recovery's decision. Pinning comes before any undoing: undoing afterwards also takes back
/// the moves that lifted the worst hexes (docs/placement-and-smoothing.md, "Smoothing never
/// fails").
/// @param allowed the verdict allows the smoothed mesh
/// @param undo_round undo rounds since the last smoothing, 0..smoothing_undo_rounds
/// @param pin_rounds pinned smoothings so far, >= 0
/// @param pin_rounds_allowed PipelineOptions::smoothing_pin_rounds (<= 0: none)
/// @param defects_listed the check lists defect hexes (their corners are what a pin pins)
SmoothingRecoveryStep smoothing_recovery_step(bool allowed, int undo_round, int pin_rounds,
                                              int pin_rounds_allowed, bool defects_listed);

/// The warning's first part, at the first rejection: what the check found.
std::string smoothing_recovery_warning_first(const MeshCheckReport& check);

/// The warning's last part, once the smoothed mesh is accepted: how many times the smoothing ran
/// again with how many nodes pinned, how many nodes went back (empty when neither).
/// @param pinned_nodes the smoothing's fixed nodes after the last pin round (the options' own too)
std::string smoothing_recovery_warning_last(int pin_rounds, size_t pinned_nodes,
                                            int64_t nodes_undone);

/// Adds the corners of `defect_hexes` (of `mesh`) to `pinned`, which stays ascending and unique.
void smoothing_pins_add(std::vector<int32_t>& pinned, const HexMesh& mesh,
                        const std::vector<int32_t>& defect_hexes);

/// Puts every node of `mesh` back to `unsmoothed` (its points before smoothing, same size);
/// returns how many nodes moved back.
int64_t mesh_smoothing_undo_all(HexMesh& mesh, const std::vector<Eigen::Vector3d>& unsmoothed);

/// Puts back the nodes of the hexes around `defect_hexes` (those sharing a node with one), then
/// those of any hex left below `unsmoothed_min` until none is (a hex with some corners back and
/// some smoothed can be worse than both meshes; the unsmoothed mesh is at least that minimum, so
/// this ends). Returns how many nodes moved back.
int64_t mesh_smoothing_undo_around(HexMesh& mesh, const std::vector<Eigen::Vector3d>& unsmoothed,
                                   const std::vector<int32_t>& defect_hexes, double unsmoothed_min);

/// Stage 6 for a smoothed start (SmoothingStart::smoothing set): checks the smoothed mesh
/// (billed to "check_smoothed"; written to `out` beside the check once the verdict allows it,
/// see pipeline_check_and_write), and while the verdict does not, takes the
/// smoothing_recovery_step (pinned smoothings billed to "smooth"). Sets the start's
/// smoothed_check, smoothed_children_min_scaled_jacobian, smoothing_nodes_undone and
/// smoothing_warning; after an undo the smoothing's minimum and mean after are the check's.
void smoothing_recover(PipelineRun& run, SmoothingStart& start, const std::string& out);

}  // namespace hexrefine
