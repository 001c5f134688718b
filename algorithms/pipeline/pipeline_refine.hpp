#pragma once
/// \file
/// Stage 2 of the pipeline (algorithms/pipeline/pipeline.cpp): refine, the selected targets
/// refined by the method and placed (algorithms/refiners/refiner.hpp refine()).

#include "algorithms/pipeline/pipeline_stage.hpp"
#include "algorithms/pipeline/smoothing_start.hpp"

namespace hexrefine {

/// The selected targets (PipelineResult::selected) refined by options.refine placed by
/// `placement`: a start's mesh, stats and placement (SmoothingStart). Refuses (OperationError)
/// before refining when n * 27^passes could exceed options.max_hexes. No targets: the input,
/// with the attributes a refinement adds. Where `placement` is `untangle` with smoothing and the
/// placement refuses, placed by `optimized` instead, with the warning (a valid input is never
/// refused for the start its smoothing prefers). Billed to "refine".
SmoothingStart pipeline_refine(PipelineRun& run, PlacementMethod placement);

/// The selected targets refined by options.refine placed by `placement`, as it is (no bound, no
/// fallback; the clock not touched). Throws as refine() does (PlacementError when the placement
/// refuses).
RefineResult pipeline_refine_placed_by(const PipelineRun& run, PlacementMethod placement);

}  // namespace hexrefine
