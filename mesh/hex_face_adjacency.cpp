#include "mesh/hex_face_adjacency.hpp"

#include <algorithm>
#include <memory>
#include <string>

#include "mesh/error.hpp"
#include "mesh/hex_convention.hpp"
#include "mesh/parallel.hpp"

namespace hexrefine {

namespace {

int32_t face_lowest_node(const HexCell& c, int lf) {
  const int* fv = hex_faces[lf];
  return std::min(std::min(c[fv[0]], c[fv[1]]), std::min(c[fv[2]], c[fv[3]]));
}

/// The three nodes of local face lf other than its lowest, ascending: with the lowest node (the
/// bucket) they identify the face's node set. A five-comparator sorting network of min and max
/// (no branch to mispredict: the lowest node's place in the face is arbitrary) sorts all four;
/// the lowest comes first.
std::array<int32_t, 3> face_other_nodes(const HexCell& c, int lf) {
  const int* fv = hex_faces[lf];
  int32_t a = c[fv[0]], b = c[fv[1]], d = c[fv[2]], e = c[fv[3]];
  auto order = [](int32_t& x, int32_t& y) {
    const int32_t lo = std::min(x, y), hi = std::max(x, y);
    x = lo;
    y = hi;
  };
  order(a, b);
  order(d, e);
  order(a, d);
  order(b, e);
  order(b, d);
  return {b, d, e};
}

/// The sorted node set of local face lf of c.
std::array<int32_t, 4> face_node_set(const HexCell& c, int lf) {
  std::array<int32_t, 4> q{};
  for (int i = 0; i < 4; ++i) q[i] = c[hex_faces[lf][i]];
  std::sort(q.begin(), q.end());
  return q;
}

/// Whether hexes a and b share two or more faces and la is the lowest local face of a among them
/// (the slow half of faces_make_doublet, out of line so the fast half inlines).
[[gnu::noinline]] bool faces_share_another_face(const HexCell& a, int la, const HexCell& b) {
  std::array<std::array<int32_t, 4>, 6> faces_b;
  for (int f = 0; f < 6; ++f) faces_b[f] = face_node_set(b, f);
  int lowest_shared = -1, shared = 0;
  for (int f = 0; f < 6; ++f) {
    const std::array<int32_t, 4> q = face_node_set(a, f);
    if (std::find(faces_b.begin(), faces_b.end(), q) == faces_b.end()) continue;
    if (lowest_shared < 0) lowest_shared = f;
    ++shared;
  }
  return shared >= 2 && lowest_shared == la;
}

/// Whether hexes a and b, which share their local faces la and lb (as node sets), form a doublet
/// counted at that face: they share another face too, and la is the lowest local face of a that
/// they share. A second shared face holds two nodes of each hex outside the first (an edge of
/// it, or all four when it is the opposite face), so the hexes' faces opposite la and lb have a
/// node in common; that test, 16 comparisons in four vector compares of b's four nodes rotated
/// against a's, settles almost every face (it runs once per interior face).
bool faces_make_doublet(const HexCell& a, int la, const HexCell& b, int lb) {
  using Four = int32_t __attribute__((vector_size(16)));
  const int* oa = hex_faces[hex_opposite_face[la]];
  const int* ob = hex_faces[hex_opposite_face[lb]];
  const Four x = {a[oa[0]], a[oa[1]], a[oa[2]], a[oa[3]]};
  const Four y = {b[ob[0]], b[ob[1]], b[ob[2]], b[ob[3]]};
  const Four equal = (x == y) | (x == __builtin_shufflevector(y, y, 1, 2, 3, 0)) |
                     (x == __builtin_shufflevector(y, y, 2, 3, 0, 1)) |
                     (x == __builtin_shufflevector(y, y, 3, 0, 1, 2));
  if ((equal[0] | equal[1] | equal[2] | equal[3]) == 0) return false;
  return faces_share_another_face(a, la, b);
}

}  // namespace

HexFaceAdjacency hex_face_adjacency_build(const HexMesh& mesh, int threads, bool neighbors) {
  const int32_t hexes = mesh.hex_count();
  if (hexes > hex_face_adjacency_max_hexes)
    throw OperationError("the mesh has " + std::to_string(hexes) +
                         " hexes; face matching handles at most " +
                         std::to_string(hex_face_adjacency_max_hexes));
  const int32_t nodes = mesh.point_count();

  // Counting sort of the slots by lowest node, over `parts` contiguous hex ranges at once: each
  // range counts its faces per node, a prefix over (node, range) gives each range its place in
  // every bucket, and each range scatters its slots there. The slots of a bucket stay in hex
  // order, so the array is the same for any thread count. offsets[p][a] first counts, then holds
  // where range p's part of node a's bucket starts, and after the scatter where it ends: the last
  // range's ends are the buckets' ends. Each range holds a count per node, so at most four
  // (the counts of four ranges weigh about half the hexes themselves).
  const int parts =
      static_cast<int>(std::clamp<int64_t>(threads, 1, std::clamp<int64_t>(hexes / 4096, 1, 4)));
  auto part_begin = [&](int p) { return static_cast<int32_t>(int64_t{hexes} * p / parts); };
  std::vector<std::vector<uint32_t>> offsets(static_cast<size_t>(parts));
  parallel_chunks(parts, parts, 1, [&](int64_t p, int64_t, int64_t) {
    std::vector<uint32_t>& count = offsets[p];
    count.assign(static_cast<size_t>(nodes), 0);
    for (int32_t h = part_begin(static_cast<int>(p)); h < part_begin(static_cast<int>(p) + 1); ++h)
      for (int lf = 0; lf < 6; ++lf) ++count[face_lowest_node(mesh.hexes[h], lf)];
  });
  uint32_t running = 0;
  for (int32_t node = 0; node < nodes; ++node)
    for (int p = 0; p < parts; ++p) {
      const uint32_t count = offsets[p][node];
      offsets[p][node] = running;
      running += count;
    }
  // Left uninitialised: the scatter writes every entry, so its threads, not a serial zero fill,
  // are the first to touch these pages (24 bytes per hex, the largest array of the checker).
  std::unique_ptr<uint32_t[]> slots(new uint32_t[running]);
  parallel_chunks(parts, parts, 1, [&](int64_t p, int64_t, int64_t) {
    std::vector<uint32_t>& cursor = offsets[p];
    for (int32_t h = part_begin(static_cast<int>(p)); h < part_begin(static_cast<int>(p) + 1); ++h)
      for (int lf = 0; lf < 6; ++lf)
        slots[cursor[face_lowest_node(mesh.hexes[h], lf)]++] = static_cast<uint32_t>(h) * 6 + lf;
  });
  const std::vector<uint32_t> bucket_end = std::move(offsets.back());
  offsets.clear();

  HexFaceAdjacency a;
  if (neighbors) a.hex_neighbors.resize(static_cast<size_t>(hexes));
  // Node ranges are matched independently; their boundary and non-manifold faces are
  // concatenated in range order, which is the sequential order.
  constexpr int64_t chunk_nodes = 1 << 15;
  constexpr int64_t prefetch_distance = 4;
  const int64_t chunks = parallel_chunk_count(nodes, chunk_nodes);
  std::vector<std::vector<HexFaceSlot>> boundary(static_cast<size_t>(chunks));
  std::vector<std::vector<HexFaceSlot>> nonmanifold(static_cast<size_t>(chunks));
  std::vector<std::vector<int32_t>> doublets(static_cast<size_t>(chunks));
  parallel_chunks(threads, nodes, chunk_nodes, [&](int64_t chunk, int64_t begin, int64_t end) {
    struct SlotKey {
      std::array<int32_t, 3> others;
      uint32_t slot;
      bool matched;
    };
    std::vector<SlotKey> keys;
    for (int64_t node = begin; node < end; ++node) {
      const uint32_t first = node == 0 ? 0 : bucket_end[node - 1];
      // The hexes of a bucket are scattered over the mesh: fetching those of a bucket a few
      // nodes ahead hides most of the cache misses.
      if (node + prefetch_distance < end)
        for (uint32_t k = bucket_end[node + prefetch_distance - 1];
             k < bucket_end[node + prefetch_distance]; ++k) {
          __builtin_prefetch(&mesh.hexes[slots[k] / 6]);
          if (neighbors) __builtin_prefetch(&a.hex_neighbors[slots[k] / 6], 1);
        }
      keys.clear();
      for (uint32_t k = first; k < bucket_end[node]; ++k) {
        const uint32_t s = slots[k];
        keys.push_back({face_other_nodes(mesh.hexes[s / 6], static_cast<int>(s % 6)), s, false});
      }
      // Buckets hold a handful of slots (6 on average), so a quadratic match beats sorting and
      // keeps the slots, hence the faces, in ascending order.
      for (size_t i = 0; i < keys.size(); ++i) {
        if (keys[i].matched) continue;
        const int32_t h0 = static_cast<int32_t>(keys[i].slot / 6);
        int32_t h1 = -1, users = 1;
        uint32_t second_slot = 0;
        for (size_t j = i + 1; j < keys.size(); ++j) {
          if (keys[j].matched || keys[j].others[0] != keys[i].others[0] ||
              keys[j].others[1] != keys[i].others[1] || keys[j].others[2] != keys[i].others[2])
            continue;
          keys[j].matched = true;
          const int32_t h = static_cast<int32_t>(keys[j].slot / 6);
          if (neighbors) a.hex_neighbors[h][keys[j].slot % 6] = h0;
          if (++users == 2) {
            h1 = h;
            second_slot = keys[j].slot;
          }
        }
        if (neighbors) a.hex_neighbors[h0][keys[i].slot % 6] = h1;
        if (h1 >= 0 && h1 != h0 &&
            faces_make_doublet(mesh.hexes[h0], static_cast<int>(keys[i].slot % 6), mesh.hexes[h1],
                               static_cast<int>(second_slot % 6)))
          doublets[chunk].push_back(h0);
        if (users == 1)
          boundary[chunk].push_back({h0, static_cast<int32_t>(keys[i].slot % 6)});
        else if (users > 2)
          nonmanifold[chunk].push_back({h0, static_cast<int32_t>(keys[i].slot % 6)});
      }
    }
  });
  slots.reset();
  for (int64_t c = 0; c < chunks; ++c) {
    a.boundary_faces.insert(a.boundary_faces.end(), boundary[c].begin(), boundary[c].end());
    a.nonmanifold_faces.insert(a.nonmanifold_faces.end(), nonmanifold[c].begin(),
                               nonmanifold[c].end());
    a.doublets.insert(a.doublets.end(), doublets[c].begin(), doublets[c].end());
  }
  std::sort(a.doublets.begin(), a.doublets.end());
  return a;
}

}  // namespace hexrefine
