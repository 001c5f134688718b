#include "algorithms/templates/template_engine.hpp"

#include <gtest/gtest.h>

#include "algorithms/refiners/selective_cells.hpp"
#include "mesh/error.hpp"
#include "mesh/generators.hpp"
#include "mesh/hex_convention.hpp"
#include "mesh/quality.hpp"
#include "mesh/topology.hpp"
#include "tests/fixtures.hpp"

namespace hexrefine {
namespace {

RefinementPlan plan_of(std::initializer_list<TemplateUse> uses) {
  RefinementPlan p;
  p.uses = uses;
  return p;
}

/// A jittered 3x3x3 brick whose node ids are shuffled (keys must not depend on id order).
HexMesh shuffled_brick() {
  BrickParams bp;
  bp.dims = {3, 3, 3};
  bp.jitter = 0.2;
  HexMesh m = generate_brick(bp);
  std::vector<int32_t> perm(m.point_count());
  for (int32_t i = 0; i < m.point_count(); ++i) perm[i] = (i * 37) % m.point_count();
  for (HexCell& c : m.hexes)
    for (int32_t& v : c) v = perm[v];
  std::vector<Eigen::Vector3d> pts(m.points.size());
  for (int32_t i = 0; i < m.point_count(); ++i) pts[perm[i]] = m.points[i];
  m.points = pts;
  return m;
}

TEST(PlanApply, FullRefinementOfTwoCubedBrickSharesNodes) {
  const HexMesh m = fixture_brick(2, 2, 2);
  const HexTopology t = topology_build(m);
  RefinementPlan plan;
  for (int32_t h = 0; h < m.hex_count(); ++h) plan.uses.push_back({HexId{h}, &template_1_27(), 0});
  const PlanApplyResult r = plan_apply(m, t, plan);
  EXPECT_EQ(r.mesh.hex_count(), 216);
  EXPECT_EQ(r.mesh.point_count(), 7 * 7 * 7);
  EXPECT_EQ(r.hexes_created, 216);
  EXPECT_EQ(r.hexes_deleted, 8);
  ASSERT_EQ(r.first_child.size(), 8u);
  for (int32_t u = 0; u < 8; ++u) EXPECT_EQ(r.first_child[u], 27 * u);
  const HexTopology rt = topology_build(r.mesh);
  EXPECT_EQ(topology_boundary_faces(rt).size(), 6u * 36u);
  const auto* tag = mesh_find_attribute(r.mesh, attribute_template_tag);
  ASSERT_NE(tag, nullptr);
  EXPECT_EQ((*tag)[0], static_cast<int32_t>(TemplateTag::t1_27));
}

TEST(PlanApply, AttributesComeFromTheParents) {
  // Hex 1 of a 3x1x1 brick refined 1-27: its 27 children inherit block_id, get the template tag,
  // level 1 and parent_hex 1; the untouched hexes keep their own ids and level 0.
  HexMesh m = fixture_brick(3, 1, 1);
  m.attributes.push_back({"block_id", {7, 8, 9}});
  const HexTopology t = topology_build(m);
  const PlanApplyResult r = plan_apply(m, t, plan_of({{HexId{1}, &template_1_27(), 0}}));
  ASSERT_EQ(r.mesh.hex_count(), 29);
  const auto& block = *mesh_find_attribute(r.mesh, "block_id");
  const auto& tag = *mesh_find_attribute(r.mesh, attribute_template_tag);
  const auto& level = *mesh_find_attribute(r.mesh, attribute_refinement_level);
  const auto& parent = *mesh_find_attribute(r.mesh, attribute_parent_hex);
  EXPECT_EQ(block.front(), 7);
  EXPECT_EQ(block.back(), 9);
  EXPECT_EQ(parent.front(), 0);
  EXPECT_EQ(parent.back(), 2);
  EXPECT_EQ(tag.front(), 0);
  EXPECT_EQ(level.front(), 0);
  for (int32_t i = 1; i <= 27; ++i) {
    EXPECT_EQ(block[i], 8);
    EXPECT_EQ(parent[i], 1);
    EXPECT_EQ(tag[i], static_cast<int32_t>(TemplateTag::t1_27));
    EXPECT_EQ(level[i], 1);
  }
  // A second pass inherits parent_hex (the first input's ids) and adds a level.
  const HexTopology t2 = topology_build(r.mesh);
  const PlanApplyResult r2 = plan_apply(r.mesh, t2, plan_of({{HexId{5}, &template_1_3(), 0}}));
  const auto& parent2 = *mesh_find_attribute(r2.mesh, attribute_parent_hex);
  const auto& level2 = *mesh_find_attribute(r2.mesh, attribute_refinement_level);
  EXPECT_EQ(parent2[5], 1);
  EXPECT_EQ(level2[5], 2);
  EXPECT_EQ(r2.mesh.hex_count(), 31);
}

TEST(PlanApply, RefusesUsesOutOfOrder) {
  const HexMesh m = fixture_brick(2, 1, 1);
  const HexTopology t = topology_build(m);
  EXPECT_THROW(
      plan_apply(m, t, plan_of({{HexId{1}, &template_1_3(), 0}, {HexId{0}, &template_1_3(), 0}})),
      OperationError);
  EXPECT_THROW(plan_apply(m, t, plan_of({{HexId{2}, &template_1_3(), 0}})), OperationError);
}

TEST(PlanApply, OneToThreeInEverySymmetryStaysConformal) {
  // Two hexes side by side in x, both split across y: the shared face must be split identically
  // from both sides whatever orientation each template is applied in.
  const HexMesh m = fixture_brick(2, 1, 1);
  const HexTopology t = topology_build(m);
  const uint16_t canonical = template_split_edges(template_1_3());
  const uint16_t wanted = (1 << 1) | (1 << 3) | (1 << 5) | (1 << 7);  // the y-parallel edges
  int tried = 0;
  for (int s0 = 0; s0 < 48; ++s0) {
    if (cube_symmetry_edge_mask(cube_symmetries()[s0], canonical) != wanted) continue;
    for (int s1 = 0; s1 < 48; ++s1) {
      if (cube_symmetry_edge_mask(cube_symmetries()[s1], canonical) != wanted) continue;
      const PlanApplyResult r = plan_apply(m, t,
                                           plan_of({{HexId{0}, &template_1_3(), int8_t(s0)},
                                                    {HexId{1}, &template_1_3(), int8_t(s1)}}));
      ASSERT_EQ(r.mesh.hex_count(), 6);
      ASSERT_EQ(r.mesh.point_count(), 24);
      const HexTopology rt = topology_build(r.mesh);
      ASSERT_EQ(topology_boundary_faces(rt).size(), 22u);  // as a 2x3x1 brick
      for (int32_t h = 0; h < r.mesh.hex_count(); ++h)
        ASSERT_TRUE(hex_corners_positive(hex_points(r.mesh, h)));
      ++tried;
    }
  }
  EXPECT_EQ(tried, 16 * 16);  // 16 symmetries map the x-slabs onto the y-slabs
}

TEST(TemplateEngine, KeyedAndSlotPathsGiveTheSameNodes) {
  // Without aliases the engine goes straight to the slots; with one it derives every key
  // (NodeKey, node_key_at's frames). On a jittered mesh with shuffled node ids both create the
  // same nodes, in the same order, at bit-identical positions.
  const HexMesh m = shuffled_brick();
  const HexTopology topo = topology_build(m);
  int compared = 0;
  for (const HexTemplate* t :
       {&template_1_27(), &template_1_13(), &template_1_5(), &template_1_4(), &template_1_3()}) {
    for (int sym = 0; sym < 48; sym += 5) {
      TemplateEngine direct(m, topo), keyed(m, topo);
      // An alias no template names: only switches the keyed path on.
      keyed.alias(NodeKey::interior(HexId{0}, {1, 1, 1}), NodeKey::interior(HexId{0}, {2, 2, 2}));
      std::vector<HexCell> a, b;
      for (int32_t h = 0; h < m.hex_count(); h += 2) {
        direct.apply(HexId{h}, *t, sym, false, a);
        keyed.apply(HexId{h}, *t, sym, false, b);
      }
      ASSERT_EQ(a, b) << template_tag_name(t->tag) << " symmetry " << sym;
      ASSERT_EQ(direct.points(), keyed.points());
      ++compared;
    }
  }
  EXPECT_EQ(compared, 5 * 10);
}

TEST(TemplateEngine, NodeKeysAreTheSameFromBothSidesOfAFace) {
  // The position (1/3, 1/2) of the face between two hexes, named from each hex's own cube.
  const HexMesh m = shuffled_brick();
  const HexTopology t = topology_build(m);
  int faces = 0;
  for (int32_t f = 0; f < t.face_count(); ++f) {
    if (face_is_boundary(t, f)) continue;
    const int32_t h0 = t.face_hexes[f][0], h1 = t.face_hexes[f][1];
    // The reference positions on that face seen from each hex: map a point of h0's face into
    // h1's cube by matching the face's corner nodes.
    const int l0 = hex_local_face(t, h0, f), l1 = hex_local_face(t, h1, f);
    const int64_t u = template_param_unit;
    auto param_of = [&](int32_t h, int lf, int32_t node_a, int32_t node_b, int32_t node_d,
                        int64_t s, int64_t r) {
      // Point a + s/u (b - a) + r/u (d - a) in hex h's cube, a, b, d corners of face lf.
      auto corner = [&](int32_t node) {
        for (int v = 0; v < 8; ++v)
          if (m.hexes[h][v] == node)
            return TemplateParam{hex_corner[v][0] * u, hex_corner[v][1] * u, hex_corner[v][2] * u};
        return TemplateParam{};
      };
      const TemplateParam a = corner(node_a), b = corner(node_b), d = corner(node_d);
      TemplateParam p;
      for (int k = 0; k < 3; ++k) p[k] = a[k] + (b[k] - a[k]) / u * s + (d[k] - a[k]) / u * r;
      (void)lf;
      return p;
    };
    const auto& q = t.face_nodes[f];
    const int64_t s = u / 3, r = u / 2;
    const NodeKey k0 = node_key_at(m, t, HexId{h0}, param_of(h0, l0, q[0], q[1], q[3], s, r));
    const NodeKey k1 = node_key_at(m, t, HexId{h1}, param_of(h1, l1, q[0], q[1], q[3], s, r));
    EXPECT_EQ(k0.kind(), NodeKey::Kind::face);
    EXPECT_EQ(k0, k1) << "face " << f;
    ++faces;
  }
  EXPECT_EQ(faces, 3 * 3 * 3 * 3 - 3 * 9);  // interior faces of a 3x3x3 brick: 54
}

TEST(SelectiveCells, AWholeCellRefinedIsTheLibraryTemplate) {
  // The template made of the cells of one symbolic refinement gives the same mesh as the
  // library template applied directly (exact positions, the same keys).
  const HexMesh m = shuffled_brick();
  const HexTopology t = topology_build(m);
  for (const HexTemplate* tmpl : {&template_1_13(), &template_1_5(), &template_1_4()}) {
    for (int sym : {0, 7, 29}) {
      CellRefiner cells(m, t);
      std::vector<TemplateCell> children;
      cells.refine(cells.cell_whole(13), *tmpl, sym, children);
      RefinementPlan own;
      own.owned.push_back(selective_cells_template(children, TemplateTag::directional, cells));
      own.uses.push_back({HexId{13}, own.owned.back().get(), 0});
      const PlanApplyResult a = plan_apply(m, t, own);
      const PlanApplyResult b = plan_apply(m, t, plan_of({{HexId{13}, tmpl, int8_t(sym)}}));
      ASSERT_EQ(a.mesh.hex_count(), b.mesh.hex_count());
      ASSERT_EQ(a.mesh.point_count(), b.mesh.point_count());
      // Same node positions as sets (the node order may differ).
      std::vector<std::array<double, 3>> pa, pb;
      for (const auto& p : a.mesh.points) pa.push_back({p[0], p[1], p[2]});
      for (const auto& p : b.mesh.points) pb.push_back({p[0], p[1], p[2]});
      std::sort(pa.begin(), pa.end());
      std::sort(pb.begin(), pb.end());
      EXPECT_EQ(pa, pb) << template_tag_name(tmpl->tag) << " symmetry " << sym;
    }
  }
}

TEST(SelectiveCells, NestedTooDeepIsRefusedAndAliasesComeBeforeUse) {
  const HexMesh m = fixture_brick(1, 1, 1);
  const HexTopology t = topology_build(m);
  CellRefiner cells(m, t);
  std::vector<NodeKey> keys;
  std::vector<TemplateCell> children;
  cells.refine(cells.cell_whole(0), template_1_3(), 0, children, &keys);
  // A key a cell already uses cannot be aliased any more.
  NodeKey used = keys[1];
  EXPECT_FALSE(cells.alias(used, NodeKey::interior(HexId{0}, {1, 2, 3})));
  // Cells refined again and again leave the exact grid, then are refused.
  bool refused = false;
  TemplateCell cell = children[1];
  for (int depth = 0; depth < 20 && !refused; ++depth) {
    std::vector<TemplateCell> next;
    try {
      cells.refine(cell, template_1_5(), depth % 48, next);
      cell = next[3];  // a skewed child
    } catch (const OperationError&) {
      refused = true;
    }
  }
  EXPECT_TRUE(refused);
}

}  // namespace
}  // namespace hexrefine
