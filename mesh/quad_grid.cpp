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
  // Mean face size keeps a few quads per cell; the floor keeps cell indices within 20 bits.
  const double extent = (hi - lo).maxCoeff();
  cell_ = std::max({diameter_sum / static_cast<double>(quads.size()), extent / double(1 << 19),
                    std::numeric_limits<double>::min() * 1e10});
  std::vector<int32_t> counts;
  box_lo_.resize(quads.size());
  box_hi_.resize(quads.size());
  for (int pass = 0; pass < 2; ++pass) {
    for (size_t i = 0; i < quads.size(); ++i) {
      Eigen::Vector3d qlo = quads[i][0], qhi = quads[i][0];
      for (const Eigen::Vector3d& c : quads[i]) {
        qlo = qlo.cwiseMin(c);
        qhi = qhi.cwiseMax(c);
      }
      const Eigen::Vector3d grow = Eigen::Vector3d::Constant(tolerances[i]);
      // find()'s box test: a little wider than the tolerance, so that rounding in
      // quad_within never makes it refuse a quad the test would accept.
      // Rounding grows with the coordinates too (meshes far from the origin).
      const double magnitude = std::max(qlo.cwiseAbs().maxCoeff(), qhi.cwiseAbs().maxCoeff());
      const Eigen::Vector3d margin =
          grow + Eigen::Vector3d::Constant(1e-9 * (tolerances[i] + (qhi - qlo).maxCoeff()) +
                                           1e-12 * magnitude);
      box_lo_[i] = qlo - margin;
      box_hi_[i] = qhi + margin;
      const auto a = cell_of(qlo - grow), b = cell_of(qhi + grow);
      for (int64_t z = a[2]; z <= b[2]; ++z)
        for (int64_t y = a[1]; y <= b[1]; ++y)
          for (int64_t x = a[0]; x <= b[0]; ++x) {
            const uint64_t key = pack({x, y, z});
            if (pass == 0) {
              const auto [it, added] =
                  bucket_of_cell_.try_emplace(key, static_cast<int32_t>(counts.size()));
              if (added) counts.push_back(0);
              ++counts[it->second];
            } else {
              items_[fill_[bucket_of_cell_.at(key)]++] = static_cast<int32_t>(i);
            }
          }
    }
    if (pass == 0) {
      offsets_.assign(counts.size() + 1, 0);
      std::partial_sum(counts.begin(), counts.end(), offsets_.begin() + 1);
      items_.resize(offsets_.back());
      fill_.assign(offsets_.begin(), offsets_.end() - 1);
    }
  }
}

}  // namespace hexrefine
