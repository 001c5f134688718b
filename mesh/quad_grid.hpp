#pragma once
/// \file
/// A hash grid over quads (bilinear patches, mesh/quad_patch.hpp) for point queries: which
/// quads lie within their tolerance of a point. The checker asks it whether a face's corners and
/// centroid lie on the reference's boundary, and which nodes hang on a non-conformal face.

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "mesh/quad_patch.hpp"

namespace hexrefine {

/// Hash grid over quads: each quad is listed in every cell its bounding box (grown by its
/// tolerance) overlaps, so a point query looks in one cell only.
class QuadGrid {
 public:
  /// Registers quads[i] grown by tolerances[i]; both vectors must outlive the grid.
  QuadGrid(const std::vector<Quad>& quads, const std::vector<double>& tolerances);

  /// Calls visit(quad index) for each quad registered in p's cell (its box, grown by its
  /// tolerance, overlaps the cell), until it returns true; returns whether one did.
  template <class Visit>
  bool visit_cell(const Eigen::Vector3d& p, Visit visit) const {
    if (offsets_.empty()) return false;
    const auto it = bucket_of_cell_.find(pack(cell_of(p)));
    if (it == bucket_of_cell_.end()) return false;
    for (int32_t k = offsets_[it->second]; k < offsets_[it->second + 1]; ++k)
      if (visit(items_[k])) return true;
    return false;
  }

  /// Calls visit(quad index) for each quad whose tolerance band contains p, until it returns true;
  /// returns whether one did.
  template <class Visit>
  bool find(const Eigen::Vector3d& p, Visit visit) const {
    if (offsets_.empty()) return false;
    const auto it = bucket_of_cell_.find(pack(cell_of(p)));
    if (it == bucket_of_cell_.end()) return false;
    for (int32_t k = offsets_[it->second]; k < offsets_[it->second + 1]; ++k) {
      const int32_t i = items_[k];
      // The patch lies in its corners' box: a point outside the box grown by the tolerance is
      // farther than the tolerance, and most quads of a cell are rejected without projecting.
      if ((p.array() < box_lo_[i].array()).any() || (p.array() > box_hi_[i].array()).any())
        continue;
      if (quad_within(quads_[i], p, tolerances_[i]) && visit(i)) return true;
    }
    return false;
  }

 private:
  std::array<int64_t, 3> cell_of(const Eigen::Vector3d& p) const {
    std::array<int64_t, 3> c;
    for (int k = 0; k < 3; ++k) {
      const double x = std::floor((p[k] - origin_[k]) / cell_);
      c[k] = static_cast<int64_t>(std::clamp(x, -2.0, double(1 << 20)));
    }
    return c;
  }
  static uint64_t pack(const std::array<int64_t, 3>& c) {
    uint64_t key = 0;
    for (int k = 0; k < 3; ++k) key = (key << 21) | (static_cast<uint64_t>(c[k] + 2) & 0x1FFFFF);
    return key;
  }

  const std::vector<Quad>& quads_;
  const std::vector<double>& tolerances_;
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();
  double cell_ = 1.0;
  std::unordered_map<uint64_t, int32_t> bucket_of_cell_;
  std::vector<int32_t> offsets_, items_, fill_;
  std::vector<Eigen::Vector3d> box_lo_, box_hi_;  // per quad: its corners' box, grown
};

}  // namespace hexrefine
