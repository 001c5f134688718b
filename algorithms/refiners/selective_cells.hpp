#pragma once
/// \file
/// Sub-cells of the Selective Approach's directional refinement (Parrish, section 5.3), kept
/// symbolically: a cell is the whole input hex or a sub-hex made by earlier directional steps,
/// each corner given by its exact position in the input hex's reference cube and its node key
/// (template_engine.hpp). Refining a cell by a template maps the template's nodes through the
/// cell's corners (exact while positions stay on the template_param_unit grid) and keys them,
/// so that cells of one hex and of neighbouring hexes name a shared edge or face position alike.
/// No node is created here: when the directional steps are done, a hex's cells become one
/// template of that hex (selective_cells_template) and the engine applies it like any other.

#include <array>
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "algorithms/templates/template_engine.hpp"
#include "algorithms/templates/template_reference.hpp"

namespace hexrefine {

/// A node of a cell off the exact grid (nested too deep): unique to its hex, never shared.
/// Key kind interior with `b` < 0 never collides with an exact interior key.
struct TemplateCell {
  int32_t hex = -1;
  std::array<TemplateParam, 8> param{};  ///< exact position of each corner (if exact)
  std::array<NodeKey, 8> key{};          ///< key of each corner, before aliasing
  /// Reference position of each corner in the hex's cube (exact ones: param / unit).
  std::array<std::array<double, 3>, 8> ref{};
  /// Reference position of each corner for the reference placement (template_reference.hpp):
  /// the steps' templates' reference positions composed through the cells' `place` corners.
  std::array<std::array<double, 3>, 8> place{};
  /// Local axis k of this cell belongs to the sheet of axis axis[k] of the input hex (-1: a sheet
  /// closed inside a template, never refined again).
  std::array<int8_t, 3> axis = {0, 1, 2};
  bool whole = true;       ///< the input hex itself
  bool exact = true;       ///< every corner's param is exact (else it cannot be refined further)
  bool collapsed = false;  ///< a corner is redirected onto another node by an alias
};

/// The symbolic refiner of cells over one input mesh: keys, aliases, the keys in use.
class CellRefiner {
 public:
  /// `mesh` and `topology` (TopologyParts::all) must outlive the refiner.
  CellRefiner(const HexMesh& mesh, const HexTopology& topology);

  /// The cell of a whole input hex.
  TemplateCell cell_whole(int32_t hex) const;

  /// Key of template node `node` of `tmpl` applied to `cell` in orientation `symmetry`, as
  /// refine() would key it. Throws OperationError if the position is not exact.
  NodeKey key_of_template_node(const TemplateCell& cell, int symmetry,
                               const TemplateNode& node) const;

  /// Nodes named `from` are the node named `to` from now on. Returns false (and changes nothing)
  /// if `from` already names a different node, or a cell already uses `from` (too late).
  bool alias(const NodeKey& from, const NodeKey& to);

  /// `key` after aliasing.
  const NodeKey& resolve(const NodeKey& key) const;

  /// Some alias names `key` as its target (an adjustment node that neighbours name too).
  bool is_alias_target(const NodeKey& key) const { return alias_targets_.count(key) > 0; }

  /// Refines `cell` by `tmpl` in orientation `symmetry`, appending the children (their keys,
  /// params and axes filled in); `node_keys`, if given, receives the key of each template node
  /// (before aliasing), indexed like tmpl.nodes. Throws OperationError if the cell cannot be
  /// refined (inexact corners, a boundary node off the grid, two template nodes on one node).
  void refine(const TemplateCell& cell, const HexTemplate& tmpl, int symmetry,
              std::vector<TemplateCell>& children, std::vector<NodeKey>* node_keys = nullptr);

  /// The aliases registered so far, in a deterministic order.
  std::vector<NodeAlias> aliases() const;

 private:
  const HexMesh& mesh_;
  const HexTopology& topology_;
  std::unordered_map<NodeKey, NodeKey, NodeKeyHash> aliases_;
  std::unordered_set<NodeKey, NodeKeyHash> alias_targets_;
  std::unordered_set<NodeKey, NodeKeyHash> used_;
  int64_t off_grid_count_ = 0;
};

/// The template of one hex made of its cells: nodes at the cells' corner positions (exact ones
/// on the grid, so the engine keys them and neighbours share them; off-grid ones strictly inside),
/// children the cells, tag `tag`; compiled for symmetry 0 only. Reference positions: the cells'
/// composed `place` corners, the movable nodes (strictly inside, no alias target of `refiner`,
/// which are TemplateNode::shared) from the directional configurations of `templates` when
/// they list this one and `configuration_table` is set (template_reference.hpp). Without
/// `placed` (the thesis' trilinear placement) neither reference positions nor the children's
/// quality at them are made: the template holds the exact positions alone.
std::unique_ptr<HexTemplate> selective_cells_template(
    const std::vector<TemplateCell>& cells, TemplateTag tag, const CellRefiner& refiner,
    const TemplateLibrary& templates = template_library_committed(),
    bool configuration_table = true, bool placed = true);

}  // namespace hexrefine
