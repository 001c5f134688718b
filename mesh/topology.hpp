#pragma once
/// \file
/// Derived topology of a HexMesh: unique edges and quad faces, node -> hexes, edge -> hexes,
/// face -> hexes, boundary faces. Built once by topology_build into plain flat arrays; nothing is
/// computed lazily.

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "mesh/hex_mesh.hpp"

namespace hexrefine {

struct HexTopology {
  int32_t node_count = 0;

  /// node -> hexes, CSR: hexes of node n are node_hexes[node_hex_offsets[n] .. [n+1]).
  std::vector<int32_t> node_hex_offsets;
  std::vector<int32_t> node_hexes;

  /// Unique edges as (lower node id, higher node id); hex_edge_ids[h][e] is the id of local edge e.
  std::vector<std::array<int32_t, 2>> edge_nodes;
  std::vector<std::array<int32_t, 12>> hex_edge_ids;
  /// edge -> hexes, CSR (ascending hex ids).
  std::vector<int32_t> edge_hex_offsets;
  std::vector<int32_t> edge_hexes;

  /// Unique quad faces, nodes ordered as in face_hexes[f][0] (outward from that hex).
  std::vector<std::array<int32_t, 4>> face_nodes;
  std::vector<std::array<int32_t, 6>> hex_face_ids;
  /// The first two hexes of each face (second is -1 on the boundary) and their local face index.
  std::vector<std::array<int32_t, 2>> face_hexes;
  std::vector<std::array<int8_t, 2>> face_local;
  /// Faces used by more than two hexes (non-manifold input); empty for a valid mesh.
  std::vector<int32_t> nonmanifold_faces;

  int32_t edge_count() const { return static_cast<int32_t>(edge_nodes.size()); }
  int32_t face_count() const { return static_cast<int32_t>(face_nodes.size()); }
};

/// Which parts topology_build fills.
enum class TopologyParts : uint8_t {
  all,    ///< everything
  faces,  ///< the faces only (face_nodes, face_hexes, hex_face_ids, nonmanifold_faces): edges,
          ///< node -> hexes and face_local stay empty (about half the memory)
};

/// Builds the topology in O(n) time (node-centric grouping, no global sort, no node-pair map).
/// Precondition: mesh_validate_ids(mesh) holds. With TopologyParts::faces, functions that need
/// edges or node -> hexes (node_hexes, edge_hexes, edge_is_boundary, edge_face_count,
/// hex_local_edge) must not be called.
HexTopology topology_build(const HexMesh& mesh, TopologyParts parts = TopologyParts::all);

/// Hexes around node n.
inline std::span<const int32_t> node_hexes(const HexTopology& t, int32_t n) {
  return {t.node_hexes.data() + t.node_hex_offsets[n],
          t.node_hexes.data() + t.node_hex_offsets[n + 1]};
}

/// Hexes around edge e (its valence is the size).
inline std::span<const int32_t> edge_hexes(const HexTopology& t, int32_t e) {
  return {t.edge_hexes.data() + t.edge_hex_offsets[e],
          t.edge_hexes.data() + t.edge_hex_offsets[e + 1]};
}

inline bool face_is_boundary(const HexTopology& t, int32_t f) {
  return t.face_hexes[f][1] < 0;
}

/// The hex across local face lf of hex h, or -1 on the boundary.
inline int32_t hex_face_neighbor(const HexTopology& t, int32_t h, int lf) {
  const auto& fh = t.face_hexes[t.hex_face_ids[h][lf]];
  return fh[0] == h ? fh[1] : fh[0];
}

/// True if edge e lies on a boundary face of one of its hexes.
bool edge_is_boundary(const HexTopology& t, int32_t e);

/// Number of distinct faces that contain edge e (3 for an interior edge of valence 3, or a
/// boundary edge with two hexes).
int edge_face_count(const HexTopology& t, int32_t e);

/// Ids of all boundary faces, ascending.
std::vector<int32_t> topology_boundary_faces(const HexTopology& t);

/// Local index (0..11) of edge id e in hex h, or -1.
int hex_local_edge(const HexTopology& t, int32_t h, int32_t e);

/// Local index (0..5) of face id f in hex h, or -1.
int hex_local_face(const HexTopology& t, int32_t h, int32_t f);

}  // namespace hexrefine
