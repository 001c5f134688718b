#pragma once
/// \file
/// The hexes of lowest scaled Jacobian, and where they sit: how many of their faces lie on the
/// boundary. The question a user asks of a refined or smoothed mesh that misses a quality target
/// ("is the worst hex a transition inside the region, or a hex pressed against the surface?"),
/// and the one that decides whether pillowing could help: pillowing the boundary turns a hex
/// with two or three faces on one smooth surface into an interior hex, and does nothing for a
/// hex with none.

#include <cstdint>
#include <vector>

#include "mesh/hex_mesh.hpp"

namespace hexrefine {

struct WorstHex {
  int32_t hex = -1;  ///< its id, in [0, hex_count)
  /// hex_scaled_jacobian of the hex, in [-1, 1].
  double scaled_jacobian = 1.0;
  /// How many of its six faces no other hex uses, in [0, 6].
  int boundary_faces = 0;
};

/// The `count` hexes of lowest hex_scaled_jacobian (fewer if the mesh has fewer), ascending by
/// value (NaN as -1), ties by id, each with its boundary-face count. On up to `threads` threads;
/// the result is the same for every thread count. Time: one pass of scaled Jacobians
/// (mesh_scaled_jacobians) and one face matching (hex_face_adjacency_build, no neighbour array).
/// Preconditions: mesh_validate_ids(mesh) holds, count >= 0.
std::vector<WorstHex> mesh_worst_hexes(const HexMesh& mesh, int count, int threads = 1);

}  // namespace hexrefine
