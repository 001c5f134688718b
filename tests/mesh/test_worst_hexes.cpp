#include "mesh/worst_hexes.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include "mesh/generators.hpp"
#include "mesh/quality.hpp"
#include "tests/fixtures.hpp"

namespace hexrefine {
namespace {

TEST(WorstHexes, BoundaryFacesOfA3x3x3BrickByPlace) {
  // Every hex a unit cube (scaled Jacobian 1): the ties go by id, so all 27 come in id order.
  const HexMesh m = fixture_brick(3, 3, 3);
  const std::vector<WorstHex> worst = mesh_worst_hexes(m, 30);
  ASSERT_EQ(worst.size(), 27u);
  int by_count[7] = {};
  for (size_t k = 0; k < worst.size(); ++k) {
    EXPECT_EQ(worst[k].hex, static_cast<int32_t>(k));
    EXPECT_DOUBLE_EQ(worst[k].scaled_jacobian, 1.0);
    ++by_count[worst[k].boundary_faces];
  }
  EXPECT_EQ(worst[fixture_brick_hex(3, 3, 1, 1, 1)].boundary_faces, 0);  // the centre
  EXPECT_EQ(worst[fixture_brick_hex(3, 3, 0, 0, 0)].boundary_faces, 3);  // a corner
  EXPECT_EQ(worst[fixture_brick_hex(3, 3, 1, 0, 0)].boundary_faces, 2);  // an edge
  EXPECT_EQ(worst[fixture_brick_hex(3, 3, 1, 1, 0)].boundary_faces, 1);  // a face
  // 1 centre, 6 face hexes, 12 edge hexes, 8 corners.
  EXPECT_EQ(by_count[0], 1);
  EXPECT_EQ(by_count[1], 6);
  EXPECT_EQ(by_count[2], 12);
  EXPECT_EQ(by_count[3], 8);
  EXPECT_TRUE(mesh_worst_hexes(m, 0).empty());
}

TEST(WorstHexes, TiesAcrossChunksGoByIdForEveryThreadCount) {
  // 30^3 unit cubes: 27,000 equal values over two of its chunks (16,384 hexes each), each
  // trimmed: the lowest 20,000 by (value, id) are ids 0 .. 19,999 on any thread count.
  const HexMesh m = fixture_brick(30, 30, 30);
  for (const int threads : {1, 2}) {
    const std::vector<WorstHex> worst = mesh_worst_hexes(m, 20000, threads);
    ASSERT_EQ(worst.size(), 20000u);
    for (size_t k = 0; k < worst.size(); ++k) ASSERT_EQ(worst[k].hex, static_cast<int32_t>(k));
  }
}

TEST(WorstHexes, TheLowestByValueForEveryThreadCount) {
  // 40^3 jittered: several of mesh_worst_hexes' chunks, each trimmed more than once.
  BrickParams p;
  p.dims = {40, 40, 40};
  p.jitter = 0.3;
  p.seed = 7;
  const HexMesh m = generate_brick(p);
  std::vector<std::pair<double, int32_t>> all;
  for (int32_t h = 0; h < m.hex_count(); ++h)
    all.emplace_back(hex_scaled_jacobian(hex_points(m, h)), h);
  std::sort(all.begin(), all.end());
  const std::vector<WorstHex> one = mesh_worst_hexes(m, 50, 1);
  const std::vector<WorstHex> three = mesh_worst_hexes(m, 50, 3);
  ASSERT_EQ(one.size(), 50u);
  ASSERT_EQ(three.size(), 50u);
  for (size_t k = 0; k < one.size(); ++k) {
    EXPECT_EQ(one[k].hex, all[k].second) << k;
    EXPECT_EQ(one[k].scaled_jacobian, all[k].first) << k;
    EXPECT_EQ(three[k].hex, one[k].hex) << k;
    EXPECT_EQ(three[k].boundary_faces, one[k].boundary_faces) << k;
  }
  EXPECT_LT(one.front().scaled_jacobian, one.back().scaled_jacobian);
}

}  // namespace
}  // namespace hexrefine
