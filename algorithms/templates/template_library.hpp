#pragma once
/// \file
/// The template library: refinement templates as data (Parrish, Appendix E; Harris' directional
/// set). A template is a table of nodes given by their position in the reference cube [0,1]^3
/// (canonical orientation, mesh/hex_convention.hpp) and a table of child hexes over those
/// nodes, VTK order, positively oriented. The standard templates are literal tables in
/// template_library.cpp (positions in sixths: thirds for splits, halves for transition nodes,
/// 1/6 and 5/6 for the 1-13 interior and the adjustment nodes); nothing here applies them (that
/// is template_engine.hpp) or turns them (cube_symmetry.hpp).
///
/// Every template has two positions per node: the exact one (the thesis' positions: what the node
/// is keyed by, so which nodes exist never depends on where they go) and a reference position
/// (template_reference.hpp: the positions that maximise the minimum scaled Jacobian of the
/// children on the unit cube, computed offline and read from a committed table), where the
/// reference placement puts the node through its parent's trilinear map.
///
/// Also here, because they are data derived from the tables once:
///  - the mask table: which template and symmetry a split-edge pattern calls for, for both
///    refiners (TemplateSet);
///  - per template and symmetry, the compiled plan: each node classified by the entity of a hex
///    it lies on (corner, edge, face, inside), its exact position and the trilinear weights of
///    its exact and of its reference position, children re-oriented for the symmetry.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "algorithms/templates/cube_symmetry.hpp"

namespace hexrefine {

/// Template tag written per output hex (attribute "template_tag"). Untouched hexes keep 0.
enum class TemplateTag : int32_t {
  untouched = 0,
  t1_27 = 1,
  t1_13 = 2,
  t1_5 = 3,
  t1_4 = 4,
  t1_3 = 5,
  t1_3_adjust1 = 6,
  t1_3_adjust2 = 7,
  directional = 8,  ///< produced by directional refinement (several templates in sequence)
  sheet = 9,        ///< produced by sheet refinement passes
  t1_9 = 10,        ///< 1-3 across two directions (a sheet crossing itself in a refined hex)
};
inline constexpr int template_tag_count = 11;

/// Short name used in reports ("1-27", "1-3-adj1", ...); "unknown" outside the enumeration.
const char* template_tag_name(TemplateTag tag);

/// Exact positions in a hex's reference cube, in units of 1 / template_param_unit (6^10:
/// template nodes on cell boundaries sit on a sixths grid, so three levels of sub-cells, each
/// mapping sixths trilinearly, stay exact).
inline constexpr int64_t template_param_unit = 60466176;
using TemplateParam = std::array<int64_t, 3>;

/// A template node: position in the canonical reference cube; an adjustment node (Appendix E:
/// 1-3 with one or two adjustments) also names the canonical local edge it belongs to and its
/// index along it (0 nearer the edge's first vertex).
struct TemplateNode {
  std::array<double, 3> ref;
  int8_t adjustment_edge = -1;  ///< >= 0: an adjustment node of this canonical local edge
  int8_t adjustment_index = 0;
  /// Named by another hex too (a directional configuration's adjustment node, which the
  /// neighbours' aliases name): its reference position is not the template's to choose.
  bool shared = false;
};

/// What part of a hex a reference position lies on.
enum class CubeEntity : int8_t { corner, edge, face, interior };

/// One template node as seen from a whole hex in one cube symmetry.
struct TemplatePlanNode {
  CubeEntity entity = CubeEntity::interior;
  int8_t local = -1;  ///< local vertex, edge or face of the hex (by entity); -1 inside
  /// Not a multiple of 1 / template_param_unit (a node nested deeper than exact positions
  /// reach): always strictly inside, never shared, placed by `weight` alone.
  bool off_grid = false;
  TemplateParam param{};           ///< exact position in the hex's cube (when on the grid)
  std::array<int8_t, 3> p6{};      ///< the same in sixths where it is a multiple of 1/6, else -1
  std::array<double, 8> weight{};  ///< trilinear weights of the hex corners at that position
  /// Trilinear weights at the node's reference position (HexTemplate::reference) in this
  /// symmetry; equal to `weight` where the reference position is the exact one.
  std::array<double, 8> reference_weight{};
};

/// A template compiled for one cube symmetry: children re-oriented for it (positive in the
/// hex's frame).
struct TemplatePlan {
  std::vector<TemplatePlanNode> nodes;
  std::vector<std::array<int16_t, 8>> children;
  /// Every edge and face node lies on the thirds-and-halves grid (sixths 2, 3, 4) of flat slot
  /// arrays (template_engine.hpp): the plan can be applied without a hash lookup, in parallel.
  bool slotted = true;
};

/// A template in canonical orientation. Children are 8 node indices each, VTK order, positively
/// oriented in the reference cube.
struct HexTemplate {
  TemplateTag tag = TemplateTag::untouched;
  std::vector<TemplateNode> nodes;
  std::vector<std::array<int16_t, 8>> children;
  /// Per child and local axis: the canonical axis of the parent's sheet that this direction of
  /// the child belongs to (sheets followed through the children's shared faces, seeded by the
  /// pieces of the cube's edges), -1 for a sheet closed inside the template. Topological, not
  /// geometric: in 1-4 the top child's "y" edges lie on the sheet that turns round from the
  /// split x-edge, so that direction belongs to x. Filled by template_compute_child_axes.
  std::vector<std::array<int8_t, 3>> child_axis;
  /// Reference position of each node in the canonical cube (empty: every node at its exact
  /// position `ref`). Corners and adjustment nodes stay where `ref` puts them; a node on an edge
  /// or face of the cube is where template_reference.hpp's rule for that edge's or face's
  /// subdivision puts it (so two hexes sharing it agree); a node inside the cube is free.
  std::vector<std::array<double, 3>> reference;
  /// Per child: its scaled Jacobian on the unit cube with every node at its reference position
  /// (template_compile): what the child is on an undistorted parent (node_placement.cpp's
  /// yardstick in a later pass, whose parents are the earlier passes' children).
  std::vector<double> child_reference_quality;
  /// The largest edge ratio of a child on the unit cube at the reference positions
  /// (template_compile).
  double reference_edge_ratio = 1;
  /// Per cube symmetry: the compiled template (template_compile); the standard templates have
  /// all 48, a template made for one hex (plan-owned) only symmetry 0.
  std::vector<TemplatePlan> plans;
};

/// Reference position of node i of `tmpl` (its exact position `ref` when tmpl.reference is
/// empty).
inline const std::array<double, 3>& template_node_reference(const HexTemplate& tmpl,
                                                            std::size_t i) {
  return tmpl.reference.empty() ? tmpl.nodes[i].ref : tmpl.reference[i];
}

/// Fills tmpl.child_axis.
void template_compute_child_axes(HexTemplate& tmpl);

/// Fills tmpl.plans for symmetries 0 .. symmetry_count - 1 (48: all) and, with
/// `child_quality`, tmpl.child_reference_quality and tmpl.reference_edge_ratio (what placement
/// other than trilinear reads; a plan for the thesis' trilinear placement skips them: a scaled
/// Jacobian and an edge ratio per child of every directional hex). Throws OperationError if a
/// node off the exact grid is not strictly inside the cube (it could not be shared with a
/// neighbour), or if tmpl.reference is neither empty nor one position per node.
void template_compile(HexTemplate& tmpl, int symmetry_count = 48, bool child_quality = true);

/// The standard templates in canonical orientation, compiled for all 48 symmetries, at the
/// committed table's reference positions (template_library_committed, template_reference.hpp).
/// 1-27: all twelve edges split; 3 x 3 x 3 children.
const HexTemplate& template_1_27();
/// 1-13: the four edges of face z=0 split (e0..e3); 13 children.
const HexTemplate& template_1_13();
/// 1-5: one edge split (e0); faces y=0 and z=0 carry 1-4 face templates; 5 children.
const HexTemplate& template_1_5();
/// 1-4: two parallel edges of one face split (e0, e4: face y=0); 4 children.
const HexTemplate& template_1_4();
/// 1-3: the four x-parallel edges (e0 e2 e4 e6) split; three slabs across x.
const HexTemplate& template_1_3();
/// 1-3 with one adjustment: e0 e2 e4 split, e6 not; adjustment nodes on e6; 3 children.
const HexTemplate& template_1_3_adjust1();
/// 1-3 with two adjustments: e0 e6 split; adjustment nodes on e2 and e4; 3 children.
const HexTemplate& template_1_3_adjust2();
/// 1-9: the x- and y-parallel edges split, 3 x 3 columns (1-3 across x then across y as one
/// template): where a dual sheet crosses itself in a fully refined hex (sheet refinement).
const HexTemplate& template_1_9();

/// The tags of the standard templates, in the order of TemplateLibrary::standard.
inline constexpr std::array<TemplateTag, 8> template_standard_tags = {
    TemplateTag::t1_27, TemplateTag::t1_13,        TemplateTag::t1_5,         TemplateTag::t1_4,
    TemplateTag::t1_3,  TemplateTag::t1_3_adjust1, TemplateTag::t1_3_adjust2, TemplateTag::t1_9};

/// The standard template tagged `tag` from its literal table: nodes, children and child axes,
/// every node at its exact position (reference empty), not compiled. Throws OperationError for
/// a tag with no standard template.
HexTemplate template_standard_exact(TemplateTag tag);

/// 1-13 with its four interior nodes at height `interior_height` in (0, 1) (for quality scans;
/// reference positions the exact ones).
HexTemplate template_1_13_build(double interior_height);
/// Height of the four interior nodes of 1-13. The minimum scaled Jacobian is 4/13 = 0.3077 (the
/// thesis' L-shaped value) on a plateau of low heights, fixed by the corner children; above it
/// it drops (0.5 is degenerate; the scan: results/methods.md, "Template constants"). 1/6 lies
/// inside the plateau and on the sixths grid.
inline constexpr double template_1_13_interior_height = 1.0 / 6.0;
/// Depth q of adjustment nodes: (x, q, q) for an adjustment at edge (y1, z1). A multiple of 1/6
/// so that sub-hexes of directional refinement keep exact reference positions. Chosen, not given
/// by the thesis (its Figure E-21 is missing): 5/6 gives the L-shaped case a higher minimum than
/// 2/3 (results/methods.md, "Template constants").
inline constexpr double template_adjustment_depth = 5.0 / 6.0;

/// Which templates a split-edge pattern may call for.
enum class TemplateSet : uint8_t {
  /// The Selective Approach's element-by-element set (Appendix E): 1-27, 1-13, 1-5, 1-4, 1-3,
  /// 1-3 with one and with two adjustments. Restricted to the edges of one direction it is also
  /// the set of its directional steps.
  element_by_element,
  /// Harris' directional set, one direction at a time: 1-3, 1-4, 1-5, and where a dual sheet
  /// crosses itself in a fully split hex, 1-9 (two directions) and 1-27 (three).
  sheet_directional,
};

/// The template and symmetry for a split-edge mask (bit e = local edge e split); tmpl is nullptr
/// for mask 0 and for masks the set has no template for.
struct TemplateChoice {
  const HexTemplate* tmpl = nullptr;
  int8_t symmetry = 0;
};
/// One choice per split-edge mask (4096).
using TemplateMaskTable = std::array<TemplateChoice, 4096>;

/// Fills `table` (every choice empty on entry) as the mask table of a set's templates
/// (`templates`, in order; they must outlive it): for each template and each of the 48
/// symmetries, the mask the symmetry maps its canonical mask onto; the first template and
/// symmetry to reach a mask win. In place: a table is 64 KiB, built where it stays.
void template_mask_table_fill(std::span<const HexTemplate* const> templates,
                              TemplateMaskTable& table);

/// The templates of `set` in the order template_mask_table_fill takes them.
std::vector<TemplateTag> template_set_tags(TemplateSet set);

/// The committed library's choice for `mask` (TemplateLibrary::choice).
TemplateChoice template_for_mask(uint16_t mask, TemplateSet set = TemplateSet::element_by_element);

/// True for the two adjusted 1-3 templates (their adjustment nodes merge neighbours' faces), of
/// any library (by tag).
bool template_is_adjusted(const HexTemplate& tmpl);

/// Which position of each template node: the exact one (TemplateNode::ref, the thesis') or the
/// reference one (HexTemplate::reference).
enum class TemplatePositions : uint8_t { exact, reference };

/// Checks a template on the unit cube with its nodes at `positions`: every child has positive
/// scaled Jacobian, children fill the cube (volumes sum to 1; an adjusted template leaves a
/// wedge at its unsplit edge to the neighbours), and no face is shared by more than two
/// children. Returns the minimum scaled Jacobian of the children; throws OperationError
/// describing the first defect.
double template_validate(const HexTemplate& tmpl,
                         TemplatePositions positions = TemplatePositions::exact);

/// Split-edge bit mask of a canonical template: local edges that carry edge nodes.
uint16_t template_split_edges(const HexTemplate& tmpl);

/// Trilinear weights of the eight corners at reference point p (hex_convention.hpp order).
std::array<double, 8> hex_trilinear_weights(const std::array<double, 3>& p);

}  // namespace hexrefine
