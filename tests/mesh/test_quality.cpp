#include "mesh/quality.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

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

/// Cubes with every corner moved by up to `spread` at random: at 0.6 many are inverted or
/// tangled, and every tenth gets a zero-length edge (corner 1 on corner 0).
std::vector<HexCorners> random_hexes(int count, double spread, uint32_t seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> offset(-spread, spread);
  std::vector<HexCorners> out;
  for (int i = 0; i < count; ++i) {
    HexCorners p = unit_cube();
    for (Eigen::Vector3d& x : p)
      x += Eigen::Vector3d(offset(random), offset(random), offset(random));
    if (i % 10 == 9) p[1] = p[0];
    out.push_back(p);
  }
  return out;
}

/// The scaled Jacobian as its definition reads, on Eigen's matrices: each sample's determinant
/// over its three column lengths, clamped to [-1, 1], 0 for a zero product of lengths.
double scaled_jacobian_by_definition(const HexCorners& p) {
  auto sample = [](const Eigen::Matrix3d& a) {
    const double lengths = a.col(0).norm() * a.col(1).norm() * a.col(2).norm();
    if (!(lengths > std::numeric_limits<double>::min())) return 0.0;
    return std::clamp(a.determinant() / lengths, -1.0, 1.0);
  };
  double best = sample(hex_centre_jacobian(p));
  for (int v = 0; v < 8; ++v) best = std::min(best, sample(hex_corner_jacobian(p, v)));
  return best;
}

TEST(Quality, ScaledJacobianIsBitForBitTheEigenFormulation) {
  // The two-lane kernel must give exactly what the matrix formulation gives (the refiners'
  // decisions and every committed figure were made with it).
  for (double spread : {0.05, 0.3, 0.6}) {
    const std::vector<HexCorners> hexes = random_hexes(2000, spread, 11);
    for (size_t k = 0; k + 1 < hexes.size(); ++k) {
      const std::array<double, 2> pair = hex_scaled_jacobian_pair(hexes[k], hexes[k + 1]);
      ASSERT_EQ(pair[0], scaled_jacobian_by_definition(hexes[k]));
      ASSERT_EQ(pair[1], scaled_jacobian_by_definition(hexes[k + 1]));
    }
    for (const HexCorners& p : hexes) {
      std::array<double, 9> samples;
      hex_scaled_jacobian_samples(p, samples);
      const double expected = scaled_jacobian_by_definition(p);
      ASSERT_EQ(hex_scaled_jacobian(p), expected);
      ASSERT_EQ(std::min(samples[8], *std::min_element(samples.begin(), samples.begin() + 8)),
                expected);
    }
  }
}

TEST(Quality, MeshScaledJacobiansOfAnyRangeMatchEachHex) {
  HexMesh m;
  for (const HexCorners& p : random_hexes(7, 0.3, 5)) {
    HexCell c;
    for (int v = 0; v < 8; ++v) {
      c[v] = m.point_count();
      m.points.push_back(p[v]);
    }
    m.hexes.push_back(c);
  }
  for (int32_t first = 0; first < 7; ++first)
    for (int32_t count = 0; first + count <= 7; ++count) {
      std::vector<double> out(static_cast<size_t>(count), -2.0);
      mesh_scaled_jacobians(m, first, out);
      for (int32_t k = 0; k < count; ++k)
        ASSERT_EQ(out[k], hex_scaled_jacobian(hex_points(m, first + k))) << first << " " << k;
    }
  // A list of hexes in any order, repeats allowed, odd or even length.
  const std::vector<int32_t> ids = {6, 0, 3, 3, 5};
  for (size_t count = 0; count <= ids.size(); ++count) {
    std::vector<double> out(count, -2.0);
    mesh_scaled_jacobians(m, std::span<const int32_t>(ids.data(), count), out);
    for (size_t k = 0; k < count; ++k)
      ASSERT_EQ(out[k], hex_scaled_jacobian(hex_points(m, ids[k]))) << count << " " << k;
  }
}

TEST(Quality, ScaledJacobiansAndVolumesOfAnyRangeMatchEachHexBitForBit) {
  // The checker's pass: both values from one gather of the corners, exactly the per-hex ones
  // (its volume sum is compared with the reference's).
  HexMesh m;
  for (double spread : {0.05, 0.6})
    for (const HexCorners& p : random_hexes(301, spread, 17)) {
      HexCell c;
      for (int v = 0; v < 8; ++v) {
        c[v] = m.point_count();
        m.points.push_back(p[v]);
      }
      m.hexes.push_back(c);
    }
  for (int32_t first : {0, 1, 300, 601})
    for (int32_t count : {0, 1, 2, 301}) {
      if (first + count > m.hex_count()) continue;
      std::vector<double> sj(static_cast<size_t>(count), -2.0), volume(sj.size(), -2.0);
      mesh_scaled_jacobians_and_volumes(m, first, sj, volume);
      for (int32_t k = 0; k < count; ++k) {
        const HexCorners p = hex_points(m, first + k);
        ASSERT_EQ(sj[k], hex_scaled_jacobian(p)) << first << " " << k;
        ASSERT_EQ(volume[k], hex_volume(p)) << first << " " << k;
      }
    }
}

TEST(Quality, VolumeIsTheGaussIntegralOfTheJacobian) {
  // det J of the trilinear map has degree <= 2 per reference coordinate, so the 2x2x2 Gauss rule
  // integrates it exactly: an independent evaluation of the same integral.
  auto gauss_volume = [](const HexCorners& p) {
    const double g[2] = {0.5 - 0.5 / std::sqrt(3.0), 0.5 + 0.5 / std::sqrt(3.0)};
    double volume = 0.0;
    for (double x : g)
      for (double y : g)
        for (double z : g) {
          Eigen::Matrix3d jacobian = Eigen::Matrix3d::Zero();
          for (int v = 0; v < 8; ++v) {
            const double t[3] = {x, y, z};
            double shape[3], slope[3];
            for (int k = 0; k < 3; ++k) {
              shape[k] = hex_corner[v][k] ? t[k] : 1.0 - t[k];
              slope[k] = hex_corner[v][k] ? 1.0 : -1.0;
            }
            jacobian.col(0) += slope[0] * shape[1] * shape[2] * p[v];
            jacobian.col(1) += shape[0] * slope[1] * shape[2] * p[v];
            jacobian.col(2) += shape[0] * shape[1] * slope[2] * p[v];
          }
          volume += jacobian.determinant() / 8.0;
        }
    return volume;
  };
  for (const HexCorners& p : random_hexes(500, 0.3, 3)) {
    const double expected = gauss_volume(p);
    ASSERT_NEAR(hex_volume(p), expected, 1e-13 * std::max(1.0, std::abs(expected)));
  }
}

}  // namespace
}  // namespace hexrefine
