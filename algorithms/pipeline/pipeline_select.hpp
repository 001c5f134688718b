#pragma once
/// \file
/// Stage 1 of the pipeline (algorithms/pipeline/pipeline.cpp): select, the targets.

#include "algorithms/pipeline/pipeline_stage.hpp"

namespace hexrefine {

/// Looks options.method up (an unknown method is refused before any spec is read), sets the
/// ablation flag (a switch that may leave a non-conformal mesh by design) and the targets:
/// options.targets as given, else the hexes options.select selects, ascending, and the warning
/// when they match none (PipelineResult::selected, selection_warning). Billed to "select".
/// Throws InputError for an unknown method or a bad spec (mesh/selection.hpp).
void pipeline_select(PipelineRun& run);

}  // namespace hexrefine
