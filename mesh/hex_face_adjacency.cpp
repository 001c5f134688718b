#include "mesh/hex_face_adjacency.hpp"

#include <algorithm>
#include <cstring>
#include <memory>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#include <string>

#include "mesh/error.hpp"
#include "mesh/hex_convention.hpp"
#include "mesh/parallel.hpp"

namespace hexrefine {

namespace {

/// The lowest node of each of the six local faces of c, from eight pairwise minima (each face's
/// four nodes are two of the pairs; hex_faces: f0 {0,4,7,3}, f1 {1,2,6,5}, f2 {0,1,5,4}, f3
/// {3,7,6,2}, f4 {0,3,2,1}, f5 {4,5,6,7}).
std::array<int32_t, 6> hex_face_lowest_nodes(const HexCell& c) {
  const int32_t m01 = std::min(c[0], c[1]), m23 = std::min(c[2], c[3]);
  const int32_t m45 = std::min(c[4], c[5]), m67 = std::min(c[6], c[7]);
  const int32_t m03 = std::min(c[0], c[3]), m12 = std::min(c[1], c[2]);
  const int32_t m47 = std::min(c[4], c[7]), m56 = std::min(c[5], c[6]);
  return {std::min(m03, m47), std::min(m12, m56), std::min(m01, m45),
          std::min(m23, m67), std::min(m01, m23), std::min(m45, m67)};
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
using Four = int32_t __attribute__((vector_size(16)));

/// Whether some lane of a comparison's result is set.
bool lanes_any(Four mask) {
#if defined(__SSE2__)
  return _mm_movemask_epi8(reinterpret_cast<__m128i>(mask)) != 0;
#else
  return (mask[0] | mask[1] | mask[2] | mask[3]) != 0;
#endif
}

bool faces_make_doublet(const HexCell& a, int la, const HexCell& b, int lb) {
  // The four nodes of each hex off the shared face: those of its opposite face, by a table (no
  // branch on the face: it varies from one face to the next).
  const int* oa = hex_faces[hex_opposite_face[la]];
  const int* ob = hex_faces[hex_opposite_face[lb]];
  const Four x = {a[oa[0]], a[oa[1]], a[oa[2]], a[oa[3]]};
  const Four y = {b[ob[0]], b[ob[1]], b[ob[2]], b[ob[3]]};
  const Four equal = (x == y) | (x == __builtin_shufflevector(y, y, 1, 2, 3, 0)) |
                     (x == __builtin_shufflevector(y, y, 2, 3, 0, 1)) |
                     (x == __builtin_shufflevector(y, y, 3, 0, 1, 2));
  if (!lanes_any(equal)) return false;
  return faces_share_another_face(a, la, b);
}

}  // namespace

uint32_t counting_sort_starts(std::vector<std::vector<uint32_t>>& counts, int threads) {
  if (counts.empty()) return 0;
  const int64_t buckets = static_cast<int64_t>(counts[0].size());
  constexpr int64_t block = 1 << 16;
  std::vector<uint32_t> block_start(static_cast<size_t>(parallel_chunk_count(buckets, block)) + 1,
                                    0);
  parallel_chunks(threads, buckets, block, [&](int64_t b, int64_t begin, int64_t end) {
    uint32_t total = 0;
    for (const std::vector<uint32_t>& part : counts)
      for (int64_t k = begin; k < end; ++k) total += part[k];
    block_start[b + 1] = total;
  });
  for (size_t b = 1; b < block_start.size(); ++b) block_start[b] += block_start[b - 1];
  parallel_chunks(threads, buckets, block, [&](int64_t b, int64_t begin, int64_t end) {
    uint32_t running = block_start[b];
    for (int64_t k = begin; k < end; ++k)
      for (std::vector<uint32_t>& part : counts) {
        const uint32_t count = part[k];
        part[k] = running;
        running += count;
      }
  });
  return block_start.back();
}

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
    const int32_t last = part_begin(static_cast<int>(p) + 1);
    for (int32_t h = part_begin(static_cast<int>(p)); h < last; ++h)
      for (const int32_t lowest : hex_face_lowest_nodes(mesh.hexes[h])) ++count[lowest];
  });
  const uint32_t running = counting_sort_starts(offsets, threads);
  // Left uninitialised: the scatter writes every entry, so its threads, not a serial zero fill,
  // are the first to touch these pages (24 bytes per hex, the largest array of the checker).
  std::unique_ptr<uint32_t[]> slots(new uint32_t[running]);
  parallel_chunks(parts, parts, 1, [&](int64_t p, int64_t, int64_t) {
    std::vector<uint32_t>& cursor = offsets[p];
    const int32_t last = part_begin(static_cast<int>(p) + 1);
    for (int32_t h = part_begin(static_cast<int>(p)); h < last; ++h) {
      const std::array<int32_t, 6> lowest = hex_face_lowest_nodes(mesh.hexes[h]);
      for (int lf = 0; lf < 6; ++lf)
        slots[cursor[lowest[lf]]++] = static_cast<uint32_t>(h) * 6 + lf;
    }
  });
  const std::vector<uint32_t> bucket_end = std::move(offsets.back());
  offsets.clear();

  HexFaceAdjacency a;
  if (neighbors) a.hex_neighbors.resize(static_cast<size_t>(hexes));
  // Node ranges are matched independently; their boundary and non-manifold faces are
  // concatenated in range order, which is the sequential order.
  constexpr int64_t chunk_nodes = 1 << 15;
  constexpr uint32_t prefetch_slots = 24;
  const int64_t chunks = parallel_chunk_count(nodes, chunk_nodes);
  std::vector<std::vector<HexFaceSlot>> boundary(static_cast<size_t>(chunks));
  std::vector<std::vector<HexFaceSlot>> nonmanifold(static_cast<size_t>(chunks));
  std::vector<std::vector<int32_t>> doublets(static_cast<size_t>(chunks));
  parallel_chunks(threads, nodes, chunk_nodes, [&](int64_t chunk, int64_t begin, int64_t end) {
    // A slot's other three nodes, b < d < e, as (b, d) in `low` and e in `high`.
    struct SlotKey {
      uint64_t low;
      uint32_t high, slot;
    };
    constexpr uint32_t local_keys = 64;
    SlotKey local[local_keys];
    std::vector<SlotKey> spill;    // buckets of more than local_keys slots
    std::vector<char> done_flags;  // and their matched flags
    std::vector<HexFaceSlot>& boundary_out = boundary[chunk];
    std::vector<HexFaceSlot>& nonmanifold_out = nonmanifold[chunk];
    const uint32_t chunk_last = bucket_end[end - 1];
    for (int64_t node = begin; node < end; ++node) {
      const uint32_t first = node == 0 ? 0 : bucket_end[node - 1];
      const uint32_t count = bucket_end[node] - first;
      if (count == 0) continue;
      SlotKey* keys = local;
      if (count > local_keys) {
        spill.resize(count);
        keys = spill.data();
      }
      for (uint32_t k = 0; k < count; ++k) {
        // The hexes of a bucket are scattered over the mesh: fetching the hex of a slot a few
        // buckets ahead hides most of the cache misses.
        if (first + k + prefetch_slots < chunk_last) {
          const uint32_t ahead = slots[first + k + prefetch_slots] / 6;
          __builtin_prefetch(&mesh.hexes[ahead]);
          if (neighbors) __builtin_prefetch(&a.hex_neighbors[ahead], 1);
        }
        const uint32_t s = slots[first + k];
        const std::array<int32_t, 3> o =
            face_other_nodes(mesh.hexes[s / 6], static_cast<int>(s % 6));
        keys[k] = {
            static_cast<uint64_t>(static_cast<uint32_t>(o[0])) << 32 | static_cast<uint32_t>(o[1]),
            static_cast<uint32_t>(o[2]), s};
      }
      // Buckets hold a handful of slots (6 on average, 24 at most in a refined brick): a
      // quadratic match, each slot against the later ones, finds each face at its lowest slot,
      // so the faces come out in slot order. `done` marks the slots already matched (a bitmask up
      // to 64 slots, flags beyond).
      uint64_t done = 0;
      if (count > 64) done_flags.assign(count, 0);
      auto is_done = [&](uint32_t k) {
        return count <= 64 ? (done >> k & 1) != 0 : done_flags[k] != 0;
      };
      for (uint32_t i = 0; i < count; ++i) {
        if (is_done(i)) continue;
        const SlotKey key = keys[i];
        int users = 1;
        uint32_t second = 0;
        for (uint32_t j = i + 1; j < count; ++j) {
          if (keys[j].low != key.low || keys[j].high != key.high || is_done(j)) continue;
          if (count <= 64)
            done |= uint64_t{1} << j;
          else
            done_flags[j] = 1;
          if (++users == 2) second = keys[j].slot;
          if (neighbors)
            a.hex_neighbors[keys[j].slot / 6][keys[j].slot % 6] =
                static_cast<int32_t>(key.slot / 6);
        }
        const int32_t h0 = static_cast<int32_t>(key.slot / 6);
        const int lf0 = static_cast<int>(key.slot % 6);
        const int32_t h1 = users > 1 ? static_cast<int32_t>(second / 6) : -1;
        if (neighbors) a.hex_neighbors[h0][lf0] = h1;
        if (h1 < 0) {
          boundary_out.push_back({h0, lf0});
        } else {
          if (h1 != h0 &&
              faces_make_doublet(mesh.hexes[h0], lf0, mesh.hexes[h1], static_cast<int>(second % 6)))
            doublets[chunk].push_back(h0);
          if (users > 2) nonmanifold_out.push_back({h0, lf0});
        }
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
