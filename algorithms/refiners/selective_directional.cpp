/// \file
/// The Selective Approach's ranking system and directional refinement (M. H. Parrish, "A
/// Selective Approach to Conformal Refinement of Unstructured Hexahedral Meshes", MS thesis,
/// BYU, section 5.3, Figure 5-4, Table 5-1 lines 11-19), on symbolic cells (selective_cells.hpp).
///
///  1. Ranking (Figure 5-4): directional hexes are grouped by face adjacency; in each group an
///     unranked (hex, direction) gets the next rank, which spreads through the opposite edges of
///     adjacent faces across the group. The "arbitrary" seed is made deterministic: the
///     direction with the most split edges first (so the multiply-connected direction, the one
///     needing an adjustment, is refined first), then the lower hex id, then x, y, z.
///  2. Directional refinement (Table 5-1 lines 14-19): in increasing rank, every current cell
///     of the ranked hexes is refined in that direction by the template chosen from the split
///     state of its four parallel edges (none, 1-5, 1-4, 1-3 with two adjustments, 1-3 with one
///     adjustment, 1-3); all cells of one rank choose (and register their adjustments) before any
///     is refined, so neighbours refined in the same rank see each other's adjustments.
///     Propagation (section 5.3.2): a new edge perpendicular to the refined direction is split if
///     it lies on a cell face whose two edges parallel to it are split (or, inside the cell, if
///     all four cell edges parallel to it are split): this is what turns a 1-9 face into nine
///     quads across two directional steps, and what keeps a sheet of splits running through the
///     cells. Because every choice depends only on the split states of a face's own edges, and
///     both sides of a face refine its two directions in the same (ranked) order, neighbours
///     subdivide shared faces identically. Directions follow sheets: a child's local axis belongs
///     to the parent sheet it continues (HexTemplate::child_axis), not to the closest geometric
///     axis.

#include <algorithm>
#include <string>
#include <unordered_map>

#include "algorithms/refiners/selective_pass.hpp"
#include "mesh/error.hpp"
#include "mesh/hex_convention.hpp"

namespace hexrefine::selective_detail {

namespace {

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

/// By tag: which edges a step makes depends on the template's nodes and children alone, the
/// same in every library.
const std::vector<NewEdge>& new_edges_of(const HexTemplate* t) {
  static const TemplateTag keys[4] = {TemplateTag::t1_5, TemplateTag::t1_4,
                                      TemplateTag::t1_3_adjust1, TemplateTag::t1_3_adjust2};
  static const std::vector<NewEdge> lists[5] = {
      template_new_edges(template_1_5()), template_new_edges(template_1_4()),
      template_new_edges(template_1_3_adjust1()), template_new_edges(template_1_3_adjust2()),
      template_new_edges(template_1_3())};
  for (int i = 0; i < 4; ++i)
    if (keys[i] == t->tag) return lists[i];
  return lists[4];
}

}  // namespace

void SelectivePass::rank() {
  const int32_t nd = static_cast<int32_t>(directional_.size());
  cells_.assign(nd, {});
  for (int32_t di = 0; di < nd; ++di)
    cells_[di].push_back(cells_refiner_.cell_whole(directional_[di]));
  stats_.directional_hexes += nd;
  if (nd == 0) return;
  const std::vector<int32_t> group = directional_groups();
  const bool by_hex = options_.directional_order == DirectionalOrder::by_hex;
  if (!options_.ranking) {
    rounds_without_ranking(by_hex);
    return;
  }
  std::vector<int32_t> rank_of;
  const std::vector<Rank> members = ranks_build(group, rank_of);
  stats_.ranks += static_cast<int64_t>(members.size());
  if (by_hex)
    rounds_by_hex(rank_of);
  else
    rounds_by_rank(members);
}

std::vector<int32_t> SelectivePass::directional_groups() {
  const int32_t nd = static_cast<int32_t>(directional_.size());
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
  return group;
}

void SelectivePass::rounds_without_ranking(bool by_hex) {
  const int32_t nd = static_cast<int32_t>(directional_.size());
  if (by_hex) {
    for (int32_t di = 0; di < nd; ++di)
      for (int8_t d = 0; d < 3; ++d) rounds_.push_back({{di, d}});
  } else {
    for (int8_t d = 0; d < 3; ++d) {
      rounds_.emplace_back();
      for (int32_t di = 0; di < nd; ++di) rounds_.back().push_back({di, d});
    }
  }
}

std::vector<SelectivePass::Rank> SelectivePass::ranks_build(const std::vector<int32_t>& group,
                                                            std::vector<int32_t>& rank_of) {
  const int32_t nd = static_cast<int32_t>(directional_.size());
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
  rank_of.assign(3 * static_cast<size_t>(nd), -1);
  std::vector<Rank> members;
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
  return members;
}

void SelectivePass::rounds_by_hex(const std::vector<int32_t>& rank_of) {
  const int32_t nd = static_cast<int32_t>(directional_.size());
  for (int32_t di = 0; di < nd; ++di) {
    std::array<int8_t, 3> order = {0, 1, 2};
    std::sort(order.begin(), order.end(),
              [&](int8_t a, int8_t b) { return rank_of[3 * di + a] < rank_of[3 * di + b]; });
    for (int8_t d : order) rounds_.push_back({{di, d}});
  }
}

void SelectivePass::rounds_by_rank(const std::vector<Rank>& members) {
  // A hex met twice by one rank (a self-intersecting sheet) refines those directions in turn.
  std::vector<int8_t> seen_in_rank(directional_.size(), 0);
  for (const auto& m : members) {
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
  const NodeKey& ka = c.key[a];
  const NodeKey& kb = c.key[b];
  if (ka.kind() == NodeKey::Kind::corner && kb.kind() == NodeKey::Kind::corner) {
    // Both ends are input nodes: an input edge of the hex, or a segment across a face/interior.
    int differ = 0;
    for (int k = 0; k < 3; ++k) differ += c.param[a][k] != c.param[b][k];
    if (differ == 1) {
      for (int e = 0; e < 12; ++e) {
        const int32_t g = topo_.hex_edge_ids[c.hex][e];
        const auto& en = topo_.edge_nodes[g];
        const int32_t na = ka.id();
        const int32_t nb = kb.id();
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
    d.choice = templates_.choice(mask);
    if (c.collapsed || !c.exact)
      throw OperationError("selective_refine: hex " + std::to_string(c.hex) +
                           ": a sub-hex next to an adjustment needs further refinement (not "
                           "supported)");
    bool needs_input_edge = false;
    if (template_is_adjusted(*d.choice.tmpl)) {
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
          const NodeKey na = cells_refiner_.resolve(c.key[hex_edges[le][0]]);
          const NodeKey nb = cells_refiner_.resolve(c.key[hex_edges[le][1]]);
          int valence = 0;
          for (const TemplateCell& o : cells)
            for (int e = 0; e < 12; ++e) {
              const NodeKey& x = cells_refiner_.resolve(o.key[hex_edges[e][0]]);
              const NodeKey& y = cells_refiner_.resolve(o.key[hex_edges[e][1]]);
              valence += (x == na && y == nb) || (x == nb && y == na);
            }
          if (valence < 4) {
            // Appendix F inside the hex: split the edge and choose this rank's templates again.
            if (split_segments_
                    .insert(segment_key(c.key[hex_edges[le][0]], c.key[hex_edges[le][1]]))
                    .second)
              count_doublet(DoubletRule::cell_three_faces);
            return true;
          }
        }
        if (bad && on == 2) {
          needed_input_edges_.push_back(cell_edge_input_edge(c, le));
          needs_input_edge = true;
          continue;
        }
        if (bad)
          throw OperationError("selective_refine: hex " + std::to_string(c.hex) +
                               ": a directional adjustment would create a doublet");
      }
    }
    if (!needs_input_edge) out.push_back(d);
  }
  return false;
}

void SelectivePass::apply(const Decision& d, std::vector<TemplateCell>& next) {
  const TemplateCell& c = cells_[d.di][d.cell];
  std::vector<NodeKey> keys;
  cells_refiner_.refine(c, *d.choice.tmpl, d.choice.symmetry, next, &keys);
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
        NodeKey to;
        const TemplateCell* cell;
        int8_t edge;
      };
      std::unordered_map<NodeKey, Owner, NodeKeyHash> round_alias;
      std::vector<AliasPair> pairs;
      // Splits the adjusted edge of `c` if it lies inside its input hex.
      auto split_inside = [&](const TemplateCell& c, int le) {
        const int a = hex_edges[le][0], b = hex_edges[le][1];
        for (int m = 0; m < 3; ++m)
          if ((c.param[a][m] == 0 || c.param[a][m] == template_param_unit) &&
              c.param[b][m] == c.param[a][m])
            return false;
        if (split_segments_.insert(segment_key(c.key[a], c.key[b])).second)
          count_doublet(DoubletRule::cell_one_face_twice);
        return true;
      };
      // A conflict no split inside a hex resolves needs an input edge split: the decision is
      // dropped and the pass goes on (it restarts at its end, SelectivePass::run).
      std::vector<uint8_t> dropped(decisions.size(), 0);
      for (size_t i = 0; i < decisions.size(); ++i) {
        const Decision& dc = decisions[i];
        if (!template_is_adjusted(*dc.choice.tmpl)) continue;
        const TemplateCell& c = cells_[dc.di][dc.cell];
        pairs.clear();
        adjustment_aliases(c, dc.choice, pairs);
        for (const AliasPair& p : pairs) {
          const auto [it, inserted] = round_alias.emplace(p.from, Owner{p.to, &c, p.edge});
          if (inserted || it->second.to == p.to) continue;
          if (split_inside(c, p.edge) || split_inside(*it->second.cell, it->second.edge)) {
            again = true;
            continue;
          }
          int32_t ie = cell_edge_input_edge(c, p.edge);
          if (ie < 0) ie = cell_edge_input_edge(*it->second.cell, it->second.edge);
          if (ie < 0)
            throw OperationError("selective_refine: hex " + std::to_string(c.hex) +
                                 ": two directional adjustments collapse one face (a doublet)");
          needed_input_edges_.push_back(ie);
          dropped[i] = 1;
        }
      }
      if (!again && std::find(dropped.begin(), dropped.end(), 1) != dropped.end()) {
        size_t kept = 0;
        for (size_t i = 0; i < decisions.size(); ++i)
          if (!dropped[i]) decisions[kept++] = decisions[i];
        decisions.resize(kept);
      }
    }
    for (const Decision& dc : decisions) {
      if (template_is_adjusted(*dc.choice.tmpl))
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

}  // namespace hexrefine::selective_detail
