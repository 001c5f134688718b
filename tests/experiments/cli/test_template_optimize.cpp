/// \file
/// The template optimiser (experiments/cli/template_optimize.hpp): its node optimisation on the
/// unit cube, and the committed table being exactly what its writer writes.

#include "experiments/cli/template_optimize.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

namespace hexrefine {
namespace {

TEST(TemplateOptimize, OptimisingNodesNeverLowersTheMinimum) {
  // 1-5 at the table's rules, its two interior nodes from the thesis' positions: the minimum
  // rises from what the rule leaves (0.19) to the rule's bound, under the cap.
  HexTemplate t = template_1_5();
  t.reference.clear();
  template_reference_set(t, template_reference_rules(), {});
  const double start = template_validate(t, TemplatePositions::reference);
  std::vector<uint8_t> movable(t.nodes.size());
  for (size_t i = 0; i < t.nodes.size(); ++i) movable[i] = template_node_movable(t, i);
  EXPECT_EQ(std::count(movable.begin(), movable.end(), 1), 2);
  const double after = template_reference_optimize_nodes(t, movable, template_reference_edge_ratio);
  EXPECT_GT(after, start + 0.1);
  EXPECT_NEAR(after, 1 / std::sqrt(3.0), 2e-3);
  for (size_t i = 0; i < t.nodes.size(); ++i)
    if (!movable[i]) {
      EXPECT_EQ(t.reference[i], template_node_reference(template_1_5(), i));
    }
}

TEST(TemplateOptimize, TheCommittedTableIsWhatTheGeneratorWrites) {
  // algorithms/templates/template_reference_table.inc is `hexrefine templates --optimize`'s output,
  // not edited by hand: written again from what the library read, it is the same text.
  std::ifstream in(std::string(HEXREFINE_SOURCE_DIR) +
                   "/algorithms/templates/template_reference_table.inc");
  ASSERT_TRUE(in);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(template_reference_table_source(template_reference_committed()), text.str());
}

}  // namespace
}  // namespace hexrefine
