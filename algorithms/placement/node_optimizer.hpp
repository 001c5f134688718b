#pragma once
/// \file
/// Local node optimization shared by node placement (node_placement.hpp) and smoothing
/// (smoothing.hpp): a set of movable nodes, the hexes around each, how each may move
/// (node_slide.hpp), and Gauss-Seidel sweeps that move one node at a time to raise the worst scaled
/// Jacobian of the hexes around it. See node_optimizer.cpp for the objective and its sources.

#include <array>
#include <cstdint>
#include <vector>

#include "algorithms/placement/node_slide.hpp"
#include "mesh/hex_mesh.hpp"
#include "mesh/quality.hpp"
#include "mesh/reference_surface.hpp"

namespace hexrefine {

/// A local problem: movable nodes, how each slides, the hexes around each.
struct NodeProblem {
  std::vector<int32_t> nodes;             ///< movable nodes (ids into mesh.points), ascending
  std::vector<NodeSlide> slides;          ///< per movable node
  std::vector<int32_t> hexes;             ///< every hex around a movable node, ascending, unique
  std::vector<int32_t> node_hex_offsets;  ///< CSR: movable node i -> indices into `hexes`
  std::vector<int32_t> node_hex;
  /// Per entry of `hexes`, its corners as movable node indices (-1: a corner that does not
  /// move): whom a move wakes, without a search per corner.
  std::vector<std::array<int32_t, 8>> hex_local_nodes;
  SlideGeometry geometry;
  /// Optional (smoothing against the input of a refinement): `surface` and, per movable node,
  /// the boundary faces of the mesh it is a corner of that a move can take off the surface
  /// (CSR into `faces`: mesh node ids in cyclic order; smoothing.cpp leaves out the faces whose
  /// corners all stay on one input face). A node visit is kept only if it ends with each of
  /// them on the surface (reference_surface_holds_face, the checker's own test), and a joint
  /// ascent step only if it leaves them there. Empty offsets: no such guard.
  const ReferenceSurface* surface = nullptr;
  std::vector<std::array<int32_t, 4>> faces;
  std::vector<int32_t> node_face_offsets, node_face;
};

/// Whether every boundary face of local node i lies on problem.surface at the mesh's current
/// positions (true without a surface guard).
bool node_faces_on_surface(const NodeProblem& problem, const HexMesh& mesh, int32_t i);

/// The largest edge ratio a move may give the hex with corners p (its start):
/// max(limit, hex_edge_ratio(p) (1 + 1e-9)), so that a hex already stretched beyond the limit
/// (an anisotropic parent's child) may stay as it is (up to the rounding of a node projected
/// back onto its slide) but not get worse; +inf when limit <= 0.
double hex_edge_ratio_cap(const HexCorners& p, double limit);

/// Fills problem.hexes, the node -> hex CSR and hex_local_nodes from `candidates` (ascending hex
/// ids that include
/// every hex with a movable node; others are skipped). Linear in the candidates; uses one int32
/// per mesh node as scratch. Precondition: problem.nodes ascending.
void node_problem_connect(NodeProblem& problem, const HexMesh& mesh,
                          const std::vector<int32_t>& candidates);

struct NodeOptimizerOptions {
  /// Try the mean of the node's edge neighbours, as a full, half and quarter move (Freitag's
  /// smart Laplacian).
  bool laplacian = false;
  /// Then one Newton step on the inverse mean ratio (Knupp; free nodes).
  bool mean_ratio = false;
  /// Then the max-min ascent of the scaled Jacobian around the node.
  bool ascent = true;
  /// Nodes whose worst hex is at or above this are not visited (in (0, 1]; 1: every node).
  double visit_below = 1.0;
  /// No move may give a hex an edge ratio (hex_edge_ratio) above hex_edge_ratio_cap(its start,
  /// max_edge_ratio) (<= 0: no cap). The scaled Jacobian is blind to edge length: maximising its
  /// minimum alone pulls two new nodes of a transition together until their edge is a
  /// thousandth of the others, hexes fine by their angles and useless to an analysis. 20
  /// (PlacementOptions and SmoothOptions too): above what the templates give the children of
  /// the shared meshes' parents, and past it a looser cap gains little smoothed quality
  /// (docs/placement-and-smoothing.md, 'The edge-ratio cap' and 'The edge-ratio cap's default';
  /// results/edge_ratio_cap.md).
  double max_edge_ratio = 20;
  /// Never turn a hex with a positive scaled Jacobian non-positive (smoothing). false: an
  /// inverted hex may be traded for a less inverted one while untangling (placement), as long
  /// as the worst hex around the node improves.
  bool keep_positive = true;
  int max_sweeps = 12;   ///< >= 0
  int ascent_steps = 4;  ///< ascent steps per node visit
  /// Sweeps of a first, smooth phase before the max-min sweeps: ascent of the KS soft minimum with
  /// a low beta (it weighs every sample around the node, not only the worst), a move kept when
  /// that soft minimum rises. Nodes then move together towards a balanced configuration that
  /// one-node max-min steps cannot reach from a poor start (the transition nodes of a template
  /// in a long parent). The problem's minimum is restored if this phase lowered it.
  int smooth_sweeps = 0;
  double smooth_beta = 8.0;
  /// Threads visiting the nodes of one dependency level of a sweep at once (>= 1; the result is
  /// the same for any count).
  int threads = 1;
  /// Empty, or one flag per problem node: the nodes the first max-min sweep visits (the others
  /// join when a neighbour moves). A second round after the joint ascent starts from the nodes
  /// it moved instead of every node the first round already left where it could not improve.
  std::vector<uint8_t> initially_active;
};

struct NodeOptimizerStats {
  int sweeps = 0;
  int64_t nodes_moved = 0;  ///< movable nodes whose position changed
  /// Minimum and mean scaled Jacobian over problem.hexes before and after (1 if none).
  double min_before = 1, min_after = 1, mean_before = 1, mean_after = 1;
};

/// Moves problem.nodes in `mesh` (see the file comment); deterministic: the result is that of
/// serial Gauss-Seidel sweeps in worst-first order (ties by node id) for any options.threads,
/// which visit the nodes of one dependency level at a time. The minimum over problem.hexes never
/// decreases.
NodeOptimizerStats nodes_optimize(HexMesh& mesh, const NodeProblem& problem,
                                  const NodeOptimizerOptions& options);

/// Gradients of the nine scaled-Jacobian samples of a hex (hex_scaled_jacobian_samples: corners
/// 0..7, then the centre) with respect to the position of its local vertex `vertex`.
/// Sample s = det(A) / (|a0| |a1| |a2|), column k of A = c_k x + const (c_k in {-1, -1/4, 0,
/// 1/4, 1}): ds/dx = sum_k c_k (cof_k / L - s a_k / |a_k|^2), cof_k the cofactor column
/// (a1 x a2, a2 x a0, a0 x a1), L the product of the column lengths; zero where L is 0.
void hex_scaled_jacobian_gradients(const std::array<Eigen::Vector3d, 8>& corners, int vertex,
                                   std::array<double, 9>& samples,
                                   std::array<Eigen::Vector3d, 9>& gradients);

}  // namespace hexrefine
