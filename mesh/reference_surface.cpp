/// \file
/// The reference surface and the checker's face test (reference_surface.hpp).

#include "mesh/reference_surface.hpp"

#include <cmath>
#include <numbers>

#include "mesh/conformity.hpp"
#include "mesh/hex_convention.hpp"
#include "mesh/hex_face_adjacency.hpp"
#include "mesh/parallel.hpp"

namespace hexrefine {

ReferenceSurface::ReferenceSurface(const HexMesh& reference, int threads) {
  const std::vector<HexFaceSlot> slots =
      hex_face_adjacency_build(reference, threads, false).boundary_faces;
  quads_.resize(slots.size());
  tolerances_.resize(slots.size());
  parallel_chunks(threads, static_cast<int64_t>(slots.size()), 1 << 12,
                  [&](int64_t, int64_t begin, int64_t end) {
                    for (int64_t i = begin; i < end; ++i) {
                      const HexCell& c = reference.hexes[slots[i].hex];
                      const int* fv = hex_faces[slots[i].local_face];
                      quads_[i] = {reference.points[c[fv[0]]], reference.points[c[fv[1]]],
                                   reference.points[c[fv[2]]], reference.points[c[fv[3]]]};
                      tolerances_[i] = mesh_check_surface_tolerance * quad_diameter(quads_[i]) +
                                       quad_warp(quads_[i]);
                    }
                  });
  grid_ = std::make_unique<QuadGrid>(quads_, tolerances_);
}

namespace {

/// The "across" half of reference_surface_holds_face.
bool face_lies_across_reference(const Quad& q, const ReferenceSurface& reference) {
  const Eigen::Vector3d normal = quad_unit_normal(q);
  if (normal.isZero()) return false;
  const double cos_limit = std::cos(mesh_check_across_angle_degrees * std::numbers::pi / 180);
  const QuadGrid& grid = reference.grid();
  for (int k = 0; k < 4; ++k) {
    const bool found = grid.find(q[k], [&](int32_t j) {
      return std::abs(quad_unit_normal(reference.quads()[j]).dot(normal)) >= cos_limit;
    });
    if (!found) return false;
  }
  // The centroid may lie over a reference face none of the corners is on (a corner slid into a
  // diagonal neighbour): the faces near it are those of its grid cell and of its corners' cells.
  const Eigen::Vector3d centroid = (q[0] + q[1] + q[2] + q[3]) / 4.0;
  const double chord = mesh_check_across_chord * quad_diameter(q);
  const auto near = [&](int32_t j) {
    return quad_within(reference.quads()[j], centroid, reference.tolerances()[j] + chord);
  };
  if (grid.visit_cell(centroid, near)) return true;
  for (const Eigen::Vector3d& c : q)
    if (grid.visit_cell(c, near)) return true;
  return false;
}

}  // namespace

bool reference_surface_holds_face(const ReferenceSurface& reference, const Quad& q) {
  const Eigen::Vector3d centroid = (q[0] + q[1] + q[2] + q[3]) / 4.0;
  const bool on_one_face = reference.grid().find(centroid, [&](int32_t j) {
    for (const Eigen::Vector3d& c : q)
      if (!quad_within(reference.quads()[j], c, reference.tolerances()[j])) return false;
    return true;
  });
  return on_one_face || face_lies_across_reference(q, reference);
}

}  // namespace hexrefine
