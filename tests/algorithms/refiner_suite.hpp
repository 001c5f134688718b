#pragma once
/// \file
/// Checks shared by the tests of both refiners: an output mesh is conformal (every face shared
/// by at most two hexes, every boundary face on the input's boundary) and valid (no inverted hex),
/// with its minimum scaled Jacobian. Uses only topology and geometry, so it runs before the
/// project's checker (mesh/conformity.hpp) is available; both must agree.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>

#include "algorithms/refiner.hpp"
#include "mesh/hex_convention.hpp"
#include "mesh/topology.hpp"

namespace hexrefine {

struct RefinerSuiteVerdict {
  int64_t nonmanifold_faces = 0;
  int64_t interior_boundary_faces = 0;  ///< boundary faces of the output not on the input boundary
  int64_t inverted_hexes = 0;
  int64_t doublets = 0;  ///< pairs of hexes sharing two or more faces
  double min_scaled_jacobian = 2.0;
  bool conformal() const { return nonmanifold_faces == 0 && interior_boundary_faces == 0; }
};

/// Scaled Jacobian of one hex (minimum over the 8 corners of the determinant of unit edges).
inline double refiner_suite_scaled_jacobian(const std::array<Eigen::Vector3d, 8>& x) {
  double out = 2.0;
  for (int v = 0; v < 8; ++v) {
    std::array<Eigen::Vector3d, 3> e;
    for (int k = 0; k < 3; ++k) {
      const int edge = hex_vertex_edges[v][k];
      const int w = hex_edges[edge][0] == v ? hex_edges[edge][1] : hex_edges[edge][0];
      e[k] = hex_corner[v][k] ? (x[v] - x[w]) : (x[w] - x[v]);
      if (e[k].norm() == 0) return -1;
      e[k].normalize();
    }
    out = std::min(out, e[0].dot(e[1].cross(e[2])));
  }
  return out;
}

/// `on_input_boundary(p)` says whether a point lies on the input's boundary surface.
inline RefinerSuiteVerdict refiner_suite_check(
    const HexMesh& out, const std::function<bool(const Eigen::Vector3d&)>& on_input_boundary) {
  RefinerSuiteVerdict v;
  const HexTopology t = topology_build(out);
  v.nonmanifold_faces = static_cast<int64_t>(t.nonmanifold_faces.size());
  for (int32_t f : topology_boundary_faces(t)) {
    bool ok = true;
    for (int32_t n : t.face_nodes[f]) ok = ok && on_input_boundary(out.points[n]);
    if (!ok) ++v.interior_boundary_faces;
  }
  for (int32_t h = 0; h < out.hex_count(); ++h) {
    const double sj = refiner_suite_scaled_jacobian(hex_points(out, h));
    if (!(sj > 0)) ++v.inverted_hexes;
    v.min_scaled_jacobian = std::min(v.min_scaled_jacobian, sj);
    // Doublets: a neighbour met through two faces.
    std::array<int32_t, 6> nb;
    for (int lf = 0; lf < 6; ++lf) nb[lf] = hex_face_neighbor(t, h, lf);
    for (int a = 0; a < 6; ++a)
      for (int b = a + 1; b < 6; ++b)
        if (nb[a] >= 0 && nb[a] == nb[b] && nb[a] > h) ++v.doublets;
  }
  return v;
}

/// Boundary test of an axis-aligned box [lo, hi].
inline std::function<bool(const Eigen::Vector3d&)> refiner_suite_box(const Eigen::Vector3d& lo,
                                                                     const Eigen::Vector3d& hi) {
  return [lo, hi](const Eigen::Vector3d& p) {
    for (int k = 0; k < 3; ++k)
      if (std::abs(p[k] - lo[k]) < 1e-9 || std::abs(p[k] - hi[k]) < 1e-9) return true;
    return false;
  };
}

}  // namespace hexrefine
