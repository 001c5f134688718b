#pragma once
/// \file
/// Node placement: where the nodes a refinement pass created go. See node_placement.cpp for the
/// objective, the optimizer and its sources.

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "algorithms/placement/node_optimizer.hpp"
#include "algorithms/templates/template_engine.hpp"
#include "mesh/quad_patch.hpp"

namespace hexrefine {

enum class PlacementMethod : uint8_t {
  /// Every new node stays at the parent's trilinear map of the template's exact position (the
  /// thesis' placement: its tables are reproduced with it).
  trilinear,
  /// Reference positions first, then the new nodes around the children still poor move to
  /// raise the worst scaled Jacobian around them, inverted children untangled first
  /// (node_placement.cpp).
  optimized,
  /// The thesis' trilinear positions, and only the new nodes of inverted children move, until
  /// those are valid (no joint ascent): the start for smoothing, which then raises the quality
  /// from positions that have not yet used up the edge-ratio room
  /// (PlacementOptions::max_edge_ratio). Over the real-mesh study's cases smoothing ends higher
  /// from here than from `optimized` (results/smooth_start.md). Not from the reference
  /// positions, although issue 29 asked for it: smoothed from them, the shared meshes' cases
  /// ended lower more often than higher (docs/placement-and-smoothing.md, 'Why `untangle` keeps
  /// the thesis' positions'): the reference positions spend the room smoothing needs.
  untangle,
  /// Every new node at the parent's trilinear map of the template's reference position
  /// (template_reference.hpp: the positions that maximise the worst child on the unit cube),
  /// at the cost of `trilinear`; in a later pass, boundary nodes projected onto the input's
  /// boundary patches.
  reference,
};
NLOHMANN_JSON_SERIALIZE_ENUM(PlacementMethod, {{PlacementMethod::trilinear, "trilinear"},
                                               {PlacementMethod::optimized, "optimized"},
                                               {PlacementMethod::untangle, "untangle"},
                                               {PlacementMethod::reference, "reference"}})

/// "trilinear" / "optimized" / "untangle" / "reference".
std::string_view placement_method_name(PlacementMethod m);

/// Where the engine puts the new nodes before placement moves any: the templates' exact
/// positions for `trilinear` and `untangle`, their reference positions for `reference` and
/// `optimized`.
TemplatePositions placement_start_positions(PlacementMethod m);

struct PlacementOptions {
  PlacementMethod method = PlacementMethod::optimized;
  /// A child is worked on when its scaled Jacobian is below (1 + active_band) times the worst
  /// positive child's of the pass, or not positive (>= 0): the reference positions already are
  /// the best each template does on an undistorted parent, so optimisation pays where the pass
  /// is worst, and the band keeps it to those children and the hexes around them. In rounds: the
  /// first from the start positions; then, while the worst child rises, the band around the new
  /// worst, as long as each round fits what is left of a budget of max(active_floor,
  /// active_share x the pass's new hexes) children, so the optimisation costs a share of the
  /// refinement (docs/placement-and-smoothing.md, 'Where placement starts'; results/placement.md).
  double active_band = 0.25;
  double active_share = 0.005;
  double active_floor = 0;
  /// In a later pass (whose parents are the earlier passes' children) a child is also worked on
  /// when its scaled Jacobian is below active_ratio times its parent's times its own on the
  /// unit cube at the reference positions (HexTemplate::child_reference_quality) (in (0, 1]).
  double active_ratio = 0.9;
  int max_sweeps = 8;  ///< >= 0: Gauss-Seidel max-min sweeps over the active nodes, worst first
  /// >= 0: sweeps of the smooth phase first (NodeOptimizerOptions::smooth_sweeps).
  int smooth_sweeps = 0;
  /// Layers of children around the active ones whose new nodes may move too (0, 1, ...).
  int layers = 0;
  /// >= 0: L-BFGS iterations of the joint ascent after the sweeps (node_joint_ascent.hpp; 0:
  /// none), then the sweeps again if it raised the minimum.
  int joint_iterations = 100;
  /// No move gives a hex an edge ratio above max(max_edge_ratio, its ratio at the start
  /// positions) (NodeOptimizerOptions::max_edge_ratio; <= 0: no cap, the scaled Jacobian alone).
  double max_edge_ratio = 20;
  /// Directional hexes take their movable nodes' reference positions from the committed table
  /// of directional configurations where it lists theirs (template_reference.hpp); false: the
  /// composed positions of their steps alone (`hexrefine templates --optimize` builds the table
  /// from those).
  bool configuration_table = true;
};
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(PlacementOptions, method, active_band, active_share,
                                                active_floor, active_ratio, max_sweeps,
                                                smooth_sweeps, layers, joint_iterations,
                                                max_edge_ratio, configuration_table)

struct PlacementStats {
  int64_t active_hexes = 0;  ///< children worked on (all passes)
  int64_t free_nodes = 0;    ///< new nodes that could move (interior, or sliding on the boundary)
  int64_t nodes_moved = 0;   ///< of those, the ones that moved
  int64_t inverted_before = 0;  ///< children inverted at their trilinear positions
  int64_t untangled = 0;        ///< of those, the ones placement made valid
  /// Parents whose new nodes start at their exact positions because the reference positions
  /// stretch a child past the edge-ratio cap (node_placement.cpp, step 0).
  int64_t exact_parents = 0;
  int sweeps = 0;            ///< sweeps carried out (largest over the passes)
  int joint_iterations = 0;  ///< joint ascent iterations (all passes)
  /// Minimum scaled Jacobian over the active children before and after (1 if none).
  double min_before = 1, min_after = 1;
  double seconds = 0;
};
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(PlacementStats, active_hexes, free_nodes,
                                                nodes_moved, inverted_before, untangled,
                                                exact_parents, sweeps, joint_iterations, min_before,
                                                min_after, seconds)

/// The boundary of the input of a refinement (before its first pass) as bilinear patches: where
/// boundary nodes stay whatever the pass. Patch p is a boundary face of the input, its corners in
/// the order of topology face_nodes (outward); patches of input hex h are
/// hex_patches[hex_patch_offsets[h] .. [h+1]).
struct BoundaryReference {
  std::vector<Quad> patches;
  std::vector<int32_t> hex_patch_offsets;
  std::vector<int32_t> hex_patches;
};

/// Builds the reference of `input`. Precondition: `topology` built from it (faces at least).
BoundaryReference boundary_reference_build(const HexMesh& input, const HexTopology& topology);

/// Slides on the input's boundary for nodes of a refined mesh, collected into one geometry (the
/// patches and segments copied once each).
class ReferenceSlides {
 public:
  ReferenceSlides(const BoundaryReference& reference, SlideGeometry& geometry)
      : reference_(reference), geometry_(geometry) {}

  /// The slide of a node at x on the boundary of the input hexes `input_hexes` (those of the
  /// refined hexes around it): on the nearest of their input patches, strictly inside it (a
  /// patch slide), on one of its sides (a segment slide along that side, which two input faces
  /// share or which is the rim of the boundary), or nullopt at a patch corner or when no patch
  /// is found (the node stays). With `feature_cos` > -1 (smoothing), a node on a side that two
  /// of those patches share, their unit normals' dot product at least `feature_cos`, slides on
  /// both patches instead (a patches slide: the side is no feature of the input's surface).
  std::optional<NodeSlide> at(const Eigen::Vector3d& x, std::span<const int32_t> input_hexes,
                              double feature_cos = -2);

  /// The slide of an input node at x (a corner of input patches, not yet moved) on the boundary
  /// of the input hexes `input_hexes` (those around it), for smoothing: the patch sides at x are
  /// feature sides when they lie on other than two patches or when the patches' unit normals
  /// (of their diagonals) have a dot product below `feature_cos`. No feature side: the node
  /// slides on the union of its patches (a patches slide); two: along those two sides (a
  /// segments slide, the feature curve) unless the curve turns at x by more than the feature
  /// angle (a corner of the surface); otherwise, or at a degenerate patch, nullopt (stays).
  std::optional<NodeSlide> at_input_node(const Eigen::Vector3d& x,
                                         std::span<const int32_t> input_hexes, double feature_cos);

 private:
  const BoundaryReference& reference_;
  SlideGeometry& geometry_;
  std::unordered_map<int32_t, int32_t> patch_copy_;   ///< input patch -> geometry patch
  std::unordered_map<int32_t, int32_t> rim_segment_;  ///< input patch * 4 + side -> segment
};

/// One pass's placement: `current` is the mesh the pass refined (topology `topology`, all parts),
/// `plan` and `applied` the pass, `original_of` the input hex of each hex of `current` (empty:
/// `current` is the input), `reference` the input's boundary.
struct PlacementPass {
  const HexMesh& current;
  const HexTopology& topology;
  const RefinementPlan& plan;
  const std::vector<int32_t>& first_child;  ///< PlanApplyResult::first_child
  std::span<const int32_t> original_of;
  const BoundaryReference& reference;
  bool allow_inverted = false;
  /// What a child of a valid parent left inverted leads to: true, an OperationError naming the
  /// input hexes and their scaled Jacobians; false, the parents are returned to the caller (the
  /// refinement driver then makes them targets and plans the pass again, refiner.cpp).
  bool refuse = true;
  int threads = 1;  ///< for the node optimizer's levels (same result for any count)
  /// Nodes of the refinement's input (ids below this) never move. A later pass's `current`
  /// holds the new nodes of the earlier passes (ids from here to current.point_count()): those
  /// at the corners of the pass's active children move with the pass's new nodes.
  int32_t input_nodes = 0;
};

/// Moves the new nodes of `refined` (the pass's output, its nodes from current.point_count() on
/// new) as PlacementOptions say; accumulates into `stats`. Returns the parents (hex ids of
/// `current`, ascending) whose children stay inverted when neither allow_inverted nor refuse is
/// set; empty otherwise. Throws OperationError for them under `refuse` (see PlacementPass).
std::vector<int32_t> place_new_nodes(const PlacementPass& pass, HexMesh& refined,
                                     const PlacementOptions& options, PlacementStats& stats);

}  // namespace hexrefine
