#include "algorithms/templates/cube_symmetry.hpp"

#include <gtest/gtest.h>

#include <set>

#include "mesh/hex_convention.hpp"

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

TEST(CubeSymmetries, ReflectedOrderRestoresPositiveOrientation) {
  // A reflection mirrors a child; swapping its vertices 1 <-> 3 and 5 <-> 7 makes it positive.
  for (const CubeSymmetry& s : cube_symmetries()) {
    std::array<std::array<double, 3>, 8> q;
    for (int v = 0; v < 8; ++v) {
      const int w = s.reflection ? hex_reflected_order[v] : v;
      q[v] = cube_symmetry_apply(
          s, {double(hex_corner[w][0]), double(hex_corner[w][1]), double(hex_corner[w][2])});
    }
    // Corner Jacobian at vertex 0: edges to vertices 1, 3, 4.
    auto d = [&](int a) {
      return std::array<double, 3>{q[a][0] - q[0][0], q[a][1] - q[0][1], q[a][2] - q[0][2]};
    };
    const auto a = d(1), b = d(3), c = d(4);
    const double det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                       a[2] * (b[0] * c[1] - b[1] * c[0]);
    EXPECT_GT(det, 0);
  }
}

TEST(CubeSymmetries, EdgeMaskFollowsTheEdgeMap) {
  const uint16_t x_edges = (1 << 0) | (1 << 2) | (1 << 4) | (1 << 6);
  int onto_y = 0;
  for (const CubeSymmetry& s : cube_symmetries())
    onto_y += cube_symmetry_edge_mask(s, x_edges) == ((1 << 1) | (1 << 3) | (1 << 5) | (1 << 7));
  EXPECT_EQ(onto_y, 16);  // the x-axis onto the y-axis: 2 permutations x 8 flips
  EXPECT_EQ(cube_symmetry_edge_mask(cube_symmetries()[0], 0x5A5), 0x5A5);
}

}  // namespace
}  // namespace hexrefine
