#include "mesh/worst_hexes.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <utility>

#include "mesh/hex_face_adjacency.hpp"
#include "mesh/parallel.hpp"
#include "mesh/quality.hpp"

namespace hexrefine {

std::vector<WorstHex> mesh_worst_hexes(const HexMesh& mesh, int count, int threads) {
  const int64_t hexes = mesh.hex_count();
  const size_t keep = static_cast<size_t>(std::min<int64_t>(std::max(count, 0), hexes));
  if (keep == 0) return {};
  // Each chunk keeps its `keep` lowest (value, id) pairs; the union of the chunks' lowest holds
  // the overall lowest, and (value, id) is a total order, so the result is the same for any
  // thread count.
  using Entry = std::pair<double, int32_t>;
  constexpr int64_t chunk_hexes = 1 << 14;
  std::vector<std::vector<Entry>> lowest(
      static_cast<size_t>(parallel_chunk_count(hexes, chunk_hexes)));
  parallel_chunks(threads, hexes, chunk_hexes, [&](int64_t chunk, int64_t begin, int64_t end) {
    std::vector<Entry>& mine = lowest[chunk];
    constexpr int64_t block = 256;
    std::array<double, block> values;
    for (int64_t first = begin; first < end; first += block) {
      const size_t n = static_cast<size_t>(std::min(block, end - first));
      mesh_scaled_jacobians(mesh, static_cast<int32_t>(first), std::span<double>(values.data(), n));
      for (size_t k = 0; k < n; ++k)  // NaN (never from valid corners) as -1: a total order
        mine.emplace_back(std::isnan(values[k]) ? -1.0 : values[k],
                          static_cast<int32_t>(first + static_cast<int64_t>(k)));
      if (mine.size() > 2 * keep + block) {  // trimmed now and then: linear in the chunk
        std::nth_element(mine.begin(), mine.begin() + static_cast<std::ptrdiff_t>(keep),
                         mine.end());
        mine.resize(keep);
      }
    }
  });
  std::vector<Entry> all;
  for (const std::vector<Entry>& mine : lowest) all.insert(all.end(), mine.begin(), mine.end());
  std::partial_sort(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(keep), all.end());
  all.resize(keep);

  std::vector<WorstHex> worst(keep);
  for (size_t k = 0; k < keep; ++k) worst[k] = {all[k].second, all[k].first, 0};
  // Boundary faces of the listed hexes: a few, so each boundary slot looks them up in a sorted
  // copy of their ids.
  std::vector<std::pair<int32_t, size_t>> by_id(keep);
  for (size_t k = 0; k < keep; ++k) by_id[k] = {worst[k].hex, k};
  std::sort(by_id.begin(), by_id.end());
  for (const HexFaceSlot& slot : hex_face_adjacency_build(mesh, threads, false).boundary_faces) {
    const auto it = std::lower_bound(by_id.begin(), by_id.end(), std::pair{slot.hex, size_t{0}});
    if (it != by_id.end() && it->first == slot.hex) ++worst[it->second].boundary_faces;
  }
  return worst;
}

}  // namespace hexrefine
