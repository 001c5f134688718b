#include "algorithms/placement/node_slide.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

namespace hexrefine {

using Vec3 = Eigen::Vector3d;

int slide_dimension(SlideKind kind) {
  switch (kind) {
    case SlideKind::free:
      return 3;
    case SlideKind::patch:
    case SlideKind::patches:
      return 2;
    case SlideKind::segment:
    case SlideKind::segments:
      return 1;
  }
  return 3;
}

Vec3 slide_project(const NodeSlide& slide, const SlideGeometry& geometry, const Vec3& x,
                   SlideState& state) {
  if (slide.kind == SlideKind::free) return x;
  const bool on_patches = slide.kind == SlideKind::patch || slide.kind == SlideKind::patches;
  const SlideState hint = state;
  double best = std::numeric_limits<double>::infinity();
  Vec3 out = x;
  for (int32_t k = slide.first; k < slide.first + slide.count; ++k) {
    const int32_t item = geometry.items[k];
    if (on_patches) {
      const bool same = item == hint.item;
      const QuadProjection p =
          quad_closest_point(geometry.patches[item], x, same ? hint.u : 0.5, same ? hint.v : 0.5);
      if (p.distance < best) {
        best = p.distance;
        out = p.point;
        state = {item, p.u, p.v};
      }
    } else {
      const Vec3& a = geometry.segments[item][0];
      const Vec3 d = geometry.segments[item][1] - a;
      const double len2 = d.squaredNorm();
      const double t = len2 > 0 ? std::clamp((x - a).dot(d) / len2, 0.0, 1.0) : 0.0;
      const Vec3 p = a + t * d;
      const double distance = (p - x).norm();
      if (distance < best) {
        best = distance;
        out = p;
        state = {item, t, 0.0};
      }
    }
  }
  return out;
}

Vec3 slide_tangent(const NodeSlide& slide, const SlideGeometry& geometry, const SlideState& state,
                   const Vec3& g) {
  if (slide.kind == SlideKind::free || state.item < 0) return g;
  if (slide.kind == SlideKind::patch || slide.kind == SlideKind::patches) {
    const auto [su, sv] = quad_tangents(geometry.patches[state.item], state.u, state.v);
    Eigen::Matrix<double, 3, 2> j;
    j.col(0) = su;
    j.col(1) = sv;
    const Eigen::Matrix2d jtj = j.transpose() * j;
    if (!(std::abs(jtj.determinant()) > 1e-300)) return Vec3::Zero();
    return j * jtj.inverse() * (j.transpose() * g);
  }
  const Vec3 d = (geometry.segments[state.item][1] - geometry.segments[state.item][0]).normalized();
  return d.dot(g) * d;
}

}  // namespace hexrefine
