#include "algorithms/pipeline/pipeline_children.hpp"

#include <algorithm>
#include <atomic>

#include "mesh/parallel.hpp"
#include "mesh/quality.hpp"

namespace hexrefine {

RefinedChildren refined_children_find(const HexMesh& input, const HexMesh& mesh, int threads) {
  RefinedChildren c;
  const std::vector<int32_t>* parent = mesh_find_attribute(mesh, attribute_parent_hex);
  const std::vector<int32_t>* level = mesh_find_attribute(mesh, attribute_refinement_level);
  const std::vector<int32_t>* input_level = mesh_find_attribute(input, attribute_refinement_level);
  // Both passes over the output on every thread (a parent marked by two threads gets the same 1
  // from each).
  constexpr int64_t chunk_hexes = 1 << 16;
  std::vector<uint8_t> refined(input.hexes.size(), 0);
  if (parent && level)
    parallel_chunks(threads, mesh.hex_count(), chunk_hexes, [&](int64_t, int64_t b, int64_t e) {
      for (int64_t h = b; h < e; ++h) {
        const int32_t p = (*parent)[h];
        if ((*level)[h] > (input_level ? (*input_level)[p] : 0))
          std::atomic_ref<uint8_t>(refined[p]).store(1, std::memory_order_relaxed);
      }
    });
  for (int32_t h = 0; h < input.hex_count(); ++h)
    if (refined[h]) {
      ++c.parents;
      c.parents_min_scaled_jacobian =
          std::min(c.parents_min_scaled_jacobian, hex_scaled_jacobian(hex_points(input, h)));
    }
  c.is_child.resize(mesh.hexes.size(), 0);
  if (parent && level) {
    std::vector<int64_t> chunk_children(
        static_cast<size_t>(parallel_chunk_count(mesh.hex_count(), chunk_hexes)), 0);
    parallel_chunks(threads, mesh.hex_count(), chunk_hexes,
                    [&](int64_t chunk, int64_t b, int64_t e) {
                      for (int64_t h = b; h < e; ++h)
                        chunk_children[chunk] += c.is_child[h] = refined[(*parent)[h]];
                    });
    for (int64_t n : chunk_children) c.children += n;
  }
  return c;
}

double refined_children_min_scaled_jacobian(const RefinedChildren& children, const HexMesh& mesh,
                                            const MeshCheckReport& check) {
  if (children.children == mesh.hex_count()) return check.min_scaled_jacobian;
  double m = 1;
  for (int32_t h = 0; h < mesh.hex_count(); ++h)
    if (children.is_child[h]) m = std::min(m, hex_scaled_jacobian(hex_points(mesh, h)));
  return m;
}

void pipeline_children(PipelineRun& run, SmoothingStart& start) {
  run.clock.begin("check");
  start.children = refined_children_find(run.input, start.mesh, run.options.refine.threads);
}

}  // namespace hexrefine
