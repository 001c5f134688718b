#include "algorithms/pipeline/pipeline_refine.hpp"

#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>
#include <string>
#include <utility>

#include "mesh/error.hpp"

namespace hexrefine {

namespace {

/// n * 27^passes, saturated at INT64_MAX.
int64_t refine_hex_bound(int64_t hexes, int passes) {
  int64_t bound = hexes;
  for (int p = 0; p < passes; ++p)
    bound = bound > std::numeric_limits<int64_t>::max() / 27 ? std::numeric_limits<int64_t>::max()
                                                             : bound * 27;
  return bound;
}

void size_bound_check(const HexMesh& input, const PipelineOptions& o) {
  const int passes = o.refine.passes;
  const int64_t bound = refine_hex_bound(input.hex_count(), passes);
  if (bound <= o.max_hexes) return;
  std::ostringstream estimate;
  if (bound < std::numeric_limits<int64_t>::max())
    estimate << bound;
  else
    estimate << std::setprecision(3)
             << static_cast<double>(input.hex_count()) * std::pow(27.0, passes);
  throw OperationError("the input has " + std::to_string(input.hex_count()) + " hexes; " +
                       std::to_string(passes) + " passes can give up to " +
                       std::to_string(input.hex_count()) + " x 27^" + std::to_string(passes) +
                       " = " + estimate.str() + " hexes, above the limit of " +
                       std::to_string(o.max_hexes) +
                       " hexes (--max-hexes; at most 2^31 - 1, the int32 hex ids); nothing "
                       "refined or written: use fewer passes");
}

/// Nothing to refine: the input, with the attributes a refinement adds.
SmoothingStart input_unrefined(const HexMesh& input, const std::string& method) {
  SmoothingStart s;
  s.mesh = input;
  std::vector<int32_t> parent(input.hexes.size()), tag_of(input.hexes.size(), -1);
  std::iota(parent.begin(), parent.end(), 0);
  mesh_attributes_from_parents(input, parent, tag_of, s.mesh);
  s.stats.method = method;
  s.stats.initial_hexes = s.stats.final_hexes = input.hex_count();
  s.stats.final_nodes = input.point_count();
  return s;
}

}  // namespace

RefineResult pipeline_refine_placed_by(const PipelineRun& run, PlacementMethod placement) {
  RefineOptions options = run.options.refine;
  options.placement.method = placement;
  return refine(*run.method, run.input, Targets{run.result.selected}, options);
}

SmoothingStart pipeline_refine(PipelineRun& run, PlacementMethod placement) {
  const PipelineOptions& o = run.options;
  run.clock.begin("refine");
  size_bound_check(run.input, o);
  SmoothingStart s;
  if (run.result.selected.empty()) {
    s = input_unrefined(run.input, o.method);
  } else {
    RefineResult refined;
    try {
      refined = pipeline_refine_placed_by(run, placement);
    } catch (const PlacementError& e) {
      // `untangle` keeps the thesis' positions, the better start for smoothing, but on a
      // distorted input they can leave a child no untangling saves (ecr_cap.mesh, two passes:
      // real_meshes.md); `optimized` starts from the reference positions and may not. The
      // counts can differ (placement retargets), never the validity.
      if (!o.smooth || placement != PlacementMethod::untangle) throw;
      refined = pipeline_refine_placed_by(run, PlacementMethod::optimized);
      s.placement_used = PlacementMethod::optimized;
      s.placement_warning = std::string("the untangle start was refused (") + e.what() +
                            "); placed by optimized instead";
    }
    s.mesh = std::move(refined.mesh);
    s.stats = std::move(refined.stats);
  }
  run.clock.end("refine");
  return s;
}

}  // namespace hexrefine
