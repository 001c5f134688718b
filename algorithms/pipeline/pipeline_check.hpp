#pragma once
/// \file
/// Stage 4 of the pipeline (algorithms/pipeline/pipeline.cpp): check, a mesh against the input
/// (mesh/conformity.hpp), the verdict on it, and the output written beside the check of the final
/// mesh (mesh/staged_write.hpp): the file becomes the output only once the verdict allows it.

#include <string>

#include "algorithms/pipeline/pipeline_stage.hpp"
#include "algorithms/pipeline/smoothing_start.hpp"
#include "mesh/conformity.hpp"
#include "mesh/error.hpp"
#include "mesh/hex_mesh.hpp"

namespace hexrefine {

/// An InputError of the output's writer (e.g. a field name its format cannot hold): it names the
/// output, so pipeline_run_files does not put the input's path in front of it.
class OutputWriteError : public InputError {
 public:
  using InputError::InputError;
};

/// Whether a result with this check may be returned: valid, or a switch allows it (an ablation
/// switch, options.refine.allow_inverted).
bool pipeline_verdict_allows(const MeshCheckReport& check, const PipelineOptions& options,
                             bool ablation);

/// The defects of `check` (of `mesh`) as lines, and the input hexes they descend from.
std::string mesh_check_defects_text(const MeshCheckReport& check, const HexMesh& mesh);

/// Checks `mesh` against the input into `check`, and its children's minimum into
/// `children_min_scaled_jacobian`; billed to `stage`. With a non-empty `out` the mesh is written
/// there: beside the check on a thread of its own when there is more than one thread (its time
/// and CPU the "write" stage's, left out of `stage`'s CPU), else after the check; the file
/// becomes `out` only once the verdict allows it (an InputError of the writer is rethrown as
/// OutputWriteError). Returns whether the verdict allows the mesh (nothing written when not).
/// Builds the input's surface (PipelineRun::input_surface) on the first call. `mesh` is not
/// changed while a write may read it.
bool pipeline_check_and_write(PipelineRun& run, const std::string& stage, const HexMesh& mesh,
                              const RefinedChildren& children, MeshCheckReport& check,
                              double& children_min_scaled_jacobian, const std::string& out);

/// Stage 4 for one start (its children found, pipeline_children): the smoothing region (the
/// refined hexes, with options.smooth) and the check of the refined mesh, billed to "check",
/// written to `out` when nothing is to be smoothed (it is the output then). Throws when the
/// verdict does not allow the refined mesh, naming the stage that failed: InputError when the
/// input itself fails the checker (nothing refined from it can be valid), OperationError naming
/// the refiner and the defects otherwise.
void pipeline_check(PipelineRun& run, SmoothingStart& start, const std::string& out);

/// Writes `mesh` to `out` after its check (the verdict allowed it), atomically; the "write"
/// stage's wall and CPU time are the writer's. An InputError of the writer is rethrown as
/// OutputWriteError.
void pipeline_write(PipelineRun& run, const HexMesh& mesh, const std::string& out);

}  // namespace hexrefine
