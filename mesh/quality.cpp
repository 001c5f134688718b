#include "mesh/quality.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

#include "mesh/hex_convention.hpp"

namespace hexrefine {

namespace {

/// The twelve edge vectors in hex_edges order, each from its corner at 0 to its corner at 1
/// along its axis: the columns of every corner Jacobian and, weighted, of the Jacobian anywhere.
std::array<Eigen::Vector3d, 12> hex_edge_vectors(const HexCorners& p) {
  std::array<Eigen::Vector3d, 12> edges;
  for (int e = 0; e < 12; ++e) edges[e] = p[hex_edges[e][1]] - p[hex_edges[e][0]];
  return edges;
}

Eigen::Matrix3d corner_jacobian(const std::array<Eigen::Vector3d, 12>& edges, int v) {
  Eigen::Matrix3d a;
  for (int k = 0; k < 3; ++k) a.col(k) = edges[hex_vertex_edges[v][k]];
  return a;
}

Eigen::Matrix3d centre_jacobian(const std::array<Eigen::Vector3d, 12>& edges) {
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  for (int k = 0; k < 3; ++k)
    for (int e : hex_axis_edges[k]) a.col(k) += edges[e];
  return a / 4.0;
}

/// det(A) / (|a1| |a2| |a3|) given the column lengths, 0 if a column has zero length.
double scaled_determinant(const Eigen::Matrix3d& a, double length0, double length1,
                          double length2) {
  const double lengths = length0 * length1 * length2;
  if (!(lengths > std::numeric_limits<double>::min())) return 0.0;
  // Clamped: rounding can push a right-angled frame a hair past 1.
  return std::clamp(a.determinant() / lengths, -1.0, 1.0);
}

double scaled_determinant(const Eigen::Matrix3d& a) {
  return scaled_determinant(a, a.col(0).norm(), a.col(1).norm(), a.col(2).norm());
}

/// Corner v's sample from the edge vectors and their lengths (each edge serves two corners, so
/// its length is taken once).
double corner_scaled_determinant(const std::array<Eigen::Vector3d, 12>& edges,
                                 const std::array<double, 12>& lengths, int v) {
  const int* e = hex_vertex_edges[v];
  return scaled_determinant(corner_jacobian(edges, v), lengths[e[0]], lengths[e[1]], lengths[e[2]]);
}

/// Weight of edge e in the Jacobian column of its axis at Gauss point q of the 2x2x2 rule: the
/// bilinear shape function of the edge's position in the other two reference coordinates.
struct GaussEdgeWeights {
  double w[8][12];
};
constexpr GaussEdgeWeights make_gauss_edge_weights() {
  constexpr double offset = 0.28867513459481288225;  // 1 / (2 sqrt 3)
  GaussEdgeWeights out{};
  for (int q = 0; q < 8; ++q) {
    const double t[3] = {q & 1 ? 0.5 + offset : 0.5 - offset, q & 2 ? 0.5 + offset : 0.5 - offset,
                         q & 4 ? 0.5 + offset : 0.5 - offset};
    for (int e = 0; e < 12; ++e) {
      const int* low = hex_corner[hex_edges[e][0]];
      const int* high = hex_corner[hex_edges[e][1]];
      double w = 1.0;
      for (int j = 0; j < 3; ++j)
        if (low[j] == high[j]) w *= low[j] == 1 ? t[j] : 1.0 - t[j];
      out.w[q][e] = w;
    }
  }
  return out;
}
constexpr GaussEdgeWeights gauss_edge_weights = make_gauss_edge_weights();
constexpr bool gauss_edge_weights_partition_unity() {
  for (int q = 0; q < 8; ++q)
    for (int k = 0; k < 3; ++k) {
      double sum = 0.0;
      for (int e : hex_axis_edges[k]) sum += gauss_edge_weights.w[q][e];
      if (sum < 1.0 - 1e-15 || sum > 1.0 + 1e-15) return false;
    }
  return true;
}
// The four edges of an axis interpolate its column, so an affine hex's Jacobian is its edges'.
static_assert(gauss_edge_weights_partition_unity());

}  // namespace

Eigen::Matrix3d hex_corner_jacobian(const HexCorners& p, int v) {
  Eigen::Matrix3d a;
  for (int k = 0; k < 3; ++k) {
    const int e = hex_vertex_edges[v][k];
    a.col(k) = p[hex_edges[e][1]] - p[hex_edges[e][0]];
  }
  return a;
}

Eigen::Matrix3d hex_centre_jacobian(const HexCorners& p) {
  return centre_jacobian(hex_edge_vectors(p));
}

bool hex_corners_positive(const HexCorners& p) {
  for (int v = 0; v < 8; ++v)
    if (!(hex_corner_jacobian(p, v).determinant() > 0)) return false;
  return true;
}

void hex_scaled_jacobian_samples(const HexCorners& p, std::array<double, 9>& out) {
  const std::array<Eigen::Vector3d, 12> edges = hex_edge_vectors(p);
  std::array<double, 12> lengths;
  for (int e = 0; e < 12; ++e) lengths[e] = edges[e].norm();
  for (int v = 0; v < 8; ++v) out[v] = corner_scaled_determinant(edges, lengths, v);
  out[8] = scaled_determinant(centre_jacobian(edges));
}

double hex_scaled_jacobian(const HexCorners& p) {
  const std::array<Eigen::Vector3d, 12> edges = hex_edge_vectors(p);
  std::array<double, 12> lengths;
  for (int e = 0; e < 12; ++e) lengths[e] = edges[e].norm();
  double best = scaled_determinant(centre_jacobian(edges));
  for (int v = 0; v < 8; ++v) best = std::min(best, corner_scaled_determinant(edges, lengths, v));
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
  // per direction (exact to degree 3) integrates it exactly; at each point J's columns are the
  // edge vectors of their axis weighted bilinearly.
  const std::array<Eigen::Vector3d, 12> edges = hex_edge_vectors(p);
  double volume = 0.0;
  for (int q = 0; q < 8; ++q) {
    Eigen::Matrix3d jacobian = Eigen::Matrix3d::Zero();
    for (int k = 0; k < 3; ++k)
      for (int e : hex_axis_edges[k]) jacobian.col(k) += gauss_edge_weights.w[q][e] * edges[e];
    volume += jacobian.determinant();
  }
  return volume / 8.0;  // each Gauss weight is 1/8 on the unit cube
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
