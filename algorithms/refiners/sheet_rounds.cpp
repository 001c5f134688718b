/// \file
/// Rounds and composites of sheet refinement (see sheet.cpp for the pass and the citation).
///
/// A round refines each hex in the axes of its pieces of that round's colour with the directional
/// template its split pattern calls for (TemplateSet::sheet_directional), as one plan applied by
/// the engine to the whole current mesh. Composites: what the rounds do to a hex depends only on
/// its corner marks and on the order in which its axes' pieces are refined (two axes of one
/// piece: the same round). Inside the hex, every node a round creates is marked or not by the
/// same rule whoever creates it, so the cells' split patterns are a function of that
/// configuration. The rounds of each configuration met are run once on a one-hex mesh (the unit
/// cube) and the resulting cells become one template (TemplateTag::sheet), applied to every hex of
/// that configuration with its nodes keyed on the input's edges and faces. Neighbours must
/// subdivide their shared face alike: the round path checks this per split edge and round, the
/// composites on their final face subdivisions (face hashes), before anything is applied.

#include "algorithms/refiners/sheet_rounds.hpp"

#include "algorithms/refiners/sheet.hpp"
#include "algorithms/templates/template_reference.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

#include "mesh/error.hpp"
#include "mesh/hex_convention.hpp"
#include "mesh/quality.hpp"

namespace hexrefine::sheet_detail {

namespace {

constexpr double kSnap = 1e-9;

uint16_t axis_mask(int axis) {
  uint16_t m = 0;
  for (int e : hex_axis_edges[axis]) m |= static_cast<uint16_t>(1u << e);
  return m;
}

Orientation orientation_make(const TemplateChoice& choice) {
  const HexTemplate& t = *choice.tmpl;
  const CubeSymmetry& sym = cube_symmetries()[choice.symmetry];
  Orientation o;
  o.choice = choice;
  const uint16_t mask = cube_symmetry_edge_mask(sym, template_split_edges(t));
  for (int e = 0; e < 12; ++e)
    if (mask & (1u << e)) o.axes |= static_cast<uint8_t>(1u << hex_edge_axis[e]);
  for (const auto& child : t.children) {
    std::array<std::array<double, 3>, 8> p{};
    for (int j = 0; j < 8; ++j) {
      const int canonical = sym.reflection ? hex_reflected_order[j] : j;
      p[j] = cube_symmetry_apply(sym, t.nodes[child[canonical]].ref);
    }
    std::array<int8_t, 3> axes{};
    for (int k = 0; k < 3; ++k) {
      int found = -1;
      bool consistent = true;
      for (int e : hex_axis_edges[k]) {
        const auto& a = p[hex_edges[e][0]];
        const auto& b = p[hex_edges[e][1]];
        int moving = 0, along = -1;
        for (int c = 0; c < 3; ++c)
          if (std::abs(a[c] - b[c]) > kSnap) ++moving, along = c;
        if (moving != 1) continue;
        if (found >= 0 && found != along) consistent = false;
        found = along;
      }
      axes[k] = static_cast<int8_t>(consistent ? found : -1);
    }
    uint8_t edge_nodes = 0;
    for (int j = 0; j < 8; ++j) {
      int extreme = 0;
      for (int c = 0; c < 3; ++c)
        if (std::abs(p[j][c]) < kSnap || std::abs(p[j][c] - 1.0) < kSnap) ++extreme;
      if (extreme == 2) edge_nodes |= static_cast<uint8_t>(1u << j);
    }
    // A composite (1-9, 1-27) is the sequence of 1-3s in a fully marked hex: there, every
    // node lies on a split edge of an intermediate hex and is marked.
    if (std::popcount(o.axes) > 1) edge_nodes = 0xFF;
    o.child_axis.push_back(axes);
    o.child_edge_nodes.push_back(edge_nodes);
  }
  return o;
}

uint64_t hash_mix(uint64_t h, int64_t x) {
  h ^= static_cast<uint64_t>(x) + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
  return h;
}

// Hashes of the face subdivisions of a template with exact parameters (see SheetComposite).
void composite_face_hashes(const HexTemplate& t, std::array<std::array<uint64_t, 8>, 6>& out) {
  constexpr int64_t unit = template_param_unit;
  std::vector<std::array<int64_t, 3>> param;
  for (const TemplateNode& n : t.nodes)
    param.push_back({std::llround(n.ref[0] * unit), std::llround(n.ref[1] * unit),
                     std::llround(n.ref[2] * unit)});
  for (int lf = 0; lf < 6; ++lf) {
    const int axis = lf / 2;
    const int64_t level = (lf % 2) * unit;
    for (int i0 = 0; i0 < 4; ++i0)
      for (int step : {1, 3}) {
        const int* o = hex_corner[hex_faces[lf][i0]];
        const int* c1 = hex_corner[hex_faces[lf][(i0 + step) % 4]];
        const int* c3 = hex_corner[hex_faces[lf][(i0 + 3 * step) % 4]];
        std::vector<std::array<std::array<int64_t, 2>, 4>> quads;
        for (const auto& child : t.children)
          for (int cf = 0; cf < 6; ++cf) {
            std::array<std::array<int64_t, 2>, 4> q;
            bool on = true;
            for (int i = 0; i < 4; ++i) {
              const auto& p = param[child[hex_faces[cf][i]]];
              on = on && p[axis] == level;
              int64_t u = 0, v = 0;
              for (int k = 0; k < 3; ++k) {
                u += (c1[k] - o[k]) * (p[k] - o[k] * unit);
                v += (c3[k] - o[k]) * (p[k] - o[k] * unit);
              }
              q[i] = {u, v};
            }
            if (!on) continue;
            std::sort(q.begin(), q.end());
            quads.push_back(q);
          }
        std::sort(quads.begin(), quads.end());
        uint64_t h = 0xCBF29CE484222325ull;
        for (const auto& q : quads)
          for (const auto& p : q) h = hash_mix(hash_mix(h, p[0]), p[1]);
        out[lf][2 * i0 + (step == 1 ? 0 : 1)] = h | 1;  // never 0: 0 marks "not seen"
      }
  }
}

}  // namespace

const Orientation* sheet_orientation(uint16_t split_mask) {
  static const std::vector<Orientation> table = [] {
    std::vector<Orientation> out(4096);
    for (int m = 1; m < 4096; ++m) {
      const TemplateChoice c =
          template_for_mask(static_cast<uint16_t>(m), TemplateSet::sheet_directional);
      if (c.tmpl) out[m] = orientation_make(c);
    }
    return out;
  }();
  const Orientation& o = table[split_mask & 0xFFF];
  return o.choice.tmpl ? &o : nullptr;
}

RoundCounts sheet_round(HexMesh& mesh, RoundState& state, const std::vector<int32_t>& color,
                        int32_t round, const std::function<std::string(int32_t)>& piece_name,
                        TemplatePositions positions, const TemplateLibrary& templates) {
  const int32_t count = mesh.hex_count();
  const HexTopology rt = topology_build(mesh);
  RefinementPlan plan;
  std::vector<const Orientation*> orientation_of(count, nullptr);
  std::vector<uint8_t> axes_of(count, 0);  // axes refined in this round
  for (int32_t h = 0; h < count; ++h) {
    auto& occ = state.occurrence[h];
    uint8_t axes = 0;
    int32_t piece = -1;
    for (int k = 0; k < 3; ++k) {
      if (occ[k] < 0 || color[occ[k]] != round) continue;
      // Two pieces of one colour never share a hex; one piece twice is a self-intersection.
      if (piece >= 0 && occ[k] != piece)
        throw OperationError("sheet refinement: a hex descending from input hex " +
                             std::to_string(state.origin[h]) +
                             " would be refined in two directions in one round (sheets of "
                             "edges " +
                             piece_name(piece) + " and " + piece_name(occ[k]) + ")");
      piece = occ[k];
      axes |= static_cast<uint8_t>(1u << k);
    }
    if (!axes) continue;
    uint16_t wanted = 0;
    for (int k = 0; k < 3; ++k)
      if (axes & (1u << k)) {
        wanted |= axis_mask(k);
        occ[k] = -1;
      }
    const uint16_t split = hex_split_mask(mesh, state.node_marked, h) & wanted;
    if (!split) continue;
    const Orientation* o = sheet_orientation(split);
    if (!o)
      throw OperationError("sheet refinement: a hex descending from input hex " +
                           std::to_string(state.origin[h]) +
                           " has a split pattern with no directional template (" +
                           std::to_string(std::popcount(split)) + " edges split in " +
                           std::to_string(std::popcount(axes)) +
                           " directions) in the sheet of edge " + piece_name(piece));
    orientation_of[h] = o;
    axes_of[h] = o->axes;
    // The orientation's template as `templates` has it (its own reference positions).
    plan.uses.push_back({HexId{h}, &templates.of(o->choice.tmpl->tag), o->choice.symmetry, false});
  }
  // Conformity by construction needs every hex around a split edge to split it in this round.
  for (const TemplateUse& u : plan.uses) {
    const int32_t h = index_of(u.hex);
    const uint16_t split = hex_split_mask(mesh, state.node_marked, h);
    for (int e = 0; e < 12; ++e) {
      if (!(split & (1u << e)) || !(axes_of[h] & (1u << hex_edge_axis[e]))) continue;
      const int32_t id = rt.hex_edge_ids[h][e];
      for (int32_t g : edge_hexes(rt, id)) {
        const int le = hex_local_edge(rt, g, id);
        if (!(axes_of[g] & (1u << hex_edge_axis[le])))
          throw OperationError("sheet refinement: hexes descending from input hexes " +
                               std::to_string(state.origin[h]) + " and " +
                               std::to_string(state.origin[g]) +
                               " do not split their shared edge in the same sheet pass");
      }
    }
  }

  PlanApplyResult applied = plan_apply(mesh, rt, plan, 1, positions);
  RoundCounts counts{applied.hexes_created, applied.hexes_deleted};

  // The next state: occurrences inherited through the children's axes, edge nodes marked.
  RoundState next;
  const int32_t out_count = applied.mesh.hex_count();
  next.occurrence.resize(out_count);
  next.origin.resize(out_count);
  next.node_marked = std::move(state.node_marked);
  next.node_marked.resize(applied.mesh.points.size(), 0);
  int32_t at = 0;
  for (int32_t h = 0; h < count; ++h) {
    const Orientation* o = orientation_of[h];
    if (!o) {
      next.occurrence[at] = state.occurrence[h];
      next.origin[at++] = state.origin[h];
      continue;
    }
    for (size_t child = 0; child < o->child_axis.size(); ++child, ++at) {
      next.origin[at] = state.origin[h];
      for (int k = 0; k < 3; ++k) {
        // The parent's refined axes were set to -1 above: children are done in them.
        const int p = o->child_axis[child][k];
        next.occurrence[at][k] = p < 0 ? -1 : state.occurrence[h][p];
      }
      const uint8_t edge_nodes = o->child_edge_nodes[child];
      for (int j = 0; j < 8; ++j)
        if (edge_nodes & (1u << j)) next.node_marked[applied.mesh.hexes[at][j]] = 1;
    }
  }
  mesh = std::move(applied.mesh);
  state = std::move(next);
  return counts;
}

std::unique_ptr<SheetComposite> sheet_composite_build(uint8_t marks,
                                                      const std::array<int8_t, 3>& rank,
                                                      int32_t input_hex,
                                                      const TemplateLibrary& templates,
                                                      bool configuration_table, bool placed) {
  const std::vector<int32_t> color = {0, 1, 2};
  const int32_t rounds = 1 + std::max({rank[0], rank[1], rank[2]});
  auto c = std::make_unique<SheetComposite>();
  // The rounds on the unit cube, at the templates' exact positions and then at their reference
  // positions: the same nodes in the same order (what is created depends on the marks alone).
  auto run = [&](TemplatePositions positions, bool count) {
    HexMesh cube;
    RoundState state;
    for (int v = 0; v < 8; ++v) {
      cube.points.emplace_back(hex_corner[v][0], hex_corner[v][1], hex_corner[v][2]);
      state.node_marked.push_back((marks >> v) & 1);
    }
    cube.hexes.push_back({0, 1, 2, 3, 4, 5, 6, 7});
    state.origin = {input_hex};
    state.occurrence = {{rank[0], rank[1], rank[2]}};
    for (int32_t round = 0; round < rounds; ++round) {
      const RoundCounts r = sheet_round(
          cube, state, color, round,
          [&](int32_t piece) {
            std::string axes;
            for (int k = 0; k < 3; ++k)
              if (rank[k] == piece) axes += "xyz"[k];
            return "through local axes " + axes + " of input hex " + std::to_string(input_hex);
          },
          positions, templates);
      if (!count) continue;
      c->counts.created += r.created;
      c->counts.deleted += r.deleted;
    }
    return cube;
  };
  const HexMesh cube = run(TemplatePositions::exact, true);
  const HexMesh at_reference = placed ? run(TemplatePositions::reference, false) : cube;
  c->tmpl = std::make_unique<HexTemplate>();
  HexTemplate& t = *c->tmpl;
  t.tag = TemplateTag::sheet;
  for (const Eigen::Vector3d& x : cube.points) t.nodes.push_back({{x[0], x[1], x[2]}});
  if (at_reference.points != cube.points)
    for (const Eigen::Vector3d& x : at_reference.points) t.reference.push_back({x[0], x[1], x[2]});
  for (int32_t h = 0; h < cube.hex_count(); ++h) {
    std::array<int16_t, 8> child{};
    for (int k = 0; k < 8; ++k) child[k] = static_cast<int16_t>(cube.hexes[h][k]);
    t.children.push_back(child);
    c->positive = c->positive && hex_corners_positive(hex_points(cube, h));
  }
  if (configuration_table && placed) template_reference_from_configurations(t, templates);
  template_compile(t, 1, placed);
  composite_face_hashes(t, c->face_hash);
  return c;
}

uint64_t sheet_whole_face_hash() {
  static const uint64_t hash = [] {
    HexTemplate whole;
    for (int v = 0; v < 8; ++v)
      whole.nodes.push_back(
          {{double(hex_corner[v][0]), double(hex_corner[v][1]), double(hex_corner[v][2])}});
    whole.children.push_back({0, 1, 2, 3, 4, 5, 6, 7});
    std::array<std::array<uint64_t, 8>, 6> h{};
    composite_face_hashes(whole, h);
    return h[0][0];
  }();
  return hash;
}

int sheet_face_frame_index(const HexCell& hex, int lf) {
  int i0 = 0;
  for (int c = 1; c < 4; ++c)
    if (hex[hex_faces[lf][c]] < hex[hex_faces[lf][i0]]) i0 = c;
  const bool step1 = hex[hex_faces[lf][(i0 + 1) % 4]] < hex[hex_faces[lf][(i0 + 3) % 4]];
  return 2 * i0 + (step1 ? 0 : 1);
}

}  // namespace hexrefine::sheet_detail
