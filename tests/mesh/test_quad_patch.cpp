/// \file
/// The bilinear patch of a quad (mesh/quad_patch.hpp): the unit square's reference values and a
/// warped quad.

#include "mesh/quad_patch.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace hexrefine {
namespace {

const Quad unit_square = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0),
                          Eigen::Vector3d(1, 1, 0), Eigen::Vector3d(0, 1, 0)};

TEST(QuadPatch, UnitSquareReferenceValues) {
  EXPECT_EQ(quad_unit_normal(unit_square), Eigen::Vector3d(0, 0, 1));
  const Quad reversed = {unit_square[0], unit_square[3], unit_square[2], unit_square[1]};
  EXPECT_EQ(quad_unit_normal(reversed), Eigen::Vector3d(0, 0, -1));
  EXPECT_DOUBLE_EQ(quad_diameter(unit_square), std::sqrt(2.0));
  EXPECT_NEAR(quad_area(unit_square), 1.0, 1e-15);
  EXPECT_EQ(quad_warp(unit_square), 0.0);
  EXPECT_EQ(quad_point(unit_square, 0.25, 0.5), Eigen::Vector3d(0.25, 0.5, 0));
  const QuadProjection p = quad_closest_point(unit_square, Eigen::Vector3d(0.3, 0.6, 2));
  EXPECT_NEAR(p.u, 0.3, 1e-12);
  EXPECT_NEAR(p.v, 0.6, 1e-12);
  EXPECT_NEAR(p.distance, 2.0, 1e-12);
  // Beyond a side: the nearest point is on that side.
  EXPECT_NEAR(quad_distance(unit_square, Eigen::Vector3d(1.5, 0.5, 0)), 0.5, 1e-12);
}

TEST(QuadPatch, DegenerateQuadHasNoNormal) {
  const Quad line = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(2, 0, 0),
                     Eigen::Vector3d(3, 0, 0)};
  EXPECT_EQ(quad_unit_normal(line), Eigen::Vector3d::Zero());
  const Quad point = {Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(1, 1, 1),
                      Eigen::Vector3d(1, 1, 1)};
  EXPECT_EQ(quad_unit_normal(point), Eigen::Vector3d::Zero());
}

TEST(QuadPatch, WarpedQuad) {
  // Corner q2 raised by 0.4: the diagonals' normal tilts towards -x, -y; the warp is the spread
  // of the corners' heights along it.
  Quad q = unit_square;
  q[2].z() = 0.4;
  const Eigen::Vector3d n = quad_unit_normal(q);
  EXPECT_NEAR(n.norm(), 1.0, 1e-15);
  EXPECT_GT(n.z(), 0.9);
  EXPECT_LT(n.x(), 0.0);
  EXPECT_LT(n.y(), 0.0);
  // Heights of q1, q2, q3 over q0 along n: (n.x), (n.x + n.y + 0.4 n.z), (n.y).
  const double heights[3] = {n.x(), n.x() + n.y() + 0.4 * n.z(), n.y()};
  const double lo = std::min({0.0, heights[0], heights[1], heights[2]});
  const double hi = std::max({0.0, heights[0], heights[1], heights[2]});
  EXPECT_NEAR(quad_warp(q), hi - lo, 1e-15);
  EXPECT_NEAR(quad_relative_warp(q), (hi - lo) / quad_diameter(q), 1e-15);
  // The patch passes through its corners and its centre is the mean of them.
  EXPECT_EQ(quad_point(q, 1, 1), q[2]);
  EXPECT_NEAR((quad_point(q, 0.5, 0.5) - Eigen::Vector3d(0.5, 0.5, 0.1)).norm(), 0.0, 1e-15);
}

TEST(QuadPatch, WithinSaysYesExactlyWhereAPatchPointIsThatClose) {
  // quad_within never misses a yes of quad_distance, and each of its own yeses names a real
  // patch point: where quad_distance says no, the patch's dense sampling finds a point within
  // the tolerance (plus the sampling's spacing). Points on, near and off planar and warped
  // quads of skewed shapes, at tolerances around their distance.
  std::mt19937 random(23);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3), where(-0.5, 1.5), height(-0.02, 0.02);
  auto sampled_distance = [](const Quad& q, const Eigen::Vector3d& p) {
    double best = std::numeric_limits<double>::infinity();
    for (int i = 0; i <= 400; ++i)
      for (int j = 0; j <= 400; ++j)
        best = std::min(best, (quad_point(q, i / 400.0, j / 400.0) - p).norm());
    return best;
  };
  int yes = 0, beyond_distance = 0;
  for (int shape = 0; shape < 100; ++shape) {
    Quad q = unit_square;
    for (Eigen::Vector3d& c : q) c += Eigen::Vector3d(jitter(random), jitter(random), 0);
    if (shape % 2) q[2].z() += jitter(random);  // warped
    for (int k = 0; k < 20; ++k) {
      const Eigen::Vector3d p =
          quad_point(q, where(random), where(random)) + Eigen::Vector3d(0, 0, height(random));
      const double distance = quad_distance(q, p);
      for (double tolerance : {0.5 * distance, 0.999 * distance, distance, 2.0 * distance}) {
        const bool within = quad_within(q, p, tolerance);
        if (distance <= tolerance) {
          ASSERT_TRUE(within) << shape << " " << k;
        }
        yes += within;
        if (!within || distance <= tolerance) continue;
        ++beyond_distance;
        ASSERT_LE(sampled_distance(q, p), tolerance + 0.01) << shape << " " << k;
      }
    }
  }
  EXPECT_GE(yes, 4000);             // the distance and twice it, for each of the 2,000 points
  EXPECT_LT(beyond_distance, 100);  // quad_distance is right almost everywhere
  // On the unit square: inside at height 0.1, beyond a side by 0.5.
  EXPECT_TRUE(quad_within(unit_square, Eigen::Vector3d(0.3, 0.6, 0.1), 0.1 + 1e-15));
  EXPECT_FALSE(quad_within(unit_square, Eigen::Vector3d(0.3, 0.6, 0.1), 0.099));
  EXPECT_FALSE(quad_within(unit_square, Eigen::Vector3d(1.5, 0.5, 0), 0.49));
  EXPECT_TRUE(quad_within(unit_square, Eigen::Vector3d(1.5, 0.5, 0), 0.51));
}

}  // namespace
}  // namespace hexrefine
