/// Sheets and chords of the dual (see dual.hpp for the definitions).
///
/// Steps: (1) union the four parallel edges of every hex (sheets) and the two opposite faces of
/// every hex per axis (chords) in two union-find forests over flat id arrays; (2) relabel the
/// roots in ascending order of the lowest member id; (3) one pass over the hexes for hex counts
/// and self-intersection, one pass over the boundary faces for closedness; (4) a counting-sort
/// CSR of sheet -> hexes.
#include "mesh/dual.hpp"

#include "mesh/hex_convention.hpp"

namespace hexrefine {

namespace {

// Union-find with path halving and union by lower id (the lower id stays root, which keeps the
// relabelling in step 2 a single ascending scan).
struct DisjointSets {
  std::vector<int32_t> parent;
  explicit DisjointSets(int32_t n) : parent(n) {
    for (int32_t i = 0; i < n; ++i) parent[i] = i;
  }
  int32_t find(int32_t x) {
    while (parent[x] != x) {
      parent[x] = parent[parent[x]];
      x = parent[x];
    }
    return x;
  }
  void unite(int32_t a, int32_t b) {
    a = find(a);
    b = find(b);
    if (a == b) return;
    if (a < b)
      parent[b] = a;
    else
      parent[a] = b;
  }
  // Class ids 0..k-1 in order of the lowest member; returns k.
  int32_t label(std::vector<int32_t>& out) {
    const int32_t n = static_cast<int32_t>(parent.size());
    out.assign(n, -1);
    int32_t count = 0;
    for (int32_t i = 0; i < n; ++i) {
      const int32_t r = find(i);
      if (r == i) out[i] = count++;
      out[i] = out[r];
    }
    return count;
  }
};

}  // namespace

DualSheets dual_build(const HexMesh& mesh, const HexTopology& t, DualParts parts) {
  DualSheets d;
  const int32_t nh = mesh.hex_count();

  // Sheets.
  DisjointSets edges(t.edge_count());
  for (int32_t h = 0; h < nh; ++h)
    for (int axis = 0; axis < 3; ++axis) {
      const int32_t e0 = t.hex_edge_ids[h][hex_axis_edges[axis][0]];
      for (int k = 1; k < 4; ++k) edges.unite(e0, t.hex_edge_ids[h][hex_axis_edges[axis][k]]);
    }
  const int32_t sheet_count = edges.label(d.edge_sheet);
  d.sheets.assign(sheet_count, SheetInfo{0, 0, false, true});
  for (int32_t e = 0; e < t.edge_count(); ++e) ++d.sheets[d.edge_sheet[e]].edge_count;

  d.hex_sheet.resize(nh);
  const bool csr = parts == DualParts::all;
  if (csr) d.sheet_hex_offsets.assign(static_cast<size_t>(sheet_count) + 1, 0);
  for (int32_t h = 0; h < nh; ++h) {
    auto& hs = d.hex_sheet[h];
    for (int axis = 0; axis < 3; ++axis)
      hs[axis] = d.edge_sheet[t.hex_edge_ids[h][hex_axis_edges[axis][0]]];
    for (int axis = 0; axis < 3; ++axis) {
      bool seen_before = false;
      for (int b = 0; b < axis; ++b) seen_before |= hs[b] == hs[axis];
      if (seen_before) {
        d.sheets[hs[axis]].self_intersecting = true;
        continue;
      }
      ++d.sheets[hs[axis]].hex_count;
      if (csr) ++d.sheet_hex_offsets[hs[axis] + 1];
    }
  }
  if (!csr) return d;
  for (int32_t s = 0; s < sheet_count; ++s) d.sheet_hex_offsets[s + 1] += d.sheet_hex_offsets[s];
  d.sheet_hexes.resize(d.sheet_hex_offsets[sheet_count]);
  {
    std::vector<int32_t> cursor(d.sheet_hex_offsets.begin(), d.sheet_hex_offsets.end() - 1);
    for (int32_t h = 0; h < nh; ++h) {
      const auto& hs = d.hex_sheet[h];
      for (int axis = 0; axis < 3; ++axis) {
        bool seen_before = false;
        for (int b = 0; b < axis; ++b) seen_before |= hs[b] == hs[axis];
        if (!seen_before) d.sheet_hexes[cursor[hs[axis]]++] = h;
      }
    }
  }

  // Chords.
  DisjointSets faces(t.face_count());
  for (int32_t h = 0; h < nh; ++h)
    for (int axis = 0; axis < 3; ++axis)
      faces.unite(t.hex_face_ids[h][2 * axis], t.hex_face_ids[h][2 * axis + 1]);
  const int32_t chord_count = faces.label(d.face_chord);
  d.chords.assign(chord_count, ChordInfo{0, true});
  d.hex_chord.resize(nh);
  for (int32_t h = 0; h < nh; ++h) {
    auto& hc = d.hex_chord[h];
    for (int axis = 0; axis < 3; ++axis) {
      hc[axis] = d.face_chord[t.hex_face_ids[h][2 * axis]];
      bool seen_before = false;
      for (int b = 0; b < axis; ++b) seen_before |= hc[b] == hc[axis];
      if (!seen_before) ++d.chords[hc[axis]].hex_count;
    }
  }

  // Closedness: a boundary face opens its chord and the sheets of its four edges.
  for (int32_t f = 0; f < t.face_count(); ++f) {
    if (!face_is_boundary(t, f)) continue;
    d.chords[d.face_chord[f]].closed = false;
    const int32_t h = t.face_hexes[f][0];
    const int lf = t.face_local[f][0];
    for (int le : hex_face_edges[lf]) d.sheets[d.edge_sheet[t.hex_edge_ids[h][le]]].closed = false;
  }
  return d;
}

SheetPieces dual_sheet_pieces(const HexTopology& t, std::span<const int32_t> hexes,
                              std::span<const uint16_t> edge_masks) {
  DisjointSets edges(t.edge_count());
  for (size_t i = 0; i < hexes.size(); ++i)
    for (int axis = 0; axis < 3; ++axis) {
      int32_t first = -1;
      for (int e : hex_axis_edges[axis]) {
        if (!(edge_masks[i] & (1u << e))) continue;
        const int32_t id = t.hex_edge_ids[hexes[i]][e];
        if (first < 0)
          first = id;
        else
          edges.unite(first, id);
      }
    }
  SheetPieces out;
  out.hex_piece.resize(hexes.size());
  std::vector<int32_t> piece_of_root(t.edge_count(), -1);
  for (size_t i = 0; i < hexes.size(); ++i)
    for (int axis = 0; axis < 3; ++axis) {
      out.hex_piece[i][axis] = -1;
      for (int e : hex_axis_edges[axis]) {
        if (!(edge_masks[i] & (1u << e))) continue;
        const int32_t root = edges.find(t.hex_edge_ids[hexes[i]][e]);
        if (piece_of_root[root] < 0) {
          piece_of_root[root] = out.piece_count();
          out.piece_edge.push_back(root);  // union by lower id: the root is the lowest edge
        }
        out.hex_piece[i][axis] = piece_of_root[root];
        break;
      }
    }
  return out;
}

}  // namespace hexrefine
