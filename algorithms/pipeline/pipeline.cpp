#include "algorithms/pipeline/pipeline.hpp"

#include <sys/resource.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <ctime>
#include <iomanip>
#include <numeric>
#include <ostream>
#include <sstream>

#include "mesh/error.hpp"
#include "mesh/parallel.hpp"
#include "mesh/quality.hpp"
#include "mesh/reference_surface.hpp"
#include "mesh/selection.hpp"
#include "mesh/staged_write.hpp"

namespace hexrefine {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// CPU time of this process (all its threads).
double process_cpu_seconds() {
  timespec ts{};
  ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

/// Ends a stage: its wall and CPU time go to the result and, with --verbose, to the stream.
class StageClock {
 public:
  StageClock(PipelineResult& result, std::ostream* verbose, std::ostream* progress = nullptr)
      : result_(result), verbose_(verbose), progress_(progress) {}
  /// Names the stage that starts on the progress stream (one line, overwritten by the next).
  void begin(const std::string& stage) {
    if (progress_) *progress_ << "\rhexrefine: " << stage << " ...\033[K" << std::flush;
  }
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

 private:
  PipelineResult& result_;
  std::ostream* verbose_;
  std::ostream* progress_;
  Clock::time_point start_ = Clock::now();
  double cpu_start_ = process_cpu_seconds();
};

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

/// An InputError of the output's writer (e.g. a field name its format cannot hold): it names the
/// output, so pipeline_run_files does not put the input's path in front of it.
class OutputWriteError : public InputError {
 public:
  using InputError::InputError;
};

/// Whether a result with this check may be returned: valid, or a switch allows it.
bool verdict_allows(const MeshCheckReport& check, const PipelineOptions& o, bool ablation) {
  return check.valid() || ablation || o.refine.allow_inverted;
}

/// The defects of `check` (of `mesh`) as lines, and the input hexes they descend from.
std::string defects_text(const MeshCheckReport& check, const HexMesh& mesh) {
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

/// Throws when the refined mesh's `check` is invalid and no switch allows it, naming the stage
/// that failed: InputError when the input itself fails the checker (nothing refined from it can
/// be valid), OperationError naming the refiner and the defects otherwise.
void refine_verdict_enforce(const MeshCheckReport& check, const HexMesh& mesh, const HexMesh& input,
                            const PipelineOptions& o, bool ablation) {
  if (verdict_allows(check, o, ablation)) return;
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
                       defects_text(check, mesh));
}

/// At most this many rounds of undoing the smoothing around the defects the checker finds,
/// before the whole smoothing is undone.
constexpr int smoothing_undo_rounds = 4;

}  // namespace

double process_peak_memory_mb() {
  rusage usage{};
  if (::getrusage(RUSAGE_SELF, &usage) != 0) return 0;
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KB on Linux
}

namespace {

PipelineResult pipeline_run_both_starts(const HexMesh& input, const PipelineOptions& o,
                                        const std::string& out);

/// pipeline_run, and with a non-empty `out` the write of the final mesh there (see
/// pipeline_run_files). `placed`, optional: the refinement of the selected targets by o.refine,
/// already done (the restart from optimized reuses the one it compared with).
PipelineResult pipeline_run_writing(const HexMesh& input, const PipelineOptions& o,
                                    const std::string& out, RefineResult* placed = nullptr) {
  if (o.smooth && o.smoothing_both_starts && o.refine.placement.method == PlacementMethod::untangle)
    return pipeline_run_both_starts(input, o, out);
  const auto start = Clock::now();
  PipelineResult r;
  StageClock clock(r, o.verbose, o.progress);
  clock.begin("select");
  const RefineMethod& method = refine_method(o.method);
  r.ablation = !o.refine.ranking || !o.refine.propagation || o.refine.ebe_only;

  if (o.targets) {
    r.selected = *o.targets;
  } else {
    Selection selection = select_hexes(input, o.select);
    r.selected = std::move(selection.hexes);
    r.selection_warning = std::move(selection.warning);
  }
  clock.end("select");
  clock.begin("refine");

  size_bound_check(input, o);
  if (r.selected.empty()) {
    // Nothing to refine: the input, with the attributes a refinement adds.
    r.mesh = input;
    std::vector<int32_t> parent(input.hexes.size()), tag_of(input.hexes.size(), -1);
    std::iota(parent.begin(), parent.end(), 0);
    mesh_attributes_from_parents(input, parent, tag_of, r.mesh);
    r.stats.method = o.method;
    r.stats.initial_hexes = r.stats.final_hexes = input.hex_count();
    r.stats.final_nodes = input.point_count();
  } else {
    RefineResult refined;
    try {
      refined = placed ? std::move(*placed) : refine(method, input, Targets{r.selected}, o.refine);
    } catch (const PlacementError& e) {
      // `untangle` keeps the thesis' positions, the better start for smoothing, but on a
      // distorted input they can leave a child no untangling saves (ecr_cap.mesh, two passes:
      // real_meshes.md); `optimized` starts from the reference positions and may not. The
      // counts can differ (placement retargets), never the validity.
      if (!o.smooth || o.refine.placement.method != PlacementMethod::untangle) throw;
      RefineOptions optimized = o.refine;
      optimized.placement.method = PlacementMethod::optimized;
      refined = refine(method, input, Targets{r.selected}, optimized);
      r.placement_used = PlacementMethod::optimized;
      r.placement_warning = std::string("the untangle start was refused (") + e.what() +
                            "); placed by optimized instead";
    }
    r.mesh = std::move(refined.mesh);
    r.stats = std::move(refined.stats);
  }
  clock.end("refine");
  clock.begin("check");
  std::vector<uint8_t> is_child;  // per output hex: made by refining an input hex
  int64_t children = 0;
  {
    // A refined parent's children are a level above it (the input's own levels, if any, kept).
    const std::vector<int32_t>* parent = mesh_find_attribute(r.mesh, attribute_parent_hex);
    const std::vector<int32_t>* level = mesh_find_attribute(r.mesh, attribute_refinement_level);
    const std::vector<int32_t>* input_level =
        mesh_find_attribute(input, attribute_refinement_level);
    // Both passes over the output on every thread (a parent marked by two threads gets the
    // same 1 from each).
    const int threads = o.refine.threads;
    constexpr int64_t chunk_hexes = 1 << 16;
    std::vector<uint8_t> refined(input.hexes.size(), 0);
    if (parent && level)
      parallel_chunks(threads, r.mesh.hex_count(), chunk_hexes, [&](int64_t, int64_t b, int64_t e) {
        for (int64_t h = b; h < e; ++h) {
          const int32_t p = (*parent)[h];
          if ((*level)[h] > (input_level ? (*input_level)[p] : 0))
            std::atomic_ref<uint8_t>(refined[p]).store(1, std::memory_order_relaxed);
        }
      });
    for (int32_t h = 0; h < input.hex_count(); ++h)
      if (refined[h]) {
        ++r.refined_parents;
        r.refined_parents_min_scaled_jacobian = std::min(r.refined_parents_min_scaled_jacobian,
                                                         hex_scaled_jacobian(hex_points(input, h)));
      }
    is_child.resize(r.mesh.hexes.size(), 0);
    if (parent && level) {
      std::vector<int64_t> chunk_children(
          static_cast<size_t>(parallel_chunk_count(r.mesh.hex_count(), chunk_hexes)), 0);
      parallel_chunks(threads, r.mesh.hex_count(), chunk_hexes,
                      [&](int64_t chunk, int64_t b, int64_t e) {
                        for (int64_t h = b; h < e; ++h)
                          chunk_children[chunk] += is_child[h] = refined[(*parent)[h]];
                      });
      for (int64_t c : chunk_children) children += c;
    }
  }
  // The minimum over the children: the checker's own when every hex is one (a full refinement,
  // where a second pass would cost as much as the checker's quality samples), else a pass over
  // them alone.
  auto children_min = [&](const MeshCheckReport& check) {
    if (children == r.mesh.hex_count()) return check.min_scaled_jacobian;
    double m = 1;
    for (int32_t h = 0; h < r.mesh.hex_count(); ++h)
      if (is_child[h]) m = std::min(m, hex_scaled_jacobian(hex_points(r.mesh, h)));
    return m;
  };

  // The final mesh is the smoothed one when there is a refined region to smooth.
  std::vector<int32_t> smooth_region;
  if (o.smooth) smooth_region = mesh_refined_hexes(r.mesh);
  // Checks the mesh; the check of the final mesh runs beside its write to `out` when there is
  // more than one thread (the writer takes a thread of its own; one thread: one after the
  // other). The written file becomes `out` only once the verdict allows it: returns false, with
  // nothing written, when it does not.
  // The input's boundary surface, which both checks and the smoothing test faces against:
  // built once, before the first check (its cost the check's).
  std::optional<ReferenceSurface> input_surface;
  auto mesh_check_and_write = [&](const std::string& stage, MeshCheckReport& check,
                                  double& children_min_scaled_jacobian, bool final_mesh) {
    std::optional<StagedMeshWrite> staged;
    if (final_mesh && !out.empty() && o.refine.threads > 1) {
      clock.begin(stage == "check" ? "check and write" : "check (smoothed) and write");
      staged.emplace(out, r.mesh, o.write);
    }
    check = mesh_check(r.mesh, &input, o.refine.threads, &*input_surface);
    children_min_scaled_jacobian = children_min(check);
    const double writer_cpu = staged ? staged->cpu_seconds_so_far() : 0.0;
    clock.end(stage);
    r.stage_cpu_seconds[stage] -= writer_cpu;  // the writer's thread is the write stage's
    if (!verdict_allows(check, o, r.ablation)) return false;
    if (final_mesh && !out.empty()) {
      if (!staged) {
        clock.begin("write");
        staged.emplace(out, r.mesh, o.write);
      }
      try {
        staged->commit();
      } catch (const InputError& e) {
        throw OutputWriteError(e.what());  // names the output: no input prefix (below)
      }
      r.stage_seconds["write"] = staged->seconds();
      r.stage_cpu_seconds["write"] = staged->cpu_seconds();
      if (o.verbose)
        *o.verbose << "hexrefine: write " << std::fixed << std::setprecision(3) << staged->seconds()
                   << " s" << (o.refine.threads > 1 ? " (beside the check)" : "") << std::endl;
    }
    return true;
  };

  input_surface.emplace(input, o.refine.threads);
  if (!mesh_check_and_write("check", r.check, r.children_min_scaled_jacobian,
                            smooth_region.empty()))
    refine_verdict_enforce(r.check, r.mesh, input, o, r.ablation);
  if (!smooth_region.empty()) {
    SmoothOptions so = o.smoothing;
    so.region_hexes = std::move(smooth_region);
    // Boundary nodes the refinement made slide within the input face or edge they subdivide,
    // the input's boundary nodes stay: the smoothed mesh is checked against the input again.
    const BoundaryReference reference =
        boundary_reference_build(input, topology_build(input, TopologyParts::faces));
    so.reference = &reference;
    if (o.smoothing_surface_guard) so.reference_surface = &*input_surface;
    so.reference_nodes = input.point_count();
    so.threads = o.refine.threads;
    const std::vector<Eigen::Vector3d> unsmoothed = r.mesh.points;
    clock.begin("smooth");
    r.smoothing = mesh_smooth(r.mesh, so);
    // The start's guarantee (PipelineOptions::smoothing_start_fallback): the minimum plain
    // `refine` reaches, placed by `optimized`.
    double optimized_min = -std::numeric_limits<double>::infinity();
    PipelineOptions again = o;
    again.refine.placement.method = PlacementMethod::optimized;
    std::optional<RefineResult> plain;
    if (o.smoothing_start_fallback && o.refine.placement.method == PlacementMethod::untangle &&
        !r.placement_used) {
      try {
        plain = refine(method, input, Targets{r.selected}, again.refine);
        optimized_min = mesh_min_scaled_jacobian(plain->mesh);
      } catch (const PlacementError&) {
        // optimized refuses: nothing to fall back on
      }
    }
    clock.end("smooth");
    std::optional<PipelineResult> restarted;
    if (r.smoothing->min_scaled_jacobian_after < optimized_min) {
      try {
        // The restart takes the optimized refinement just made instead of refining again.
        restarted = pipeline_run_writing(input, again, out, &*plain);
      } catch (const OperationError&) {
        // The optimized refinement failed a check the untangle one passed (nothing was
        // written): the untangle start stands.
      }
    }
    if (restarted) {
      PipelineResult& b = *restarted;
      b.placement_used = PlacementMethod::optimized;
      std::ostringstream why;
      why << "smoothing from untangle reached " << r.smoothing->min_scaled_jacobian_after
          << ", below the " << optimized_min
          << " of the optimized placement unsmoothed; placed by optimized and smoothed from there";
      b.placement_warning = why.str();
      // The first start's stages count: both refinements, both smoothings.
      for (const auto& [stage, seconds] : r.stage_seconds) b.stage_seconds[stage] += seconds;
      for (const auto& [stage, seconds] : r.stage_cpu_seconds)
        b.stage_cpu_seconds[stage] += seconds;
      b.stage_seconds["total"] = seconds_since(start);
      return std::move(b);
    }
    plain.reset();  // not needed past the comparison
    clock.begin("check (smoothed)");
    r.smoothed_check.emplace();
    r.smoothed_children_min_scaled_jacobian.emplace();
    // Smoothing never fails a valid refinement. The surface guard keeps the faces it moves on
    // the input surface as the checker tests it; should the checker still reject the smoothed
    // mesh, it is smoothed again with the corners of the rejected hexes pinned (at most
    // smoothing_pin_rounds times), and then the nodes of the defect hexes and of the hexes
    // around them go back to their unsmoothed positions, round by round; after
    // smoothing_undo_rounds rounds all of them do. The refined mesh passed the same check, so
    // the last resort is valid.
    int pin_rounds = 0;
    std::vector<int32_t> pinned;  // the corners of the rejected hexes, ascending
    for (int round = 0;; ++round) {
      const bool whole = round == smoothing_undo_rounds;
      if (mesh_check_and_write("check_smoothed", *r.smoothed_check,
                               *r.smoothed_children_min_scaled_jacobian, true))
        break;
      if (whole) {
        // Unreachable for a valid refined mesh; kept so that a checker disagreeing with itself
        // names the stage instead of looping.
        throw OperationError("smoothing was undone and the mesh still fails the check:" +
                             defects_text(*r.smoothed_check, r.mesh));
      }
      std::string why;
      for (const std::string& d : mesh_check_defects(*r.smoothed_check))
        why += (why.empty() ? "" : "; ") + d;
      if (r.smoothing_warning.empty())
        r.smoothing_warning = "the smoothed mesh failed the check (" + why + ")";
      // The rejected faces are where a boundary node slid too far (their corners on the input
      // surface, the face cutting a chord across a bend). Pin the corners of the defect hexes at
      // their unsmoothed positions and smooth again from the refined mesh, up to
      // o.smoothing_pin_rounds times, before undoing anything: undoing afterwards also takes back
      // the moves that lifted the worst hexes (phm_rabbit random:0.02,1, selective: 0.058
      // smoothed, 0.011 after the undo).
      if (pin_rounds < o.smoothing_pin_rounds && !r.smoothed_check->defect_hexes.empty()) {
        ++pin_rounds;
        clock.end("check_smoothed");  // the undo bookkeeping since the check
        for (int32_t h : r.smoothed_check->defect_hexes)
          for (int32_t v : r.mesh.hexes[h]) pinned.push_back(v);
        std::sort(pinned.begin(), pinned.end());
        pinned.erase(std::unique(pinned.begin(), pinned.end()), pinned.end());
        so.fixed_nodes = o.smoothing.fixed_nodes;
        so.fixed_nodes.insert(so.fixed_nodes.end(), pinned.begin(), pinned.end());
        r.mesh.points = unsmoothed;
        clock.begin("smooth");
        const double first_seconds = r.smoothing->seconds;
        r.smoothing = mesh_smooth(r.mesh, so);
        r.smoothing->seconds += first_seconds;
        clock.end("smooth");
        round = -1;  // the undo rounds start again for the new smoothing
        continue;
      }
      int64_t undone = 0;
      auto undo = [&](int32_t h) {
        for (int32_t v : r.mesh.hexes[h])
          if (r.mesh.points[v] != unsmoothed[v]) {
            r.mesh.points[v] = unsmoothed[v];
            ++undone;
          }
      };
      if (round + 1 == smoothing_undo_rounds) {
        for (int32_t h = 0; h < r.mesh.hex_count(); ++h) undo(h);
        r.smoothing_warning += "; the whole smoothing was undone";
      } else {
        // The listed defect hexes (the checker names the lowest ids) and a ring around them.
        std::vector<uint8_t> near(r.mesh.points.size(), 0);
        for (int32_t h : r.smoothed_check->defect_hexes)
          for (int32_t v : r.mesh.hexes[h]) near[v] = 1;
        for (int32_t h = 0; h < r.mesh.hex_count(); ++h)
          if (std::any_of(r.mesh.hexes[h].begin(), r.mesh.hexes[h].end(),
                          [&](int32_t v) { return near[v]; }))
            undo(h);
        // A hex with some corners back and some smoothed can be worse than both meshes: undo
        // those too, until every hex is at least the unsmoothed minimum (the unsmoothed mesh
        // is, so this ends).
        for (bool again = true; again;) {
          again = false;
          const std::vector<double> q = mesh_scaled_jacobians(r.mesh);
          for (int32_t h = 0; h < r.mesh.hex_count(); ++h)
            if (q[h] < r.check.min_scaled_jacobian) {
              const int64_t before = undone;
              undo(h);
              again = again || undone > before;
            }
        }
      }
      r.smoothing_nodes_undone += undone;
    }
    if (pin_rounds > 0)
      r.smoothing_warning += "; smoothed again " + std::to_string(pin_rounds) +
                             (pin_rounds == 1 ? " time" : " times") + " with " +
                             std::to_string(so.fixed_nodes.size()) +
                             " nodes of rejected hexes pinned";
    if (r.smoothing_nodes_undone > 0) {
      r.smoothing_warning += "; " + std::to_string(r.smoothing_nodes_undone) +
                             " smoothed nodes went back to their unsmoothed positions";
      r.smoothing->min_scaled_jacobian_after = r.smoothed_check->min_scaled_jacobian;
      r.smoothing->mean_scaled_jacobian_after = r.smoothed_check->mean_scaled_jacobian;
    }
  }
  r.stage_seconds["total"] = seconds_since(start);
  r.peak_memory_mb = process_peak_memory_mb();
  return r;
}

/// PipelineOptions::smoothing_both_starts: both runs without a write, then the better one
/// written (both passed their checks, or they would have thrown).
PipelineResult pipeline_run_both_starts(const HexMesh& input, const PipelineOptions& o,
                                        const std::string& out) {
  const auto start = Clock::now();
  PipelineOptions first = o;
  first.smoothing_both_starts = false;
  first.smoothing_start_fallback = false;  // the second start is the optimized one
  PipelineResult kept = pipeline_run_writing(input, first, "");
  PipelineOptions second = first;
  second.refine.placement.method = PlacementMethod::optimized;
  std::optional<PipelineResult> other;
  // Where the untangle start was refused the first run was placed by optimized already.
  if (!kept.placement_used) try {
      other = pipeline_run_writing(input, second, "");
    } catch (const OperationError& e) {
      // optimized refused where untangle did not: the untangle start stands
      kept.placement_warning =
          std::string("the optimized start failed (") + e.what() + "); kept the untangle start";
    }
  auto final_min = [](const PipelineResult& r) {
    return r.smoothed_check ? r.smoothed_check->min_scaled_jacobian : r.check.min_scaled_jacobian;
  };
  if (other) {
    const double untangle_min = final_min(kept), optimized_min = final_min(*other);
    if (optimized_min > untangle_min) {
      std::swap(kept, *other);
      kept.placement_used = PlacementMethod::optimized;
      std::ostringstream why;
      why << "smoothed from both starts: " << optimized_min << " from optimized, " << untangle_min
          << " from untangle; kept optimized";
      kept.placement_warning = why.str();
    }
    for (const auto& [stage, seconds] : other->stage_seconds) kept.stage_seconds[stage] += seconds;
    for (const auto& [stage, seconds] : other->stage_cpu_seconds)
      kept.stage_cpu_seconds[stage] += seconds;
  }
  if (!out.empty()) {
    StagedMeshWrite staged(out, kept.mesh, o.write);
    try {
      staged.commit();
    } catch (const InputError& e) {
      throw OutputWriteError(e.what());  // names the output: no input prefix
    }
    kept.stage_seconds["write"] = staged.seconds();
    kept.stage_cpu_seconds["write"] = staged.cpu_seconds();
  }
  kept.stage_seconds["total"] = seconds_since(start);
  kept.peak_memory_mb = process_peak_memory_mb();
  return kept;
}

}  // namespace

PipelineResult pipeline_run(const HexMesh& input, const PipelineOptions& o) {
  return pipeline_run_writing(input, o, "");
}

PipelineResult pipeline_run_files(const std::string& in, const std::string& out,
                                  const PipelineOptions& options) {
  const auto start = Clock::now();
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
  r.stage_seconds["total"] = seconds_since(start);
  r.peak_memory_mb = process_peak_memory_mb();
  return r;
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
  j["check"] = r.check;
  if (r.smoothing) {
    j["smoothing"] = {{"stats", *r.smoothing},
                      {"check", *r.smoothed_check},
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
