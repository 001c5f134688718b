/// \file
/// The Selective Approach (M. H. Parrish, "A Selective Approach to Conformal Refinement of
/// Unstructured Hexahedral Meshes", MS thesis, Brigham Young University; chapter 5, Table 5-1,
/// Appendices E and F). This file decides one pass up to the element-by-element templates and
/// assembles the plan; selective_directional.cpp does the ranking and directional refinement.
///
/// Steps of one pass:
///  1. Marking (Appendix E): every edge of a target hex is split in three.
///  2. Doublets (Appendix F): wherever an adjustment would sit on an edge shared by fewer than
///     four faces (the thesis' rule), on a boundary face, on an edge another hex also adjusts
///     at, or beside a directional neighbour across a merged face (rules this implementation
///     adds: the thesis is silent on them, and each would otherwise give a doublet or a dented
///     boundary), the edge is split and templates are chosen again (a worklist over the hexes
///     around split edges). Counted per rule (RefineStats::doublets_by_rule).
///  3. Element by element (Table 5-1 lines 1-10): targets get 1-27; every other hex with split
///     edges whose pattern is one of the seven templates (template_for_mask) gets that template;
///     the rest are directional hexes. The adjusted templates register their aliases: the two
///     neighbour faces merged at the unsplit edge name the adjustment nodes.
///  4. Ranking and directional refinement (selective_directional.cpp), on symbolic cells
///     (selective_cells.hpp).
///  5. The plan: 1-27 on targets, the chosen template on element-by-element hexes, and per
///     directional hex the template made of its final cells; the aliases. The engine
///     (template_engine.hpp) applies it; node placement (node_placement.hpp) then moves the new
///     nodes, and the checker verifies the result: geometry never decides the topology here.
/// Where the directional scheme meets a doublet it can only avoid by splitting an input edge, the
/// pass starts again with that edge split (each attempt splits one more edge, so this ends). What
/// still fails throws OperationError naming the input hexes.
/// Cost: marking, worklists and ranking touch only the hexes around split edges; each cell is
/// refined once per direction.

#include "algorithms/refiners/selective.hpp"

#include <algorithm>
#include <chrono>
#include <string>

#include "algorithms/refiners/selective_pass.hpp"
#include "mesh/error.hpp"
#include "mesh/hex_convention.hpp"

namespace hexrefine {

namespace selective_detail {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// Local edges an element-by-element template or a directional step would adjust at, for a hex
// with split mask `mask` (bits = local edges). Returns the count written to `out`.
int adjustment_edges(const TemplateLibrary& templates, uint16_t mask, bool directional,
                     std::array<int, 12>& out) {
  int n = 0;
  auto collect = [&](uint16_t m) {
    const TemplateChoice c = templates.choice(m);
    if (!c.tmpl) return;
    for (const TemplateNode& tn : c.tmpl->nodes)
      if (tn.adjustment_edge >= 0 && tn.adjustment_index == 0)
        out[n++] = cube_symmetries()[c.symmetry].edge[tn.adjustment_edge];
  };
  if (!directional) {
    collect(mask);
    return n;
  }
  for (int d = 0; d < 3; ++d) {
    uint16_t m = 0;
    for (int e : hex_axis_edges[d]) m |= mask & (1u << e);
    collect(m);
  }
  return n;
}

}  // namespace

const char* doublet_rule_name(DoubletRule rule) {
  switch (rule) {
    case DoubletRule::three_faces:
      return "edge_of_three_faces";
    case DoubletRule::boundary_face:
      return "merged_boundary_face";
    case DoubletRule::two_adjustments:
      return "two_adjustments_at_edge";
    case DoubletRule::directional_neighbour:
      return "directional_neighbour";
    case DoubletRule::cell_three_faces:
      return "cell_edge_of_three_faces";
    case DoubletRule::cell_one_face_twice:
      return "cell_face_merged_twice";
    case DoubletRule::input_edge_retry:
      return "input_edge_after_restart";
  }
  return "unknown";
}

void SelectivePass::count_doublet(DoubletRule rule) {
  ++stats_.doublets_resolved;
  ++stats_.doublets_by_rule[doublet_rule_name(rule)];
}

void SelectivePass::mark() {
  const int32_t nh = mesh_.hex_count();
  role_.assign(nh, kUntouched);
  split_.assign(topo_.edge_count(), 0);
  for (int32_t h : targets_) {
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
    if (!split_[e]) count_doublet(DoubletRule::input_edge_retry);
    split_[e] = 1;
    touch(e);
  }
  std::sort(touched_.begin(), touched_.end());
}

bool SelectivePass::is_directional(uint16_t mask) const {
  return !templates_.choice(mask).tmpl;
}

void SelectivePass::resolve_doublets() {
  // Worklist: hexes whose split mask changed. An edge is bad for an adjustment if fewer than
  // four faces meet there (the two neighbours would share two faces, Appendix F), if one of the
  // adjusted hex's faces there is a boundary face (the boundary would be dented or opened), if a
  // directional neighbour sits across a merged face, or if two hexes adjust at it (one face
  // collapsed twice). The first rule that applies names the split.
  const int32_t nh = mesh_.hex_count();
  std::vector<uint8_t> queued(nh, 0);
  for (int32_t h : touched_) queued[h] = 1;
  std::vector<int32_t> adjusting_hex(topo_.edge_count(), -1);
  std::vector<int32_t> adjusted_edges;  // edges recorded in adjusting_hex (for reset)
  bool changed = true;
  while (changed) {
    changed = false;
    for (int32_t e : adjusted_edges) adjusting_hex[e] = -1;
    adjusted_edges.clear();
    std::vector<std::pair<int32_t, DoubletRule>> to_split;
    for (int32_t h : touched_) {
      const uint16_t mask = hex_split_mask(topo_, split_, h);
      if (!mask) continue;
      std::array<int, 12> adj{};
      const int n = adjustment_edges(templates_, mask, is_directional(mask), adj);
      for (int i = 0; i < n; ++i) {
        const int le = adj[i];
        const int32_t e = topo_.hex_edge_ids[h][le];
        bool boundary = false, directional_neighbour = false;
        for (int lf : hex_edge_faces[le]) {
          boundary = boundary || face_is_boundary(topo_, topo_.hex_face_ids[h][lf]);
          // A directional neighbour across a merged face would have to refine a cell whose
          // corners were moved onto the adjustment (not supported): split instead.
          const int32_t nb = hex_face_neighbor(topo_, h, lf);
          if (nb >= 0 && role_[nb] != kTarget) {
            const uint16_t nm = hex_split_mask(topo_, split_, nb);
            directional_neighbour = directional_neighbour || (nm && is_directional(nm));
          }
        }
        const bool shared = adjusting_hex[e] >= 0 && adjusting_hex[e] != h;
        if (adjusting_hex[e] < 0) {
          adjusting_hex[e] = h;
          adjusted_edges.push_back(e);
        }
        if (edge_face_count(topo_, e) < 4)
          to_split.push_back({e, DoubletRule::three_faces});
        else if (boundary)
          to_split.push_back({e, DoubletRule::boundary_face});
        else if (directional_neighbour)
          to_split.push_back({e, DoubletRule::directional_neighbour});
        else if (shared)
          to_split.push_back({e, DoubletRule::two_adjustments});
      }
    }
    for (const auto& [e, rule] : to_split) {
      if (split_[e]) continue;
      split_[e] = 1;
      count_doublet(rule);
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
    const TemplateChoice c = templates_.choice(mask);
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
  // faces are redirected to the adjustment nodes before anything is refined.
  for (int32_t h : touched_)
    if (role_[h] == kElement && template_is_adjusted(*element_choice_[h].tmpl))
      register_adjustments(cells_refiner_.cell_whole(h), element_choice_[h]);
}

void SelectivePass::adjustment_aliases(const TemplateCell& cell, const TemplateChoice& c,
                                       std::vector<AliasPair>& out) const {
  const CubeSymmetry& s = cube_symmetries()[c.symmetry];
  for (const TemplateNode& tn : c.tmpl->nodes) {
    if (tn.adjustment_edge < 0) continue;
    const NodeKey to = cells_refiner_.key_of_template_node(cell, c.symmetry, tn);
    // The two faces at the adjusted (canonical x-) edge: y = ye and z = ze; their 1-4 face
    // templates' transition nodes sit at (x, ye, 1/2) and (x, 1/2, ze).
    const double ye = hex_corner[hex_edges[tn.adjustment_edge][0]][1];
    const double ze = hex_corner[hex_edges[tn.adjustment_edge][0]][2];
    const std::array<std::array<double, 3>, 2> q = {{{tn.ref[0], ye, 0.5}, {tn.ref[0], 0.5, ze}}};
    for (const auto& r : q)
      out.push_back({cells_refiner_.key_of_template_node(cell, c.symmetry, TemplateNode{r}), to,
                     static_cast<int8_t>(s.edge[tn.adjustment_edge])});
  }
}

void SelectivePass::register_adjustments(const TemplateCell& cell, const TemplateChoice& c) {
  std::vector<AliasPair> pairs;
  adjustment_aliases(cell, c, pairs);
  for (const AliasPair& p : pairs)
    if (!cells_refiner_.alias(p.from, p.to))
      throw OperationError("selective_refine: hex " + std::to_string(cell.hex) +
                           ": an adjustment would collapse a face that is already subdivided, or "
                           "one collapsed by another adjustment (a doublet)");
}

RefinementPlan SelectivePass::assemble() {
  RefinementPlan plan;
  const int32_t nh = mesh_.hex_count();
  for (int32_t h = 0; h < nh; ++h) {
    TemplateUse use{HexId{h}, nullptr, 0, role_[h] == kTarget};
    if (role_[h] == kTarget) {
      use.tmpl = &templates_.of(TemplateTag::t1_27);
    } else if (role_[h] == kElement) {
      use.tmpl = element_choice_[h].tmpl;
      use.symmetry = element_choice_[h].symmetry;
    } else if (role_[h] == kDirectional) {
      const std::vector<TemplateCell>& cells = cells_[directional_index_[h]];
      if (cells.size() == 1 && cells[0].whole) continue;
      // The table's positions are reference positions: the thesis' placement needs none, nor
      // the children's quality at them.
      const bool placed = options_.placement.method != PlacementMethod::trilinear;
      plan.owned.push_back(
          selective_cells_template(cells, TemplateTag::directional, cells_refiner_, templates_,
                                   options_.placement.configuration_table, placed));
      use.tmpl = plan.owned.back().get();
    } else {
      continue;
    }
    stats_.hexes_created += static_cast<int64_t>(use.tmpl->children.size());
    stats_.hexes_deleted += 1;
    plan.uses.push_back(use);
  }
  plan.aliases = cells_refiner_.aliases();
  return plan;
}

RefinementPlan SelectivePass::run() {
  auto t0 = Clock::now();
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
  if (!options_.ebe_only) {
    // A cell that needs an input edge split is left as it is and the pass goes on, so one
    // restart learns every such edge the pass meets; what goes wrong downstream of a skipped
    // cell is moot once a restart is due.
    try {
      refine_directional();
    } catch (const OperationError&) {
      if (needed_input_edges_.empty()) throw;
    }
    if (!needed_input_edges_.empty()) throw InputEdgeSplitNeeded{needed_input_edges_};
  }
  stats_.phase_seconds["directional"] += seconds_since(t3);

  auto t4 = Clock::now();
  RefinementPlan plan = assemble();
  stats_.phase_seconds["assembly"] += seconds_since(t4);
  return plan;
}

}  // namespace selective_detail

RefinementPlan selective_plan(const HexMesh& mesh, const HexTopology& topology,
                              const std::vector<int32_t>& targets, const RefineOptions& options,
                              RefineStats& stats, const TemplateLibrary& templates) {
  using namespace selective_detail;
  // A pass that meets an adjustment it can only avoid by splitting an input edge starts again
  // with that edge split (each attempt splits one more edge, so this ends).
  std::vector<int32_t> forced;
  const RefineStats before = stats;
  double restarted_seconds = 0;
  for (;;) {
    const auto start = Clock::now();
    try {
      SelectivePass pass(mesh, topology, targets, options, stats, forced, templates);
      RefinementPlan plan = pass.run();
      stats.input_edges_forced = static_cast<int64_t>(forced.size());
      stats.phase_seconds["restarted_passes"] = restarted_seconds;
      return plan;
    } catch (const InputEdgeSplitNeeded& need) {
      const size_t before_count = forced.size();
      for (int32_t e : need.edges) {
        if (e < 0)
          throw OperationError(
              "selective_refine: a directional adjustment needs an edge split "
              "that lies on no input edge");
        if (std::find(forced.begin(), forced.end(), e) == forced.end()) forced.push_back(e);
      }
      if (forced.size() == before_count)
        throw OperationError("selective_refine: cannot avoid a doublet at input edge " +
                             std::to_string(need.edges.front()));
      restarted_seconds += seconds_since(start);
      stats = before;
    }
  }
}

RefineResult selective_refine(const HexMesh& mesh, const Targets& targets,
                              const RefineOptions& options) {
  return refine(refine_method("selective"), mesh, targets, options);
}

}  // namespace hexrefine
