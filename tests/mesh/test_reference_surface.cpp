#include "mesh/reference_surface.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "mesh/generators.hpp"

namespace hexrefine {
namespace {

using V = Eigen::Vector3d;

/// A 2 x 1 x 1 brick of two unit hexes: its bottom (z = 0) is two unit squares side by side.
const HexMesh& two_hexes() {
  static const HexMesh m = generate_brick({.dims = {2, 1, 1}, .size = {2, 1, 1}});
  return m;
}

TEST(ReferenceSurface, HoldsEveryBoundaryFaceOfTheReference) {
  const ReferenceSurface s(two_hexes());
  EXPECT_EQ(s.quads().size(), 10u);  // 2 x 5 outer faces, the shared one is interior
  ASSERT_EQ(s.tolerances().size(), 10u);
  for (size_t i = 0; i < s.quads().size(); ++i) {
    EXPECT_TRUE(reference_surface_holds_face(s, s.quads()[i])) << i;
    EXPECT_NEAR(s.tolerances()[i], 1e-6 * std::sqrt(2.0), 1e-15);  // planar: no warp term
  }
}

TEST(ReferenceSurface, HoldsASubFaceAndAFaceAcrossTwoCoplanarFaces) {
  const ReferenceSurface s(two_hexes());
  EXPECT_TRUE(reference_surface_holds_face(
      s, {V(0.2, 0.2, 0), V(0.6, 0.2, 0), V(0.6, 0.7, 0), V(0.2, 0.7, 0)}));
  // Straddles the two bottom squares (a smoothed face whose corners slid over both).
  EXPECT_TRUE(
      reference_surface_holds_face(s, {V(0.5, 0, 0), V(1.5, 0, 0), V(1.5, 1, 0), V(0.5, 1, 0)}));
}

TEST(ReferenceSurface, RejectsAFaceOffTheSurfaceOrCuttingAnEdge) {
  const ReferenceSurface s(two_hexes());
  // Lifted by 1e-3 of its size: beyond the tolerance (1e-6 x the diagonal), a gap.
  EXPECT_FALSE(reference_surface_holds_face(
      s, {V(0.2, 0.2, 1e-3), V(0.6, 0.2, 1e-3), V(0.6, 0.7, 1e-3), V(0.2, 0.7, 1e-3)}));
  // Corners on the bottom and on the side x = 2, cutting the edge between them: the corners on
  // the side lie on no face within 45 degrees of the face's normal (14 degrees from the bottom).
  EXPECT_FALSE(
      reference_surface_holds_face(s, {V(1.6, 0, 0), V(2, 0, 0.1), V(2, 1, 0.1), V(1.6, 1, 0)}));
  // A degenerate face (zero area: no normal) lies across nothing, here over both bottom
  // squares, which hold its corners.
  EXPECT_FALSE(
      reference_surface_holds_face(s, {V(0.5, 0, 0), V(1.5, 0, 0), V(1.5, 0, 0), V(0.5, 0, 0)}));
}

// A face whose corners all lie on the surface but whose centroid sags off it by more than
// mesh_check_across_chord x its diameter. The reference's top bends by 60 degrees at x = 1 (the
// right hex's top rises with slope tan 60); a face across the bend has its normal 30 degrees from
// both tops, so only the chord decides.
TEST(ReferenceSurface, RejectsAChordSaggingAcrossABendAndHoldsAShortOne) {
  HexMesh bent = two_hexes();
  const double rise = std::tan(60 * std::numbers::pi / 180);
  for (V& p : bent.points)
    if (p.x() == 2 && p.z() == 1) p.z() = 1 + rise;
  const ReferenceSurface s(bent);
  const auto across = [&](double d) {  // corners d from the bend on either side
    const V left(1 - d, 0, 1), right(1 + d / 2, 0, 1 + d * rise / 2);
    return Quad{left, right, right + V(0, 1, 0), left + V(0, 1, 0)};
  };
  // d = 0.5: centroid 0.2165 from both tops, diameter 1.32: a sag of 0.16 x the diameter.
  EXPECT_FALSE(reference_surface_holds_face(s, across(0.5)));
  // d = 0.05: a sag of 0.02 x the diameter.
  EXPECT_TRUE(reference_surface_holds_face(s, across(0.05)));
}

}  // namespace
}  // namespace hexrefine
