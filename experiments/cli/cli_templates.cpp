/// \file
/// `hexrefine templates [--report R.json] [--optimize OUT]`: the template library
/// (algorithms/templates/template_library.hpp) as a table: every template's split edges, nodes,
/// children, the minimum scaled Jacobian of its children alone on the unit cube at the exact
/// (thesis') positions and at the reference positions
/// (algorithms/templates/template_reference.hpp), the bound a rule of the template's own would
/// reach where the shared face rule stops it, and the sets it belongs to; the directional
/// configurations of the committed table. The JSON behind results/templates.md.
///
/// --optimize OUT runs the offline optimisation (template_reference_optimize) and writes the
/// table's C++ source to OUT (algorithms/templates/template_reference_table.inc is the committed
/// one). The directional configurations are collected from the plans of a fixed corpus of generated
/// refinements (selective_plan with the configuration table off: their composed positions),
/// which are built from the library's compiled-in reference positions: when the optimisation's
/// rule or templates differ from those, OUT gets the templates alone and the command says to
/// rebuild and run it again (a second run, on the new library, adds the configurations; the
/// optimisation is deterministic, so that is a fixed point).

#include <bit>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>

#include "algorithms/refiners/refiner.hpp"
#include "algorithms/templates/template_reference.hpp"
#include "experiments/cli/cli.hpp"
#include "experiments/cli/cli_output.hpp"
#include "mesh/atomic_file.hpp"
#include "mesh/error.hpp"
#include "mesh/generators.hpp"
#include "mesh/selection.hpp"
#include "mesh/topology.hpp"

namespace hexrefine {

namespace {

constexpr std::array<const HexTemplate* (*)(), 8> standard = {
    [] { return &template_1_27(); },        [] { return &template_1_13(); },
    [] { return &template_1_5(); },         [] { return &template_1_4(); },
    [] { return &template_1_3(); },         [] { return &template_1_3_adjust1(); },
    [] { return &template_1_3_adjust2(); }, [] { return &template_1_9(); }};

/// What stops a template where its reference positions leave it, in words.
std::string template_constraint(const TemplateReferenceEntry& e) {
  if (e.own_rule_min > e.reference_min + 1e-3)
    return "the 1-4 face rule shared with 1-13, 1-5, 1-4";
  if (e.reference_min >= 1 - 1e-12) return "none (boxes)";
  if (e.tag == TemplateTag::t1_3_adjust1 || e.tag == TemplateTag::t1_3_adjust2)
    return "adjustment nodes placed for the neighbours (the L-shaped case's rule)";
  return "its own: the parent's corners fixed";
}

/// The corpus of the directional configurations: generated meshes and seeded target sets,
/// planned by both refiners (the same every run); one composite per configuration in `out`, how
/// many hexes had it in `counts`.
std::string corpus_collect(std::vector<std::unique_ptr<HexTemplate>>& out,
                           std::vector<int64_t>& counts) {
  std::map<std::array<uint64_t, 2>, size_t> index;
  struct Case {
    std::array<int, 3> dims;
    double jitter;
    std::vector<std::string> select;
  };
  std::vector<Case> cases;
  auto random = [](double fraction, int seed) {
    char spec[64];
    std::snprintf(spec, sizeof spec, "random:%g,%d", fraction, seed);
    return std::string(spec);
  };
  // Many small bricks: the configurations are local, and rare ones are met by sampling often.
  for (int n : {5, 6, 8})
    for (double fraction : {0.05, 0.1, 0.15, 0.2, 0.3})
      for (int seed = 100; seed < (n == 8 ? 140 : 200); ++seed)
        cases.push_back({{n, n, n}, 0, {random(fraction, seed)}});
  // Seeds 1-6 only: the study's cases (seed 7) stay out of the corpus.
  for (int n : {6, 10, 16})
    for (double fraction : {0.01, 0.02, 0.03, 0.05, 0.08, 0.12, 0.2})
      for (int seed = 1; seed <= (n <= 10 ? 6 : 2); ++seed)
        cases.push_back({{n, n, n}, 0, {random(fraction, seed)}});
  for (double fraction : {0.01, 0.02, 0.03, 0.05, 0.08, 0.12, 0.2})
    for (int seed = 1; seed <= 6; ++seed)
      cases.push_back({{27, 27, 27}, 0, {random(fraction, seed)}});
  for (double fraction : {0.03, 0.05})
    for (int seed = 1; seed <= 2; ++seed)
      cases.push_back({{40, 40, 40}, 0, {random(fraction, seed)}});
  for (int seed = 1; seed <= 6; ++seed)
    cases.push_back({{16, 16, 16}, 0, {"blob:200," + std::to_string(seed)}});
  cases.push_back({{10, 10, 10}, 0, {"boundary:-1,0,0", "boundary:0,0,-1"}});
  for (int n : {10, 20}) {
    const double c = n / 2.0, r = 0.3 * n;
    cases.push_back({{n, n, n},
                     0,
                     {"sphere:" + std::to_string(c) + "," + std::to_string(c) + "," +
                      std::to_string(c) + "," + std::to_string(r)}});
  }
  RefineOptions options;
  options.placement.configuration_table = false;
  int64_t planned = 0;
  for (const Case& c : cases) {
    BrickParams p;
    p.dims = c.dims;
    p.size = {double(c.dims[0]), double(c.dims[1]), double(c.dims[2])};
    p.jitter = c.jitter;
    const HexMesh mesh = generate_brick(p);
    const HexTopology topology = topology_build(mesh);
    const std::vector<int32_t> targets = select_hexes(mesh, topology, c.select).hexes;
    if (targets.empty()) continue;
    for (const char* method : {"selective", "sheet"}) {
      RefineStats stats;
      RefinementPlan plan;
      try {
        plan = refine_method(method).plan(mesh, topology, targets, options, stats);
      } catch (const OperationError&) {
        continue;
      }
      ++planned;
      for (auto& t : plan.owned) {
        if (t->tag != TemplateTag::directional && t->tag != TemplateTag::sheet) continue;
        const auto [it, inserted] = index.try_emplace(template_configuration(*t).hash, out.size());
        if (inserted) {
          out.push_back(std::move(t));
          counts.push_back(0);
        }
        ++counts[it->second];
      }
    }
  }
  return std::to_string(planned) +
         " plans (Selective Approach and sheet refinement) on generated bricks: 5^3, 6^3, 8^3 "
         "with random targets 5-30 % (seeds 100-199, 8^3 100-139); 6^3, 10^3, 16^3, 27^3 with "
         "1-20 %, 40^3 with 3 and 5 % (seeds 1-6); 16^3 blobs, the L-shaped case, spheres at "
         "10^3 and 20^3 (experiments/cli_templates.cpp)";
}

int templates_run(const CliArgs& a) {
  if (!a.positional.empty())
    throw InputError("hexrefine templates: unexpected argument '" + a.positional[0] + "'");
  const std::optional<std::string> report = a.value("--report");
  if (report) cli_output_check("hexrefine templates", *report, CliOutputKind::report);
  const std::optional<std::string> optimize = a.value("--optimize");
  if (optimize) cli_output_check("hexrefine templates", *optimize, CliOutputKind::report);

  // What the library uses: the committed table, or the one computed here (installed).
  TemplateReferenceTable used = template_reference_committed();
  if (optimize) {
    // Installs the new rules and templates: the corpus is planned with them.
    TemplateReferenceTable table = template_reference_optimize(template_reference_edge_ratio);
    std::vector<std::unique_ptr<HexTemplate>> composites;
    std::vector<int64_t> counts;
    table.corpus = corpus_collect(composites, counts);
    std::vector<const HexTemplate*> pointers;
    for (const auto& t : composites) pointers.push_back(t.get());
    table.configurations.clear();
    table.corpus_hexes = table.corpus_configurations = 0;
    table.corpus_worst_min = 1;
    template_reference_add_configurations(table, pointers, counts);
    template_reference_install(table);
    std::cout << "directional configurations: " << table.corpus_configurations << " distinct in "
              << table.corpus_hexes << " directional hexes, " << table.configurations.size()
              << " raised by the optimisation kept\n";
    file_write_atomically(*optimize,
                          [&](std::ostream& os) { os << template_reference_table_source(table); });
    used = std::move(table);
  }

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
  for (const auto& get : standard) {
    const HexTemplate* t = get();
    const uint16_t mask = template_split_edges(*t);
    std::vector<std::string> sets;
    for (const auto& [set, name] :
         {std::pair{TemplateSet::element_by_element, "element_by_element"},
          std::pair{TemplateSet::sheet_directional, "sheet_directional"}})
      if (template_for_mask(mask, set).tmpl == t) sets.push_back(name);
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
