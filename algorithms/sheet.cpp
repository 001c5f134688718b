// Harris-style sheet refinement: the baseline the Selective Approach is compared against.
//
// Citation: J. Parrish, "A Selective Approach to Conformal Refinement of Unstructured Hexahedral
// Finite Element Meshes", MS thesis, Brigham Young University (chapter 2, chapter 4, Appendices
// C, D, E, G), describing the sheet refinement implemented by Harris (template insertion in
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
//  3. Sheets. Only hexes with a split edge change. On the original mesh the dual is walked from
//     those hexes: the split edges of one direction of one hex are parallel, so they belong to
//     one dual sheet; a union-find over the split edges gives the connected pieces of the dual
//     sheets that must be refined (a sheet pass refines one such piece: all hexes around each
//     split edge at once, which keeps the mesh conformal). A piece that occupies two directions
//     of one hex is a sheet crossing itself where it must refine (Harris' special case): if all
//     edges of the hex are split, the pass refines both directions at once with the composite
//     1-9 template (1-3 across one direction then the other, as one template; 1-27 for three);
//     otherwise a transition template for two directions would be needed, and the case is
//     refused (OperationError naming the sheet and the hexes). The dual sheets that cross
//     themselves in a refined hex are counted (self_intersection_cases, per hex).
//     Pieces are coloured first-fit so that no two pieces of one colour share a hex; one colour
//     is one round, and processing the pieces of one round together is the same as processing
//     them one after the other, since they share no hex (sheet_passes counts the pieces). For a
//     structured brick the rounds are the x-, y- and z-like sheets.
//  4. Rounds. The refined region (the hexes with a split edge) is refined round by round with
//     the directional templates. Every hex carries, per local axis, the sheet piece it still
//     has to be refined in; a child's axis inherits the piece of the parent axis its split
//     edges run along (computed from the template data once per template orientation), the
//     axis just refined is done. New nodes inside a split edge are marked (so the strips of a
//     1-3 face are split in the next direction); new face and interior nodes are not. A fully
//     refined hex goes 1 -> 3 -> 9 -> 27 (13 deleted, 39 created, thesis 4.3).
//     Two ways to run them, with the same mesh: (a) composites (default): what the rounds do to
//     one hex depends only on its corner marks and the order of its axes' pieces, so the rounds
//     of each configuration met are run once on a one-hex region (the reference cube) and the
//     result is applied to all hexes of that configuration as one template (templates_apply,
//     nodes keyed on the input's edges and faces); neighbours' shared faces are compared on
//     their final subdivisions before anything is applied. (b) round by round on the whole
//     region (an observer, one sheet per pass, or SheetControl::composites = false): the region
//     is copied with compact node ids and every round builds the next mesh (templates_apply
//     over that mesh's topology), as Harris' implementation did.
//  5. Assembly: the untouched hexes and the refined region in input hex order. Every refined
//     hex is tagged TemplateTag::sheet, its refinement level one above its input hex's.
// Options: `passes` repeats the whole on the descendants of the given targets; the selective
// refiner's options (ranking, propagation, ebe_only, buffer) do not apply and are ignored.
// A safety check before every round makes sure all hexes around each split edge split it in
// that round (OperationError otherwise), so a result is conformal by construction.
//
// Speed: every step is linear in the size of the refined region (plus one pass over the mesh's
// edges for the dual sheet labels); there is no rescan of the mesh per sheet. With composites
// the output is written once, as by the selective refiner; round by round, every intermediate
// mesh and its topology are built (the thesis' intrinsic 39 created + 13 deleted per hex).

#include "algorithms/sheet.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <functional>
#include <memory>
#include <numeric>
#include <string>

#include "algorithms/templates.hpp"
#include "mesh/error.hpp"
#include "mesh/hex_convention.hpp"
#include "mesh/quality.hpp"

namespace hexrefine {

namespace {

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

// ---------------------------------------------------------------------------------------------
// Directional templates and their 48 orientations.

// One directional template in one orientation, with what the rounds need to know about its
// children: per child local axis, the parent local axis its edges run along (-1 when its edges
// are not parallel to a parent axis, as in the skewed children of 1-5: such an axis has no
// edge between two marked nodes, see orientation_make), and which child vertices lie inside a
// parent edge (they get marked).
struct Orientation {
  const HexTemplate* tmpl = nullptr;
  int8_t symmetry = 0;
  uint8_t axes = 0;  // bit k: refines parent local axis k (two or three bits for 1-9, 1-27)
  std::vector<std::array<int8_t, 3>> child_axis;
  std::vector<uint8_t> child_edge_nodes;
};

struct DirectionalTable {
  std::vector<Orientation> orientations;
  std::array<int16_t, 4096> by_mask{};  // split mask (edges of one axis) -> orientation, or -1
};

// 1-9: the x- and y-parallel edges split, 3 x 3 columns: 1-3 across x then across y, as one
// template. Used where a dual sheet crosses itself in a fully marked hex (Harris' special case:
// the hex is refined in its two directions of that sheet within the sheet's pass).
const HexTemplate& sheet_template_1_9() {
  static const HexTemplate t = [] {
    HexTemplate r;
    r.tag = TemplateTag::sheet;
    auto id = [](int i, int j, int k) { return static_cast<int16_t>(i + 4 * (j + 4 * k)); };
    for (int k = 0; k < 2; ++k)
      for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) r.nodes.push_back({{i / 3.0, j / 3.0, double(k)}});
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i)
        r.children.push_back({id(i, j, 0), id(i + 1, j, 0), id(i + 1, j + 1, 0), id(i, j + 1, 0),
                              id(i, j, 1), id(i + 1, j, 1), id(i + 1, j + 1, 1), id(i, j + 1, 1)});
    return r;
  }();
  return t;
}

// The directional templates (one direction) and the composites for self-intersecting sheets
// (two directions: 1-9; three: 1-27). Their split masks never coincide.
const std::vector<const HexTemplate*>& directional_templates() {
  static const std::vector<const HexTemplate*> list = {
      &template_1_3(), &template_1_4(), &template_1_5(), &sheet_template_1_9(), &template_1_27()};
  return list;
}

// Children vertex order after templates_apply: a reflection swaps local axes 1 and 3.
constexpr int kReflectedVertex[8] = {0, 3, 2, 1, 4, 7, 6, 5};
constexpr double kSnap = 1e-9;

Orientation orientation_make(const HexTemplate& t, int s) {
  const CubeSymmetry& sym = cube_symmetries()[s];
  Orientation o;
  o.tmpl = &t;
  o.symmetry = static_cast<int8_t>(s);
  const uint16_t mask = cube_symmetry_edge_mask(sym, template_split_edges(t));
  for (int e = 0; e < 12; ++e)
    if (mask & (1u << e)) o.axes |= static_cast<uint8_t>(1u << hex_edge_axis[e]);
  for (const auto& child : t.children) {
    std::array<std::array<double, 3>, 8> p{};
    for (int j = 0; j < 8; ++j) {
      const int canonical = sym.reflection ? kReflectedVertex[j] : j;
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

const DirectionalTable& directional_table() {
  static const DirectionalTable table = [] {
    DirectionalTable d;
    d.by_mask.fill(-1);
    for (const HexTemplate* t : directional_templates()) {
      const uint16_t canonical = template_split_edges(*t);
      for (int s = 0; s < 48; ++s) {
        const uint16_t m = cube_symmetry_edge_mask(cube_symmetries()[s], canonical);
        if (d.by_mask[m] >= 0) continue;
        d.by_mask[m] = static_cast<int16_t>(d.orientations.size());
        d.orientations.push_back(orientation_make(*t, s));
      }
    }
    return d;
  }();
  return table;
}

// ---------------------------------------------------------------------------------------------

struct UnionFind {
  std::vector<int32_t> parent;
  explicit UnionFind(int32_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int32_t find(int32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void unite(int32_t a, int32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

void targets_validate(const HexMesh& mesh, const Targets& targets) {
  int32_t previous = -1;
  for (int32_t t : targets.hexes) {
    if (t < 0 || t >= mesh.hex_count())
      throw InputError("sheet refinement: target hex " + std::to_string(t) +
                       " is out of range 0.." + std::to_string(mesh.hex_count() - 1));
    if (t <= previous)
      throw InputError("sheet refinement: targets must be ascending and unique (hex " +
                       std::to_string(t) + " after " + std::to_string(previous) + ")");
    previous = t;
  }
}

void marking_seed(const HexMesh& mesh, const Targets& targets, SheetMarking& m) {
  m.node_marked.assign(mesh.points.size(), 0);
  m.hex_target.assign(mesh.hexes.size(), 0);
  m.added_targets = 0;
  for (int32_t t : targets.hexes) {
    m.hex_target[t] = 1;
    for (int32_t v : mesh.hexes[t]) m.node_marked[v] = 1;
  }
}

// Waves, as "add the multiply-connected transitions to the targets and repeat": every wave
// decides all candidates on the marks of the previous wave, then adds them together. (Adding
// one hex at a time would depend on the visiting order: a hex can get all its nodes marked by
// its neighbours' growth and be fully refined without ever being added, which changes
// added_targets; the thesis' L-shaped case adds exactly the 810 non-target hexes.)
void marking_grow(const HexMesh& mesh, const HexTopology& topology, const Targets& targets,
                  SheetMarking& m) {
  std::vector<uint8_t> queued(mesh.hexes.size(), 0);
  std::vector<int32_t> candidates, added, newly_marked;
  auto enqueue_around = [&](int32_t v) {
    for (int32_t g : node_hexes(topology, v))
      if (!m.hex_target[g] && !queued[g]) {
        queued[g] = 1;
        candidates.push_back(g);
      }
  };
  for (int32_t t : targets.hexes)
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

// The hexes being refined, with compact node ids, and what each still has to do.
struct Region {
  HexMesh mesh;
  std::vector<int32_t> node_input;  // first `input_nodes` local nodes -> input
  int32_t input_nodes = 0;
  std::vector<uint8_t> node_marked;                // per local node
  std::vector<int32_t> origin;                     // per hex: the input hex it descends from
  std::vector<std::array<int32_t, 3>> occurrence;  // per hex and local axis: piece, or -1
};

struct PassOutput {
  HexMesh mesh;
  std::vector<int32_t> origin;  // per output hex: input hex it descends from
};

// The input mesh with the refined region in place of the affected hexes (input hex order).
PassOutput region_assemble(const HexMesh& input, const std::vector<uint8_t>& affected,
                           const Region& region) {
  PassOutput out;
  HexMesh& m = out.mesh;
  const int32_t np = input.point_count();
  m.points = input.points;
  m.points.insert(m.points.end(), region.mesh.points.begin() + region.input_nodes,
                  region.mesh.points.end());
  auto node_out = [&](int32_t local) {
    return local < region.input_nodes ? region.node_input[local]
                                      : np + (local - region.input_nodes);
  };
  const size_t total = input.hexes.size() + region.mesh.hexes.size() -
                       static_cast<size_t>(std::count(affected.begin(), affected.end(), 1));
  m.hexes.reserve(total);
  out.origin.reserve(total);
  std::vector<uint8_t> refined;
  refined.reserve(total);
  size_t next = 0;
  for (int32_t h = 0; h < input.hex_count(); ++h) {
    if (!affected[h]) {
      m.hexes.push_back(input.hexes[h]);
      out.origin.push_back(h);
      refined.push_back(0);
      continue;
    }
    for (; next < region.origin.size() && region.origin[next] == h; ++next) {
      HexCell c = region.mesh.hexes[next];
      for (int32_t& v : c) v = node_out(v);
      m.hexes.push_back(c);
      out.origin.push_back(h);
      refined.push_back(1);
    }
  }
  for (const HexAttribute& a : input.attributes) {
    HexAttribute copy{a.name, std::vector<int32_t>(m.hexes.size())};
    for (size_t i = 0; i < m.hexes.size(); ++i) copy.values[i] = a.values[out.origin[i]];
    m.attributes.push_back(std::move(copy));
  }
  std::vector<int32_t>& tag = mesh_attribute(m, attribute_template_tag, 0);
  std::vector<int32_t>& level = mesh_attribute(m, attribute_refinement_level, 0);
  for (size_t i = 0; i < m.hexes.size(); ++i)
    if (refined[i]) {
      tag[i] = static_cast<int32_t>(TemplateTag::sheet);
      ++level[i];
    }
  return out;
}

// Orientation (sign of the corner tetrahedron) at each corner; false if one is not positive.
bool hex_corners_positive(const HexMesh& m, int32_t h) {
  const HexCell& c = m.hexes[h];
  for (int v = 0; v < 8; ++v) {
    const Eigen::Vector3d& o = m.points[c[v]];
    Eigen::Vector3d d[3];
    for (int k = 0; k < 3; ++k) {
      const int e = hex_vertex_edges[v][k];
      const int w = hex_edges[e][0] == v ? hex_edges[e][1] : hex_edges[e][0];
      d[k] = (m.points[c[w]] - o) * (hex_corner[w][k] > hex_corner[v][k] ? 1.0 : -1.0);
    }
    if (d[0].cross(d[1]).dot(d[2]) <= 0) return false;
  }
  return true;
}

std::string hex_list(const std::vector<int32_t>& hexes) {
  std::string s;
  for (size_t i = 0; i < hexes.size() && i < 10; ++i)
    s += (i ? ", " : "") + std::to_string(hexes[i]);
  if (hexes.size() > 10) s += ", ... (" + std::to_string(hexes.size()) + " hexes)";
  return s;
}

// Hexes created and deleted by the rounds.
struct RoundCounts {
  int64_t created = 0, deleted = 0;
};

// Refines `region` round by round: in round r, every hex refines the local axes whose piece has
// colour r, with the directional template its split edges (node marks) call for; children
// inherit the pieces of the parent axes their edges run along, new nodes inside split edges
// are marked. `piece_name` describes a piece for messages; `after_round`, if set, is called
// after every round. Throws OperationError where a hex has no directional template or two
// hexes around a split edge would not split it in the same round.
RoundCounts region_run_rounds(Region& region, const std::vector<int32_t>& color,
                              int32_t round_count,
                              const std::function<std::string(int32_t)>& piece_name,
                              const std::function<void(int32_t)>& after_round) {
  RoundCounts counts;
  const DirectionalTable& table = directional_table();
  for (int32_t round = 0; round < round_count; ++round) {
    const HexMesh& cur = region.mesh;
    const int32_t count = cur.hex_count();
    const HexTopology rt = topology_build(cur);
    std::vector<TemplateApplication> apps;
    std::vector<int16_t> orientation_of(count, -1);
    std::vector<uint8_t> axes_of(count, 0);  // axes refined in this round
    for (int32_t h = 0; h < count; ++h) {
      auto& occ = region.occurrence[h];
      uint8_t axes = 0;
      int32_t piece = -1;
      for (int k = 0; k < 3; ++k) {
        if (occ[k] < 0 || color[occ[k]] != round) continue;
        // Two pieces of one colour never share a hex; one piece twice is a self-intersection.
        if (piece >= 0 && occ[k] != piece)
          throw OperationError("sheet refinement: a hex descending from input hex " +
                               std::to_string(region.origin[h]) +
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
      const uint16_t split = hex_split_mask(cur, region.node_marked, h) & wanted;
      if (!split) continue;
      const int16_t o = table.by_mask[split];
      if (o < 0)
        throw OperationError("sheet refinement: a hex descending from input hex " +
                             std::to_string(region.origin[h]) +
                             " has a split pattern with no directional template (" +
                             std::to_string(std::popcount(split)) + " edges split in " +
                             std::to_string(std::popcount(axes)) +
                             " directions) in the sheet of edge " + piece_name(piece));
      orientation_of[h] = o;
      axes_of[h] = table.orientations[o].axes;
      apps.push_back({h, table.orientations[o].tmpl, table.orientations[o].symmetry});
    }
    // Conformity by construction needs every hex around a split edge to split it in this round.
    for (const TemplateApplication& a : apps) {
      const uint16_t split = hex_split_mask(cur, region.node_marked, a.hex);
      for (int e = 0; e < 12; ++e) {
        if (!(split & (1u << e)) || !(axes_of[a.hex] & (1u << hex_edge_axis[e]))) continue;
        const int32_t id = rt.hex_edge_ids[a.hex][e];
        for (int32_t g : edge_hexes(rt, id)) {
          const int le = hex_local_edge(rt, g, id);
          if (!(axes_of[g] & (1u << hex_edge_axis[le])))
            throw OperationError("sheet refinement: hexes descending from input hexes " +
                                 std::to_string(region.origin[a.hex]) + " and " +
                                 std::to_string(region.origin[g]) +
                                 " do not split their shared edge in the same sheet pass");
        }
      }
    }

    TemplateApplyResult applied = templates_apply(cur, rt, apps);
    counts.created += applied.hexes_created;
    counts.deleted += applied.hexes_deleted;

    // The next state: occurrences inherited through the children's axes, edge nodes marked.
    const int32_t out_count = applied.mesh.hex_count();
    std::vector<std::array<int32_t, 3>> occurrence(out_count);
    std::vector<int32_t> origin(out_count);
    std::vector<uint8_t> marked = std::move(region.node_marked);
    marked.resize(applied.mesh.points.size(), 0);
    int32_t previous_parent = -1, child = 0;
    for (int32_t i = 0; i < out_count; ++i) {
      const int32_t parent = applied.parent[i];
      child = parent == previous_parent ? child + 1 : 0;
      previous_parent = parent;
      origin[i] = region.origin[parent];
      const int16_t o = orientation_of[parent];
      if (o < 0) {
        occurrence[i] = region.occurrence[parent];
        continue;
      }
      const Orientation& orient = table.orientations[o];
      for (int k = 0; k < 3; ++k) {
        // The parent's refined axes were set to -1 above: children are done in them.
        const int p = orient.child_axis[child][k];
        occurrence[i][k] = p < 0 ? -1 : region.occurrence[parent][p];
      }
      const uint8_t edge_nodes = orient.child_edge_nodes[child];
      for (int j = 0; j < 8; ++j)
        if (edge_nodes & (1u << j)) marked[applied.mesh.hexes[i][j]] = 1;
    }
    region.mesh = std::move(applied.mesh);
    region.mesh.attributes.clear();
    region.occurrence = std::move(occurrence);
    region.origin = std::move(origin);
    region.node_marked = std::move(marked);
    if (after_round) after_round(round);
  }

  return counts;
}

// ---------------------------------------------------------------------------------------------
// Composite templates: the rounds of one hex, replayed on the reference cube.
//
// What the rounds do to a hex depends only on its corner marks and on the order in which its
// axes' pieces are refined (two axes of one piece: the same round). Inside the hex, every node
// a round creates is marked or not by the same rule whoever creates it, so the cells' split
// patterns are a function of that configuration. The rounds of each configuration met are run
// once on a one-hex region (the unit cube) and the resulting cells become one template
// (TemplateTag::sheet), applied to every hex of that configuration by templates_apply with the
// nodes keyed on the input's edges and faces. Neighbours must subdivide their shared face alike;
// the round-by-round path checks this per split edge and round, here it is checked on the final
// face subdivisions (SheetComposite::face_hash), before anything is applied.

struct SheetComposite {
  HexTemplate tmpl;
  RoundCounts counts;
  bool positive = true;  // every child positive in the reference cube
  // Hash of the subdivision of local face lf, in the face frame with origin at position i0 of
  // hex_faces[lf] and u towards position i0 + step (index 2 * i0 + (step == 1 ? 0 : 1)).
  std::array<std::array<uint64_t, 8>, 6> face_hash{};
};

uint64_t hash_mix(uint64_t h, int64_t x) {
  h ^= static_cast<uint64_t>(x) + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
  return h;
}

// Hashes of the face subdivisions of a template with exact parameters (see SheetComposite).
void composite_face_hashes(SheetComposite& c) {
  constexpr int64_t unit = template_param_unit;
  std::vector<std::array<int64_t, 3>> param;
  for (const TemplateNode& n : c.tmpl.nodes)
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
        for (const auto& child : c.tmpl.children)
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
        c.face_hash[lf][2 * i0 + (step == 1 ? 0 : 1)] = h | 1;  // never 0: 0 marks "not seen"
      }
  }
}

// The composite of a hex with corner marks `marks` (bit v: vertex v) whose local axis k is
// refined in round rank[k] (-1: never).
std::unique_ptr<SheetComposite> composite_build(uint8_t marks, const std::array<int8_t, 3>& rank,
                                                int32_t input_hex) {
  Region region;
  for (int v = 0; v < 8; ++v) {
    region.mesh.points.emplace_back(hex_corner[v][0], hex_corner[v][1], hex_corner[v][2]);
    region.node_input.push_back(v);
    region.node_marked.push_back((marks >> v) & 1);
  }
  region.mesh.hexes.push_back({0, 1, 2, 3, 4, 5, 6, 7});
  region.input_nodes = 8;
  region.origin = {input_hex};
  region.occurrence = {{rank[0], rank[1], rank[2]}};
  std::vector<int32_t> color = {0, 1, 2};
  const int32_t rounds = 1 + std::max({rank[0], rank[1], rank[2]});
  auto c = std::make_unique<SheetComposite>();
  c->counts = region_run_rounds(region, color, rounds,
                                [&](int32_t piece) {
                                  std::string axes;
                                  for (int k = 0; k < 3; ++k)
                                    if (rank[k] == piece) axes += "xyz"[k];
                                  return "through local axes " + axes + " of input hex " +
                                         std::to_string(input_hex);
                                },
                                {});
  c->tmpl.tag = TemplateTag::sheet;
  for (const Eigen::Vector3d& x : region.mesh.points) c->tmpl.nodes.push_back({{x[0], x[1], x[2]}});
  for (const HexCell& h : region.mesh.hexes) {
    std::array<int16_t, 8> child{};
    for (int k = 0; k < 8; ++k) child[k] = static_cast<int16_t>(h[k]);
    c->tmpl.children.push_back(child);
  }
  for (int32_t h = 0; h < region.mesh.hex_count(); ++h)
    c->positive = c->positive && hex_corners_positive(region.mesh, h);
  template_compile(c->tmpl);
  composite_face_hashes(*c);
  return c;
}

// The face frame index (see SheetComposite::face_hash) of local face lf of hex h.
int face_frame_index(const HexCell& hex, int lf) {
  int i0 = 0;
  for (int c = 1; c < 4; ++c)
    if (hex[hex_faces[lf][c]] < hex[hex_faces[lf][i0]]) i0 = c;
  const bool step1 = hex[hex_faces[lf][(i0 + 1) % 4]] < hex[hex_faces[lf][(i0 + 3) % 4]];
  return 2 * i0 + (step1 ? 0 : 1);
}

PassOutput refine_composites(const HexMesh& mesh, const HexTopology& topology,
                             const RefineOptions& options, const std::vector<uint8_t>& node_marked,
                             const std::vector<int32_t>& region_hexes,
                             const std::vector<std::array<int32_t, 3>>& occurrence,
                             const std::vector<int32_t>& color, RefineStats& stats) {
  // Configuration: 8 mark bits, then per axis 2 bits of (rank + 1).
  std::vector<std::unique_ptr<SheetComposite>> composites(1u << 14);
  std::vector<const SheetComposite*> composite_of(region_hexes.size());
  std::vector<TemplateApplication> apps;
  apps.reserve(region_hexes.size());
  for (size_t i = 0; i < region_hexes.size(); ++i) {
    const int32_t h = region_hexes[i];
    uint8_t marks = 0;
    for (int v = 0; v < 8; ++v) marks |= static_cast<uint8_t>(node_marked[mesh.hexes[h][v]] << v);
    std::array<int32_t, 3> c{};
    for (int k = 0; k < 3; ++k) c[k] = occurrence[i][k] < 0 ? -1 : color[occurrence[i][k]];
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
    if (!composites[key]) composites[key] = composite_build(marks, rank, h);
    composite_of[i] = composites[key].get();
    apps.push_back({h, &composite_of[i]->tmpl, 0});
    stats.hexes_created += composite_of[i]->counts.created;
    stats.hexes_deleted += composite_of[i]->counts.deleted;
  }
  // Shared faces subdivided alike (an unrefined neighbour's face is whole).
  SheetComposite whole;
  for (int v = 0; v < 8; ++v)
    whole.tmpl.nodes.push_back(
        {{double(hex_corner[v][0]), double(hex_corner[v][1]), double(hex_corner[v][2])}});
  whole.tmpl.children.push_back({0, 1, 2, 3, 4, 5, 6, 7});
  composite_face_hashes(whole);
  const uint64_t whole_face = whole.face_hash[0][0];
  std::vector<uint8_t> in_region(mesh.hexes.size(), 0);
  for (int32_t h : region_hexes) in_region[h] = 1;
  std::vector<uint64_t> face_seen(topology.face_count(), 0);
  for (size_t i = 0; i < region_hexes.size(); ++i) {
    const int32_t h = region_hexes[i];
    for (int lf = 0; lf < 6; ++lf) {
      const int32_t f = topology.hex_face_ids[h][lf];
      if (face_is_boundary(topology, f)) continue;
      const uint64_t hash = composite_of[i]->face_hash[lf][face_frame_index(mesh.hexes[h], lf)];
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
  TemplateApplyResult applied = templates_apply(mesh, topology, apps, {}, options.threads);
  if (!options.allow_inverted) {
    std::vector<uint8_t> check(mesh.hexes.size(), 0);
    for (size_t i = 0; i < region_hexes.size(); ++i) {
      const int32_t h = region_hexes[i];
      if (!composite_of[i]->positive)
        throw OperationError("sheet refinement: the refinement of input hex " + std::to_string(h) +
                             " is inverted even on the reference cube");
      check[h] = !hex_is_parallelepiped(hex_points(mesh, h));
    }
    for (int32_t i = 0; i < applied.mesh.hex_count(); ++i)
      if (check[applied.parent[i]] && !hex_corners_positive(applied.mesh, i))
        throw OperationError("sheet refinement: a hex refined from input hex " +
                             std::to_string(applied.parent[i]) +
                             " is inverted (non-positive corner Jacobian)");
  }
  return {std::move(applied.mesh), std::move(applied.parent)};
}

// One refinement of `targets` of `mesh`; statistics are accumulated into `stats`.
PassOutput refine_once(const HexMesh& mesh, const Targets& targets, const RefineOptions& options,
                       const SheetControl& control, RefineStats& stats) {
  const auto t_start = Clock::now();
  const HexTopology topology = topology_build(mesh);
  SheetMarking marking;
  marking_seed(mesh, targets, marking);
  stats.phase_seconds["marking"] += seconds_since(t_start);

  const auto t_growth = Clock::now();
  marking_grow(mesh, topology, targets, marking);
  stats.added_targets += marking.added_targets;
  stats.phase_seconds["growth"] += seconds_since(t_growth);

  const auto t_sheets = Clock::now();
  const int32_t nh = mesh.hex_count();
  // Affected hexes: those with a split edge; all of them touch a marked node.
  std::vector<uint8_t> affected(nh, 0);
  std::vector<int32_t> region_hexes;
  {
    std::vector<uint8_t> seen(nh, 0);
    for (int32_t v = 0; v < mesh.point_count(); ++v) {
      if (!marking.node_marked[v]) continue;
      for (int32_t g : node_hexes(topology, v)) {
        if (seen[g]) continue;
        seen[g] = 1;
        if (hex_split_mask(mesh, marking.node_marked, g)) {
          affected[g] = 1;
          region_hexes.push_back(g);
        }
      }
    }
    std::sort(region_hexes.begin(), region_hexes.end());
  }

  // Pieces of dual sheets to refine: union of the split edges of each direction of each hex.
  UnionFind pieces(topology.edge_count());
  for (int32_t h : region_hexes) {
    const uint16_t mask = hex_split_mask(mesh, marking.node_marked, h);
    for (int k = 0; k < 3; ++k) {
      int32_t first = -1;
      for (int e : hex_axis_edges[k]) {
        if (!(mask & (1u << e))) continue;
        const int32_t id = topology.hex_edge_ids[h][e];
        if (first < 0)
          first = id;
        else
          pieces.unite(first, id);
      }
    }
  }
  std::vector<int32_t> piece_of_root(topology.edge_count(), -1);
  std::vector<int32_t> piece_edge;  // a representative edge per piece (for messages)
  Region region;
  region.occurrence.resize(region_hexes.size());
  for (size_t i = 0; i < region_hexes.size(); ++i) {
    const int32_t h = region_hexes[i];
    const uint16_t mask = hex_split_mask(mesh, marking.node_marked, h);
    for (int k = 0; k < 3; ++k) {
      region.occurrence[i][k] = -1;
      const uint16_t split = mask & axis_mask(k);
      if (!split) continue;
      const int32_t root = pieces.find(topology.hex_edge_ids[h][std::countr_zero(split)]);
      if (piece_of_root[root] < 0) {
        piece_of_root[root] = static_cast<int32_t>(piece_edge.size());
        piece_edge.push_back(root);
      }
      region.occurrence[i][k] = piece_of_root[root];
    }
  }
  const int32_t piece_count = static_cast<int32_t>(piece_edge.size());
  auto edge_name = [&](int32_t e) {
    return "(" + std::to_string(topology.edge_nodes[e][0]) + "-" +
           std::to_string(topology.edge_nodes[e][1]) + ")";
  };

  // Self-intersections: the dual sheet of one direction of an affected hex is also the sheet of
  // another of its directions (Harris' special case). Counted on the whole dual sheets; refused
  // only where one piece must refine the hex in two directions.
  {
    UnionFind sheets(topology.edge_count());
    for (int32_t h = 0; h < nh; ++h)
      for (int k = 0; k < 3; ++k)
        for (int i = 1; i < 4; ++i)
          sheets.unite(topology.hex_edge_ids[h][hex_axis_edges[k][0]],
                       topology.hex_edge_ids[h][hex_axis_edges[k][i]]);
    std::vector<int32_t> refused;
    int32_t refused_piece = -1;
    for (size_t i = 0; i < region_hexes.size(); ++i) {
      const int32_t h = region_hexes[i];
      std::array<int32_t, 3> s{};
      for (int k = 0; k < 3; ++k)
        s[k] = sheets.find(topology.hex_edge_ids[h][hex_axis_edges[k][0]]);
      if (s[0] == s[1] || s[1] == s[2] || s[0] == s[2]) ++stats.self_intersection_cases;
      const auto& o = region.occurrence[i];
      // All edges split: the piece's directions are refined together by 1-9 (or 1-27).
      if (hex_split_mask(mesh, marking.node_marked, h) == 0xFFF) continue;
      for (int a = 0; a < 3; ++a)
        for (int b = a + 1; b < 3; ++b)
          if (o[a] >= 0 && o[a] == o[b]) {
            if (refused_piece < 0) refused_piece = o[a];
            if (o[a] == refused_piece && (refused.empty() || refused.back() != h))
              refused.push_back(h);
          }
    }
    if (!refused.empty())
      throw OperationError(
          "sheet refinement: the dual sheet of edge " + edge_name(piece_edge[refused_piece]) +
          " crosses itself in hexes " + hex_list(refused) +
          ", which it must refine in two directions within one sheet pass with transition "
          "templates; that case of a self-intersecting sheet is not handled by the sheet refiner "
          "(only fully refined hexes are: 1-9)");
  }

  // Rounds: first-fit colouring of the pieces; two pieces conflict when they share a hex.
  std::vector<int32_t> color(piece_count, -1);
  int32_t round_count = 0;
  {
    std::vector<int32_t> offsets(piece_count + 1, 0);
    for (const auto& o : region.occurrence)
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
          if (a != b && o[a] >= 0 && o[b] >= 0) ++offsets[o[a] + 1];
    for (int32_t p = 0; p < piece_count; ++p) offsets[p + 1] += offsets[p];
    std::vector<int32_t> adjacent(offsets[piece_count]);
    std::vector<int32_t> cursor(offsets.begin(), offsets.end() - 1);
    for (const auto& o : region.occurrence)
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
          if (a != b && o[a] >= 0 && o[b] >= 0) adjacent[cursor[o[a]]++] = o[b];
    std::vector<int32_t> stamp;  // stamp[c] == p: colour c is used by a neighbour of p
    for (int32_t p = 0; p < piece_count; ++p) {
      for (int32_t i = offsets[p]; i < offsets[p + 1]; ++i) {
        const int32_t c = color[adjacent[i]];
        if (c < 0) continue;
        if (c >= static_cast<int32_t>(stamp.size())) stamp.resize(c + 1, -1);
        stamp[c] = p;
      }
      int32_t c = 0;
      while (c < static_cast<int32_t>(stamp.size()) && stamp[c] == p) ++c;
      color[p] = c;
      round_count = std::max(round_count, c + 1);
    }
  }

  if (control.one_sheet_per_round) {
    std::iota(color.begin(), color.end(), 0);
    round_count = piece_count;
  }

  auto piece_name = [&](int32_t p) { return edge_name(piece_edge[p]); };
  // Without an observer of the intermediate meshes or Harris' one-sheet-per-pass schedule,
  // every hex's rounds are replayed once per configuration on a reference cube and applied as
  // one composite template (same mesh, no intermediate meshes or topologies).
  if (control.composites && !control.observer && !control.one_sheet_per_round) {
    PassOutput out = refine_composites(mesh, topology, options, marking.node_marked, region_hexes,
                                       region.occurrence, color, stats);
    stats.sheet_passes += piece_count;
    stats.phase_seconds["sheets"] += seconds_since(t_sheets);
    return out;
  }
  // The region with compact node ids.
  {
    std::vector<int32_t> local_of(mesh.points.size(), -1);
    region.mesh.hexes.reserve(region_hexes.size());
    for (int32_t h : region_hexes) {
      HexCell c = mesh.hexes[h];
      for (int32_t& v : c) {
        if (local_of[v] < 0) {
          local_of[v] = static_cast<int32_t>(region.node_input.size());
          region.node_input.push_back(v);
        }
        v = local_of[v];
      }
      region.mesh.hexes.push_back(c);
    }
    region.input_nodes = static_cast<int32_t>(region.node_input.size());
    region.mesh.points.reserve(region.node_input.size());
    region.node_marked.reserve(region.node_input.size());
    for (int32_t v : region.node_input) {
      region.mesh.points.push_back(mesh.points[v]);
      region.node_marked.push_back(marking.node_marked[v]);
    }
    region.origin = region_hexes;
  }

  stats.sheet_passes += piece_count;
  const RoundCounts counts =
      region_run_rounds(region, color, round_count, piece_name, [&](int32_t round) {
        if (control.observer) control.observer(region_assemble(mesh, affected, region).mesh, round);
      });
  stats.hexes_created += counts.created;
  stats.hexes_deleted += counts.deleted;

  if (!options.allow_inverted)
    for (int32_t h = 0; h < region.mesh.hex_count(); ++h)
      if (!hex_corners_positive(region.mesh, h))
        throw OperationError("sheet refinement: a hex refined from input hex " +
                             std::to_string(region.origin[h]) +
                             " is inverted (non-positive corner Jacobian)");
  stats.phase_seconds["sheets"] += seconds_since(t_sheets);
  return region_assemble(mesh, affected, region);
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
  marking_seed(mesh, targets, m);
  marking_grow(mesh, topology, targets, m);
  return m;
}

RefineResult sheet_refine(const HexMesh& mesh, const Targets& targets,
                          const RefineOptions& options) {
  return sheet_refine(mesh, targets, options, SheetRoundObserver());
}

RefineResult sheet_refine(const HexMesh& mesh, const Targets& targets, const RefineOptions& options,
                          const SheetRoundObserver& observer) {
  SheetControl control;
  control.observer = observer;
  return sheet_refine(mesh, targets, options, control);
}

RefineResult sheet_refine(const HexMesh& mesh, const Targets& targets, const RefineOptions& options,
                          const SheetControl& control) {
  targets_validate(mesh, targets);
  if (options.passes < 1)
    throw InputError("sheet refinement: passes must be at least 1 (got " +
                     std::to_string(options.passes) + ")");
  const auto t0 = Clock::now();
  RefineResult result;
  RefineStats& stats = result.stats;
  stats.method = "sheet";
  stats.initial_hexes = mesh.hex_count();
  for (const char* phase : {"marking", "growth", "sheets"}) stats.phase_seconds[phase] = 0;

  PassOutput current{mesh, {}};
  Targets pass_targets = targets;
  for (int pass = 0; pass < options.passes; ++pass) {
    PassOutput next = refine_once(current.mesh, pass_targets, options, control, stats);
    if (pass + 1 < options.passes) {
      // The next pass refines the descendants of this pass's (given) targets.
      std::vector<uint8_t> was_target(current.mesh.hexes.size(), 0);
      for (int32_t t : pass_targets.hexes) was_target[t] = 1;
      pass_targets.hexes.clear();
      for (int32_t i = 0; i < next.mesh.hex_count(); ++i)
        if (was_target[next.origin[i]]) pass_targets.hexes.push_back(i);
    }
    current = std::move(next);
  }
  result.mesh = std::move(current.mesh);
  // Make sure both attributes exist even when nothing was refined.
  mesh_attribute(result.mesh, attribute_template_tag, 0);
  mesh_attribute(result.mesh, attribute_refinement_level, 0);

  stats.final_hexes = result.mesh.hex_count();
  stats.final_nodes = result.mesh.point_count();
  stats_count_templates(stats, *mesh_find_attribute(result.mesh, attribute_template_tag));
  stats.time_seconds = seconds_since(t0);
  stats.phase_seconds["total"] = stats.time_seconds;
  return result;
}

}  // namespace hexrefine
