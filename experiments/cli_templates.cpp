/// \file
/// `hexrefine templates [--report R.json]`: the template library (algorithms/template_library.hpp)
/// as a table: every template's split edges, nodes, children, the minimum scaled Jacobian of its
/// children alone on the unit cube (template_validate) and the sets it belongs to. The JSON
/// behind results/templates.md.

#include <bit>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>

#include "algorithms/template_library.hpp"
#include "experiments/cli.hpp"
#include "experiments/cli_output.hpp"
#include "mesh/atomic_file.hpp"
#include "mesh/error.hpp"

namespace hexrefine {

namespace {

int templates_run(const CliArgs& a) {
  if (!a.positional.empty())
    throw InputError("hexrefine templates: unexpected argument '" + a.positional[0] + "'");
  const std::optional<std::string> report = a.value("--report");
  if (report) cli_output_check("hexrefine templates", *report, CliOutputKind::report);
  nlohmann::json list = nlohmann::json::array();
  std::cout << std::left << std::setw(10) << "template" << std::setw(13) << "split edges"
            << std::setw(7) << "nodes" << std::setw(10) << "children" << std::setw(11) << "min SJ"
            << "sets\n";
  for (const HexTemplate* t :
       {&template_1_27(), &template_1_13(), &template_1_5(), &template_1_4(), &template_1_3(),
        &template_1_3_adjust1(), &template_1_3_adjust2(), &template_1_9()}) {
    const uint16_t mask = template_split_edges(*t);
    std::vector<std::string> sets;
    for (const auto& [set, name] :
         {std::pair{TemplateSet::element_by_element, "element_by_element"},
          std::pair{TemplateSet::sheet_directional, "sheet_directional"}})
      if (template_for_mask(mask, set).tmpl == t) sets.push_back(name);
    const double min_sj = template_validate(*t);
    list.push_back({{"template", template_tag_name(t->tag)},
                    {"split_edges", std::popcount(mask)},
                    {"nodes", t->nodes.size()},
                    {"children", t->children.size()},
                    {"min_scaled_jacobian_alone", min_sj},
                    {"sets", sets}});
    std::string joined;
    for (const std::string& s : sets) joined += (joined.empty() ? "" : ", ") + s;
    std::cout << std::left << std::setw(10) << template_tag_name(t->tag) << std::setw(13)
              << std::popcount(mask) << std::setw(7) << t->nodes.size() << std::setw(10)
              << t->children.size() << std::setw(11) << std::setprecision(4) << min_sj << joined
              << "\n";
  }
  if (report) file_write_atomically(*report, [&](std::ostream& os) { os << list.dump(2) << "\n"; });
  return 0;
}

}  // namespace

const CliCommand cli_templates_command = {
    "templates",
    "",
    "Lists the template library: split edges, nodes, children, minimum scaled Jacobian alone.",
    {{"--report", "R.json", "write the table as JSON"}},
    "",
    templates_run,
};

}  // namespace hexrefine
