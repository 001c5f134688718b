/// The mesh-wide quality passes (mesh/quality_lanes.inc at two and, where the machine has AVX2,
/// four hexes per evaluation) against the per-hex functions, bit for bit: regular, distorted,
/// inverted and degenerate hexes, a collapsed edge, a NaN corner, odd counts.

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <random>

#include "mesh/quality.hpp"
#include "tests/fixtures.hpp"

namespace hexrefine {
namespace {

uint64_t bits(double x) {
  return std::bit_cast<uint64_t>(x);
}

/// 2 x 3 x 5 jittered brick with every hex's own nodes, then distorted hexes appended.
HexMesh mesh_of_hard_hexes() {
  const HexMesh brick = fixture_brick(5, 3, 2);
  HexMesh m;
  std::mt19937 random(11);
  std::uniform_real_distribution<double> jitter(-0.45, 0.45);
  auto add = [&](const std::array<Eigen::Vector3d, 8>& corners) {
    HexCell c;
    for (int v = 0; v < 8; ++v) {
      c[v] = m.point_count();
      m.points.push_back(corners[v]);
    }
    m.hexes.push_back(c);
  };
  for (int32_t h = 0; h < brick.hex_count(); ++h) {
    std::array<Eigen::Vector3d, 8> p = hex_points(brick, h);
    for (Eigen::Vector3d& x : p)
      x += Eigen::Vector3d(jitter(random), jitter(random), jitter(random));
    add(p);
  }
  std::array<Eigen::Vector3d, 8> cube = hex_points(brick, 0);
  std::array<Eigen::Vector3d, 8> p = cube;
  for (int v = 0; v < 4; ++v) std::swap(p[v], p[v + 4]);  // inside out
  add(p);
  p = cube;
  p[6] = p[2];  // collapsed edge
  add(p);
  p = cube;
  p[3] = p[0];  // a corner on another: zero-length columns
  p[7] = p[4];
  add(p);
  p = cube;
  p[5].x() = std::nan("");
  add(p);
  p = cube;
  for (Eigen::Vector3d& x : p) x = 1e-160 * x;  // lengths product below the smallest normal
  add(p);
  p = cube;
  for (Eigen::Vector3d& x : p) x = 1e150 * x + Eigen::Vector3d::Constant(3e151);
  add(p);
  return m;
}

TEST(QualityLanes, MeshPassesAreBitIdenticalToThePerHexFunctions) {
  const HexMesh m = mesh_of_hard_hexes();
  for (int32_t first : {0, 1, 3}) {
    for (size_t count : {size_t{1}, size_t{2}, size_t{3}, size_t{5}, m.hexes.size() - first}) {
      SCOPED_TRACE(std::to_string(first) + " + " + std::to_string(count));
      std::vector<double> sj(count), volume(count), ratio(count), only(count);
      mesh_hex_measures(m, first, sj, volume, ratio);
      mesh_scaled_jacobians(m, first, only);
      for (size_t k = 0; k < count; ++k) {
        const HexCorners p = hex_points(m, first + static_cast<int32_t>(k));
        EXPECT_EQ(bits(sj[k]), bits(hex_scaled_jacobian(p))) << k;
        EXPECT_EQ(bits(only[k]), bits(sj[k])) << k;
        EXPECT_EQ(bits(volume[k]), bits(hex_volume(p))) << k;
        EXPECT_EQ(bits(ratio[k]), bits(hex_edge_ratio(p))) << k;
      }
    }
  }
  std::vector<int32_t> ids;
  for (int32_t h = m.hex_count() - 1; h >= 0; h -= 2) ids.push_back(h);
  std::vector<double> listed(ids.size());
  mesh_scaled_jacobians(m, ids, listed);
  for (size_t k = 0; k < ids.size(); ++k)
    EXPECT_EQ(bits(listed[k]), bits(hex_scaled_jacobian(hex_points(m, ids[k])))) << k;
  // The degenerate ones give what the metrics document.
  const int32_t n = m.hex_count();
  EXPECT_EQ(hex_scaled_jacobian(hex_points(m, n - 6)), -1.0);
  EXPECT_EQ(hex_edge_ratio(hex_points(m, n - 5)), hex_metric_max);
}

}  // namespace
}  // namespace hexrefine
