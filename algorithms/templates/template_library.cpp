/// \file
/// The standard templates as literal tables (M. H. Parrish, "A Selective Approach to Conformal
/// Refinement of Unstructured Hexahedral Meshes", MS thesis, BYU, Appendix E; Harris'
/// directional templates), and the data derived from them once: child sheet axes, compiled
/// plans per cube symmetry, the split-mask table.

#include "algorithms/templates/template_library.hpp"

#include <algorithm>
#include <cmath>
#include <span>
#include <string>

#include "algorithms/templates/template_reference.hpp"
#include "mesh/error.hpp"
#include "mesh/hex_convention.hpp"
#include "mesh/quality.hpp"

namespace hexrefine {

namespace {

/// A node of a literal table: position in sixths; an adjustment node names its canonical edge
/// and index.
struct NodeRow {
  int8_t x, y, z;
  int8_t adjustment_edge = -1;
  int8_t adjustment_index = 0;
};
using ChildRow = std::array<int16_t, 8>;

/// Coordinates in 0..6, every child's indices in range and distinct, every node used by a
/// child, and no two ordinary nodes at one position.
template <size_t N, size_t C>
constexpr bool table_well_formed(const std::array<NodeRow, N>& nodes,
                                 const std::array<ChildRow, C>& children) {
  for (const NodeRow& n : nodes)
    for (int8_t c : {n.x, n.y, n.z})
      if (c < 0 || c > 6) return false;
  for (size_t i = 0; i < N; ++i)
    for (size_t j = i + 1; j < N; ++j)
      if (nodes[i].adjustment_edge < 0 && nodes[j].adjustment_edge < 0 &&
          nodes[i].x == nodes[j].x && nodes[i].y == nodes[j].y && nodes[i].z == nodes[j].z)
        return false;
  std::array<bool, N> used{};
  for (const ChildRow& c : children)
    for (int a = 0; a < 8; ++a) {
      if (c[a] < 0 || static_cast<size_t>(c[a]) >= N) return false;
      used[c[a]] = true;
      for (int b = a + 1; b < 8; ++b)
        if (c[a] == c[b]) return false;
    }
  for (bool u : used)
    if (!u) return false;
  return true;
}

/// An NX x NY x NZ grid of boxes (each count 1 or 3): 1-27, 1-9, 1-3.
template <int NX, int NY, int NZ>
struct GridTable {
  static constexpr size_t node_count = (NX + 1) * (NY + 1) * (NZ + 1);
  std::array<NodeRow, node_count> nodes{};
  std::array<ChildRow, NX * NY * NZ> children{};
};

template <int NX, int NY, int NZ>
constexpr GridTable<NX, NY, NZ> grid_table() {
  GridTable<NX, NY, NZ> t;
  auto id = [](int i, int j, int k) {
    return static_cast<int16_t>(i + (NX + 1) * (j + (NY + 1) * k));
  };
  for (int k = 0; k <= NZ; ++k)
    for (int j = 0; j <= NY; ++j)
      for (int i = 0; i <= NX; ++i)
        t.nodes[id(i, j, k)] = {static_cast<int8_t>(6 * i / NX), static_cast<int8_t>(6 * j / NY),
                                static_cast<int8_t>(6 * k / NZ)};
  size_t c = 0;
  for (int k = 0; k < NZ; ++k)
    for (int j = 0; j < NY; ++j)
      for (int i = 0; i < NX; ++i)
        t.children[c++] = {
            id(i, j, k),     id(i + 1, j, k),     id(i + 1, j + 1, k),     id(i, j + 1, k),
            id(i, j, k + 1), id(i + 1, j, k + 1), id(i + 1, j + 1, k + 1), id(i, j + 1, k + 1)};
  return t;
}

constexpr auto grid_1_27 = grid_table<3, 3, 3>();
constexpr auto grid_1_9 = grid_table<3, 3, 1>();
constexpr auto grid_1_3 = grid_table<3, 1, 1>();
static_assert(table_well_formed(grid_1_27.nodes, grid_1_27.children) && grid_1_27.node_count == 64);
static_assert(table_well_formed(grid_1_9.nodes, grid_1_9.children) && grid_1_9.node_count == 32);
static_assert(table_well_formed(grid_1_3.nodes, grid_1_3.children) && grid_1_3.node_count == 16);

// 1-13 (face z=0 split): 1-9 on the bottom, 1-4 face templates on the four sides (transition
// nodes at z = 1/2), top face whole. Nine bottom-layer hexes over the 3x3 bottom grid (the corner
// ones reach the top corners, since each side's quad holds the whole vertical edge) whose tops
// meet at four interior nodes (i/3, j/3, 1/6); the upper region is filled by four hexes: two side
// hexes over the y=0 and y=1 edge-hexes, a centre hex whose top joins the x-side transition
// nodes, and a top hex holding the face z=1. Nodes 6, 11, 18, 21 are the interior ones.
constexpr std::array<NodeRow, 32> nodes_1_13 = {{
    {0, 0, 0}, {2, 0, 0}, {2, 2, 0}, {0, 2, 0}, {0, 0, 6}, {2, 0, 3}, {2, 2, 1}, {0, 2, 3},
    {4, 0, 0}, {4, 2, 0}, {4, 0, 3}, {4, 2, 1}, {6, 0, 0}, {6, 2, 0}, {6, 0, 6}, {6, 2, 3},
    {2, 4, 0}, {0, 4, 0}, {2, 4, 1}, {0, 4, 3}, {4, 4, 0}, {4, 4, 1}, {6, 4, 0}, {6, 4, 3},
    {2, 6, 0}, {0, 6, 0}, {2, 6, 3}, {0, 6, 6}, {4, 6, 0}, {4, 6, 3}, {6, 6, 0}, {6, 6, 6},
}};
constexpr std::array<ChildRow, 13> children_1_13 = {{
    {0, 1, 2, 3, 4, 5, 6, 7},
    {1, 8, 9, 2, 5, 10, 11, 6},
    {8, 12, 13, 9, 10, 14, 15, 11},
    {3, 2, 16, 17, 7, 6, 18, 19},
    {2, 9, 20, 16, 6, 11, 21, 18},
    {9, 13, 22, 20, 11, 15, 23, 21},
    {17, 16, 24, 25, 19, 18, 26, 27},
    {16, 20, 28, 24, 18, 21, 29, 26},
    {20, 22, 30, 28, 21, 23, 31, 29},
    {5, 10, 11, 6, 4, 14, 15, 7},
    {26, 18, 21, 29, 27, 19, 23, 31},
    {6, 11, 21, 18, 7, 15, 23, 19},
    {7, 15, 23, 19, 4, 14, 31, 27},
}};
static_assert(table_well_formed(nodes_1_13, children_1_13));
constexpr std::array<int, 4> interior_1_13 = {6, 11, 18, 21};

// 1-5 (e0 split): faces y=0 and z=0 carry 1-4 face templates (transition nodes at 1/2), two
// interior nodes (1/3, 1/2, 1/2) and (2/3, 1/2, 1/2). The end children hold the whole faces x=0
// and x=1; a middle box [1/3,2/3] x [0,1/2]^2 sits on the split edge; two upper children share
// the face through the interior nodes and the far edge: one holds face y=1, the other face z=1.
constexpr std::array<NodeRow, 16> nodes_1_5 = {{
    {2, 0, 0},
    {2, 3, 0},
    {2, 3, 3},
    {2, 0, 3},
    {0, 0, 0},
    {0, 6, 0},
    {0, 6, 6},
    {0, 0, 6},
    {4, 0, 0},
    {4, 3, 0},
    {4, 3, 3},
    {4, 0, 3},
    {6, 0, 0},
    {6, 6, 0},
    {6, 6, 6},
    {6, 0, 6},
}};
constexpr std::array<ChildRow, 5> children_1_5 = {{
    {4, 5, 6, 7, 0, 1, 2, 3},
    {0, 1, 2, 3, 8, 9, 10, 11},
    {8, 9, 10, 11, 12, 13, 14, 15},
    {1, 9, 13, 5, 2, 10, 14, 6},
    {3, 7, 15, 11, 2, 6, 14, 10},
}};
static_assert(table_well_formed(nodes_1_5, children_1_5));

// 1-4 (e0 and e4 split: the two x-edges of face y=0): face y=0 is a 1-3 face, faces z=0 and z=1
// carry the 1-4 face template (transition nodes at y = 1/2), faces x=0, x=1 and y=1 stay whole:
// the 2D 1-4 quad template extruded along z.
constexpr std::array<NodeRow, 16> nodes_1_4 = {{
    {0, 0, 0},
    {2, 0, 0},
    {2, 3, 0},
    {0, 6, 0},
    {0, 0, 6},
    {2, 0, 6},
    {2, 3, 6},
    {0, 6, 6},
    {4, 0, 0},
    {4, 3, 0},
    {4, 0, 6},
    {4, 3, 6},
    {6, 0, 0},
    {6, 6, 0},
    {6, 0, 6},
    {6, 6, 6},
}};
constexpr std::array<ChildRow, 4> children_1_4 = {{
    {0, 1, 2, 3, 4, 5, 6, 7},
    {1, 8, 9, 2, 5, 10, 11, 6},
    {8, 12, 13, 9, 10, 14, 15, 11},
    {2, 9, 13, 3, 6, 11, 15, 7},
}};
static_assert(table_well_formed(nodes_1_4, children_1_4));

// The adjusted 1-3 templates: three slabs across x; the end slabs hold the whole faces x=0 and
// x=1, the inner sections are quads (y, z) whose corners at an adjusted edge are adjustment
// nodes at depth q = 5/6 (index 0 at x = 1/3, 1 at x = 2/3).
// One adjustment (e0 e2 e4 split, e6 not): faces y=1 and z=1 carry 1-4 face templates whose top
// quads both touch e6; the adjustment (Figure E-21) merges their transition nodes into the two
// adjustment nodes (x, q, q), so the two top quads become one face shared by the neighbours
// across y=1 and z=1. Section (0,0) (1,0) (q,q) (0,1).
constexpr std::array<NodeRow, 16> nodes_1_3_adjust1 = {{
    {2, 0, 0},
    {2, 6, 0},
    {2, 5, 5, 6, 0},
    {2, 0, 6},
    {4, 0, 0},
    {4, 6, 0},
    {4, 5, 5, 6, 1},
    {4, 0, 6},
    {0, 0, 0},
    {0, 6, 0},
    {0, 6, 6},
    {0, 0, 6},
    {6, 0, 0},
    {6, 6, 0},
    {6, 6, 6},
    {6, 0, 6},
}};
// Two adjustments (e0 e6 split): all four side faces carry 1-4 face templates; adjustments at e2
// (y1 z0: faces y=1 and z=0 merged) and at e4 (y0 z1: faces y=0 and z=1). Section (0,0)
// (q,1-q) (1,1) (1-q,q).
constexpr std::array<NodeRow, 16> nodes_1_3_adjust2 = {{
    {2, 0, 0},
    {2, 5, 1, 2, 0},
    {2, 6, 6},
    {2, 1, 5, 4, 0},
    {4, 0, 0},
    {4, 5, 1, 2, 1},
    {4, 6, 6},
    {4, 1, 5, 4, 1},
    {0, 0, 0},
    {0, 6, 0},
    {0, 6, 6},
    {0, 0, 6},
    {6, 0, 0},
    {6, 6, 0},
    {6, 6, 6},
    {6, 0, 6},
}};
constexpr std::array<ChildRow, 3> children_adjusted = {{
    {8, 9, 10, 11, 0, 1, 2, 3},
    {0, 1, 2, 3, 4, 5, 6, 7},
    {4, 5, 6, 7, 12, 13, 14, 15},
}};
static_assert(table_well_formed(nodes_1_3_adjust1, children_adjusted));
static_assert(table_well_formed(nodes_1_3_adjust2, children_adjusted));
static_assert(6 * template_adjustment_depth == 5, "adjustment rows are written for q = 5/6");

HexTemplate template_from_table(TemplateTag tag, std::span<const NodeRow> nodes,
                                std::span<const ChildRow> children) {
  HexTemplate t;
  t.tag = tag;
  for (const NodeRow& n : nodes)
    t.nodes.push_back({{n.x / 6.0, n.y / 6.0, n.z / 6.0}, n.adjustment_edge, n.adjustment_index});
  t.children.assign(children.begin(), children.end());
  template_compute_child_axes(t);
  return t;
}

constexpr double kOnBoundary = 1e-12;

bool is_extreme(double x) {
  return std::abs(x) < kOnBoundary || std::abs(x - 1.0) < kOnBoundary;
}

// The local edge holding a reference point that lies inside an edge (two coordinates extreme).
int local_edge_at(const std::array<double, 3>& p, int free_axis) {
  std::array<int, 3> lo{}, hi{};
  for (int k = 0; k < 3; ++k) {
    const int c = k == free_axis ? 0 : static_cast<int>(std::lround(p[k]));
    lo[k] = c;
    hi[k] = k == free_axis ? 1 : c;
  }
  return hex_edge_joining(hex_vertex_at(lo[0], lo[1], lo[2]), hex_vertex_at(hi[0], hi[1], hi[2]));
}

}  // namespace

const char* template_tag_name(TemplateTag tag) {
  switch (tag) {
    case TemplateTag::untouched:
      return "untouched";
    case TemplateTag::t1_27:
      return "1-27";
    case TemplateTag::t1_13:
      return "1-13";
    case TemplateTag::t1_5:
      return "1-5";
    case TemplateTag::t1_4:
      return "1-4";
    case TemplateTag::t1_3:
      return "1-3";
    case TemplateTag::t1_3_adjust1:
      return "1-3-adj1";
    case TemplateTag::t1_3_adjust2:
      return "1-3-adj2";
    case TemplateTag::directional:
      return "directional";
    case TemplateTag::sheet:
      return "sheet";
    case TemplateTag::t1_9:
      return "1-9";
  }
  return "unknown";
}

std::array<double, 8> hex_trilinear_weights(const std::array<double, 3>& p) {
  std::array<double, 8> w{};
  for (int v = 0; v < 8; ++v) {
    double x = 1.0;
    for (int k = 0; k < 3; ++k) x *= hex_corner[v][k] ? p[k] : 1.0 - p[k];
    w[v] = x;
  }
  return w;
}

HexTemplate template_standard_exact(TemplateTag tag) {
  switch (tag) {
    case TemplateTag::t1_27:
      return template_from_table(tag, grid_1_27.nodes, grid_1_27.children);
    case TemplateTag::t1_13:
      return template_from_table(tag, nodes_1_13, children_1_13);
    case TemplateTag::t1_5:
      return template_from_table(tag, nodes_1_5, children_1_5);
    case TemplateTag::t1_4:
      return template_from_table(tag, nodes_1_4, children_1_4);
    case TemplateTag::t1_3:
      return template_from_table(tag, grid_1_3.nodes, grid_1_3.children);
    case TemplateTag::t1_3_adjust1:
      return template_from_table(tag, nodes_1_3_adjust1, children_adjusted);
    case TemplateTag::t1_3_adjust2:
      return template_from_table(tag, nodes_1_3_adjust2, children_adjusted);
    case TemplateTag::t1_9:
      return template_from_table(tag, grid_1_9.nodes, grid_1_9.children);
    default:
      throw OperationError(std::string("no standard template ") + template_tag_name(tag));
  }
}

HexTemplate template_standard_build(TemplateTag tag, const TemplateReferenceTable& table) {
  HexTemplate t = template_standard_exact(tag);
  template_reference_from_table(t, table);
  template_compile(t);
  return t;
}

const HexTemplate& template_1_27() {
  return template_library_committed().of(TemplateTag::t1_27);
}

const HexTemplate& template_1_9() {
  return template_library_committed().of(TemplateTag::t1_9);
}

const HexTemplate& template_1_3() {
  return template_library_committed().of(TemplateTag::t1_3);
}

const HexTemplate& template_1_13() {
  return template_library_committed().of(TemplateTag::t1_13);
}

HexTemplate template_1_13_build(double interior_height) {
  HexTemplate t;
  t.tag = TemplateTag::t1_13;
  for (const NodeRow& n : nodes_1_13) t.nodes.push_back({{n.x / 6.0, n.y / 6.0, n.z / 6.0}});
  for (int i : interior_1_13) t.nodes[i].ref[2] = interior_height;
  t.children.assign(children_1_13.begin(), children_1_13.end());
  template_compute_child_axes(t);
  template_compile(t);
  return t;
}

const HexTemplate& template_1_5() {
  return template_library_committed().of(TemplateTag::t1_5);
}

const HexTemplate& template_1_4() {
  return template_library_committed().of(TemplateTag::t1_4);
}

const HexTemplate& template_1_3_adjust1() {
  return template_library_committed().of(TemplateTag::t1_3_adjust1);
}

const HexTemplate& template_1_3_adjust2() {
  return template_library_committed().of(TemplateTag::t1_3_adjust2);
}

bool template_is_adjusted(const HexTemplate& tmpl) {
  return tmpl.tag == TemplateTag::t1_3_adjust1 || tmpl.tag == TemplateTag::t1_3_adjust2;
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

void template_mask_table_fill(std::span<const HexTemplate* const> templates,
                              TemplateMaskTable& out) {
  for (const HexTemplate* t : templates) {
    const uint16_t canonical = template_split_edges(*t);
    for (int s = 0; s < 48; ++s) {
      const uint16_t m = cube_symmetry_edge_mask(cube_symmetries()[s], canonical);
      if (!out[m].tmpl) out[m] = {t, static_cast<int8_t>(s)};
    }
  }
}

std::vector<TemplateTag> template_set_tags(TemplateSet set) {
  if (set == TemplateSet::element_by_element)
    return {TemplateTag::t1_27,       TemplateTag::t1_13, TemplateTag::t1_5,
            TemplateTag::t1_4,        TemplateTag::t1_3,  TemplateTag::t1_3_adjust1,
            TemplateTag::t1_3_adjust2};
  return {TemplateTag::t1_3, TemplateTag::t1_4, TemplateTag::t1_5, TemplateTag::t1_9,
          TemplateTag::t1_27};
}

TemplateChoice template_for_mask(uint16_t mask, TemplateSet set) {
  return template_library_committed().choice(mask, set);
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

void template_compile(HexTemplate& t, int symmetry_count, bool child_quality) {
  constexpr int64_t unit = template_param_unit, sixth = unit / 6;
  if (!t.reference.empty() && t.reference.size() != t.nodes.size())
    throw OperationError(std::string("template ") + template_tag_name(t.tag) + ": " +
                         std::to_string(t.reference.size()) + " reference positions for " +
                         std::to_string(t.nodes.size()) + " nodes");
  t.child_reference_quality.clear();
  t.reference_edge_ratio = 1;
  if (child_quality)
    for (const auto& child : t.children) {
      HexCorners x;
      for (int k = 0; k < 8; ++k) {
        const auto& r = template_node_reference(t, static_cast<size_t>(child[k]));
        x[k] = Eigen::Vector3d(r[0], r[1], r[2]);
      }
      t.child_reference_quality.push_back(hex_scaled_jacobian(x));
      t.reference_edge_ratio = std::max(t.reference_edge_ratio, hex_edge_ratio(x));
    }
  t.plans.assign(static_cast<size_t>(symmetry_count), {});
  for (int sym = 0; sym < symmetry_count; ++sym) {
    const CubeSymmetry& s = cube_symmetries()[sym];
    TemplatePlan& plan = t.plans[sym];
    for (size_t i = 0; i < t.nodes.size(); ++i) {
      const TemplateNode& tn = t.nodes[i];
      TemplatePlanNode n;
      const std::array<double, 3> p = cube_symmetry_apply(s, tn.ref);
      const bool moved = !t.reference.empty() && t.reference[i] != tn.ref;
      const std::array<double, 3> reference_point =
          moved ? cube_symmetry_apply(s, t.reference[i]) : p;
      // Exact positions: multiples of 1 / template_param_unit (thirds and sixths of the standard
      // templates, and the finer positions of templates made of sub-cells).
      bool on_grid = true, inside = true;
      int extreme = 0, free_axis = -1, fixed_axis = -1;
      for (int k = 0; k < 3; ++k) {
        const double scaled = p[k] * double(unit);
        const int64_t q = std::llround(scaled);
        on_grid = on_grid && std::abs(scaled - double(q)) < 1e-3 && q >= 0 && q <= unit;
        inside = inside && p[k] > kOnBoundary && p[k] < 1.0 - kOnBoundary;
        n.param[k] = q;
        n.p6[k] = static_cast<int8_t>(q % sixth == 0 ? q / sixth : -1);
        if (q == 0 || q == unit) {
          ++extreme;
          fixed_axis = k;
        } else {
          free_axis = k;
        }
      }
      if (!on_grid) {
        if (!inside)
          throw OperationError(std::string("template ") + template_tag_name(t.tag) +
                               ": a node on the cube's boundary is off the exact grid");
        n.off_grid = true;
        n.param = {};
        n.p6 = {-1, -1, -1};
        n.weight = hex_trilinear_weights(p);
        n.reference_weight = moved ? hex_trilinear_weights(reference_point) : n.weight;
        plan.nodes.push_back(n);
        continue;
      }
      // The weights of the exact position (the same expression wherever a key is placed).
      n.weight = hex_trilinear_weights(
          {double(n.param[0]) / unit, double(n.param[1]) / unit, double(n.param[2]) / unit});
      n.reference_weight = moved ? hex_trilinear_weights(reference_point) : n.weight;
      // Slot grid: sixths 2, 3 and 4 in every free coordinate.
      bool slot_grid = true;
      for (int k = 0; k < 3; ++k) {
        const int64_t q = n.param[k];
        if (q == 0 || q == unit) continue;
        slot_grid = slot_grid && q % sixth == 0 && q / sixth >= 2 && q / sixth <= 4;
      }
      if (extreme == 3) {
        n.entity = CubeEntity::corner;
        n.local = static_cast<int8_t>(
            hex_vertex_at(int(n.param[0] / unit), int(n.param[1] / unit), int(n.param[2] / unit)));
      } else if (extreme == 2) {
        plan.slotted = plan.slotted && slot_grid;
        n.entity = CubeEntity::edge;
        n.local = static_cast<int8_t>(local_edge_at(
            {double(n.param[0] / unit), double(n.param[1] / unit), double(n.param[2] / unit)},
            free_axis));
      } else if (extreme == 1) {
        plan.slotted = plan.slotted && slot_grid;
        n.entity = CubeEntity::face;
        n.local = static_cast<int8_t>(2 * fixed_axis + (n.param[fixed_axis] == unit ? 1 : 0));
      } else {
        n.entity = CubeEntity::interior;
      }
      plan.nodes.push_back(n);
    }
    for (std::array<int16_t, 8> c : t.children) {
      if (s.reflection) {
        const std::array<int16_t, 8> original = c;
        for (int k = 0; k < 8; ++k) c[k] = original[hex_reflected_order[k]];
      }
      plan.children.push_back(c);
    }
  }
}

double template_validate(const HexTemplate& tmpl, TemplatePositions positions) {
  auto fail = [&](const std::string& why) {
    throw OperationError(std::string("template ") + template_tag_name(tmpl.tag) + ": " + why);
  };
  double min_sj = 2.0, volume = 0.0;
  std::vector<std::array<int16_t, 4>> faces;
  for (size_t c = 0; c < tmpl.children.size(); ++c) {
    HexCorners x;
    for (int k = 0; k < 8; ++k) {
      const size_t i = static_cast<size_t>(tmpl.children[c][k]);
      const auto& r = positions == TemplatePositions::reference ? template_node_reference(tmpl, i)
                                                                : tmpl.nodes.at(i).ref;
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
  // The exact adjustment nodes (depth 5/6) leave a wedge of 1/6 x 1/6 / 2 of the section, more
  // than half the cube always; reference positions may sit deeper.
  const double least = positions == TemplatePositions::exact ? 0.5 : 0.0;
  if (adjusted && (volume >= 1.0 - 1e-9 || volume <= least))
    fail("adjusted children fill volume " + std::to_string(volume));
  return min_sj;
}

}  // namespace hexrefine
