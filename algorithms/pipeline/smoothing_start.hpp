#pragma once
/// \file
/// Stage 5 of the pipeline (algorithms/pipeline/pipeline.cpp): the smoothing starts. A start is a
/// value (SmoothingStart): the targets refined and placed by one placement method, checked, and
/// smoothed. Where the options ask for a second start (PipelineOptions::smoothing_start_fallback,
/// smoothing_both_starts) both are computed as values and a policy, a pure function of the two
/// (smoothing_start_choose_fallback, smoothing_start_choose_both), says which one is kept: the
/// policies never run a stage themselves, and are tested on hand-built values
/// (tests/algorithms/pipeline/test_smoothing_start.cpp). Why two starts: docs/placement-and-
/// smoothing.md, "--smooth never ends below plain refine" and "Both starts".

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "algorithms/pipeline/pipeline_stage.hpp"
#include "algorithms/placement/smoothing.hpp"
#include "mesh/conformity.hpp"
#include "mesh/hex_mesh.hpp"

namespace hexrefine {

/// The input hexes a refinement refined (its children's refinement level is above theirs) and
/// their children, found by refined_children_find (algorithms/pipeline/pipeline_children.hpp).
struct RefinedChildren {
  int64_t parents = 0;                     ///< input hexes refined
  double parents_min_scaled_jacobian = 1;  ///< their lowest scaled Jacobian, 1 if none
  std::vector<uint8_t> is_child;           ///< per output hex: 1 when made by refining an input hex
  int64_t children = 0;                    ///< output hexes with is_child
};

/// One start of the pipeline, as a value: the refinement placed by one placement method, its
/// children, its check, and, where it is smoothed, the smoothing and the smoothed mesh's check.
/// Filled stage by stage: refine (mesh, stats, placement), children, check, smooth
/// (smoothing_start_smooth), recovery (smoothed_check on, algorithms/pipeline/
/// smoothing_recovery.hpp). Without smoothing it is the run's one start.
struct SmoothingStart {
  HexMesh mesh;  ///< the refined mesh; smoothed in place by the smooth stage
  RefineStats stats;
  /// The placement the refinement was placed by when it is not the options' (the untangle start
  /// refused, or a policy kept the optimized start), and what the report says of it
  /// (PipelineResult::placement_used, placement_warning).
  std::optional<PlacementMethod> placement_used;
  std::string placement_warning;
  RefinedChildren children;
  /// Lowest scaled Jacobian over the refined mesh's children (1 if none).
  double children_min_scaled_jacobian = 1;
  MeshCheckReport check;  ///< the refined mesh against the input, before any smoothing
  /// The hexes the smooth stage smooths (the refined ones; options.smooth only): empty when
  /// nothing is smoothed, and then the check above is the output's.
  std::vector<int32_t> smoothing_region;
  /// The smoothing as it ran (region, reference, the pins of the recovery's pin rounds).
  SmoothOptions smoothing_options;
  std::vector<Eigen::Vector3d> unsmoothed;  ///< the refined mesh's points, kept for the recovery
  std::optional<SmoothStats> smoothing;
  /// The smoothed mesh against the input, once the recovery has run (the output's check).
  std::optional<MeshCheckReport> smoothed_check;
  std::optional<double> smoothed_children_min_scaled_jacobian;
  int64_t smoothing_nodes_undone = 0;  ///< as PipelineResult::smoothing_nodes_undone
  std::string smoothing_warning;       ///< as PipelineResult::smoothing_warning
};

/// Smooths the start's region (SmoothingStart::smoothing_region: the refined hexes, and
/// options.smoothing.layers layers around them), its boundary nodes within the input's boundary
/// surface, against the input (PipelineOptions::smoothing). Keeps the refined points
/// (SmoothingStart::unsmoothed) for the recovery. Leaves the clock running: the caller bills
/// "smooth". Precondition: the region is not empty.
void smoothing_start_smooth(PipelineRun& run, SmoothingStart& start);

/// Which start a policy keeps, and what the report says of it.
struct SmoothingStartChoice {
  bool optimized = false;  ///< the optimized start (else the untangle one, the options')
  /// The kept start's refine.placement_warning; empty: the start's own stands.
  std::string placement_warning;
};

/// PipelineOptions::smoothing_start_fallback, when it wants the optimized start: the untangle
/// start smoothed ends below the minimum the optimized placement gives unsmoothed (-infinity
/// when there is none to fall back on).
bool smoothing_start_fallback_wanted(double untangle_smoothed_min, double optimized_unsmoothed_min);

/// PipelineOptions::smoothing_start_fallback: the optimized start where it is wanted
/// (smoothing_start_fallback_wanted) and passed its checks, with a warning naming both minima;
/// else the untangle start as it is.
/// @param untangle smoothed (SmoothingStart::smoothing set)
/// @param optimized the optimized start smoothed; nullptr when it was not made or failed a check
/// @param optimized_unsmoothed_min the optimized placement's minimum unsmoothed
SmoothingStartChoice smoothing_start_choose_fallback(const SmoothingStart& untangle,
                                                     const SmoothingStart* optimized,
                                                     double optimized_unsmoothed_min);

/// The lowest scaled Jacobian of the start's output: the smoothed mesh's once recovered, else
/// the refined mesh's.
double smoothing_start_output_min(const SmoothingStart& start);

/// PipelineOptions::smoothing_both_starts: the start whose output has the higher minimum
/// (smoothing_start_output_min), the untangle one on a tie, with a warning naming both minima
/// when the optimized one is kept, or why it failed when it did.
/// @param untangle smoothed and recovered
/// @param optimized smoothed and recovered; nullptr when it was not made or failed
/// @param optimized_failure what the optimized start's failure said (empty: it did not fail)
SmoothingStartChoice smoothing_start_choose_both(const SmoothingStart& untangle,
                                                 const SmoothingStart* optimized,
                                                 const std::string& optimized_failure);

/// The start `choice` names, its placement and warning set from the choice.
SmoothingStart smoothing_start_keep(const SmoothingStartChoice& choice, SmoothingStart untangle,
                                    std::optional<SmoothingStart> optimized);

/// Stage 5 with PipelineOptions::smoothing_start_fallback (or a single start): smooths `start`
/// and, where the options' placement is `untangle` (not refused) and the fallback is on, places
/// the targets by `optimized` too (billed to "smooth"); where smoothing_start_fallback_wanted, the
/// optimized start is checked and smoothed as well (an OperationError of its check leaves it
/// out) and smoothing_start_choose_fallback keeps one. Returns the start kept, smoothed, not yet
/// recovered.
SmoothingStart smoothing_starts_fallback(PipelineRun& run, SmoothingStart start);

/// Stage 5 with PipelineOptions::smoothing_both_starts: smooths and recovers `untangle` and
/// (unless the untangle start was refused) the optimized start, neither written, and keeps one by
/// smoothing_start_choose_both (an OperationError of the optimized start leaves it out, with a
/// warning). Every stage of both is billed.
SmoothingStart smoothing_starts_both(PipelineRun& run, SmoothingStart untangle);

}  // namespace hexrefine
