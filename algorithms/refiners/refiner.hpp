#pragma once
/// \file
/// The interface both refiners share (the Selective Approach and Harris-style sheet refinement):
/// the same targets, options, statistics and result, and one registry of methods by name, so
/// that every front end (CLI, runner, benchmarks, Python) runs them alike.
///
/// A method decides one pass and returns a plan (template_engine.hpp); `refine` runs the passes:
/// for each, the method's plan, the engine's application of it, then node placement
/// (node_placement.hpp) over the new nodes, then the next pass's targets.

#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "algorithms/placement/node_placement.hpp"
#include "algorithms/templates/template_engine.hpp"
#include "algorithms/templates/template_reference.hpp"
#include "mesh/hex_mesh.hpp"
#include "mesh/topology.hpp"

namespace hexrefine {

/// The hexes selected for refinement: ascending, unique ids into the input mesh.
struct Targets {
  std::vector<int32_t> hexes;
};

/// What joins a pass's targets when a method that uses a buffer (the Selective Approach) refines
/// more than once (see refine()).
enum class PassBuffer {
  /// The thesis' rule, read from Table H-2's counts: every pass (the first included) refines the
  /// descendants of the user's targets plus one layer of hexes of the current mesh face-adjacent
  /// to them; the layer's children are not carried into the next pass, so every transition of
  /// the next pass sits in an unrefined-by-transition cube. The one rule of the three that gives
  /// H-2's count and minimum exactly (results/methods.md, choice 1).
  layer,
  /// The descendants of the user's targets only: each pass's transitions are refined again by
  /// the next pass's templates, which degrades them pass after pass (results/methods.md,
  /// choice 1).
  none,
  /// Every child of the previous pass's transitions joins the next pass's targets, cumulatively:
  /// H-2's minimum with more hexes than the thesis counts (results/methods.md, choice 1).
  transitions,
};
NLOHMANN_JSON_SERIALIZE_ENUM(PassBuffer, {{PassBuffer::layer, "layer"},
                                          {PassBuffer::none, "none"},
                                          {PassBuffer::transitions, "transitions"}})

/// "layer", "none" or "transitions"; InputError listing them otherwise.
PassBuffer pass_buffer_from_name(std::string_view name);

/// In what order the Selective Approach's directional refinement visits the (hex, direction)
/// pairs it must refine (each step followed by the propagation scheme).
enum class DirectionalOrder {
  /// Rank after rank: all pairs of a rank (or, without the ranking system, all hexes' local
  /// x, then y, then z) in one step. On every case tried the output is the same as by_hex's
  /// (results/methods.md, choice 2): the propagation scheme closes the split edges to the same
  /// set.
  by_rank,
  /// Hex after hex, each hex's directions in rank order (without ranking: local x, y, z), "until
  /// the hexahedron is completely refined and the algorithm moves onto the next hexahedron"
  /// (thesis section 5.3.1, Table 5-1 lines 14-19). The default.
  by_hex,
};
NLOHMANN_JSON_SERIALIZE_ENUM(DirectionalOrder, {{DirectionalOrder::by_rank, "by_rank"},
                                                {DirectionalOrder::by_hex, "by_hex"}})

struct RefineOptions {
  bool ranking = true;  ///< Selective: rank directions across directional groups.
  DirectionalOrder directional_order = DirectionalOrder::by_hex;  ///< Selective
  bool propagation = true;  ///< Selective: propagation scheme after each directional step.
  bool ebe_only = false;    ///< Selective: element-by-element only (as Schneiders).
  int passes = 1;           ///< Refine the region this many times.
  PassBuffer buffer = PassBuffer::layer;  ///< Selective, passes > 1: what joins the targets.
  bool allow_inverted = false;            ///< Refine an input with inverted hexes (no refusal).
  /// Threads for applying whole-hex templates (the assembly of the output) and for the node
  /// optimizer of the placement (and, in the pipeline, smoothing, the check and the write).
  /// The output is identical for every count: node ids are claimed in hex order first, then
  /// the positions and children are written in parallel; the optimizer visits the nodes of one
  /// dependency level at once. 1: everything in the calling thread.
  int threads = 1;
  PlacementOptions placement;  ///< where the new nodes go after each pass
};
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(RefineOptions, ranking, directional_order,
                                                propagation, ebe_only, passes, buffer,
                                                allow_inverted, threads, placement)

/// Statistics of one refinement. Fields a method does not use stay zero.
struct RefineStats {
  std::string method;
  int64_t initial_hexes = 0;
  int64_t final_hexes = 0;
  int64_t final_nodes = 0;
  std::map<std::string, int64_t> hexes_per_template;  ///< output hexes by template name
  int64_t hexes_created = 0;
  int64_t hexes_deleted = 0;
  int64_t directional_hexes = 0;
  int64_t directional_groups = 0;
  int64_t ranks = 0;
  int64_t doublets_resolved = 0;
  std::map<std::string, int64_t> doublets_by_rule;  ///< doublets_resolved split by rule
  int64_t edges_split_by_propagation = 0;
  int64_t sheet_passes = 0;
  int64_t added_targets = 0;
  int64_t self_intersection_cases = 0;
  /// Input edges the selective refiner split to avoid an adjustment it could not carry out;
  /// each cost one restart of the pass (phase "restarted_passes" holds their time).
  int64_t input_edges_forced = 0;
  /// Hexes made targets of their pass because node placement found no valid position for the
  /// children a transition template gave them (refiner.cpp); each such pass was planned again.
  int64_t placement_retargets = 0;
  /// Children still inverted after placement and its retargets that the fallback made valid by
  /// moving the nodes around them, the refined parents' own (input) nodes included, as
  /// smoothing does (refiner.cpp); 0 when placement alone sufficed.
  int64_t placement_fallback_untangled = 0;
  PlacementStats placement;
  /// Seconds per phase: the method's own (marking, element_by_element, ranking, ...) and the
  /// driver's (plan, apply, placement, total).
  std::map<std::string, double> phase_seconds;
  double time_seconds = 0;  ///< refinement with placement, no I/O
};
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(
    RefineStats, method, initial_hexes, final_hexes, final_nodes, hexes_per_template, hexes_created,
    hexes_deleted, directional_hexes, directional_groups, ranks, doublets_resolved,
    doublets_by_rule, edges_split_by_propagation, sheet_passes, added_targets,
    self_intersection_cases, input_edges_forced, placement_retargets, placement_fallback_untangled,
    placement, phase_seconds, time_seconds)

/// Fills stats.hexes_per_template from a list of per-hex template tags.
void stats_count_templates(RefineStats& stats, const std::vector<int32_t>& tags);

/// Completes the statistics of a refinement that produced `mesh` in `seconds`: final counts,
/// hexes per template, time (and phase "total").
void refine_stats_finish(RefineStats& stats, const HexMesh& mesh, double seconds);

/// Output of a refinement: the new mesh (attributes "template_tag", "refinement_level",
/// "parent_hex", plus the input's, inherited) and its statistics.
struct RefineResult {
  HexMesh mesh;
  RefineStats stats;
};

/// A refinement method: decides one pass over `mesh`. `targets` are ascending, unique and in
/// range; `topology` was built from `mesh` (TopologyParts::all). The plan's uses mark the
/// targets (TemplateUse::target). Throws OperationError naming the hexes where the method cannot
/// handle the configuration. The plan's templates are `templates`' (its standard templates and
/// directional configurations, which it must outlive).
using RefinePlanFn = RefinementPlan (*)(const HexMesh& mesh, const HexTopology& topology,
                                        const std::vector<int32_t>& targets,
                                        const RefineOptions& options, RefineStats& stats,
                                        const TemplateLibrary& templates);

struct RefineMethod {
  std::string_view name;
  std::string_view description;  ///< one line, for --help
  RefinePlanFn plan;
  /// RefineOptions::buffer applies (the method's transitions would otherwise be refined again by
  /// the next pass's templates).
  bool uses_buffer;
};

/// Every method, in a fixed order ("selective", "sheet").
std::span<const RefineMethod> refine_methods();

/// The method called `name`; InputError listing the known names otherwise.
const RefineMethod& refine_method(std::string_view name);

/// The checks refine() makes before any work: targets ascending, unique and in range, passes and
/// threads >= 1, and (unless options.allow_inverted) no input hex with a scaled Jacobian <= 0.
/// Throws InputError naming `method` and the offending hexes (with their scaled Jacobians).
void refine_input_validate(const HexMesh& mesh, const Targets& targets,
                           const RefineOptions& options, std::string_view method);

/// Refines `targets` of `mesh` by `method`, options.passes times: each pass plans, applies the
/// plan and places the new nodes; the next pass refines the descendants of the user's targets,
/// with, for methods that use a buffer and passes > 1, options.buffer's additions (PassBuffer).
/// Throws InputError for invalid targets or options, or (unless options.allow_inverted) an input
/// with hexes of scaled Jacobian <= 0, naming them; OperationError where the method refuses or no
/// valid placement was found, naming the hexes. `templates`: the library the passes take their
/// templates from (the committed table's; the template optimiser passes candidates).
RefineResult refine(const RefineMethod& method, const HexMesh& mesh, const Targets& targets,
                    const RefineOptions& options,
                    const TemplateLibrary& templates = template_library_committed());

}  // namespace hexrefine
