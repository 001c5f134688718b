#include "mesh/quality.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "mesh/hex_convention.hpp"
#include "tests/fixtures.hpp"

namespace hexrefine {
namespace {

HexCorners unit_cube() {
  HexCorners p;
  for (int v = 0; v < 8; ++v)
    p[v] = Eigen::Vector3d(hex_corner[v][0], hex_corner[v][1], hex_corner[v][2]);
  return p;
}

/// The irregular hex of Verdict's reference tests (Verdict's hex order = VTK order).
HexCorners verdict_reference_hex() {
  return {Eigen::Vector3d(-.2, -.7, -.3), Eigen::Vector3d(-.7, .4, -.6),
          Eigen::Vector3d(-.5, .5, .3),   Eigen::Vector3d(-.3, -.5, .5),
          Eigen::Vector3d(.5, -.8, -.2),  Eigen::Vector3d(.4, .4, -.6),
          Eigen::Vector3d(.2, .5, .2),    Eigen::Vector3d(.5, -.3, .8)};
}

TEST(Quality, UnitCubeIsPerfect) {
  const HexCorners p = unit_cube();
  EXPECT_DOUBLE_EQ(hex_scaled_jacobian(p), 1.0);
  EXPECT_DOUBLE_EQ(hex_jacobian(p), 1.0);
  EXPECT_DOUBLE_EQ(hex_shape(p), 1.0);
  EXPECT_DOUBLE_EQ(hex_condition(p), 1.0);
  EXPECT_DOUBLE_EQ(hex_edge_ratio(p), 1.0);
  EXPECT_NEAR(hex_volume(p), 1.0, 1e-15);
}

TEST(Quality, VerdictReferenceHex) {
  const HexCorners p = verdict_reference_hex();
  EXPECT_NEAR(hex_scaled_jacobian(p), 0.7778495101, 5e-11);
  EXPECT_NEAR(hex_shape(p), 0.78978528102, 5e-12);
  EXPECT_NEAR(hex_condition(p), 1.2730598257, 5e-11);
  EXPECT_NEAR(hex_edge_ratio(p), 1.7944358445, 5e-11);
  EXPECT_NEAR(hex_jacobian(p), 0.477, 5e-4);
}

TEST(Quality, BoxScalesAsExpected) {
  HexCorners p = unit_cube();
  for (auto& x : p) x = Eigen::Vector3d(2.0 * x.x(), 3.0 * x.y(), 0.5 * x.z());
  EXPECT_DOUBLE_EQ(hex_scaled_jacobian(p), 1.0);
  EXPECT_NEAR(hex_jacobian(p), 3.0, 1e-14);
  EXPECT_NEAR(hex_volume(p), 3.0, 1e-14);
  EXPECT_DOUBLE_EQ(hex_edge_ratio(p), 6.0);
  EXPECT_LT(hex_shape(p), 1.0);
  EXPECT_GT(hex_condition(p), 1.0);
}

TEST(Quality, FlatHexIsDegenerate) {
  HexCorners p = unit_cube();
  for (int v = 4; v < 8; ++v) p[v].z() = 0.0;  // top pressed onto the bottom
  EXPECT_DOUBLE_EQ(hex_scaled_jacobian(p), 0.0);
  EXPECT_DOUBLE_EQ(hex_jacobian(p), 0.0);
  EXPECT_DOUBLE_EQ(hex_shape(p), 0.0);
  EXPECT_DOUBLE_EQ(hex_condition(p), hex_metric_max);
  EXPECT_DOUBLE_EQ(hex_volume(p), 0.0);
  EXPECT_DOUBLE_EQ(hex_edge_ratio(p), hex_metric_max);  // the vertical edges have length 0
}

TEST(Quality, InsideOutCube) {
  HexCorners p = unit_cube();
  for (int v = 0; v < 4; ++v) std::swap(p[v], p[v + 4]);
  EXPECT_DOUBLE_EQ(hex_scaled_jacobian(p), -1.0);
  EXPECT_DOUBLE_EQ(hex_jacobian(p), -1.0);
  EXPECT_NEAR(hex_volume(p), -1.0, 1e-15);
  EXPECT_DOUBLE_EQ(hex_shape(p), 0.0);
  EXPECT_DOUBLE_EQ(hex_condition(p), hex_metric_max);
  EXPECT_DOUBLE_EQ(hex_edge_ratio(p), 1.0);
}

TEST(Quality, ParallelepipedIsAffineAndPositive) {
  EXPECT_TRUE(hex_is_parallelepiped(unit_cube()));
  // Sheared and scaled: still affine.
  HexCorners sheared = unit_cube();
  for (Eigen::Vector3d& x : sheared)
    x = Eigen::Vector3d(3 * x[0] + 0.5 * x[2], x[1] - 0.2 * x[0], 2 * x[2]);
  EXPECT_TRUE(hex_is_parallelepiped(sheared));
  // Inside out: affine but negatively oriented.
  HexCorners mirrored = unit_cube();
  for (int v = 0; v < 4; ++v) std::swap(mirrored[v], mirrored[v + 4]);
  EXPECT_FALSE(hex_is_parallelepiped(mirrored));
  // One corner moved by 1e-6 of the size: no longer affine; by 1e-12: rounding, still affine.
  HexCorners bent = unit_cube();
  bent[6] += Eigen::Vector3d(0, 0, 1e-6);
  EXPECT_FALSE(hex_is_parallelepiped(bent));
  HexCorners rounded = unit_cube();
  rounded[6] += Eigen::Vector3d(0, 0, 1e-12);
  EXPECT_TRUE(hex_is_parallelepiped(rounded));
  EXPECT_FALSE(hex_is_parallelepiped(verdict_reference_hex()));
}

TEST(Quality, VolumeOfNonPlanarHexIsExactTrilinearIntegral) {
  // Lifting one top corner by d adds the volume under the bilinear patch: d/4.
  HexCorners p = unit_cube();
  p[6].z() += 0.4;
  EXPECT_NEAR(hex_volume(p), 1.1, 1e-14);
}

TEST(Quality, MeshScaledJacobians) {
  HexMesh m = fixture_brick(2, 1, 1);
  m.points[m.hexes[1][6]].z() = 0.5;  // shared corner not on hex 0: only hex 1 distorted
  const std::vector<double> sj = mesh_scaled_jacobians(m);
  ASSERT_EQ(sj.size(), 2u);
  EXPECT_DOUBLE_EQ(sj[0], 1.0);
  EXPECT_LT(sj[1], 1.0);
  EXPECT_GT(sj[1], 0.0);
  EXPECT_DOUBLE_EQ(mesh_min_scaled_jacobian(m), sj[1]);
  EXPECT_DOUBLE_EQ(mesh_min_scaled_jacobian(HexMesh{}), 1.0);
}

}  // namespace
}  // namespace hexrefine
