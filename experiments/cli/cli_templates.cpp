/// \file
/// `hexrefine templates [--report R.json] [--optimize OUT]`: the template library
/// (algorithms/templates/template_library.hpp) as a table: every template's split edges, nodes,
/// children, the minimum scaled Jacobian of its children alone on the unit cube at the exact
/// (thesis') positions and at the reference positions
/// (algorithms/templates/template_reference.hpp), the bound a rule of the template's own would
/// reach where the shared face rule stops it, and the sets it belongs to; the directional
/// configurations of the committed table. The JSON behind results/templates.md.
///
/// --optimize OUT runs the template optimiser (experiments/cli/template_optimize.hpp) and writes
/// the table's C++ source to OUT (algorithms/templates/template_reference_table.inc is the
/// committed one); the listing then shows the new table, through a library built from it. The
/// directional configurations are collected from the plans of a fixed corpus of generated
/// refinements (the configuration table off: their composed positions), planned with the
/// optimised templates.

#include <bit>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>

#include "algorithms/templates/template_reference.hpp"
#include "experiments/cli/cli.hpp"
#include "experiments/cli/cli_output.hpp"
#include "experiments/cli/template_optimize.hpp"
#include "mesh/atomic_file.hpp"
#include "mesh/error.hpp"

namespace hexrefine {

namespace {

/// What stops a template where its reference positions leave it, in words.
std::string template_constraint(const TemplateReferenceEntry& e) {
  if (e.own_rule_min > e.reference_min + 1e-3)
    return "the 1-4 face rule shared with 1-13, 1-5, 1-4";
  if (e.reference_min >= 1 - 1e-12) return "none (boxes)";
  if (e.tag == TemplateTag::t1_3_adjust1 || e.tag == TemplateTag::t1_3_adjust2)
    return "adjustment nodes placed for the neighbours (the L-shaped case's rule)";
  return "its own: the parent's corners fixed";
}

int templates_run(const CliArgs& a) {
  if (!a.positional.empty())
    throw InputError("hexrefine templates: unexpected argument '" + a.positional[0] + "'");
  const std::optional<std::string> report = a.value("--report");
  if (report) cli_output_check("hexrefine templates", *report, CliOutputKind::report);
  const std::optional<std::string> optimize = a.value("--optimize");
  if (optimize) cli_output_check("hexrefine templates", *optimize, CliOutputKind::report);

  // What the listing shows: the committed table and its library, or the table computed here
  // and a library of it.
  TemplateReferenceTable used = template_reference_committed();
  std::unique_ptr<const TemplateLibrary> optimised;
  if (optimize) {
    TemplateReferenceTable table = template_table_optimize();
    std::cout << "directional configurations: " << table.corpus_configurations << " distinct in "
              << table.corpus_hexes << " directional hexes, " << table.configurations.size()
              << " raised by the optimisation kept\n";
    file_write_atomically(*optimize,
                          [&](std::ostream& os) { os << template_reference_table_source(table); });
    optimised = template_library_build(table);
    used = std::move(table);
  }
  const TemplateLibrary& library = optimised ? *optimised : template_library_committed();

  nlohmann::json list = nlohmann::json::array();
  std::cout << "face rule (1-4 face transition nodes, u along the split edge, v across): ("
            << used.rules.along << ", " << used.rules.across
            << "), thesis (1/3, 1/2); adjustment nodes (along, depth): ("
            << used.rules.adjustment_along << ", " << used.rules.adjustment_depth
            << "), thesis (1/3, 5/6), the L-shaped case at 4^3 " << used.adjustment_case_min
            << "\n";
  std::cout << std::left << std::setw(10) << "template" << std::setw(7) << "split" << std::setw(7)
            << "nodes" << std::setw(10) << "children" << std::setw(11) << "trilinear"
            << std::setw(11) << "reference" << std::setw(9) << "bound"
            << "constraint; sets\n";
  for (const HexTemplate& standard : library.standard) {
    const HexTemplate* t = &standard;
    const uint16_t mask = template_split_edges(*t);
    std::vector<std::string> sets;
    for (const auto& [set, name] :
         {std::pair{TemplateSet::element_by_element, "element_by_element"},
          std::pair{TemplateSet::sheet_directional, "sheet_directional"}})
      if (library.choice(mask, set).tmpl == t) sets.push_back(name);
    const double trilinear = template_validate(*t);
    const double reference = template_validate(*t, TemplatePositions::reference);
    TemplateReferenceEntry entry;
    entry.tag = t->tag;
    entry.trilinear_min = trilinear;
    entry.reference_min = reference;
    entry.own_rule_min = reference;
    for (const TemplateReferenceEntry& e : used.templates)
      if (e.tag == t->tag) {
        entry.own_rule_min = e.own_rule_min;
        entry.own_rule = e.own_rule;
      }
    const std::string constraint = template_constraint(entry);
    list.push_back({{"template", template_tag_name(t->tag)},
                    {"split_edges", std::popcount(mask)},
                    {"nodes", t->nodes.size()},
                    {"children", t->children.size()},
                    {"min_scaled_jacobian_alone", trilinear},
                    {"min_scaled_jacobian_reference", reference},
                    {"min_scaled_jacobian_own_rule", entry.own_rule_min},
                    {"own_rule", {entry.own_rule.along, entry.own_rule.across}},
                    {"constraint", constraint},
                    {"sets", sets}});
    std::string joined;
    for (const std::string& s : sets) joined += (joined.empty() ? "" : ", ") + s;
    std::cout << std::left << std::setw(10) << template_tag_name(t->tag) << std::setw(7)
              << std::popcount(mask) << std::setw(7) << t->nodes.size() << std::setw(10)
              << t->children.size() << std::setw(11) << std::setprecision(4) << trilinear
              << std::setw(11) << reference << std::setw(9) << entry.own_rule_min << constraint
              << "; " << joined << "\n";
  }
  double worst_composed = 1, worst_reference = 1;
  int64_t seen = 0;
  for (const TemplateReferenceConfiguration& c : used.configurations) {
    worst_composed = std::min(worst_composed, c.composed_min);
    worst_reference = std::min(worst_reference, c.reference_min);
    seen += c.seen;
  }
  std::cout << "directional configurations in the table: " << used.configurations.size() << " of "
            << used.corpus_configurations << " in the corpus' " << used.corpus_hexes
            << " directional hexes (" << seen
            << " of them); worst unit-cube minimum of those composed " << worst_composed
            << ", at the table's positions " << worst_reference
            << "; of every configuration of the corpus at its positions " << used.corpus_worst_min
            << "\n";
  if (report) {
    nlohmann::json out = {
        {"templates", list},
        {"face_rule", {used.rules.along, used.rules.across}},
        {"adjustment_rule", {used.rules.adjustment_along, used.rules.adjustment_depth}},
        {"adjustment_case_min", used.adjustment_case_min},
        {"max_edge_ratio", used.max_edge_ratio},
        {"directional_configurations",
         {{"count", used.configurations.size()},
          {"corpus_configurations", used.corpus_configurations},
          {"corpus_hexes", used.corpus_hexes},
          {"corpus_hexes_in_table", seen},
          {"corpus_worst_min", used.corpus_worst_min},
          {"corpus", used.corpus},
          {"worst_composed_min", worst_composed},
          {"worst_reference_min", worst_reference}}}};
    file_write_atomically(*report, [&](std::ostream& os) { os << out.dump(2) << "\n"; });
  }
  return 0;
}

}  // namespace

const CliCommand cli_templates_command = {
    "templates",
    "",
    "Lists the template library: split edges, nodes, children, minimum scaled Jacobian alone at "
    "the thesis' and at the reference positions.",
    {{"--report", "R.json", "write the table as JSON"},
     {"--optimize", "OUT",
      "compute the reference positions offline and write the table's C++ source to OUT "
      "(algorithms/templates/template_reference_table.inc is the committed one)"}},
    "",
    templates_run,
};

}  // namespace hexrefine
