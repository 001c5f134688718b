#pragma once
/// \file
/// Reference positions of template nodes: where, in the unit cube, the new nodes of a template
/// go so that the worst child is as good as it can be (the thesis' positions, thirds, halves and
/// sixths, give 1-13 4/13 = 0.3077 on the unit cube). Computed offline by the template optimiser
/// (`hexrefine templates --optimize`, experiments/cli/template_optimize.hpp), written as a C++
/// table (template_reference_table.inc, committed) that the library reads when it builds its
/// templates (TemplateLibrary); the reference placement maps them through each parent's
/// trilinear map, at the cost of the thesis' placement.
///
/// Conformity by construction. A node is shared by every hex around the edge or face it
/// subdivides (template_engine.hpp keys it by the exact position, so which nodes exist never
/// depends on the reference positions); its position must therefore not depend on which of those
/// hexes places it. It does not, because a node on an edge or face of its parent is placed by a
/// rule that depends only on that edge's or face's own subdivision:
///  - on an edge: the exact position (thirds): the parent's trilinear map restricted to an edge
///    is the linear map of its two end nodes, the same from every hex around it;
///  - on a face: the face's subdivision pattern is one of the face templates (1-9: four split
///    edges, 1-3: two opposite, 1-4: one), the same seen from both hexes (that is what makes them
///    conformal). 1-9 keeps its thirds (1-27's children stay boxes); 1-4's two transition nodes
///    go to (a, b) and (1 - a, b) in the face's frame (u along the split edge, v away from it;
///    FaceTransitionRule), a rule symmetric under the one reflection that maps the pattern onto
///    itself, so both hexes name the same two points whatever their orientation; and the
///    parent's trilinear map restricted to a face is the bilinear map of its four corners, which
///    both hexes share;
///  - the directional configurations (a hex refined by several directional steps,
///    selective_cells.hpp) compose the steps' reference positions through each cell's
///    reference corners: each cell face's nodes follow the rule of that cell face's pattern in
///    the bilinear map of its corners, whose reference positions agree by induction over the
///    steps, and both sides of a face refine its directions in the same order;
///  - a node strictly inside the parent belongs to that parent alone and is free; so is every
///    node strictly inside a directional hex (the table holds them per configuration, found by
///    a canonical form under the 48 cube symmetries), except the adjustment nodes, which the
///    neighbours name through aliases and which keep their exact positions.
/// A reference position on a face of the parent stays in that face, so a boundary node lies
/// on the parent's bilinear boundary face: on the input's boundary patch in a first pass (the
/// parent's face is the patch). In a later pass a parent's boundary face is a piece of an input
/// patch that is the bilinear map of its own corners only when those corners form a rectangle
/// of the patch's parameters (1-27 children) or the patch is planar: node_placement.cpp projects
/// the others onto the patch.

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "algorithms/templates/template_library.hpp"

namespace hexrefine {

/// The rules for the nodes a template shares with its neighbours.
struct ReferenceRules {
  /// Where the two transition nodes of a 1-4 face template go in the face's frame: (along,
  /// across) and (1 - along, across), u along the split edge (from either end: the pattern is
  /// symmetric), v away from it, both in (0, 1). The thesis': (1/3, 1/2).
  double along = 1.0 / 3.0;
  double across = 0.5;
  /// Where the adjustment nodes of the adjusted 1-3 templates go (the nodes their two
  /// neighbours' merged 1-4 faces name instead of their transition nodes): canonical (x, y, z)
  /// with x = adjustment_along (index 0) or 1 - adjustment_along (index 1) and the thesis'
  /// depth 5/6 (1/6) in y and z replaced by adjustment_depth (1 - adjustment_depth). The
  /// thesis': 1/3 and 5/6 (template_adjustment_depth).
  double adjustment_along = 1.0 / 3.0;
  double adjustment_depth = 5.0 / 6.0;
};

/// The committed table's rules.
ReferenceRules template_reference_rules();

/// True if node i of `tmpl` is free for the reference positions: strictly inside the cube and
/// named by no other hex (not an adjustment node, TemplateNode::shared false).
bool template_node_movable(const HexTemplate& tmpl, size_t i);

/// Sets tmpl.reference for a template in canonical orientation made of face templates (1-9,
/// 1-3, 1-4: every standard template): corners, edge nodes and 1-9 face nodes at their exact
/// positions, 1-4 face nodes and adjustment nodes by `rules`, the movable nodes
/// (template_node_movable, in node order) at `interior` (their exact positions when empty).
/// Throws OperationError for a face node of another pattern or a wrong count. Does not compile.
void template_reference_set(HexTemplate& tmpl, const ReferenceRules& rules,
                            std::span<const std::array<double, 3>> interior);

/// The edge-ratio cap of the offline optimisation: no child of a template gets an edge ratio
/// above max(6, its ratio at the exact positions). 6 is the largest the thesis' positions give
/// a standard template's child (1-13's corner children: an edge of 1 beside one of 1/6), so the
/// reference positions never stretch a child more than the thesis' worst; placement's looser
/// cap (PlacementOptions::max_edge_ratio) reaches the same minima on the standard templates, but
/// through slivers, which a distorted parent then inverts first (results/templates.md).
/// The directional configurations follow the same principle: no child above max(the largest
/// edge ratio the thesis' positions give a child of the corpus' configurations, its own there).
inline constexpr double template_reference_edge_ratio = 6;

/// One standard template in the table: its movable nodes' reference positions and, for the
/// report, its unit-cube minima.
struct TemplateReferenceEntry {
  TemplateTag tag = TemplateTag::untouched;
  /// Minimum scaled Jacobian of the children on the unit cube: at the exact (thesis') positions,
  /// at the reference positions (the shared face rule), and with a face rule of the template's
  /// own (the bound the shared rule stops it at when lower).
  double trilinear_min = 0, reference_min = 0, own_rule_min = 0;
  ReferenceRules own_rule;
  std::vector<std::array<double, 3>> interior;  ///< movable nodes' reference positions
};

/// One directional configuration of the table, in its canonical frame.
struct TemplateReferenceConfiguration {
  std::array<uint64_t, 2> hash{};
  int32_t nodes = 0;
  double composed_min = 0, reference_min = 0;  ///< unit-cube minima before and after
  int64_t seen = 0;                            ///< hexes of the corpus with it
  std::vector<std::array<double, 3>> movable;  ///< canonical order of the movable nodes
};

/// The table: the rules, the standard templates' movable nodes, the configurations.
struct TemplateReferenceTable {
  ReferenceRules rules;
  /// The adjustment rule's objective at its optimum: the minimum of the L-shaped case
  /// (experiments/cli/template_optimize.hpp).
  double adjustment_case_min = 0;
  double max_edge_ratio = template_reference_edge_ratio;  ///< of the standard templates
  double configuration_edge_ratio = 0;                    ///< of the configurations
  std::vector<TemplateReferenceEntry> templates;
  std::vector<TemplateReferenceConfiguration> configurations;  ///< ascending hash
  std::string corpus;  ///< what the configurations were collected from
  /// The corpus' directional hexes and their distinct configurations (those whose optimisation
  /// raised the minimum have a row), and the worst unit-cube minimum over all of them at the
  /// positions the library gives them (the table's, or the composed ones).
  int64_t corpus_hexes = 0, corpus_configurations = 0;
  double corpus_worst_min = 1;
};

/// The committed table (template_reference_table.inc): what the library reads.
TemplateReferenceTable template_reference_committed();

/// Sets tmpl.reference from `table` for a standard template (by its tag; a template the table
/// does not list keeps its exact positions, tmpl.reference empty; so does one whose positions
/// all equal the exact ones). Throws OperationError when the table's row has no positions for
/// a template with movable nodes. Does not compile.
void template_reference_from_table(HexTemplate& tmpl, const TemplateReferenceTable& table);

/// A template's configuration up to the 48 cube symmetries: two 64-bit hashes of its nodes'
/// exact positions and its children in a canonical frame (the symmetry `symmetry` maps the
/// template into it), and the order of the nodes there (order[k]: the node at canonical rank
/// k, nodes sorted by their position in the canonical frame).
struct TemplateConfiguration {
  std::array<uint64_t, 2> hash{};
  int8_t symmetry = 0;
  std::vector<int32_t> order;
};

/// The configuration of a template in canonical orientation (its nodes' `ref`; it need not be
/// compiled).
TemplateConfiguration template_configuration(const HexTemplate& tmpl);

/// The templates a refinement uses, at one table's reference positions: the standard templates
/// compiled for the 48 symmetries, the split-mask tables over them, and the table's directional
/// configurations. The library's own (template_library_committed) reads the committed table;
/// template_library_build makes one of another table, which is how the template optimiser
/// (experiments/cli/template_optimize.hpp) tries its candidates: a value passed to the
/// refinement (refine()'s `templates`), never a table swapped under the library. Neither
/// copyable nor movable: the mask tables point into `standard`.
struct TemplateLibrary {
  /// One directional configuration as the table file lists it: its movable nodes' positions
  /// (canonical order) are configuration_positions[first .. first + count).
  struct ConfigurationRow {
    uint64_t hash0, hash1;
    int32_t nodes, first, count;
    double composed_min, reference_min;
    int64_t seen;
  };
  /// 1-27, 1-13, 1-5, 1-4, 1-3, 1-3 with one and with two adjustments, 1-9 (template_standard_tags
  /// order).
  std::array<HexTemplate, 8> standard;
  /// Per TemplateSet: the template and symmetry of each split-edge mask
  /// (template_mask_table_fill).
  std::array<TemplateMaskTable, 2> masks;
  /// The table's directional configurations, ascending (hash0, hash1), and their positions: the
  /// committed table's compiled-in arrays themselves (nothing to build before the first lookup),
  /// or another table's, held in the storage below.
  std::span<const ConfigurationRow> configuration_rows;
  std::span<const std::array<double, 3>> configuration_positions;
  std::vector<ConfigurationRow> configuration_row_storage;
  std::vector<std::array<double, 3>> configuration_position_storage;

  TemplateLibrary() = default;
  TemplateLibrary(const TemplateLibrary&) = delete;
  TemplateLibrary& operator=(const TemplateLibrary&) = delete;

  /// The standard template tagged `tag`; OperationError for a tag with none.
  const HexTemplate& of(TemplateTag tag) const;
  /// The template and symmetry for a split-edge mask (template_for_mask, on this library).
  TemplateChoice choice(uint16_t mask, TemplateSet set = TemplateSet::element_by_element) const {
    return masks[static_cast<int>(set)][mask & 0xFFF];
  }
};

/// The library of `table`: every standard template (template_standard_build), the mask tables of
/// both sets, the table's configurations. Throws OperationError as template_reference_from_table.
std::unique_ptr<const TemplateLibrary> template_library_build(const TemplateReferenceTable& table);

/// The standard template tagged `tag` (template_standard_exact) with its reference positions
/// from `table` (template_reference_from_table), compiled for the 48 symmetries.
HexTemplate template_standard_build(TemplateTag tag, const TemplateReferenceTable& table);

/// The library of the committed table, built once (thread-safe): what every refinement uses
/// unless it is given another, and what template_1_27() ... template_for_mask() return from.
const TemplateLibrary& template_library_committed();

/// Sets the movable nodes' reference positions of a directional configuration (a plan-owned
/// template whose tmpl.reference holds the composed positions) from the configurations of
/// `templates`, if they list its configuration; returns whether it did. Does not compile.
bool template_reference_from_configurations(
    HexTemplate& tmpl, const TemplateLibrary& templates = template_library_committed());

}  // namespace hexrefine
