#pragma once
/// \file
/// The refinement pipeline, one function for every front end (the CLI's `refine`, the experiment
/// runner, the benchmarks, the Python module):
///   read -> select -> refine (per pass: plan, apply, place nodes) -> check -> smooth -> check
///   -> write,
/// each stage timed (stage_seconds), the report one JSON object (pipeline_report; its "check"
/// is the mesh written's), each stage a function in a file of its own (pipeline.cpp lists them).
///
/// Verdicts: the result is checked against the input by the project's checker
/// (mesh/conformity.hpp). Without an ablation switch (ranking, propagation or ebe_only off) or
/// allow_inverted, an invalid result is an error: InputError if the input itself fails the
/// checker (bad input, not a refiner failure), OperationError otherwise, naming the defects and
/// the input hexes they descend from; nothing is returned or written. With an ablation switch the
/// result may be non-conformal by design and is returned with the checker's counts.
/// Smoothing (optional) moves the nodes of the refined region and two layers around it
/// (algorithms/placement/smoothing.hpp), boundary nodes on the input's boundary surface (the
/// input's own boundary nodes too, over the input faces around them), and the result is checked
/// against the input again. The smoothing keeps every boundary face it moves passing the
/// checker's own surface test (mesh/reference_surface.hpp), so the check agrees with it by
/// construction. Smoothing never turns a valid refinement into an error: should the checker
/// still reject the smoothed mesh, it is smoothed again from the refined mesh with the corners
/// of the rejected hexes pinned (smoothing_pin_rounds times at most), and then the smoothed nodes
/// around the defects go back to their unsmoothed positions (at worst all of them); the report's
/// smoothing.warning says so and smoothing.nodes_undone counts them. An error names the stage that
/// failed: the input only when the input itself fails the checker.

#include <cstdint>
#include <iosfwd>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "algorithms/placement/smoothing.hpp"
#include "algorithms/refiners/refiner.hpp"
#include "mesh/conformity.hpp"
#include "mesh/hex_mesh.hpp"
#include "mesh/io.hpp"

namespace hexrefine {

/// The node placement of a run that names none: `untangle` when the run smooths, `optimized`
/// otherwise. Smoothing raises the quality from positions that have not yet used up the
/// edge-ratio room (PlacementOptions::max_edge_ratio), so from untangle it ends higher, and
/// sooner, than from optimized (docs/placement-and-smoothing.md, "Which placement to smooth
/// from"; results/smooth_start.md).
/// Every front end (CLI `refine`, the runner's cases, the Python module) resolves an absent
/// placement through this, and the report's options.placement.method names the one used.
inline PlacementMethod pipeline_default_placement(bool smooth) {
  return smooth ? PlacementMethod::untangle : PlacementMethod::optimized;
}

/// SmoothOptions with two layers around the refined region.
inline SmoothOptions pipeline_smoothing_defaults() {
  SmoothOptions o;
  o.layers = 2;
  return o;
}

struct PipelineOptions {
  std::string method = "selective";  ///< a name of refine_methods()
  /// Selection specs (mesh/selection.hpp), united; ignored when `targets` is set.
  std::vector<std::string> select;
  std::optional<std::vector<int32_t>> targets;  ///< explicit target hex ids instead of `select`
  RefineOptions refine;
  bool smooth = false;
  /// How to smooth: the region is the refined hexes (region_hexes is replaced) and two layers
  /// around them; the reference is the input.
  SmoothOptions smoothing = pipeline_smoothing_defaults();
  /// false: the smoothing moves boundary nodes without the checker's surface test (its
  /// reference_surface unset), which the checker may then reject; for ablation and for the
  /// tests of the retries above.
  bool smoothing_surface_guard = true;
  /// Smoothings again with the rejected hexes' corners pinned before any node is undone (<= 0:
  /// none).
  int smoothing_pin_rounds = 3;
  /// `--smooth` from `untangle` (the default start, pipeline_default_placement): when the
  /// smoothing ends below the minimum the `optimized` placement gives unsmoothed (plain
  /// `refine`'s default), the optimized start is checked and smoothed too and kept instead,
  /// which never ends below that minimum (a few cases of the real-mesh study ended below it:
  /// docs/placement-and-smoothing.md, "--smooth never ends below plain refine"). So `--smooth`
  /// never ends below plain `refine` where the checker accepts the smoothing at once, as on
  /// every case of the study; after a rejection the pin and undo rounds hold only the untangle
  /// start's own minimum. Should the optimized start fail a check, the untangle start stands.
  /// The optimized placement is billed to the smooth stage. The policy:
  /// smoothing_start_choose_fallback (algorithms/pipeline/smoothing_start.hpp). false: one
  /// start only (ablation, tests).
  bool smoothing_start_fallback = true;
  /// `--smooth` from both starts (`refine --smooth-both-starts`): placed by `untangle` and
  /// smoothed, placed by `optimized` and smoothed, and the one with the higher smoothed minimum
  /// kept (the untangle one on a tie; the policy: smoothing_start_choose_both); both
  /// refinements and smoothings are billed, about twice the time. Neither start is the better
  /// one on every case of the real-mesh study (docs/placement-and-smoothing.md, "Both starts";
  /// results/smoothing_starts.md). Only where the start is `untangle` (the default with
  /// smoothing).
  bool smoothing_both_starts = false;
  /// Refuse before refining when n * 27^passes could exceed this many output hexes (int32 ids).
  int64_t max_hexes = std::numeric_limits<int32_t>::max();
  MeshWriteOptions write;  ///< how pipeline_run_files writes the output
  /// Where stage lines go as stages end ("select: 0.012 s"), or nullptr.
  std::ostream* verbose = nullptr;
  /// Where the running stage is named as it starts ("\rhexrefine: check ..."), one line
  /// overwritten by the next and cleared at the end; the CLI passes stderr when it is a
  /// terminal. nullptr: nothing.
  std::ostream* progress = nullptr;
};

struct PipelineResult {
  HexMesh mesh;  ///< the refined (and smoothed) mesh
  RefineStats stats;
  std::vector<int32_t> selected;  ///< the targets, ascending
  std::string selection_warning;  ///< non-empty when the selection matched nothing
  /// Non-empty when the smoothing start (`untangle`, the thesis' positions) was refused and the
  /// refinement was placed by `optimized` instead (what it said, and that): a valid input is
  /// never refused for the start its smoothing prefers (report: refine.placement_warning).
  std::string placement_warning;
  /// The placement the refinement was placed by when it is not the options' (see above); the
  /// report's options.placement.method names it.
  std::optional<PlacementMethod> placement_used;
  /// Input hexes that were refined (their children's refinement level is above theirs) and their
  /// lowest scaled Jacobian (1 if none): what a refinement's quality is fairly
  /// compared with.
  int64_t refined_parents = 0;
  double refined_parents_min_scaled_jacobian = 1;
  /// Lowest scaled Jacobian over the children of the refined parents (1 if none). The mesh-wide
  /// minimum (check) holds the untouched input hexes too, which may be worse than every refined
  /// parent: this is the figure to set against refined_parents_min_scaled_jacobian.
  double children_min_scaled_jacobian = 1;
  /// The same hexes after smoothing (which also moves nodes of input hexes around them: those
  /// are held by its guarantee that the mesh-wide minimum never decreases).
  std::optional<double> smoothed_children_min_scaled_jacobian;
  /// The refined mesh against the input, before any smoothing. Without smoothing it is the
  /// output's check; with smoothing the output's is smoothed_check (output_check() is the one
  /// of the mesh returned and written). Report: "check" without smoothing,
  /// "smoothing.refined_check" with it.
  MeshCheckReport check;
  std::optional<SmoothStats> smoothing;
  /// The smoothed mesh against the input, set when smoothing ran: the output's check (report:
  /// "check").
  std::optional<MeshCheckReport> smoothed_check;
  /// The check of the mesh returned and written: the smoothed mesh's when smoothing ran, else
  /// the refined mesh's.
  const MeshCheckReport& output_check() const { return smoothed_check ? *smoothed_check : check; }
  /// Smoothed nodes put back to their unsmoothed positions because the checker rejected the
  /// smoothed mesh around them (0 when it passed at once), and what the check said then (empty
  /// when it passed at once): smoothing returns a valid mesh, at worst the unsmoothed one.
  int64_t smoothing_nodes_undone = 0;
  std::string smoothing_warning;
  /// Seconds per stage: read, select, refine, check, smooth, check_smoothed, write, total
  /// (read and write only from pipeline_run_files).
  std::map<std::string, double> stage_seconds;
  /// Process CPU seconds per stage (all threads; "write" is the writer thread's own and the
  /// final check's leaves it out when they overlap): on a shared machine the better measure of
  /// single-threaded stages, whose wall time includes waiting.
  std::map<std::string, double> stage_cpu_seconds;
  double peak_memory_mb = 0;  ///< the process's peak resident size when the pipeline ended
  /// A refinement switch that may give a non-conformal mesh by design (ablation).
  bool ablation = false;
};

/// Runs select -> refine -> check -> smooth -> check on an in-memory mesh. Throws InputError for
/// bad options, specs or input, OperationError when the method refuses, the size bound is
/// exceeded or the result is invalid (see the file comment). An empty selection is not an error:
/// the mesh is returned unchanged (with the attributes a refinement adds) and the warning set.
PipelineResult pipeline_run(const HexMesh& input, const PipelineOptions& options);

/// read `in` -> pipeline_run -> write `out` (atomically; not written when the pipeline throws).
/// `out` may be empty (nothing written). Adds the read and write stages. With more than one
/// thread (options.refine.threads) the final mesh is written beside its check, on a thread of
/// its own (mesh/staged_write.hpp): the file becomes `out` only once the verdict allows it, so
/// the result is the same as writing after the check, and the two stages' times overlap
/// ("write" is the writer thread's wall and CPU time; "check" leaves that thread's CPU out).
PipelineResult pipeline_run_files(const std::string& in, const std::string& out,
                                  const PipelineOptions& options);

/// The version of the report's keys (pipeline_report's "schema_version", stamped on every run
/// record too): raised whenever a key is renamed, removed or changes its type or unit, or a key
/// is added outside the objects the schema leaves open (docs/schema/report.schema.json; the
/// changelog is in docs/report.md).
inline constexpr int pipeline_report_schema_version = 2;

/// The report: "method", "options" (RefineOptions plus "smooth"), "selection" ({"specs",
/// "hexes", "warning"?}), "refine" (RefineStats), "refined_parents" ({"hexes",
/// "min_scaled_jacobian", "children_min_scaled_jacobian",
/// "smoothed_children_min_scaled_jacobian"?}), "check" (the output's: output_check()),
/// "smoothing"? ({"stats", "refined_check" (the refined mesh's before smoothing), "nodes_undone",
/// "max_sweeps", "max_joint_iterations", "max_joint_rounds", "both_starts", "warning"?}: the
/// three max_ are the smoothing's budget, options.smoothing's), "stage_seconds",
/// "stage_cpu_seconds", "peak_memory_mb". The CLI writes it with --report, the runner adds its
/// identification fields to it, the Python module returns it as a dict.
nlohmann::json pipeline_report(const PipelineResult& result, const PipelineOptions& options);

/// Peak resident set size of this process in MB (getrusage), 0 if unknown.
double process_peak_memory_mb();

}  // namespace hexrefine
