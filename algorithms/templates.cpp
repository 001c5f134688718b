#include "algorithms/templates.hpp"

#include <algorithm>
#include <cmath>

#include "mesh/error.hpp"
#include "mesh/hex_convention.hpp"

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

// Node slots: an edge holds up to 4 keyed nodes (split positions in sixths, and adjustment
// nodes), a face up to 4 (the 1-9 face template's interior nodes).
constexpr int kEdgeSlots = 4;
constexpr int kFaceSlots = 4;
constexpr int kAdjustmentCode = 10;  // edge slot code of adjustment node k: kAdjustmentCode + k

struct Slot {
  int32_t code = -1;
  int32_t node = -1;
};

class NodeTable {
 public:
  NodeTable(int32_t edges, int32_t faces) : edge_block_(edges, -1), face_block_(faces, -1) {}

  // Returns the slot for `code` in the block of entity `id`, creating block and slot as needed;
  // nullptr if the block is full.
  Slot* edge_slot(int32_t id, int32_t code) {
    return find(edge_block_, edge_slots_, kEdgeSlots, id, code);
  }
  Slot* face_slot(int32_t id, int32_t code) {
    return find(face_block_, face_slots_, kFaceSlots, id, code);
  }

 private:
  static Slot* find(std::vector<int32_t>& block, std::vector<Slot>& slots, int capacity, int32_t id,
                    int32_t code) {
    if (block[id] < 0) {
      block[id] = static_cast<int32_t>(slots.size());
      slots.resize(slots.size() + capacity);
    }
    Slot* b = slots.data() + block[id];
    for (int i = 0; i < capacity; ++i) {
      if (b[i].code == code) return &b[i];
      if (b[i].code < 0) {
        b[i].code = code;
        return &b[i];
      }
    }
    return nullptr;
  }
  std::vector<int32_t> edge_block_, face_block_;
  std::vector<Slot> edge_slots_, face_slots_;
};

// Canonical (u6, v6) code of a point with bilinear weights w[i] on the face corners whose global
// ids are g[i] (in the hex's local face order).
int32_t face_code(const std::array<int32_t, 4>& g, const std::array<double, 4>& w) {
  int i0 = 0;
  for (int i = 1; i < 4; ++i)
    if (g[i] < g[i0]) i0 = i;
  const int step = g[(i0 + 1) % 4] < g[(i0 + 3) % 4] ? 1 : 3;
  std::array<double, 4> c{};
  for (int k = 0; k < 4; ++k) c[k] = w[(i0 + k * step) % 4];
  const int u6 = static_cast<int>(std::lround(6.0 * (c[1] + c[2])));
  const int v6 = static_cast<int>(std::lround(6.0 * (c[2] + c[3])));
  return u6 * 7 + v6;
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

  HexTemplate take() { return std::move(t_); }

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

TemplateApplyResult templates_apply(const HexMesh& mesh, const HexTopology& topology,
                                    std::span<const TemplateApplication> applications,
                                    std::span<const TemplateFaceAlias> aliases) {
  const int32_t nh = mesh.hex_count();
  std::vector<int32_t> application_of(nh, -1);
  for (size_t i = 0; i < applications.size(); ++i) {
    const int32_t h = applications[i].hex;
    if (h < 0 || h >= nh || application_of[h] >= 0)
      throw OperationError("templates_apply: hex " + std::to_string(h) +
                           " is out of range or has two templates");
    application_of[h] = static_cast<int32_t>(i);
  }

  // Face aliases: face-template nodes redirected to an edge's adjustment nodes.
  std::vector<int32_t> alias_of_face;
  if (!aliases.empty()) {
    alias_of_face.assign(topology.face_count(), -1);
    for (size_t i = 0; i < aliases.size(); ++i)
      alias_of_face[aliases[i].face] = static_cast<int32_t>(i);
  }

  TemplateApplyResult out;
  HexMesh& res = out.mesh;
  res.points = mesh.points;
  res.hexes.reserve(mesh.hexes.size());
  out.parent.reserve(mesh.hexes.size());
  NodeTable table(topology.edge_count(), topology.face_count());
  const auto& symmetries = cube_symmetries();

  auto new_point = [&](const Eigen::Vector3d& x) {
    res.points.push_back(x);
    return static_cast<int32_t>(res.points.size() - 1);
  };

  std::vector<int32_t> node_ids;
  for (int32_t h = 0; h < nh; ++h) {
    const int32_t a = application_of[h];
    if (a < 0) {
      res.hexes.push_back(mesh.hexes[h]);
      out.parent.push_back(h);
      continue;
    }
    const TemplateApplication& app = applications[a];
    const HexTemplate& t = *app.tmpl;
    const CubeSymmetry& s = symmetries[app.symmetry];
    const HexCell& cell = mesh.hexes[h];
    const std::array<Eigen::Vector3d, 8> x = hex_points(mesh, h);
    auto fail = [&](const std::string& why) {
      throw OperationError("templates_apply: hex " + std::to_string(h) + " (" +
                           template_tag_name(t.tag) + "): " + why);
    };
    node_ids.assign(t.nodes.size(), -1);
    for (size_t i = 0; i < t.nodes.size(); ++i) {
      const TemplateNode& tn = t.nodes[i];
      const std::array<double, 3> p = cube_symmetry_apply(s, tn.ref);
      if (tn.adjustment_edge >= 0) {
        const int le = s.edge[tn.adjustment_edge];
        const int32_t e = topology.hex_edge_ids[h][le];
        // Adjustment index in the edge's global direction.
        const bool same_direction = cell[hex_edges[le][0]] == topology.edge_nodes[e][0];
        const bool canonical_same = s.vertex[hex_edges[tn.adjustment_edge][0]] == hex_edges[le][0];
        const int k =
            (same_direction == canonical_same) ? tn.adjustment_index : 1 - tn.adjustment_index;
        Slot* slot = table.edge_slot(e, kAdjustmentCode + k);
        if (!slot) fail("too many nodes on edge " + std::to_string(e));
        if (slot->node < 0) slot->node = new_point(trilinear(x, p));
        node_ids[i] = slot->node;
        continue;
      }
      int extreme = 0, free_axis = -1, fixed_axis = -1;
      for (int k = 0; k < 3; ++k) {
        if (is_extreme(p[k])) {
          ++extreme;
          fixed_axis = k;
        } else {
          free_axis = k;
        }
      }
      if (extreme == 3) {
        node_ids[i] = cell[vertex_of(
            {int(std::lround(p[0])), int(std::lround(p[1])), int(std::lround(p[2]))})];
      } else if (extreme == 2) {
        const int le = local_edge_at(p, free_axis);
        const int32_t e = topology.hex_edge_ids[h][le];
        int k6 = static_cast<int>(std::lround(6.0 * p[free_axis]));
        if (cell[hex_edges[le][0]] != topology.edge_nodes[e][0]) k6 = 6 - k6;
        Slot* slot = table.edge_slot(e, k6);
        if (!slot) fail("too many nodes on edge " + std::to_string(e));
        if (slot->node < 0) slot->node = new_point(trilinear(x, p));
        node_ids[i] = slot->node;
      } else if (extreme == 1) {
        const int lf = 2 * fixed_axis + static_cast<int>(std::lround(p[fixed_axis]));
        const int32_t f = topology.hex_face_ids[h][lf];
        std::array<int32_t, 4> g{};
        std::array<double, 4> w{};
        for (int c = 0; c < 4; ++c) {
          const int v = hex_faces[lf][c];
          g[c] = cell[v];
          double wc = 1.0;
          for (int k = 0; k < 3; ++k)
            if (k != fixed_axis) wc *= hex_corner[v][k] ? p[k] : 1.0 - p[k];
          w[c] = wc;
        }
        const int32_t code = face_code(g, w);
        Slot* slot = nullptr;
        if (!alias_of_face.empty() && alias_of_face[f] >= 0) {
          const TemplateFaceAlias& al = aliases[alias_of_face[f]];
          for (int k = 0; k < 2; ++k)
            if (al.face_positions[k][0] * 7 + al.face_positions[k][1] == code)
              slot = table.edge_slot(al.edge, kAdjustmentCode + k);
        }
        if (!slot) slot = table.face_slot(f, code);
        if (!slot) fail("too many nodes on face " + std::to_string(f));
        if (slot->node < 0) slot->node = new_point(trilinear(x, p));
        node_ids[i] = slot->node;
      } else {
        node_ids[i] = new_point(trilinear(x, p));
      }
    }
    for (const auto& child : t.children) {
      HexCell c{};
      for (int k = 0; k < 8; ++k) c[k] = node_ids[child[k]];
      if (s.reflection) c = {c[0], c[3], c[2], c[1], c[4], c[7], c[6], c[5]};
      res.hexes.push_back(c);
      out.parent.push_back(h);
    }
    out.hexes_created += static_cast<int64_t>(t.children.size());
    out.hexes_deleted += 1;
  }

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
    return r;
  }();
  return t;
}

}  // namespace hexrefine

namespace hexrefine {

namespace {

// Scaled Jacobian of a hex (Knupp): the minimum over the 8 corners and the centre of the
// determinant of the three unit edge (or principal axis) vectors. 1 for a cube, <= 0 inverted.
double child_scaled_jacobian(const std::array<Eigen::Vector3d, 8>& x) {
  double out = 2.0;
  for (int v = 0; v < 8; ++v) {
    std::array<Eigen::Vector3d, 3> e;
    for (int k = 0; k < 3; ++k) {
      const int edge = hex_vertex_edges[v][k];
      const int w = hex_edges[edge][0] == v ? hex_edges[edge][1] : hex_edges[edge][0];
      // Point along +axis so the triple product of a positive hex is positive.
      e[k] = hex_corner[v][k] ? (x[v] - x[w]) : (x[w] - x[v]);
      const double n = e[k].norm();
      if (n == 0) return -1.0;
      e[k] /= n;
    }
    out = std::min(out, e[0].dot(e[1].cross(e[2])));
  }
  std::array<Eigen::Vector3d, 3> a;
  for (int k = 0; k < 3; ++k) {
    a[k] = Eigen::Vector3d::Zero();
    for (int v = 0; v < 8; ++v) a[k] += (hex_corner[v][k] ? 0.25 : -0.25) * x[v];
    const double n = a[k].norm();
    if (n == 0) return -1.0;
    a[k] /= n;
  }
  return std::min(out, a[0].dot(a[1].cross(a[2])));
}

// Volume of a trilinear hex by 2x2x2 Gauss quadrature of its Jacobian determinant.
double child_volume(const std::array<Eigen::Vector3d, 8>& x) {
  const double g[2] = {0.5 - 0.5 / std::sqrt(3.0), 0.5 + 0.5 / std::sqrt(3.0)};
  double vol = 0;
  for (double r : g)
    for (double s : g)
      for (double t : g) {
        const double p[3] = {r, s, t};
        Eigen::Matrix3d j = Eigen::Matrix3d::Zero();
        for (int v = 0; v < 8; ++v)
          for (int k = 0; k < 3; ++k) {
            double w = hex_corner[v][k] ? 1.0 : -1.0;
            for (int m = 0; m < 3; ++m)
              if (m != k) w *= hex_corner[v][m] ? p[m] : 1.0 - p[m];
            j.col(k) += w * x[v];
          }
        vol += j.determinant() / 8.0;
      }
  return vol;
}

}  // namespace

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
    const double sj = child_scaled_jacobian(x);
    if (sj <= 0) fail("child " + std::to_string(c) + " is inverted or degenerate");
    min_sj = std::min(min_sj, sj);
    volume += child_volume(x);
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

}  // namespace hexrefine
