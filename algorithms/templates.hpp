#pragma once
/// \file
/// Refinement templates as data, and the one generic routine that applies them.
///
/// A template is a list of nodes given by their position in the reference cube [0,1]^3 (canonical
/// orientation, mesh/hex_convention.hpp) and a list of child hexes over those nodes. To apply it
/// to a cell (an input hex, or a sub-hex of one made by earlier directional steps), a cube
/// symmetry maps the canonical cube onto the cell's local frame and the cell's corners map that
/// onto exact positions (integers over template_param_unit) in the input hex's reference cube.
/// Each template node is then keyed by where that position lies in the input hex:
///  - at a corner: the input node;
///  - inside an edge: (edge id, position along the edge, lower node id -> higher node id);
///  - inside a face: (face id, position in the face's canonical frame: origin at the face's
///    lowest node id, u towards its lower-id neighbour);
///  - inside the hex: (hex id, position), shared by the sub-hexes of that hex;
///  - an *adjustment* node (explicitly marked): (edge id, index) of the unsplit edge it collapses
///    faces at (Parrish, Appendix E: 1-3 with one / two adjustments), or its position in the hex
///    when cells are refined again (TemplateRefiner::set_adjustment_keys_by_position). Faces of
///    neighbouring hexes whose face-template nodes are collapsed onto it name it through an
///    alias (TemplateFaceAlias, TemplateRefiner::alias).
/// Because every cell derives the same key for the same edge/face position, neighbours share
/// nodes and conformity holds by construction. Nodes are positioned by the input hex's trilinear
/// map at their exact position; on a shared face both hexes' maps agree (the bilinear face map).
/// Node lookup (TemplateRefiner) goes through flat slot arrays wherever a key lies on the
/// thirds-and-halves grid of its entity: three slots per input edge, nine per input face
/// (allocated on first use). Only keys off that grid (sub-cells nested deeper, adjustment nodes)
/// and interior nodes shared by sub-cells go to a hash table. Templates are compiled once per cube
/// symmetry (TemplatePlan) so that refining a whole input hex is a table walk: no per-node search,
/// no allocation, no hash lookup.

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <unordered_map>
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

/// One template node as seen from a whole input hex in one cube symmetry.
struct TemplatePlanNode {
  /// TemplateNodeKey::Kind of the node (corner, edge, face or interior), or -1 if it needs the
  /// generic path (an adjustment node, or a position off the sixths grid).
  int8_t kind = -1;
  int8_t local = -1;               ///< local vertex, edge or face of the hex (by kind)
  std::array<int64_t, 3> param{};  ///< exact position in the hex's cube (template_param_unit)
  std::array<int8_t, 3> p6{};      ///< the same in sixths, where it is a multiple of 1/6
  std::array<double, 8> weight{};  ///< trilinear weights of the hex corners at that position
};

/// A template compiled for one cube symmetry: nodes classified by the entity of the hex they
/// lie on, children already re-oriented for the symmetry (positive in the hex's frame).
struct TemplatePlan {
  std::vector<TemplatePlanNode> nodes;
  std::vector<std::array<int16_t, 8>> children;
  bool generic = false;  ///< some node needs the generic path (TemplateRefiner::apply)
  /// Every edge and face node lies on the slot grid (thirds and halves): the plan can be
  /// applied in parallel (TemplateRefiner::apply_whole_batch).
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
  /// geometric: in 1-4 the top child's "y" edges (Q1 D, Q2 C) lie on the sheet that turns
  /// round from the split x-edge, so that direction belongs to x. Filled by
  /// template_compute_child_axes.
  std::vector<std::array<int8_t, 3>> child_axis;
  /// Per cube symmetry (48): the compiled template (template_compile); empty if not compiled,
  /// in which case TemplateRefiner::apply_whole takes the generic path.
  std::vector<TemplatePlan> plans;
};

/// Fills tmpl.child_axis.
void template_compute_child_axes(HexTemplate& tmpl);

/// Fills tmpl.plans (48 symmetries). The standard templates are compiled when built; a template
/// assembled by hand must be compiled again after its nodes or children change.
void template_compile(HexTemplate& tmpl);

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

/// Exact positions in an input hex's reference cube, in units of 1 / template_param_unit
/// (6^10: template nodes on cell boundaries sit on a sixths grid, so three levels of sub-cells,
/// each mapping sixths trilinearly, stay exact).
inline constexpr int64_t template_param_unit = 60466176;
using TemplateParam = std::array<int64_t, 3>;

/// What a node subdivides, independent of the hex it is seen from: kind corner (entity = node
/// id), edge (entity = edge id, a = position along the edge from its lower to its higher node
/// id), face (entity = face id, (a, b) = position in the face's canonical frame: origin at its
/// lowest node id, u towards the lower-id neighbour), interior (entity = input hex, a = x * (unit
/// + 1) + y, b = z), adjustment (entity = edge id, a = index along the edge's global direction)
/// and fresh (entity = node id: a node nobody else can name, e.g. an interior node off the grid).
struct TemplateNodeKey {
  enum Kind : int64_t { corner = 0, edge = 1, face = 2, interior = 3, adjustment = 4, fresh = 5 };
  int64_t entity = 0;  ///< kind << 40 | id
  int64_t a = 0, b = 0;
  bool operator==(const TemplateNodeKey& o) const {
    return entity == o.entity && a == o.a && b == o.b;
  }
  Kind kind() const { return static_cast<Kind>(entity >> 40); }
};

struct TemplateNodeKeyHash {
  size_t operator()(const TemplateNodeKey& k) const {
    uint64_t h = static_cast<uint64_t>(k.entity) * 0x9E3779B97F4A7C15ull;
    h ^= static_cast<uint64_t>(k.a) + 0x7F4A7C159E3779B9ull + (h << 6) + (h >> 2);
    h ^= static_cast<uint64_t>(k.b) + 0x94D049BB133111EBull + (h << 6) + (h >> 2);
    return static_cast<size_t>(h);
  }
};

/// A cell to refine: the whole input hex `hex`, or a sub-hex of it produced by earlier steps of
/// directional refinement. Corners carry their output node ids, their exact reference positions
/// in `hex`'s cube and their keys.
struct TemplateCell {
  int32_t hex = -1;
  HexCell nodes{};
  std::array<TemplateParam, 8> param{};
  std::array<TemplateNodeKey, 8> key{};
  /// Local axis k of this cell belongs to the sheet of axis axis[k] of the input hex (-1: a sheet
  /// closed inside a template, never refined again).
  std::array<int8_t, 3> axis = {0, 1, 2};
  bool whole = true;       ///< the input hex itself
  bool exact = true;       ///< every corner's param is exact (else it cannot be refined further)
  bool collapsed = false;  ///< a corner was redirected onto an adjustment node by a face alias
};

/// The one generic routine behind every template application: maps template nodes through a
/// cell's frame to exact positions in its input hex, keys them by what they subdivide and
/// shares them through a hash table, so that any two cells (of the same or of neighbouring input
/// hexes) that name the same edge or face position get the same node. Positions come from the
/// input hex's trilinear map. Adjustment nodes are positioned by their owner (the cell whose
/// template has them), overriding a provisional position set through an alias.
class TemplateRefiner {
 public:
  /// `mesh` and `topology` must outlive the refiner; output points start as a copy of the input's.
  TemplateRefiner(const HexMesh& mesh, const HexTopology& topology);

  /// The cell of a whole input hex.
  TemplateCell cell_whole(int32_t hex) const;

  /// Key of the exact point `p` of input hex `hex`'s reference cube.
  TemplateNodeKey key_at(int32_t hex, const TemplateParam& p) const;

  /// Key of adjustment node `k` (in the edge's global direction) of edge `edge`.
  static TemplateNodeKey key_adjustment(int32_t edge, int k);

  /// Nodes named `from` are the node named `to` from now on. Returns false (and changes nothing)
  /// if `from` already names a different node (two adjustments would collapse one face) or a
  /// node was already created under `from` (the alias would come too late).
  bool alias(const TemplateNodeKey& from, const TemplateNodeKey& to);

  /// Applies `tmpl` in orientation `symmetry` to `cell` and appends its children to `children`
  /// (their keys, params and axes filled in). Throws OperationError if the cell cannot be refined
  /// (inexact corners, or sub-cells nested too deep for exact positions).
  /// `node_keys`, if given, receives the key each template node was placed under (before
  /// aliasing), indexed like tmpl.nodes.
  void apply(const TemplateCell& cell, const HexTemplate& tmpl, int symmetry,
             std::vector<TemplateCell>& children,
             std::vector<TemplateNodeKey>* node_keys = nullptr);

  /// Applies `tmpl` in orientation `symmetry` to the whole input hex `hex` and appends the
  /// children's node ids to `children`; the same nodes as apply(cell_whole(hex), ...) would give,
  /// through the compiled plan (falls back to apply() for templates with adjustment nodes or
  /// without plans). `interior_private`: the hex gets no other application (no sub-cell of it is
  /// ever refined), so nodes strictly inside it are created without keying them for sharing.
  /// Precondition: the hex's eight node ids are distinct. Throws OperationError as apply().
  void apply_whole(int32_t hex, const HexTemplate& tmpl, int symmetry, bool interior_private,
                   std::vector<HexCell>& children);

  /// Key of the template node `node` (with its position `local_ref` in the cell's frame, i.e.
  /// already mapped by the symmetry) as apply() would place it; throws OperationError if the
  /// position is not exact.
  TemplateNodeKey key_of_template_node(const TemplateCell& cell, int symmetry,
                                       const TemplateNode& node) const;

  /// Key of every node created so far, indexed by node id - input point count (while
  /// record_keys is on, the default).
  const std::vector<TemplateNodeKey>& created_keys() const { return created_keys_; }
  /// Switches recording created_keys off (or on again): saves 24 bytes per node when no one
  /// asks for the keys. Precondition for switching off: no node created yet, or the keys
  /// recorded so far are not needed.
  void set_record_keys(bool on) { record_keys_ = on; }

  /// Key adjustment nodes of whole cells by their exact position inside the hex (like those of
  /// sub-cells) instead of by (edge, index): needed when the cells around an adjustment are
  /// refined again, so that a later template naming that position finds the same node. Aliases
  /// must then target TemplateRefiner::key_at positions (templates_apply keeps (edge, index)).
  void set_adjustment_keys_by_position(bool on) { adjustment_by_position_ = on; }

  /// Output points (input points first, then every node created).
  const std::vector<Eigen::Vector3d>& points() const { return points_; }
  std::vector<Eigen::Vector3d>& points() { return points_; }

  /// apply_whole on every application in order, interior nodes private, children written to
  /// children[child_offset[i] + c] (children sized by the caller): the same node ids, positions,
  /// keys and children as the serial calls, with the positions and children of up to `threads`
  /// contiguous runs of applications written in parallel after the node ids have been claimed
  /// in order. Serial when threads <= 1, when aliases exist or a plan is not slotted.
  /// Preconditions: ascending distinct hexes, each given once.
  void apply_whole_batch(std::span<const TemplateApplication> applications,
                         std::span<const size_t> child_offset, std::vector<HexCell>& children,
                         int threads);

  /// Reserves room for `nodes` created nodes (an estimate: saves reallocating the outputs).
  void reserve_created(size_t nodes);

 private:
  int32_t node_of(const TemplateNodeKey& key, const Eigen::Vector3d& x, bool* aliased);
  /// node_of with the position computed (position()) only if the node is created.
  template <class Position>
  int32_t node_at(const TemplateNodeKey& key, const Position& position, bool* aliased);
  /// The slot array entry of a key on the sixths grid of an edge or a face, or nullptr (the
  /// key is looked up in the hash table). The pointer is valid until the next slot call.
  int32_t* slot_of(const TemplateNodeKey& key);
  /// The node created under `key` (after aliasing), or -1.
  int32_t find_node(const TemplateNodeKey& key);
  int32_t create_node(const TemplateNodeKey& key, const Eigen::Vector3d& x);
  const TemplateNodeKey* alias_of(const TemplateNodeKey& key) const;
  const HexMesh& mesh_;
  const HexTopology& topology_;
  std::vector<Eigen::Vector3d> points_;
  std::vector<TemplateNodeKey> created_keys_;
  bool adjustment_by_position_ = false;
  bool record_keys_ = true;
  std::vector<int32_t> edge_slot_;     ///< 3 per input edge: sixths 2, 3, 4 in the edge's direction
  std::vector<int32_t> face_base_;     ///< per input face: offset into face_slot_, or -1
  std::vector<int32_t> face_slot_;     ///< 9 per used face: (u6 - 2) * 3 + (v6 - 2), u6, v6 in 2..4
  std::vector<uint8_t> face_aliased_;  ///< per input face: some key on it is aliased
  int64_t other_aliases_ = 0;          ///< aliases whose source is not a face key
  std::unordered_map<TemplateNodeKey, int32_t, TemplateNodeKeyHash> nodes_;
  std::unordered_map<TemplateNodeKey, TemplateNodeKey, TemplateNodeKeyHash> aliases_;
  struct Placed {
    int32_t node;
    TemplateParam param;
    TemplateNodeKey key;
    bool exact, aliased;
  };
  std::vector<Placed> placed_;       ///< scratch of apply()
  std::vector<int32_t> placed_ids_;  ///< scratch of apply_whole()
  /// Slot of a compiled edge or face node of a whole hex of a slotted plan, computed from its
  /// sixths without building the key (same slot as slot_of(plan_node_key(...))).
  int32_t& plan_node_slot(int32_t hex, const TemplatePlanNode& n,
                          std::array<std::array<int8_t, 3>, 6>& frame);
  /// Key of a compiled edge or face node of a whole hex (kind edge or face only).
  TemplateNodeKey plan_node_key(int32_t hex, const TemplatePlanNode& n,
                                std::array<std::array<int8_t, 3>, 6>& frame) const;
};

/// Applies every template application to its hex at once and returns the new mesh: untouched
/// hexes are copied, refined hexes are replaced by their children, in input hex order (so the
/// output is deterministic). Output attributes: those of the input, inherited by children;
/// "template_tag" set from each template's tag (untouched hexes keep theirs, or 0); and
/// "refinement_level" incremented for children.
/// Preconditions: at most one application per hex; `topology` built from `mesh`.
/// `threads`: see RefineOptions::threads (the output does not depend on it).
/// Throws OperationError if a cell is degenerate, naming the hex.
TemplateApplyResult templates_apply(const HexMesh& mesh, const HexTopology& topology,
                                    std::span<const TemplateApplication> applications,
                                    std::span<const TemplateFaceAlias> aliases = {},
                                    int threads = 1);

/// The standard templates in canonical orientation (see templates.cpp for each template's
/// split-edge pattern and construction). Only the ones defined so far are listed.
const HexTemplate& template_1_27();
/// 1-3: the four x-parallel edges (e0 e2 e4 e6) split; three slabs across x.
const HexTemplate& template_1_3();
/// 1-4: two parallel edges of one face split (e0, e4: face y=0); the 2D 1-4 extruded, 4 children.
const HexTemplate& template_1_4();
/// 1-5: one edge split (e0); faces y=0 and z=0 carry 1-4 face templates; 5 children.
const HexTemplate& template_1_5();
/// 1-13: the four edges of face z=0 split (e0..e3); 13 children.
const HexTemplate& template_1_13();
/// 1-3 with one adjustment: e0 e2 e4 split, e6 not; adjustment nodes on e6; 3 children.
const HexTemplate& template_1_3_adjust1();
/// 1-3 with two adjustments: e0 e6 split; adjustment nodes on e2 and e4; 3 children.
const HexTemplate& template_1_3_adjust2();

/// 1-13 with its four interior nodes at height `interior_height` in (0, 1) (for quality scans).
HexTemplate template_1_13_build(double interior_height);
/// Height of the four interior nodes of 1-13. The minimum scaled Jacobian is 4/13 = 0.3077 (the
/// thesis' L-shaped value) for every height in (0, 0.27], fixed by the corner children; above
/// that it drops (0.5 is degenerate). 1/6 lies inside the plateau and on the sixths grid.
inline constexpr double template_1_13_interior_height = 1.0 / 6.0;
/// Depth q of adjustment nodes: (x, q, q) for an adjustment at edge (y1, z1). A multiple of 1/6
/// so that sub-hexes of directional refinement keep exact reference positions.
inline constexpr double template_adjustment_depth = 5.0 / 6.0;

/// The template and symmetry for a split-edge mask (bit e = local edge e split), from a table
/// precomputed over the seven templates and 48 symmetries; tmpl is nullptr for mask 0 and for
/// masks no template matches (those hexes need directional refinement).
struct TemplateChoice {
  const HexTemplate* tmpl = nullptr;
  int8_t symmetry = 0;
};
TemplateChoice template_for_mask(uint16_t mask);

/// Checks a template on the unit cube: every child has positive scaled Jacobian, children fill the
/// cube (volumes sum to 1), and no face is shared by more than two children. Returns the minimum
/// scaled Jacobian of the children; throws OperationError describing the first defect.
double template_validate(const HexTemplate& tmpl);

/// Split-edge bit mask of a canonical template: local edges that carry edge nodes.
uint16_t template_split_edges(const HexTemplate& tmpl);

}  // namespace hexrefine
