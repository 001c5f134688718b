#include "algorithms/templates.hpp"

#include <gtest/gtest.h>

#include <set>

#include "mesh/hex_convention.hpp"
#include "mesh/topology.hpp"
#include "tests/fixtures.hpp"

namespace hexrefine {
namespace {

TEST(CubeSymmetries, FortyEightDistinctWithTwentyFourReflections) {
  const auto& s = cube_symmetries();
  std::set<std::array<int8_t, 8>> maps;
  int reflections = 0;
  for (const CubeSymmetry& x : s) {
    maps.insert(x.vertex);
    reflections += x.reflection;
    // Edge and face maps are bijections consistent with the vertex map.
    std::set<int> edges(x.edge.begin(), x.edge.end()), faces(x.face.begin(), x.face.end());
    EXPECT_EQ(edges.size(), 12u);
    EXPECT_EQ(faces.size(), 6u);
  }
  EXPECT_EQ(maps.size(), 48u);
  EXPECT_EQ(reflections, 24);
  for (int v = 0; v < 8; ++v) EXPECT_EQ(s[0].vertex[v], v);  // identity first
}

TEST(Templates, SplitEdgeMasks) {
  EXPECT_EQ(template_split_edges(template_1_27()), 0xFFF);
  EXPECT_EQ(template_split_edges(template_1_3()), (1 << 0) | (1 << 2) | (1 << 4) | (1 << 6));
}

TEST(TemplatesApply, FullRefinementOfTwoCubedBrickSharesNodes) {
  const HexMesh m = fixture_brick(2, 2, 2);
  const HexTopology t = topology_build(m);
  std::vector<TemplateApplication> apps;
  for (int32_t h = 0; h < m.hex_count(); ++h) apps.push_back({h, &template_1_27(), 0});
  const TemplateApplyResult r = templates_apply(m, t, apps);
  EXPECT_EQ(r.mesh.hex_count(), 216);
  EXPECT_EQ(r.mesh.point_count(), 7 * 7 * 7);
  EXPECT_EQ(r.hexes_created, 216);
  EXPECT_EQ(r.hexes_deleted, 8);
  const HexTopology rt = topology_build(r.mesh);
  EXPECT_EQ(topology_boundary_faces(rt).size(), 6u * 36u);
  const auto* tag = mesh_find_attribute(r.mesh, attribute_template_tag);
  ASSERT_NE(tag, nullptr);
  EXPECT_EQ((*tag)[0], static_cast<int32_t>(TemplateTag::t1_27));
}

TEST(TemplatesApply, OneToThreeInEverySymmetryStaysConformal) {
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
      const std::vector<TemplateApplication> apps = {{0, &template_1_3(), int8_t(s0)},
                                                     {1, &template_1_3(), int8_t(s1)}};
      const TemplateApplyResult r = templates_apply(m, t, apps);
      ASSERT_EQ(r.mesh.hex_count(), 6);
      ASSERT_EQ(r.mesh.point_count(), 24);
      const HexTopology rt = topology_build(r.mesh);
      ASSERT_EQ(topology_boundary_faces(rt).size(), 22u);  // as a 2x3x1 brick
      // Positive orientation: the corner Jacobian at vertex 0 of every child.
      for (const HexCell& c : r.mesh.hexes) {
        const Eigen::Vector3d o = r.mesh.points[c[0]];
        const double det =
            (r.mesh.points[c[1]] - o).cross(r.mesh.points[c[3]] - o).dot(r.mesh.points[c[4]] - o);
        ASSERT_GT(det, 0);
      }
      ++tried;
    }
  }
  EXPECT_EQ(tried, 16 * 16);  // 16 symmetries map the x-slabs onto the y-slabs
}

}  // namespace
}  // namespace hexrefine
