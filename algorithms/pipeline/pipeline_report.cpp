#include "algorithms/pipeline/pipeline_report.hpp"

#include <sys/resource.h>

#include <utility>

namespace hexrefine {

void pipeline_result_take(PipelineResult& r, SmoothingStart&& kept) {
  r.mesh = std::move(kept.mesh);
  r.stats = std::move(kept.stats);
  r.placement_used = kept.placement_used;
  r.placement_warning = std::move(kept.placement_warning);
  r.refined_parents = kept.children.parents;
  r.refined_parents_min_scaled_jacobian = kept.children.parents_min_scaled_jacobian;
  r.children_min_scaled_jacobian = kept.children_min_scaled_jacobian;
  r.smoothed_children_min_scaled_jacobian = kept.smoothed_children_min_scaled_jacobian;
  r.check = std::move(kept.check);
  r.smoothing = std::move(kept.smoothing);
  r.smoothed_check = std::move(kept.smoothed_check);
  r.smoothing_nodes_undone = kept.smoothing_nodes_undone;
  r.smoothing_warning = std::move(kept.smoothing_warning);
}

double process_peak_memory_mb() {
  rusage usage{};
  if (::getrusage(RUSAGE_SELF, &usage) != 0) return 0;
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KB on Linux
}

nlohmann::json pipeline_report(const PipelineResult& r, const PipelineOptions& o) {
  nlohmann::json j;
  j["schema_version"] = pipeline_report_schema_version;
  j["method"] = o.method;
  j["options"] = o.refine;
  if (r.placement_used) j["options"]["placement"]["method"] = *r.placement_used;
  j["options"]["smooth"] = o.smooth;
  nlohmann::json selection = {{"hexes", r.selected.size()}};
  if (o.targets)
    selection["specs"] = nlohmann::json::array({"targets given by id"});
  else
    selection["specs"] = o.select;
  if (!r.selection_warning.empty()) selection["warning"] = r.selection_warning;
  j["selection"] = selection;
  j["refine"] = r.stats;
  if (!r.placement_warning.empty()) j["refine"]["placement_warning"] = r.placement_warning;
  j["refined_parents"] = {{"hexes", r.refined_parents},
                          {"min_scaled_jacobian", r.refined_parents_min_scaled_jacobian},
                          {"children_min_scaled_jacobian", r.children_min_scaled_jacobian}};
  if (r.smoothed_children_min_scaled_jacobian)
    j["refined_parents"]["smoothed_children_min_scaled_jacobian"] =
        *r.smoothed_children_min_scaled_jacobian;
  j["check"] = r.output_check();  // the mesh written (docs/report.md, schema_version 2)
  if (r.smoothing) {
    j["smoothing"] = {{"stats", *r.smoothing},
                      {"refined_check", r.check},
                      {"nodes_undone", r.smoothing_nodes_undone},
                      {"max_sweeps", o.smoothing.max_sweeps},
                      {"max_joint_iterations", o.smoothing.joint_iterations},
                      {"max_joint_rounds", o.smoothing.joint_rounds},
                      {"both_starts", o.smoothing_both_starts}};
    if (!r.smoothing_warning.empty()) j["smoothing"]["warning"] = r.smoothing_warning;
  }
  j["stage_seconds"] = r.stage_seconds;
  j["stage_cpu_seconds"] = r.stage_cpu_seconds;
  j["peak_memory_mb"] = r.peak_memory_mb;
  return j;
}

}  // namespace hexrefine
