#pragma once
/// \file
/// Refinement templates as data, and the one generic routine that applies them.
///
/// A template is a list of nodes given by their position in the reference cube [0,1]^3 (canonical
/// orientation, mesh/hex_convention.hpp) and a list of child hexes over those nodes. To apply it
/// to a hex, a cube symmetry maps the canonical reference cube onto the hex's local frame; each
/// template node is then classified by where its mapped position lies:
///  - at a corner: the parent's node;
///  - inside an edge: keyed by (edge id, position along the edge in the edge's global direction,
///    lower node id -> higher node id, in sixths);
///  - inside a face: keyed by (face id, position in the face's canonical frame, in sixths): the
///  frame
///    starts at the face's lowest node id and runs towards its lower-id neighbour;
///  - inside the hex: a new node of this hex only;
///  - an *adjustment* node (explicitly marked): keyed by (edge id, index) of the unsplit edge it
///    collapses faces at (Parrish, Appendix E: 1-3 with one / two adjustments). Faces of
///    neighbouring hexes whose face-template nodes are collapsed onto that edge name the same key
///    through TemplateFaceAlias.
/// Because every hex derives the same key for the same edge/face position, neighbours share nodes
/// and conformity holds by construction. The first hex to create a node sets its position from
/// its own trilinear map; for straight-edged hexes and planar (bilinear) faces both sides compute
/// the same point up to rounding.

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "algorithms/refiner.hpp"
#include "mesh/hex_mesh.hpp"
#include "mesh/topology.hpp"

namespace hexrefine {

/// Positions are multiples of 1/6 on the cube's edges and faces (thirds for splits, halves for
/// transition nodes); interior nodes may sit anywhere.
struct TemplateNode {
  std::array<double, 3> ref;    ///< position in the canonical reference cube
  int8_t adjustment_edge = -1;  ///< >= 0: an adjustment node belonging to this canonical local edge
  int8_t adjustment_index = 0;  ///< which adjustment node of that edge (ordered along the edge)
};

/// A template in canonical orientation. Children are 8 node indices each, VTK order, positively
/// oriented in the reference cube.
struct HexTemplate {
  TemplateTag tag = TemplateTag::untouched;
  std::vector<TemplateNode> nodes;
  std::vector<std::array<int16_t, 8>> children;
};

/// One of the 48 symmetries of the cube: reference point p maps to
/// q[k] = flip[k] ? 1 - p[axis[k]] : p[axis[k]].
struct CubeSymmetry {
  std::array<int8_t, 3> axis;
  std::array<bool, 3> flip;
  bool reflection;               ///< determinant -1 (children must be re-oriented)
  std::array<int8_t, 8> vertex;  ///< canonical local vertex -> actual local vertex
  std::array<int8_t, 12> edge;   ///< canonical local edge -> actual local edge
  std::array<int8_t, 6> face;    ///< canonical local face -> actual local face
};

/// The 48 symmetries; index 0 is the identity.
const std::array<CubeSymmetry, 48>& cube_symmetries();

/// Maps a reference point by a symmetry.
std::array<double, 3> cube_symmetry_apply(const CubeSymmetry& s, const std::array<double, 3>& p);

/// Bit mask of local edges (bit e = local edge e) mapped by a symmetry.
uint16_t cube_symmetry_edge_mask(const CubeSymmetry& s, uint16_t canonical_mask);

/// Apply `tmpl` to hex `hex` in orientation `symmetry` (index into cube_symmetries()).
struct TemplateApplication {
  int32_t hex;
  const HexTemplate* tmpl;
  int8_t symmetry;
};

/// Face-template nodes of face `face` that are collapsed onto the adjustment nodes of edge `edge`
/// (an edge of that face): a face node at canonical face position (u6, v6) in sixths whose
/// position, projected on the edge, is adjustment index k maps to adjustment key (edge, k).
/// `face_nodes` lists the (u6, v6) face positions to alias, in adjustment-index order.
struct TemplateFaceAlias {
  int32_t face;
  int32_t edge;
  std::array<std::array<int8_t, 2>, 2> face_positions;
};

struct TemplateApplyResult {
  HexMesh mesh;
  /// Per output hex: the input hex it came from (untouched hexes map to themselves).
  std::vector<int32_t> parent;
  int64_t hexes_created = 0;
  int64_t hexes_deleted = 0;
};

/// Applies every template application to its hex at once and returns the new mesh: untouched
/// hexes are copied, refined hexes are replaced by their children, in input hex order (so the
/// output is deterministic). Output attributes: those of the input, inherited by children;
/// "template_tag" set from each template's tag (untouched hexes keep theirs, or 0); and
/// "refinement_level" incremented for children.
/// Preconditions: at most one application per hex; `topology` built from `mesh`.
/// Throws OperationError if a template asks for more distinct nodes on one edge or face than
/// a slot can hold (a template bug), naming the hex.
TemplateApplyResult templates_apply(const HexMesh& mesh, const HexTopology& topology,
                                    std::span<const TemplateApplication> applications,
                                    std::span<const TemplateFaceAlias> aliases = {});

/// The standard templates in canonical orientation (see templates.cpp for each template's
/// split-edge pattern and construction). Only the ones defined so far are listed.
const HexTemplate& template_1_27();
/// 1-3: the four x-parallel edges (e0 e2 e4 e6) split; three slabs across x.
const HexTemplate& template_1_3();
/// 1-4: two parallel edges of one face split (e0, e4: face y=0); the 2D 1-4 extruded, 4 children.
const HexTemplate& template_1_4();
/// 1-5: one edge split (e0); faces y=0 and z=0 carry 1-4 face templates; 5 children.
const HexTemplate& template_1_5();

/// Checks a template on the unit cube: every child has positive scaled Jacobian, children fill the
/// cube (volumes sum to 1), and no face is shared by more than two children. Returns the minimum
/// scaled Jacobian of the children; throws OperationError describing the first defect.
double template_validate(const HexTemplate& tmpl);

/// Split-edge bit mask of a canonical template: local edges that carry edge nodes.
uint16_t template_split_edges(const HexTemplate& tmpl);

}  // namespace hexrefine
