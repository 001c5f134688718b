/// \file
/// algorithms/placement/node_slide.hpp: projection onto a slide (patch, segment, unions) and its
/// tangent space.

#include "algorithms/placement/node_slide.hpp"

#include <gtest/gtest.h>

namespace hexrefine {
namespace {

using Vec3 = Eigen::Vector3d;

/// The unit square in z = 0 (patch 0) and the square beside it, tilted up by 90 degrees along
/// x = 1 (patch 1); segments along the x and y axes.
SlideGeometry two_patches() {
  SlideGeometry g;
  g.patches.push_back({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)});
  g.patches.push_back({Vec3(1, 0, 0), Vec3(1, 0, 1), Vec3(1, 1, 1), Vec3(1, 1, 0)});
  g.segments.push_back({Vec3(0, 0, 0), Vec3(2, 0, 0)});
  g.segments.push_back({Vec3(0, 0, 0), Vec3(0, 3, 0)});
  g.items = {0, 1, 0, 1};  // patches 0, 1; segments 0, 1
  return g;
}

TEST(NodeSlide, DimensionsOfTheKinds) {
  EXPECT_EQ(slide_dimension(SlideKind::free), 3);
  EXPECT_EQ(slide_dimension(SlideKind::patch), 2);
  EXPECT_EQ(slide_dimension(SlideKind::patches), 2);
  EXPECT_EQ(slide_dimension(SlideKind::segment), 1);
  EXPECT_EQ(slide_dimension(SlideKind::segments), 1);
}

TEST(NodeSlide, ProjectsOntoThePatchClampedToItsSquare) {
  const SlideGeometry g = two_patches();
  const NodeSlide patch{SlideKind::patch, 0, 1};
  SlideState s;
  Vec3 p = slide_project(patch, g, Vec3(0.25, 0.5, 0.7), s);
  EXPECT_NEAR((p - Vec3(0.25, 0.5, 0)).norm(), 0, 1e-12);
  EXPECT_EQ(s.item, 0);
  EXPECT_NEAR(s.u, 0.25, 1e-12);
  EXPECT_NEAR(s.v, 0.5, 1e-12);
  // Beyond its side x = 1: the nearest point of the square is on that side.
  p = slide_project(patch, g, Vec3(1.5, 0.5, -0.2), s);
  EXPECT_NEAR((p - Vec3(1, 0.5, 0)).norm(), 0, 1e-12);
  EXPECT_NEAR(s.u, 1, 1e-12);
  // A free node is not moved.
  SlideState unused;
  EXPECT_EQ(slide_project(NodeSlide{}, g, Vec3(7, 8, 9), unused), Vec3(7, 8, 9));
}

TEST(NodeSlide, UnionsPickTheNearestItem) {
  const SlideGeometry g = two_patches();
  const NodeSlide patches{SlideKind::patches, 0, 2};
  SlideState s;
  Vec3 p = slide_project(patches, g, Vec3(1.2, 0.5, 0.6), s);  // nearer the upright patch
  EXPECT_EQ(s.item, 1);
  EXPECT_NEAR((p - Vec3(1, 0.5, 0.6)).norm(), 0, 1e-12);
  p = slide_project(patches, g, Vec3(0.6, 0.5, 0.1), s);
  EXPECT_EQ(s.item, 0);
  EXPECT_NEAR((p - Vec3(0.6, 0.5, 0)).norm(), 0, 1e-12);
  const NodeSlide segments{SlideKind::segments, 2, 2};
  p = slide_project(segments, g, Vec3(0.2, 1.5, 0.3), s);
  EXPECT_EQ(s.item, 1);
  EXPECT_NEAR(s.u, 0.5, 1e-12);
  EXPECT_NEAR((p - Vec3(0, 1.5, 0)).norm(), 0, 1e-12);
  p = slide_project(segments, g, Vec3(5, -1, 0), s);  // past the end of segment 0
  EXPECT_EQ(s.item, 0);
  EXPECT_EQ(s.u, 1);
  EXPECT_EQ(p, Vec3(2, 0, 0));
}

TEST(NodeSlide, TangentDropsTheNormalPart) {
  const SlideGeometry g = two_patches();
  const Vec3 g_in(0.3, -0.4, 2.0);
  SlideState s{0, 0.5, 0.5};
  EXPECT_NEAR(
      (slide_tangent(NodeSlide{SlideKind::patch, 0, 1}, g, s, g_in) - Vec3(0.3, -0.4, 0)).norm(), 0,
      1e-12);
  s = {0, 0.2, 0};
  EXPECT_NEAR(
      (slide_tangent(NodeSlide{SlideKind::segment, 2, 1}, g, s, g_in) - Vec3(0.3, 0, 0)).norm(), 0,
      1e-12);
  // Free, or not placed yet: the gradient itself.
  EXPECT_EQ(slide_tangent(NodeSlide{}, g, s, g_in), g_in);
  EXPECT_EQ(slide_tangent(NodeSlide{SlideKind::patch, 0, 1}, g, SlideState{}, g_in), g_in);
}

}  // namespace
}  // namespace hexrefine
