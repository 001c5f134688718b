#include "algorithms/refiners/selective_cells.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "algorithms/templates/template_reference.hpp"
#include "mesh/error.hpp"
#include "mesh/hex_convention.hpp"

namespace hexrefine {

namespace {

constexpr int64_t kUnit = template_param_unit;

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

std::array<double, 3> param_ref(const TemplateParam& p) {
  return {double(p[0]) / kUnit, double(p[1]) / kUnit, double(p[2]) / kUnit};
}

// The template position p (in the cell's frame) mapped into the hex's cube by the cell's corners
// `corners` (its exact `ref` or its reference `place`).
std::array<double, 3> cell_map(const std::array<std::array<double, 3>, 8>& corners,
                               const std::array<double, 3>& p) {
  const std::array<double, 8> w = hex_trilinear_weights(p);
  std::array<double, 3> out{0, 0, 0};
  for (int v = 0; v < 8; ++v)
    for (int k = 0; k < 3; ++k) out[k] += w[v] * corners[v][k];
  return out;
}

// Sixths of a template position, if it lies on the sixths grid.
bool to_sixths(const std::array<double, 3>& p, std::array<int64_t, 3>& p6) {
  bool on_grid = true;
  for (int k = 0; k < 3; ++k) {
    p6[k] = std::lround(6.0 * p[k]);
    on_grid = on_grid && std::abs(6.0 * p[k] - double(p6[k])) < 1e-9;
  }
  return on_grid;
}

}  // namespace

CellRefiner::CellRefiner(const HexMesh& mesh, const HexTopology& topology)
    : mesh_(mesh), topology_(topology) {}

TemplateCell CellRefiner::cell_whole(int32_t hex) const {
  TemplateCell c;
  c.hex = hex;
  for (int v = 0; v < 8; ++v) {
    for (int k = 0; k < 3; ++k) {
      c.param[v][k] = hex_corner[v][k] * kUnit;
      c.ref[v][k] = hex_corner[v][k];
      c.place[v][k] = hex_corner[v][k];
    }
    c.key[v] = NodeKey::corner(NodeId{mesh_.hexes[hex][v]});
  }
  return c;
}

NodeKey CellRefiner::key_of_template_node(const TemplateCell& cell, int symmetry,
                                          const TemplateNode& tn) const {
  const std::array<double, 3> p = cube_symmetry_apply(cube_symmetries()[symmetry], tn.ref);
  std::array<int64_t, 3> p6{};
  if (!to_sixths(p, p6))
    throw OperationError("hex " + std::to_string(cell.hex) + ": template node off the grid");
  TemplateParam param;
  if (!cell.exact || !cell_map_sixths(cell, p6, param))
    throw OperationError("hex " + std::to_string(cell.hex) + ": sub-hex nested too deep");
  if ((p6[0] % 6 == 0) && (p6[1] % 6 == 0) && (p6[2] % 6 == 0))
    return cell.key[hex_vertex_at(int(p6[0] / 6), int(p6[1] / 6), int(p6[2] / 6))];
  return node_key_at(mesh_, topology_, HexId{cell.hex}, param);
}

bool CellRefiner::alias(const NodeKey& from, const NodeKey& to) {
  if (used_.count(from)) return false;
  const auto [it, inserted] = aliases_.emplace(from, to);
  if (inserted) alias_targets_.insert(to);
  return inserted || it->second == to;
}

const NodeKey& CellRefiner::resolve(const NodeKey& key) const {
  if (aliases_.empty()) return key;
  const auto it = aliases_.find(key);
  return it == aliases_.end() ? key : it->second;
}

std::vector<NodeAlias> CellRefiner::aliases() const {
  std::vector<NodeAlias> out;
  out.reserve(aliases_.size());
  for (const auto& [from, to] : aliases_) out.push_back({from, to});
  std::sort(out.begin(), out.end(),
            [](const NodeAlias& x, const NodeAlias& y) { return node_key_less(x.from, y.from); });
  return out;
}

void CellRefiner::refine(const TemplateCell& cell, const HexTemplate& t, int symmetry,
                         std::vector<TemplateCell>& children, std::vector<NodeKey>* node_keys) {
  const CubeSymmetry& s = cube_symmetries()[symmetry];
  const int32_t h = cell.hex;
  auto fail = [&](const std::string& why) {
    throw OperationError("hex " + std::to_string(h) + " (" + template_tag_name(t.tag) +
                         "): " + why);
  };
  if (!cell.exact && !cell.whole) fail("a sub-hex with inexact corners cannot be refined again");

  struct Placed {
    TemplateParam param;
    std::array<double, 3> ref, place;
    NodeKey key;
    bool exact, aliased;
  };
  std::vector<Placed> placed(t.nodes.size());
  for (size_t i = 0; i < t.nodes.size(); ++i) {
    const std::array<double, 3> p = cube_symmetry_apply(s, t.nodes[i].ref);
    Placed& out = placed[i];
    out.aliased = false;
    // The step's reference position through the cell's reference corners (a corner of the cell
    // keeps its own below).
    out.place = cell_map(cell.place, cube_symmetry_apply(s, template_node_reference(t, i)));
    std::array<int64_t, 3> p6{};
    const bool on_grid = to_sixths(p, p6);
    out.exact = on_grid && cell.exact && cell_map_sixths(cell, p6, out.param);
    if (on_grid && (p6[0] % 6 == 0) && (p6[1] % 6 == 0) && (p6[2] % 6 == 0)) {
      const int corner = hex_vertex_at(int(p6[0] / 6), int(p6[1] / 6), int(p6[2] / 6));
      out.param = cell.param[corner];
      out.ref = cell.ref[corner];
      out.place = cell.place[corner];
      out.key = cell.key[corner];
      out.exact = cell.exact;
      continue;
    }
    if (!out.exact && t.nodes[i].adjustment_edge >= 0) fail("adjustment node off the exact grid");
    if (!out.exact) {
      // Off the grid: only an interior node of a cell that is not refined again.
      bool interior = true;
      for (int k = 0; k < 3; ++k) interior = interior && p[k] > 1e-12 && p[k] < 1 - 1e-12;
      if (!interior) fail("a node on the cell's boundary is off the exact grid");
      out.ref = cell_map(cell.ref, p);
      // A key nobody else can name: interior kind, negative b.
      out.key = NodeKey::interior(HexId{h}, {0, 0, 0});
      out.key.b = -1 - off_grid_count_++;
      continue;
    }
    out.ref = param_ref(out.param);
    out.key = node_key_at(mesh_, topology_, HexId{h}, out.param);
    out.aliased = !(resolve(out.key) == out.key);
  }
  // One lookup per node and a sort: a 1-27 template has 64 nodes, so pairwise lookups cost
  // thousands of hash probes per cell.
  std::vector<NodeKey> resolved(placed.size());
  for (size_t i = 0; i < placed.size(); ++i) resolved[i] = resolve(placed[i].key);
  std::sort(resolved.begin(), resolved.end(), node_key_less);
  if (std::adjacent_find(resolved.begin(), resolved.end()) != resolved.end())
    fail("two template nodes fall on one node (the cell is degenerate)");
  if (node_keys) {
    node_keys->resize(placed.size());
    for (size_t i = 0; i < placed.size(); ++i) (*node_keys)[i] = placed[i].key;
  }
  for (const Placed& p : placed) used_.insert(p.key);
  for (size_t ci = 0; ci < t.children.size(); ++ci) {
    std::array<int16_t, 8> c = t.children[ci];
    if (s.reflection) {
      const std::array<int16_t, 8> original = c;
      for (int k = 0; k < 8; ++k) c[k] = original[hex_reflected_order[k]];
    }
    TemplateCell out;
    out.hex = h;
    out.whole = false;
    out.exact = true;
    for (int k = 0; k < 8; ++k) {
      const Placed& pl = placed[c[k]];
      out.param[k] = pl.param;
      out.ref[k] = pl.ref;
      out.place[k] = pl.place;
      out.key[k] = pl.key;
      out.exact = out.exact && pl.exact;
      out.collapsed = out.collapsed || pl.aliased;
    }
    // Local axes of the child: the template's sheet classes (canonical axes), mapped by the
    // symmetry to the cell's axes, then to the input hex's. A reflection swaps the child's
    // local x and y (the re-ordering above).
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

std::unique_ptr<HexTemplate> selective_cells_template(const std::vector<TemplateCell>& cells,
                                                      TemplateTag tag, const CellRefiner& refiner,
                                                      const TemplateLibrary& templates,
                                                      bool configuration_table, bool placed) {
  auto t = std::make_unique<HexTemplate>();
  t->tag = tag;
  std::unordered_map<NodeKey, int16_t, NodeKeyHash> index;
  bool moved = false;
  for (const TemplateCell& c : cells) {
    std::array<int16_t, 8> child{};
    for (int v = 0; v < 8; ++v) {
      const auto [it, inserted] = index.emplace(c.key[v], static_cast<int16_t>(t->nodes.size()));
      if (inserted) {
        TemplateNode n{c.ref[v]};
        if (placed) {
          n.shared = refiner.is_alias_target(c.key[v]);
          t->reference.push_back(c.place[v]);
          moved = moved || c.place[v] != c.ref[v];
        }
        t->nodes.push_back(n);
      }
      child[v] = it->second;
    }
    t->children.push_back(child);
  }
  if (!moved) t->reference.clear();
  if (configuration_table && placed) template_reference_from_configurations(*t, templates);
  template_compile(*t, 1, placed);
  return t;
}

}  // namespace hexrefine
