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
#include <vector>

#include "mesh/quad_patch.hpp"

namespace hexrefine {

/// Hash grid over quads: each quad is listed in every cell its bounding box (grown by its
/// tolerance) overlaps, so a point query looks in one cell only. Cells are found in an
/// open-addressing table of their packed coordinates (linear probing, at most half full), and
/// a cell's quads are listed in ascending order.
class QuadGrid {
 public:
  /// Registers quads[i] grown by tolerances[i]; both vectors must outlive the grid.
  QuadGrid(const std::vector<Quad>& quads, const std::vector<double>& tolerances);

  /// Calls visit(quad index) for each quad registered in p's cell (its box, grown by its
  /// tolerance, overlaps the cell), until it returns true; returns whether one did.
  template <class Visit>
  bool visit_cell(const Eigen::Vector3d& p, Visit visit) const {
    const int32_t bucket = bucket_of(pack(cell_of(p)));
    if (bucket < 0) return false;
    for (int32_t k = offsets_[bucket]; k < offsets_[bucket + 1]; ++k)
      if (visit(items_[k])) return true;
    return false;
  }

  /// Calls visit(quad index) for each quad whose tolerance band contains p, until it returns true;
  /// returns whether one did.
  template <class Visit>
  bool find(const Eigen::Vector3d& p, Visit visit) const {
    const int32_t bucket = bucket_of(pack(cell_of(p)));
    if (bucket < 0) return false;
    for (int32_t k = offsets_[bucket]; k < offsets_[bucket + 1]; ++k) {
      const int32_t i = items_[k];
      // The patch lies in its corners' box: a point outside the box grown by the tolerance is
      // farther than the tolerance, and most quads of a cell are rejected without projecting.
      if (!box_contains(i, p)) continue;
      if (quad_within(quads_[i], p, tolerances_[i]) && visit(i)) return true;
    }
    return false;
  }

  /// Whether p lies in quad i's corners' box grown by a little more than its tolerance: false
  /// means p is farther than the tolerance from the patch.
  bool box_contains(int32_t i, const Eigen::Vector3d& p) const {
    return !((p.array() < box_lo_[i].array()).any() || (p.array() > box_hi_[i].array()).any());
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
  /// Slot of the table where `key` is or would go (pack gives 63 bits: ~0 marks an empty slot).
  size_t slot_of(uint64_t key) const {
    size_t slot = static_cast<size_t>((key * 0x9E3779B97F4A7C15ull) >> shift_);
    while (table_keys_[slot] != empty_key && table_keys_[slot] != key)
      slot = (slot + 1) & (table_keys_.size() - 1);
    return slot;
  }
  /// The bucket of the cell `key`, -1 if no quad is registered there.
  int32_t bucket_of(uint64_t key) const {
    if (table_keys_.empty()) return -1;
    const size_t slot = slot_of(key);
    return table_keys_[slot] == key ? table_buckets_[slot] : -1;
  }
  /// The bucket of the cell `key`; if it has none, `next` becomes its bucket (the table doubles
  /// when half full).
  int32_t bucket_insert(uint64_t key, int32_t next);

  static constexpr uint64_t empty_key = ~uint64_t{0};
  const std::vector<Quad>& quads_;
  const std::vector<double>& tolerances_;
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();
  double cell_ = 1.0;
  std::vector<uint64_t> table_keys_;    // open addressing, a power of two long
  std::vector<int32_t> table_buckets_;  // bucket of the cell in the same slot
  int shift_ = 64;                      // 64 - log2(table size)
  std::vector<int32_t> offsets_, items_, fill_;
  std::vector<Eigen::Vector3d> box_lo_, box_hi_;  // per quad: its corners' box, grown
};

}  // namespace hexrefine
