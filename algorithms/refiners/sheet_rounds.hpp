#pragma once
/// \file
/// The rounds of sheet refinement (internal to the algorithms library): one round refines every
/// hex in the local axes whose sheet piece has the round's colour, with Harris' directional
/// templates; composites replay a hex configuration's rounds once on the reference cube. See
/// sheet.cpp for the steps of a pass.

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "algorithms/templates/template_engine.hpp"
#include "algorithms/templates/template_reference.hpp"
#include "mesh/hex_mesh.hpp"

namespace hexrefine::sheet_detail {

/// One directional template in one orientation, with what the rounds need to know about its
/// children: per child local axis, the parent local axis its edges run along (-1 when its edges
/// are not parallel to a parent axis, as in the skewed children of 1-5: such an axis has no edge
/// between two marked nodes), and which child vertices lie inside a parent edge (they get
/// marked).
struct Orientation {
  TemplateChoice choice;
  uint8_t axes = 0;  ///< bit k: refines parent local axis k (two or three bits for 1-9, 1-27)
  std::vector<std::array<int8_t, 3>> child_axis;
  std::vector<uint8_t> child_edge_nodes;
};

/// Orientation of each split mask of TemplateSet::sheet_directional (the masks of one axis, and
/// of two or three fully split axes), by mask; nullptr where the set has no template.
const Orientation* sheet_orientation(uint16_t split_mask);

/// Hexes created and deleted by rounds (the thesis' counts: 39 created and 13 deleted for a
/// fully refined hex, through its intermediate hexes).
struct RoundCounts {
  int64_t created = 0, deleted = 0;
};

/// The state the rounds carry per node and hex of the current mesh.
struct RoundState {
  std::vector<uint8_t> node_marked;                ///< per node
  std::vector<std::array<int32_t, 3>> occurrence;  ///< per hex and local axis: piece, or -1
  std::vector<int32_t> origin;                     ///< per hex: the pass's input hex (messages)
};

/// Round `round` over the whole `mesh`: every hex refines the local axes whose piece has colour
/// `round` (color[piece]), with the directional template its split edges (node marks) call for;
/// children inherit the pieces of the parent axes their edges run along, new nodes inside split
/// edges are marked. `piece_name` describes a piece for messages. New nodes go to their parent's
/// trilinear map of the `positions` of the templates of `templates` (what is created does not
/// depend on either). Throws
/// OperationError where a hex has no directional template or two hexes around a split edge would
/// not split it in the same round.
RoundCounts sheet_round(HexMesh& mesh, RoundState& state, const std::vector<int32_t>& color,
                        int32_t round, const std::function<std::string(int32_t)>& piece_name,
                        TemplatePositions positions = TemplatePositions::exact,
                        const TemplateLibrary& templates = template_library_committed());

/// What the rounds do to one hex with corner marks `marks` (bit v: vertex v marked) whose local
/// axis k is refined in round rank[k] (-1: never), as one template (TemplateTag::sheet, on the
/// exact grid, compiled for symmetry 0; its reference positions the rounds run again with the
/// directional templates' reference positions in `templates`, so the face rules of
/// template_reference.hpp compose as in the Selective Approach's directional hexes; its movable
/// nodes from the configurations of `templates` when `configuration_table` is set and they list
/// it; without `placed`,
/// the thesis' trilinear placement, no reference positions and no children's quality at them), with
/// the hashes of
/// its six face subdivisions per face frame (face_hash[lf][2 * i0 + (step == 1 ? 0 : 1)]: origin at
/// position i0 of hex_faces[lf], u towards i0 + step) so neighbours can be compared before anything
/// is applied.
struct SheetComposite {
  std::unique_ptr<HexTemplate> tmpl;
  RoundCounts counts;
  bool positive = true;  ///< every child positive in the reference cube
  std::array<std::array<uint64_t, 8>, 6> face_hash{};
};
std::unique_ptr<SheetComposite> sheet_composite_build(
    uint8_t marks, const std::array<int8_t, 3>& rank, int32_t input_hex,
    const TemplateLibrary& templates, bool configuration_table = true, bool placed = true);

/// Hash of an unrefined face (any frame).
uint64_t sheet_whole_face_hash();

/// The face frame index (see SheetComposite::face_hash) of local face lf of a hex.
int sheet_face_frame_index(const HexCell& hex, int lf);

}  // namespace hexrefine::sheet_detail
