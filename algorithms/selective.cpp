/// \file
/// The Selective Approach (M. H. Parrish, "A Selective Approach to Conformal Refinement of
/// Unstructured Hexahedral Meshes", MS thesis, Brigham Young University; chapter 5, Table 5-1,
/// Appendices E and F).
///
/// Steps of one pass:
///  1. Marking (Appendix E): every edge of a target hex is split in three.
///  2. Doublets (Appendix F): wherever an adjustment would sit on an edge shared by fewer than
///     four faces, on a boundary face, or on an edge another hex also adjusts at, the edge is
///     split and templates are chosen again (a worklist over the hexes around split edges).
///  3. Element by element (Table 5-1 lines 1-10): targets get 1-27; every other hex with split
///     edges whose pattern is one of the seven templates (4096-entry mask table, 48 symmetries)
///     gets that template; the rest are directional hexes.
///  4. Ranking (Figure 5-4): directional hexes are grouped by face adjacency; in each group an
///     unranked (hex, direction) gets the next rank, which spreads through the opposite edges of
///     adjacent faces across the group. The "arbitrary" seed is made deterministic: the
///     direction with the most split edges first (so the multiply-connected direction, the one
///     needing an adjustment, is refined first), then the lower hex id, then x, y, z.
///  5. Directional refinement (Table 5-1 lines 14-19): in increasing rank, every current cell
///     of the ranked hexes is refined in that direction by the template chosen from the split
///     state of its four parallel edges (none, 1-5, 1-4, 1-3 with two adjustments, 1-3 with one
///     adjustment, 1-3); all cells of one rank choose (and register their adjustments) before any
///     applies, so neighbours refined in the same rank see each other's adjustments. Propagation
///     (section 5.3.2): a new edge perpendicular to the refined direction is split if it lies on
///     a cell face whose two edges parallel to it are split (or, inside the cell, if all four
///     cell edges parallel to it are split): this is what turns a 1-9 face into nine quads across
///     two directional steps, and what keeps a sheet of splits running through the cells.
///     Because every choice depends only on the split states of a face's own edges, and both
///     sides of a face refine its two directions in the same (ranked) order, neighbours
///     subdivide shared faces identically.
///  6. Every node is keyed by what it subdivides (TemplateRefiner), so the element-by-element
///     templates and the directional cells share nodes on common edges and faces.
///  7. Self-check (never return a broken mesh): every output face is used by at most two hexes,
///     every output boundary face lies on one input boundary face, no child of a valid input hex
///     is inverted. Directions follow sheets: a child's local axis belongs to the parent sheet it
///     continues (HexTemplate::child_axis), not to the closest geometric axis.
/// Where the directional scheme meets a doublet it can only avoid by splitting an input edge, or
/// a distorted hex whose element-by-element children would be inverted, the pass starts again
/// with that edge split / that hex refined directionally (each attempt changes one more edge or
/// hex, so this ends). What still fails throws OperationError naming the input hexes.
/// Cost: marking, worklists and ranking touch only the hexes around split edges; each cell is
/// refined once per direction; the whole-mesh work is building the topology, copying, and the
/// self-check, once per attempt (further attempts are rare: only configurations that need them).

#include "algorithms/selective.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include "algorithms/templates.hpp"
#include "mesh/error.hpp"
#include "mesh/hex_convention.hpp"
#include "mesh/quality.hpp"
#include "mesh/topology.hpp"

namespace hexrefine {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// The checker's definition (mesh/conformity.hpp): inverted = scaled Jacobian <= 0.
bool hex_is_inverted(const HexMesh& m, int32_t h) {
  return hex_scaled_jacobian(hex_points(m, h)) <= 0.0;
}

enum Role : uint8_t { kUntouched = 0, kTarget = 1, kElement = 2, kDirectional = 3 };

// Local edges an element-by-element template or a directional step would adjust at, for a hex
// with split mask `mask` (bits = local edges). Returns the count written to `out`.
int adjustment_edges(uint16_t mask, bool directional, std::array<int, 12>& out) {
  int n = 0;
  if (!directional) {
    const TemplateChoice c = template_for_mask(mask);
    if (!c.tmpl) return 0;
    for (const TemplateNode& tn : c.tmpl->nodes)
      if (tn.adjustment_edge >= 0 && tn.adjustment_index == 0)
        out[n++] = cube_symmetries()[c.symmetry].edge[tn.adjustment_edge];
    return n;
  }
  for (int d = 0; d < 3; ++d) {
    uint16_t m = 0;
    for (int e : hex_axis_edges[d]) m |= mask & (1u << e);
    const TemplateChoice c = template_for_mask(m);
    if (!c.tmpl) continue;
    for (const TemplateNode& tn : c.tmpl->nodes)
      if (tn.adjustment_edge >= 0 && tn.adjustment_index == 0)
        out[n++] = cube_symmetries()[c.symmetry].edge[tn.adjustment_edge];
  }
  return n;
}

uint16_t hex_split_mask(const HexTopology& topo, const std::vector<uint8_t>& split, int32_t h) {
  uint16_t m = 0;
  for (int e = 0; e < 12; ++e)
    if (split[topo.hex_edge_ids[h][e]]) m |= static_cast<uint16_t>(1u << e);
  return m;
}

// A segment between two keyed nodes (ordered), for the split state of edges created by
// directional steps.
struct SegmentKey {
  TemplateNodeKey a, b;
  bool operator==(const SegmentKey& o) const { return a == o.a && b == o.b; }
};
struct SegmentKeyHash {
  size_t operator()(const SegmentKey& k) const {
    TemplateNodeKeyHash h;
    return h(k.a) * 31 + h(k.b);
  }
};
bool key_less(const TemplateNodeKey& x, const TemplateNodeKey& y) {
  if (x.entity != y.entity) return x.entity < y.entity;
  if (x.a != y.a) return x.a < y.a;
  return x.b < y.b;
}
SegmentKey segment_key(const TemplateNodeKey& a, const TemplateNodeKey& b) {
  return key_less(a, b) ? SegmentKey{a, b} : SegmentKey{b, a};
}

// New edges of a directional template (canonical direction x), perpendicular to x: node pair,
// canonical axis, and the canonical face they lie on (-1: inside the cell).
struct NewEdge {
  int16_t a, b;
  int8_t axis, face;
};

std::vector<NewEdge> template_new_edges(const HexTemplate& t) {
  std::vector<NewEdge> out;
  std::vector<std::pair<int16_t, int16_t>> seen;
  auto extreme = [](double x) { return std::abs(x) < 1e-12 || std::abs(x - 1) < 1e-12; };
  for (size_t ci = 0; ci < t.children.size(); ++ci) {
    const auto& c = t.children[ci];
    for (int e = 0; e < 12; ++e) {
      int16_t a = c[hex_edges[e][0]], b = c[hex_edges[e][1]];
      if (a > b) std::swap(a, b);
      if (std::find(seen.begin(), seen.end(), std::make_pair(a, b)) != seen.end()) continue;
      seen.emplace_back(a, b);
      // The sheet class of this edge (not its geometric direction).
      const int axis = t.child_axis[ci][hex_edge_axis[e]];
      const auto& ra = t.nodes[a].ref;
      const auto& rb = t.nodes[b].ref;
      int shared = 0, face = -1;
      for (int k = 0; k < 3; ++k) {
        const bool on = t.nodes[a].adjustment_edge < 0 && t.nodes[b].adjustment_edge < 0 &&
                        extreme(ra[k]) && std::abs(ra[k] - rb[k]) < 1e-12;
        if (on) {
          ++shared;
          face = 2 * k + (ra[k] > 0.5 ? 1 : 0);
        }
      }
      // A piece of a cell edge, parallel to the refined x, or on a sheet closed inside.
      if (shared >= 2 || axis <= 0) continue;
      if (face >= 0 && face / 2 == axis) face = -1;
      out.push_back({a, b, static_cast<int8_t>(axis), static_cast<int8_t>(face)});
    }
  }
  return out;
}

const std::vector<NewEdge>& new_edges_of(const HexTemplate* t) {
  static const HexTemplate* keys[4] = {&template_1_5(), &template_1_4(), &template_1_3_adjust1(),
                                       &template_1_3_adjust2()};
  static const std::vector<NewEdge> lists[5] = {
      template_new_edges(*keys[0]), template_new_edges(*keys[1]), template_new_edges(*keys[2]),
      template_new_edges(*keys[3]), template_new_edges(template_1_3())};
  for (int i = 0; i < 4; ++i)
    if (keys[i] == t) return lists[i];
  return lists[4];
}

bool template_is_adjusted(const HexTemplate* t) {
  return t == &template_1_3_adjust1() || t == &template_1_3_adjust2();
}

// Thrown when directional refinement meets an adjustment it can only avoid by splitting an input
// edge (Appendix F): the pass starts again with that edge split from the outset.
struct InputEdgeSplitNeeded {
  int32_t edge;
};

// Thrown when element-by-element templates would invert children of these (distorted) input
// hexes: the pass starts again refining them directionally, whose children differ.
struct DirectionalFallbackNeeded {
  std::vector<int32_t> hexes;
};

struct PassOutput {
  HexMesh mesh;
  std::vector<int32_t> parent;
  std::vector<uint8_t> role;  // per input hex
};

class SelectivePass {
 public:
  /// `forced_splits`: input edges split from the outset (found by earlier attempts).
  SelectivePass(const HexMesh& mesh, const std::vector<int32_t>& targets,
                const RefineOptions& options, RefineStats& stats,
                const std::vector<int32_t>& forced_splits,
                const std::vector<uint8_t>& forced_directional)
      : mesh_(mesh),
        targets_(targets),
        options_(options),
        stats_(stats),
        forced_splits_(forced_splits),
        forced_directional_(forced_directional) {}

  PassOutput run();

 private:
  struct Decision {
    int32_t di;
    int32_t cell;
    TemplateChoice choice;
    std::array<bool, 12> split;
  };

  void mark();
  void resolve_doublets();
  void choose();
  void rank();
  void refine_directional();
  bool cell_edge_split(const TemplateCell& c, int le) const;
  /// The input edge that local edge `le` of cell `c` lies on, or -1.
  int32_t cell_edge_input_edge(const TemplateCell& c, int le) const;
  /// Chooses the templates of hex di's cells in direction `axis`; returns true if it split an
  /// edge to avoid a doublet (the round must choose again).
  bool decide(int32_t di, int axis, std::vector<Decision>& out);
  struct AliasPair {
    TemplateNodeKey from, to;
    int8_t edge;  // local edge of the cell at which the adjustment sits
  };
  void adjustment_aliases(const TemplateCell& cell, const TemplateChoice& c,
                          std::vector<AliasPair>& out) const;
  void register_adjustments(const TemplateCell& cell, const TemplateChoice& c);
  void apply(const Decision& d, std::vector<TemplateCell>& next);
  void check_output(const PassOutput& out) const;
  /// The topological part of check_output on the output hexes of the input hexes marked in
  /// `in_region`; appends the input hexes of defects to `bad_parents`.
  void check_region(const PassOutput& out, const std::vector<uint8_t>& in_region,
                    std::vector<int32_t>& bad_parents) const;
  /// A hex with split mask `mask` is refined directionally: no template matches, or it was forced
  /// (its element-by-element children would invert).
  bool is_directional(int32_t h, uint16_t mask) const;
  /// Directional, or refined by an adjusted template: conformity is checked around it.
  bool hex_is_risky(int32_t h) const {
    return role_[h] == kDirectional ||
           (role_[h] == kElement && template_is_adjusted(element_choice_[h].tmpl));
  }

  const HexMesh& mesh_;
  const std::vector<int32_t>& targets_;
  const RefineOptions& options_;
  RefineStats& stats_;
  const std::vector<int32_t>& forced_splits_;
  const std::vector<uint8_t>& forced_directional_;  // per input hex (empty: none)
  HexTopology topo_;
  std::unique_ptr<TemplateRefiner> refiner_;
  std::vector<uint8_t> split_;  // per input edge
  std::vector<uint8_t> role_;   // per input hex
  std::vector<TemplateChoice> element_choice_;
  std::vector<int32_t> touched_;      // non-target hexes with split edges
  std::vector<int32_t> directional_;  // input hex of each directional index
  std::vector<int32_t> directional_index_;
  std::vector<std::vector<TemplateCell>> cells_;  // per directional hex: its current cells
  // Rounds of (directional index, input axis), in processing order.
  std::vector<std::vector<std::pair<int32_t, int8_t>>> rounds_;
  std::unordered_set<SegmentKey, SegmentKeyHash> split_segments_;
};

void SelectivePass::mark() {
  const int32_t nh = mesh_.hex_count();
  role_.assign(nh, kUntouched);
  split_.assign(topo_.edge_count(), 0);
  for (int32_t h : targets_) {
    if (h < 0 || h >= nh)
      throw InputError("selective_refine: target hex " + std::to_string(h) + " is not in the mesh");
    role_[h] = kTarget;
    for (int32_t e : topo_.hex_edge_ids[h]) split_[e] = 1;
  }
  // Hexes around split edges (linear in the region).
  std::vector<uint8_t> seen(nh, 0);
  auto touch = [&](int32_t e) {
    for (int32_t n : edge_hexes(topo_, e))
      if (role_[n] != kTarget && !seen[n]) {
        seen[n] = 1;
        touched_.push_back(n);
      }
  };
  for (int32_t h : targets_)
    for (int32_t e : topo_.hex_edge_ids[h]) touch(e);
  for (int32_t e : forced_splits_) {
    if (!split_[e]) ++stats_.doublets_resolved;
    split_[e] = 1;
    touch(e);
  }
  std::sort(touched_.begin(), touched_.end());
}

bool SelectivePass::is_directional(int32_t h, uint16_t mask) const {
  const TemplateChoice c = template_for_mask(mask);
  if (!c.tmpl) return true;
  return c.tmpl != &template_1_27() && !forced_directional_.empty() && forced_directional_[h];
}

void SelectivePass::resolve_doublets() {
  // Worklist: hexes whose split mask changed. An edge is bad for an adjustment if fewer than
  // four faces meet there (the two neighbours would share two faces, Appendix F), if one of the
  // adjusted hex's faces there is a boundary face (the boundary would be dented or opened), or
  // if two hexes adjust at it (one face collapsed twice).
  const int32_t nh = mesh_.hex_count();
  std::vector<int32_t> work = touched_;
  std::vector<uint8_t> queued(nh, 0);
  for (int32_t h : work) queued[h] = 1;
  std::vector<int32_t> adjusting_hex(topo_.edge_count(), -1);
  std::vector<int32_t> adjusted_edges_of;  // edges recorded in adjusting_hex (for reset)
  bool changed = true;
  while (changed) {
    changed = false;
    for (int32_t e : adjusted_edges_of) adjusting_hex[e] = -1;
    adjusted_edges_of.clear();
    std::vector<int32_t> to_split;
    for (int32_t h : touched_) {
      const uint16_t mask = hex_split_mask(topo_, split_, h);
      if (!mask) continue;
      const bool directional = is_directional(h, mask);
      std::array<int, 12> adj{};
      const int n = adjustment_edges(mask, directional, adj);
      for (int i = 0; i < n; ++i) {
        const int le = adj[i];
        const int32_t e = topo_.hex_edge_ids[h][le];
        bool bad = edge_face_count(topo_, e) < 4;
        for (int lf : hex_edge_faces[le]) {
          bad = bad || face_is_boundary(topo_, topo_.hex_face_ids[h][lf]);
          // A directional neighbour across a merged face would have to refine a cell whose
          // corners were moved onto the adjustment (not supported): split instead.
          const int32_t n = hex_face_neighbor(topo_, h, lf);
          if (n >= 0 && role_[n] != kTarget) {
            const uint16_t nm = hex_split_mask(topo_, split_, n);
            bad = bad || (nm && is_directional(n, nm));
          }
        }
        if (adjusting_hex[e] >= 0 && adjusting_hex[e] != h) bad = true;
        if (adjusting_hex[e] < 0) {
          adjusting_hex[e] = h;
          adjusted_edges_of.push_back(e);
        }
        if (bad) to_split.push_back(e);
      }
    }
    for (int32_t e : to_split) {
      if (split_[e]) continue;
      split_[e] = 1;
      ++stats_.doublets_resolved;
      changed = true;
      for (int32_t n : edge_hexes(topo_, e))
        if (role_[n] != kTarget && !queued[n]) {
          queued[n] = 1;
          touched_.push_back(n);
        }
    }
    if (changed) std::sort(touched_.begin(), touched_.end());
  }
}

void SelectivePass::choose() {
  element_choice_.assign(mesh_.hex_count(), TemplateChoice{});
  directional_index_.assign(mesh_.hex_count(), -1);
  for (int32_t h : touched_) {
    const uint16_t mask = hex_split_mask(topo_, split_, h);
    if (!mask) continue;
    TemplateChoice c = template_for_mask(mask);
    // 1-27 stays (its children cannot invert in a valid hex); others may be forced directional.
    if (is_directional(h, mask)) c = {};
    if (c.tmpl) {
      role_[h] = kElement;
      element_choice_[h] = c;
    } else {
      role_[h] = kDirectional;
      directional_index_[h] = static_cast<int32_t>(directional_.size());
      directional_.push_back(h);
    }
  }
  // Adjustments of element-by-element hexes: the neighbours' transition nodes on the two merged
  // faces are redirected to the adjustment nodes before anything is applied.
  for (int32_t h : touched_)
    if (role_[h] == kElement && template_is_adjusted(element_choice_[h].tmpl))
      register_adjustments(refiner_->cell_whole(h), element_choice_[h]);
}

void SelectivePass::adjustment_aliases(const TemplateCell& cell, const TemplateChoice& c,
                                       std::vector<AliasPair>& out) const {
  const CubeSymmetry& s = cube_symmetries()[c.symmetry];
  for (const TemplateNode& tn : c.tmpl->nodes) {
    if (tn.adjustment_edge < 0) continue;
    const TemplateNodeKey to = refiner_->key_of_template_node(cell, c.symmetry, tn);
    // The two faces at the adjusted (canonical x-) edge: y = ye and z = ze; their 1-4 face
    // templates' transition nodes sit at (x, ye, 1/2) and (x, 1/2, ze).
    const double ye = hex_corner[hex_edges[tn.adjustment_edge][0]][1];
    const double ze = hex_corner[hex_edges[tn.adjustment_edge][0]][2];
    const std::array<std::array<double, 3>, 2> q = {{{tn.ref[0], ye, 0.5}, {tn.ref[0], 0.5, ze}}};
    for (const auto& r : q) {
      TemplateNode qn{r};
      out.push_back({refiner_->key_of_template_node(cell, c.symmetry, qn), to,
                     static_cast<int8_t>(s.edge[tn.adjustment_edge])});
    }
  }
}

void SelectivePass::register_adjustments(const TemplateCell& cell, const TemplateChoice& c) {
  std::vector<AliasPair> pairs;
  adjustment_aliases(cell, c, pairs);
  for (const AliasPair& p : pairs)
    if (!refiner_->alias(p.from, p.to))
      throw OperationError("selective_refine: hex " + std::to_string(cell.hex) +
                           ": an adjustment would collapse a face that is already subdivided, or "
                           "one collapsed by another adjustment (a doublet)");
}

void SelectivePass::rank() {
  const int32_t nd = static_cast<int32_t>(directional_.size());
  cells_.assign(nd, {});
  for (int32_t di = 0; di < nd; ++di) cells_[di].push_back(refiner_->cell_whole(directional_[di]));
  stats_.directional_hexes += nd;
  if (nd == 0) return;
  // Groups (face-connected directional hexes).
  std::vector<int32_t> group(nd, -1);
  int64_t groups = 0;
  std::vector<int32_t> stack;
  for (int32_t s = 0; s < nd; ++s) {
    if (group[s] >= 0) continue;
    group[s] = static_cast<int32_t>(groups);
    stack.push_back(s);
    while (!stack.empty()) {
      const int32_t di = stack.back();
      stack.pop_back();
      for (int lf = 0; lf < 6; ++lf) {
        const int32_t n = hex_face_neighbor(topo_, directional_[di], lf);
        if (n < 0 || directional_index_[n] < 0 || group[directional_index_[n]] >= 0) continue;
        group[directional_index_[n]] = static_cast<int32_t>(groups);
        stack.push_back(directional_index_[n]);
      }
    }
    ++groups;
  }
  stats_.directional_groups += groups;

  if (!options_.ranking) {
    // Ablation: each hex refines its own local x, y, z in turn, hex after hex.
    for (int32_t di = 0; di < nd; ++di)
      for (int8_t d = 0; d < 3; ++d) rounds_.push_back({{di, d}});
    return;
  }
  // Seeds: (hex, direction) by decreasing split count, then group, hex, direction.
  std::vector<std::array<int32_t, 4>> seeds;  // -count, group, di, d
  for (int32_t di = 0; di < nd; ++di) {
    const uint16_t mask = hex_split_mask(topo_, split_, directional_[di]);
    for (int d = 0; d < 3; ++d) {
      int count = 0;
      for (int e : hex_axis_edges[d]) count += (mask >> e) & 1;
      seeds.push_back({-count, group[di], di, d});
    }
  }
  std::sort(seeds.begin(), seeds.end());
  std::vector<int32_t> rank_of(3 * static_cast<size_t>(nd), -1);
  std::vector<std::vector<std::pair<int32_t, int8_t>>> members;
  std::vector<std::pair<int32_t, int8_t>> queue;
  for (const auto& sd : seeds) {
    const int32_t di0 = sd[2];
    const int d0 = sd[3];
    if (rank_of[3 * di0 + d0] >= 0) continue;
    const int32_t r = static_cast<int32_t>(members.size());
    members.emplace_back();
    rank_of[3 * di0 + d0] = r;
    queue.assign(1, {di0, static_cast<int8_t>(d0)});
    for (size_t qi = 0; qi < queue.size(); ++qi) {
      const auto [di, d] = queue[qi];
      members[r].push_back({di, d});
      const int32_t h = directional_[di];
      // Opposite edges of adjacent faces: through every face holding d-edges.
      for (int lf = 0; lf < 6; ++lf) {
        if (lf / 2 == d) continue;
        const int32_t n = hex_face_neighbor(topo_, h, lf);
        if (n < 0 || directional_index_[n] < 0) continue;
        int le = -1;
        for (int fe : hex_face_edges[lf])
          if (hex_edge_axis[fe] == d) le = fe;
        const int ne = hex_local_edge(topo_, n, topo_.hex_edge_ids[h][le]);
        const int nd2 = hex_edge_axis[ne];
        const int32_t ndi = directional_index_[n];
        if (rank_of[3 * ndi + nd2] >= 0) continue;
        rank_of[3 * ndi + nd2] = r;
        queue.push_back({ndi, static_cast<int8_t>(nd2)});
      }
    }
  }
  stats_.ranks += static_cast<int64_t>(members.size());
  // A hex met twice by one rank (a self-intersecting sheet) refines those directions in turn.
  std::vector<int8_t> seen_in_rank(nd, 0);
  for (auto& m : members) {
    std::vector<std::pair<int32_t, int8_t>> first, later;
    for (const auto& x : m) (seen_in_rank[x.first]++ ? later : first).push_back(x);
    for (const auto& x : m) seen_in_rank[x.first] = 0;
    rounds_.push_back(std::move(first));
    while (!later.empty()) {
      std::vector<std::pair<int32_t, int8_t>> a, b;
      for (const auto& x : later) (seen_in_rank[x.first]++ ? b : a).push_back(x);
      for (const auto& x : later) seen_in_rank[x.first] = 0;
      rounds_.push_back(std::move(a));
      later = std::move(b);
    }
  }
}

int32_t SelectivePass::cell_edge_input_edge(const TemplateCell& c, int le) const {
  const auto& pa = c.param[hex_edges[le][0]];
  const auto& pb = c.param[hex_edges[le][1]];
  for (int e = 0; e < 12; ++e) {
    int fixed = 0;
    bool match = true;
    for (int m = 0; m < 3; ++m) {
      if (m == hex_edge_axis[e]) continue;
      const int64_t x = hex_corner[hex_edges[e][0]][m] * template_param_unit;
      match = match && pa[m] == x && pb[m] == x;
      ++fixed;
    }
    if (match && fixed == 2) return topo_.hex_edge_ids[c.hex][e];
  }
  return -1;
}

bool SelectivePass::cell_edge_split(const TemplateCell& c, int le) const {
  const int a = hex_edges[le][0], b = hex_edges[le][1];
  const TemplateNodeKey& ka = c.key[a];
  const TemplateNodeKey& kb = c.key[b];
  if (ka.kind() == TemplateNodeKey::corner && kb.kind() == TemplateNodeKey::corner) {
    // Both ends are input nodes: an input edge of the hex, or a segment across a face/interior.
    int differ = 0;
    for (int k = 0; k < 3; ++k) differ += c.param[a][k] != c.param[b][k];
    if (differ == 1) {
      for (int e = 0; e < 12; ++e) {
        const int32_t g = topo_.hex_edge_ids[c.hex][e];
        const auto& en = topo_.edge_nodes[g];
        const int32_t na = static_cast<int32_t>(ka.entity & 0xFFFFFFFFFF);
        const int32_t nb = static_cast<int32_t>(kb.entity & 0xFFFFFFFFFF);
        if ((en[0] == na && en[1] == nb) || (en[0] == nb && en[1] == na)) return split_[g];
      }
    }
  }
  // A piece of an input edge (both ends on one input edge) is never split again.
  int on_edge_axes = 0;
  for (int k = 0; k < 3; ++k) {
    const int64_t x = c.param[a][k];
    if ((x == 0 || x == template_param_unit) && c.param[b][k] == x) ++on_edge_axes;
  }
  if (on_edge_axes >= 2) return false;
  return split_segments_.count(segment_key(ka, kb)) > 0;
}

bool SelectivePass::decide(int32_t di, int axis, std::vector<Decision>& out) {
  const std::vector<TemplateCell>& cells = cells_[di];
  for (int32_t ci = 0; ci < static_cast<int32_t>(cells.size()); ++ci) {
    const TemplateCell& c = cells[ci];
    int k = -1;
    for (int m = 0; m < 3; ++m)
      if (c.axis[m] == axis) k = m;
    Decision d{di, ci, {}, {}};
    uint16_t mask = 0;
    for (int le = 0; le < 12; ++le) {
      d.split[le] = cell_edge_split(c, le);
      if (d.split[le] && hex_edge_axis[le] == k) mask |= static_cast<uint16_t>(1u << le);
    }
    if (k < 0 || !mask) continue;
    d.choice = template_for_mask(mask);
    if (c.collapsed || !c.exact)
      throw OperationError("selective_refine: hex " + std::to_string(c.hex) +
                           ": a sub-hex next to an adjustment needs further refinement (not "
                           "supported)");
    if (template_is_adjusted(d.choice.tmpl)) {
      // Appendix F at the cell level: the adjusted cell edge must have four faces and no
      // boundary face; an adjustment on an input edge or input face is checked like step 2.
      const CubeSymmetry& s = cube_symmetries()[d.choice.symmetry];
      for (const TemplateNode& tn : d.choice.tmpl->nodes) {
        if (tn.adjustment_edge < 0 || tn.adjustment_index != 0) continue;
        const int le = s.edge[tn.adjustment_edge];
        const auto& pa = c.param[hex_edges[le][0]];
        const auto& pb = c.param[hex_edges[le][1]];
        bool bad = false;
        int on = 0;
        for (int m = 0; m < 3; ++m) {
          const int64_t x = pa[m];
          if ((x == 0 || x == template_param_unit) && pb[m] == x) {
            ++on;
            const int lf = 2 * m + (x ? 1 : 0);
            bad = bad || face_is_boundary(topo_, topo_.hex_face_ids[c.hex][lf]);
          }
        }
        if (on == 2) {
          for (int e = 0; e < 12; ++e) {
            bool match = true;
            for (int m = 0; m < 3; ++m) {
              const int64_t x = pa[m];
              if ((x == 0 || x == template_param_unit) && pb[m] == x)
                match = match && hex_corner[hex_edges[e][0]][m] * template_param_unit == x &&
                        hex_corner[hex_edges[e][1]][m] * template_param_unit == x;
            }
            if (match && edge_face_count(topo_, topo_.hex_edge_ids[c.hex][e]) < 4) bad = true;
          }
        }
        if (on == 0) {
          // Inside the input hex: the faces around the edge are those of this hex's cells.
          const int32_t na = c.nodes[hex_edges[le][0]], nb = c.nodes[hex_edges[le][1]];
          int valence = 0;
          for (const TemplateCell& o : cells)
            for (int e = 0; e < 12; ++e) {
              const int32_t x = o.nodes[hex_edges[e][0]], y = o.nodes[hex_edges[e][1]];
              valence += (x == na && y == nb) || (x == nb && y == na);
            }
          if (valence < 4) {
            // Appendix F inside the hex: split the edge and choose this rank's templates again.
            if (split_segments_
                    .insert(segment_key(c.key[hex_edges[le][0]], c.key[hex_edges[le][1]]))
                    .second)
              ++stats_.doublets_resolved;
            return true;
          }
        }
        if (bad && on == 2) throw InputEdgeSplitNeeded{cell_edge_input_edge(c, le)};
        if (bad)
          throw OperationError("selective_refine: hex " + std::to_string(c.hex) +
                               ": a directional adjustment would create a doublet");
      }
    }
    out.push_back(d);
  }
  return false;
}

void SelectivePass::apply(const Decision& d, std::vector<TemplateCell>& next) {
  const TemplateCell& c = cells_[d.di][d.cell];
  std::vector<TemplateNodeKey> keys;
  refiner_->apply(c, *d.choice.tmpl, d.choice.symmetry, next, &keys);
  if (!options_.propagation) return;
  const CubeSymmetry& s = cube_symmetries()[d.choice.symmetry];
  for (const NewEdge& ne : new_edges_of(d.choice.tmpl)) {
    bool all = true;
    if (ne.face >= 0) {
      for (int fe : hex_face_edges[ne.face])
        if (hex_edge_axis[fe] == ne.axis) all = all && d.split[s.edge[fe]];
    } else {
      for (int fe : hex_axis_edges[ne.axis]) all = all && d.split[s.edge[fe]];
    }
    if (!all) continue;
    if (split_segments_.insert(segment_key(keys[ne.a], keys[ne.b])).second)
      ++stats_.edges_split_by_propagation;
  }
}

void SelectivePass::refine_directional() {
  std::vector<Decision> decisions;
  std::vector<TemplateCell> next;
  std::vector<uint8_t> replaced;
  for (const auto& round : rounds_) {
    for (bool again = true; again;) {
      again = false;
      decisions.clear();
      for (const auto& [di, d] : round) again = decide(di, d, decisions) || again;
      if (again) continue;
      // Two adjustments collapsing one face (Appendix F, Figure F-3): split the second one's
      // edge when it lies inside its input hex, and choose again.
      struct Owner {
        TemplateNodeKey to;
        const TemplateCell* cell;
        int8_t edge;
      };
      std::unordered_map<TemplateNodeKey, Owner, TemplateNodeKeyHash> round_alias;
      std::vector<AliasPair> pairs;
      // Splits the adjusted edge of `c` if it lies inside its input hex.
      auto split_inside = [&](const TemplateCell& c, int le) {
        const int a = hex_edges[le][0], b = hex_edges[le][1];
        for (int m = 0; m < 3; ++m)
          if ((c.param[a][m] == 0 || c.param[a][m] == template_param_unit) &&
              c.param[b][m] == c.param[a][m])
            return false;
        if (split_segments_.insert(segment_key(c.key[a], c.key[b])).second)
          ++stats_.doublets_resolved;
        return true;
      };
      for (const Decision& dc : decisions) {
        if (!template_is_adjusted(dc.choice.tmpl)) continue;
        const TemplateCell& c = cells_[dc.di][dc.cell];
        pairs.clear();
        adjustment_aliases(c, dc.choice, pairs);
        for (const AliasPair& p : pairs) {
          const auto [it, inserted] = round_alias.emplace(p.from, Owner{p.to, &c, p.edge});
          if (inserted || it->second.to == p.to) continue;
          if (!split_inside(c, p.edge) && !split_inside(*it->second.cell, it->second.edge)) {
            for (const auto& [cc, ee] :
                 {std::pair{&c, p.edge}, {it->second.cell, it->second.edge}}) {
              const int32_t ie = cell_edge_input_edge(*cc, ee);
              if (ie >= 0) throw InputEdgeSplitNeeded{ie};
            }
            throw OperationError("selective_refine: hex " + std::to_string(c.hex) +
                                 ": two directional adjustments collapse one face (a doublet)");
          }
          again = true;
        }
      }
    }
    for (const Decision& dc : decisions) {
      if (template_is_adjusted(dc.choice.tmpl))
        register_adjustments(cells_[dc.di][dc.cell], dc.choice);
    }
    // Apply per hex: refined cells are replaced by their children.
    size_t i = 0;
    while (i < decisions.size()) {
      const int32_t di = decisions[i].di;
      std::vector<TemplateCell>& cells = cells_[di];
      replaced.assign(cells.size(), 0);
      next.clear();
      for (; i < decisions.size() && decisions[i].di == di; ++i) {
        apply(decisions[i], next);
        replaced[decisions[i].cell] = 1;
      }
      for (size_t ci = 0; ci < cells.size(); ++ci)
        if (!replaced[ci]) next.push_back(cells[ci]);
      cells.swap(next);
    }
  }
}

void SelectivePass::check_output(const PassOutput& out) const {
  // The refiner's own guard against writing a broken mesh: every output face is shared by at
  // most two hexes, every boundary face of the output lies on the input's boundary (a face left
  // open by non-matching subdivisions shows up as a boundary face inside the mesh), and no
  // output hex from a valid input hex is inverted (corner Jacobians).
  // Where it looks: a face between two hexes refined by the basic templates (1-27, 1-13, 1-5,
  // 1-4, 1-3) or left untouched is conformal by construction, because each basic template
  // subdivides a face only as a function of that face's split edges (asserted for every
  // template, symmetry and face by test_templates) and the nodes are keyed by the face. So the
  // topological check covers the "risky" input hexes (directional ones and adjusted templates,
  // whose adjustments alias their neighbours' face nodes) and the ring of their face
  // neighbours; the rest of the output is never rebuilt. Children of an affine input hex are
  // affine images of the template's children, which template_validate found positive, so only
  // hexes from non-affine parents (or risky ones) get the inversion test.
  const int32_t nh = mesh_.hex_count();
  std::vector<uint8_t> in_region(nh, 0);
  bool any_risky = false;
  for (int32_t h = 0; h < nh; ++h) {
    if (!hex_is_risky(h)) continue;
    any_risky = true;
    in_region[h] = 1;
    for (int lf = 0; lf < 6; ++lf) {
      const int32_t n = hex_face_neighbor(topo_, h, lf);
      if (n >= 0) in_region[n] = 1;
    }
  }
  std::vector<int32_t> bad_parents, inverted_parents;
  if (any_risky) check_region(out, in_region, bad_parents);
  std::vector<uint8_t> affine(nh, 0);
  for (int32_t h = 0; h < nh; ++h)
    affine[h] = !in_region[h] && hex_is_parallelepiped(hex_points(mesh_, h));
  for (int32_t h = 0; h < out.mesh.hex_count(); ++h) {
    if (out.role[out.parent[h]] == kUntouched || affine[out.parent[h]]) continue;
    if (options_.allow_inverted && hex_is_inverted(mesh_, out.parent[h])) continue;
    const auto x = hex_points(out.mesh, h);
    for (int v = 0; v < 8; ++v) {
      const Eigen::Vector3d a = x[hex_edges[hex_vertex_edges[v][0]][hex_corner[v][0] ? 0 : 1]];
      const Eigen::Vector3d b = x[hex_edges[hex_vertex_edges[v][1]][hex_corner[v][1] ? 0 : 1]];
      const Eigen::Vector3d c = x[hex_edges[hex_vertex_edges[v][2]][hex_corner[v][2] ? 0 : 1]];
      const double sa = hex_corner[v][0] ? -1 : 1, sb = hex_corner[v][1] ? -1 : 1,
                   sc = hex_corner[v][2] ? -1 : 1;
      const double det = (sa * (a - x[v])).dot((sb * (b - x[v])).cross(sc * (c - x[v])));
      if (!(det > 0)) {
        inverted_parents.push_back(out.parent[h]);
        break;
      }
    }
  }
  auto listed = [](std::vector<int32_t>& v) {
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
    std::string list = std::to_string(v.size()) + " input hexes affected: ";
    for (size_t i = 0; i < v.size() && i < 20; ++i) list += (i ? ", " : "") + std::to_string(v[i]);
    if (v.size() > 20) list += ", ...";
    return list;
  };
  if (!bad_parents.empty())
    throw OperationError("selective_refine: cannot refine this configuration conformally; " +
                         listed(bad_parents));
  if (!inverted_parents.empty()) {
    std::vector<int32_t> element;
    for (int32_t h : inverted_parents)
      if (role_[h] == kElement && element_choice_[h].tmpl != &template_1_27()) element.push_back(h);
    if (!element.empty()) throw DirectionalFallbackNeeded{element};
  }
  if (!inverted_parents.empty())
    throw OperationError(
        "selective_refine: the templates would invert hexes here (the input "
        "hexes are too distorted for them); " +
        listed(inverted_parents));
}

void SelectivePass::check_region(const PassOutput& out, const std::vector<uint8_t>& in_region,
                                 std::vector<int32_t>& bad_parents) const {
  // The output hexes of the region, with compact node ids (global id of local node i:
  // global_of[i]).
  HexMesh sub;
  std::vector<int32_t> sub_parent, global_of;
  std::vector<int32_t> local_of(out.mesh.points.size(), -1);
  for (int32_t h = 0; h < out.mesh.hex_count(); ++h) {
    if (!in_region[out.parent[h]]) continue;
    HexCell c = out.mesh.hexes[h];
    for (int32_t& v : c) {
      if (local_of[v] < 0) {
        local_of[v] = static_cast<int32_t>(global_of.size());
        global_of.push_back(v);
      }
      v = local_of[v];
    }
    sub.hexes.push_back(c);
    sub_parent.push_back(out.parent[h]);
  }
  sub.points.resize(global_of.size(), Eigen::Vector3d::Zero());
  const HexTopology t = topology_build(sub);
  for (int32_t f : t.nonmanifold_faces) bad_parents.push_back(sub_parent[t.face_hexes[f][0]]);
  const int32_t n_in = mesh_.point_count();
  // A face of the region's surface must lie on one input face on the region's surface (an
  // input boundary face, or a face to a hex outside the region): every node is an input node
  // of that face, a node keyed on one of its edges, or a node keyed on it.
  auto face_is_outer = [&](int32_t g) {
    const auto& fh = topo_.face_hexes[g];
    return fh[1] < 0 || !in_region[fh[0]] || !in_region[fh[1]];
  };
  const auto& keys = refiner_->created_keys();
  auto key_of = [&](int32_t n) -> const TemplateNodeKey* {
    return n >= n_in ? &keys[n - n_in] : nullptr;
  };
  auto node_on_face = [&](int32_t n, int32_t f) {
    const auto& fn = topo_.face_nodes[f];
    auto has = [&](int32_t x) { return std::find(fn.begin(), fn.end(), x) != fn.end(); };
    const TemplateNodeKey* k = key_of(n);
    if (!k) return has(n);
    const int32_t id = static_cast<int32_t>(k->entity & 0xFFFFFFFFFF);
    if (k->kind() == TemplateNodeKey::face) return id == f;
    if (k->kind() == TemplateNodeKey::edge)
      return has(topo_.edge_nodes[id][0]) && has(topo_.edge_nodes[id][1]);
    return false;
  };
  std::vector<int32_t> candidates;
  for (int32_t f : topology_boundary_faces(t)) {
    std::array<int32_t, 4> q = t.face_nodes[f];
    for (int32_t& n : q) n = global_of[n];
    candidates.clear();
    int32_t anchor = q[0];
    for (int32_t n : q) {
      const TemplateNodeKey* k = key_of(n);
      if (k && k->kind() == TemplateNodeKey::face) anchor = n;
    }
    const TemplateNodeKey* k = key_of(anchor);
    if (k && k->kind() == TemplateNodeKey::face) {
      candidates.push_back(static_cast<int32_t>(k->entity & 0xFFFFFFFFFF));
    } else {
      // Input faces around an input node of this face, or around the edge a keyed node sits on.
      int32_t around = -1;
      for (int32_t n : q)
        if (n < n_in) around = n;
      if (around < 0 && k && k->kind() == TemplateNodeKey::edge)
        around = topo_.edge_nodes[k->entity & 0xFFFFFFFFFF][0];
      if (around >= 0)
        for (int32_t h : node_hexes(topo_, around))
          for (int32_t g : topo_.hex_face_ids[h]) candidates.push_back(g);
    }
    bool ok = false;
    for (int32_t g : candidates) {
      bool all = face_is_outer(g);
      for (int32_t n : q) all = all && node_on_face(n, g);
      if (all) {
        ok = true;
        break;
      }
    }
    if (!ok) bad_parents.push_back(sub_parent[t.face_hexes[f][0]]);
  }
}

PassOutput SelectivePass::run() {
  auto t0 = Clock::now();
  topo_ = topology_build(mesh_);
  refiner_ = std::make_unique<TemplateRefiner>(mesh_, topo_);
  refiner_->set_adjustment_keys_by_position(true);
  mark();
  resolve_doublets();
  stats_.phase_seconds["marking"] += seconds_since(t0);

  auto t1 = Clock::now();
  choose();
  stats_.phase_seconds["element_by_element"] += seconds_since(t1);

  auto t2 = Clock::now();
  if (!options_.ebe_only) {
    rank();
  } else {
    for (int32_t h : directional_) role_[h] = kUntouched;
    directional_.clear();
    cells_.clear();
  }
  stats_.phase_seconds["ranking"] += seconds_since(t2);

  auto t3 = Clock::now();
  if (!options_.ebe_only) refine_directional();
  stats_.phase_seconds["directional"] += seconds_since(t3);

  auto t4 = Clock::now();
  PassOutput out;
  out.role = role_;
  HexMesh& res = out.mesh;
  std::vector<int32_t> parent_tag(mesh_.hex_count(), -1);  // tag of a refined input hex
  const int32_t nh = mesh_.hex_count();
  size_t out_hexes = 0, new_nodes = 0;
  for (int32_t h = 0; h < nh; ++h) {
    const HexTemplate* t = role_[h] == kTarget    ? &template_1_27()
                           : role_[h] == kElement ? element_choice_[h].tmpl
                                                  : nullptr;
    out_hexes += t                          ? t->children.size()
                 : role_[h] == kDirectional ? cells_[directional_index_[h]].size()
                                            : 1;
    if (t) new_nodes += t->nodes.size();
  }
  res.hexes.reserve(out_hexes);
  out.parent.reserve(out_hexes);
  // Node keys are needed only by the self-check around risky hexes (check_region).
  bool any_risky = false;
  for (int32_t h = 0; h < nh; ++h) any_risky = any_risky || hex_is_risky(h);
  if (!any_risky) refiner_->set_record_keys(false);
  refiner_->reserve_created(new_nodes);
  // Untouched hexes and directional cells are copied; targets and element-by-element hexes get
  // one whole-hex application each (their interior nodes are private to them), in hex order,
  // through the batch (parallel with options.threads, the same output).
  std::vector<TemplateApplication> apps;
  std::vector<size_t> offsets;
  // One thread: children appended as they are made. More: slots laid out first, the batch
  // fills the template hexes' slots in parallel.
  const bool parallel = options_.threads > 1;
  if (parallel)
    res.hexes.resize(out_hexes);
  else
    res.hexes.reserve(out_hexes);
  size_t at = 0;
  auto put = [&](const HexCell& c) {
    if (parallel)
      res.hexes[at] = c;
    else
      res.hexes.push_back(c);
    ++at;
  };
  for (int32_t h = 0; h < nh; ++h) {
    const size_t before = at;
    TemplateTag tag = TemplateTag::untouched;
    if (role_[h] == kTarget || role_[h] == kElement) {
      const TemplateChoice c =
          role_[h] == kTarget ? TemplateChoice{&template_1_27(), 0} : element_choice_[h];
      if (parallel) {
        apps.push_back({h, c.tmpl, c.symmetry});
        offsets.push_back(at);
      } else {
        refiner_->apply_whole(h, *c.tmpl, c.symmetry, true, res.hexes);
      }
      at += c.tmpl->children.size();
      tag = c.tmpl->tag;
    } else if (role_[h] == kDirectional) {
      const auto& cells = cells_[directional_index_[h]];
      if (cells.size() > 1 || !cells[0].whole) {
        for (const TemplateCell& c : cells) put(c.nodes);
        tag = TemplateTag::directional;
      }
    }
    if (at == before) put(mesh_.hexes[h]);
    out.parent.resize(at, h);
    if (tag == TemplateTag::untouched) continue;
    parent_tag[h] = static_cast<int32_t>(tag);
    stats_.hexes_created += static_cast<int64_t>(at - before);
    stats_.hexes_deleted += 1;
  }
  if (parallel) refiner_->apply_whole_batch(apps, offsets, res.hexes, options_.threads);
  res.points = std::move(refiner_->points());
  for (const HexAttribute& attr : mesh_.attributes) {
    HexAttribute copy{attr.name, std::vector<int32_t>(res.hexes.size())};
    for (size_t i = 0; i < res.hexes.size(); ++i) copy.values[i] = attr.values[out.parent[i]];
    res.attributes.push_back(std::move(copy));
  }
  const std::vector<int32_t>* in_level = mesh_find_attribute(mesh_, attribute_refinement_level);
  std::vector<int32_t> level(res.hexes.size());
  for (size_t i = 0; i < res.hexes.size(); ++i)
    level[i] = (in_level ? (*in_level)[out.parent[i]] : 0) + (parent_tag[out.parent[i]] >= 0);
  std::vector<int32_t>& tag_attr = mesh_attribute(res, attribute_template_tag, 0);
  for (size_t i = 0; i < res.hexes.size(); ++i)
    if (parent_tag[out.parent[i]] >= 0) tag_attr[i] = parent_tag[out.parent[i]];
  mesh_attribute(res, attribute_refinement_level, 0) = std::move(level);
  stats_.phase_seconds["assembly"] += seconds_since(t4);

  if (options_.ranking && options_.propagation && !options_.ebe_only) check_output(out);
  return out;
}

}  // namespace

RefineResult selective_refine(const HexMesh& mesh, const Targets& targets,
                              const RefineOptions& options) {
  const auto t0 = Clock::now();
  RefineResult result;
  RefineStats& stats = result.stats;
  stats.method = "selective";
  stats.initial_hexes = mesh.hex_count();
  if (options.passes < 1)
    throw InputError("selective_refine: passes must be at least 1, got " +
                     std::to_string(options.passes));
  if (!options.allow_inverted) {
    int64_t inverted = 0;
    int32_t first = -1;
    for (int32_t h = 0; h < mesh.hex_count(); ++h)
      if (hex_is_inverted(mesh, h)) {
        if (first < 0) first = h;
        ++inverted;
      }
    if (inverted)
      throw InputError("selective_refine: " + std::to_string(inverted) +
                       " inverted hexes, first at id " + std::to_string(first));
  }
  std::vector<int32_t> current_targets = targets.hexes;
  // The mesh a pass refines: the input for the first pass (not copied), the previous pass's
  // output after that.
  HexMesh current;
  const HexMesh* source = &mesh;
  for (int pass = 0; pass < options.passes; ++pass) {
    // A pass that meets an adjustment it can only avoid by splitting an input edge starts
    // again with that edge split (each attempt splits one more edge, so this ends).
    std::vector<int32_t> forced;
    std::vector<uint8_t> forced_directional;
    PassOutput out;
    const RefineStats before = stats;
    for (;;) {
      try {
        SelectivePass p(*source, current_targets, options, stats, forced, forced_directional);
        out = p.run();
        break;
      } catch (const DirectionalFallbackNeeded& need) {
        // Distorted hexes whose element-by-element children would invert: refine them
        // directionally instead (each attempt forces at least one more hex, so this ends).
        if (forced_directional.empty()) forced_directional.assign(source->hex_count(), 0);
        bool progress = false;
        for (int32_t h : need.hexes) {
          progress = progress || !forced_directional[h];
          forced_directional[h] = 1;
        }
        if (!progress) throw OperationError("selective_refine: directional fallback failed");
        const auto phases = stats.phase_seconds;
        stats = before;
        stats.phase_seconds = phases;
      } catch (const InputEdgeSplitNeeded& need) {
        if (need.edge < 0 || std::find(forced.begin(), forced.end(), need.edge) != forced.end())
          throw OperationError("selective_refine: cannot avoid a doublet at input edge " +
                               std::to_string(need.edge));
        forced.push_back(need.edge);
        const auto phases = stats.phase_seconds;
        stats = before;
        stats.phase_seconds = phases;
      }
    }
    std::vector<int32_t> next;
    for (int32_t h = 0; h < out.mesh.hex_count(); ++h) {
      const uint8_t r = out.role[out.parent[h]];
      if (r == kTarget) {
        next.push_back(h);
      } else if (options.buffer && (r == kElement || r == kDirectional)) {
        next.push_back(h);
        if (pass + 1 < options.passes) ++stats.added_targets;
      }
    }
    current = std::move(out.mesh);
    source = &current;
    current_targets = std::move(next);
  }
  result.mesh = std::move(current);
  stats.final_hexes = result.mesh.hex_count();
  stats.final_nodes = result.mesh.point_count();
  stats_count_templates(stats, mesh_attribute(result.mesh, attribute_template_tag, 0));
  stats.time_seconds = seconds_since(t0);
  stats.phase_seconds["total"] = stats.time_seconds;
  return result;
}

}  // namespace hexrefine
