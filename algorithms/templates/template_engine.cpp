#include "algorithms/templates/template_engine.hpp"

#include <algorithm>
#include <exception>
#include <string>
#include <thread>

#include "mesh/error.hpp"
#include "mesh/hex_convention.hpp"

namespace hexrefine {

namespace {

constexpr int64_t kUnit = template_param_unit;

// The canonical frame of local face lf of a hex with node ids `input`: origin at its lowest node
// id, u towards the lower-id neighbour; computed once per face and hex (frame[lf][0] < 0: not
// yet). Returns {origin, u corner, v corner} as local vertices.
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

Eigen::Vector3d weighted(const std::array<double, 8>& w, const std::array<Eigen::Vector3d, 8>& x) {
  Eigen::Vector3d out = Eigen::Vector3d::Zero();
  for (int v = 0; v < 8; ++v) out += w[v] * x[v];
  return out;
}

std::array<double, 8> param_weights(const TemplateParam& p) {
  return hex_trilinear_weights({double(p[0]) / kUnit, double(p[1]) / kUnit, double(p[2]) / kUnit});
}

}  // namespace

NodeKey node_key_at(const HexMesh& mesh, const HexTopology& topology, HexId hex_id,
                    const TemplateParam& p) {
  const int32_t hex = index_of(hex_id);
  const HexCell& cell = mesh.hexes[hex];
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
    return NodeKey::corner(
        NodeId{cell[hex_vertex_at(int(p[0] / kUnit), int(p[1] / kUnit), int(p[2] / kUnit))]});
  if (extreme == 2) {
    std::array<int, 3> lo{}, hi{};
    for (int k = 0; k < 3; ++k) {
      lo[k] = k == free_axis ? 0 : int(p[k] / kUnit);
      hi[k] = k == free_axis ? 1 : lo[k];
    }
    const int le =
        hex_edge_joining(hex_vertex_at(lo[0], lo[1], lo[2]), hex_vertex_at(hi[0], hi[1], hi[2]));
    const int32_t e = topology.hex_edge_ids[hex][le];
    return NodeKey::edge(EdgeId{e},
                         edge_position(cell, topology.edge_nodes[e], le, p[free_axis], kUnit));
  }
  if (extreme == 1) {
    const int lf = 2 * fixed_axis + (p[fixed_axis] == kUnit ? 1 : 0);
    std::array<std::array<int8_t, 3>, 6> frame;
    frame[lf][0] = -1;
    const auto uv = face_position(face_frame(cell, lf, frame), p, kUnit);
    return NodeKey::face(FaceId{topology.hex_face_ids[hex][lf]}, uv[0], uv[1]);
  }
  return NodeKey::interior(hex_id, p);
}

TemplateEngine::TemplateEngine(const HexMesh& mesh, const HexTopology& topology,
                               TemplatePositions positions)
    : mesh_(mesh),
      topology_(topology),
      positions_(positions),
      points_(mesh.points),
      edge_slot_(3 * static_cast<size_t>(topology.edge_count()), -1),
      face_base_(topology.face_count(), -1) {
  // Address space only: pages are touched as faces are first used.
  face_slot_.reserve(9 * static_cast<size_t>(topology.face_count()));
}

void TemplateEngine::alias(const NodeKey& from, const NodeKey& to) {
  aliases_[from] = to;
  if (face_aliased_.empty()) face_aliased_.assign(topology_.face_count(), 0);
  if (from.kind() == NodeKey::Kind::face) face_aliased_[from.id()] = 1;
}

int32_t* TemplateEngine::slot_of(const NodeKey& key) {
  // Slots cover the positions templates use on whole hexes: thirds and halves (sixths 2, 3, 4)
  // along an edge and in both directions of a face. Others go to the hash table.
  constexpr int64_t sixth = kUnit / 6;
  auto index = [](int64_t x) -> int {
    if (x % sixth != 0) return -1;
    const int64_t i = x / sixth - 2;
    return i >= 0 && i < 3 ? static_cast<int>(i) : -1;
  };
  switch (key.kind()) {
    case NodeKey::Kind::edge: {
      const int i = index(key.a);
      return i < 0 ? nullptr : &edge_slot_[3 * static_cast<size_t>(key.id()) + i];
    }
    case NodeKey::Kind::face: {
      const int i = index(key.a), j = index(key.b);
      if (i < 0 || j < 0) return nullptr;
      int32_t& base = face_base_[key.id()];
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

int32_t TemplateEngine::create_node(const Eigen::Vector3d& x) {
  points_.push_back(x);
  return static_cast<int32_t>(points_.size() - 1);
}

Eigen::Vector3d TemplateEngine::interior_position(const NodeKey& key) const {
  if (!interior_reference_.empty()) {
    const auto it = interior_reference_.find(key);
    if (it != interior_reference_.end()) return it->second;
  }
  return weighted(param_weights(key.interior_param()), hex_points(mesh_, key.id()));
}

template <class Position>
int32_t TemplateEngine::node_at(const NodeKey& key, const Position& position, bool* aliased) {
  const NodeKey* target = nullptr;
  if (!aliases_.empty() && (key.kind() != NodeKey::Kind::face || face_aliased_[key.id()])) {
    const auto it = aliases_.find(key);
    if (it != aliases_.end()) target = &it->second;
  }
  if (!target) return node_unaliased(key, position);
  *aliased = true;
  // An interior target is placed by its own hex's map, whoever names it first.
  return node_unaliased(*target, [&] {
    return target->kind() == NodeKey::Kind::interior ? interior_position(*target) : position();
  });
}

template <class Position>
int32_t TemplateEngine::node_unaliased(const NodeKey& key, const Position& position) {
  if (key.kind() == NodeKey::Kind::corner) return key.id();
  if (int32_t* s = slot_of(key)) {
    if (*s < 0) *s = create_node(position());
    return *s;
  }
  const auto [it, inserted] = nodes_.emplace(key, static_cast<int32_t>(points_.size()));
  if (inserted) create_node(position());
  return it->second;
}

int32_t& TemplateEngine::plan_node_slot(int32_t h, const TemplatePlanNode& n,
                                        std::array<std::array<int8_t, 3>, 6>& frame) {
  const HexCell& input = mesh_.hexes[h];
  if (n.entity == CubeEntity::edge) {
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

NodeKey TemplateEngine::plan_node_key(int32_t h, const TemplatePlanNode& n,
                                      std::array<std::array<int8_t, 3>, 6>& frame) const {
  const HexCell& input = mesh_.hexes[h];
  if (n.entity == CubeEntity::edge) {
    const int32_t e = topology_.hex_edge_ids[h][n.local];
    return NodeKey::edge(EdgeId{e}, edge_position(input, topology_.edge_nodes[e], n.local,
                                                  n.param[hex_edge_axis[n.local]], kUnit));
  }
  const auto uv = face_position(face_frame(input, n.local, frame), n.param, kUnit);
  return NodeKey::face(FaceId{topology_.hex_face_ids[h][n.local]}, uv[0], uv[1]);
}

void TemplateEngine::apply(HexId hex, const HexTemplate& t, int symmetry, bool interior_private,
                           std::vector<HexCell>& children) {
  const int32_t h = index_of(hex);
  const HexCell& input = mesh_.hexes[h];
  const TemplatePlan& plan = t.plans.at(symmetry);
  std::array<Eigen::Vector3d, 8> x;
  for (int v = 0; v < 8; ++v) x[v] = mesh_.points[input[v]];
  std::array<std::array<int8_t, 3>, 6> frame;
  for (auto& f : frame) f[0] = -1;
  bool aliased = false;
  const bool direct = plan.slotted && aliases_.empty();
  placed_.resize(plan.nodes.size());
  for (size_t i = 0; i < plan.nodes.size(); ++i) {
    const TemplatePlanNode& n = plan.nodes[i];
    auto position = [&] { return weighted(weights(n), x); };
    int32_t id = -1;
    switch (n.entity) {
      case CubeEntity::corner:
        id = input[n.local];
        break;
      case CubeEntity::edge:
      case CubeEntity::face:
        if (direct) {
          // Nobody needs the key: straight to the slot.
          int32_t& s = plan_node_slot(h, n, frame);
          if (s < 0) s = create_node(position());
          id = s;
        } else {
          id = node_at(plan_node_key(h, n, frame), position, &aliased);
        }
        break;
      case CubeEntity::interior:
        id = interior_private || n.off_grid
                 ? create_node(position())
                 : node_at(NodeKey::interior(hex, n.param), position, &aliased);
        break;
    }
    placed_[i] = id;
  }
  for (const auto& c : plan.children) {
    HexCell out;
    for (int k = 0; k < 8; ++k) out[k] = placed_[c[k]];
    if (aliased)
      for (int a = 0; a < 8; ++a)
        for (int b = a + 1; b < 8; ++b)
          if (out[a] == out[b])
            throw OperationError("hex " + std::to_string(h) + " (" + template_tag_name(t.tag) +
                                 "): two corners of a child fall on one node (an adjustment "
                                 "collapses them)");
    children.push_back(out);
  }
}

void TemplateEngine::apply_batch(std::span<const TemplateUse> uses,
                                 std::span<const size_t> child_offset,
                                 std::vector<HexCell>& children, int threads) {
  bool parallel = threads > 1 && aliases_.empty() && uses.size() > 1;
  for (const TemplateUse& u : uses) {
    if (!parallel) break;
    parallel = u.tmpl->plans.at(u.symmetry).slotted;
  }
  if (!parallel) {
    std::vector<HexCell> out;
    for (size_t i = 0; i < uses.size(); ++i) {
      out.clear();
      apply(uses[i].hex, *uses[i].tmpl, uses[i].symmetry, true, out);
      std::copy(out.begin(), out.end(),
                children.begin() + static_cast<std::ptrdiff_t>(child_offset[i]));
    }
    return;
  }
  // 1. Claim node ids in order, exactly as the serial calls would create them.
  std::vector<int32_t> first_new(uses.size() + 1);
  int32_t next = static_cast<int32_t>(points_.size());
  std::array<std::array<int8_t, 3>, 6> frame;
  for (size_t i = 0; i < uses.size(); ++i) {
    first_new[i] = next;
    const TemplatePlan& plan = uses[i].tmpl->plans[uses[i].symmetry];
    for (auto& f : frame) f[0] = -1;
    for (const TemplatePlanNode& n : plan.nodes) {
      if (n.entity == CubeEntity::corner) continue;
      if (n.entity == CubeEntity::interior) {
        ++next;
        continue;
      }
      int32_t& s = plan_node_slot(index_of(uses[i].hex), n, frame);
      if (s < 0) s = next++;
    }
  }
  first_new[uses.size()] = next;
  points_.resize(static_cast<size_t>(next));  // Eigen leaves them uninitialised: no page touched
  // 2. Positions and children, in contiguous runs of uses.
  auto run = [&](size_t begin, size_t end) {
    std::array<std::array<int8_t, 3>, 6> fr;
    std::vector<int32_t> ids;
    for (size_t i = begin; i < end; ++i) {
      const int32_t h = index_of(uses[i].hex);
      const HexCell& input = mesh_.hexes[h];
      const TemplatePlan& plan = uses[i].tmpl->plans[uses[i].symmetry];
      std::array<Eigen::Vector3d, 8> x;
      for (int v = 0; v < 8; ++v) x[v] = mesh_.points[input[v]];
      for (auto& f : fr) f[0] = -1;
      ids.resize(plan.nodes.size());
      int32_t own = first_new[i];
      for (size_t j = 0; j < plan.nodes.size(); ++j) {
        const TemplatePlanNode& n = plan.nodes[j];
        if (n.entity == CubeEntity::corner) {
          ids[j] = input[n.local];
          continue;
        }
        int32_t id;
        if (n.entity == CubeEntity::interior) {
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
        points_[id] = weighted(weights(n), x);
      }
      HexCell* out = children.data() + child_offset[i];
      for (const auto& c : plan.children) {
        for (int k = 0; k < 8; ++k) (*out)[k] = ids[c[k]];
        ++out;
      }
    }
  };
  const size_t parts = std::min<size_t>(static_cast<size_t>(threads), uses.size());
  // An exception in a worker (only std::bad_alloc can arise) is rethrown here, after the join.
  std::vector<std::exception_ptr> failure(parts);
  auto guarded = [&](size_t p) {
    try {
      run(uses.size() * p / parts, uses.size() * (p + 1) / parts);
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

PlanApplyResult plan_apply(const HexMesh& mesh, const HexTopology& topology,
                           const RefinementPlan& plan, int threads, TemplatePositions positions) {
  const int32_t nh = mesh.hex_count();
  std::vector<int32_t> use_of(nh, -1);
  int32_t previous = -1;
  for (size_t i = 0; i < plan.uses.size(); ++i) {
    const int32_t h = index_of(plan.uses[i].hex);
    if (h <= previous || h >= nh)
      throw OperationError("plan_apply: hex " + std::to_string(h) +
                           " is out of range or not in ascending order");
    previous = h;
    use_of[h] = static_cast<int32_t>(i);
  }
  TemplateEngine engine(mesh, topology, positions);
  // Hexes whose interior nodes someone else names (alias sources or targets) key them.
  std::vector<uint8_t> interior_keyed;
  for (const NodeAlias& al : plan.aliases) {
    engine.alias(al.from, al.to);
    for (const NodeKey* k : {&al.from, &al.to})
      if (k->kind() == NodeKey::Kind::interior) {
        if (interior_keyed.empty()) interior_keyed.assign(nh, 0);
        interior_keyed[k->id()] = 1;
      }
  }
  if (positions == TemplatePositions::reference && !interior_keyed.empty()) {
    // An alias target is placed by its own hex's template, whoever names it first: its
    // reference position may differ from its exact one.
    for (const TemplateUse& u : plan.uses) {
      const int32_t h = index_of(u.hex);
      if (!interior_keyed[h]) continue;
      const std::array<Eigen::Vector3d, 8> x = hex_points(mesh, h);
      for (const TemplatePlanNode& n : u.tmpl->plans.at(u.symmetry).nodes)
        if (n.entity == CubeEntity::interior && !n.off_grid)
          engine.set_interior_position(NodeKey::interior(u.hex, n.param),
                                       weighted(n.reference_weight, x));
    }
  }

  PlanApplyResult out;
  HexMesh& res = out.mesh;
  size_t out_hexes = mesh.hexes.size(), new_nodes = 0;
  for (const TemplateUse& u : plan.uses) {
    out_hexes += u.tmpl->children.size() - 1;
    new_nodes += u.tmpl->nodes.size();
  }
  engine.reserve_created(new_nodes);
  // One thread: children appended as they are made. More: slots laid out first, the batch
  // fills the template hexes' slots in parallel.
  const bool parallel = threads > 1 && plan.aliases.empty();
  if (parallel)
    res.hexes.resize(out_hexes);
  else
    res.hexes.reserve(out_hexes);
  std::vector<int32_t> parent;
  parent.reserve(out_hexes);
  out.first_child.reserve(plan.uses.size());
  std::vector<size_t> offsets;
  size_t at = 0;
  for (int32_t h = 0; h < nh; ++h) {
    const int32_t u = use_of[h];
    if (u < 0) {
      if (parallel)
        res.hexes[at] = mesh.hexes[h];
      else
        res.hexes.push_back(mesh.hexes[h]);
      ++at;
    } else {
      const TemplateUse& use = plan.uses[u];
      out.first_child.push_back(static_cast<int32_t>(at));
      if (parallel) {
        offsets.push_back(at);
      } else {
        try {
          engine.apply(use.hex, *use.tmpl, use.symmetry,
                       interior_keyed.empty() || !interior_keyed[h], res.hexes);
        } catch (const OperationError& e) {
          throw OperationError(std::string("plan_apply: ") + e.what());
        }
      }
      at += use.tmpl->children.size();
      out.hexes_created += static_cast<int64_t>(use.tmpl->children.size());
      out.hexes_deleted += 1;
    }
    parent.resize(at, h);
  }
  if (parallel) engine.apply_batch(plan.uses, offsets, res.hexes, threads);
  res.points = std::move(engine.points());

  std::vector<int32_t> tag_of(nh, -1);
  for (const TemplateUse& u : plan.uses)
    tag_of[index_of(u.hex)] = static_cast<int32_t>(u.tmpl->tag);
  mesh_attributes_from_parents(mesh, parent, tag_of, res);
  return out;
}

void mesh_attributes_from_parents(const HexMesh& input, std::span<const int32_t> parent,
                                  std::span<const int32_t> tag_of, HexMesh& output) {
  const size_t n = parent.size();
  output.attributes.clear();
  for (const HexAttribute& attr : input.attributes) {
    HexAttribute copy{attr.name, std::vector<int32_t>(n)};
    for (size_t i = 0; i < n; ++i) copy.values[i] = attr.values[parent[i]];
    output.attributes.push_back(std::move(copy));
  }
  // Room for the three attributes added here, so creating `level` does not move `tag`.
  output.attributes.reserve(output.attributes.size() + 3);
  std::vector<int32_t>& tag = mesh_attribute(output, attribute_template_tag, 0);
  std::vector<int32_t>& level = mesh_attribute(output, attribute_refinement_level, 0);
  for (size_t i = 0; i < n; ++i) {
    const int32_t t = tag_of[parent[i]];
    if (t < 0) continue;
    tag[i] = t;
    ++level[i];
  }
  if (!mesh_find_attribute(input, attribute_parent_hex))
    output.attributes.push_back(
        {std::string(attribute_parent_hex), std::vector<int32_t>(parent.begin(), parent.end())});
}

}  // namespace hexrefine
