/// \file
/// Reference positions (algorithms/templates/template_reference.hpp): the committed table's values
/// on the unit cube, the face rule every template with a 1-4 face follows, the conformity argument
/// (the reference position of a node on an edge or face does not depend on which hex around it
/// places it) on refinement plans of bricks and a real mesh, and the canonical form of the
/// directional configurations. The optimiser that writes the table is tested with it
/// (tests/experiments/cli/test_template_optimize.cpp).

#include "algorithms/templates/template_reference.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <unordered_map>

#include "algorithms/refiners/refiner.hpp"
#include "mesh/generators.hpp"
#include "mesh/hex_convention.hpp"
#include "mesh/io.hpp"
#include "mesh/quality.hpp"
#include "mesh/selection.hpp"
#include "mesh/topology.hpp"
#include "tests/cli_runner.hpp"
#include "tests/fixtures.hpp"

namespace hexrefine {
namespace {

/// The minimum scaled Jacobian of tmpl's children at its reference positions.
double children_min(const HexTemplate& tmpl) {
  double m = 1;
  for (const auto& c : tmpl.children) {
    HexCorners x;
    for (int k = 0; k < 8; ++k) {
      const auto& r = template_node_reference(tmpl, static_cast<size_t>(c[k]));
      x[k] = Eigen::Vector3d(r[0], r[1], r[2]);
    }
    m = std::min(m, hex_scaled_jacobian(x));
  }
  return m;
}

const std::vector<const HexTemplate*>& standard_templates() {
  static const std::vector<const HexTemplate*> all = {
      &template_1_27(), &template_1_13(),        &template_1_5(),         &template_1_4(),
      &template_1_3(),  &template_1_3_adjust1(), &template_1_3_adjust2(), &template_1_9()};
  return all;
}

TEST(TemplateReference, EveryStandardTemplateAtLeastPoint4OnTheUnitCube) {
  // The target: at least 0.40 wherever the shared face rule allows (it allows it for
  // every standard template); the thesis' positions are unchanged (1-13: 4/13).
  std::map<TemplateTag, double> trilinear = {
      {TemplateTag::t1_13, 4.0 / 13.0}, {TemplateTag::t1_5, 0.4264}, {TemplateTag::t1_4, 0.5547}};
  for (const HexTemplate* t : standard_templates()) {
    SCOPED_TRACE(template_tag_name(t->tag));
    const double exact = template_validate(*t);
    const double reference = template_validate(*t, TemplatePositions::reference);
    EXPECT_GE(reference, 0.40);
    if (trilinear.count(t->tag)) {
      EXPECT_NEAR(exact, trilinear[t->tag], 1e-4);
    }
  }
  // Measured (results/templates.md): 1-13 reaches its bound 1/2 (its edges and 1-9 face stay at
  // thirds), 1-5 and 1-4 the bounds 1/sqrt(3) and 1/sqrt(2) of the shared face rule.
  EXPECT_NEAR(template_validate(template_1_13(), TemplatePositions::reference), 0.5, 1e-4);
  EXPECT_NEAR(template_validate(template_1_5(), TemplatePositions::reference), 1 / std::sqrt(3.0),
              1e-3);
  EXPECT_NEAR(template_validate(template_1_4(), TemplatePositions::reference), 1 / std::sqrt(2.0),
              1e-3);
  // Boxes stay boxes: 1-27, 1-3, 1-9 keep the thesis' positions bit for bit.
  for (const HexTemplate* t : {&template_1_27(), &template_1_3(), &template_1_9()})
    EXPECT_TRUE(t->reference.empty()) << template_tag_name(t->tag);
}

TEST(TemplateReference, TheTableMatchesTheLibraryAndNoChildIsStretchedPastItsCap) {
  const TemplateReferenceTable table = template_reference_committed();
  ASSERT_EQ(table.templates.size(), 8u);
  for (const TemplateReferenceEntry& e : table.templates) {
    const HexTemplate* t = nullptr;
    for (const HexTemplate* s : standard_templates())
      if (s->tag == e.tag) t = s;
    ASSERT_TRUE(t);
    SCOPED_TRACE(template_tag_name(e.tag));
    EXPECT_NEAR(template_validate(*t, TemplatePositions::reference), e.reference_min, 1e-12);
    EXPECT_NEAR(template_validate(*t), e.trilinear_min, 1e-12);
    EXPECT_GE(e.own_rule_min, e.reference_min);
    // No child beyond max(6, its edge ratio at the thesis' positions).
    for (const auto& c : t->children) {
      HexCorners exact, reference;
      for (int k = 0; k < 8; ++k) {
        const auto& r = t->nodes[c[k]].ref;
        const auto& p = template_node_reference(*t, static_cast<size_t>(c[k]));
        exact[k] = Eigen::Vector3d(r[0], r[1], r[2]);
        reference[k] = Eigen::Vector3d(p[0], p[1], p[2]);
      }
      EXPECT_LE(hex_edge_ratio(reference),
                hex_edge_ratio_cap(exact, template_reference_edge_ratio) * (1 + 1e-9));
    }
  }
}

TEST(TemplateReference, OneFaceRuleForEveryOneToFourFaceSymmetricUnderItsReflection) {
  // Every 1-4 face of 1-13, 1-5 and 1-4: its two transition nodes at (a, b) and (1 - a, b) in
  // the face frame (u along the split edge, v away from it), the same (a, b) for all.
  const ReferenceRules rules = template_reference_rules();
  int faces = 0;
  for (const HexTemplate* t : {&template_1_13(), &template_1_5(), &template_1_4()}) {
    const uint16_t mask = template_split_edges(*t);
    for (int lf = 0; lf < 6; ++lf) {
      int split = 0, edge = -1;
      for (int fe : hex_face_edges[lf])
        if ((mask >> fe) & 1) ++split, edge = fe;
      if (split != 1) continue;
      const int fixed = lf / 2, along = hex_edge_axis[edge], across = 3 - fixed - along;
      const double at = hex_corner[hex_edges[edge][0]][across];
      std::vector<std::array<double, 2>> uv;
      for (size_t i = 0; i < t->nodes.size(); ++i) {
        const auto& r = t->nodes[i].ref;
        if (std::abs(r[fixed] - (lf % 2)) > 1e-12) continue;
        int extreme = 0;
        for (double x : r) extreme += std::abs(x) < 1e-12 || std::abs(x - 1) < 1e-12;
        if (extreme != 1) continue;
        const auto& p = template_node_reference(*t, i);
        EXPECT_DOUBLE_EQ(p[fixed], r[fixed]);  // stays in the face
        uv.push_back({p[along], at == 0 ? p[across] : 1 - p[across]});
      }
      ASSERT_EQ(uv.size(), 2u) << template_tag_name(t->tag) << " face " << lf;
      std::sort(uv.begin(), uv.end());
      EXPECT_NEAR(uv[0][0], rules.along, 1e-15);
      EXPECT_NEAR(uv[1][0], 1 - rules.along, 1e-15);
      EXPECT_NEAR(uv[0][1], rules.across, 1e-15);
      EXPECT_NEAR(uv[1][1], rules.across, 1e-15);
      ++faces;
    }
  }
  EXPECT_EQ(faces, 4 + 2 + 2);
  EXPECT_GT(std::abs(rules.along - 1.0 / 3.0) + std::abs(rules.across - 0.5), 0.01);
}

/// For every edge and face node of every use of `plan` (not renamed by an alias): its reference
/// position through the use's parent; the largest distance between two uses that name the same
/// node, and how many nodes more than one use named.
std::pair<double, int64_t> plan_reference_disagreement(const HexMesh& mesh,
                                                       const HexTopology& topology,
                                                       const RefinementPlan& plan) {
  std::unordered_map<NodeKey, Eigen::Vector3d, NodeKeyHash> seen;
  std::unordered_map<NodeKey, bool, NodeKeyHash> aliased;
  for (const NodeAlias& a : plan.aliases) aliased[a.from] = true;
  double worst = 0;
  int64_t shared = 0;
  for (const TemplateUse& u : plan.uses) {
    const HexCorners x = hex_points(mesh, index_of(u.hex));
    for (const TemplatePlanNode& n : u.tmpl->plans.at(u.symmetry).nodes) {
      if (n.entity != CubeEntity::edge && n.entity != CubeEntity::face) continue;
      const NodeKey key = node_key_at(mesh, topology, u.hex, n.param);
      if (aliased.count(key)) continue;
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      for (int v = 0; v < 8; ++v) p += n.reference_weight[v] * x[v];
      const auto [it, inserted] = seen.try_emplace(key, p);
      if (inserted) continue;
      ++shared;
      worst = std::max(worst, (it->second - p).norm());
    }
  }
  return {worst, shared};
}

TEST(TemplateReference, EveryHexAroundAnEdgeOrFaceNodePutsItInTheSamePlace) {
  // Conformity by construction: the two (or more) hexes around a new edge or face node compute
  // the same reference position for it, to rounding, whichever template and orientation each
  // uses and however its directional steps were composed; so it does not matter which of them
  // the engine lets place it. Random target sets on bricks (plain and jittered) and the rocker
  // arm, both refiners.
  struct Case {
    HexMesh mesh;
    std::string select;
  };
  std::vector<Case> cases;
  for (double jitter : {0.0, 0.2}) {
    BrickParams p;
    p.dims = {8, 8, 8};
    p.size = {8, 8, 8};
    p.jitter = jitter;
    p.seed = 3;
    for (const char* select : {"random:0.05,11", "random:0.12,12", "blob:40,13"})
      cases.push_back({generate_brick(p), select});
  }
  cases.push_back({mesh_read(shared_mesh("rockerarm.mesh")), "random:0.02,5"});
  int64_t shared = 0;
  for (const Case& c : cases)
    for (const char* method : {"selective", "sheet"}) {
      SCOPED_TRACE(c.select + " " + method);
      const HexTopology topology = topology_build(c.mesh);
      const std::vector<int32_t> targets = select_hexes(c.mesh, topology, {c.select}).hexes;
      RefineStats stats;
      const RefinementPlan plan = refine_method(method).plan(
          c.mesh, topology, targets, RefineOptions{}, stats, template_library_committed());
      const auto [worst, count] = plan_reference_disagreement(c.mesh, topology, plan);
      const auto [lo, hi] = mesh_bounding_box(c.mesh);
      EXPECT_LT(worst, 1e-12 * (hi - lo).norm());
      EXPECT_GT(count, 100);
      shared += count;
    }
  EXPECT_GT(shared, 10000);
}

TEST(TemplateReference, AConfigurationIsFoundInEveryOrientation) {
  // The L-shaped case's directional hexes, turned by cube symmetries: the same canonical hashes,
  // and the table's positions give the turned hex the same children's minimum.
  BrickParams p;
  p.dims = {4, 4, 4};
  p.size = {4, 4, 4};
  const HexMesh m = generate_brick(p);
  const HexTopology t = topology_build(m);
  RefineStats stats;
  const RefinementPlan plan =
      refine_method("selective")
          .plan(m, t, select_hexes(m, t, {"boundary:-1,0,0", "boundary:0,0,-1"}).hexes,
                RefineOptions{}, stats, template_library_committed());
  int found = 0;
  for (const auto& owned : plan.owned) {
    const HexTemplate& composite = *owned;
    const TemplateConfiguration c0 = template_configuration(composite);
    HexTemplate looked = composite;
    const bool listed = template_reference_from_configurations(looked);
    if (listed) template_compile(looked, 1);
    found += listed;
    for (int s : {1, 7, 13, 30, 47}) {
      const CubeSymmetry& sym = cube_symmetries()[s];
      HexTemplate turned;
      turned.tag = composite.tag;
      for (size_t i = 0; i < composite.nodes.size(); ++i) {
        TemplateNode n = composite.nodes[i];
        n.ref = cube_symmetry_apply(sym, n.ref);
        turned.nodes.push_back(n);
        // The composed positions turn with it.
        turned.reference.push_back(cube_symmetry_apply(sym, template_node_reference(composite, i)));
      }
      for (auto c : composite.children) {
        if (sym.reflection) {
          const auto original = c;
          for (int k = 0; k < 8; ++k) c[k] = original[hex_reflected_order[k]];
        }
        turned.children.push_back(c);
      }
      template_compile(turned, 1);
      EXPECT_EQ(template_configuration(turned).hash, c0.hash) << "symmetry " << s;
      if (!listed) continue;
      // The positions land where the table's do (up to a symmetry of the configuration itself,
      // which maps one optimum onto another): the same children, the same minimum.
      ASSERT_TRUE(template_reference_from_configurations(turned));
      template_compile(turned, 1);
      EXPECT_NEAR(children_min(turned), children_min(looked), 1e-12) << "symmetry " << s;
    }
  }
  EXPECT_GT(found, 0);
}

}  // namespace
}  // namespace hexrefine
