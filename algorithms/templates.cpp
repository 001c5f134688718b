#include "algorithms/templates.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <thread>

#include "mesh/error.hpp"
#include "mesh/hex_convention.hpp"
#include "mesh/quality.hpp"

namespace hexrefine {

namespace {

constexpr double kOnBoundary = 1e-12;

bool is_extreme(double x) {
  return std::abs(x) < kOnBoundary || std::abs(x - 1.0) < kOnBoundary;
}

int vertex_of(const std::array<int, 3>& c) {
  for (int v = 0; v < 8; ++v)
    if (hex_corner[v][0] == c[0] && hex_corner[v][1] == c[1] && hex_corner[v][2] == c[2]) return v;
  return -1;
}

int edge_of_vertices(int a, int b) {
  for (int e = 0; e < 12; ++e)
    if ((hex_edges[e][0] == a && hex_edges[e][1] == b) ||
        (hex_edges[e][0] == b && hex_edges[e][1] == a))
      return e;
  return -1;
}

// The local edge holding a reference point that lies inside an edge (two coordinates extreme).
int local_edge_at(const std::array<double, 3>& p, int free_axis) {
  std::array<int, 3> lo{}, hi{};
  for (int k = 0; k < 3; ++k) {
    const int c = k == free_axis ? 0 : static_cast<int>(std::lround(p[k]));
    lo[k] = c;
    hi[k] = k == free_axis ? 1 : c;
  }
  return edge_of_vertices(vertex_of(lo), vertex_of(hi));
}

std::array<CubeSymmetry, 48> make_symmetries() {
  std::array<CubeSymmetry, 48> out{};
  std::array<int8_t, 3> perm = {0, 1, 2};
  int n = 0;
  do {
    const int perm_sign =
        (perm[0] == 0 ? (perm[1] == 1 ? 1 : -1)
                      : (perm[0] == 1 ? (perm[1] == 2 ? 1 : -1) : (perm[1] == 0 ? 1 : -1)));
    for (int flips = 0; flips < 8; ++flips) {
      CubeSymmetry s{};
      s.axis = perm;
      int sign = perm_sign;
      for (int k = 0; k < 3; ++k) {
        s.flip[k] = (flips >> k) & 1;
        if (s.flip[k]) sign = -sign;
      }
      s.reflection = sign < 0;
      for (int v = 0; v < 8; ++v) {
        const std::array<double, 3> p = {double(hex_corner[v][0]), double(hex_corner[v][1]),
                                         double(hex_corner[v][2])};
        const std::array<double, 3> q = cube_symmetry_apply(s, p);
        s.vertex[v] = static_cast<int8_t>(
            vertex_of({int(std::lround(q[0])), int(std::lround(q[1])), int(std::lround(q[2]))}));
      }
      for (int e = 0; e < 12; ++e)
        s.edge[e] = static_cast<int8_t>(
            edge_of_vertices(s.vertex[hex_edges[e][0]], s.vertex[hex_edges[e][1]]));
      for (int f = 0; f < 6; ++f) {
        for (int g = 0; g < 6; ++g) {
          int matched = 0;
          for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j) matched += s.vertex[hex_faces[f][i]] == hex_faces[g][j];
          if (matched == 4) s.face[f] = static_cast<int8_t>(g);
        }
      }
      out[n++] = s;
    }
  } while (std::next_permutation(perm.begin(), perm.end()));
  return out;
}

Eigen::Vector3d trilinear(const std::array<Eigen::Vector3d, 8>& x, const std::array<double, 3>& p) {
  Eigen::Vector3d out = Eigen::Vector3d::Zero();
  for (int v = 0; v < 8; ++v) {
    double w = 1.0;
    for (int k = 0; k < 3; ++k) w *= hex_corner[v][k] ? p[k] : 1.0 - p[k];
    out += w * x[v];
  }
  return out;
}

// Determinant of the trilinear map's Jacobian at the reference centre (orientation test).
double hex_center_jacobian(const std::array<Eigen::Vector3d, 8>& x) {
  Eigen::Matrix3d j = Eigen::Matrix3d::Zero();
  for (int v = 0; v < 8; ++v)
    for (int k = 0; k < 3; ++k) {
      double w = hex_corner[v][k] ? 1.0 : -1.0;
      for (int m = 0; m < 3; ++m)
        if (m != k) w *= 0.5;
      j.col(k) += w * x[v];
    }
  return j.determinant();
}

// Builds a template in the canonical cube: nodes are deduplicated by position (adjustment nodes
// are kept apart), and children are re-ordered to positive orientation if given mirrored, so
// the template tables below can list children in the order that reads best.
class TemplateBuilder {
 public:
  explicit TemplateBuilder(TemplateTag tag) { t_.tag = tag; }

  int16_t node(double x, double y, double z) {
    for (size_t i = 0; i < t_.nodes.size(); ++i) {
      const TemplateNode& n = t_.nodes[i];
      if (n.adjustment_edge < 0 && std::abs(n.ref[0] - x) < 1e-12 &&
          std::abs(n.ref[1] - y) < 1e-12 && std::abs(n.ref[2] - z) < 1e-12)
        return static_cast<int16_t>(i);
    }
    t_.nodes.push_back({{x, y, z}});
    return static_cast<int16_t>(t_.nodes.size() - 1);
  }

  int16_t adjustment(int edge, int index, double x, double y, double z) {
    TemplateNode n{{x, y, z}};
    n.adjustment_edge = static_cast<int8_t>(edge);
    n.adjustment_index = static_cast<int8_t>(index);
    t_.nodes.push_back(n);
    return static_cast<int16_t>(t_.nodes.size() - 1);
  }

  void child(std::array<int16_t, 8> c) {
    std::array<Eigen::Vector3d, 8> x;
    for (int k = 0; k < 8; ++k) {
      const auto& r = t_.nodes[c[k]].ref;
      x[k] = Eigen::Vector3d(r[0], r[1], r[2]);
    }
    if (hex_center_jacobian(x) < 0) c = {c[0], c[3], c[2], c[1], c[4], c[7], c[6], c[5]};
    t_.children.push_back(c);
  }

  // A hex from two quads ("bottom" a, "top" b) whose corners correspond.
  void child(const std::array<int16_t, 4>& a, const std::array<int16_t, 4>& b) {
    child({a[0], a[1], a[2], a[3], b[0], b[1], b[2], b[3]});
  }

  HexTemplate take() {
    template_compute_child_axes(t_);
    template_compile(t_);
    return std::move(t_);
  }

 private:
  HexTemplate t_;
};
}  // namespace

const std::array<CubeSymmetry, 48>& cube_symmetries() {
  static const std::array<CubeSymmetry, 48> table = make_symmetries();
  return table;
}

std::array<double, 3> cube_symmetry_apply(const CubeSymmetry& s, const std::array<double, 3>& p) {
  std::array<double, 3> q{};
  for (int k = 0; k < 3; ++k) q[k] = s.flip[k] ? 1.0 - p[s.axis[k]] : p[s.axis[k]];
  return q;
}

uint16_t cube_symmetry_edge_mask(const CubeSymmetry& s, uint16_t canonical_mask) {
  uint16_t out = 0;
  for (int e = 0; e < 12; ++e)
    if (canonical_mask & (1u << e)) out |= static_cast<uint16_t>(1u << s.edge[e]);
  return out;
}

uint16_t template_split_edges(const HexTemplate& tmpl) {
  uint16_t mask = 0;
  for (const TemplateNode& n : tmpl.nodes) {
    if (n.adjustment_edge >= 0) continue;
    int extreme = 0, free_axis = -1;
    for (int k = 0; k < 3; ++k) {
      if (is_extreme(n.ref[k]))
        ++extreme;
      else
        free_axis = k;
    }
    if (extreme == 2) mask |= static_cast<uint16_t>(1u << local_edge_at(n.ref, free_axis));
  }
  return mask;
}

namespace {

constexpr int64_t kUnit = template_param_unit;

TemplateNodeKey make_key(TemplateNodeKey::Kind kind, int64_t id, int64_t a = 0, int64_t b = 0) {
  return {(static_cast<int64_t>(kind) << 40) | id, a, b};
}

std::array<double, 3> param_to_ref(const TemplateParam& p) {
  return {double(p[0]) / kUnit, double(p[1]) / kUnit, double(p[2]) / kUnit};
}

// Exact image of a template position given in sixths under the cell's trilinear frame; false if
// it is not representable (nested too deep).
bool cell_map_sixths(const TemplateCell& cell, const std::array<int64_t, 3>& p6,
                     TemplateParam& out) {
  std::array<int64_t, 3> sum = {0, 0, 0};
  for (int v = 0; v < 8; ++v) {
    int64_t w = 1;
    for (int k = 0; k < 3; ++k) w *= hex_corner[v][k] ? p6[k] : 6 - p6[k];
    if (w == 0) continue;
    for (int k = 0; k < 3; ++k) sum[k] += w * cell.param[v][k];
  }
  for (int k = 0; k < 3; ++k) {
    if (sum[k] % 216 != 0) return false;
    out[k] = sum[k] / 216;
  }
  return true;
}

}  // namespace

TemplateRefiner::TemplateRefiner(const HexMesh& mesh, const HexTopology& topology)
    : mesh_(mesh),
      topology_(topology),
      points_(mesh.points),
      edge_slot_(3 * static_cast<size_t>(topology.edge_count()), -1),
      face_base_(topology.face_count(), -1) {
  // Address space only: pages are touched as faces are first used.
  face_slot_.reserve(9 * static_cast<size_t>(topology.face_count()));
}

void TemplateRefiner::reserve_created(size_t nodes) {
  points_.reserve(points_.size() + nodes);
  if (record_keys_) created_keys_.reserve(created_keys_.size() + nodes);
}

TemplateCell TemplateRefiner::cell_whole(int32_t hex) const {
  TemplateCell c;
  c.hex = hex;
  c.nodes = mesh_.hexes[hex];
  for (int v = 0; v < 8; ++v) {
    for (int k = 0; k < 3; ++k) c.param[v][k] = hex_corner[v][k] * kUnit;
    c.key[v] = make_key(TemplateNodeKey::corner, c.nodes[v]);
  }
  return c;
}

TemplateNodeKey TemplateRefiner::key_adjustment(int32_t edge, int k) {
  return make_key(TemplateNodeKey::adjustment, edge, k);
}

TemplateNodeKey TemplateRefiner::key_at(int32_t hex, const TemplateParam& p) const {
  const HexCell& cell = mesh_.hexes[hex];
  int extreme = 0, free_axis = -1, fixed_axis = -1;
  for (int k = 0; k < 3; ++k) {
    if (p[k] == 0 || p[k] == kUnit) {
      ++extreme;
      fixed_axis = k;
    } else {
      free_axis = k;
    }
  }
  if (extreme == 3)
    return make_key(TemplateNodeKey::corner,
                    cell[vertex_of({int(p[0] / kUnit), int(p[1] / kUnit), int(p[2] / kUnit)})]);
  if (extreme == 2) {
    std::array<double, 3> r = param_to_ref(p);
    const int le = local_edge_at(r, free_axis);
    const int32_t e = topology_.hex_edge_ids[hex][le];
    int64_t t = p[free_axis];
    if (cell[hex_edges[le][0]] != topology_.edge_nodes[e][0]) t = kUnit - t;
    return make_key(TemplateNodeKey::edge, e, t);
  }
  if (extreme == 1) {
    const int lf = 2 * fixed_axis + (p[fixed_axis] == kUnit ? 1 : 0);
    const int32_t f = topology_.hex_face_ids[hex][lf];
    std::array<int32_t, 4> g{};
    for (int c = 0; c < 4; ++c) g[c] = cell[hex_faces[lf][c]];
    int i0 = 0;
    for (int i = 1; i < 4; ++i)
      if (g[i] < g[i0]) i0 = i;
    const int step = g[(i0 + 1) % 4] < g[(i0 + 3) % 4] ? 1 : 3;
    const int* o = hex_corner[hex_faces[lf][i0]];
    const int* c1 = hex_corner[hex_faces[lf][(i0 + step) % 4]];
    const int* c3 = hex_corner[hex_faces[lf][(i0 + 3 * step) % 4]];
    int64_t u = 0, v = 0;
    for (int k = 0; k < 3; ++k) {
      u += (c1[k] - o[k]) * (p[k] - o[k] * kUnit);
      v += (c3[k] - o[k]) * (p[k] - o[k] * kUnit);
    }
    return make_key(TemplateNodeKey::face, f, u, v);
  }
  return make_key(TemplateNodeKey::interior, hex, p[0] * (kUnit + 1) + p[1], p[2]);
}

int32_t* TemplateRefiner::slot_of(const TemplateNodeKey& key) {
  // Slots cover the positions templates use on whole hexes and on the first level of
  // sub-cells: thirds and halves (sixths 2, 3, 4) along an edge and in both directions of a
  // face. 1/6 and 5/6 occur only deeper or at adjustments and go to the hash table.
  constexpr int64_t sixth = kUnit / 6;
  auto index = [](int64_t x) -> int {
    if (x % sixth != 0) return -1;
    const int64_t i = x / sixth - 2;
    return i >= 0 && i < 3 ? static_cast<int>(i) : -1;
  };
  const int64_t id = key.entity & 0xFFFFFFFFFF;
  switch (key.kind()) {
    case TemplateNodeKey::edge: {
      const int i = index(key.a);
      return i < 0 ? nullptr : &edge_slot_[3 * id + i];
    }
    case TemplateNodeKey::face: {
      const int i = index(key.a), j = index(key.b);
      if (i < 0 || j < 0) return nullptr;
      int32_t& base = face_base_[id];
      if (base < 0) {
        base = static_cast<int32_t>(face_slot_.size());
        face_slot_.resize(face_slot_.size() + 9, -1);
      }
      return &face_slot_[base + 3 * i + j];
    }
    default:
      return nullptr;
  }
}

const TemplateNodeKey* TemplateRefiner::alias_of(const TemplateNodeKey& key) const {
  if (aliases_.empty()) return nullptr;
  if (key.kind() == TemplateNodeKey::face) {
    // Empty while every alias so far starts from a non-face key.
    if (face_aliased_.empty() || !face_aliased_[key.entity & 0xFFFFFFFFFF]) return nullptr;
  } else if (other_aliases_ == 0) {
    return nullptr;
  }
  const auto it = aliases_.find(key);
  return it == aliases_.end() ? nullptr : &it->second;
}

int32_t TemplateRefiner::find_node(const TemplateNodeKey& key) {
  if (key.kind() == TemplateNodeKey::corner) return static_cast<int32_t>(key.entity & 0xFFFFFFFFFF);
  if (const int32_t* s = slot_of(key)) return *s;
  const auto it = nodes_.find(key);
  return it == nodes_.end() ? -1 : it->second;
}

int32_t TemplateRefiner::create_node(const TemplateNodeKey& key, const Eigen::Vector3d& x) {
  points_.push_back(x);
  if (record_keys_) created_keys_.push_back(key);
  return static_cast<int32_t>(points_.size() - 1);
}

bool TemplateRefiner::alias(const TemplateNodeKey& from, const TemplateNodeKey& to) {
  // Too late if a node was already created under `from`: cells made before would keep it.
  if (find_node(from) >= 0) return false;
  auto [it, inserted] = aliases_.emplace(from, to);
  if (inserted) {
    if (from.kind() == TemplateNodeKey::face) {
      if (face_aliased_.empty()) face_aliased_.assign(topology_.face_count(), 0);
      face_aliased_[from.entity & 0xFFFFFFFFFF] = 1;
    } else {
      ++other_aliases_;
    }
  }
  return inserted || it->second == to;
}

int32_t TemplateRefiner::node_of(const TemplateNodeKey& key, const Eigen::Vector3d& x,
                                 bool* aliased) {
  return node_at(
      key, [&] { return x; }, aliased);
}

template <class Position>
int32_t TemplateRefiner::node_at(const TemplateNodeKey& key, const Position& position,
                                 bool* aliased) {
  const TemplateNodeKey* target = alias_of(key);
  if (target && aliased) *aliased = true;
  const TemplateNodeKey& k = target ? *target : key;
  if (k.kind() == TemplateNodeKey::corner) return static_cast<int32_t>(k.entity & 0xFFFFFFFFFF);
  if (int32_t* s = slot_of(k)) {
    if (*s < 0) *s = create_node(k, position());
    return *s;
  }
  const auto [it, inserted] = nodes_.emplace(k, static_cast<int32_t>(points_.size()));
  if (inserted) create_node(k, position());
  return it->second;
}

TemplateNodeKey TemplateRefiner::key_of_template_node(const TemplateCell& cell, int symmetry,
                                                      const TemplateNode& tn) const {
  const CubeSymmetry& s = cube_symmetries()[symmetry];
  if (tn.adjustment_edge >= 0 && cell.whole && !adjustment_by_position_) {
    const int32_t h = cell.hex;
    const int le = s.edge[tn.adjustment_edge];
    const int32_t e = topology_.hex_edge_ids[h][le];
    const bool same_direction = mesh_.hexes[h][hex_edges[le][0]] == topology_.edge_nodes[e][0];
    const bool canonical_same = s.vertex[hex_edges[tn.adjustment_edge][0]] == hex_edges[le][0];
    return key_adjustment(
        e, (same_direction == canonical_same) ? tn.adjustment_index : 1 - tn.adjustment_index);
  }
  const std::array<double, 3> p = cube_symmetry_apply(s, tn.ref);
  std::array<int64_t, 3> p6{};
  for (int k = 0; k < 3; ++k) {
    p6[k] = std::lround(6.0 * p[k]);
    if (std::abs(6.0 * p[k] - double(p6[k])) > 1e-9)
      throw OperationError("hex " + std::to_string(cell.hex) + ": template node off the grid");
  }
  TemplateParam param;
  if (!cell.exact || !cell_map_sixths(cell, p6, param))
    throw OperationError("hex " + std::to_string(cell.hex) + ": sub-hex nested too deep");
  if ((p6[0] % 6 == 0) && (p6[1] % 6 == 0) && (p6[2] % 6 == 0) && tn.adjustment_edge < 0)
    return cell.key[vertex_of({int(p6[0] / 6), int(p6[1] / 6), int(p6[2] / 6)})];
  return key_at(cell.hex, param);
}

void TemplateRefiner::apply(const TemplateCell& cell, const HexTemplate& t, int symmetry,
                            std::vector<TemplateCell>& children,
                            std::vector<TemplateNodeKey>* node_keys) {
  const CubeSymmetry& s = cube_symmetries()[symmetry];
  const int32_t h = cell.hex;
  const HexCell& input = mesh_.hexes[h];
  const std::array<Eigen::Vector3d, 8> x = hex_points(mesh_, h);
  std::array<Eigen::Vector3d, 8> xc;
  for (int v = 0; v < 8; ++v) xc[v] = points_[cell.nodes[v]];
  auto fail = [&](const std::string& why) {
    throw OperationError("hex " + std::to_string(h) + " (" + template_tag_name(t.tag) +
                         "): " + why);
  };
  if (!cell.exact && !cell.whole) fail("a sub-hex with inexact corners cannot be refined again");

  std::vector<Placed>& placed = placed_;
  placed.resize(t.nodes.size());
  for (size_t i = 0; i < t.nodes.size(); ++i) {
    const TemplateNode& tn = t.nodes[i];
    const std::array<double, 3> p = cube_symmetry_apply(s, tn.ref);
    Placed& out = placed[i];
    out.aliased = false;
    std::array<int64_t, 3> p6{};
    bool on_grid = true;
    for (int k = 0; k < 3; ++k) {
      p6[k] = std::lround(6.0 * p[k]);
      on_grid = on_grid && std::abs(6.0 * p[k] - double(p6[k])) < 1e-9;
    }
    out.exact = on_grid && cell.exact && cell_map_sixths(cell, p6, out.param);
    int corner = -1;
    if (on_grid && (p6[0] % 6 == 0) && (p6[1] % 6 == 0) && (p6[2] % 6 == 0))
      corner = vertex_of({int(p6[0] / 6), int(p6[1] / 6), int(p6[2] / 6)});
    if (corner >= 0 && tn.adjustment_edge < 0) {
      out.node = cell.nodes[corner];
      out.param = cell.param[corner];
      out.key = cell.key[corner];
      out.exact = cell.exact;
      continue;
    }
    const Eigen::Vector3d position =
        out.exact ? trilinear(x, param_to_ref(out.param)) : trilinear(xc, p);
    if (tn.adjustment_edge >= 0) {
      if (cell.whole && !adjustment_by_position_) {
        const int le = s.edge[tn.adjustment_edge];
        const int32_t e = topology_.hex_edge_ids[h][le];
        // Adjustment index in the edge's global direction.
        const bool same_direction = input[hex_edges[le][0]] == topology_.edge_nodes[e][0];
        const bool canonical_same = s.vertex[hex_edges[tn.adjustment_edge][0]] == hex_edges[le][0];
        const int k =
            (same_direction == canonical_same) ? tn.adjustment_index : 1 - tn.adjustment_index;
        out.key = key_adjustment(e, k);
      } else {
        if (!out.exact) fail("adjustment node off the exact grid");
        out.key = key_at(h, out.param);
      }
      out.node = node_of(out.key, position, nullptr);
      points_[out.node] = position;  // the owner places its adjustment nodes
      continue;
    }
    if (!out.exact) {
      // Off the grid: only an interior node of a cell that is not refined again.
      bool interior = true;
      for (int k = 0; k < 3; ++k) interior = interior && p[k] > 1e-12 && p[k] < 1 - 1e-12;
      if (!interior) fail("a node on the cell's boundary is off the exact grid");
      out.key = make_key(TemplateNodeKey::fresh, static_cast<int32_t>(points_.size()));
      out.node = create_node(out.key, position);
      continue;
    }
    out.key = key_at(h, out.param);
    out.node = node_of(out.key, position, &out.aliased);
  }

  for (size_t i = 0; i < placed.size(); ++i)
    for (size_t j = i + 1; j < placed.size(); ++j)
      if (placed[i].node == placed[j].node)
        fail("two template nodes fall on one node (the cell is degenerate)");
  if (node_keys) {
    node_keys->resize(placed.size());
    for (size_t i = 0; i < placed.size(); ++i) (*node_keys)[i] = placed[i].key;
  }
  for (const auto& child : t.children) {
    std::array<int16_t, 8> c = child;
    if (s.reflection) c = {c[0], c[3], c[2], c[1], c[4], c[7], c[6], c[5]};
    TemplateCell out;
    out.hex = h;
    out.whole = false;
    out.exact = true;
    for (int k = 0; k < 8; ++k) {
      const Placed& pl = placed[c[k]];
      out.nodes[k] = pl.node;
      out.param[k] = pl.param;
      out.key[k] = pl.key;
      out.exact = out.exact && pl.exact;
      out.collapsed = out.collapsed || pl.aliased;
    }
    // Local axes of the child: the template's sheet classes (canonical axes), mapped by the
    // symmetry to the cell's axes, then to the input hex's. A reflection swaps the child's
    // local x and y (the re-ordering above).
    const size_t ci = static_cast<size_t>(&child - t.children.data());
    for (int k = 0; k < 3; ++k) {
      const int kt = s.reflection ? (k == 0 ? 1 : k == 1 ? 0 : 2) : k;
      const int cls = t.child_axis.empty() ? -1 : t.child_axis[ci][kt];
      int8_t mapped = -1;
      if (cls >= 0)
        for (int m = 0; m < 3; ++m)
          if (s.axis[m] == cls) mapped = cell.axis[m];
      out.axis[k] = mapped;
    }
    children.push_back(out);
  }
}

void TemplateRefiner::apply_whole(int32_t h, const HexTemplate& t, int symmetry,
                                  bool interior_private, std::vector<HexCell>& children) {
  const HexCell& input = mesh_.hexes[h];
  bool distinct = true;
  for (int a = 0; a < 8; ++a)
    for (int b = a + 1; b < 8; ++b) distinct = distinct && input[a] != input[b];
  if (t.plans.empty() || t.plans[symmetry].generic || !distinct) {
    std::vector<TemplateCell> cells;
    apply(cell_whole(h), t, symmetry, cells);
    for (const TemplateCell& c : cells) children.push_back(c.nodes);
    return;
  }
  const TemplatePlan& plan = t.plans[symmetry];
  std::array<Eigen::Vector3d, 8> x;
  for (int v = 0; v < 8; ++v) x[v] = mesh_.points[input[v]];
  // The canonical frame of each face (as key_at): origin vertex and the u and v neighbours.
  std::array<std::array<int8_t, 3>, 6> frame;
  for (int lf = 0; lf < 6; ++lf) frame[lf][0] = -1;
  bool aliased = false;
  const bool direct = plan.slotted && aliases_.empty() && !record_keys_;
  placed_ids_.resize(plan.nodes.size());
  for (size_t i = 0; i < plan.nodes.size(); ++i) {
    const TemplatePlanNode& n = plan.nodes[i];
    auto position = [&] {
      Eigen::Vector3d out = Eigen::Vector3d::Zero();
      for (int v = 0; v < 8; ++v) out += n.weight[v] * x[v];
      return out;
    };
    int32_t id = -1;
    switch (n.kind) {
      case TemplateNodeKey::corner:
        id = input[n.local];
        break;
      case TemplateNodeKey::edge:
      case TemplateNodeKey::face:
        if (direct) {
          // Nobody needs the key: straight to the slot.
          int32_t& s = plan_node_slot(h, n, frame);
          if (s < 0) s = create_node(TemplateNodeKey{}, position());
          id = s;
        } else {
          id = node_at(plan_node_key(h, n, frame), position, &aliased);
        }
        break;
      default: {
        const TemplateNodeKey key = make_key(TemplateNodeKey::interior, h,
                                             n.param[0] * (kUnit + 1) + n.param[1], n.param[2]);
        id = interior_private ? create_node(key, position()) : node_at(key, position, &aliased);
        break;
      }
    }
    placed_ids_[i] = id;
  }
  if (aliased)
    for (size_t i = 0; i < placed_ids_.size(); ++i)
      for (size_t j = i + 1; j < placed_ids_.size(); ++j)
        if (placed_ids_[i] == placed_ids_[j])
          throw OperationError("hex " + std::to_string(h) + " (" + template_tag_name(t.tag) +
                               "): two template nodes fall on one node (the cell is degenerate)");
  for (const auto& c : plan.children) {
    HexCell out;
    for (int k = 0; k < 8; ++k) out[k] = placed_ids_[c[k]];
    children.push_back(out);
  }
}

namespace {

// The canonical frame of local face lf of a hex with node ids `input` (as key_at): origin at its
// lowest node id, u towards the lower-id neighbour; computed once per face and hex
// (frame[lf][0] < 0: not yet). Returns {origin, u corner, v corner} as local vertices.
const std::array<int8_t, 3>& face_frame(const HexCell& input, int lf,
                                        std::array<std::array<int8_t, 3>, 6>& frame) {
  auto& fr = frame[lf];
  if (fr[0] < 0) {
    int i0 = 0;
    for (int c = 1; c < 4; ++c)
      if (input[hex_faces[lf][c]] < input[hex_faces[lf][i0]]) i0 = c;
    const int step =
        input[hex_faces[lf][(i0 + 1) % 4]] < input[hex_faces[lf][(i0 + 3) % 4]] ? 1 : 3;
    fr = {static_cast<int8_t>(hex_faces[lf][i0]),
          static_cast<int8_t>(hex_faces[lf][(i0 + step) % 4]),
          static_cast<int8_t>(hex_faces[lf][(i0 + 3 * step) % 4])};
  }
  return fr;
}

// Position (in `unit`s of the edge) of a point whose coordinate along local edge le's axis is
// `along`, measured in the edge's global direction (from its lower node id).
int64_t edge_position(const HexCell& input, const std::array<int32_t, 2>& edge_nodes, int le,
                      int64_t along, int64_t unit) {
  int64_t t = hex_corner[hex_edges[le][0]][hex_edge_axis[le]] ? unit - along : along;
  if (input[hex_edges[le][0]] != edge_nodes[0]) t = unit - t;
  return t;
}

// Coordinates (u, v) (in `unit`s of the face) of point p (in `unit`s of the hex) in a face frame.
template <class Point>
std::array<int64_t, 2> face_position(const std::array<int8_t, 3>& fr, const Point& p,
                                     int64_t unit) {
  const int* o = hex_corner[fr[0]];
  const int* c1 = hex_corner[fr[1]];
  const int* c3 = hex_corner[fr[2]];
  std::array<int64_t, 2> uv{0, 0};
  for (int k = 0; k < 3; ++k) {
    uv[0] += (c1[k] - o[k]) * (p[k] - o[k] * unit);
    uv[1] += (c3[k] - o[k]) * (p[k] - o[k] * unit);
  }
  return uv;
}

}  // namespace

int32_t& TemplateRefiner::plan_node_slot(int32_t h, const TemplatePlanNode& n,
                                         std::array<std::array<int8_t, 3>, 6>& frame) {
  const HexCell& input = mesh_.hexes[h];
  if (n.kind == TemplateNodeKey::edge) {
    const int32_t e = topology_.hex_edge_ids[h][n.local];
    const int64_t t6 =
        edge_position(input, topology_.edge_nodes[e], n.local, n.p6[hex_edge_axis[n.local]], 6);
    return edge_slot_[3 * static_cast<size_t>(e) + t6 - 2];
  }
  const auto uv = face_position(face_frame(input, n.local, frame), n.p6, 6);
  int32_t& base = face_base_[topology_.hex_face_ids[h][n.local]];
  if (base < 0) {
    base = static_cast<int32_t>(face_slot_.size());
    face_slot_.resize(face_slot_.size() + 9, -1);
  }
  return face_slot_[base + 3 * (uv[0] - 2) + (uv[1] - 2)];
}

TemplateNodeKey TemplateRefiner::plan_node_key(int32_t h, const TemplatePlanNode& n,
                                               std::array<std::array<int8_t, 3>, 6>& frame) const {
  const HexCell& input = mesh_.hexes[h];
  if (n.kind == TemplateNodeKey::edge) {
    const int32_t e = topology_.hex_edge_ids[h][n.local];
    return make_key(TemplateNodeKey::edge, e,
                    edge_position(input, topology_.edge_nodes[e], n.local,
                                  n.param[hex_edge_axis[n.local]], kUnit));
  }
  const auto uv = face_position(face_frame(input, n.local, frame), n.param, kUnit);
  return make_key(TemplateNodeKey::face, topology_.hex_face_ids[h][n.local], uv[0], uv[1]);
}

void TemplateRefiner::apply_whole_batch(std::span<const TemplateApplication> apps,
                                        std::span<const size_t> child_offset,
                                        std::vector<HexCell>& children, int threads) {
  bool parallel = threads > 1 && aliases_.empty() && apps.size() > 1;
  for (const TemplateApplication& a : apps) {
    if (!parallel) break;
    const HexTemplate& t = *a.tmpl;
    parallel = !t.plans.empty() && !t.plans[a.symmetry].generic && t.plans[a.symmetry].slotted;
    const HexCell& c = mesh_.hexes[a.hex];
    for (int i = 0; i < 8 && parallel; ++i)
      for (int j = i + 1; j < 8; ++j) parallel = parallel && c[i] != c[j];
  }
  if (!parallel) {
    std::vector<HexCell> out;
    for (size_t i = 0; i < apps.size(); ++i) {
      out.clear();
      apply_whole(apps[i].hex, *apps[i].tmpl, apps[i].symmetry, true, out);
      std::copy(out.begin(), out.end(),
                children.begin() + static_cast<std::ptrdiff_t>(child_offset[i]));
    }
    return;
  }
  // 1. Claim node ids in order, exactly as the serial calls would create them.
  const int32_t first_free = static_cast<int32_t>(points_.size());
  std::vector<int32_t> first_new(apps.size() + 1);
  int32_t next = first_free;
  std::array<std::array<int8_t, 3>, 6> frame;
  for (size_t i = 0; i < apps.size(); ++i) {
    first_new[i] = next;
    const TemplatePlan& plan = apps[i].tmpl->plans[apps[i].symmetry];
    for (auto& f : frame) f[0] = -1;
    for (const TemplatePlanNode& n : plan.nodes) {
      if (n.kind == TemplateNodeKey::corner) continue;
      if (n.kind == TemplateNodeKey::interior) {
        ++next;
        continue;
      }
      int32_t& s = plan_node_slot(apps[i].hex, n, frame);
      if (s < 0) s = next++;
    }
  }
  first_new[apps.size()] = next;
  points_.resize(static_cast<size_t>(next));  // Eigen leaves them uninitialised: no page touched
  if (record_keys_) created_keys_.resize(static_cast<size_t>(next) - mesh_.points.size());
  // 2. Positions, keys and children, in contiguous runs of applications.
  auto run = [&](size_t begin, size_t end) {
    std::array<std::array<int8_t, 3>, 6> fr;
    std::vector<int32_t> ids;
    for (size_t i = begin; i < end; ++i) {
      const int32_t h = apps[i].hex;
      const HexCell& input = mesh_.hexes[h];
      const TemplatePlan& plan = apps[i].tmpl->plans[apps[i].symmetry];
      std::array<Eigen::Vector3d, 8> x;
      for (int v = 0; v < 8; ++v) x[v] = mesh_.points[input[v]];
      for (auto& f : fr) f[0] = -1;
      ids.resize(plan.nodes.size());
      int32_t own = first_new[i];
      for (size_t j = 0; j < plan.nodes.size(); ++j) {
        const TemplatePlanNode& n = plan.nodes[j];
        TemplateNodeKey key;
        int32_t id;
        if (n.kind == TemplateNodeKey::corner) {
          ids[j] = input[n.local];
          continue;
        }
        if (n.kind == TemplateNodeKey::interior) {
          key = make_key(TemplateNodeKey::interior, h, n.param[0] * (kUnit + 1) + n.param[1],
                         n.param[2]);
          id = own++;
        } else {
          id = plan_node_slot(h, n, fr);  // every slot was claimed (and allocated) above
          if (id < first_new[i]) {
            ids[j] = id;
            continue;
          }
          ++own;
        }
        ids[j] = id;
        Eigen::Vector3d p = Eigen::Vector3d::Zero();
        for (int v = 0; v < 8; ++v) p += n.weight[v] * x[v];
        points_[id] = p;
        if (record_keys_)
          created_keys_[id - mesh_.points.size()] =
              n.kind == TemplateNodeKey::interior ? key : plan_node_key(h, n, fr);
      }
      HexCell* out = children.data() + child_offset[i];
      for (const auto& c : plan.children) {
        for (int k = 0; k < 8; ++k) (*out)[k] = ids[c[k]];
        ++out;
      }
    }
  };
  const size_t parts = std::min<size_t>(static_cast<size_t>(threads), apps.size());
  // An exception in a worker (only std::bad_alloc can arise) is rethrown here, after the join.
  std::vector<std::exception_ptr> failure(parts);
  auto guarded = [&](size_t p) {
    try {
      run(apps.size() * p / parts, apps.size() * (p + 1) / parts);
    } catch (...) {
      failure[p] = std::current_exception();
    }
  };
  std::vector<std::thread> workers;
  for (size_t p = 1; p < parts; ++p) workers.emplace_back(guarded, p);
  guarded(0);
  for (std::thread& w : workers) w.join();
  for (const std::exception_ptr& e : failure)
    if (e) std::rethrow_exception(e);
}

void template_compile(HexTemplate& t) {
  t.plans.assign(48, {});
  for (int sym = 0; sym < 48; ++sym) {
    const CubeSymmetry& s = cube_symmetries()[sym];
    TemplatePlan& plan = t.plans[sym];
    for (const TemplateNode& tn : t.nodes) {
      TemplatePlanNode n;
      const std::array<double, 3> p = cube_symmetry_apply(s, tn.ref);
      // Exact positions: multiples of 1 / template_param_unit (thirds and sixths of the
      // standard templates, and the finer positions of composites built from them).
      bool on_grid = true;
      int extreme = 0, free_axis = -1, fixed_axis = -1;
      for (int k = 0; k < 3; ++k) {
        const double scaled = p[k] * double(kUnit);
        const int64_t q = std::llround(scaled);
        on_grid = on_grid && std::abs(scaled - double(q)) < 1e-3 && q >= 0 && q <= kUnit;
        n.param[k] = q;
        n.p6[k] = static_cast<int8_t>(q % (kUnit / 6) == 0 ? q / (kUnit / 6) : -1);
        if (q == 0 || q == kUnit) {
          ++extreme;
          fixed_axis = k;
        } else {
          free_axis = k;
        }
      }
      // The same weights as the generic path's trilinear(x, param / unit).
      for (int v = 0; v < 8; ++v) {
        double w = 1.0;
        for (int k = 0; k < 3; ++k) {
          const double r = double(n.param[k]) / kUnit;
          w *= hex_corner[v][k] ? r : 1.0 - r;
        }
        n.weight[v] = w;
      }
      // Slot grid: sixths 2, 3 and 4 (TemplateRefiner::slot_of), in every free coordinate.
      bool slot_grid = true;
      for (int k = 0; k < 3; ++k) {
        const int64_t q = n.param[k];
        if (q == 0 || q == kUnit) continue;
        slot_grid =
            slot_grid && q % (kUnit / 6) == 0 && q / (kUnit / 6) >= 2 && q / (kUnit / 6) <= 4;
      }
      if (tn.adjustment_edge >= 0 || !on_grid) {
        plan.generic = true;
      } else if (extreme == 3) {
        n.kind = TemplateNodeKey::corner;
        n.local = static_cast<int8_t>(
            vertex_of({int(n.param[0] / kUnit), int(n.param[1] / kUnit), int(n.param[2] / kUnit)}));
      } else if (extreme == 2) {
        plan.slotted = plan.slotted && slot_grid;
        n.kind = TemplateNodeKey::edge;
        n.local = static_cast<int8_t>(local_edge_at(
            {double(n.param[0] / kUnit), double(n.param[1] / kUnit), double(n.param[2] / kUnit)},
            free_axis));
      } else if (extreme == 1) {
        plan.slotted = plan.slotted && slot_grid;
        n.kind = TemplateNodeKey::face;
        n.local = static_cast<int8_t>(2 * fixed_axis + (n.param[fixed_axis] == kUnit ? 1 : 0));
      } else {
        n.kind = TemplateNodeKey::interior;
      }
      plan.nodes.push_back(n);
    }
    for (std::array<int16_t, 8> c : t.children) {
      if (s.reflection) c = {c[0], c[3], c[2], c[1], c[4], c[7], c[6], c[5]};
      plan.children.push_back(c);
    }
  }
}

TemplateApplyResult templates_apply(const HexMesh& mesh, const HexTopology& topology,
                                    std::span<const TemplateApplication> applications,
                                    std::span<const TemplateFaceAlias> aliases, int threads) {
  const int32_t nh = mesh.hex_count();
  std::vector<int32_t> application_of(nh, -1);
  for (size_t i = 0; i < applications.size(); ++i) {
    const int32_t h = applications[i].hex;
    if (h < 0 || h >= nh || application_of[h] >= 0)
      throw OperationError("templates_apply: hex " + std::to_string(h) +
                           " is out of range or has two templates");
    application_of[h] = static_cast<int32_t>(i);
  }
  TemplateRefiner refiner(mesh, topology);
  refiner.set_record_keys(false);  // the keys stay inside: nobody reads them
  for (const TemplateFaceAlias& al : aliases)
    for (int k = 0; k < 2; ++k)
      refiner.alias(make_key(TemplateNodeKey::face, al.face, al.face_positions[k][0] * kUnit / 6,
                             al.face_positions[k][1] * kUnit / 6),
                    TemplateRefiner::key_adjustment(al.edge, k));

  TemplateApplyResult out;
  HexMesh& res = out.mesh;
  size_t out_hexes = mesh.hexes.size(), new_nodes = 0;
  for (const TemplateApplication& a : applications) {
    out_hexes += a.tmpl->children.size() - 1;
    new_nodes += a.tmpl->nodes.size();
  }
  refiner.reserve_created(new_nodes);
  // One thread: children appended as they are made. More: slots laid out first, the batch
  // fills the template hexes' slots in parallel.
  const bool parallel = threads > 1;
  if (parallel)
    res.hexes.resize(out_hexes);
  else
    res.hexes.reserve(out_hexes);
  out.parent.reserve(out_hexes);
  std::vector<size_t> offsets;
  std::vector<TemplateApplication> ordered;
  size_t at = 0;
  for (int32_t h = 0; h < nh; ++h) {
    const int32_t a = application_of[h];
    if (a < 0) {
      if (parallel)
        res.hexes[at] = mesh.hexes[h];
      else
        res.hexes.push_back(mesh.hexes[h]);
      ++at;
    } else {
      if (parallel) {
        ordered.push_back(applications[a]);
        offsets.push_back(at);
      } else {
        try {
          refiner.apply_whole(h, *applications[a].tmpl, applications[a].symmetry, true, res.hexes);
        } catch (const OperationError& e) {
          throw OperationError(std::string("templates_apply: ") + e.what());
        }
      }
      at += applications[a].tmpl->children.size();
      out.hexes_created += static_cast<int64_t>(applications[a].tmpl->children.size());
      out.hexes_deleted += 1;
    }
    out.parent.resize(at, h);
  }
  if (parallel) {
    try {
      refiner.apply_whole_batch(ordered, offsets, res.hexes, threads);
    } catch (const OperationError& e) {
      throw OperationError(std::string("templates_apply: ") + e.what());
    }
  }
  res.points = std::move(refiner.points());

  // Attributes: inherited from the parent; template tag and refinement level updated.
  for (const HexAttribute& attr : mesh.attributes) {
    HexAttribute copy{attr.name, std::vector<int32_t>(res.hexes.size())};
    for (size_t i = 0; i < res.hexes.size(); ++i) copy.values[i] = attr.values[out.parent[i]];
    res.attributes.push_back(std::move(copy));
  }
  std::vector<int32_t>& tag = mesh_attribute(res, attribute_template_tag, 0);
  std::vector<int32_t>& level = mesh_attribute(res, attribute_refinement_level, 0);
  for (size_t i = 0; i < res.hexes.size(); ++i) {
    const int32_t a = application_of[out.parent[i]];
    if (a < 0) continue;
    tag[i] = static_cast<int32_t>(applications[a].tmpl->tag);
    const std::vector<int32_t>* in_level = mesh_find_attribute(mesh, attribute_refinement_level);
    level[i] = (in_level ? (*in_level)[out.parent[i]] : 0) + 1;
  }
  return out;
}

void template_compute_child_axes(HexTemplate& t) {
  const int nc = static_cast<int>(t.children.size());
  std::vector<int> parent(3 * nc);
  for (int i = 0; i < 3 * nc; ++i) parent[i] = i;
  auto find = [&](int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  auto local_edge = [&](int c, int16_t a, int16_t b) {
    for (int e = 0; e < 12; ++e) {
      const int16_t x = t.children[c][hex_edges[e][0]], y = t.children[c][hex_edges[e][1]];
      if ((x == a && y == b) || (x == b && y == a)) return e;
    }
    return -1;
  };
  // Children sharing a face: each edge of the face joins the two children's directions.
  std::vector<std::pair<std::array<int16_t, 4>, std::pair<int, int>>> faces;
  for (int c = 0; c < nc; ++c)
    for (int f = 0; f < 6; ++f) {
      std::array<int16_t, 4> q;
      for (int i = 0; i < 4; ++i) q[i] = t.children[c][hex_faces[f][i]];
      std::sort(q.begin(), q.end());
      faces.push_back({q, {c, f}});
    }
  std::sort(faces.begin(), faces.end());
  for (size_t i = 0; i + 1 < faces.size(); ++i) {
    if (faces[i].first != faces[i + 1].first) continue;
    const int ca = faces[i].second.first, fa = faces[i].second.second;
    const int cb = faces[i + 1].second.first;
    for (int k = 0; k < 4; ++k) {
      const int le = hex_face_edges[fa][k];
      const int16_t a = t.children[ca][hex_edges[le][0]], b = t.children[ca][hex_edges[le][1]];
      const int lb = local_edge(cb, a, b);
      if (lb < 0) continue;
      parent[find(3 * ca + hex_edge_axis[le])] = find(3 * cb + hex_edge_axis[lb]);
    }
  }
  // Seeds: a child edge on a cube edge belongs to that edge's axis.
  std::vector<int8_t> root_class(3 * nc, -1);
  for (int c = 0; c < nc; ++c)
    for (int e = 0; e < 12; ++e) {
      const TemplateNode& na = t.nodes[t.children[c][hex_edges[e][0]]];
      const TemplateNode& nb = t.nodes[t.children[c][hex_edges[e][1]]];
      if (na.adjustment_edge >= 0 || nb.adjustment_edge >= 0) continue;
      int fixed = 0, free_axis = -1;
      for (int k = 0; k < 3; ++k) {
        if (is_extreme(na.ref[k]) && std::abs(na.ref[k] - nb.ref[k]) < 1e-12)
          ++fixed;
        else
          free_axis = k;
      }
      if (fixed != 2) continue;
      int8_t& rc = root_class[find(3 * c + hex_edge_axis[e])];
      if (rc < 0) rc = static_cast<int8_t>(free_axis);
    }
  t.child_axis.assign(nc, {-1, -1, -1});
  for (int c = 0; c < nc; ++c)
    for (int k = 0; k < 3; ++k) t.child_axis[c][k] = root_class[find(3 * c + k)];
}

const HexTemplate& template_1_27() {
  static const HexTemplate t = [] {
    HexTemplate r;
    r.tag = TemplateTag::t1_27;
    auto id = [](int i, int j, int k) { return static_cast<int16_t>(i + 4 * (j + 4 * k)); };
    for (int k = 0; k < 4; ++k)
      for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) r.nodes.push_back({{i / 3.0, j / 3.0, k / 3.0}});
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i)
          r.children.push_back({id(i, j, k), id(i + 1, j, k), id(i + 1, j + 1, k), id(i, j + 1, k),
                                id(i, j, k + 1), id(i + 1, j, k + 1), id(i + 1, j + 1, k + 1),
                                id(i, j + 1, k + 1)});
    template_compute_child_axes(r);
    template_compile(r);
    return r;
  }();
  return t;
}

const HexTemplate& template_1_3() {
  static const HexTemplate t = [] {
    HexTemplate r;
    r.tag = TemplateTag::t1_3;
    // Nodes (i/3, j, k): index i + 4 * (j + 2 * k).
    auto id = [](int i, int j, int k) { return static_cast<int16_t>(i + 4 * (j + 2 * k)); };
    for (int k = 0; k < 2; ++k)
      for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 4; ++i) r.nodes.push_back({{i / 3.0, double(j), double(k)}});
    for (int i = 0; i < 3; ++i)
      r.children.push_back({id(i, 0, 0), id(i + 1, 0, 0), id(i + 1, 1, 0), id(i, 1, 0), id(i, 0, 1),
                            id(i + 1, 0, 1), id(i + 1, 1, 1), id(i, 1, 1)});
    template_compute_child_axes(r);
    template_compile(r);
    return r;
  }();
  return t;
}

double template_validate(const HexTemplate& tmpl) {
  auto fail = [&](const std::string& why) {
    throw OperationError(std::string("template ") + template_tag_name(tmpl.tag) + ": " + why);
  };
  double min_sj = 2.0, volume = 0.0;
  std::vector<std::array<int16_t, 4>> faces;
  for (size_t c = 0; c < tmpl.children.size(); ++c) {
    std::array<Eigen::Vector3d, 8> x;
    for (int k = 0; k < 8; ++k) {
      const auto& r = tmpl.nodes.at(tmpl.children[c][k]).ref;
      x[k] = Eigen::Vector3d(r[0], r[1], r[2]);
    }
    const double sj = hex_scaled_jacobian(x);
    if (sj <= 0) fail("child " + std::to_string(c) + " is inverted or degenerate");
    min_sj = std::min(min_sj, sj);
    volume += hex_volume(x);
    for (int f = 0; f < 6; ++f) {
      std::array<int16_t, 4> q;
      for (int i = 0; i < 4; ++i) q[i] = tmpl.children[c][hex_faces[f][i]];
      std::sort(q.begin(), q.end());
      faces.push_back(q);
    }
  }
  std::sort(faces.begin(), faces.end());
  for (size_t i = 0; i + 2 < faces.size(); ++i)
    if (faces[i] == faces[i + 2]) fail("a face is shared by more than two children");
  // Adjustment templates leave a wedge at their unsplit edge to the neighbours (Appendix E).
  bool adjusted = false;
  for (const TemplateNode& n : tmpl.nodes) adjusted |= n.adjustment_edge >= 0;
  if (!adjusted && std::abs(volume - 1.0) > 1e-9)
    fail("children fill volume " + std::to_string(volume) + ", not the unit cube");
  if (adjusted && (volume >= 1.0 - 1e-9 || volume <= 0.5))
    fail("adjusted children fill volume " + std::to_string(volume));
  return min_sj;
}

const HexTemplate& template_1_4() {
  // e0 and e4 split (the two x-edges of face y=0): face y=0 is a 1-3 face, faces z=0 and z=1
  // carry the 1-4 face template (interior nodes at y = 1/2, on the sixths grid of face slots),
  // faces x=0, x=1 and y=1 stay whole: the 2D 1-4 quad template extruded along z.
  static const HexTemplate t = [] {
    TemplateBuilder b(TemplateTag::t1_4);
    // Section points (x, y) of the 2D template, extruded over z in {0, 1}.
    const double sec[8][2] = {{0, 0}, {1 / 3.0, 0}, {2 / 3.0, 0},   {1, 0},
                              {1, 1}, {0, 1},       {1 / 3.0, 0.5}, {2 / 3.0, 0.5}};
    enum { A, P1, P2, B, C, D, Q1, Q2 };
    const int quads[4][4] = {{A, P1, Q1, D}, {P1, P2, Q2, Q1}, {P2, B, C, Q2}, {Q1, Q2, C, D}};
    for (const auto& q : quads) {
      std::array<int16_t, 8> c{};
      for (int k = 0; k < 2; ++k)
        for (int i = 0; i < 4; ++i) c[4 * k + i] = b.node(sec[q[i]][0], sec[q[i]][1], k);
      b.child(c);
    }
    return b.take();
  }();
  return t;
}

const HexTemplate& template_1_5() {
  // e0 split (the x-edge at y=0, z=0): faces y=0 and z=0 carry 1-4 face templates (transition
  // nodes at 1/2), two interior nodes (1/3, 1/2, 1/2) and (2/3, 1/2, 1/2). The two end children
  // hold the whole faces x=0 and x=1; a middle box [1/3,2/3] x [0,1/2]^2 sits on the split edge;
  // two upper children share the face (1/3,h,h) (2/3,h,h) (1,1,1) (0,1,1): one holds face y=1,
  // the other face z=1. Five children.
  static const HexTemplate t = [] {
    TemplateBuilder b(TemplateTag::t1_5);
    const double h = 0.5;
    // Section (y, z) at x: the whole face, and the small square [0,h]^2.
    auto whole = [&](double x) {
      return std::array<int16_t, 4>{b.node(x, 0, 0), b.node(x, 1, 0), b.node(x, 1, 1),
                                    b.node(x, 0, 1)};
    };
    auto small = [&](double x) {
      return std::array<int16_t, 4>{b.node(x, 0, 0), b.node(x, h, 0), b.node(x, h, h),
                                    b.node(x, 0, h)};
    };
    const double x1 = 1 / 3.0, x2 = 2 / 3.0;
    b.child(whole(0), small(x1));
    b.child(small(x1), small(x2));
    b.child(small(x2), whole(1));
    const int16_t i1 = b.node(x1, h, h), i2 = b.node(x2, h, h);
    const int16_t top0 = b.node(0, 1, 1), top1 = b.node(1, 1, 1);
    // Holds face y=1: bottom quad on z=0.
    b.child(
        {b.node(x1, h, 0), b.node(x2, h, 0), b.node(1, 1, 0), b.node(0, 1, 0), i1, i2, top1, top0});
    // Holds face z=1: bottom quad on y=0.
    b.child(
        {b.node(x1, 0, h), b.node(x2, 0, h), b.node(1, 0, 1), b.node(0, 0, 1), i1, i2, top1, top0});
    return b.take();
  }();
  return t;
}

const HexTemplate& template_1_13() {
  // The four edges of face z=0 split: 1-9 on the bottom, 1-4 face templates on the four sides
  // (transition nodes at z = 1/2), top face whole. Nine bottom-layer hexes over the 3x3 bottom
  // grid (the corner ones reach the top corners, since each side's quad (A, P1, Q1, D) holds the
  // whole vertical edge) whose tops meet at four interior nodes (i/3, j/3, t); the upper region,
  // bounded by 14 quads, is filled by four hexes: two side hexes over the y=0 and y=1 edge-hexes
  // (each also taking the tops of the two adjacent corner hexes), a centre hex whose top joins
  // the x-side transition nodes, and a top hex holding the face z=1. 13 children.
  static const HexTemplate t = template_1_13_build(template_1_13_interior_height);
  return t;
}

HexTemplate template_1_13_build(double interior_height) {
  {
    TemplateBuilder b(TemplateTag::t1_13);
    const double h = 0.5, tz = interior_height;
    // Top node of bottom-layer grid line (i, j), i, j in 0..3.
    auto top = [&](int i, int j) {
      const bool ei = i == 0 || i == 3, ej = j == 0 || j == 3;
      const double z = (ei && ej) ? 1.0 : (ei || ej) ? h : tz;
      return b.node(i / 3.0, j / 3.0, z);
    };
    auto bottom = [&](int i, int j) { return b.node(i / 3.0, j / 3.0, 0); };
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i)
        b.child({bottom(i, j), bottom(i + 1, j), bottom(i + 1, j + 1), bottom(i, j + 1), top(i, j),
                 top(i + 1, j), top(i + 1, j + 1), top(i, j + 1)});
    const int16_t c00 = b.node(0, 0, 1), c10 = b.node(1, 0, 1), c11 = b.node(1, 1, 1),
                  c01 = b.node(0, 1, 1);
    b.child({top(1, 0), top(2, 0), top(2, 1), top(1, 1), c00, c10, top(3, 1), top(0, 1)});
    b.child({top(1, 3), top(2, 3), top(2, 2), top(1, 2), c01, c11, top(3, 2), top(0, 2)});
    b.child(
        {top(1, 1), top(2, 1), top(2, 2), top(1, 2), top(0, 1), top(3, 1), top(3, 2), top(0, 2)});
    b.child({top(0, 1), top(3, 1), top(3, 2), top(0, 2), c00, c10, c11, c01});
    return b.take();
  }
}

namespace {

// The three slabs across x of the adjusted 1-3 templates: the end slabs hold the whole faces
// x=0 and x=1, inner sections are the quad `section` (y, z) whose corners at adjusted edges are
// adjustment nodes (index 0 at x=1/3, 1 at x=2/3).
HexTemplate template_adjusted_slabs(TemplateTag tag,
                                    const std::array<std::array<double, 2>, 4>& sec,
                                    const std::array<int, 4>& adjust_edge) {
  TemplateBuilder b(tag);
  auto whole = [&](double x) {
    return std::array<int16_t, 4>{b.node(x, 0, 0), b.node(x, 1, 0), b.node(x, 1, 1),
                                  b.node(x, 0, 1)};
  };
  std::array<std::array<int16_t, 4>, 2> inner;
  for (int k = 0; k < 2; ++k) {
    const double x = (k + 1) / 3.0;
    for (int c = 0; c < 4; ++c)
      inner[k][c] = adjust_edge[c] >= 0 ? b.adjustment(adjust_edge[c], k, x, sec[c][0], sec[c][1])
                                        : b.node(x, sec[c][0], sec[c][1]);
  }
  b.child(whole(0), inner[0]);
  b.child(inner[0], inner[1]);
  b.child(inner[1], whole(1));
  return b.take();
}

}  // namespace

const HexTemplate& template_1_3_adjust1() {
  // x-edges e0 (y0 z0), e2 (y1 z0), e4 (y0 z1) split, e6 (y1 z1) not. Faces y=0 and z=0 are 1-3
  // faces, faces y=1 and z=1 carry 1-4 face templates whose top quads both touch e6: the
  // adjustment (Parrish, Figure E-21) merges their transition nodes into two adjustment nodes
  // (x, q, q) inside the hex, so the two top quads become one face shared by the neighbours
  // across y=1 and z=1 (TemplateFaceAlias). Three slabs with section (0,0) (1,0) (q,q) (0,1).
  static const HexTemplate t = template_adjusted_slabs(
      TemplateTag::t1_3_adjust1,
      {{{0, 0}, {1, 0}, {template_adjustment_depth, template_adjustment_depth}, {0, 1}}},
      {-1, -1, 6, -1});
  return t;
}

const HexTemplate& template_1_3_adjust2() {
  // x-edges e0 (y0 z0) and e6 (y1 z1) split: all four side faces carry 1-4 face templates;
  // adjustments at e2 (y1 z0: faces y=1 and z=0 merged) and at e4 (y0 z1: faces y=0 and z=1).
  // Three slabs with section (0,0) (q,1-q) (1,1) (1-q,q).
  const double q = template_adjustment_depth;
  static const HexTemplate t = template_adjusted_slabs(
      TemplateTag::t1_3_adjust2, {{{0, 0}, {q, 1 - q}, {1, 1}, {1 - q, q}}}, {-1, 2, -1, 4});
  return t;
}

}  // namespace hexrefine

namespace hexrefine {

TemplateChoice template_for_mask(uint16_t mask) {
  static const std::array<TemplateChoice, 4096> table = [] {
    std::array<TemplateChoice, 4096> out{};
    const HexTemplate* all[] = {&template_1_27(),       &template_1_13(), &template_1_5(),
                                &template_1_4(),        &template_1_3(),  &template_1_3_adjust1(),
                                &template_1_3_adjust2()};
    for (const HexTemplate* t : all) {
      const uint16_t canonical = template_split_edges(*t);
      for (int s = 0; s < 48; ++s) {
        const uint16_t m = cube_symmetry_edge_mask(cube_symmetries()[s], canonical);
        if (!out[m].tmpl) out[m] = {t, static_cast<int8_t>(s)};
      }
    }
    return out;
  }();
  return table[mask & 0xFFF];
}

}  // namespace hexrefine
