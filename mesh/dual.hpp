#pragma once
/// \file
/// The dual of an all-hex mesh: sheets (twist planes) and chords.
///
/// A *sheet* is a class of edges closed under "opposite edges of a quad face": the four parallel
/// edges of a hex are in one sheet, and the sheet crosses every hex that has one of its edges. In
/// the dual it is the layer of hexes that Harris' sheet refinement splits. A *chord* is a class of
/// faces closed under "opposite faces of a hex": the stack of hexes entered through one face and
/// left through the opposite one (the dual curve where two sheets cross).
///
/// Definitions fixed here (the thesis leaves them informal):
/// - A sheet *self-intersects* when some hex has two (or three) of its three directions in it.
/// - A sheet is *closed* when none of its edges lies on the boundary (an edge on a boundary face);
///   a sheet running from boundary to boundary is open.
/// - A chord is *closed* when none of its faces is a boundary face.
/// - Ids are numbered in order of first appearance: sheet s is the class of the lowest edge id not
///   in sheets 0..s-1 (chords likewise by face id), so results are deterministic.

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "mesh/hex_mesh.hpp"
#include "mesh/topology.hpp"

namespace hexrefine {

struct SheetInfo {
  int32_t hex_count;       ///< hexes crossed, each counted once even if crossed twice
  int32_t edge_count;      ///< edges in the class
  bool self_intersecting;  ///< some hex has two of its directions in this sheet
  bool closed;             ///< no edge of the sheet is a boundary edge
};

struct ChordInfo {
  int32_t hex_count;  ///< hexes on the chord, each counted once
  bool closed;        ///< no face of the chord is a boundary face
};

struct DualSheets {
  std::vector<int32_t> edge_sheet;  ///< edge id -> sheet id (class of parallel edges)
  std::vector<std::array<int32_t, 3>>
      hex_sheet;  ///< hex -> sheet of its x, y, z edges (local axes)
  std::vector<SheetInfo> sheets;
  std::vector<int32_t> face_chord;  ///< face id -> chord id (stack of hexes through opposite faces)
  std::vector<std::array<int32_t, 3>>
      hex_chord;  ///< hex -> chord through its faces normal to axis 0/1/2
  std::vector<ChordInfo> chords;
  /// Hexes of each sheet, CSR, ascending and unique per sheet: sheet s has
  /// sheet_hexes[sheet_hex_offsets[s] .. [s+1]) (sizes equal SheetInfo::hex_count).
  std::vector<int32_t> sheet_hex_offsets;
  std::vector<int32_t> sheet_hexes;

  int32_t sheet_count() const { return static_cast<int32_t>(sheets.size()); }
  int32_t chord_count() const { return static_cast<int32_t>(chords.size()); }
};

/// Which parts dual_build fills.
enum class DualParts : uint8_t {
  all,     ///< everything
  sheets,  ///< edge_sheet, hex_sheet and sheets only (no sheet -> hex CSR, no chords)
};

/// Builds sheets and chords in linear time (union-find with path halving over flat arrays).
/// Precondition: `topology` was built from `mesh`.
DualSheets dual_build(const HexMesh& mesh, const HexTopology& topology,
                      DualParts parts = DualParts::all);

/// Pieces of dual sheets inside a part of the mesh: for every hex hexes[i] and axis k, the edges
/// of axis k whose bits are set in edge_masks[i] (bit e: local edge e) join one class, and
/// classes that share an edge are one piece. hex_piece[i][k] is the piece of those edges (-1 if
/// none is set), pieces numbered in order of first appearance over (i, k); piece_edge[p] is the
/// lowest edge id of piece p. Time linear in the edge count plus the part's size.
struct SheetPieces {
  std::vector<std::array<int32_t, 3>> hex_piece;
  std::vector<int32_t> piece_edge;
  int32_t piece_count() const { return static_cast<int32_t>(piece_edge.size()); }
};
SheetPieces dual_sheet_pieces(const HexTopology& topology, std::span<const int32_t> hexes,
                              std::span<const uint16_t> edge_masks);

/// Sheet id of edge `edge` (in [0, edge count)).
inline int32_t sheet_of_edge(const DualSheets& d, int32_t edge) {
  return d.edge_sheet[edge];
}

/// Chord id of face `face` (in [0, face count)).
inline int32_t chord_of_face(const DualSheets& d, int32_t face) {
  return d.face_chord[face];
}

/// Hexes crossed by sheet `s`, ascending.
inline std::span<const int32_t> sheet_hexes(const DualSheets& d, int32_t s) {
  return {d.sheet_hexes.data() + d.sheet_hex_offsets[s],
          d.sheet_hexes.data() + d.sheet_hex_offsets[s + 1]};
}

}  // namespace hexrefine
