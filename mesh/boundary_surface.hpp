#pragma once
/// \file
/// The boundary surface of a hex mesh as an OpenMesh quad PolyMesh, mapped back to the hexes,
/// and its segmentation into patches (the "surfaces" of a model) by feature angle.

#include <Eigen/Core>
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>
#include <array>
#include <cstdint>
#include <vector>

#include "mesh/hex_mesh.hpp"
#include "mesh/topology.hpp"

namespace hexrefine {

using SurfaceMesh = OpenMesh::PolyMesh_ArrayKernelT<>;

/// The boundary quads of a hex mesh. OpenMesh face i (FaceHandle(i)) is local face face_local[i]
/// of hex face_hex[i] (topology face face_id[i]), with its vertices in the order of
/// hex_faces[face_local[i]] (counter-clockwise seen from outside, so OpenMesh normals point out).
/// OpenMesh vertex v is mesh node vertex_node[v]; only nodes on boundary faces are present.
struct BoundarySurface {
  SurfaceMesh surface;
  std::vector<int32_t> face_hex;
  std::vector<int8_t> face_local;
  std::vector<int32_t> face_id;
  std::vector<int32_t> vertex_node;
  /// Faces that would have made the OpenMesh surface non-manifold (an edge with more than two
  /// boundary faces, or a vertex where boundary sheets touch) and were added with their own
  /// copies of the shared vertices; 0 for a manifold boundary. Copies map to the same node.
  int32_t split_face_count = 0;

  int32_t face_count() const { return static_cast<int32_t>(face_hex.size()); }
};

/// Builds the boundary surface, boundary faces in ascending topology face id. Linear time.
/// Precondition: `topology` was built from `mesh`.
BoundarySurface boundary_surface_build(const HexMesh& mesh, const HexTopology& topology);

/// Patches of the boundary surface: maximal sets of faces connected across surface edges whose
/// dihedral angle (angle between the two face normals) is below the feature angle.
struct SurfacePatches {
  std::vector<int32_t> face_patch;         ///< OpenMesh face index -> patch id
  std::vector<int32_t> patch_face_counts;  ///< patch id -> number of faces
  int32_t patch_count() const { return static_cast<int32_t>(patch_face_counts.size()); }
};

/// Flood fill over the OpenMesh faces; patch ids in order of their lowest face index. Faces with
/// a zero normal (degenerate quads) never join a neighbour. `feature_angle_degrees` in (0, 180].
SurfacePatches boundary_surface_patches(const BoundarySurface& surface,
                                        double feature_angle_degrees = 30.0);

/// Area-weighted normal of the quad (a, b, c, d): (c - a) x (d - b), the cross product of the
/// diagonals; its length is twice the area of a planar quad. Points outward for a quad that is
/// counter-clockwise seen from outside. Zero for a degenerate quad.
Eigen::Vector3d quad_area_normal(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                 const Eigen::Vector3d& c, const Eigen::Vector3d& d);

/// Unit normal of topology face `face`, outward from its first hex face_hexes[face][0] (for a
/// boundary face: outward from the mesh); zero for a degenerate face.
Eigen::Vector3d face_unit_normal(const HexMesh& mesh, const HexTopology& topology, int32_t face);

}  // namespace hexrefine
