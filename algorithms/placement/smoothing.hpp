#pragma once
/// \file
/// Node smoothing of an all-hex mesh after refinement (the thesis smooths its refined meshes
/// before reporting "Final Minimum Quality (Smoothed)", Tables 6-2 and H-1). See smoothing.cpp.
///
/// Guarantees (for any input whose hexes all have a positive scaled Jacobian, and for the others
/// as far as they go): the minimum scaled Jacobian never decreases, no hex with a positive scaled
/// Jacobian becomes non-positive, boundary nodes stay on the boundary surface by construction
/// (on the quads they started on, or with a reference on the input face they subdivide), the
/// hexes, their connectivity and attributes are unchanged, only the region's nodes move, and the
/// result is deterministic.

#include <cstdint>
#include <nlohmann/json.hpp>
#include <span>
#include <vector>

#include "algorithms/placement/node_placement.hpp"
#include "mesh/hex_mesh.hpp"
#include "mesh/topology.hpp"

namespace hexrefine {

/// Both methods keep a move only if no hex around the node gets worse than the node's current
/// local minimum and the local minimum or the local sum of scaled Jacobians rises (smoothing.cpp).
enum class SmoothMethod {
  laplacian,  ///< guarded Laplacian: towards the mean of the edge neighbours
  optimize,   ///< guarded Laplacian candidate, then a mean-ratio Newton step, then ascent of the
              ///< minimum scaled Jacobian of the hexes around the node; then rounds of joint
              ///< ascent of the nodes around the worst hexes (boundary nodes on their slides)
              ///< and the sweeps again
};

/// How smoothing treats a boundary node, from the boundary faces around it.
enum class SmoothNodeKind : int8_t {
  interior,  ///< on no boundary face: moves freely
  surface,   ///< on the boundary, no feature edge: slides on the boundary quads around it
  curve,     ///< on exactly two feature edges: slides along them
  corner,    ///< on one or three or more feature edges, or a degenerate or non-manifold face
};

/// Per-node classification (SmoothNodeKind), size node_count.
struct SmoothNodeClasses {
  std::vector<SmoothNodeKind> kind;
};

/// Classifies every node. A boundary edge is a feature edge when the unit normals (from the
/// diagonals' cross product) of two boundary faces at it differ by more than
/// `feature_angle_degrees`, or when it lies on other than two boundary faces. A zero-area boundary
/// face makes its nodes corners. Precondition: `topology` was built from `mesh`.
SmoothNodeClasses mesh_classify_smooth_nodes(const HexMesh& mesh, const HexTopology& topology,
                                             double feature_angle_degrees);

struct SmoothOptions {
  SmoothMethod method = SmoothMethod::optimize;
  /// >= 0, before the joint ascent and again after each of its rounds; 0 only measures.
  int max_sweeps = 20;
  /// Boundary faces whose normals differ by more than this (in (0, 180)) meet at a feature edge.
  double feature_angle_degrees = 30;
  /// Empty: all hexes. Otherwise only the nodes of these hexes move (ids in [0, hex_count)).
  std::vector<int32_t> region_hexes;
  /// >= 0: layers of hexes (sharing a node) around the region whose nodes move too.
  int layers = 0;
  /// Nodes are visited only while the worst hex around them is below this (in (0, 1]; default
  /// 0.5, the lower end of Verdict's acceptable range): a region of acceptable hexes costs one
  /// pass over its nodes, the work goes where quality is poor.
  double visit_below = 0.5;
  /// The input of a refinement (refine --smooth): every boundary node stays on the input's
  /// boundary surface: one the refinement made slides within the input face or edge it
  /// subdivides, one of the input (id < `reference_nodes`) on the input faces around it or along
  /// its feature curve (smoothing.cpp). The mesh's parent_hex attribute names the input hexes.
  /// nullptr: boundary nodes slide on the mesh's own boundary quads (SmoothNodeKind).
  const BoundaryReference* reference = nullptr;
  int32_t reference_nodes = 0;
  /// With `reference`, optional: the input's boundary surface as the checker sees it. A node
  /// visit or joint-ascent step is then kept only if the boundary faces at the moved nodes still
  /// pass the checker's test (reference_surface_holds_face; NodeProblem::surface says which
  /// faces and when): a node slid over a bend of the input can leave a face whose
  /// centroid sags off the surface (docs/placement-and-smoothing.md, 'Smoothing and the check
  /// agree'), which `check --reference` rejects. The same surface as check's, so the two agree.
  const ReferenceSurface* reference_surface = nullptr;
  /// Mesh node ids (in [0, node_count), any order) that stay where they are although in the
  /// region: refine --smooth pins the corners of the boundary faces the checker rejected in a
  /// first smoothing and smooths again (pipeline.cpp).
  std::vector<int32_t> fixed_nodes;
  int threads = 1;  ///< >= 1: threads for the node visits (the result is the same for any count)
  /// optimize, >= 0: L-BFGS iterations per round of the joint ascent of the nodes around the
  /// worst hexes after the sweeps, interior nodes and boundary nodes on their slides
  /// (node_joint_ascent.hpp; 0: none), then the sweeps again if it raised the minimum. Not with
  /// max_sweeps 0 (which only measures). A round stops earlier where its minimum stalls
  /// (JointAscentOptions::stall_iterations), so the budget costs only where the ascent still
  /// climbs, which it does slowly but steadily around transitions that must thicken as a layer:
  /// over the real-mesh study 1000 lifts more cases' children to 0.5 x the parents than 100, at
  /// about one and a half times the smoothing time (docs/placement-and-smoothing.md, 'Its
  /// budget'; results/smoothing_budget_all/smoothing_budget.md).
  int joint_iterations = 1000;
  /// >= 1: rounds of joint ascent and sweeps, while a round raises the minimum
  /// (JointAscentOptions::rounds; results/smoothing_budget.md compares one round and three on
  /// the real-mesh study's cases of rocker arm size).
  int joint_rounds = 3;
  /// No move gives a hex an edge ratio above max(max_edge_ratio, its ratio before smoothing)
  /// (NodeOptimizerOptions::max_edge_ratio; <= 0: no cap, the scaled Jacobian alone).
  double max_edge_ratio = 20;
};

struct SmoothStats {
  double min_scaled_jacobian_before = 1, min_scaled_jacobian_after = 1;
  /// Mean hex scaled Jacobian (1 for an empty mesh).
  double mean_scaled_jacobian_before = 1, mean_scaled_jacobian_after = 1;
  double seconds = 0;        ///< smoothing only, no I/O
  int sweeps = 0;            ///< sweeps carried out (<= max_sweeps)
  int64_t nodes_moved = 0;   ///< nodes whose final position differs from the input
  int64_t region_hexes = 0;  ///< hexes of the region and its layers
  int64_t movable_nodes = 0;
  int joint_iterations = 0;  ///< iterations of the joint ascent carried out, every round
  int joint_rounds = 0;      ///< rounds of joint ascent that raised the minimum
};
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(SmoothStats, min_scaled_jacobian_before,
                                                min_scaled_jacobian_after,
                                                mean_scaled_jacobian_before,
                                                mean_scaled_jacobian_after, seconds, sweeps,
                                                nodes_moved, region_hexes, movable_nodes,
                                                joint_iterations, joint_rounds)

/// Smooths `mesh` in place. Throws InputError for bad options (negative sweeps, layers or joint
/// iterations, joint rounds below 1, feature
/// angle outside (0, 180), visit_below outside (0, 1], region hex or fixed node id out of range) or
/// a mesh failing mesh_validate_ids or holding a non-finite coordinate. The min and mean before and
/// after are over the whole mesh.
SmoothStats mesh_smooth(HexMesh& mesh, const SmoothOptions& options);

/// The default region of `refine --smooth`: the refined and transition hexes, i.e. those whose
/// template_tag attribute is non-zero, ascending. Empty if there is none or the mesh has no
/// template_tag (callers then skip smoothing: an empty SmoothOptions::region_hexes means all).
std::vector<int32_t> mesh_refined_hexes(const HexMesh& mesh);

/// "laplacian" / "optimize".
const char* smooth_method_name(SmoothMethod m);

}  // namespace hexrefine
