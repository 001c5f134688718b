/// \file
/// The pipeline as its stage list (docs/architecture.md): pipeline_run_writing calls one
/// function per stage, each in a file of its own in this folder.

#include "algorithms/pipeline/pipeline.hpp"

#include <utility>

#include "algorithms/pipeline/pipeline_check.hpp"
#include "algorithms/pipeline/pipeline_children.hpp"
#include "algorithms/pipeline/pipeline_refine.hpp"
#include "algorithms/pipeline/pipeline_report.hpp"
#include "algorithms/pipeline/pipeline_select.hpp"
#include "algorithms/pipeline/pipeline_stage.hpp"
#include "algorithms/pipeline/smoothing_recovery.hpp"
#include "algorithms/pipeline/smoothing_start.hpp"
#include "mesh/io.hpp"

namespace hexrefine {

namespace {

/// pipeline_run, and with a non-empty `out` the one write of the output there (see
/// pipeline_run_files). The stages:
///   1. select ............ pipeline_select: the targets
///   2. refine ............ pipeline_refine: refined and placed, a start (SmoothingStart)
///   3. children .......... pipeline_children: the refined parents and their children
///   4. check ............. pipeline_check: the verdict; written beside the check when nothing
///                          is smoothed
///   5. smoothing starts .. smoothing_starts_fallback / smoothing_starts_both: smoothed, and a
///                          policy keeps the untangle or the optimized start
///   6. smoothing recovery  smoothing_recover: the smoothed mesh checked and written beside its
///                          check, pinned or undone while rejected (with both starts each start
///                          is recovered in stage 5 and the kept one written after: pipeline_write)
///   7. report ............ pipeline_result_take: the kept start's figures, the total time
PipelineResult pipeline_run_writing(const HexMesh& input, const PipelineOptions& o,
                                    const std::string& out) {
  const StageClock::Clock::time_point started = StageClock::Clock::now();
  PipelineResult r;
  StageClock clock(r, o.verbose, o.progress);
  PipelineRun run(input, o, r, clock);
  pipeline_select(run);                                                    // 1
  SmoothingStart start = pipeline_refine(run, o.refine.placement.method);  // 2
  pipeline_children(run, start);                                           // 3
  pipeline_check(run, start, out);                                         // 4
  if (!start.smoothing_region.empty()) {
    if (o.smoothing_both_starts && o.refine.placement.method == PlacementMethod::untangle) {
      start = smoothing_starts_both(run, std::move(start));  // 5, 6
      if (!out.empty()) pipeline_write(run, start.mesh, out);
    } else {
      start = smoothing_starts_fallback(run, std::move(start));  // 5
      smoothing_recover(run, start, out);                        // 6
    }
  }
  pipeline_result_take(r, std::move(start));  // 7
  r.stage_seconds["total"] = StageClock::seconds_since(started);
  r.peak_memory_mb = process_peak_memory_mb();
  return r;
}

}  // namespace

PipelineResult pipeline_run(const HexMesh& input, const PipelineOptions& o) {
  return pipeline_run_writing(input, o, "");
}

PipelineResult pipeline_run_files(const std::string& in, const std::string& out,
                                  const PipelineOptions& options) {
  const StageClock::Clock::time_point started = StageClock::Clock::now();
  PipelineResult scratch;
  StageClock clock(scratch, options.verbose, options.progress);
  clock.begin("read");
  const HexMesh input = mesh_read(in);
  clock.end("read");
  PipelineResult r;
  try {
    r = pipeline_run_writing(input, options, out);
  } catch (const OutputWriteError&) {
    throw;
  } catch (const InputError& e) {
    throw InputError(in + ": " + e.what());  // the input, or a spec applied to it
  }
  r.stage_seconds["read"] = scratch.stage_seconds["read"];
  r.stage_cpu_seconds["read"] = scratch.stage_cpu_seconds["read"];
  r.stage_seconds["total"] = StageClock::seconds_since(started);
  r.peak_memory_mb = process_peak_memory_mb();
  return r;
}

}  // namespace hexrefine
