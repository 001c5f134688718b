/// \file
/// Guarded node smoothing of all-hex meshes, local to a region, boundary nodes kept on the
/// boundary surface.
///
/// The per-node optimization is node_optimizer.cpp (smart Laplacian after Freitag 1997, a Newton
/// step on Knupp's inverse mean ratio, the max-min ascent of the scaled Jacobian after Freitag
/// and Plassmann 2000), every move guarded so that the minimum never drops and no valid hex
/// inverts. This file decides which nodes move and how (mesh_smooth, after smooth_options_check;
/// the steps share a SmoothingPart):
///  1. smoothing_region_gather: the region, the given hexes (refine --smooth: the refined and
///     transition hexes) and `layers` layers of hexes sharing a node with it. Movable: the
///     region's nodes. Everything below is built on the region and one more layer (the hexes
///     around its nodes), never on the whole mesh, so the cost is linear in the region.
///  2. region_nodes_movable, then movable_nodes_slide_on_input or
///     movable_nodes_slide_on_own_boundary: boundary nodes, from the boundary faces of that part
///     (a face holding a region node has both its hexes in it, so its boundary status is the
///     whole mesh's):
///     - with a reference (the input of a refinement): a node the refinement made slides on the
///       input face or edge it subdivides (ReferenceSlides, as in node placement); a node of the
///       input slides on the union of the input's boundary patches around it, or along the two
///       feature sides at it (patch sides whose patches meet at more than the feature angle, or
///       any angle when every input face is planar: there the facets are the geometry), and
///       stays at a corner (ReferenceSlides::at_input_node). Every boundary node stays on the
///       input's boundary surface; a boundary face may then straddle two input faces, which the
///       checker accepts when its corners lie on the input surface and it does not cut a chord
///       across a bend (conformity.hpp). With `reference_surface` every move keeps the faces at
///       the moved node passing that same test (the surface guard, sliding_nodes_guard_faces:
///       node visits and joint-ascent steps that would fail it are not kept), so the check
///       agrees by construction; without it, a node slid over a bend of the input could leave a
///       face the checker rejects, and the smoothing there was undone node by node
///       (docs/placement-and-smoothing.md, 'Smoothing and the check agree'). The transition
///       children of a boundary parent are where refinement loses most quality, and the input's
///       own boundary nodes are half of their corners;
///     - without one: a boundary node slides on the boundary quads around it (their bilinear
///       patches at the start: projection onto the nearest), a node on exactly two feature edges
///       slides along them, other feature nodes (corners, ends of feature curves) stay.
///  3. smoothing_sweep_options: sweeps, worst node first, nodes whose worst hex is already at or
///     above visit_below left alone (a region of good hexes costs one pass), until no move,
///     max_sweeps, or a sweep that improves neither the minimum nor the mean.
///  4. smoothing_joint_ascent_options (optimize): where the sweeps stop, the worst hexes are
///     usually held by several nodes at once (a transition child whose corners all sit at the
///     minimum, a flat boundary layer that must thicken as a whole): a joint ascent moves the
///     nodes around them together, boundary nodes on their slides, steered along the edge-ratio
///     caps (node_joint_ascent.hpp), and if it raised the minimum the sweeps run again from
///     there; up to joint_rounds rounds, each with a sharper soft minimum. It is what lifts the
///     1-13 children of flat boundary parents, which the sweeps alone leave well below 0.5
///     (docs/placement-and-smoothing.md, 'Smoothing').
///  Steps 3 and 4 run as one call, nodes_sweep_and_ascend (node_joint_ascent.hpp).

#include "algorithms/placement/smoothing.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <numeric>
#include <string>
#include <unordered_map>

#include "algorithms/placement/node_joint_ascent.hpp"
#include "algorithms/placement/node_optimizer.hpp"
#include "mesh/conformity.hpp"
#include "mesh/error.hpp"
#include "mesh/hex_convention.hpp"
#include "mesh/hex_face_adjacency.hpp"
#include "mesh/quality.hpp"
#include "mesh/reference_surface.hpp"

namespace hexrefine {

namespace {

using Vec3 = Eigen::Vector3d;

void min_mean(const HexMesh& mesh, double& min, double& mean) {
  min = 1.0;
  mean = 1.0;
  if (mesh.hexes.empty()) return;
  double sum = 0;
  const std::vector<double> q = mesh_scaled_jacobians(mesh);  // two hexes per evaluation
  for (double v : q) {
    min = std::min(min, v);
    sum += v;
  }
  mean = sum / static_cast<double>(mesh.hexes.size());
}

/// node -> hexes of `hexes`, CSR over all mesh nodes.
void node_hexes_of(const HexMesh& mesh, const std::vector<int32_t>& hexes,
                   std::vector<int32_t>& offsets, std::vector<int32_t>& items) {
  offsets.assign(mesh.points.size() + 1, 0);
  for (int32_t h : hexes)
    for (int32_t v : mesh.hexes[h]) ++offsets[v + 1];
  for (size_t n = 0; n + 1 < offsets.size(); ++n) offsets[n + 1] += offsets[n];
  items.resize(offsets.back());
  std::vector<int32_t> cursor(offsets.begin(), offsets.end() - 1);
  for (int32_t h : hexes)
    for (int32_t v : mesh.hexes[h]) items[cursor[v]++] = h;
}

/// The hexes sharing a node with `hexes` (ascending, `hexes` included).
std::vector<int32_t> hexes_around(const HexMesh& mesh, const std::vector<int32_t>& hexes,
                                  const std::vector<int32_t>& offsets,
                                  const std::vector<int32_t>& items) {
  std::vector<uint8_t> in(mesh.hexes.size(), 0);
  std::vector<int32_t> out;
  auto add = [&](int32_t h) {
    if (!in[h]) {
      in[h] = 1;
      out.push_back(h);
    }
  };
  for (int32_t h : hexes) {
    add(h);
    for (int32_t v : mesh.hexes[h])
      for (int32_t k = offsets[v]; k < offsets[v + 1]; ++k) add(items[k]);
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

const char* smooth_method_name(SmoothMethod m) {
  return m == SmoothMethod::laplacian ? "laplacian" : "optimize";
}

SmoothNodeClasses mesh_classify_smooth_nodes(const HexMesh& mesh, const HexTopology& topology,
                                             double feature_angle_degrees) {
  const int32_t nn = topology.node_count;
  SmoothNodeClasses c;
  c.kind.assign(nn, SmoothNodeKind::interior);
  const double feature_cos = std::cos(feature_angle_degrees * std::numbers::pi / 180.0);
  std::vector<uint8_t> corner(nn, 0);
  std::vector<int8_t> feature_edges(nn, 0);
  // Boundary edges: their boundary faces' normals, gathered per (lower, higher) node pair.
  struct EdgeFaces {
    uint64_t key;
    Vec3 normal;
  };
  std::vector<EdgeFaces> edge_faces;
  for (int32_t f : topology_boundary_faces(topology)) {
    const auto& q = topology.face_nodes[f];
    const Vec3 normal = quad_unit_normal(
        {mesh.points[q[0]], mesh.points[q[1]], mesh.points[q[2]], mesh.points[q[3]]});
    const bool degenerate = normal.isZero();
    for (int k = 0; k < 4; ++k) {
      const int32_t n = q[k];
      if (c.kind[n] == SmoothNodeKind::interior) c.kind[n] = SmoothNodeKind::surface;
      if (degenerate) corner[n] = 1;
      const uint32_t a = static_cast<uint32_t>(q[k]), b = static_cast<uint32_t>(q[(k + 1) % 4]);
      edge_faces.push_back({static_cast<uint64_t>(std::min(a, b)) << 32 | std::max(a, b), normal});
    }
  }
  std::sort(edge_faces.begin(), edge_faces.end(),
            [](const EdgeFaces& x, const EdgeFaces& y) { return x.key < y.key; });
  for (size_t i = 0; i < edge_faces.size();) {
    size_t j = i;
    while (j < edge_faces.size() && edge_faces[j].key == edge_faces[i].key) ++j;
    bool feature = j - i != 2;  // an edge on other than two boundary faces
    if (!feature)
      feature = edge_faces[i].normal.isZero() || edge_faces[i + 1].normal.isZero() ||
                edge_faces[i].normal.dot(edge_faces[i + 1].normal) < feature_cos;
    if (feature) {
      ++feature_edges[static_cast<int32_t>(edge_faces[i].key >> 32)];
      ++feature_edges[static_cast<int32_t>(edge_faces[i].key & 0xFFFFFFFF)];
    }
    i = j;
  }
  for (int32_t f : topology.nonmanifold_faces)
    for (int32_t n : topology.face_nodes[f]) corner[n] = 1;
  for (int32_t n = 0; n < nn; ++n) {
    if (c.kind[n] == SmoothNodeKind::interior) continue;
    if (corner[n] || (feature_edges[n] != 0 && feature_edges[n] != 2))
      c.kind[n] = SmoothNodeKind::corner;
    else if (feature_edges[n] == 2)
      c.kind[n] = SmoothNodeKind::curve;
  }
  return c;
}

namespace {

/// What the steps of mesh_smooth share: the region, the part built around it, the part as a
/// mesh of its own and which of its nodes may move.
struct SmoothingPart {
  /// The region's hexes, ascending (step 1).
  std::vector<int32_t> region;
  /// The region and the hexes around its nodes, ascending: everything below is built on it.
  std::vector<int32_t> hexes;
  /// `hexes` as a mesh of its own (step 2).
  SubMesh sub;
  /// Per node of `sub`: 1 if it is a region node and not fixed (step 2).
  std::vector<uint8_t> in_region;
};

/// The options and the mesh as mesh_smooth needs them; InputError otherwise.
void smooth_options_check(const HexMesh& mesh, const SmoothOptions& options) {
  if (options.max_sweeps < 0)
    throw InputError("mesh_smooth: max_sweeps must be >= 0, got " +
                     std::to_string(options.max_sweeps));
  if (options.layers < 0)
    throw InputError("mesh_smooth: layers must be >= 0, got " + std::to_string(options.layers));
  if (options.joint_iterations < 0)
    throw InputError("mesh_smooth: joint_iterations must be >= 0, got " +
                     std::to_string(options.joint_iterations));
  if (options.joint_rounds < 1)
    throw InputError("mesh_smooth: joint_rounds must be >= 1, got " +
                     std::to_string(options.joint_rounds));
  if (!(options.feature_angle_degrees > 0 && options.feature_angle_degrees < 180))
    throw InputError("mesh_smooth: feature angle must be in (0, 180) degrees, got " +
                     std::to_string(options.feature_angle_degrees));
  if (!(options.visit_below > 0 && options.visit_below <= 1))
    throw InputError("mesh_smooth: visit_below must be in (0, 1], got " +
                     std::to_string(options.visit_below));
  mesh_validate_ids(mesh, "mesh_smooth");
  for (int32_t n = 0; n < mesh.point_count(); ++n)
    if (!mesh.points[n].allFinite())
      throw InputError("mesh_smooth: node " + std::to_string(n) + " has a non-finite coordinate");
  for (int32_t h : options.region_hexes)
    if (h < 0 || h >= mesh.hex_count())
      throw InputError("mesh_smooth: region hex " + std::to_string(h) + " out of range 0.." +
                       std::to_string(mesh.hex_count() - 1));

  for (int32_t v : options.fixed_nodes)
    if (v < 0 || v >= mesh.point_count())
      throw InputError("mesh_smooth: fixed node " + std::to_string(v) + " out of range 0.." +
                       std::to_string(mesh.point_count() - 1));
}

/// Step 1 (see the file comment): the region (every hex when options.region_hexes is empty),
/// its options.layers layers, and the hexes around their nodes, into part.region and
/// part.hexes.
void smoothing_region_gather(const HexMesh& mesh, const SmoothOptions& options,
                             SmoothingPart& part) {
  std::vector<int32_t>& region = part.region;
  region = options.region_hexes;
  if (region.empty()) {
    region.resize(mesh.hexes.size());
    for (int32_t h = 0; h < mesh.hex_count(); ++h) region[h] = h;
  }
  std::sort(region.begin(), region.end());
  region.erase(std::unique(region.begin(), region.end()), region.end());
  std::vector<int32_t> offsets, items;
  const bool whole = static_cast<int64_t>(region.size()) == mesh.hex_count();
  if (!whole) {
    std::vector<int32_t> all(mesh.hexes.size());
    for (int32_t h = 0; h < mesh.hex_count(); ++h) all[h] = h;
    node_hexes_of(mesh, all, offsets, items);
    for (int layer = 0; layer < options.layers; ++layer)
      region = hexes_around(mesh, region, offsets, items);
  }
  part.hexes = whole ? region : hexes_around(mesh, region, offsets, items);
}

/// Step 2: the part as a mesh of its own, and per node of it whether it may move (a region node
/// not in options.fixed_nodes).
void region_nodes_movable(const HexMesh& mesh, const SmoothOptions& options, SmoothingPart& part) {
  part.sub = mesh_extract(mesh, part.hexes);
  const SubMesh& sub = part.sub;
  std::vector<uint8_t>& in_region = part.in_region;
  in_region.assign(sub.mesh.points.size(), 0);
  std::vector<int32_t> local_of_part(mesh.hexes.size(), -1);
  for (size_t k = 0; k < part.hexes.size(); ++k)
    local_of_part[part.hexes[k]] = static_cast<int32_t>(k);
  for (int32_t h : part.region)
    for (int32_t v : sub.mesh.hexes[local_of_part[h]]) in_region[v] = 1;
  if (!options.fixed_nodes.empty()) {
    std::vector<uint8_t> fixed(mesh.points.size(), 0);
    for (int32_t v : options.fixed_nodes) fixed[v] = 1;
    for (size_t n = 0; n < in_region.size(); ++n)
      if (fixed[sub.node_of[n]]) in_region[n] = 0;
  }
}

/// Step 2, with options.reference_surface: the surface guard's faces. Per movable node of
/// `problem` (nodes and slides set), the part's boundary faces (`boundary_faces`) it is a
/// corner of that need the guard, into problem.faces, node_face_offsets and node_face.
void sliding_nodes_guard_faces(const SmoothOptions& options, const SubMesh& sub,
                               const std::vector<HexFaceSlot>& boundary_faces,
                               NodeProblem& problem) {
  // The boundary faces at a sliding node (a face holding a region node is a boundary face
  // of the whole mesh, see the file comment), and per movable node the ones it is a corner of.
  std::vector<int32_t> sliding_of_sub(sub.mesh.points.size(), -1);
  for (const HexFaceSlot& f : boundary_faces)
    for (int k = 0; k < 4; ++k) {
      const int32_t v = sub.mesh.hexes[f.hex][hex_faces[f.local_face][k]];
      const auto at = std::lower_bound(problem.nodes.begin(), problem.nodes.end(), sub.node_of[v]);
      if (at != problem.nodes.end() && *at == sub.node_of[v] &&
          problem.slides[at - problem.nodes.begin()].kind != SlideKind::free)
        sliding_of_sub[v] = static_cast<int32_t>(at - problem.nodes.begin());
    }
  problem.surface = options.reference_surface;
  // A face needs the guard when a corner slides, unless every corner stays on one input
  // face: its moving corners slide on that one patch and its fixed ones lie on it. Such a
  // face passes the checker's first test whatever the moves (most faces of the region:
  // the sub-faces of an input face), and skipping it halves the guard's cost.
  const auto guarded = [&](const HexFaceSlot& f) {
    int32_t patch = -1;
    bool sliding = false, one_patch = true;
    for (int k = 0; k < 4 && one_patch; ++k) {
      const int32_t i = sliding_of_sub[sub.mesh.hexes[f.hex][hex_faces[f.local_face][k]]];
      if (i < 0) continue;
      sliding = true;
      const NodeSlide& slide = problem.slides[i];
      const int32_t item = problem.geometry.items[slide.first];
      one_patch = slide.kind == SlideKind::patch && (patch < 0 || patch == item);
      patch = item;
    }
    if (!sliding) return false;
    if (!one_patch) return true;
    const Quad& on = problem.geometry.patches[patch];
    for (int k = 0; k < 4; ++k) {
      const int32_t v = sub.mesh.hexes[f.hex][hex_faces[f.local_face][k]];
      if (sliding_of_sub[v] < 0 &&
          !quad_within(on, sub.mesh.points[v], mesh_check_surface_tolerance * quad_diameter(on)))
        return true;
    }
    return false;
  };
  std::vector<uint8_t> face_guarded(boundary_faces.size());
  problem.node_face_offsets.assign(problem.nodes.size() + 1, 0);
  for (size_t fi = 0; fi < boundary_faces.size(); ++fi) {
    const HexFaceSlot& f = boundary_faces[fi];
    face_guarded[fi] = guarded(f);
    if (!face_guarded[fi]) continue;
    std::array<int32_t, 4> q;
    for (int k = 0; k < 4; ++k) {
      const int32_t v = sub.mesh.hexes[f.hex][hex_faces[f.local_face][k]];
      q[k] = sub.node_of[v];
      if (sliding_of_sub[v] >= 0) ++problem.node_face_offsets[sliding_of_sub[v] + 1];
    }
    problem.faces.push_back(q);
  }
  for (size_t i = 0; i < problem.nodes.size(); ++i)
    problem.node_face_offsets[i + 1] += problem.node_face_offsets[i];
  problem.node_face.resize(problem.node_face_offsets.back());
  std::vector<int32_t> cursor(problem.node_face_offsets.begin(),
                              problem.node_face_offsets.end() - 1);
  int32_t guarded_index = 0;
  for (size_t fi = 0; fi < boundary_faces.size(); ++fi) {
    if (!face_guarded[fi]) continue;
    const HexFaceSlot& f = boundary_faces[fi];
    for (int k = 0; k < 4; ++k) {
      const int32_t i = sliding_of_sub[sub.mesh.hexes[f.hex][hex_faces[f.local_face][k]]];
      if (i >= 0) problem.node_face[cursor[i]++] = guarded_index;
    }
    ++guarded_index;
  }
}

/// Step 2 with options.reference: the movable nodes (ascending) and their slides on the
/// input's boundary (ReferenceSlides), and with options.reference_surface the guard's faces,
/// into `problem`.
void movable_nodes_slide_on_input(const HexMesh& mesh, const SmoothOptions& options,
                                  const SmoothingPart& part, NodeProblem& problem) {
  const SubMesh& sub = part.sub;
  const std::vector<int32_t>* parent = mesh_find_attribute(mesh, attribute_parent_hex);
  if (!parent) throw InputError("mesh_smooth: a reference needs the mesh's parent_hex attribute");
  // The part's boundary nodes and the hexes around each node, from matched faces and one
  // counting sort: no general topology (its edges and face ids) is needed here.
  std::vector<uint8_t> boundary(sub.mesh.points.size(), 0);
  const std::vector<HexFaceSlot> boundary_faces =
      hex_face_adjacency_build(sub.mesh, options.threads, false).boundary_faces;
  for (const HexFaceSlot& f : boundary_faces)
    for (int k = 0; k < 4; ++k) boundary[sub.mesh.hexes[f.hex][hex_faces[f.local_face][k]]] = 1;
  std::vector<int32_t> sub_hexes(sub.mesh.hexes.size()), hex_offsets, hex_items;
  std::iota(sub_hexes.begin(), sub_hexes.end(), 0);
  node_hexes_of(sub.mesh, sub_hexes, hex_offsets, hex_items);
  ReferenceSlides slides(*options.reference, problem.geometry);
  // On a planar-faced input every kink between its faces is its geometry (the checker holds
  // such an output to the input's volume and area): input nodes slide only across flat
  // sides there. On a curved (warped) input the feature angle decides.
  bool planar_faced = true;
  for (const Quad& q : options.reference->patches)
    if (quad_relative_warp(q) > 1e-12) {
      planar_faced = false;
      break;
    }
  const double input_feature_cos =
      planar_faced ? 1 - 1e-9 : std::cos(options.feature_angle_degrees * std::numbers::pi / 180.0);
  std::vector<int32_t> around;
  std::vector<std::pair<int32_t, NodeSlide>> movable;
  for (int32_t n = 0; n < sub.mesh.point_count(); ++n) {
    if (!part.in_region[n]) continue;
    const int32_t node = sub.node_of[n];
    NodeSlide slide;
    if (boundary[n]) {
      around.clear();
      for (int32_t k = hex_offsets[n]; k < hex_offsets[n + 1]; ++k)
        around.push_back((*parent)[part.hexes[hex_items[k]]]);
      std::sort(around.begin(), around.end());
      around.erase(std::unique(around.begin(), around.end()), around.end());
      const std::optional<NodeSlide> s =
          node < options.reference_nodes
              ? slides.at_input_node(mesh.points[node], around, input_feature_cos)
              : slides.at(mesh.points[node], around, input_feature_cos);
      if (!s) continue;
      slide = *s;
    }
    movable.push_back({node, slide});
  }
  std::sort(movable.begin(), movable.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& [node, slide] : movable) {
    problem.nodes.push_back(node);
    problem.slides.push_back(slide);
  }
  if (options.reference_surface) sliding_nodes_guard_faces(options, sub, boundary_faces, problem);
}

/// Step 2 without options.reference: the movable nodes (ascending) and their slides on the
/// part's own boundary quads and feature edges (SmoothNodeKind; corners stay), into `problem`.
void movable_nodes_slide_on_own_boundary(const SmoothOptions& options, const SmoothingPart& part,
                                         NodeProblem& problem) {
  const SubMesh& sub = part.sub;
  const HexTopology topology = topology_build(sub.mesh);
  const SmoothNodeClasses classes =
      mesh_classify_smooth_nodes(sub.mesh, topology, options.feature_angle_degrees);
  // Boundary quads and feature edges around each node, by the part's topology.
  std::vector<int32_t> patch_of_face(topology.face_count(), -1);
  std::unordered_map<uint64_t, int32_t> segment_of_edge;
  SlideGeometry& g = problem.geometry;
  std::vector<std::pair<int32_t, NodeSlide>> movable;
  for (int32_t n = 0; n < sub.mesh.point_count(); ++n) {
    if (!part.in_region[n]) continue;
    const SmoothNodeKind kind = classes.kind[n];
    if (kind == SmoothNodeKind::corner) continue;
    NodeSlide slide;
    slide.first = static_cast<int32_t>(g.items.size());
    if (kind == SmoothNodeKind::surface) {
      // The boundary quads around the node.
      for (int32_t h : node_hexes(topology, n))
        for (int lf = 0; lf < 6; ++lf) {
          const int32_t f = topology.hex_face_ids[h][lf];
          const auto& q = topology.face_nodes[f];
          if (!face_is_boundary(topology, f) || std::find(q.begin(), q.end(), n) == q.end())
            continue;
          if (patch_of_face[f] < 0) {
            patch_of_face[f] = static_cast<int32_t>(g.patches.size());
            g.patches.push_back({sub.mesh.points[q[0]], sub.mesh.points[q[1]],
                                 sub.mesh.points[q[2]], sub.mesh.points[q[3]]});
          }
          if (std::find(g.items.begin() + slide.first, g.items.end(), patch_of_face[f]) ==
              g.items.end())
            g.items.push_back(patch_of_face[f]);
        }
      slide.kind = SlideKind::patches;
    }
    if (kind == SmoothNodeKind::curve) {
      // The two feature edges at the node: boundary edges whose faces meet at a feature angle.
      slide.kind = SlideKind::segments;
      const double feature_cos = std::cos(options.feature_angle_degrees * std::numbers::pi / 180);
      std::vector<std::pair<int32_t, Vec3>> neighbours;  // (other node, face normal)
      for (int32_t h : node_hexes(topology, n))
        for (int lf = 0; lf < 6; ++lf) {
          const int32_t f = topology.hex_face_ids[h][lf];
          if (!face_is_boundary(topology, f)) continue;
          const auto& q = topology.face_nodes[f];
          const int at = static_cast<int>(std::find(q.begin(), q.end(), n) - q.begin());
          if (at == 4) continue;
          const Vec3 normal = (sub.mesh.points[q[2]] - sub.mesh.points[q[0]])
                                  .cross(sub.mesh.points[q[3]] - sub.mesh.points[q[1]])
                                  .normalized();
          neighbours.push_back({q[(at + 1) % 4], normal});
          neighbours.push_back({q[(at + 3) % 4], normal});
        }
      std::sort(neighbours.begin(), neighbours.end(),
                [](const auto& x, const auto& y) { return x.first < y.first; });
      for (size_t i = 0; i < neighbours.size();) {
        size_t j = i;
        while (j < neighbours.size() && neighbours[j].first == neighbours[i].first) ++j;
        const bool feature =
            j - i != 2 || neighbours[i].second.dot(neighbours[i + 1].second) < feature_cos;
        if (feature) {
          const int32_t other = neighbours[i].first;
          const uint64_t key = static_cast<uint64_t>(std::min(n, other)) << 32 |
                               static_cast<uint32_t>(std::max(n, other));
          const auto [it, inserted] =
              segment_of_edge.try_emplace(key, static_cast<int32_t>(g.segments.size()));
          if (inserted) g.segments.push_back({sub.mesh.points[n], sub.mesh.points[other]});
          g.items.push_back(it->second);
        }
        i = j;
      }
    }
    slide.count = static_cast<int32_t>(g.items.size()) - slide.first;
    if (kind != SmoothNodeKind::interior && slide.count == 0) continue;
    movable.push_back({sub.node_of[n], slide});
  }
  std::sort(movable.begin(), movable.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& [node, slide] : movable) {
    problem.nodes.push_back(node);
    problem.slides.push_back(slide);
  }
}

/// Step 3: the sweeps' options (smart Laplacian always; with SmoothMethod::optimize the Newton
/// step and the max-min ascent; no valid hex may invert).
NodeOptimizerOptions smoothing_sweep_options(const SmoothOptions& options) {
  NodeOptimizerOptions o;
  o.laplacian = true;
  o.mean_ratio = options.method == SmoothMethod::optimize;
  o.ascent = options.method == SmoothMethod::optimize;
  o.keep_positive = true;
  o.max_sweeps = options.max_sweeps;
  o.ascent_steps = 3;
  o.visit_below = options.visit_below;
  o.threads = options.threads;
  o.max_edge_ratio = options.max_edge_ratio;
  return o;
}

/// Step 4: the joint ascent's options (SmoothMethod::optimize only; boundary nodes on their
/// slides, steered along the edge-ratio caps, in options.joint_rounds rounds).
JointAscentOptions smoothing_joint_ascent_options(const SmoothOptions& options) {
  JointAscentOptions joint_options;
  joint_options.max_edge_ratio = options.max_edge_ratio;
  joint_options.max_iterations =
      options.method == SmoothMethod::optimize ? options.joint_iterations : 0;
  joint_options.threads = options.threads;
  joint_options.slide = true;
  joint_options.cap_samples = true;
  joint_options.rounds = options.joint_rounds;
  return joint_options;
}

}  // namespace

SmoothStats mesh_smooth(HexMesh& mesh, const SmoothOptions& options) {
  const auto clock_start = std::chrono::steady_clock::now();
  smooth_options_check(mesh, options);
  SmoothStats stats;
  min_mean(mesh, stats.min_scaled_jacobian_before, stats.mean_scaled_jacobian_before);

  SmoothingPart part;
  smoothing_region_gather(mesh, options, part);  // 1
  stats.region_hexes = static_cast<int64_t>(part.region.size());
  region_nodes_movable(mesh, options, part);  // 2
  NodeProblem problem;
  if (options.reference)
    movable_nodes_slide_on_input(mesh, options, part, problem);
  else
    movable_nodes_slide_on_own_boundary(options, part, problem);
  stats.movable_nodes = static_cast<int64_t>(problem.nodes.size());
  std::vector<Vec3> start_points;
  start_points.reserve(problem.nodes.size());
  for (int32_t v : problem.nodes) start_points.push_back(mesh.points[v]);
  node_problem_connect(problem, mesh, part.hexes);

  const SweepsAndAscentStats run =
      nodes_sweep_and_ascend(mesh, problem, smoothing_sweep_options(options),  // 3
                             smoothing_joint_ascent_options(options));         // 4
  stats.sweeps = run.sweeps;
  stats.joint_iterations = run.joint_iterations;
  stats.joint_rounds = run.joint_rounds;
  stats.nodes_moved = 0;
  for (size_t i = 0; i < problem.nodes.size(); ++i)
    stats.nodes_moved += mesh.points[problem.nodes[i]] != start_points[i];
  min_mean(mesh, stats.min_scaled_jacobian_after, stats.mean_scaled_jacobian_after);
  stats.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - clock_start).count();
  return stats;
}

std::vector<int32_t> mesh_refined_hexes(const HexMesh& mesh) {
  std::vector<int32_t> out;
  const std::vector<int32_t>* tags = mesh_find_attribute(mesh, attribute_template_tag);
  if (!tags) return out;
  for (int32_t h = 0; h < static_cast<int32_t>(tags->size()); ++h)
    if ((*tags)[h] != 0) out.push_back(h);
  return out;
}

}  // namespace hexrefine
