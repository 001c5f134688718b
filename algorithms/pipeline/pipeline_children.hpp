#pragma once
/// \file
/// Stage 3 of the pipeline (algorithms/pipeline/pipeline.cpp): children, the input hexes a
/// refinement refined and their children, the figures a refinement's quality is fairly compared
/// with (the mesh-wide minimum also holds the untouched input hexes, which may be worse than
/// every refined parent).

#include "algorithms/pipeline/pipeline_stage.hpp"
#include "algorithms/pipeline/smoothing_start.hpp"
#include "mesh/conformity.hpp"
#include "mesh/hex_mesh.hpp"

namespace hexrefine {

/// The refined parents of `mesh` (a refinement of `input`: attributes parent_hex and
/// refinement_level; none found without them), their lowest scaled Jacobian and their children.
/// A parent is refined when one of its output hexes is a level above it (the input's own levels,
/// if any, kept). The same for any thread count (`threads` >= 1).
RefinedChildren refined_children_find(const HexMesh& input, const HexMesh& mesh, int threads);

/// The lowest scaled Jacobian over the children of `mesh` (1 if none): the checker's own minimum
/// (`check`, of `mesh`) when every hex is a child (a full refinement, where a second pass would
/// cost as much as the checker's quality samples), else a pass over the children alone.
double refined_children_min_scaled_jacobian(const RefinedChildren& children, const HexMesh& mesh,
                                            const MeshCheckReport& check);

/// Stage 3 for one start (its refinement done): its children (refined_children_find), billed
/// with the check that follows to "check".
void pipeline_children(PipelineRun& run, SmoothingStart& start);

}  // namespace hexrefine
