#include "mesh/topology.hpp"

#include <algorithm>

#include "mesh/hex_convention.hpp"

namespace hexrefine {

namespace {

// Counting-sort CSR of `items` keyed by key(i) in [0, key_count).
template <class KeyOf>
void build_csr(int32_t key_count, int64_t item_count, KeyOf key_of, std::vector<int32_t>& offsets,
               std::vector<int32_t>& values, int per_item,
               const std::vector<int32_t>* item_values) {
  offsets.assign(static_cast<size_t>(key_count) + 1, 0);
  for (int64_t i = 0; i < item_count; ++i)
    for (int k = 0; k < per_item; ++k) ++offsets[key_of(i, k) + 1];
  for (int32_t k = 0; k < key_count; ++k) offsets[k + 1] += offsets[k];
  values.resize(offsets[key_count]);
  std::vector<int32_t> cursor(offsets.begin(), offsets.end() - 1);
  for (int64_t i = 0; i < item_count; ++i)
    for (int k = 0; k < per_item; ++k)
      values[cursor[key_of(i, k)]++] = item_values ? (*item_values)[i] : static_cast<int32_t>(i);
}

// The three local faces through each local vertex (a face whose lowest node is `a` contains `a`,
// so a node need only look at these).
constexpr std::array<std::array<int, 3>, 8> make_vertex_faces() {
  std::array<std::array<int, 3>, 8> out{};
  for (int v = 0; v < 8; ++v) {
    int k = 0;
    for (int f = 0; f < 6; ++f)
      for (int i = 0; i < 4; ++i)
        if (hex_faces[f][i] == v) out[v][k++] = f;
  }
  return out;
}
constexpr std::array<std::array<int, 3>, 8> vertex_faces = make_vertex_faces();

}  // namespace

HexTopology topology_build(const HexMesh& mesh, TopologyParts parts) {
  const bool edges = parts == TopologyParts::all;
  HexTopology t;
  const int32_t nh = mesh.hex_count();
  t.node_count = mesh.point_count();
  build_csr(
      t.node_count, nh, [&](int64_t h, int k) { return mesh.hexes[h][k]; }, t.node_hex_offsets,
      t.node_hexes, 8, nullptr);

  // Edges and faces are grouped at their lowest node: every node looks only at its own hexes.
  if (edges) t.hex_edge_ids.assign(nh, {});
  t.hex_face_ids.assign(nh, {});
  // About 3 edges and 3 faces per hex plus the boundary's share; 3.25 per hex covers bricks of
  // 25^3 and more without a reallocation (a 100^3 brick has 3.03 M edges and faces).
  const size_t expected = static_cast<size_t>(nh) * 13 / 4 + 1024;
  if (edges) t.edge_nodes.reserve(expected);
  t.face_nodes.reserve(expected);
  t.face_hexes.reserve(expected);
  if (edges) t.face_local.reserve(expected);
  struct LocalEdge {
    int32_t other, id;
  };
  struct LocalFace {
    std::array<int32_t, 3> others;  // sorted remaining nodes
    int32_t id;
    int32_t users;
  };
  std::vector<LocalEdge> local_edges;
  std::vector<LocalFace> local_faces;
  for (int32_t a = 0; a < t.node_count; ++a) {
    local_edges.clear();
    local_faces.clear();
    for (int32_t h : node_hexes(t, a)) {
      const HexCell& c = mesh.hexes[h];
      int i = 0;
      while (c[i] != a) ++i;
      for (int le : hex_vertex_edges[i]) {
        if (!edges) break;
        const int32_t b = c[hex_edges[le][0]] == a ? c[hex_edges[le][1]] : c[hex_edges[le][0]];
        if (b < a) continue;
        int32_t id = -1;
        for (const LocalEdge& x : local_edges)
          if (x.other == b) {
            id = x.id;
            break;
          }
        if (id < 0) {
          id = static_cast<int32_t>(t.edge_nodes.size());
          t.edge_nodes.push_back({a, b});
          local_edges.push_back({b, id});
        }
        t.hex_edge_ids[h][le] = id;
      }
      for (int lf : vertex_faces[i]) {
        const int* fv = hex_faces[lf];
        std::array<int32_t, 4> q = {c[fv[0]], c[fv[1]], c[fv[2]], c[fv[3]]};
        if (*std::min_element(q.begin(), q.end()) != a) continue;
        std::array<int32_t, 3> others{};
        int k = 0;
        for (int32_t v : q)
          if (v != a) others[k++] = v;
        std::sort(others.begin(), others.end());
        LocalFace* found = nullptr;
        for (LocalFace& x : local_faces)
          if (x.others[0] == others[0] && x.others[1] == others[1] && x.others[2] == others[2]) {
            found = &x;
            break;
          }
        if (!found) {
          const int32_t id = static_cast<int32_t>(t.face_nodes.size());
          t.face_nodes.push_back(q);
          t.face_hexes.push_back({h, -1});
          if (edges) t.face_local.push_back({static_cast<int8_t>(lf), -1});
          local_faces.push_back({others, id, 1});
          t.hex_face_ids[h][lf] = id;
          continue;
        }
        const int32_t id = found->id;
        t.hex_face_ids[h][lf] = id;
        if (++found->users == 2) {
          t.face_hexes[id][1] = h;
          if (edges) t.face_local[id][1] = static_cast<int8_t>(lf);
        } else if (found->users == 3) {
          t.nonmanifold_faces.push_back(id);
        }
      }
    }
  }
  std::sort(t.nonmanifold_faces.begin(), t.nonmanifold_faces.end());

  if (!edges) {
    // Only the grouping needed node -> hexes here; its memory goes back before the caller's
    // next allocations.
    std::vector<int32_t>().swap(t.node_hexes);
    std::vector<int32_t>().swap(t.node_hex_offsets);
  }
  if (edges)
    build_csr(
        t.edge_count(), nh, [&](int64_t h, int k) { return t.hex_edge_ids[h][k]; },
        t.edge_hex_offsets, t.edge_hexes, 12, nullptr);
  return t;
}

bool edge_is_boundary(const HexTopology& t, int32_t e) {
  for (int32_t h : edge_hexes(t, e)) {
    const int le = hex_local_edge(t, h, e);
    for (int lf : hex_edge_faces[le])
      if (face_is_boundary(t, t.hex_face_ids[h][lf])) return true;
  }
  return false;
}

int edge_face_count(const HexTopology& t, int32_t e) {
  // Each hex contributes its two faces at the edge; interior faces are counted twice.
  int count2 = 0;
  for (int32_t h : edge_hexes(t, e)) {
    const int le = hex_local_edge(t, h, e);
    for (int lf : hex_edge_faces[le]) count2 += face_is_boundary(t, t.hex_face_ids[h][lf]) ? 2 : 1;
  }
  return count2 / 2;
}

std::vector<int32_t> topology_boundary_faces(const HexTopology& t) {
  std::vector<int32_t> out;
  for (int32_t f = 0; f < t.face_count(); ++f)
    if (face_is_boundary(t, f)) out.push_back(f);
  return out;
}

int hex_local_edge(const HexTopology& t, int32_t h, int32_t e) {
  for (int le = 0; le < 12; ++le)
    if (t.hex_edge_ids[h][le] == e) return le;
  return -1;
}

int hex_local_face(const HexTopology& t, int32_t h, int32_t f) {
  for (int lf = 0; lf < 6; ++lf)
    if (t.hex_face_ids[h][lf] == f) return lf;
  return -1;
}

}  // namespace hexrefine
