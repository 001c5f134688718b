#include "algorithms/pipeline/pipeline_check.hpp"

#include <algorithm>
#include <iomanip>
#include <optional>
#include <ostream>
#include <vector>

#include "algorithms/pipeline/pipeline_children.hpp"
#include "mesh/staged_write.hpp"

namespace hexrefine {

namespace {

/// Throws when the refined mesh's `check` is invalid and no switch allows it (see
/// pipeline_check).
void refine_verdict_enforce(const MeshCheckReport& check, const HexMesh& mesh, const HexMesh& input,
                            const PipelineOptions& o, bool ablation) {
  if (pipeline_verdict_allows(check, o, ablation)) return;
  const MeshCheckReport input_check = mesh_check(input, nullptr, o.refine.threads);
  if (!input_check.valid()) {
    std::string why;
    for (const std::string& d : mesh_check_defects(input_check)) why += "\n  " + d;
    throw InputError(
        "the input mesh fails the check (before any refinement), so no refinement "
        "of it can be valid:" +
        why);
  }
  throw OperationError("the " + o.method + " refiner left an invalid mesh; nothing written:" +
                       mesh_check_defects_text(check, mesh));
}

}  // namespace

bool pipeline_verdict_allows(const MeshCheckReport& check, const PipelineOptions& o,
                             bool ablation) {
  return check.valid() || ablation || o.refine.allow_inverted;
}

std::string mesh_check_defects_text(const MeshCheckReport& check, const HexMesh& mesh) {
  std::string why;
  for (const std::string& d : mesh_check_defects(check)) why += "\n  " + d;
  if (const std::vector<int32_t>* parent = mesh_find_attribute(mesh, attribute_parent_hex)) {
    std::vector<int32_t> parents;
    for (int32_t h : check.defect_hexes) parents.push_back((*parent)[h]);
    std::sort(parents.begin(), parents.end());
    parents.erase(std::unique(parents.begin(), parents.end()), parents.end());
    if (!parents.empty()) why += "\n  refined from input hexes";
    for (int32_t p : parents) {
      why += ' ';
      why += std::to_string(p);
    }
  }
  return why;
}

bool pipeline_check_and_write(PipelineRun& run, const std::string& stage, const HexMesh& mesh,
                              const RefinedChildren& children, MeshCheckReport& check,
                              double& children_min_scaled_jacobian, const std::string& out) {
  const PipelineOptions& o = run.options;
  PipelineResult& r = run.result;
  if (!run.input_surface) run.input_surface.emplace(run.input, o.refine.threads);
  // The writer takes a thread of its own; with one thread the write follows the check.
  std::optional<StagedMeshWrite> staged;
  if (!out.empty() && o.refine.threads > 1) {
    run.clock.begin(stage == "check" ? "check and write" : "check (smoothed) and write");
    staged.emplace(out, mesh, o.write);
  }
  check = mesh_check(mesh, &run.input, o.refine.threads, &*run.input_surface);
  children_min_scaled_jacobian = refined_children_min_scaled_jacobian(children, mesh, check);
  const double writer_cpu = staged ? staged->cpu_seconds_so_far() : 0.0;
  run.clock.end(stage);
  r.stage_cpu_seconds[stage] -= writer_cpu;  // the writer's thread is the write stage's
  if (!pipeline_verdict_allows(check, o, r.ablation)) return false;
  if (!out.empty()) {
    if (!staged) {
      run.clock.begin("write");
      staged.emplace(out, mesh, o.write);
    }
    try {
      staged->commit();
    } catch (const InputError& e) {
      throw OutputWriteError(e.what());  // names the output: no input prefix
    }
    r.stage_seconds["write"] = staged->seconds();
    r.stage_cpu_seconds["write"] = staged->cpu_seconds();
    if (o.verbose)
      *o.verbose << "hexrefine: write " << std::fixed << std::setprecision(3) << staged->seconds()
                 << " s" << (o.refine.threads > 1 ? " (beside the check)" : "") << std::endl;
  }
  return true;
}

void pipeline_check(PipelineRun& run, SmoothingStart& start, const std::string& out) {
  run.clock.begin("check");
  if (run.options.smooth) start.smoothing_region = mesh_refined_hexes(start.mesh);
  if (!pipeline_check_and_write(run, "check", start.mesh, start.children, start.check,
                                start.children_min_scaled_jacobian,
                                start.smoothing_region.empty() ? out : std::string()))
    refine_verdict_enforce(start.check, start.mesh, run.input, run.options, run.result.ablation);
}

void pipeline_write(PipelineRun& run, const HexMesh& mesh, const std::string& out) {
  StagedMeshWrite staged(out, mesh, run.options.write);
  try {
    staged.commit();
  } catch (const InputError& e) {
    throw OutputWriteError(e.what());  // names the output: no input prefix
  }
  run.result.stage_seconds["write"] = staged.seconds();
  run.result.stage_cpu_seconds["write"] = staged.cpu_seconds();
}

}  // namespace hexrefine
