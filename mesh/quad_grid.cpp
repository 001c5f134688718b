#include "mesh/quad_grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace hexrefine {

QuadGrid::QuadGrid(const std::vector<Quad>& quads, const std::vector<double>& tolerances)
    : quads_(quads), tolerances_(tolerances) {
  if (quads.empty()) return;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  double diameter_sum = 0.0;
  for (size_t i = 0; i < quads.size(); ++i) {
    for (const Eigen::Vector3d& c : quads[i]) {
      lo = lo.cwiseMin(c - Eigen::Vector3d::Constant(tolerances[i]));
      hi = hi.cwiseMax(c + Eigen::Vector3d::Constant(tolerances[i]));
    }
    diameter_sum += quad_diameter(quads[i]);
  }
  origin_ = lo;
  // Twice the mean face size: a handful of quads per cell and few cells per quad (fewer cells to
  // find in the table than with the mean size, a few more box tests per query); the floor keeps
  // cell indices within 20 bits.
  const double extent = (hi - lo).maxCoeff();
  cell_ = std::max({2.0 * diameter_sum / static_cast<double>(quads.size()),
                    extent / double(1 << 19), std::numeric_limits<double>::min() * 1e10});
  // The cells of each quad's box (grown by its tolerance), and find()'s box test: a little wider
  // than the tolerance, so that rounding in quad_within never makes it refuse a quad the test
  // would accept (rounding grows with the coordinates too: meshes far from the origin).
  box_lo_.resize(quads.size());
  box_hi_.resize(quads.size());
  std::vector<std::array<int64_t, 6>> ranges(quads.size());
  size_t registrations = 0;
  for (size_t i = 0; i < quads.size(); ++i) {
    Eigen::Vector3d qlo = quads[i][0], qhi = quads[i][0];
    for (const Eigen::Vector3d& c : quads[i]) {
      qlo = qlo.cwiseMin(c);
      qhi = qhi.cwiseMax(c);
    }
    const Eigen::Vector3d grow = Eigen::Vector3d::Constant(tolerances[i]);
    const double magnitude = std::max(qlo.cwiseAbs().maxCoeff(), qhi.cwiseAbs().maxCoeff());
    const Eigen::Vector3d margin =
        grow + Eigen::Vector3d::Constant(1e-9 * (tolerances[i] + (qhi - qlo).maxCoeff()) +
                                         1e-12 * magnitude);
    box_lo_[i] = qlo - margin;
    box_hi_[i] = qhi + margin;
    const auto a = cell_of(qlo - grow), b = cell_of(qhi + grow);
    ranges[i] = {a[0], a[1], a[2], b[0], b[1], b[2]};
    registrations += static_cast<size_t>((b[0] - a[0] + 1) * (b[1] - a[1] + 1) * (b[2] - a[2] + 1));
  }
  // The table at most half full even if every registration is a cell of its own.
  int bits = 4;
  while ((size_t{1} << bits) < 2 * registrations && bits < 40) ++bits;
  table_keys_.assign(size_t{1} << bits, empty_key);
  table_buckets_.assign(table_keys_.size(), -1);
  shift_ = 64 - bits;
  // Each registration's bucket, found once; then a counting sort of the registrations by bucket
  // (quads ascending within a bucket).
  std::vector<int32_t> counts, bucket_of_registration(registrations);
  size_t r = 0;
  for (size_t i = 0; i < quads.size(); ++i) {
    const std::array<int64_t, 6>& c = ranges[i];
    for (int64_t z = c[2]; z <= c[5]; ++z)
      for (int64_t y = c[1]; y <= c[4]; ++y)
        for (int64_t x = c[0]; x <= c[3]; ++x) {
          const int32_t bucket =
              bucket_insert(pack({x, y, z}), static_cast<int32_t>(counts.size()));
          if (bucket == static_cast<int32_t>(counts.size())) counts.push_back(0);
          ++counts[bucket];
          bucket_of_registration[r++] = bucket;
        }
  }
  offsets_.assign(counts.size() + 1, 0);
  std::partial_sum(counts.begin(), counts.end(), offsets_.begin() + 1);
  items_.resize(offsets_.back());
  fill_.assign(offsets_.begin(), offsets_.end() - 1);
  r = 0;
  for (size_t i = 0; i < quads.size(); ++i) {
    const std::array<int64_t, 6>& c = ranges[i];
    const size_t cells =
        static_cast<size_t>((c[3] - c[0] + 1) * (c[4] - c[1] + 1) * (c[5] - c[2] + 1));
    for (size_t k = 0; k < cells; ++k)
      items_[fill_[bucket_of_registration[r++]]++] = static_cast<int32_t>(i);
  }
  fill_ = {};
}

int32_t QuadGrid::bucket_insert(uint64_t key, int32_t next) {
  size_t slot = slot_of(key);
  if (table_keys_[slot] == key) return table_buckets_[slot];
  if (2 * (static_cast<size_t>(next) + 1) > table_keys_.size()) {
    std::vector<uint64_t> keys(2 * table_keys_.size(), empty_key);
    std::vector<int32_t> buckets(keys.size(), -1);
    keys.swap(table_keys_);
    buckets.swap(table_buckets_);
    --shift_;
    for (size_t k = 0; k < keys.size(); ++k)
      if (keys[k] != empty_key) {
        const size_t s = slot_of(keys[k]);
        table_keys_[s] = keys[k];
        table_buckets_[s] = buckets[k];
      }
    slot = slot_of(key);
  }
  table_keys_[slot] = key;
  table_buckets_[slot] = next;
  return next;
}

}  // namespace hexrefine
