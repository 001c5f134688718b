#pragma once
/// \file
/// Stage 7 of the pipeline (algorithms/pipeline/pipeline.cpp): the report. The kept start's
/// figures go into the result (pipeline_result_take); pipeline_report (pipeline.hpp) writes the
/// result as the report's JSON.

#include "algorithms/pipeline/pipeline.hpp"
#include "algorithms/pipeline/smoothing_start.hpp"

namespace hexrefine {

/// Moves the kept start's mesh and figures into `result` (PipelineResult's fields of the same
/// names; the refined parents from its children), leaving the selection and the stage times.
void pipeline_result_take(PipelineResult& result, SmoothingStart&& kept);

}  // namespace hexrefine
