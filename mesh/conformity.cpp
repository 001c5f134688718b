#include "mesh/conformity.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <string>
#include <unordered_map>

#include "mesh/hex_convention.hpp"
#include "mesh/quad_patch.hpp"
#include "mesh/quality.hpp"
#include "mesh/topology.hpp"

namespace hexrefine {

namespace {

/// Hash grid over quads: each quad is listed in every cell its bounding box (grown by its
/// tolerance) overlaps, so a point query looks in one cell only.
class QuadGrid {
 public:
  QuadGrid(const std::vector<Quad>& quads, const std::vector<double>& tolerances)
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
    for (int pass = 0; pass < 2; ++pass) {
      for (size_t i = 0; i < quads.size(); ++i) {
        Eigen::Vector3d qlo = quads[i][0], qhi = quads[i][0];
        for (const Eigen::Vector3d& c : quads[i]) {
          qlo = qlo.cwiseMin(c);
          qhi = qhi.cwiseMax(c);
        }
        const Eigen::Vector3d grow = Eigen::Vector3d::Constant(tolerances[i]);
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

  /// Calls visit(quad index) for each quad whose tolerance band contains p, until it returns true;
  /// returns whether one did.
  template <class Visit>
  bool find(const Eigen::Vector3d& p, Visit visit) const {
    if (offsets_.empty()) return false;
    const auto it = bucket_of_cell_.find(pack(cell_of(p)));
    if (it == bucket_of_cell_.end()) return false;
    for (int32_t k = offsets_[it->second]; k < offsets_[it->second + 1]; ++k) {
      const int32_t i = items_[k];
      if (quad_distance(quads_[i], p) <= tolerances_[i] && visit(i)) return true;
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
};

/// Boundary surface of a mesh: face ids, their node ids (outward from their hex) and positions.
struct BoundarySurface {
  std::vector<int32_t> faces;
  std::vector<std::array<int32_t, 4>> nodes;
  std::vector<Quad> quads;
  std::vector<double> tolerances;  ///< surface tolerance x diameter, per face
};

BoundarySurface boundary_surface(const HexMesh& mesh, const HexTopology& t) {
  BoundarySurface s;
  s.faces = topology_boundary_faces(t);
  s.nodes.reserve(s.faces.size());
  s.quads.reserve(s.faces.size());
  for (int32_t f : s.faces) {
    const auto& n = t.face_nodes[f];
    s.nodes.push_back(n);
    s.quads.push_back({mesh.points[n[0]], mesh.points[n[1]], mesh.points[n[2]], mesh.points[n[3]]});
    // A point averaged from patch points (a sub-face centroid, a node placed by a template whose
    // footprint is not a parameter rectangle) can leave a warped patch by up to its warp.
    s.tolerances.push_back(mesh_check_surface_tolerance * quad_diameter(s.quads.back()) +
                           quad_warp(s.quads.back()));
  }
  return s;
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

/// Nodes within mesh_check_duplicate_tolerance x diagonal of a lower-id node. Points are sorted
/// by a coarse cell (about one point per cell); near pairs share a cell unless they straddle a
/// cell wall, so only points within the tolerance of a wall also search the neighbouring cells.
/// The cell size is an irrational multiple of the mean spacing so structured grids do not put
/// their points on the walls. Worst case (many points in one cell) is quadratic in that cell.
int64_t count_duplicate_nodes(const HexMesh& mesh) {
  const int32_t n = mesh.point_count();
  if (n < 2) return 0;
  const auto [lo, hi] = mesh_bounding_box(mesh);
  const double tolerance = mesh_check_duplicate_tolerance * (hi - lo).norm();
  const double extent = (hi - lo).maxCoeff();
  const double cell =
      std::max({1.6180339887 * extent / std::cbrt(static_cast<double>(n)), 4.0 * tolerance,
                extent / double(1 << 20), std::numeric_limits<double>::min() * 1e10});
  const Eigen::Vector3d origin = lo - Eigen::Vector3d::Constant(0.3819660113 * cell);
  auto cell_index = [&](double x, int d) {
    return static_cast<int64_t>(std::floor((x - origin[d]) / cell));
  };
  auto pack = [](int64_t x, int64_t y, int64_t z) {
    const uint64_t mask = 0x1FFFFF;  // indices stay in [0, 2^20 + 2) by the cell size above
    return ((static_cast<uint64_t>(x) & mask) << 42) | ((static_cast<uint64_t>(y) & mask) << 21) |
           (static_cast<uint64_t>(z) & mask);
  };
  std::vector<std::pair<uint64_t, int32_t>> sorted(n);
  for (int32_t i = 0; i < n; ++i) {
    const Eigen::Vector3d& p = mesh.points[i];
    sorted[i] = {pack(cell_index(p[0], 0), cell_index(p[1], 1), cell_index(p[2], 2)), i};
  }
  std::sort(sorted.begin(), sorted.end());
  std::vector<char> duplicate(n, 0);
  auto compare = [&](int32_t i, int32_t j) {
    if (i != j && (mesh.points[i] - mesh.points[j]).norm() <= tolerance)
      duplicate[std::max(i, j)] = 1;
  };
  for (size_t begin = 0; begin < sorted.size();) {
    size_t end = begin + 1;
    while (end < sorted.size() && sorted[end].first == sorted[begin].first) ++end;
    for (size_t a = begin; a < end; ++a)
      for (size_t b = a + 1; b < end; ++b) compare(sorted[a].second, sorted[b].second);
    begin = end;
  }
  for (int32_t i = 0; i < n; ++i) {
    const Eigen::Vector3d& p = mesh.points[i];
    int64_t k[3];
    int low[3], high[3];
    bool near_wall = false;
    for (int d = 0; d < 3; ++d) {
      k[d] = cell_index(p[d], d);
      const double wall = origin[d] + static_cast<double>(k[d]) * cell;
      low[d] = p[d] - wall <= tolerance ? -1 : 0;
      high[d] = wall + cell - p[d] <= tolerance ? 1 : 0;
      near_wall = near_wall || low[d] || high[d];
    }
    if (!near_wall) continue;
    for (int dz = low[2]; dz <= high[2]; ++dz)
      for (int dy = low[1]; dy <= high[1]; ++dy)
        for (int dx = low[0]; dx <= high[0]; ++dx) {
          if (dx == 0 && dy == 0 && dz == 0) continue;
          const uint64_t key = pack(k[0] + dx, k[1] + dy, k[2] + dz);
          auto it =
              std::lower_bound(sorted.begin(), sorted.end(), std::make_pair(key, int32_t{-1}));
          for (; it != sorted.end() && it->first == key; ++it) compare(i, it->second);
        }
  }
  return std::count(duplicate.begin(), duplicate.end(), 1);
}

/// Bin of scaled_jacobian_histogram.
int scaled_jacobian_bin(double v) {
  if (std::isnan(v)) v = -1.0;
  return std::clamp(static_cast<int>(std::floor((v + 1.0) / 0.1 + 1e-9)), 0, 19);
}

}  // namespace

MeshCheckReport mesh_check(const HexMesh& mesh, const HexMesh* reference) {
  mesh_validate_ids(mesh, "mesh");
  if (reference) mesh_validate_ids(*reference, "reference mesh");
  MeshCheckReport r;
  r.hexes = mesh.hex_count();
  r.nodes = mesh.point_count();
  // Unused and duplicate nodes first: their work arrays are gone before the topology is built.
  {
    std::vector<char> used(mesh.points.size(), 0);
    for (const HexCell& c : mesh.hexes)
      for (int32_t v : c) used[v] = 1;
    r.unused_nodes = std::count(used.begin(), used.end(), 0);
  }
  r.duplicate_nodes = count_duplicate_nodes(mesh);
  // Faces only: the check needs no edge table (boundary edges are counted below from the
  // boundary faces alone), which keeps the memory of checking a large output down.
  const HexTopology t = topology_build(mesh, TopologyParts::faces);
  r.nonmanifold_faces = static_cast<int64_t>(t.nonmanifold_faces.size());

  // Quality and volume.
  std::vector<int32_t> defects;  // hexes with a defect (a few, for messages)
  auto defect = [&](int32_t h) {
    if (defects.size() < 4 * mesh_check_defect_hex_limit) defects.push_back(h);
  };
  double sum_scaled_jacobian = 0.0;
  r.scaled_jacobian_histogram.assign(20, 0);
  for (int32_t h = 0; h < mesh.hex_count(); ++h) {
    const HexCorners p = hex_points(mesh, h);
    const double sj = hex_scaled_jacobian(p);
    sum_scaled_jacobian += sj;
    r.min_scaled_jacobian = std::min(r.min_scaled_jacobian, sj);
    r.volume += hex_volume(p);
    ++r.scaled_jacobian_histogram[scaled_jacobian_bin(sj)];
    if (sj <= 0.0) {
      if (r.inverted_hexes == 0) r.first_inverted_hex = h;
      ++r.inverted_hexes;
      defect(h);
    }
  }
  for (int32_t f : t.nonmanifold_faces) defect(t.face_hexes[f][0]);
  if (r.hexes > 0) r.mean_scaled_jacobian = sum_scaled_jacobian / static_cast<double>(r.hexes);

  // Doublets: a neighbour met across two local faces of the same hex.
  for (int32_t h = 0; h < mesh.hex_count(); ++h) {
    std::array<int32_t, 6> neighbours;
    for (int lf = 0; lf < 6; ++lf) neighbours[lf] = hex_face_neighbor(t, h, lf);
    for (int a = 0; a < 6; ++a) {
      const int32_t g = neighbours[a];
      if (g <= h) continue;  // count each pair once, from its lower hex
      bool seen_before = false, repeated = false;
      for (int b = 0; b < 6; ++b)
        if (b != a && neighbours[b] == g) (b < a ? seen_before : repeated) = true;
      if (repeated && !seen_before) {
        ++r.doublets;
        defect(h);
      }
    }
  }

  // Boundary surface: closedness and area.
  const BoundarySurface surface = boundary_surface(mesh, t);
  r.boundary_faces = static_cast<int64_t>(surface.faces.size());
  // Every boundary edge must be used by exactly two boundary faces: count the uses of each
  // (lower node, higher node) pair over the boundary faces (sorted, linear in the boundary).
  std::vector<uint64_t> boundary_edges;
  boundary_edges.reserve(4 * surface.faces.size());
  for (size_t i = 0; i < surface.faces.size(); ++i) {
    const auto& n = surface.nodes[i];
    for (int k = 0; k < 4; ++k) {
      const uint32_t a = static_cast<uint32_t>(n[k]), b = static_cast<uint32_t>(n[(k + 1) % 4]);
      boundary_edges.push_back(static_cast<uint64_t>(std::min(a, b)) << 32 | std::max(a, b));
    }
    r.boundary_area += quad_area(surface.quads[i]);
  }
  std::sort(boundary_edges.begin(), boundary_edges.end());
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
    const HexTopology reference_topology = topology_build(*reference, TopologyParts::faces);
    const BoundarySurface reference_surface = boundary_surface(*reference, reference_topology);
    const QuadGrid grid(reference_surface.quads, reference_surface.tolerances);
    for (size_t i = 0; i < surface.quads.size(); ++i) {
      const Quad& q = surface.quads[i];
      const Eigen::Vector3d centroid = (q[0] + q[1] + q[2] + q[3]) / 4.0;
      const bool on_reference = grid.find(centroid, [&](int32_t j) {
        for (const Eigen::Vector3d& c : q)
          if (quad_distance(reference_surface.quads[j], c) > reference_surface.tolerances[j])
            return false;
        return true;
      });
      if (!on_reference) non_conformal.push_back(static_cast<int32_t>(i));
    }
    r.reference_compared = true;
    r.reference_volume = mesh_volume(*reference);
    r.reference_planar_faced = true;
    for (const Quad& q : reference_surface.quads) {
      r.reference_boundary_area += quad_area(q);
      if (quad_relative_warp(q) > 1e-12) r.reference_planar_faced = false;
    }
    r.volume_relative_error = relative_error(r.volume, r.reference_volume);
    r.boundary_area_relative_error = relative_error(r.boundary_area, r.reference_boundary_area);
    r.geometry_preserved = !r.reference_planar_faced ||
                           (r.volume_relative_error <= mesh_check_geometry_tolerance &&
                            r.boundary_area_relative_error <= mesh_check_geometry_tolerance);
  } else {
    const QuadGrid grid(surface.quads, surface.tolerances);
    for (size_t i = 0; i < surface.quads.size(); ++i) {
      const Quad& q = surface.quads[i];
      const Eigen::Vector3d centroid = (q[0] + q[1] + q[2] + q[3]) / 4.0;
      if (grid.find(centroid, [&](int32_t j) { return j != static_cast<int32_t>(i); }))
        non_conformal.push_back(static_cast<int32_t>(i));
    }
  }
  r.non_conformal_faces = static_cast<int64_t>(non_conformal.size());
  for (int32_t i : non_conformal) defect(t.face_hexes[surface.faces[i]][0]);
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
  j["min_scaled_jacobian"] = r.min_scaled_jacobian;
  j["mean_scaled_jacobian"] = r.mean_scaled_jacobian;
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
  add(r.non_conformal_faces, "non-conformal faces");
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
