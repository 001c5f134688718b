#include "mesh/hex_face_adjacency.hpp"

#include <algorithm>
#include <cstring>
#include <memory>
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
/// against a's (each hex's four taken by one shuffle of its two halves), settles almost every
/// face (it runs once per interior face).
using Four = int32_t __attribute__((vector_size(16)));

/// The four nodes of c outside its local face lf (those of the opposite face, in some order),
/// from its two halves lo = c[0..3] and hi = c[4..7].
Four hex_nodes_off_face(const HexCell& c, int lf) {
  Four lo, hi;
  std::memcpy(&lo, c.data(), sizeof lo);
  std::memcpy(&hi, c.data() + 4, sizeof hi);
  switch (lf) {
    case 0:
      return __builtin_shufflevector(lo, hi, 1, 2, 5, 6);  // f1 {1,2,6,5}
    case 1:
      return __builtin_shufflevector(lo, hi, 0, 3, 4, 7);  // f0 {0,4,7,3}
    case 2:
      return __builtin_shufflevector(lo, hi, 2, 3, 6, 7);  // f3 {3,7,6,2}
    case 3:
      return __builtin_shufflevector(lo, hi, 0, 1, 4, 5);  // f2 {0,1,5,4}
    case 4:
      return hi;  // f5 {4,5,6,7}
    default:
      return lo;  // f4 {0,3,2,1}
  }
}

bool faces_make_doublet(const HexCell& a, int la, const HexCell& b, int lb) {
  const Four x = hex_nodes_off_face(a, la), y = hex_nodes_off_face(b, lb);
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
      for (const int32_t lowest : hex_face_lowest_nodes(mesh.hexes[h])) ++count[lowest];
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
    for (int32_t h = part_begin(static_cast<int>(p)); h < part_begin(static_cast<int>(p) + 1);
         ++h) {
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
    std::vector<SlotKey> spill;  // buckets of more than local_keys slots
    std::vector<HexFaceSlot>& boundary_out = boundary[chunk];
    std::vector<HexFaceSlot>& nonmanifold_out = nonmanifold[chunk];
    // The faces of one bucket are found in key order; in the lists they go in slot order.
    auto slot_order = [](std::vector<HexFaceSlot>& list, size_t from) {
      for (size_t i = from + 1; i < list.size(); ++i) {
        const HexFaceSlot x = list[i];
        size_t j = i;
        for (; j > from && (x.hex < list[j - 1].hex ||
                            (x.hex == list[j - 1].hex && x.local_face < list[j - 1].local_face));
             --j)
          list[j] = list[j - 1];
        list[j] = x;
      }
    };
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
      // Equal faces next to each other, each face's slots ascending: an insertion sort (buckets
      // hold a handful of slots, 6 on average, 24 at most in a refined brick).
      auto before = [](const SlotKey& x, const SlotKey& y) {
        return x.low != y.low     ? x.low < y.low
               : x.high != y.high ? x.high < y.high
                                  : x.slot < y.slot;
      };
      if (count > local_keys) {
        std::sort(keys, keys + count, before);
      } else {
        for (uint32_t i = 1; i < count; ++i) {
          const SlotKey x = keys[i];
          uint32_t j = i;
          for (; j > 0 && before(x, keys[j - 1]); --j) keys[j] = keys[j - 1];
          keys[j] = x;
        }
      }
      const size_t boundary_from = boundary_out.size(), nonmanifold_from = nonmanifold_out.size();
      for (uint32_t i = 0; i < count;) {
        uint32_t j = i + 1;
        while (j < count && keys[j].low == keys[i].low && keys[j].high == keys[i].high) ++j;
        const int32_t h0 = static_cast<int32_t>(keys[i].slot / 6);
        const int lf0 = static_cast<int>(keys[i].slot % 6);
        const int32_t h1 = j - i > 1 ? static_cast<int32_t>(keys[i + 1].slot / 6) : -1;
        if (neighbors) {
          a.hex_neighbors[h0][lf0] = h1;
          for (uint32_t k = i + 1; k < j; ++k)
            a.hex_neighbors[keys[k].slot / 6][keys[k].slot % 6] = h0;
        }
        if (h1 < 0) {
          boundary_out.push_back({h0, lf0});
        } else {
          if (h1 != h0 && faces_make_doublet(mesh.hexes[h0], lf0, mesh.hexes[h1],
                                             static_cast<int>(keys[i + 1].slot % 6)))
            doublets[chunk].push_back(h0);
          if (j - i > 2) nonmanifold_out.push_back({h0, lf0});
        }
        i = j;
      }
      slot_order(boundary_out, boundary_from);
      slot_order(nonmanifold_out, nonmanifold_from);
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
