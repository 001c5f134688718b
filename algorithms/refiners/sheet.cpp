// Harris-style sheet refinement: the baseline the Selective Approach is compared against.
//
// Citation: M. H. Parrish, "A Selective Approach to Conformal Refinement of Unstructured
// Hexahedral Meshes", MS thesis, Brigham Young University (chapter 2, chapter 4, Appendices C,
// D, E, G), describing the sheet refinement implemented by Harris (template insertion in
// hexahedral sheets, after Tchon's and Schneiders' directional refinement).
//
// Steps (one refinement pass):
//  1. Marking (as Harris did: nodes first). Every node of a target hex is marked; an edge is
//     split when both its end nodes are marked.
//  2. Growth. In a hex, the split pattern of one direction (its four parallel edges) calls for
//     a directional template: four split -> 1-3, two on one face -> 1-4, one -> 1-5. Three, or
//     two diagonal, would need an adjustment template Harris did not have: the hex is a
//     multiply-connected transition. It is decided per hex and direction from the node marks
//     on the original mesh; all such hexes are added to the targets (their nodes marked) in
//     waves until none is left (each wave looks only at the hexes around newly marked nodes).
//     A hex all of whose nodes get marked is fully refined without being counted as added.
//  3. Sheets. Only hexes with a split edge change. The split edges of one direction of one hex
//     are parallel, so they belong to one dual sheet; the connected pieces of the dual sheets
//     restricted to the split edges (dual_sheet_pieces) are what a sheet pass refines: all hexes
//     around each split edge at once, which keeps the mesh conformal. A piece that occupies two
//     directions of one hex is a sheet crossing itself where it must refine (Harris' special
//     case): if all edges of the hex are split, the pass refines both directions at once with
//     1-9 (1-3 across one direction then the other, as one template; 1-27 for three); otherwise
//     a transition template for two directions would be needed, and the case is refused
//     (OperationError naming the sheet and the hexes). The dual sheets (dual_build) that cross
//     themselves in a refined hex are counted (self_intersection_cases, per hex).
//     Pieces are coloured first-fit so that no two pieces of one colour share a hex; one colour
//     is one round, and processing the pieces of one round together is the same as processing
//     them one after the other, since they share no hex (sheet_passes counts the pieces). For a
//     structured brick the rounds are the x-, y- and z-like sheets.
//  4. Rounds (sheet_rounds.cpp). Every hex carries, per local axis, the sheet piece it still
//     has to be refined in; a child's axis inherits the piece of the parent axis its split
//     edges run along, the axis just refined is done. New nodes inside a split edge are marked
//     (so the strips of a 1-3 face are split in the next direction); new face and interior
//     nodes are not. A fully refined hex goes 1 -> 3 -> 9 -> 27 (13 deleted, 39 created,
//     thesis 4.3). Two ways to run them, with the same mesh: (a) composites (sheet_plan, the
//     default): the rounds of each hex configuration are replayed once on the reference cube and
//     the pass is one plan of those templates; (b) round by round over the whole mesh (an
//     observer, one sheet per pass, or SheetControl::composites = false), as Harris'
//     implementation did; every round is a plan applied to the current mesh.
// Options: `passes` repeats the whole on the descendants of the given targets; the selective
// refiner's options (ranking, propagation, ebe_only, buffer) do not apply and are ignored.
//
// Speed: every step is linear in the size of the refined region (plus one pass over the mesh's
// edges for the dual sheet labels); there is no rescan of the mesh per sheet. With composites
// the output is written once, as by the selective refiner; round by round, every intermediate
// mesh and its topology are built (the thesis' intrinsic 39 created + 13 deleted per hex).

#include "algorithms/refiners/sheet.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <numeric>
#include <string>

#include "algorithms/refiners/sheet_rounds.hpp"
#include "mesh/dual.hpp"
#include "mesh/error.hpp"
#include "mesh/hex_convention.hpp"

namespace hexrefine {

namespace {

using namespace sheet_detail;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

uint16_t axis_mask(int axis) {
  uint16_t m = 0;
  for (int e : hex_axis_edges[axis]) m |= static_cast<uint16_t>(1u << e);
  return m;
}

bool edges_share_face(int a, int b) {
  for (int fa : hex_edge_faces[a])
    for (int fb : hex_edge_faces[b])
      if (fa == fb) return true;
  return false;
}

void marking_seed(const HexMesh& mesh, const std::vector<int32_t>& targets, SheetMarking& m) {
  m.node_marked.assign(mesh.points.size(), 0);
  m.hex_target.assign(mesh.hexes.size(), 0);
  m.added_targets = 0;
  for (int32_t t : targets) {
    m.hex_target[t] = 1;
    for (int32_t v : mesh.hexes[t]) m.node_marked[v] = 1;
  }
}

// Waves, as "add the multiply-connected transitions to the targets and repeat": every wave
// decides all candidates on the marks of the previous wave, then adds them together. (Adding
// one hex at a time would depend on the visiting order: a hex can get all its nodes marked by
// its neighbours' growth and be fully refined without ever being added, which changes
// added_targets; the waves add exactly the thesis' count on its L-shaped case, which
// tests/algorithms/refiners/test_sheet.cpp asserts.)
void marking_grow(const HexMesh& mesh, const HexTopology& topology,
                  const std::vector<int32_t>& targets, SheetMarking& m) {
  std::vector<uint8_t> queued(mesh.hexes.size(), 0);
  std::vector<int32_t> candidates, added, newly_marked;
  auto enqueue_around = [&](int32_t v) {
    for (int32_t g : node_hexes(topology, v))
      if (!m.hex_target[g] && !queued[g]) {
        queued[g] = 1;
        candidates.push_back(g);
      }
  };
  for (int32_t t : targets)
    for (int32_t v : mesh.hexes[t]) enqueue_around(v);
  while (!candidates.empty()) {
    added.clear();
    for (int32_t h : candidates) {
      queued[h] = 0;
      if (hex_is_multiply_connected(hex_split_mask(mesh, m.node_marked, h))) added.push_back(h);
    }
    candidates.clear();
    newly_marked.clear();
    for (int32_t h : added) {
      m.hex_target[h] = 1;
      ++m.added_targets;
      for (int32_t v : mesh.hexes[h])
        if (!m.node_marked[v]) {
          m.node_marked[v] = 1;
          newly_marked.push_back(v);
        }
    }
    for (int32_t v : newly_marked) enqueue_around(v);
  }
}

std::string hex_list(const std::vector<int32_t>& hexes) {
  std::string s;
  for (size_t i = 0; i < hexes.size() && i < 10; ++i)
    s += (i ? ", " : "") + std::to_string(hexes[i]);
  if (hexes.size() > 10) s += ", ... (" + std::to_string(hexes.size()) + " hexes)";
  return s;
}

// Steps 1-3 of a pass: marking, growth, the sheet pieces to refine and their rounds.
struct SheetPass {
  SheetMarking marking;
  std::vector<int32_t> region_hexes;  ///< hexes with a split edge, ascending
  SheetPieces pieces;                 ///< per region hex (index as region_hexes)
  std::vector<int32_t> color;         ///< per piece: its round
  int32_t round_count = 0;

  std::string piece_name(const HexTopology& t, int32_t p) const {
    const int32_t e = pieces.piece_edge[p];
    std::string name = "(";
    name += std::to_string(t.edge_nodes[e][0]);
    name += '-';
    name += std::to_string(t.edge_nodes[e][1]);
    name += ')';
    return name;
  }
};

/// The hexes with a split edge (ascending; all of them touch a marked node) into
/// pass.region_hexes; returns their split masks (one per region hex).
std::vector<uint16_t> region_find(const HexMesh& mesh, const HexTopology& topology,
                                  SheetPass& pass) {
  std::vector<uint16_t> masks;
  std::vector<uint8_t> seen(mesh.hexes.size(), 0);
  for (int32_t v = 0; v < mesh.point_count(); ++v) {
    if (!pass.marking.node_marked[v]) continue;
    for (int32_t g : node_hexes(topology, v)) {
      if (seen[g]) continue;
      seen[g] = 1;
      if (hex_split_mask(mesh, pass.marking.node_marked, g)) pass.region_hexes.push_back(g);
    }
  }
  std::sort(pass.region_hexes.begin(), pass.region_hexes.end());
  for (int32_t h : pass.region_hexes)
    masks.push_back(hex_split_mask(mesh, pass.marking.node_marked, h));
  return masks;
}

/// Self-intersections: the dual sheet of one direction of a refined hex is also the sheet of
/// another of its directions (Harris' special case). Counted on the whole dual sheets; refused
/// (OperationError naming the sheet and hexes) only where one piece must refine a hex in two
/// directions without splitting all its edges.
void self_intersections_check(const HexMesh& mesh, const HexTopology& topology,
                              const SheetPass& pass, const std::vector<uint16_t>& masks,
                              RefineStats& stats) {
  const DualSheets sheets = dual_build(mesh, topology, DualParts::sheets);
  std::vector<int32_t> refused;
  int32_t refused_piece = -1;
  for (size_t i = 0; i < pass.region_hexes.size(); ++i) {
    const auto& s = sheets.hex_sheet[pass.region_hexes[i]];
    if (s[0] == s[1] || s[1] == s[2] || s[0] == s[2]) ++stats.self_intersection_cases;
    const auto& o = pass.pieces.hex_piece[i];
    // All edges split: the piece's directions are refined together by 1-9 (or 1-27).
    if (masks[i] == 0xFFF) continue;
    for (int a = 0; a < 3; ++a)
      for (int b = a + 1; b < 3; ++b)
        if (o[a] >= 0 && o[a] == o[b]) {
          if (refused_piece < 0) refused_piece = o[a];
          const int32_t h = pass.region_hexes[i];
          if (o[a] == refused_piece && (refused.empty() || refused.back() != h))
            refused.push_back(h);
        }
  }
  if (!refused.empty())
    throw OperationError(
        "sheet refinement: the dual sheet of edge " + pass.piece_name(topology, refused_piece) +
        " crosses itself in hexes " + hex_list(refused) +
        ", which it must refine in two directions within one sheet pass with transition "
        "templates; that case of a self-intersecting sheet is not handled by the sheet refiner "
        "(only fully refined hexes are: 1-9)");
}

/// Rounds: first-fit colouring of the pieces (pass.color, pass.round_count); two pieces
/// conflict when they share a hex.
void pieces_color(SheetPass& pass) {
  const int32_t piece_count = pass.pieces.piece_count();
  pass.color.assign(piece_count, -1);
  std::vector<int32_t> offsets(piece_count + 1, 0);
  for (const auto& o : pass.pieces.hex_piece)
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        if (a != b && o[a] >= 0 && o[b] >= 0) ++offsets[o[a] + 1];
  for (int32_t p = 0; p < piece_count; ++p) offsets[p + 1] += offsets[p];
  std::vector<int32_t> adjacent(offsets[piece_count]);
  std::vector<int32_t> cursor(offsets.begin(), offsets.end() - 1);
  for (const auto& o : pass.pieces.hex_piece)
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        if (a != b && o[a] >= 0 && o[b] >= 0) adjacent[cursor[o[a]]++] = o[b];
  std::vector<int32_t> stamp;  // stamp[c] == p: colour c is used by a neighbour of p
  for (int32_t p = 0; p < piece_count; ++p) {
    for (int32_t i = offsets[p]; i < offsets[p + 1]; ++i) {
      const int32_t c = pass.color[adjacent[i]];
      if (c < 0) continue;
      if (c >= static_cast<int32_t>(stamp.size())) stamp.resize(c + 1, -1);
      stamp[c] = p;
    }
    int32_t c = 0;
    while (c < static_cast<int32_t>(stamp.size()) && stamp[c] == p) ++c;
    pass.color[p] = c;
    pass.round_count = std::max(pass.round_count, c + 1);
  }
}

SheetPass sheet_pass_prepare(const HexMesh& mesh, const HexTopology& topology,
                             const std::vector<int32_t>& targets, bool one_sheet_per_round,
                             RefineStats& stats) {
  const auto t_start = Clock::now();
  SheetPass pass;
  marking_seed(mesh, targets, pass.marking);
  stats.phase_seconds["marking"] += seconds_since(t_start);

  const auto t_growth = Clock::now();
  marking_grow(mesh, topology, targets, pass.marking);
  stats.added_targets += pass.marking.added_targets;
  stats.phase_seconds["growth"] += seconds_since(t_growth);

  const auto t_sheets = Clock::now();
  const std::vector<uint16_t> masks = region_find(mesh, topology, pass);
  pass.pieces = dual_sheet_pieces(topology, pass.region_hexes, masks);
  const int32_t piece_count = pass.pieces.piece_count();
  self_intersections_check(mesh, topology, pass, masks, stats);
  pieces_color(pass);
  if (one_sheet_per_round) {
    std::iota(pass.color.begin(), pass.color.end(), 0);
    pass.round_count = piece_count;
  }
  stats.sheet_passes += piece_count;
  stats.phase_seconds["sheets"] += seconds_since(t_sheets);
  return pass;
}

// Round by round over the whole mesh (SheetControl): the pass's output, and per output hex the
// input hex it came from.
HexMesh sheet_rounds_run(const HexMesh& mesh, const HexTopology& topology,
                         const std::vector<int32_t>& targets, const SheetControl& control,
                         RefineStats& stats, std::vector<int32_t>& origin) {
  const SheetPass pass =
      sheet_pass_prepare(mesh, topology, targets, control.one_sheet_per_round, stats);
  const auto t_rounds = Clock::now();
  HexMesh current;
  current.points = mesh.points;
  current.hexes = mesh.hexes;
  RoundState state;
  state.node_marked = pass.marking.node_marked;
  state.occurrence.assign(mesh.hexes.size(), {-1, -1, -1});
  for (size_t i = 0; i < pass.region_hexes.size(); ++i)
    state.occurrence[pass.region_hexes[i]] = pass.pieces.hex_piece[i];
  state.origin.resize(mesh.hexes.size());
  std::iota(state.origin.begin(), state.origin.end(), 0);
  std::vector<int32_t> tag_of(mesh.hexes.size(), -1);
  for (int32_t h : pass.region_hexes) tag_of[h] = static_cast<int32_t>(TemplateTag::sheet);
  for (int32_t round = 0; round < pass.round_count; ++round) {
    const RoundCounts c = sheet_round(current, state, pass.color, round,
                                      [&](int32_t p) { return pass.piece_name(topology, p); });
    stats.hexes_created += c.created;
    stats.hexes_deleted += c.deleted;
    if (control.observer) {
      mesh_attributes_from_parents(mesh, state.origin, tag_of, current);
      control.observer(current, round);
    }
  }
  mesh_attributes_from_parents(mesh, state.origin, tag_of, current);
  origin = std::move(state.origin);
  stats.phase_seconds["sheets"] += seconds_since(t_rounds);
  return current;
}

}  // namespace

SheetPattern hex_axis_pattern(uint16_t split_mask, int axis) {
  const uint16_t split = split_mask & axis_mask(axis);
  switch (std::popcount(split)) {
    case 0:
      return SheetPattern::none;
    case 1:
      return SheetPattern::one_to_five;
    case 2: {
      const int a = std::countr_zero(split);
      const int b = std::countr_zero(static_cast<uint16_t>(split & (split - 1)));
      return edges_share_face(a, b) ? SheetPattern::one_to_four : SheetPattern::multiply_connected;
    }
    case 4:
      return SheetPattern::one_to_three;
    default:
      return SheetPattern::multiply_connected;
  }
}

uint16_t hex_split_mask(const HexMesh& mesh, const std::vector<uint8_t>& node_marked, int32_t h) {
  const HexCell& c = mesh.hexes[h];
  uint16_t mask = 0;
  for (int e = 0; e < 12; ++e)
    if (node_marked[c[hex_edges[e][0]]] && node_marked[c[hex_edges[e][1]]])
      mask |= static_cast<uint16_t>(1u << e);
  return mask;
}

bool hex_is_multiply_connected(uint16_t split_mask) {
  for (int k = 0; k < 3; ++k)
    if (hex_axis_pattern(split_mask, k) == SheetPattern::multiply_connected) return true;
  return false;
}

SheetMarking sheet_mark(const HexMesh& mesh, const HexTopology& topology, const Targets& targets) {
  SheetMarking m;
  marking_seed(mesh, targets.hexes, m);
  marking_grow(mesh, topology, targets.hexes, m);
  return m;
}

RefinementPlan sheet_plan(const HexMesh& mesh, const HexTopology& topology,
                          const std::vector<int32_t>& targets, const RefineOptions& options,
                          RefineStats& stats, const TemplateLibrary& templates) {
  const SheetPass pass = sheet_pass_prepare(mesh, topology, targets, false, stats);
  const auto t_composites = Clock::now();
  // Configuration: 8 mark bits, then per axis 2 bits of (rank + 1).
  std::vector<std::unique_ptr<SheetComposite>> composites(1u << 14);
  std::vector<const SheetComposite*> composite_of(pass.region_hexes.size());
  std::vector<uint8_t> is_target(mesh.hexes.size(), 0);
  for (int32_t t : targets) is_target[t] = 1;
  RefinementPlan plan;
  plan.uses.reserve(pass.region_hexes.size());
  for (size_t i = 0; i < pass.region_hexes.size(); ++i) {
    const int32_t h = pass.region_hexes[i];
    uint8_t marks = 0;
    for (int v = 0; v < 8; ++v)
      marks |= static_cast<uint8_t>(pass.marking.node_marked[mesh.hexes[h][v]] << v);
    std::array<int32_t, 3> c{};
    for (int k = 0; k < 3; ++k) {
      const int32_t piece = pass.pieces.hex_piece[i][k];
      c[k] = piece < 0 ? -1 : pass.color[piece];
    }
    std::array<int8_t, 3> rank{};
    for (int k = 0; k < 3; ++k) {
      rank[k] = -1;
      if (c[k] < 0) continue;
      int r = 0;  // dense rank among the hex's distinct colours
      for (int m = 0; m < 3; ++m) {
        bool counted = false;
        for (int q = 0; q < m; ++q) counted = counted || c[q] == c[m];
        r += !counted && c[m] >= 0 && c[m] < c[k];
      }
      rank[k] = static_cast<int8_t>(r);
    }
    const uint32_t key = marks | (rank[0] + 1) << 8 | (rank[1] + 1) << 10 | (rank[2] + 1) << 12;
    if (!composites[key]) {
      composites[key] =
          sheet_composite_build(marks, rank, h, templates, options.placement.configuration_table,
                                options.placement.method != PlacementMethod::trilinear);
      if (!composites[key]->positive)
        throw OperationError("sheet refinement: the refinement of input hex " + std::to_string(h) +
                             " is inverted even on the reference cube");
    }
    composite_of[i] = composites[key].get();
    plan.uses.push_back({HexId{h}, composite_of[i]->tmpl.get(), 0, is_target[h] != 0});
    stats.hexes_created += composite_of[i]->counts.created;
    stats.hexes_deleted += composite_of[i]->counts.deleted;
  }
  // Shared faces subdivided alike (an unrefined neighbour's face is whole).
  const uint64_t whole_face = sheet_whole_face_hash();
  std::vector<uint8_t> in_region(mesh.hexes.size(), 0);
  for (int32_t h : pass.region_hexes) in_region[h] = 1;
  std::vector<uint64_t> face_seen(topology.face_count(), 0);
  for (size_t i = 0; i < pass.region_hexes.size(); ++i) {
    const int32_t h = pass.region_hexes[i];
    for (int lf = 0; lf < 6; ++lf) {
      const int32_t f = topology.hex_face_ids[h][lf];
      if (face_is_boundary(topology, f)) continue;
      const uint64_t hash =
          composite_of[i]->face_hash[lf][sheet_face_frame_index(mesh.hexes[h], lf)];
      const int32_t n = hex_face_neighbor(topology, h, lf);
      const uint64_t other = in_region[n] ? face_seen[f] : whole_face;
      if (in_region[n] && other == 0) {
        face_seen[f] = hash;
        continue;
      }
      if (other != hash)
        throw OperationError("sheet refinement: input hexes " + std::to_string(h) + " and " +
                             std::to_string(n) +
                             " would subdivide their shared face differently (their sheets "
                             "split its edges in different passes)");
    }
  }
  for (auto& c : composites)
    if (c) plan.owned.push_back(std::move(c->tmpl));
  stats.phase_seconds["sheets"] += seconds_since(t_composites);
  return plan;
}

RefineResult sheet_refine(const HexMesh& mesh, const Targets& targets,
                          const RefineOptions& options) {
  return refine(refine_method("sheet"), mesh, targets, options);
}

RefineResult sheet_refine(const HexMesh& mesh, const Targets& targets, const RefineOptions& options,
                          const SheetRoundObserver& observer) {
  SheetControl control;
  control.observer = observer;
  return sheet_refine(mesh, targets, options, control);
}

RefineResult sheet_refine(const HexMesh& mesh, const Targets& targets, const RefineOptions& options,
                          const SheetControl& control) {
  if (control.composites && !control.observer && !control.one_sheet_per_round)
    return sheet_refine(mesh, targets, options);
  refine_input_validate(mesh, targets, options, "sheet refinement");
  const auto t0 = Clock::now();
  RefineResult result;
  RefineStats& stats = result.stats;
  stats.method = "sheet";
  stats.initial_hexes = mesh.hex_count();
  for (const char* phase : {"marking", "growth", "sheets"}) stats.phase_seconds[phase] = 0;

  HexMesh current = mesh;
  std::erase_if(current.attributes,
                [](const HexAttribute& a) { return a.name == attribute_parent_hex; });
  std::vector<int32_t> pass_targets = targets.hexes;
  for (int pass = 0; pass < options.passes; ++pass) {
    const HexTopology topology = topology_build(current);
    std::vector<int32_t> origin;
    HexMesh next = sheet_rounds_run(current, topology, pass_targets, control, stats, origin);
    if (pass + 1 < options.passes) {
      // The next pass refines the descendants of this pass's (given) targets.
      std::vector<uint8_t> was_target(current.hexes.size(), 0);
      for (int32_t t : pass_targets) was_target[t] = 1;
      pass_targets.clear();
      for (int32_t i = 0; i < next.hex_count(); ++i)
        if (was_target[origin[i]]) pass_targets.push_back(i);
    }
    current = std::move(next);
  }
  result.mesh = std::move(current);
  refine_stats_finish(stats, result.mesh, seconds_since(t0));
  return result;
}

}  // namespace hexrefine
