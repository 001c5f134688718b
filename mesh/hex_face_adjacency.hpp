#pragma once
/// \file
/// Face adjacency of a hex mesh without the general topology: which hex lies across each local
/// face, the boundary faces, the non-manifold faces and the doublets, from one counting sort of
/// the 6 n face slots (hex, local face) by their lowest node and a match of the remaining three
/// nodes within each node's slots. No face ids, face node arrays or node -> hex lists are built:
/// 24 bytes per hex (the slots) and 4 per node and thread (the bucket counts, at most four),
/// plus 24 per hex for the neighbour array when it is asked for (the checker does not), instead
/// of the ~150 of topology_build.
///
/// Two slots are the same face when their four nodes are the same set (as in topology_build).

#include <array>
#include <cstdint>
#include <vector>

#include "mesh/hex_mesh.hpp"

namespace hexrefine {

/// A local face of a hex: hex id and local face index in [0, 6) (hex_faces order).
struct HexFaceSlot {
  int32_t hex;
  int32_t local_face;
};

struct HexFaceAdjacency {
  /// hex_neighbors[h][lf]: the hex across local face lf of hex h, -1 on the boundary. A face used
  /// by more than two hexes: its two lowest hexes point to each other and every other user to
  /// the lowest (what hex_face_neighbor gives on topology_build's faces).
  std::vector<std::array<int32_t, 6>> hex_neighbors;
  /// Faces used by exactly one hex, ordered by lowest node, then hex, then local face (the order
  /// of topology_boundary_faces).
  std::vector<HexFaceSlot> boundary_faces;
  /// Each face used by more than two hexes, as its lowest hex's slot, in the same face order.
  std::vector<HexFaceSlot> nonmanifold_faces;
  /// Doublets: pairs of hexes that share two or more faces (as node sets), each pair once as its
  /// lower hex, ascending (a hex in several pairs repeats). Found while matching, from the two
  /// lowest users of each face, counted at the pair's lowest shared face in its lower hex's
  /// order, so no neighbour array is needed. Where faces have more than two users
  /// (non-manifold: an invalid mesh anyway) a pair may go uncounted: the other users are not
  /// paired, and a pair whose lowest shared face has a third user below its second is missed.
  std::vector<int32_t> doublets;
};

/// The prefix of a counting sort over parts: counts[p][k], how many items part p puts in bucket
/// k (every part the same number of buckets), becomes where part p's items of bucket k start
/// when the buckets follow each other in order and, within a bucket, the parts do; returns the
/// total. On up to `threads` threads (block totals, their prefix, then each block); the result
/// is the same for every thread count. Precondition: the total fits 32 bits.
uint32_t counting_sort_starts(std::vector<std::vector<uint32_t>>& counts, int threads);

/// Most hexes hex_face_adjacency_build accepts: its slot ids h * 6 + lf are 32-bit.
inline constexpr int64_t hex_face_adjacency_max_hexes = (int64_t{1} << 32) / 6 - 1;

/// Builds the face adjacency in O(n) time, matching on up to `threads` threads; the result is
/// the same for every thread count. `neighbors` false leaves hex_neighbors empty (the boundary
/// and non-manifold faces only: 24 bytes per hex less, for a reader's manifold test).
/// Preconditions: mesh_validate_ids(mesh) holds and mesh.hex_count() <=
/// hex_face_adjacency_max_hexes (OperationError otherwise).
HexFaceAdjacency hex_face_adjacency_build(const HexMesh& mesh, int threads = 1,
                                          bool neighbors = true);

}  // namespace hexrefine
