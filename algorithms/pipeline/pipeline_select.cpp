#include "algorithms/pipeline/pipeline_select.hpp"

#include <utility>

#include "mesh/selection.hpp"

namespace hexrefine {

void pipeline_select(PipelineRun& run) {
  const PipelineOptions& o = run.options;
  PipelineResult& r = run.result;
  run.clock.begin("select");
  run.method = &refine_method(o.method);
  r.ablation = !o.refine.ranking || !o.refine.propagation || o.refine.ebe_only;
  if (o.targets) {
    r.selected = *o.targets;
  } else {
    Selection selection = select_hexes(run.input, o.select);
    r.selected = std::move(selection.hexes);
    r.selection_warning = std::move(selection.warning);
  }
  run.clock.end("select");
}

}  // namespace hexrefine
