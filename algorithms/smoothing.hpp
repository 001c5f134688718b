#pragma once
/// \file
/// Node smoothing of an all-hex mesh after refinement (the thesis smooths its refined meshes
/// before reporting "Final Minimum Quality (Smoothed)", Tables 6-2 and H-1). See smoothing.cpp.
///
/// Guarantees (for any input whose hexes all have a positive scaled Jacobian, and for the others
/// as far as they go): the minimum scaled Jacobian never decreases, no hex with a positive scaled
/// Jacobian becomes non-positive, boundary nodes stay on their planar patch (or stay put), the
/// hexes, their connectivity and attributes are unchanged, and the result is deterministic.

#include <cstdint>
#include <nlohmann/json.hpp>
#include <vector>

#include "mesh/hex_mesh.hpp"
#include "mesh/topology.hpp"

namespace hexrefine {

/// Both methods keep a move only if no hex around the node gets worse than the node's current
/// local minimum and the local minimum or the local sum of scaled Jacobians rises (smoothing.cpp).
enum class SmoothMethod {
  laplacian,  ///< guarded Laplacian: towards the mean of the edge neighbours
  optimize,   ///< guarded Laplacian candidate, then a mean-ratio Newton step, then ascent of the
              ///< minimum scaled Jacobian of the hexes around the node
};

struct SmoothOptions {
  SmoothMethod method = SmoothMethod::optimize;
  int max_sweeps = 20;  ///< >= 0; 0 only measures
  /// Boundary nodes whose boundary faces' normals differ by more than this (in (0, 180)) are
  /// feature nodes (edges, corners) and stay fixed.
  double feature_angle_degrees = 30;
  /// Empty: all hexes. Otherwise only the nodes of these hexes move (ids in [0, hex_count)).
  std::vector<int32_t> region_hexes;
};

struct SmoothStats {
  double min_scaled_jacobian_before = 1, min_scaled_jacobian_after = 1;
  /// Mean hex scaled Jacobian (1 for an empty mesh).
  double mean_scaled_jacobian_before = 1, mean_scaled_jacobian_after = 1;
  double seconds = 0;       ///< smoothing only, no I/O
  int sweeps = 0;           ///< sweeps carried out (<= max_sweeps)
  int64_t nodes_moved = 0;  ///< nodes whose final position differs from the input
};
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(SmoothStats, min_scaled_jacobian_before,
                                                min_scaled_jacobian_after,
                                                mean_scaled_jacobian_before,
                                                mean_scaled_jacobian_after, seconds, sweeps,
                                                nodes_moved)

/// How smoothing treats a node (mesh_smooth classifies every node once, before the sweeps).
enum class SmoothNodeKind : int8_t {
  interior,  ///< on no boundary face: moves freely
  planar,    ///< all boundary faces around it lie in one plane: slides in that plane
  curved,    ///< boundary faces within the feature angle but not coplanar: fixed (no geometry)
  feature,   ///< boundary face normals differ by more than the feature angle: fixed
};

/// Per-node classification and, for planar nodes, the unit normal of their plane.
struct SmoothNodeClasses {
  std::vector<SmoothNodeKind> kind;     ///< size node_count
  std::vector<Eigen::Vector3d> normal;  ///< size node_count; zero unless kind is planar
};

/// Classifies every node from the boundary faces around it (outward unit normals from the
/// diagonals' cross product). Planar: every incident boundary face normal is parallel to the first
/// (to 1e-9) and every node of those faces lies within 1e-9 face diagonals of the node's plane.
/// Feature: some pair of incident normals makes an angle above `feature_angle_degrees`; a zero-area
/// boundary face makes its nodes features too. Precondition: `topology` was built from `mesh`.
SmoothNodeClasses mesh_classify_smooth_nodes(const HexMesh& mesh, const HexTopology& topology,
                                             double feature_angle_degrees);

/// Smooths `mesh` in place. Sweeps visit the movable nodes worst-first (by the lowest scaled
/// Jacobian of the hexes around each node, ties by node id) and stop after `max_sweeps` or when a
/// sweep no longer changes the mesh noticeably. Throws InputError for bad options (negative
/// sweeps, feature angle outside (0, 180), region hex id out of range) or a mesh failing
/// mesh_validate_ids or holding a non-finite coordinate.
SmoothStats mesh_smooth(HexMesh& mesh, const SmoothOptions& options);

/// The default region of `refine --smooth`: the refined and transition hexes, i.e. those whose
/// template_tag attribute is non-zero, ascending. Empty if there is none or the mesh has no
/// template_tag (callers then skip smoothing: an empty SmoothOptions::region_hexes means all).
std::vector<int32_t> mesh_refined_hexes(const HexMesh& mesh);

/// "laplacian" / "optimize".
const char* smooth_method_name(SmoothMethod m);

}  // namespace hexrefine
