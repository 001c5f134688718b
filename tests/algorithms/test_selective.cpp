#include "algorithms/selective.hpp"

#include <gtest/gtest.h>

#include "mesh/error.hpp"
#include "tests/algorithms/refiner_suite.hpp"
#include "tests/fixtures.hpp"

namespace hexrefine {
namespace {

std::vector<int32_t> all_hexes(const HexMesh& m) {
  std::vector<int32_t> t(m.hex_count());
  for (int32_t h = 0; h < m.hex_count(); ++h) t[h] = h;
  return t;
}

TEST(Selective, FullRefinementOfBricks) {
  for (int n : {1, 2, 3, 5}) {
    const HexMesh m = fixture_brick(n, n, n);
    const RefineResult r = selective_refine(m, {all_hexes(m)}, {});
    EXPECT_EQ(r.mesh.hex_count(), 27 * n * n * n);
    EXPECT_EQ(r.mesh.point_count(), (3 * n + 1) * (3 * n + 1) * (3 * n + 1));
    const RefinerSuiteVerdict v = refiner_suite_check(
        r.mesh, refiner_suite_box({0, 0, 0}, {double(n), double(n), double(n)}));
    EXPECT_TRUE(v.conformal());
    EXPECT_EQ(v.inverted_hexes, 0);
    EXPECT_NEAR(v.min_scaled_jacobian, 1.0, 1e-12);
    EXPECT_EQ(r.stats.hexes_per_template.at("1-27"), 27 * n * n * n);
  }
}

TEST(Selective, LShapedCase) {
  const HexMesh m = fixture_brick(10, 10, 10);
  Targets t;
  for (int32_t h = 0; h < m.hex_count(); ++h) {
    const int i = h % 10, k = h / 100;
    if (i == 0 || k == 0) t.hexes.push_back(h);
  }
  ASSERT_EQ(t.hexes.size(), 190u);
  const RefineResult r = selective_refine(m, t, {});
  const RefinerSuiteVerdict v =
      refiner_suite_check(r.mesh, refiner_suite_box({0, 0, 0}, {10, 10, 10}));
  EXPECT_TRUE(v.conformal()) << v.nonmanifold_faces << " " << v.interior_boundary_faces;
  EXPECT_EQ(v.inverted_hexes, 0);
  EXPECT_EQ(v.doublets, 0);
  EXPECT_EQ(r.mesh.hex_count(), 8060);
  EXPECT_GE(v.min_scaled_jacobian, 0.3077 - 1e-4);
  // 190 x 27 + 160 face transitions x 13 + 10 corner hexes x 21 (directional) + 640 untouched.
  EXPECT_EQ(r.stats.hexes_per_template.at("1-27"), 5130);
  EXPECT_EQ(r.stats.hexes_per_template.at("1-13"), 2080);
  EXPECT_EQ(r.stats.hexes_per_template.at("directional"), 210);
  EXPECT_EQ(r.stats.hexes_per_template.at("untouched"), 640);
  EXPECT_EQ(r.stats.directional_hexes, 10);
  EXPECT_EQ(r.stats.directional_groups, 1);
  EXPECT_EQ(r.stats.doublets_resolved, 0);
  EXPECT_NEAR(v.min_scaled_jacobian, 0.3077, 1e-4);  // the thesis' value (Table G-1)
}

}  // namespace
}  // namespace hexrefine
