#include "mesh/quad_patch.hpp"

#include <algorithm>
#include <cmath>

namespace hexrefine {

Eigen::Vector3d quad_point(const Quad& q, double u, double v) {
  return (1 - u) * (1 - v) * q[0] + u * (1 - v) * q[1] + u * v * q[2] + (1 - u) * v * q[3];
}

std::array<Eigen::Vector3d, 2> quad_tangents(const Quad& q, double u, double v) {
  return {(1 - v) * (q[1] - q[0]) + v * (q[2] - q[3]), (1 - u) * (q[3] - q[0]) + u * (q[2] - q[1])};
}

double quad_diameter(const Quad& q) {
  return std::max((q[2] - q[0]).norm(), (q[3] - q[1]).norm());
}

double quad_area(const Quad& q) {
  static const double nodes[3] = {0.5 - 0.5 * std::sqrt(0.6), 0.5, 0.5 + 0.5 * std::sqrt(0.6)};
  static const double weights[3] = {5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0};
  double area = 0.0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const auto [su, sv] = quad_tangents(q, nodes[i], nodes[j]);
      area += weights[i] * weights[j] * su.cross(sv).norm();
    }
  return area;
}

Eigen::Vector3d quad_unit_normal(const Quad& q) {
  const Eigen::Vector3d cross = (q[2] - q[0]).cross(q[3] - q[1]);
  const double size2 = std::max((q[2] - q[0]).squaredNorm(), (q[3] - q[1]).squaredNorm());
  return cross.norm() > 1e-12 * size2 ? Eigen::Vector3d(cross.normalized())
                                      : Eigen::Vector3d::Zero();
}

double quad_warp(const Quad& q) {
  const Eigen::Vector3d n = (q[2] - q[0]).cross(q[3] - q[1]);
  const double n_norm = n.norm();
  if (!(n_norm > 0.0)) return 0.0;  // collinear diagonals: the points span no plane to leave
  double lo = 0.0, hi = 0.0;
  for (int i = 1; i < 4; ++i) {
    const double d = (q[i] - q[0]).dot(n) / n_norm;
    lo = std::min(lo, d);
    hi = std::max(hi, d);
  }
  return hi - lo;
}

double quad_relative_warp(const Quad& q) {
  const double diameter = quad_diameter(q);
  return diameter > 0.0 ? quad_warp(q) / diameter : 0.0;
}

QuadProjection quad_closest_point(const Quad& q, const Eigen::Vector3d& p, double u0, double v0) {
  double u = std::clamp(u0, 0.0, 1.0), v = std::clamp(v0, 0.0, 1.0);
  for (int iteration = 0; iteration < 30; ++iteration) {
    const Eigen::Vector3d r = quad_point(q, u, v) - p;
    const auto [su, sv] = quad_tangents(q, u, v);
    const double a = su.dot(su), b = su.dot(sv), c = sv.dot(sv);
    const double det = a * c - b * b;
    if (!(det > 1e-300)) break;
    const double gu = su.dot(r), gv = sv.dot(r);
    const double du = -(c * gu - b * gv) / det, dv = -(a * gv - b * gu) / det;
    const double nu = std::clamp(u + du, 0.0, 1.0), nv = std::clamp(v + dv, 0.0, 1.0);
    const bool settled = std::abs(nu - u) < 1e-15 && std::abs(nv - v) < 1e-15;
    u = nu;
    v = nv;
    if (settled) break;
  }
  QuadProjection out;
  out.u = u;
  out.v = v;
  out.point = quad_point(q, u, v);
  out.distance = (out.point - p).norm();
  return out;
}

double quad_distance(const Quad& q, const Eigen::Vector3d& p) {
  double distance = quad_closest_point(q, p).distance;
  for (const Eigen::Vector3d& c : q) distance = std::min(distance, (c - p).norm());
  return distance;
}

bool quad_within(const Quad& q, const Eigen::Vector3d& p, double tolerance) {
  const Eigen::Vector3d r = quad_point(q, 0.5, 0.5) - p;
  const auto [su, sv] = quad_tangents(q, 0.5, 0.5);
  const double a = su.dot(su), b = su.dot(sv), c = sv.dot(sv);
  const double det = a * c - b * b;
  if (det > 1e-300) {
    const double gu = su.dot(r), gv = sv.dot(r);
    const double u = 0.5 - (c * gu - b * gv) / det, v = 0.5 - (a * gv - b * gu) / det;
    if (u >= 0.0 && u <= 1.0 && v >= 0.0 && v <= 1.0 &&
        (quad_point(q, u, v) - p).norm() <= tolerance)
      return true;
  }
  return quad_distance(q, p) <= tolerance;
}

}  // namespace hexrefine
