#pragma once
/// \file
/// What the stages of the pipeline (algorithms/pipeline/pipeline.cpp) share: the clock each
/// stage bills its time to (PipelineResult::stage_seconds and stage_cpu_seconds; a stage is timed
/// from the end of the one before it, so the stages' times add up to the run's) and the run they
/// work on (PipelineRun).

#include <chrono>
#include <ctime>
#include <iomanip>
#include <optional>
#include <ostream>
#include <string>

#include "algorithms/pipeline/pipeline.hpp"
#include "algorithms/placement/node_placement.hpp"
#include "algorithms/refiners/refiner.hpp"
#include "mesh/reference_surface.hpp"

namespace hexrefine {

/// Ends a stage: its wall and CPU time go to the result and, with --verbose, to the stream.
class StageClock {
 public:
  using Clock = std::chrono::steady_clock;

  StageClock(PipelineResult& result, std::ostream* verbose, std::ostream* progress = nullptr)
      : result_(result), verbose_(verbose), progress_(progress) {}
  /// Names the stage that starts on the progress stream (one line, overwritten by the next).
  void begin(const std::string& stage) {
    if (progress_) *progress_ << "\rhexrefine: " << stage << " ...\033[K" << std::flush;
  }
  /// Bills the time since the last end() (or the clock's start) to `stage`; a stage may be
  /// billed more than once (the times add up).
  void end(const std::string& stage) {
    const double s = seconds_since(start_);
    const double cpu = process_cpu_seconds();
    result_.stage_seconds[stage] += s;
    result_.stage_cpu_seconds[stage] += cpu - cpu_start_;
    if (verbose_)
      *verbose_ << "hexrefine: " << stage << " " << std::fixed << std::setprecision(3) << s
                << " s (peak so far " << static_cast<int64_t>(process_peak_memory_mb()) << " MB)"
                << std::endl;
    if (progress_) *progress_ << "\r\033[K" << std::flush;
    start_ = Clock::now();
    cpu_start_ = cpu;
  }

  /// Wall seconds since `t0`.
  static double seconds_since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
  }

  /// CPU time of this process (all its threads), in seconds.
  static double process_cpu_seconds() {
    timespec ts{};
    ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
  }

 private:
  PipelineResult& result_;
  std::ostream* verbose_;
  std::ostream* progress_;
  Clock::time_point start_ = Clock::now();
  double cpu_start_ = process_cpu_seconds();
};

/// One run of the pipeline as its stages see it: what they read (the input, the options, the
/// method), where the selection and the stage times go (`result`), and what is built once for
/// every start's check and smoothing.
struct PipelineRun {
  PipelineRun(const HexMesh& input_mesh, const PipelineOptions& run_options,
              PipelineResult& run_result, StageClock& stage_clock)
      : input(input_mesh), options(run_options), result(run_result), clock(stage_clock) {}

  const HexMesh& input;
  const PipelineOptions& options;
  PipelineResult& result;  ///< the selection, the ablation flag and the stage times
  StageClock& clock;
  const RefineMethod* method = nullptr;  ///< options.method's, set by the select stage
  /// The input's boundary surface, which every check and the smoothing test faces against:
  /// built before the first check (its cost the check's).
  std::optional<ReferenceSurface> input_surface;
  /// The input faces and edges the refinement's boundary nodes slide within when smoothed: built
  /// before the first smoothing (its cost the smoothing's).
  std::optional<BoundaryReference> boundary_reference;
};

}  // namespace hexrefine
