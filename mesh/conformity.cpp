#include "mesh/conformity.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <atomic>
#include <bit>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <numbers>
#include <numeric>
#include <optional>
#include <string>
#include <unordered_map>

#include "mesh/error.hpp"
#include "mesh/hex_convention.hpp"
#include "mesh/hex_face_adjacency.hpp"
#include "mesh/parallel.hpp"
#include "mesh/quad_grid.hpp"
#include "mesh/quad_patch.hpp"
#include "mesh/quality.hpp"
#include "mesh/reference_surface.hpp"

namespace hexrefine {

namespace {

/// Boundary surface of a mesh: its boundary face slots, their node ids (outward from their hex)
/// and positions.
struct BoundarySurface {
  std::vector<HexFaceSlot> slots;
  std::vector<std::array<int32_t, 4>> nodes;
  std::vector<Quad> quads;
  std::vector<double> tolerances;  ///< surface tolerance x diameter, per face
};

BoundarySurface boundary_surface(const HexMesh& mesh, std::vector<HexFaceSlot> slots,
                                 int threads = 1) {
  BoundarySurface s;
  s.slots = std::move(slots);
  const int64_t faces = static_cast<int64_t>(s.slots.size());
  s.nodes.resize(s.slots.size());
  s.quads.resize(s.slots.size());
  s.tolerances.resize(s.slots.size());
  parallel_chunks(threads, faces, 1 << 12, [&](int64_t, int64_t begin, int64_t end) {
    for (int64_t i = begin; i < end; ++i) {
      const HexCell& c = mesh.hexes[s.slots[i].hex];
      const int* fv = hex_faces[s.slots[i].local_face];
      const std::array<int32_t, 4> n = {c[fv[0]], c[fv[1]], c[fv[2]], c[fv[3]]};
      s.nodes[i] = n;
      s.quads[i] = {mesh.points[n[0]], mesh.points[n[1]], mesh.points[n[2]], mesh.points[n[3]]};
      // A point averaged from patch points (a sub-face centroid, a node placed by a template
      // whose footprint is not a parameter rectangle) can leave a warped patch by up to its warp.
      s.tolerances[i] =
          mesh_check_surface_tolerance * quad_diameter(s.quads[i]) + quad_warp(s.quads[i]);
    }
  });
  return s;
}

/// Indices of the faces of `surface` for which is_defect(index) holds, ascending; faces are
/// tested per chunk on up to `threads` threads.
template <class Test>
std::vector<int32_t> boundary_faces_where(int threads, const BoundarySurface& surface,
                                          Test is_defect) {
  constexpr int64_t chunk_faces = 1 << 12;
  const int64_t faces = static_cast<int64_t>(surface.quads.size());
  std::vector<std::vector<int32_t>> found(
      static_cast<size_t>(parallel_chunk_count(faces, chunk_faces)));
  parallel_chunks(threads, faces, chunk_faces, [&](int64_t chunk, int64_t begin, int64_t end) {
    for (int32_t i = static_cast<int32_t>(begin); i < end; ++i)
      if (is_defect(i)) found[chunk].push_back(i);
  });
  std::vector<int32_t> out;
  for (const std::vector<int32_t>& list : found) out.insert(out.end(), list.begin(), list.end());
  return out;
}

/// Two boundary faces of one mesh that touch: every corner of `face` is a node of `other` or
/// lies on it (within mesh_check_surface_tolerance x its diameter), they face each other
/// (opposite normals) and `face`'s hex lies beyond `other` (see conformity.hpp). `connected`:
/// they share a node, or a corner of one is at a corner of the other (a node split in two).
struct FaceContact {
  int32_t face, other;
  bool connected;
};

/// The boundary faces that touch another part of the boundary, split into gaps (non-conformal)
/// and self-contact, both ascending (see conformity.hpp).
struct BoundaryContacts {
  std::vector<int32_t> gap_faces, self_contact_faces;
  /// Coincident face pairs between bodies (a connected contact whose faces lie in different
  /// bodies), each pair counted once whichever face found the other.
  int64_t interface_face_pairs = 0;
};

/// The contact of boundary face i with boundary face j of `surface`, if they touch (FaceContact).
std::optional<FaceContact> boundary_faces_touch(const HexMesh& mesh, const BoundarySurface& surface,
                                                const QuadGrid& grid,
                                                const std::vector<double>& tight, int32_t i,
                                                int32_t j) {
  const Quad& q = surface.quads[i];
  const Quad& other = surface.quads[j];
  const std::array<int32_t, 4>& nodes = surface.nodes[i];
  const std::array<int32_t, 4>& other_nodes = surface.nodes[j];
  bool connected = false;
  for (int k = 0; k < 4; ++k) {
    if (std::find(other_nodes.begin(), other_nodes.end(), nodes[k]) != other_nodes.end()) {
      connected = true;
      continue;
    }
    if (!grid.box_contains(j, q[k]) || !quad_within(other, q[k], tight[j])) return std::nullopt;
    for (const Eigen::Vector3d& c : other)
      if ((c - q[k]).norm() <= tight[j]) connected = true;
  }
  // Facing: the normal of i against the normal of j's patch where i's centroid projects.
  const Eigen::Vector3d normal = quad_unit_normal(q);
  if (normal.isZero()) return std::nullopt;
  const Eigen::Vector3d centroid = (q[0] + q[1] + q[2] + q[3]) / 4.0;
  const QuadProjection at = quad_closest_point(other, centroid);
  const auto [su, sv] = quad_tangents(other, at.u, at.v);
  Eigen::Vector3d other_normal = su.cross(sv);
  if (other_normal.norm() > 0.0)
    other_normal.normalize();
  else
    other_normal = quad_unit_normal(other);
  if (!(normal.dot(other_normal) < 0.0)) return std::nullopt;
  // Beyond: the centroid of the face opposite i in i's hex, on the outer side of j.
  const HexCell& c = mesh.hexes[surface.slots[i].hex];
  const int* opposite = hex_faces[hex_opposite_face[surface.slots[i].local_face]];
  const Eigen::Vector3d far = (mesh.points[c[opposite[0]]] + mesh.points[c[opposite[1]]] +
                               mesh.points[c[opposite[2]]] + mesh.points[c[opposite[3]]]) /
                              4.0;
  if (!((far - at.point).dot(other_normal) > tight[j])) return std::nullopt;
  return FaceContact{i, j, connected};
}

/// Without a reference: the boundary faces that touch another part of the boundary, found from
/// each face's first corner (the grid lists the faces within the tight tolerance of it), and
/// grouped into contact patches (faces linked by a contact): a patch with a connected contact is
/// a gap, the others self-contact. `node_body_label`: empty for a mesh of one body, else the body
/// of every node (MeshBodies); a connected contact (a corner of one face at a corner of the
/// other: coincident unmerged nodes) between faces of two bodies is then an interface, counted
/// and left out of the patches, so it makes no gap. A contact between two bodies with no corner
/// on a corner stays self-contact, as in one body.
BoundaryContacts boundary_contacts(const HexMesh& mesh, const BoundarySurface& surface, int threads,
                                   const std::vector<int32_t>& node_body_label) {
  const int64_t faces = static_cast<int64_t>(surface.quads.size());
  std::vector<double> tight(surface.quads.size());
  for (int64_t i = 0; i < faces; ++i)
    tight[i] = mesh_check_surface_tolerance * quad_diameter(surface.quads[i]);
  const QuadGrid grid(surface.quads, tight);
  constexpr int64_t chunk_faces = 1 << 12;
  std::vector<std::vector<FaceContact>> found(
      static_cast<size_t>(parallel_chunk_count(faces, chunk_faces)));
  parallel_chunks(threads, faces, chunk_faces, [&](int64_t chunk, int64_t begin, int64_t end) {
    for (int32_t i = static_cast<int32_t>(begin); i < end; ++i) {
      // Every corner of i lies on the faces it touches, the first one too: those faces are
      // registered in its cell. The faces around that corner pass the box test and fail at
      // the next corner that is neither their node nor near them.
      const Eigen::Vector3d& corner = surface.quads[i][0];
      grid.visit_cell(corner, [&](int32_t j) {
        if (j != i && grid.box_contains(j, corner))
          if (const std::optional<FaceContact> contact =
                  boundary_faces_touch(mesh, surface, grid, tight, i, j))
            found[chunk].push_back(*contact);
        return false;
      });
    }
  });
  BoundaryContacts out;
  if (!node_body_label.empty()) {
    // Faces of two bodies share no node, so a connected contact between them is a corner on a
    // corner: the unmerged nodes of a glued interface, matching (face on face) or not (a small
    // face on a big one, as where bodies meshed apart are glued). Pairs as (lower, higher) face,
    // so a pair found from both sides counts once.
    auto face_body = [&](int32_t face) {
      return node_body_label[mesh.hexes[surface.slots[face].hex][0]];
    };
    std::vector<uint64_t> pairs;
    for (std::vector<FaceContact>& list : found)
      std::erase_if(list, [&](const FaceContact& c) {
        if (!c.connected || face_body(c.face) == face_body(c.other)) return false;
        pairs.push_back(static_cast<uint64_t>(std::min(c.face, c.other)) << 32 |
                        static_cast<uint32_t>(std::max(c.face, c.other)));
        return true;
      });
    std::sort(pairs.begin(), pairs.end());
    out.interface_face_pairs = std::unique(pairs.begin(), pairs.end()) - pairs.begin();
  }
  // Contact patches: union-find over the faces in a contact (few: none in most meshes).
  std::vector<int32_t> members;
  for (const std::vector<FaceContact>& list : found)
    for (const FaceContact& c : list) {
      members.push_back(c.face);
      members.push_back(c.other);
    }
  std::sort(members.begin(), members.end());
  members.erase(std::unique(members.begin(), members.end()), members.end());
  auto index_of = [&](int32_t face) {
    return static_cast<int32_t>(std::lower_bound(members.begin(), members.end(), face) -
                                members.begin());
  };
  std::vector<int32_t> parent(members.size());
  std::iota(parent.begin(), parent.end(), 0);
  auto root = [&](int32_t k) {
    while (parent[k] != k) k = parent[k] = parent[parent[k]];
    return k;
  };
  for (const std::vector<FaceContact>& list : found)
    for (const FaceContact& c : list) {
      const int32_t a = root(index_of(c.face)), b = root(index_of(c.other));
      parent[std::max(a, b)] = std::min(a, b);
    }
  std::vector<char> gap(members.size(), 0);
  for (const std::vector<FaceContact>& list : found)
    for (const FaceContact& c : list)
      if (c.connected) gap[root(index_of(c.face))] = 1;
  for (size_t k = 0; k < members.size(); ++k)
    (gap[root(static_cast<int32_t>(k))] ? out.gap_faces : out.self_contact_faces)
        .push_back(members[k]);
  return out;
}

double relative_error(double value, double reference) {
  if (reference == 0.0) return value == 0.0 ? 0.0 : std::abs(value);
  return std::abs(value - reference) / std::abs(reference);
}

double mesh_volume(const HexMesh& mesh) {
  double volume = 0.0;
  for (int32_t h = 0; h < mesh.hex_count(); ++h) volume += hex_volume(hex_points(mesh, h));
  return volume;
}

/// Sorts `keys`, whose values are below 2^bits, by a least-significant-digit radix sort of at
/// most 16-bit digits (a counting sort per digit, each stable): linear in the keys, a few passes.
void radix_sort(std::vector<uint64_t>& keys, int bits) {
  if (keys.size() < 2) return;
  const int passes = std::max(1, (bits + 15) / 16);
  const int digit_bits = (bits + passes - 1) / passes;
  const uint64_t mask = (uint64_t{1} << digit_bits) - 1;
  std::vector<uint64_t> other(keys.size());
  std::vector<uint32_t> start(size_t{1} << digit_bits);
  for (int pass = 0; pass < passes; ++pass) {
    const int shift = pass * digit_bits;
    std::fill(start.begin(), start.end(), 0);
    for (const uint64_t k : keys) ++start[(k >> shift) & mask];
    uint32_t running = 0;
    for (uint32_t& s : start) {
      const uint32_t count = s;
      s = running;
      running += count;
    }
    for (const uint64_t k : keys) other[start[(k >> shift) & mask]++] = k;
    keys.swap(other);
  }
}

/// mesh_bounding_box (the same corners) on up to `threads` threads: per chunk of points, combined
/// in chunk order.
std::pair<Eigen::Vector3d, Eigen::Vector3d> mesh_bounding_box_on_threads(const HexMesh& mesh,
                                                                         int threads) {
  if (mesh.points.empty()) return {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  constexpr int64_t chunk_points = 1 << 16;
  const int64_t n = static_cast<int64_t>(mesh.points.size());
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> boxes(
      static_cast<size_t>(parallel_chunk_count(n, chunk_points)));
  parallel_chunks(threads, n, chunk_points, [&](int64_t chunk, int64_t begin, int64_t end) {
    Eigen::Vector3d lo = mesh.points[begin], hi = mesh.points[begin];
    for (int64_t i = begin; i < end; ++i) {
      lo = lo.cwiseMin(mesh.points[i]);
      hi = hi.cwiseMax(mesh.points[i]);
    }
    boxes[chunk] = {lo, hi};
  });
  Eigen::Vector3d lo = mesh.points[0], hi = mesh.points[0];
  for (const auto& [chunk_lo, chunk_hi] : boxes) {
    lo = lo.cwiseMin(chunk_lo);
    hi = hi.cwiseMax(chunk_hi);
  }
  return {lo, hi};
}

/// Nodes close to a lower-id node (count_duplicate_nodes): within one body (duplicates, a defect
/// where it splits a face) and between bodies (an interface, none for a mesh of one body).
struct DuplicateNodes {
  int64_t duplicate_nodes = 0, interface_nodes = 0;
};

/// Nodes within mesh_check_duplicate_tolerance x diagonal of a lower-id node. Points are
/// bucketed by a coarse cell (about four points per cell, one counting sort); near pairs share a
/// cell unless they straddle a cell wall, so only points within the tolerance of a wall also
/// search the neighbouring cells. The cell size is an irrational multiple of the mean spacing so
/// structured grids do not put their points on the walls. Pairs are compared on float keys first
/// (below). A crowded cell (a refined region is far denser than the box's mean) is sorted by key
/// and swept, comparing only pairs within the key tolerance: k log k for k points, quadratic only
/// if their keys fall within it.
/// `node_body_label`: empty for a mesh of one body, else the body of every node (MeshBodies, -1
/// for an unused node). Then a node close to a lower-id node of another body (both used) is an
/// interface node instead, unless it is also close to a lower-id node of its own body.
DuplicateNodes count_duplicate_nodes(const HexMesh& mesh, int threads,
                                     const std::vector<int32_t>& node_body_label) {
  const int32_t n = mesh.point_count();
  if (n < 2) return {};
  // Named copies, not a structured binding: clang 14 (the fuzz build) cannot capture a binding.
  const auto box = mesh_bounding_box_on_threads(mesh, threads);
  const Eigen::Vector3d lo = box.first, hi = box.second;
  const double tolerance = mesh_check_duplicate_tolerance * (hi - lo).norm();
  const double extent = (hi - lo).maxCoeff();
  const double cell =
      std::max({1.6180339887 * extent / std::cbrt(static_cast<double>(n)), 4.0 * tolerance,
                extent / double(1 << 20), std::numeric_limits<double>::min() * 1e10});
  const Eigen::Vector3d origin = lo - Eigen::Vector3d::Constant(0.3819660113 * cell);
  // At most cbrt(n) / 1.618 + 2 cells per axis by the cell size above, so about n / 4 cells:
  // cell ids fit 32 bits for any 32-bit node count.
  std::array<int64_t, 3> dims;
  for (int d = 0; d < 3; ++d)
    dims[d] = std::clamp<int64_t>(static_cast<int64_t>((hi[d] - origin[d]) / cell) + 1, 1,
                                  int64_t{1} << 21);
  // By the reciprocal: a point next to a wall may land in the cell beside its own, and the wall
  // tests below, made against the cell it landed in, still send it to look across that wall.
  const double cells_per_unit = 1.0 / cell;
  auto cell_index = [&](double x, int d) {
    const double k = std::floor((x - origin[d]) * cells_per_unit);
    return k >= 0.0 ? std::min(static_cast<int64_t>(k), dims[d] - 1) : int64_t{0};  // NaN: 0
  };
  auto cell_of = [&](int64_t x, int64_t y, int64_t z) { return (z * dims[1] + y) * dims[0] + x; };
  const int64_t cells = dims[0] * dims[1] * dims[2];
  constexpr int64_t chunk_points = 1 << 12;
  // Both index arrays are written in full before they are read: no zero fill (fresh pages cost
  // more to touch than to compute here).
  std::unique_ptr<uint32_t[]> cell_of_point(new uint32_t[n]);
  // The cell of p in k, and for each axis whether p lies within the tolerance of the cell's lower
  // (low = -1) or upper (high = 1) wall toward another cell; returns whether it does on any axis.
  auto point_cell = [&](const Eigen::Vector3d& p, int64_t k[3], int low[3], int high[3]) {
    bool near_wall = false;
    for (int d = 0; d < 3; ++d) {
      k[d] = cell_index(p[d], d);
      const double wall = origin[d] + static_cast<double>(k[d]) * cell;
      low[d] = k[d] > 0 && p[d] - wall <= tolerance ? -1 : 0;
      high[d] = k[d] + 1 < dims[d] && wall + cell - p[d] <= tolerance ? 1 : 0;
      near_wall = near_wall || low[d] || high[d];
    }
    return near_wall;
  };
  // Points near a wall (few: the cell size is chosen so) are listed per chunk as they are seen.
  std::vector<std::vector<int32_t>> near_wall(
      static_cast<size_t>(parallel_chunk_count(n, chunk_points)));
  parallel_chunks(threads, n, chunk_points, [&](int64_t chunk, int64_t begin, int64_t end) {
    for (int64_t i = begin; i < end; ++i) {
      int64_t k[3];
      int low[3], high[3];
      if (point_cell(mesh.points[i], k, low, high))
        near_wall[chunk].push_back(static_cast<int32_t>(i));
      cell_of_point[i] = static_cast<uint32_t>(cell_of(k[0], k[1], k[2]));
    }
  });
  // Counting sort by cell over `parts` contiguous point ranges at once (as in
  // hex_face_adjacency_build): each range counts its points per cell, a prefix over (cell, range)
  // gives each range its place in every cell, and each range scatters its points there, so a
  // cell's points stay in ascending order for any thread count. offsets[p][c] counts, then
  // starts, then ends; the last range's ends are the cells' ends.
  const int parts =
      static_cast<int>(std::clamp<int64_t>(threads, 1, std::clamp<int64_t>(n / 65536, 1, 4)));
  auto part_begin = [&](int p) { return static_cast<int32_t>(int64_t{n} * p / parts); };
  std::vector<std::vector<uint32_t>> offsets(static_cast<size_t>(parts));
  parallel_chunks(parts, parts, 1, [&](int64_t p, int64_t, int64_t) {
    std::vector<uint32_t>& count = offsets[p];
    count.assign(static_cast<size_t>(cells), 0);
    for (int32_t i = part_begin(static_cast<int>(p)); i < part_begin(static_cast<int>(p) + 1); ++i)
      ++count[cell_of_point[i]];
  });
  counting_sort_starts(offsets, threads);
  // Each point with a key, its projection on a fixed direction of irrational slopes, rounded to
  // float: two points within the tolerance have keys within key_tolerance (the projection moves
  // by at most key_slopes x their distance, rounding to float by half a float ulp, at most
  // 2^-24 x key_slopes x extent, each), so pairs are compared on their keys, next to each other in
  // the cell, and only pairs with close keys read both points (scattered over the mesh). The slopes
  // are irrational so that the points of a structured grid, which share coordinates, do not share
  // keys.
  const Eigen::Vector3d slopes(1.0, 0.7548776662, 0.5698402910);  // 1, 1/phi_3, 1/phi_3^2
  const double key_slopes = slopes.sum();
  const double key_tolerance =
      (key_slopes * tolerance + std::ldexp(key_slopes * (hi - lo).maxCoeff(), -23)) * (1 + 1e-9);
  auto key_of = [&](const Eigen::Vector3d& p) {
    const double key = (p - lo).dot(slopes);
    // NaN sorts last (as +infinity), so a sort by key is strict and no NaN pair is swept.
    return std::isnan(key) ? std::numeric_limits<float>::infinity() : static_cast<float>(key);
  };
  struct KeyedPoint {
    float key;
    int32_t point;
  };
  std::unique_ptr<KeyedPoint[]> sorted(new KeyedPoint[n]);
  parallel_chunks(parts, parts, 1, [&](int64_t p, int64_t, int64_t) {
    std::vector<uint32_t>& cursor = offsets[p];
    for (int32_t i = part_begin(static_cast<int>(p)); i < part_begin(static_cast<int>(p) + 1); ++i)
      sorted[cursor[cell_of_point[i]]++] = {key_of(mesh.points[i]), i};
  });
  const std::vector<uint32_t> cell_end = std::move(offsets.back());
  offsets.clear();
  auto cell_begin = [&](int64_t c) { return c == 0 ? uint32_t{0} : cell_end[c - 1]; };

  // Pairs are compared per chunk of cells, then per chunk of points near a wall, on every thread;
  // a close pair marks its higher node (atomically: two chunks may mark the same node): bit 1
  // within one body, bit 2 between two.
  std::vector<char> duplicate(n, 0);
  const bool one_body = node_body_label.empty();
  auto compare = [&](const KeyedPoint& a, const KeyedPoint& b) {
    if (a.point != b.point && std::abs(double{a.key} - double{b.key}) <= key_tolerance &&
        (mesh.points[a.point] - mesh.points[b.point]).norm() <= tolerance) {
      char mark = 1;
      if (!one_body) {
        const int32_t body_a = node_body_label[a.point], body_b = node_body_label[b.point];
        if (body_a >= 0 && body_b >= 0 && body_a != body_b) mark = 2;
      }
      std::atomic_ref<char>(duplicate[std::max(a.point, b.point)])
          .fetch_or(mark, std::memory_order_relaxed);
    }
  };
  // A crowded cell (a refined region is far denser than the bounding box's mean) is sorted by key
  // and swept: only pairs within the key tolerance are compared, so it costs k log k, not k^2.
  parallel_chunks(threads, cells, chunk_points, [&](int64_t, int64_t begin, int64_t end) {
    for (int64_t c = begin; c < end; ++c) {
      KeyedPoint* first = sorted.get() + cell_begin(c);
      KeyedPoint* last = sorted.get() + cell_end[c];
      if (last - first <= 16) {
        for (KeyedPoint* a = first; a < last; ++a)
          for (KeyedPoint* b = a + 1; b < last; ++b) compare(*a, *b);
        continue;
      }
      std::sort(first, last, [](const KeyedPoint& x, const KeyedPoint& y) {
        return x.key < y.key || (x.key == y.key && x.point < y.point);
      });
      for (KeyedPoint* a = first; a < last; ++a)
        for (KeyedPoint* b = a + 1; b < last && double{b->key} - double{a->key} <= key_tolerance;
             ++b)
          compare(*a, *b);
    }
  });
  parallel_chunks(threads, static_cast<int64_t>(near_wall.size()), 1,
                  [&](int64_t chunk, int64_t, int64_t) {
                    for (int32_t i : near_wall[chunk]) {
                      int64_t k[3];
                      int low[3], high[3];
                      point_cell(mesh.points[i], k, low, high);
                      const KeyedPoint self = {key_of(mesh.points[i]), i};
                      for (int dz = low[2]; dz <= high[2]; ++dz)
                        for (int dy = low[1]; dy <= high[1]; ++dy)
                          for (int dx = low[0]; dx <= high[0]; ++dx) {
                            if (dx == 0 && dy == 0 && dz == 0) continue;
                            const int64_t c = cell_of(k[0] + dx, k[1] + dy, k[2] + dz);
                            for (uint32_t b = cell_begin(c); b < cell_end[c]; ++b)
                              compare(self, sorted[b]);
                          }
                    }
                  });
  DuplicateNodes out;
  for (const char mark : duplicate) {
    out.duplicate_nodes += mark & 1;
    out.interface_nodes += mark == 2;
  }
  return out;
}

/// Bodies: the connected components of the hexes under "shares a node". `node_body_label` is
/// empty when there is one body (or none), else it holds the body of every node, numbered
/// 0..bodies-1 in the order of their lowest node, and -1 for an unused node (`used`: n flags, 1
/// where a hex uses the node).
struct MeshBodies {
  int64_t bodies = 0;
  std::vector<int32_t> node_body_label;
};

/// MeshBodies of `mesh` by a union-find over its nodes (each hex links its eight; path halving,
/// the lower root kept): linear in practice, one int32 per node and no per-hex storage, so a mesh
/// of one body pays one pass over its hexes.
MeshBodies mesh_bodies(const HexMesh& mesh, const std::vector<char>& used) {
  const int32_t n = mesh.point_count();
  std::vector<int32_t> root(static_cast<size_t>(n));
  std::iota(root.begin(), root.end(), 0);
  auto find = [&](int32_t v) {
    while (root[v] != v) v = root[v] = root[root[v]];
    return v;
  };
  for (const HexCell& c : mesh.hexes) {
    int32_t r = find(c[0]);
    for (int k = 1; k < 8; ++k) {
      // Most nodes already point at their root (written below when last seen): one load.
      const int32_t parent = root[c[k]];
      if (parent == r) continue;
      const int32_t other = find(parent);
      // The lower root wins: every link points to a lower node, and a body's root is its
      // lowest node (the labelling below relies on both).
      if (other < r) {
        root[r] = other;
        r = other;
      } else if (other > r) {
        root[other] = r;
      }
      root[c[k]] = r;
    }
  }
  MeshBodies out;
  for (int32_t v = 0; v < n; ++v) out.bodies += used[v] && root[v] == v;
  if (out.bodies <= 1) return out;
  // In node order a node's parent (lower) is already labelled with its body, and a root is
  // the first node of its body: one pass turns the links into labels.
  int32_t next = 0;
  for (int32_t v = 0; v < n; ++v) {
    if (root[v] == v)
      root[v] = used[v] ? next++ : -1;
    else
      root[v] = root[root[v]];
  }
  out.node_body_label = std::move(root);
  return out;
}

/// The message mesh_validate_ids gives for the lowest of hexes [begin, end) whose node ids are
/// out of range or repeated, if any.
std::optional<std::string> hexes_bad_ids(const HexMesh& mesh, const std::string& what,
                                         int64_t begin, int64_t end) {
  using Four = int32_t __attribute__((vector_size(16)));
  const int64_t n = static_cast<int64_t>(mesh.points.size());
  // Ids are int32 and n at most 2^31: an id is in range when 0 <= id < n.
  const Four limit = Four{} + static_cast<int32_t>(std::min<int64_t>(n, INT32_MAX));
  const bool all_fit = n <= INT32_MAX;
  for (int64_t h = begin; h < end; ++h) {
    const HexCell& c = mesh.hexes[h];
    // The range and the 28 pairs in eight vector compares of the two halves and their
    // rotations; the loop below only names the defect.
    Four lo, hi;
    std::memcpy(&lo, c.data(), sizeof lo);
    std::memcpy(&hi, c.data() + 4, sizeof hi);
    const Four zero = {};
    Four bad = (lo < zero) | (hi < zero);
    if (all_fit) bad |= (lo >= limit) | (hi >= limit);
    bad |= (lo == __builtin_shufflevector(lo, lo, 1, 2, 3, 0)) |
           (lo == __builtin_shufflevector(lo, lo, 2, 3, 0, 1)) |
           (hi == __builtin_shufflevector(hi, hi, 1, 2, 3, 0)) |
           (hi == __builtin_shufflevector(hi, hi, 2, 3, 0, 1)) | (lo == hi) |
           (lo == __builtin_shufflevector(hi, hi, 1, 2, 3, 0)) |
           (lo == __builtin_shufflevector(hi, hi, 2, 3, 0, 1)) |
           (lo == __builtin_shufflevector(hi, hi, 3, 0, 1, 2));
    if ((bad[0] | bad[1] | bad[2] | bad[3]) == 0) continue;
    for (int i = 0; i < 8; ++i) {
      if (c[i] < 0 || c[i] >= n)
        return what + ": hex " + std::to_string(h) + " refers to node " + std::to_string(c[i]) +
               ", expected 0.." + std::to_string(n - 1);
      for (int j = 0; j < i; ++j)
        if (c[j] == c[i])
          return what + ": hex " + std::to_string(h) + " repeats node " + std::to_string(c[i]) +
                 " (degenerate hex)";
    }
  }
  return std::nullopt;
}

/// Bin of scaled_jacobian_histogram.
int scaled_jacobian_bin(double v) {
  if (std::isnan(v)) v = -1.0;
  return std::clamp(static_cast<int>(std::floor((v + 1.0) / 0.1 + 1e-9)), 0, 19);
}

}  // namespace

MeshCheckReport mesh_check(const HexMesh& mesh, const HexMesh* reference, int threads,
                           const ReferenceSurface* reference_surface) {
  MeshCheckReport r;
  r.hexes = mesh.hex_count();
  r.nodes = mesh.point_count();

  // One pass over the hexes: their ids checked (as mesh_validate_ids does, the lowest bad hex
  // named), the nodes they use marked, and their quality and volume measured. Per fixed chunk of
  // hexes, so the sums do not depend on the thread count.
  struct ChunkSums {
    double scaled_jacobian_sum = 0.0, volume = 0.0, min_scaled_jacobian = 1.0;
    double max_edge_ratio = 1.0;
    int64_t inverted = 0;
    std::array<int64_t, 20> histogram{};
    std::vector<int32_t> defects;  // ascending, at most the limit per kind
    std::string bad_ids;           // the message for the chunk's lowest hex with bad ids
  };
  constexpr int64_t chunk_hexes = 1 << 14;
  std::vector<ChunkSums> sums(static_cast<size_t>(parallel_chunk_count(r.hexes, chunk_hexes)));
  std::vector<char> used(mesh.points.size(), 0);
  parallel_chunks(threads, r.hexes, chunk_hexes, [&](int64_t chunk, int64_t begin, int64_t end) {
    ChunkSums& s = sums[chunk];
    if (const std::optional<std::string> bad = hexes_bad_ids(mesh, "mesh", begin, end)) {
      s.bad_ids = *bad;
      return;
    }
    for (int64_t h = begin; h < end; ++h)
      for (int32_t v : mesh.hexes[h])
        std::atomic_ref<char>(used[v]).store(1, std::memory_order_relaxed);
    // Measured in blocks whose values fit on the stack (a heap array per chunk would be fresh
    // memory each time), summed in hex order.
    constexpr int64_t block = 256;
    std::array<double, block> scaled_jacobians, volumes, edge_ratios;
    for (int64_t first = begin; first < end; first += block) {
      const size_t count = static_cast<size_t>(std::min(block, end - first));
      mesh_hex_measures(mesh, static_cast<int32_t>(first), {scaled_jacobians.data(), count},
                        {volumes.data(), count}, {edge_ratios.data(), count});
      for (size_t k = 0; k < count; ++k) {
        const int32_t h = static_cast<int32_t>(first + static_cast<int64_t>(k));
        const double sj = scaled_jacobians[k];
        s.scaled_jacobian_sum += sj;
        s.min_scaled_jacobian = std::min(s.min_scaled_jacobian, sj);
        s.volume += volumes[k];
        s.max_edge_ratio = std::max(s.max_edge_ratio, edge_ratios[k]);
        ++s.histogram[scaled_jacobian_bin(sj)];
        if (sj <= 0.0 && s.inverted++ < static_cast<int64_t>(mesh_check_defect_hex_limit))
          s.defects.push_back(h);
      }
    }
  });
  for (const ChunkSums& s : sums)
    if (!s.bad_ids.empty()) throw InputError(s.bad_ids);
  for (const HexAttribute& a : mesh.attributes)  // as mesh_validate_ids, after the hexes
    if (a.values.size() != mesh.hexes.size())
      throw InputError("mesh: attribute '" + a.name + "' has " + std::to_string(a.values.size()) +
                       " values for " + std::to_string(mesh.hexes.size()) + " hexes");
  if (reference) mesh_validate_ids(*reference, "reference mesh", threads);
  r.unused_nodes = std::count(used.begin(), used.end(), 0);
  // Bodies first: coincident nodes and faces between two bodies are interfaces, not defects.
  const MeshBodies bodies = mesh_bodies(mesh, used);
  r.bodies = bodies.bodies;
  used = {};

  const DuplicateNodes duplicates = count_duplicate_nodes(mesh, threads, bodies.node_body_label);
  r.duplicate_nodes = duplicates.duplicate_nodes;
  r.interface_nodes = duplicates.interface_nodes;
  // Doublets come from the matching itself: no neighbour array (24 bytes per hex) is built.
  HexFaceAdjacency adjacency = hex_face_adjacency_build(mesh, threads, false);
  r.nonmanifold_faces = static_cast<int64_t>(adjacency.nonmanifold_faces.size());

  // Hexes with a defect: every source offers its lowest mesh_check_defect_hex_limit, so the
  // report lists the lowest overall.
  std::vector<int32_t> defects;
  for (const HexFaceSlot& f : adjacency.nonmanifold_faces) defects.push_back(f.hex);
  r.doublets = static_cast<int64_t>(adjacency.doublets.size());
  defects.insert(defects.end(), adjacency.doublets.begin(),
                 adjacency.doublets.begin() +
                     std::min(adjacency.doublets.size(), mesh_check_defect_hex_limit));

  double sum_scaled_jacobian = 0.0;
  r.scaled_jacobian_histogram.assign(20, 0);
  for (const ChunkSums& s : sums) {
    sum_scaled_jacobian += s.scaled_jacobian_sum;
    r.volume += s.volume;
    r.min_scaled_jacobian = std::min(r.min_scaled_jacobian, s.min_scaled_jacobian);
    r.max_edge_ratio = std::max(r.max_edge_ratio, s.max_edge_ratio);
    if (s.inverted > 0 && r.inverted_hexes == 0) r.first_inverted_hex = s.defects.front();
    r.inverted_hexes += s.inverted;
    for (int b = 0; b < 20; ++b) r.scaled_jacobian_histogram[b] += s.histogram[b];
    defects.insert(defects.end(), s.defects.begin(), s.defects.end());
  }
  sums.clear();
  if (r.hexes > 0) r.mean_scaled_jacobian = sum_scaled_jacobian / static_cast<double>(r.hexes);

  // Boundary surface: closedness and area.
  const BoundarySurface surface =
      boundary_surface(mesh, std::move(adjacency.boundary_faces), threads);
  r.boundary_faces = static_cast<int64_t>(surface.slots.size());
  // Every boundary edge must be used by exactly two boundary faces: count the uses of each
  // (lower node, higher node) pair over the boundary faces, keys of 2 x node_bits bits sorted by
  // radix (linear in the boundary). Keys and areas per face on every thread; the areas summed in
  // face order, so the total does not depend on the thread count.
  const int node_bits = std::max(
      1, static_cast<int>(std::bit_width(static_cast<uint32_t>(std::max(mesh.point_count(), 1)))));
  std::vector<uint64_t> boundary_edges(4 * surface.slots.size());
  {
    std::vector<double> areas(surface.slots.size());
    parallel_chunks(threads, r.boundary_faces, 1 << 12, [&](int64_t, int64_t begin, int64_t end) {
      for (int64_t i = begin; i < end; ++i) {
        const auto& n = surface.nodes[i];
        for (int k = 0; k < 4; ++k) {
          const uint32_t a = static_cast<uint32_t>(n[k]), b = static_cast<uint32_t>(n[(k + 1) % 4]);
          boundary_edges[4 * i + k] =
              static_cast<uint64_t>(std::min(a, b)) << node_bits | std::max(a, b);
        }
        areas[i] = quad_area(surface.quads[i]);
      }
    });
    for (double area : areas) r.boundary_area += area;
  }
  radix_sort(boundary_edges, 64 - std::countl_zero(std::max<uint64_t>(
                                      1, static_cast<uint64_t>(mesh.point_count()) << 32)));
  for (size_t i = 0; i < boundary_edges.size();) {
    size_t j = i;
    while (j < boundary_edges.size() && boundary_edges[j] == boundary_edges[i]) ++j;
    r.nonmanifold_boundary_edges += (j - i != 2);
    i = j;
  }

  // Non-conformal faces: boundary faces off the reference surface, or (without a reference)
  // lying on another boundary face of this mesh.
  std::vector<int32_t> non_conformal;  // indices into surface
  if (reference) {
    std::optional<ReferenceSurface> own_surface;
    if (!reference_surface) reference_surface = &own_surface.emplace(*reference, threads);
    non_conformal = boundary_faces_where(threads, surface, [&](int32_t i) {
      return !reference_surface_holds_face(*reference_surface, surface.quads[i]);
    });
    r.reference_compared = true;
    r.reference_volume = mesh_volume(*reference);
    r.reference_planar_faced = true;
    for (const Quad& q : reference_surface->quads()) {
      r.reference_boundary_area += quad_area(q);
      if (quad_relative_warp(q) > 1e-12) r.reference_planar_faced = false;
    }
    r.volume_relative_error = relative_error(r.volume, r.reference_volume);
    r.boundary_area_relative_error = relative_error(r.boundary_area, r.reference_boundary_area);
    r.geometry_preserved = !r.reference_planar_faced ||
                           (r.volume_relative_error <= mesh_check_geometry_tolerance &&
                            r.boundary_area_relative_error <= mesh_check_geometry_tolerance);
  } else {
    const BoundaryContacts contacts =
        boundary_contacts(mesh, surface, threads, bodies.node_body_label);
    non_conformal = contacts.gap_faces;
    r.self_contact_faces = static_cast<int64_t>(contacts.self_contact_faces.size());
    r.interface_faces = contacts.interface_face_pairs;
  }
  r.non_conformal_faces = static_cast<int64_t>(non_conformal.size());
  for (int32_t i : non_conformal) defects.push_back(surface.slots[i].hex);
  std::sort(defects.begin(), defects.end());
  defects.erase(std::unique(defects.begin(), defects.end()), defects.end());
  if (defects.size() > mesh_check_defect_hex_limit) defects.resize(mesh_check_defect_hex_limit);
  r.defect_hexes = std::move(defects);

  // Hanging nodes: T-junctions among the non-conformal faces.
  if (!non_conformal.empty()) {
    std::vector<Quad> quads;
    std::vector<double> tolerances;
    for (int32_t i : non_conformal) {
      quads.push_back(surface.quads[i]);
      tolerances.push_back(surface.tolerances[i]);
    }
    const QuadGrid grid(quads, tolerances);
    std::vector<char> counted(mesh.points.size(), 0);
    for (int32_t i : non_conformal)
      for (int32_t node : surface.nodes[i]) {
        if (counted[node]) continue;
        const Eigen::Vector3d& p = mesh.points[node];
        const bool hanging = grid.find(p, [&](int32_t j) {
          const auto& other = surface.nodes[non_conformal[j]];
          if (std::find(other.begin(), other.end(), node) != other.end()) return false;
          for (const Eigen::Vector3d& c : quads[j])
            if ((c - p).norm() <= tolerances[j]) return false;
          return true;
        });
        if (hanging) {
          counted[node] = 1;
          ++r.hanging_nodes;
        }
      }
  }

  r.conformal = r.nonmanifold_faces == 0 && r.non_conformal_faces == 0 && r.hanging_nodes == 0 &&
                r.nonmanifold_boundary_edges == 0 && r.doublets == 0;
  return r;
}

void to_json(nlohmann::json& j, const MeshCheckReport& r) {
  j = nlohmann::json::object();
  j["hexes"] = r.hexes;
  j["nodes"] = r.nodes;
  j["conformal"] = r.conformal;
  j["valid"] = r.valid();
  j["non_conformal_faces"] = r.non_conformal_faces;
  j["hanging_nodes"] = r.hanging_nodes;
  j["inverted_hexes"] = r.inverted_hexes;
  j["first_inverted_hex"] = r.first_inverted_hex;
  j["doublets"] = r.doublets;
  j["nonmanifold_faces"] = r.nonmanifold_faces;
  j["nonmanifold_boundary_edges"] = r.nonmanifold_boundary_edges;
  j["duplicate_nodes"] = r.duplicate_nodes;
  j["unused_nodes"] = r.unused_nodes;
  j["boundary_faces"] = r.boundary_faces;
  j["self_contact_faces"] = r.self_contact_faces;
  j["bodies"] = r.bodies;
  j["interface_faces"] = r.interface_faces;
  j["interface_nodes"] = r.interface_nodes;
  j["min_scaled_jacobian"] = r.min_scaled_jacobian;
  j["mean_scaled_jacobian"] = r.mean_scaled_jacobian;
  j["max_edge_ratio"] = r.max_edge_ratio;
  j["volume"] = r.volume;
  j["boundary_area"] = r.boundary_area;
  j["defect_hexes"] = r.defect_hexes;
  j["scaled_jacobian_histogram"] = {
      {"bin_edges_from", -1.0}, {"bin_width", 0.1}, {"counts", r.scaled_jacobian_histogram}};
  j["reference_compared"] = r.reference_compared;
  if (r.reference_compared) {
    j["reference_planar_faced"] = r.reference_planar_faced;
    j["reference_volume"] = r.reference_volume;
    j["reference_boundary_area"] = r.reference_boundary_area;
    j["volume_relative_error"] = r.volume_relative_error;
    j["boundary_area_relative_error"] = r.boundary_area_relative_error;
    j["geometry_preserved"] = r.geometry_preserved;
  }
}

std::vector<int64_t> scaled_jacobian_histogram(const std::vector<double>& values) {
  std::vector<int64_t> bins(20, 0);
  for (double v : values) ++bins[scaled_jacobian_bin(v)];
  return bins;
}

std::vector<std::string> mesh_check_defects(const MeshCheckReport& r) {
  std::vector<std::string> out;
  auto add = [&](int64_t count, const std::string& what) {
    if (count > 0) out.push_back(std::to_string(count) + " " + what);
  };
  add(r.nonmanifold_faces, "faces shared by more than two hexes");
  add(r.non_conformal_faces,
      r.reference_compared
          ? "non-conformal faces (boundary faces not on the reference's boundary surface: a gap "
            "between hexes, or a face that left the surface)"
          : "non-conformal faces (two sides of a gap between hexes that should share a face)");
  add(r.hanging_nodes, "hanging nodes");
  add(r.nonmanifold_boundary_edges, "boundary edges not in exactly two boundary faces");
  add(r.doublets, "doublets (hex pairs sharing two or more faces)");
  if (r.inverted_hexes > 0)
    out.push_back(std::to_string(r.inverted_hexes) + " inverted hexes, first at id " +
                  std::to_string(r.first_inverted_hex));
  if (!r.geometry_preserved) {
    char buf[160];
    std::snprintf(buf, sizeof buf,
                  "geometry not preserved: volume relative error %.3g, boundary area relative "
                  "error %.3g (planar-faced reference, tolerance %.0e)",
                  r.volume_relative_error, r.boundary_area_relative_error,
                  mesh_check_geometry_tolerance);
    out.emplace_back(buf);
  }
  return out;
}

}  // namespace hexrefine
