#pragma once
/// \file
/// The template engine: the one routine that turns a refinement plan (which template goes on
/// which hex, in which orientation; which face nodes an adjustment merges) into the output mesh.
/// Both refiners decide (selective.hpp, sheet.hpp); only this file creates nodes and hexes.
///
/// A template (template_library.hpp) compiled for a cube symmetry lists its nodes by the entity of
/// the hex they lie on and their exact position in the hex's reference cube. Each node is keyed
/// by what it subdivides, independent of the hex it is seen from (NodeKey):
///  - at a corner: the input node;
///  - inside an edge: (edge, position along it from its lower node id);
///  - inside a face: (face, position in the face's canonical frame: origin at its lowest node id,
///    u towards the lower-id neighbour);
///  - inside a hex: (hex, position), shared by nobody else unless an alias names it.
/// Because both hexes of an edge or face derive the same key for the same position, neighbours
/// share nodes and conformity holds by construction. A node is placed where the first hex that
/// creates it maps its position trilinearly (on a shared face both hexes' maps agree: the bilinear
/// face map): its exact position (the thesis' placement) or its reference position
/// (template_reference.hpp, whose rule for edge and face nodes depends only on the edge's or
/// face's subdivision, so that there too it does not matter which hex comes first). Where a node
/// finally goes is decided later (node_placement.hpp): it never decides which nodes exist.
/// Lookup goes through flat slot arrays wherever a key lies on the thirds-and-halves grid of its
/// entity (three slots per input edge, nine per used input face); keys off that grid (sub-cells
/// nested deeper, keys named by aliases) go to a hash table.

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <unordered_map>
#include <vector>

#include "algorithms/templates/template_library.hpp"
#include "mesh/hex_mesh.hpp"
#include "mesh/ids.hpp"
#include "mesh/topology.hpp"

namespace hexrefine {

/// What a node subdivides (see the file comment). Positions are exact, in template_param_unit.
struct NodeKey {
  enum class Kind : uint8_t { corner = 0, edge = 1, face = 2, interior = 3 };
  int64_t entity = 0;  ///< kind << 40 | id
  int64_t a = 0, b = 0;

  Kind kind() const { return static_cast<Kind>(entity >> 40); }
  int32_t id() const { return static_cast<int32_t>(entity & 0xFFFFFFFFFF); }
  bool operator==(const NodeKey& o) const = default;

  static NodeKey corner(NodeId n) { return make(Kind::corner, index_of(n), 0, 0); }
  /// t: position along the edge from its lower node id, in (0, template_param_unit).
  static NodeKey edge(EdgeId e, int64_t t) { return make(Kind::edge, index_of(e), t, 0); }
  /// (u, v): position in the face's canonical frame.
  static NodeKey face(FaceId f, int64_t u, int64_t v) {
    return make(Kind::face, index_of(f), u, v);
  }
  /// p: position strictly inside hex h's reference cube.
  static NodeKey interior(HexId h, const TemplateParam& p) {
    return make(Kind::interior, index_of(h), p[0] * (template_param_unit + 1) + p[1], p[2]);
  }
  /// The position of an interior key.
  TemplateParam interior_param() const {
    return {a / (template_param_unit + 1), a % (template_param_unit + 1), b};
  }

 private:
  static NodeKey make(Kind kind, int32_t id, int64_t a, int64_t b) {
    return {(static_cast<int64_t>(kind) << 40) | id, a, b};
  }
};

struct NodeKeyHash {
  size_t operator()(const NodeKey& k) const {
    uint64_t h = static_cast<uint64_t>(k.entity) * 0x9E3779B97F4A7C15ull;
    h ^= static_cast<uint64_t>(k.a) + 0x7F4A7C159E3779B9ull + (h << 6) + (h >> 2);
    h ^= static_cast<uint64_t>(k.b) + 0x94D049BB133111EBull + (h << 6) + (h >> 2);
    return static_cast<size_t>(h);
  }
};

/// Strict order of keys (entity, a, b): for sorting and ordered containers.
inline bool node_key_less(const NodeKey& x, const NodeKey& y) {
  if (x.entity != y.entity) return x.entity < y.entity;
  if (x.a != y.a) return x.a < y.a;
  return x.b < y.b;
}

/// Key of the exact point `p` (each coordinate in [0, template_param_unit]) of hex `hex`'s
/// reference cube. Precondition: `topology` was built from `mesh` with TopologyParts::all.
NodeKey node_key_at(const HexMesh& mesh, const HexTopology& topology, HexId hex,
                    const TemplateParam& p);

/// Apply template `tmpl` in orientation `symmetry` (index into cube_symmetries()) to `hex`.
struct TemplateUse {
  HexId hex{};
  const HexTemplate* tmpl = nullptr;
  int8_t symmetry = 0;
  /// The hex is one of the pass's targets (else the method refines it to make room: a
  /// transition, a grown target, a directional hex). Read by the rules that choose the next
  /// pass's targets.
  bool target = false;
};

/// Nodes keyed `from` are the node keyed `to`: an adjustment (Appendix E) merges the two
/// neighbour faces at its unsplit edge, so the neighbours' face-template nodes there become the
/// adjusting hex's adjustment nodes (interior keys).
struct NodeAlias {
  NodeKey from, to;
};

/// What a refiner decided for one pass over a mesh: per refined hex the template to apply, and
/// the aliases. Templates made for this plan (a directional hex's sub-cells, a sheet
/// configuration's rounds) are owned by it; the others come from template_library.hpp.
struct RefinementPlan {
  std::vector<TemplateUse> uses;  ///< ascending distinct hexes
  std::vector<NodeAlias> aliases;
  std::vector<std::unique_ptr<HexTemplate>> owned;
};

struct PlanApplyResult {
  /// Output: untouched hexes copied, each refined hex replaced by its children, in input hex
  /// order (deterministic). Attributes: the input's, inherited by children; "template_tag" set
  /// from each template's tag (untouched hexes keep theirs, or 0); "refinement_level" one above
  /// the parent's; "parent_hex" inherited if the input has it, else the parent's index.
  HexMesh mesh;
  /// Per use (plan order): index of its first child in mesh.hexes (children are contiguous, in
  /// the order of the template's plan).
  std::vector<int32_t> first_child;
  int64_t hexes_created = 0, hexes_deleted = 0;
};

/// Applies `plan` to `mesh`, every new node at its parent's trilinear map of its template's
/// `positions` (exact: the thesis'; reference: HexTemplate::reference). `threads` > 1 writes the
/// positions and children of whole-hex applications in parallel after the node ids have been
/// claimed in hex order (the output does not depend on it; serial when the plan has aliases or a
/// template off the slot grid). The nodes and hexes do not depend on `positions`.
/// Preconditions: `topology` built from `mesh` (TopologyParts::all); uses as documented.
/// Throws OperationError naming the hex if an application would give a hex with a repeated node
/// (an alias collapsing two corners of one child).
PlanApplyResult plan_apply(const HexMesh& mesh, const HexTopology& topology,
                           const RefinementPlan& plan, int threads = 1,
                           TemplatePositions positions = TemplatePositions::exact);

/// Attributes of a refined mesh from its parents: every attribute of `input` inherited by its
/// children; "template_tag" = tag_of[parent] where that is >= 0 (a refined parent; untouched
/// hexes keep theirs, or 0); "refinement_level" one above the parent's for refined parents;
/// "parent_hex" inherited if `input` has it, else the parent's index. `parent` has one entry per
/// output hex (an input hex id), `tag_of` one per input hex. Replaces output.attributes.
void mesh_attributes_from_parents(const HexMesh& input, std::span<const int32_t> parent,
                                  std::span<const int32_t> tag_of, HexMesh& output);

/// The node store behind plan_apply, exposed for tests: creates nodes by key.
class TemplateEngine {
 public:
  /// `mesh` and `topology` must outlive the engine; output points start as a copy of the input's.
  /// New nodes go to the parent's trilinear map of their template's `positions`.
  TemplateEngine(const HexMesh& mesh, const HexTopology& topology,
                 TemplatePositions positions = TemplatePositions::exact);

  /// With reference positions: the position of the alias target `key` (an interior key of the
  /// adjusting hex), which another hex may name first; by default its hex's trilinear map of
  /// the key's exact position.
  void set_interior_position(const NodeKey& key, const Eigen::Vector3d& x) {
    interior_reference_[key] = x;
  }

  /// Nodes named `from` are the node named `to` from now on. Precondition: no node created yet.
  void alias(const NodeKey& from, const NodeKey& to);

  /// Applies `tmpl` in orientation `symmetry` to the whole hex `hex` and appends the children's
  /// node ids to `children`. `interior_private`: nodes strictly inside the hex are created
  /// without keying them for sharing (nobody else names them). Throws OperationError as
  /// plan_apply.
  void apply(HexId hex, const HexTemplate& tmpl, int symmetry, bool interior_private,
             std::vector<HexCell>& children);

  /// apply on every use in order, interior nodes private, children written to
  /// children[child_offset[i] + c] (children sized by the caller): the same node ids, positions
  /// and children as the serial calls, with the positions and children of up to `threads`
  /// contiguous runs of uses written in parallel after the node ids have been claimed in order.
  /// Serial when threads <= 1, when aliases exist or a plan is not slotted.
  void apply_batch(std::span<const TemplateUse> uses, std::span<const size_t> child_offset,
                   std::vector<HexCell>& children, int threads);

  /// Output points (input points first, then every node created).
  std::vector<Eigen::Vector3d>& points() { return points_; }

  /// Reserves room for `nodes` created nodes (an estimate: saves reallocating).
  void reserve_created(size_t nodes) { points_.reserve(points_.size() + nodes); }

 private:
  /// The node keyed `key` (after aliasing), created at position() if new.
  template <class Position>
  int32_t node_at(const NodeKey& key, const Position& position, bool* aliased);
  template <class Position>
  int32_t node_unaliased(const NodeKey& key, const Position& position);
  /// The slot array entry of a key on the slot grid of an edge or a face, or nullptr.
  int32_t* slot_of(const NodeKey& key);
  int32_t create_node(const Eigen::Vector3d& x);
  /// Position of an interior key (the alias target of another hex's face node).
  Eigen::Vector3d interior_position(const NodeKey& key) const;
  /// Slot of a compiled edge or face node of a slotted plan, from its sixths.
  int32_t& plan_node_slot(int32_t hex, const TemplatePlanNode& n,
                          std::array<std::array<int8_t, 3>, 6>& frame);
  /// Key of a compiled edge or face node.
  NodeKey plan_node_key(int32_t hex, const TemplatePlanNode& n,
                        std::array<std::array<int8_t, 3>, 6>& frame) const;

  /// The weights a compiled node is placed by (positions_).
  const std::array<double, 8>& weights(const TemplatePlanNode& n) const {
    return positions_ == TemplatePositions::reference ? n.reference_weight : n.weight;
  }

  const HexMesh& mesh_;
  const HexTopology& topology_;
  TemplatePositions positions_;
  std::unordered_map<NodeKey, Eigen::Vector3d, NodeKeyHash> interior_reference_;
  std::vector<Eigen::Vector3d> points_;
  std::vector<int32_t> edge_slot_;  ///< 3 per input edge: sixths 2, 3, 4 in the edge's direction
  std::vector<int32_t> face_base_;  ///< per input face: offset into face_slot_, or -1
  std::vector<int32_t> face_slot_;  ///< 9 per used face: (u6 - 2) * 3 + (v6 - 2)
  std::unordered_map<NodeKey, int32_t, NodeKeyHash> nodes_;
  std::unordered_map<NodeKey, NodeKey, NodeKeyHash> aliases_;
  std::vector<uint8_t> face_aliased_;  ///< per input face: some key on it is aliased
  std::vector<int32_t> placed_;        ///< scratch of apply()
};

}  // namespace hexrefine
