#include "algorithms/pipeline/smoothing_start.hpp"

#include <limits>
#include <sstream>
#include <utility>

#include "algorithms/pipeline/pipeline_check.hpp"
#include "algorithms/pipeline/pipeline_children.hpp"
#include "algorithms/pipeline/pipeline_refine.hpp"
#include "algorithms/pipeline/smoothing_recovery.hpp"
#include "mesh/error.hpp"
#include "mesh/quality.hpp"
#include "mesh/topology.hpp"

namespace hexrefine {

void smoothing_start_smooth(PipelineRun& run, SmoothingStart& start) {
  const PipelineOptions& o = run.options;
  SmoothOptions& so = start.smoothing_options;
  so = o.smoothing;
  so.region_hexes = start.smoothing_region;
  // Boundary nodes the refinement made slide within the input face or edge they subdivide, the
  // input's boundary nodes stay: the smoothed mesh is checked against the input again.
  if (!run.boundary_reference)
    run.boundary_reference.emplace(
        boundary_reference_build(run.input, topology_build(run.input, TopologyParts::faces)));
  so.reference = &*run.boundary_reference;
  if (o.smoothing_surface_guard) so.reference_surface = &*run.input_surface;
  so.reference_nodes = run.input.point_count();
  so.threads = o.refine.threads;
  start.unsmoothed = start.mesh.points;
  run.clock.begin("smooth");
  start.smoothing = mesh_smooth(start.mesh, so);
}

bool smoothing_start_fallback_wanted(double untangle_smoothed_min,
                                     double optimized_unsmoothed_min) {
  return untangle_smoothed_min < optimized_unsmoothed_min;
}

SmoothingStartChoice smoothing_start_choose_fallback(const SmoothingStart& untangle,
                                                     const SmoothingStart* optimized,
                                                     double optimized_unsmoothed_min) {
  const double untangle_min = untangle.smoothing->min_scaled_jacobian_after;
  if (!optimized || !smoothing_start_fallback_wanted(untangle_min, optimized_unsmoothed_min))
    return {};
  std::ostringstream why;
  why << "smoothing from untangle reached " << untangle_min << ", below the "
      << optimized_unsmoothed_min
      << " of the optimized placement unsmoothed; placed by optimized and smoothed from there";
  return {true, why.str()};
}

double smoothing_start_output_min(const SmoothingStart& start) {
  return start.smoothed_check ? start.smoothed_check->min_scaled_jacobian
                              : start.check.min_scaled_jacobian;
}

SmoothingStartChoice smoothing_start_choose_both(const SmoothingStart& untangle,
                                                 const SmoothingStart* optimized,
                                                 const std::string& optimized_failure) {
  if (!optimized) {
    if (optimized_failure.empty()) return {};
    return {false,
            "the optimized start failed (" + optimized_failure + "); kept the untangle start"};
  }
  const double untangle_min = smoothing_start_output_min(untangle);
  const double optimized_min = smoothing_start_output_min(*optimized);
  if (!(optimized_min > untangle_min)) return {};
  std::ostringstream why;
  why << "smoothed from both starts: " << optimized_min << " from optimized, " << untangle_min
      << " from untangle; kept optimized";
  return {true, why.str()};
}

SmoothingStart smoothing_start_keep(const SmoothingStartChoice& choice, SmoothingStart untangle,
                                    std::optional<SmoothingStart> optimized) {
  SmoothingStart kept = choice.optimized ? std::move(*optimized) : std::move(untangle);
  if (choice.optimized) kept.placement_used = PlacementMethod::optimized;
  if (!choice.placement_warning.empty()) kept.placement_warning = choice.placement_warning;
  return kept;
}

SmoothingStart smoothing_starts_fallback(PipelineRun& run, SmoothingStart start) {
  const PipelineOptions& o = run.options;
  smoothing_start_smooth(run, start);
  // The start's guarantee (PipelineOptions::smoothing_start_fallback): the minimum plain
  // `refine` reaches, placed by `optimized`.
  double optimized_min = -std::numeric_limits<double>::infinity();
  std::optional<RefineResult> plain;
  if (o.smoothing_start_fallback && o.refine.placement.method == PlacementMethod::untangle &&
      !start.placement_used) {
    try {
      plain = pipeline_refine_placed_by(run, PlacementMethod::optimized);
      optimized_min = mesh_min_scaled_jacobian(plain->mesh);
    } catch (const PlacementError&) {
      // optimized refuses: nothing to fall back on
    }
  }
  run.clock.end("smooth");
  if (!smoothing_start_fallback_wanted(start.smoothing->min_scaled_jacobian_after, optimized_min))
    return start;
  // The optimized start takes the refinement just made instead of refining again.
  std::optional<SmoothingStart> optimized;
  try {
    SmoothingStart s;
    s.mesh = std::move(plain->mesh);
    s.stats = std::move(plain->stats);
    pipeline_children(run, s);
    pipeline_check(run, s, "");
    smoothing_start_smooth(run, s);  // the same targets: a refined region as the untangle one's
    run.clock.end("smooth");
    optimized = std::move(s);
  } catch (const OperationError&) {
    // The optimized refinement failed a check the untangle one passed: the untangle start
    // stands.
  }
  const SmoothingStartChoice choice =
      smoothing_start_choose_fallback(start, optimized ? &*optimized : nullptr, optimized_min);
  return smoothing_start_keep(choice, std::move(start), std::move(optimized));
}

SmoothingStart smoothing_starts_both(PipelineRun& run, SmoothingStart untangle) {
  smoothing_start_smooth(run, untangle);
  run.clock.end("smooth");
  smoothing_recover(run, untangle, "");
  std::optional<SmoothingStart> optimized;
  std::string failure;
  // Where the untangle start was refused the first start was placed by optimized already.
  if (!untangle.placement_used) try {
      SmoothingStart s = pipeline_refine(run, PlacementMethod::optimized);
      pipeline_children(run, s);
      pipeline_check(run, s, "");
      if (!s.smoothing_region.empty()) {
        smoothing_start_smooth(run, s);
        run.clock.end("smooth");
        smoothing_recover(run, s, "");
      }
      optimized = std::move(s);
    } catch (const OperationError& e) {
      failure = e.what();
    }
  const SmoothingStartChoice choice =
      smoothing_start_choose_both(untangle, optimized ? &*optimized : nullptr, failure);
  return smoothing_start_keep(choice, std::move(untangle), std::move(optimized));
}

}  // namespace hexrefine
