#pragma once
/// \file
/// The template optimiser behind `hexrefine templates --optimize` (experiments/cli_templates.cpp):
/// it computes the table of reference positions (algorithms/templates/template_reference.hpp)
/// offline and writes it as the C++ source the library compiles in
/// (algorithms/templates/template_reference_table.inc). A tool, not library: the library reads
/// the committed table and nothing else; the optimiser tries its candidate tables by building a
/// library of each (template_library_build) and passing it to the refinement it evaluates, with
/// the node optimizer and joint ascent of node placement doing the unit-cube work.

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "algorithms/templates/template_reference.hpp"

namespace hexrefine {

/// Maximises the minimum scaled Jacobian of tmpl's children on the unit cube over the reference
/// positions of the nodes `movable` flags (one per node; the others stay), from tmpl.reference
/// (its exact positions when empty), no move giving a child an edge ratio above
/// max(max_edge_ratio, its start) (node_optimizer.hpp's sweeps and node_joint_ascent.hpp's
/// joint ascent, in rounds until the minimum stops rising). Deterministic. Writes
/// tmpl.reference (does not compile) and returns the minimum.
double template_reference_optimize_nodes(HexTemplate& tmpl, const std::vector<uint8_t>& movable,
                                         double max_edge_ratio);

/// The offline optimisation of the standard templates (see template_optimize.cpp): the face
/// rule (along, across) that maximises the smallest unit-cube minimum over the templates with
/// 1-4 faces (1-13, 1-5, 1-4), each template's movable nodes at that rule, each template's own
/// best rule (the bound), and the adjustment rule that maximises the minimum of the L-shaped
/// case (the thesis' G-1 on a 4 x 4 x 4 brick) at the reference positions, its directional
/// configurations optimised. The result has no configurations
/// (template_reference_add_configurations adds them).
TemplateReferenceTable template_reference_optimize(
    double max_edge_ratio = template_reference_edge_ratio);

/// Adds to `table` the directional configurations of `composites` (plan-owned templates of
/// both refiners with composed reference positions, e.g. from the plans of a corpus of
/// refinements): each distinct configuration once, its movable nodes optimised on the unit
/// cube (template_reference_optimize_nodes, the cap table.configuration_edge_ratio: the largest
/// edge ratio of a child of `composites` at the exact positions) and kept when that raises its
/// minimum.
/// `counts` (empty, or one per composite): how many hexes each stands for (1 when empty).
void template_reference_add_configurations(TemplateReferenceTable& table,
                                           std::span<const HexTemplate* const> composites,
                                           std::span<const int64_t> counts = {});

/// The corpus of the directional configurations: generated meshes and seeded target sets,
/// planned by both refiners with `templates` and the configuration table off (their composed
/// positions; the same every run); one composite per configuration in `out`, how many hexes had
/// it in `counts`. Returns the corpus' description (TemplateReferenceTable::corpus).
std::string template_corpus_collect(const TemplateLibrary& templates,
                                    std::vector<std::unique_ptr<HexTemplate>>& out,
                                    std::vector<int64_t>& counts);

/// `hexrefine templates --optimize`'s table: template_reference_optimize, then the directional
/// configurations of the corpus (template_corpus_collect) planned with the optimised templates.
TemplateReferenceTable template_table_optimize();

/// The table as the C++ source of template_reference_table.inc.
std::string template_reference_table_source(const TemplateReferenceTable& table);

}  // namespace hexrefine
