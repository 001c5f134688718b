#include "mesh/quality.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

#include "mesh/hex_convention.hpp"

namespace hexrefine {

Eigen::Matrix3d hex_corner_jacobian(const HexCorners& p, int v) {
  Eigen::Matrix3d a;
  for (int k = 0; k < 3; ++k) {
    const int e = hex_vertex_edges[v][k];
    a.col(k) = p[hex_edges[e][1]] - p[hex_edges[e][0]];
  }
  return a;
}

Eigen::Matrix3d hex_centre_jacobian(const HexCorners& p) {
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  for (int k = 0; k < 3; ++k)
    for (int e : hex_axis_edges[k]) a.col(k) += p[hex_edges[e][1]] - p[hex_edges[e][0]];
  return a / 4.0;
}

bool hex_corners_positive(const HexCorners& p) {
  for (int v = 0; v < 8; ++v)
    if (!(hex_corner_jacobian(p, v).determinant() > 0)) return false;
  return true;
}

namespace {

/// det(A) / (|a1| |a2| |a3|), 0 if a column has zero length.
double scaled_determinant(const Eigen::Matrix3d& a) {
  const double lengths = a.col(0).norm() * a.col(1).norm() * a.col(2).norm();
  if (!(lengths > std::numeric_limits<double>::min())) return 0.0;
  // Clamped: rounding can push a right-angled frame a hair past 1.
  return std::clamp(a.determinant() / lengths, -1.0, 1.0);
}

}  // namespace

void hex_scaled_jacobian_samples(const HexCorners& p, std::array<double, 9>& out) {
  for (int v = 0; v < 8; ++v) out[v] = scaled_determinant(hex_corner_jacobian(p, v));
  out[8] = scaled_determinant(hex_centre_jacobian(p));
}

double hex_scaled_jacobian(const HexCorners& p) {
  double best = scaled_determinant(hex_centre_jacobian(p));
  for (int v = 0; v < 8; ++v) best = std::min(best, scaled_determinant(hex_corner_jacobian(p, v)));
  return best;
}

double hex_jacobian(const HexCorners& p) {
  double best = hex_centre_jacobian(p).determinant();
  for (int v = 0; v < 8; ++v) best = std::min(best, hex_corner_jacobian(p, v).determinant());
  return best;
}

double hex_shape(const HexCorners& p) {
  double best = 1.0;
  for (int v = 0; v < 8; ++v) {
    const Eigen::Matrix3d a = hex_corner_jacobian(p, v);
    const double det = a.determinant();
    const double frobenius2 = a.squaredNorm();
    if (!(det > 0.0) || !(frobenius2 > 0.0)) return 0.0;
    best = std::min(best, 3.0 * std::cbrt(det * det) / frobenius2);
  }
  return std::clamp(best, 0.0, 1.0);
}

double hex_condition(const HexCorners& p) {
  double worst = 1.0;
  for (int v = 0; v < 8; ++v) {
    const Eigen::Matrix3d a = hex_corner_jacobian(p, v);
    const double det = a.determinant();
    // The threshold (Verdict's VERDICT_DBL_MIN) keeps the inverse finite.
    if (!(det > 1e-30)) return hex_metric_max;
    const double condition = a.norm() * a.inverse().norm() / 3.0;
    worst = std::max(worst, condition);
  }
  return std::min(worst, hex_metric_max);
}

double hex_edge_ratio(const HexCorners& p) {
  double shortest = std::numeric_limits<double>::infinity(), longest = 0.0;
  for (const auto& e : hex_edges) {
    const double length = (p[e[1]] - p[e[0]]).norm();
    shortest = std::min(shortest, length);
    longest = std::max(longest, length);
  }
  if (!(shortest > 0.0)) return hex_metric_max;
  return std::min(longest / shortest, hex_metric_max);
}

double hex_volume(const HexCorners& p) {
  // det J is a polynomial of degree <= 2 in each reference coordinate, so the 2-point Gauss rule
  // per direction (exact to degree 3) integrates it exactly.
  const double g = 0.5 / std::sqrt(3.0);
  const double nodes[2] = {0.5 - g, 0.5 + g};
  double volume = 0.0;
  for (double w : nodes)
    for (double v : nodes)
      for (double u : nodes) {
        const double t[3] = {u, v, w};
        Eigen::Matrix3d jacobian = Eigen::Matrix3d::Zero();
        for (int corner = 0; corner < 8; ++corner) {
          double shape[3], derivative[3];
          for (int k = 0; k < 3; ++k) {
            const bool high = hex_corner[corner][k] == 1;
            shape[k] = high ? t[k] : 1.0 - t[k];
            derivative[k] = high ? 1.0 : -1.0;
          }
          jacobian.col(0) += p[corner] * (derivative[0] * shape[1] * shape[2]);
          jacobian.col(1) += p[corner] * (shape[0] * derivative[1] * shape[2]);
          jacobian.col(2) += p[corner] * (shape[0] * shape[1] * derivative[2]);
        }
        volume += jacobian.determinant() / 8.0;  // each Gauss weight is 1/8 on the unit cube
      }
  return volume;
}

std::vector<double> mesh_scaled_jacobians(const HexMesh& mesh) {
  std::vector<double> out(mesh.hexes.size());
  for (int32_t h = 0; h < mesh.hex_count(); ++h) out[h] = hex_scaled_jacobian(hex_points(mesh, h));
  return out;
}

double mesh_min_scaled_jacobian(const HexMesh& mesh) {
  double best = 1.0;
  for (int32_t h = 0; h < mesh.hex_count(); ++h)
    best = std::min(best, hex_scaled_jacobian(hex_points(mesh, h)));
  return best;
}

bool hex_is_parallelepiped(const HexCorners& p) {
  const Eigen::Vector3d a = p[1] - p[0], b = p[3] - p[0], c = p[4] - p[0];
  const double tolerance = 1e-9 * std::max({a.norm(), b.norm(), c.norm()});
  for (int v = 0; v < 8; ++v) {
    const Eigen::Vector3d affine =
        p[0] + hex_corner[v][0] * a + hex_corner[v][1] * b + hex_corner[v][2] * c;
    if ((p[v] - affine).norm() > tolerance) return false;
  }
  return a.dot(b.cross(c)) > 0;
}

}  // namespace hexrefine
