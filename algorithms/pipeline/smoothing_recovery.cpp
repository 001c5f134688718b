#include "algorithms/pipeline/smoothing_recovery.hpp"

#include <algorithm>

#include "algorithms/pipeline/pipeline_check.hpp"
#include "mesh/error.hpp"
#include "mesh/quality.hpp"

namespace hexrefine {

namespace {

/// Puts the smoothed corners of hex `h` back; returns how many moved.
int64_t hex_smoothing_undo(HexMesh& mesh, const std::vector<Eigen::Vector3d>& unsmoothed,
                           int32_t h) {
  int64_t undone = 0;
  for (int32_t v : mesh.hexes[h])
    if (mesh.points[v] != unsmoothed[v]) {
      mesh.points[v] = unsmoothed[v];
      ++undone;
    }
  return undone;
}

/// Smooths the start again from its refined points with `pinned` (and the options' own fixed
/// nodes) held, billed to "smooth"; its smoothing time adds up.
void smoothing_start_smooth_pinned(PipelineRun& run, SmoothingStart& s,
                                   const std::vector<int32_t>& pinned) {
  SmoothOptions& so = s.smoothing_options;
  so.fixed_nodes = run.options.smoothing.fixed_nodes;
  so.fixed_nodes.insert(so.fixed_nodes.end(), pinned.begin(), pinned.end());
  s.mesh.points = s.unsmoothed;
  run.clock.begin("smooth");
  const double first_seconds = s.smoothing->seconds;
  s.smoothing = mesh_smooth(s.mesh, so);
  s.smoothing->seconds += first_seconds;
  run.clock.end("smooth");
}

}  // namespace

SmoothingRecoveryStep smoothing_recovery_step(bool allowed, int undo_round, int pin_rounds,
                                              int pin_rounds_allowed, bool defects_listed) {
  if (allowed) return SmoothingRecoveryStep::accept;
  // Unreachable for a valid refined mesh (the whole smoothing is undone by then); kept so that a
  // checker disagreeing with itself names the stage instead of looping.
  if (undo_round == smoothing_undo_rounds) return SmoothingRecoveryStep::fail;
  if (pin_rounds < pin_rounds_allowed && defects_listed) return SmoothingRecoveryStep::pin;
  if (undo_round + 1 == smoothing_undo_rounds) return SmoothingRecoveryStep::undo_all;
  return SmoothingRecoveryStep::undo_around;
}

std::string smoothing_recovery_warning_first(const MeshCheckReport& check) {
  std::string why;
  for (const std::string& d : mesh_check_defects(check)) why += (why.empty() ? "" : "; ") + d;
  return "the smoothed mesh failed the check (" + why + ")";
}

std::string smoothing_recovery_warning_last(int pin_rounds, size_t pinned_nodes,
                                            int64_t nodes_undone) {
  std::string warning;
  if (pin_rounds > 0)
    warning += "; smoothed again " + std::to_string(pin_rounds) +
               (pin_rounds == 1 ? " time" : " times") + " with " + std::to_string(pinned_nodes) +
               " nodes of rejected hexes pinned";
  if (nodes_undone > 0)
    warning += "; " + std::to_string(nodes_undone) +
               " smoothed nodes went back to their unsmoothed positions";
  return warning;
}

void smoothing_pins_add(std::vector<int32_t>& pinned, const HexMesh& mesh,
                        const std::vector<int32_t>& defect_hexes) {
  for (int32_t h : defect_hexes)
    for (int32_t v : mesh.hexes[h]) pinned.push_back(v);
  std::sort(pinned.begin(), pinned.end());
  pinned.erase(std::unique(pinned.begin(), pinned.end()), pinned.end());
}

int64_t mesh_smoothing_undo_all(HexMesh& mesh, const std::vector<Eigen::Vector3d>& unsmoothed) {
  int64_t undone = 0;
  for (int32_t h = 0; h < mesh.hex_count(); ++h) undone += hex_smoothing_undo(mesh, unsmoothed, h);
  return undone;
}

int64_t mesh_smoothing_undo_around(HexMesh& mesh, const std::vector<Eigen::Vector3d>& unsmoothed,
                                   const std::vector<int32_t>& defect_hexes,
                                   double unsmoothed_min) {
  int64_t undone = 0;
  // The listed defect hexes (the checker names the lowest ids) and a ring around them.
  std::vector<uint8_t> near(mesh.points.size(), 0);
  for (int32_t h : defect_hexes)
    for (int32_t v : mesh.hexes[h]) near[v] = 1;
  for (int32_t h = 0; h < mesh.hex_count(); ++h)
    if (std::any_of(mesh.hexes[h].begin(), mesh.hexes[h].end(), [&](int32_t v) { return near[v]; }))
      undone += hex_smoothing_undo(mesh, unsmoothed, h);
  for (bool again = true; again;) {
    again = false;
    const std::vector<double> q = mesh_scaled_jacobians(mesh);
    for (int32_t h = 0; h < mesh.hex_count(); ++h)
      if (q[h] < unsmoothed_min) {
        const int64_t moved = hex_smoothing_undo(mesh, unsmoothed, h);
        undone += moved;
        again = again || moved > 0;
      }
  }
  return undone;
}

void smoothing_recover(PipelineRun& run, SmoothingStart& s, const std::string& out) {
  const PipelineOptions& o = run.options;
  run.clock.begin("check (smoothed)");
  s.smoothed_check.emplace();
  s.smoothed_children_min_scaled_jacobian.emplace();
  int pin_rounds = 0;
  std::vector<int32_t> pinned;  // the corners of the rejected hexes, ascending
  for (int round = 0;; ++round) {
    const bool allowed =
        pipeline_check_and_write(run, "check_smoothed", s.mesh, s.children, *s.smoothed_check,
                                 *s.smoothed_children_min_scaled_jacobian, out);
    const SmoothingRecoveryStep step =
        smoothing_recovery_step(allowed, round, pin_rounds, o.smoothing_pin_rounds,
                                !s.smoothed_check->defect_hexes.empty());
    if (step == SmoothingRecoveryStep::accept) break;
    if (step == SmoothingRecoveryStep::fail)
      throw OperationError("smoothing was undone and the mesh still fails the check:" +
                           mesh_check_defects_text(*s.smoothed_check, s.mesh));
    if (s.smoothing_warning.empty())
      s.smoothing_warning = smoothing_recovery_warning_first(*s.smoothed_check);
    if (step == SmoothingRecoveryStep::pin) {
      // The rejected faces are where a boundary node slid too far (their corners on the input
      // surface, the face cutting a chord across a bend): pinned at their unsmoothed positions.
      ++pin_rounds;
      run.clock.end("check_smoothed");  // the bookkeeping since the check
      smoothing_pins_add(pinned, s.mesh, s.smoothed_check->defect_hexes);
      smoothing_start_smooth_pinned(run, s, pinned);
      round = -1;  // the undo rounds start again for the new smoothing
      continue;
    }
    if (step == SmoothingRecoveryStep::undo_all) {
      s.smoothing_nodes_undone += mesh_smoothing_undo_all(s.mesh, s.unsmoothed);
      s.smoothing_warning += "; the whole smoothing was undone";
    } else {
      s.smoothing_nodes_undone += mesh_smoothing_undo_around(
          s.mesh, s.unsmoothed, s.smoothed_check->defect_hexes, s.check.min_scaled_jacobian);
    }
  }
  s.smoothing_warning += smoothing_recovery_warning_last(
      pin_rounds, s.smoothing_options.fixed_nodes.size(), s.smoothing_nodes_undone);
  if (s.smoothing_nodes_undone > 0) {
    s.smoothing->min_scaled_jacobian_after = s.smoothed_check->min_scaled_jacobian;
    s.smoothing->mean_scaled_jacobian_after = s.smoothed_check->mean_scaled_jacobian;
  }
}

}  // namespace hexrefine
