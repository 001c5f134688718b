/// \file
/// Node placement: after the engine has applied a pass (every new node at its parent's trilinear
/// map of the template's reference position, template_reference.hpp: the positions that
/// maximise the worst child on the unit cube, computed offline; or of its exact position, the
/// thesis' placement, for PlacementMethod::trilinear), move the new nodes around the children
/// still poor to raise the worst scaled Jacobian around them, untangling inverted children first.
/// Fixed positions, however good on the unit cube, do not suit anisotropic or distorted parents
/// (a 1-13 in a hex three times longer than wide, the children of a skewed CAD hex); where a node
/// goes never decides which nodes exist.
///
/// Objective and optimizer (node_optimizer.cpp): per node, the max-min problem of Freitag and
/// Plassmann (IJNME 49, 2000) on the scaled Jacobian of the hexes around the node (Verdict's
/// definition, mesh/quality.hpp), solved by ascent of its Kreisselmeier-Steinhauser soft minimum
/// with analytic gradients; a move is kept only if the worst hex around the node improves, so
/// the minimum never drops; the scaled Jacobian is signed, so the same problem untangles.
///
/// Steps of one pass:
///  0. Start positions (the engine's): a parent whose children the reference positions stretch
///     past the edge-ratio cap (PlacementOptions::max_edge_ratio, or what the exact positions
///     give the child if more: a 1-13 in a parent three times longer than wide, whose
///     transition nodes the face rule lifts) gets its new nodes at their exact positions, so the
///     cap holds from the start (the shared rocker arm's sphere:0,0,0,5: 23.5 otherwise, 14.9
///     at the thesis' positions). In a later pass, a new node on a boundary face or edge of
///     its parent is projected onto the input's boundary patch that holds it
///     (ReferenceSlides): the parent's face is a piece of an input patch that its bilinear map
///     reproduces only when the patch is planar or the piece is a rectangle of the patch's
///     parameters, and the reference positions of a 1-4 face make pieces that are not.
///     PlacementMethod::reference stops here.
///  1. Active children: those whose scaled Jacobian is below (1 + PlacementOptions::active_band)
///     times the pass's worst positive child's, or not positive (PlacementMethod::untangle:
///     only those not positive, and no joint ascent in step 4). The reference positions are
///     already the best each template does on an undistorted parent (a brick's cubes: what is
///     left poor there is where templates meet), so optimisation pays where the pass is worst,
///     and is kept to those children and the hexes around them, not every new node. In rounds
///     (steps 1 to 4 again): the first from the start positions; then, while the worst child
///     rises, the band around the new worst, as long as each round fits what is left of a
///     budget of PlacementOptions::active_share of the pass's new hexes (the optimisation's
///     cost stays a share of the refinement's): a 40^3 brick with 3 % random targets takes one
///     round (227 of 319,132 children), the same brick jittered four (552), where one
///     round leaves a single poor child's neighbours as the new worst. In a later pass the first
///     round also takes the children below PlacementOptions::active_ratio times their parent's
///     scaled Jacobian times their own on the unit cube (HexTemplate::child_reference_quality):
///     the parents there are the earlier passes' children, distorted by the templates
///     themselves, which the reference positions suit least (a 6^3 brick refined twice around
///     its centre: 0.20 with the band alone, 0.37 with these). Children of a parallelepiped by
///     a template of boxes equal their parent and are skipped without evaluating them; the
///     others are evaluated on `threads` threads (parallel.hpp), in later rounds only the hexes
///     the last round's problem held.
///  2. Free nodes: the new nodes of active children. From the template node that made each
///     (entity and local index in its parent): strictly inside the parent, or on an interior
///     face or edge of the refined mesh: free (both sides share the node, so conformity holds);
///     on a boundary face: slides on the input's boundary patch that holds it (its bilinear
///     patch, (u, v) in [0,1]^2); on a boundary edge: slides along the input patch edge that
///     holds it, or on the input patch if the edge lies inside one (a later pass's edge); input
///     nodes never move. So boundary nodes stay on the input's boundary surface, in the input
///     face they subdivide (the checker's conformity against the input still holds). In a
///     later pass the earlier passes' new nodes at the corners of active children are free too
///     (those on the boundary slide on the input patches of the input hexes around them): they
///     are new nodes of the refinement, and a transition child of pass 1 refined again in pass
///     2 otherwise keeps the corners that made it poor, its children compounding the loss.
///  3. The problem is local: the hexes around the free nodes are the children of the parents
///     around the active ones (node neighbours in the refined mesh), gathered without building
///     the output's topology. Worst node first, ties by id: the same result for any --threads.
///  4. Where the sweeps stop with every active child valid and the worst still below the band's
///     top, a joint ascent of the free interior nodes around the worst children
///     (node_joint_ascent.hpp: the transition nodes of one template move together, which one
///     node at a time cannot do when several hold the worst child at the same value), then the
///     sweeps again if it raised the minimum. Where the sweeps lifted the worst past the band's
///     top the round's goal is reached without it (the rocker arm's sphere: the joint ascent
///     cost half the placement there and raised nothing).
///  5. A child of a valid parent still inverted after the sweeps: its parent is returned, and
///     the driver refines that parent as a target in a new plan of the pass (refiner.cpp); when
///     that does not help, a refusal (OperationError naming the input hexes and their scaled
///     Jacobians), unless allow_inverted.

#include "algorithms/placement/node_placement.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <string>
#include <unordered_map>

#include "algorithms/placement/node_joint_ascent.hpp"
#include "algorithms/placement/node_optimizer.hpp"
#include "mesh/error.hpp"
#include "mesh/hex_convention.hpp"
#include "mesh/parallel.hpp"
#include "mesh/quality.hpp"

namespace hexrefine {

namespace {

/// Every child of the template is an axis-aligned box of the reference cube: its image under an
/// affine parent has the parent's scaled Jacobian.
bool template_is_boxes(const HexTemplate& t) {
  for (const auto& child : t.children)
    for (int e = 0; e < 12; ++e) {
      const auto& a = t.nodes[child[hex_edges[e][0]]].ref;
      const auto& b = t.nodes[child[hex_edges[e][1]]].ref;
      int moving = 0;
      for (int k = 0; k < 3; ++k) moving += std::abs(a[k] - b[k]) > 1e-12;
      if (moving != 1) return false;
    }
  return true;
}

/// The template node behind a new node: the use, and the plan node of its first active child.
struct NodeOrigin {
  int32_t use = -1;
  int16_t plan_node = -1;
};

/// The input hex of hex h of the pass's mesh (h itself in the first pass).
int32_t pass_original(const PlacementPass& pass, int32_t h) {
  return pass.original_of.empty() ? h : pass.original_of[h];
}

/// Into `around`: the input hexes of the boundary around new node `pn` of a template on hex h
/// (its parent's face if that face is on the boundary, the hexes around its parent's edge if
/// that edge is); empty for a node inside its parent or on an interior face or edge.
void boundary_input_hexes_around(const PlacementPass& pass, int32_t h, const TemplatePlanNode& pn,
                                 std::vector<int32_t>& around) {
  const HexTopology& topology = pass.topology;
  around.clear();
  if (pn.entity == CubeEntity::face) {
    if (face_is_boundary(topology, topology.hex_face_ids[h][pn.local]))
      around.push_back(pass_original(pass, h));
  } else if (pn.entity == CubeEntity::edge) {
    const int32_t e = topology.hex_edge_ids[h][pn.local];
    if (edge_is_boundary(topology, e))
      for (int32_t g : edge_hexes(topology, e)) around.push_back(pass_original(pass, g));
  }
}

/// Step 0 (see the file comment): the parents whose children at the reference positions exceed
/// the edge-ratio cap (max(cap, what the exact positions give the child)) get every new node of
/// theirs at its exact position instead, except the nodes an alias gives to an adjusting hex
/// (they are the adjusting hex's interior nodes, where its own template puts them); a node
/// shared with a neighbour moves for the neighbour too, so the scan repeats (at most three
/// times) over the parents of the children that changed. Only parents whose template has
/// reference positions are scanned (boxes keep the exact ones). Returns how many parents.
/// Known limit, measured: a child holding such a node can stay above its exact ratio
/// (phm_metatron blob:90,1, selective: 22.1 against 21.2). Sending the adjusting hexes to their
/// exact positions too fixes that case but leaves a child inverted elsewhere (ecr_cap's ball of
/// Pipeline.PlacementFallbackMakesAFormerRefusalValid then needs 5 fallback untangles and
/// changes the counts), and so does moving only the aliased nodes to the adjusting hex's exact
/// positions where no hex holding them gets worse: the children there start closer to their
/// exact ratios, so their caps are tighter and the optimizer no longer untangles the child that
/// the looser caps let it untangle. So it is not done.
int64_t parents_past_cap_to_exact(const PlacementPass& pass, HexMesh& refined, double cap) {
  if (!(cap > 0)) return 0;
  const auto& uses = pass.plan.uses;
  const int32_t old_nodes = pass.current.point_count();
  std::vector<uint8_t> scan(uses.size(), 0), exact(uses.size(), 0);
  for (size_t u = 0; u < uses.size(); ++u) scan[u] = !uses[u].tmpl->reference.empty();
  std::unordered_map<NodeKey, bool, NodeKeyHash> aliased;
  for (const NodeAlias& a : pass.plan.aliases) aliased[a.from] = true;
  // Per new node, the uses whose children hold it (to rescan them when it moves).
  int64_t reverted = 0;
  for (int round = 0; round < 3; ++round) {
    std::vector<int32_t> marked;
    for (size_t u = 0; u < uses.size(); ++u) {
      if (!scan[u] || exact[u]) continue;
      const TemplatePlan& plan = uses[u].tmpl->plans[uses[u].symmetry];
      const HexCorners parent = hex_points(pass.current, index_of(uses[u].hex));
      // At the reference positions (the first round), an affine parent stretches a child's
      // edges by at most its map's condition number: a brick's cubes need no look.
      if (round == 0 && hex_is_parallelepiped(parent)) {
        Eigen::Matrix3d a;
        a << parent[1] - parent[0], parent[3] - parent[0], parent[4] - parent[0];
        const Eigen::Vector3d sigma =
            Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(a.transpose() * a).eigenvalues();
        if (sigma[0] > 0 &&
            uses[u].tmpl->reference_edge_ratio * std::sqrt(sigma[2] / sigma[0]) <= cap)
          continue;
      }
      for (size_t c = 0; c < plan.children.size(); ++c) {
        const int32_t child = pass.first_child[u] + static_cast<int32_t>(c);
        const double now = hex_edge_ratio(hex_points(refined, child));
        if (now <= cap) continue;
        HexCorners at_exact;
        for (int k = 0; k < 8; ++k) {
          const TemplatePlanNode& n = plan.nodes[plan.children[c][k]];
          at_exact[k] = n.entity == CubeEntity::corner ? parent[n.local] : Eigen::Vector3d::Zero();
          if (n.entity != CubeEntity::corner)
            for (int v = 0; v < 8; ++v) at_exact[k] += n.weight[v] * parent[v];
        }
        if (now > hex_edge_ratio_cap(at_exact, cap)) {
          marked.push_back(static_cast<int32_t>(u));
          break;
        }
      }
    }
    if (marked.empty()) break;
    std::fill(scan.begin(), scan.end(), 0);
    std::vector<int32_t> moved;
    for (int32_t u : marked) {
      exact[u] = 1;
      ++reverted;
      const TemplatePlan& plan = uses[u].tmpl->plans[uses[u].symmetry];
      const int32_t h = index_of(uses[u].hex);
      const HexCorners parent = hex_points(pass.current, h);
      for (size_t c = 0; c < plan.children.size(); ++c)
        for (int k = 0; k < 8; ++k) {
          const TemplatePlanNode& n = plan.nodes[plan.children[c][k]];
          const int32_t node = refined.hexes[pass.first_child[u] + static_cast<int32_t>(c)][k];
          if (node < old_nodes || n.entity == CubeEntity::corner) continue;
          if (!aliased.empty() && !n.off_grid && n.entity != CubeEntity::interior &&
              aliased.count(node_key_at(pass.current, pass.topology, uses[u].hex, n.param)))
            continue;
          Eigen::Vector3d x = Eigen::Vector3d::Zero();
          for (int v = 0; v < 8; ++v) x += n.weight[v] * parent[v];
          if (x == refined.points[node]) continue;
          refined.points[node] = x;
          if (n.entity != CubeEntity::interior) moved.push_back(node);
        }
    }
    if (moved.empty()) break;
    // The parents around the nodes that moved are scanned again.
    std::sort(moved.begin(), moved.end());
    for (size_t u = 0; u < uses.size(); ++u) {
      if (exact[u] || uses[u].tmpl->reference.empty()) continue;
      const int32_t first = pass.first_child[u];
      const int32_t count = static_cast<int32_t>(uses[u].tmpl->children.size());
      for (int32_t c = first; c < first + count && !scan[u]; ++c)
        for (int32_t v : refined.hexes[c])
          if (std::binary_search(moved.begin(), moved.end(), v)) {
            scan[u] = 1;
            break;
          }
    }
  }
  return reverted;
}

/// Step 0 (see the file comment): the new nodes on a boundary face or edge of their parent,
/// each once, projected onto the nearest input patch (or patch side) of the input hexes around
/// that face or edge; those at a patch corner stay.
void boundary_nodes_project(const PlacementPass& pass, HexMesh& refined) {
  const HexTopology& topology = pass.topology;
  const int32_t old_nodes = pass.current.point_count();
  SlideGeometry geometry;
  ReferenceSlides slides(pass.reference, geometry);
  std::vector<uint8_t> done(refined.points.size() - static_cast<size_t>(old_nodes), 0);
  std::vector<int32_t> around;
  const auto& uses = pass.plan.uses;
  for (size_t u = 0; u < uses.size(); ++u) {
    const int32_t h = index_of(uses[u].hex);
    bool boundary = false;
    for (int lf = 0; lf < 6 && !boundary; ++lf)
      boundary = face_is_boundary(topology, topology.hex_face_ids[h][lf]);
    if (!boundary) continue;
    const TemplatePlan& plan = uses[u].tmpl->plans[uses[u].symmetry];
    for (size_t c = 0; c < plan.children.size(); ++c)
      for (int k = 0; k < 8; ++k) {
        const int32_t node = refined.hexes[pass.first_child[u] + static_cast<int32_t>(c)][k];
        if (node < old_nodes || done[node - old_nodes]) continue;
        done[node - old_nodes] = 1;
        boundary_input_hexes_around(pass, h, plan.nodes[plan.children[c][k]], around);
        if (around.empty()) continue;
        std::sort(around.begin(), around.end());
        around.erase(std::unique(around.begin(), around.end()), around.end());
        const std::optional<NodeSlide> slide = slides.at(refined.points[node], around);
        if (!slide) continue;
        SlideState state;
        refined.points[node] = slide_project(*slide, geometry, refined.points[node], state);
      }
  }
}

}  // namespace

std::optional<NodeSlide> ReferenceSlides::at(const Eigen::Vector3d& x,
                                             std::span<const int32_t> input_hexes,
                                             double feature_cos) {
  int32_t best = -1;
  QuadProjection projection;
  for (int32_t h : input_hexes)
    for (int32_t k = reference_.hex_patch_offsets[h]; k < reference_.hex_patch_offsets[h + 1];
         ++k) {
      const int32_t p = reference_.hex_patches[k];
      const QuadProjection q = quad_closest_point(reference_.patches[p], x);
      if (best < 0 || q.distance < projection.distance) {
        best = p;
        projection = q;
      }
    }
  if (best < 0) return std::nullopt;
  constexpr double rim = 1e-9;
  const bool u_rim = projection.u < rim || projection.u > 1 - rim;
  const bool v_rim = projection.v < rim || projection.v > 1 - rim;
  if (u_rim && v_rim) return std::nullopt;
  NodeSlide slide;
  slide.first = static_cast<int32_t>(geometry_.items.size());
  slide.count = 1;
  if (!u_rim && !v_rim) {
    slide.kind = SlideKind::patch;
    const auto [it, inserted] =
        patch_copy_.try_emplace(best, static_cast<int32_t>(geometry_.patches.size()));
    if (inserted) geometry_.patches.push_back(reference_.patches[best]);
    geometry_.items.push_back(it->second);
    return slide;
  }
  // The patch side: v = 0 (q0 q1), u = 1 (q1 q2), v = 1 (q2 q3), u = 0 (q3 q0).
  const int side = v_rim ? (projection.v < 0.5 ? 0 : 2) : (projection.u > 0.5 ? 1 : 3);
  const Quad& q = reference_.patches[best];
  if (feature_cos > -1) {
    // The other patch on this side, if the surface does not bend there by more than allowed.
    const Eigen::Vector3d normal = quad_unit_normal(q);
    for (int32_t h : input_hexes)
      for (int32_t k = reference_.hex_patch_offsets[h]; k < reference_.hex_patch_offsets[h + 1];
           ++k) {
        const int32_t p = reference_.hex_patches[k];
        const Quad& o = reference_.patches[p];
        if (p == best || std::find(o.begin(), o.end(), q[side]) == o.end() ||
            std::find(o.begin(), o.end(), q[(side + 1) % 4]) == o.end())
          continue;
        const Eigen::Vector3d other = quad_unit_normal(o);
        if (normal.isZero() || other.isZero() || normal.dot(other) < feature_cos) break;
        slide.kind = SlideKind::patches;
        slide.count = 2;
        for (const int32_t both : {std::min(best, p), std::max(best, p)}) {
          const auto [it, inserted] =
              patch_copy_.try_emplace(both, static_cast<int32_t>(geometry_.patches.size()));
          if (inserted) geometry_.patches.push_back(reference_.patches[both]);
          geometry_.items.push_back(it->second);
        }
        return slide;
      }
  }
  const auto [it, inserted] =
      rim_segment_.try_emplace(4 * best + side, static_cast<int32_t>(geometry_.segments.size()));
  if (inserted) geometry_.segments.push_back({q[side], q[(side + 1) % 4]});
  slide.kind = SlideKind::segment;
  geometry_.items.push_back(it->second);
  return slide;
}

std::optional<NodeSlide> ReferenceSlides::at_input_node(const Eigen::Vector3d& x,
                                                        std::span<const int32_t> input_hexes,
                                                        double feature_cos) {
  // The sides at x of the patches cornered at x: (patch, side, its other end, patch normal).
  struct Side {
    int32_t patch;
    int side;
    Eigen::Vector3d other, normal;
  };
  std::vector<Side> sides;
  std::vector<int32_t> patches;
  for (int32_t h : input_hexes)
    for (int32_t k = reference_.hex_patch_offsets[h]; k < reference_.hex_patch_offsets[h + 1];
         ++k) {
      const int32_t p = reference_.hex_patches[k];
      const Quad& q = reference_.patches[p];
      const int at = static_cast<int>(std::find(q.begin(), q.end(), x) - q.begin());
      if (at == 4 || std::find(patches.begin(), patches.end(), p) != patches.end()) continue;
      const Eigen::Vector3d normal = quad_unit_normal(q);
      if (normal.isZero()) return std::nullopt;
      patches.push_back(p);
      sides.push_back({p, at, q[(at + 1) % 4], normal});
      sides.push_back({p, (at + 3) % 4, q[(at + 3) % 4], normal});
    }
  if (patches.empty()) return std::nullopt;
  const auto before = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
  };
  std::sort(sides.begin(), sides.end(),
            [&](const Side& a, const Side& b) { return before(a.other, b.other); });
  std::vector<const Side*> feature;
  for (size_t i = 0; i < sides.size();) {
    size_t j = i;
    while (j < sides.size() && sides[j].other == sides[i].other) ++j;
    if (j - i != 2 || sides[i].normal.dot(sides[i + 1].normal) < feature_cos)
      feature.push_back(&sides[i]);
    i = j;
  }
  NodeSlide slide;
  slide.first = static_cast<int32_t>(geometry_.items.size());
  if (feature.empty()) {
    std::sort(patches.begin(), patches.end());
    for (int32_t p : patches) {
      const auto [it, inserted] =
          patch_copy_.try_emplace(p, static_cast<int32_t>(geometry_.patches.size()));
      if (inserted) geometry_.patches.push_back(reference_.patches[p]);
      geometry_.items.push_back(it->second);
    }
    slide.kind = SlideKind::patches;
  } else if (feature.size() == 2) {
    // A feature curve that turns at x by more than the feature angle is a corner of the
    // surface: sliding along one segment would take the corner of the faces that border only
    // the other across the crease between them (issue 28: ecr_hanger's and ecr_dragon's
    // smoothings the checker rejected).
    const Eigen::Vector3d ahead = (feature[0]->other - x).normalized();
    const Eigen::Vector3d behind = (x - feature[1]->other).normalized();
    if (ahead.dot(behind) < feature_cos) return std::nullopt;
    for (const Side* s : feature) {
      const Quad& q = reference_.patches[s->patch];
      const auto [it, inserted] = rim_segment_.try_emplace(
          4 * s->patch + s->side, static_cast<int32_t>(geometry_.segments.size()));
      if (inserted) geometry_.segments.push_back({q[s->side], q[(s->side + 1) % 4]});
      geometry_.items.push_back(it->second);
    }
    slide.kind = SlideKind::segments;
  } else {
    return std::nullopt;
  }
  slide.count = static_cast<int32_t>(geometry_.items.size()) - slide.first;
  return slide;
}

std::string_view placement_method_name(PlacementMethod m) {
  switch (m) {
    case PlacementMethod::trilinear:
      return "trilinear";
    case PlacementMethod::optimized:
      return "optimized";
    case PlacementMethod::untangle:
      return "untangle";
    case PlacementMethod::reference:
      return "reference";
  }
  return "optimized";
}

TemplatePositions placement_start_positions(PlacementMethod m) {
  return m == PlacementMethod::trilinear || m == PlacementMethod::untangle
             ? TemplatePositions::exact
             : TemplatePositions::reference;
}

BoundaryReference boundary_reference_build(const HexMesh& input, const HexTopology& t) {
  BoundaryReference r;
  r.hex_patch_offsets.assign(static_cast<size_t>(input.hex_count()) + 1, 0);
  std::vector<int32_t> patch_of_face(t.face_count(), -1);
  for (int32_t f = 0; f < t.face_count(); ++f) {
    if (!face_is_boundary(t, f)) continue;
    patch_of_face[f] = static_cast<int32_t>(r.patches.size());
    const auto& n = t.face_nodes[f];
    r.patches.push_back(
        {input.points[n[0]], input.points[n[1]], input.points[n[2]], input.points[n[3]]});
    ++r.hex_patch_offsets[t.face_hexes[f][0] + 1];
  }
  for (int32_t h = 0; h < input.hex_count(); ++h)
    r.hex_patch_offsets[h + 1] += r.hex_patch_offsets[h];
  r.hex_patches.resize(r.patches.size());
  std::vector<int32_t> cursor(r.hex_patch_offsets.begin(), r.hex_patch_offsets.end() - 1);
  for (int32_t f = 0; f < t.face_count(); ++f)
    if (patch_of_face[f] >= 0) r.hex_patches[cursor[t.face_hexes[f][0]]++] = patch_of_face[f];
  return r;
}

std::vector<int32_t> place_new_nodes(const PlacementPass& pass, HexMesh& refined,
                                     const PlacementOptions& options, PlacementStats& stats) {
  if (options.method == PlacementMethod::trilinear) return {};
  const auto start = std::chrono::steady_clock::now();
  const HexMesh& current = pass.current;
  const HexTopology& topology = pass.topology;
  const int32_t old_nodes = current.point_count();
  const auto& uses = pass.plan.uses;
  auto original = [&](int32_t h) { return pass_original(pass, h); };

  // 0. Parents the reference positions stretch past the cap at their exact positions (nothing
  // to do where the start is the exact positions); in a later pass, boundary new nodes onto the
  // input's boundary patches.
  if (placement_start_positions(options.method) == TemplatePositions::reference)
    stats.exact_parents += parents_past_cap_to_exact(pass, refined, options.max_edge_ratio);
  if (pass.input_nodes < old_nodes) boundary_nodes_project(pass, refined);
  if (options.method == PlacementMethod::reference) return {};

  // 1. Active children, in rounds (see the file comment).
  std::unordered_map<const HexTemplate*, bool> boxes;
  std::vector<int32_t> active;  // output hexes, every round's (for step 5)
  std::vector<int32_t> active_use;
  std::vector<double> parent_quality(uses.size(), 1.0);
  // The parents whose children are evaluated.
  std::vector<int32_t> evaluated;  // uses
  for (size_t u = 0; u < uses.size(); ++u) {
    const HexCorners x = hex_points(current, index_of(uses[u].hex));
    const auto [it, inserted] = boxes.try_emplace(uses[u].tmpl, false);
    if (inserted) it->second = template_is_boxes(*uses[u].tmpl);
    if (it->second && hex_is_parallelepiped(x)) continue;
    parent_quality[u] = hex_scaled_jacobian(x);
    evaluated.push_back(static_cast<int32_t>(u));
  }
  const bool later = pass.input_nodes < old_nodes;
  std::vector<double> quality(refined.hexes.size(), 1.0);
  constexpr int64_t parents_per_chunk = 1024;
  std::vector<int32_t> changed;  // the hexes of the last round's problem
  // What the rounds after the first may take, in children.
  int64_t budget = static_cast<int64_t>(std::max<double>(
      options.active_floor,
      options.active_share * static_cast<double>(refined.hex_count() - current.hex_count())));
  double previous_worst = -std::numeric_limits<double>::infinity();
  for (int round = 0;; ++round) {
    // The children's scaled Jacobians at the current positions: every evaluated child's in the
    // first round (per chunk of parents: the same values for any thread count), after that the
    // hexes the previous round's problem held (the others did not change).
    if (round == 0)
      parallel_chunks(pass.threads, static_cast<int64_t>(evaluated.size()), parents_per_chunk,
                      [&](int64_t, int64_t begin, int64_t end) {
                        for (int64_t i = begin; i < end; ++i) {
                          const int32_t u = evaluated[i];
                          const int32_t first = pass.first_child[u];
                          const int32_t count = static_cast<int32_t>(uses[u].tmpl->children.size());
                          for (int32_t c = first; c < first + count; ++c)
                            quality[c] = hex_scaled_jacobian(hex_points(refined, c));
                        }
                      });
    else
      for (int32_t h : changed) quality[h] = hex_scaled_jacobian(hex_points(refined, h));
    double worst_positive = 1;
    for (int32_t u : evaluated)
      for (int32_t c = pass.first_child[u];
           c < pass.first_child[u] + static_cast<int32_t>(uses[u].tmpl->children.size()); ++c)
        if (quality[c] > 0) worst_positive = std::min(worst_positive, quality[c]);
    const double top = (1 + options.active_band) * worst_positive;
    std::vector<int32_t> round_active, round_use;
    std::vector<uint8_t> round_parents(uses.size(), 0);
    int64_t inverted = 0;
    for (int32_t u : evaluated) {
      const int32_t first = pass.first_child[u];
      const int32_t count = static_cast<int32_t>(uses[u].tmpl->children.size());
      const std::vector<double>& unit_cube = uses[u].tmpl->child_reference_quality;
      for (int32_t c = first; c < first + count; ++c) {
        const double q = quality[c];
        const bool poor =
            options.method != PlacementMethod::untangle &&
            (q < top || (round == 0 && later &&
                         q < options.active_ratio * parent_quality[u] * unit_cube[c - first]));
        if (!poor && q > 0) continue;
        round_active.push_back(c);
        round_use.push_back(u);
        round_parents[u] = 1;
        inverted += !(q > 0);
        if (round == 0) stats.min_before = std::min(stats.min_before, q);
      }
    }
    if (round_active.empty()) break;
    // After the first round: only while the worst child rises and the round fits the budget.
    if (round > 0) {
      if (options.method == PlacementMethod::untangle || !(worst_positive > previous_worst) ||
          static_cast<int64_t>(round_active.size()) > budget)
        break;
      budget -= static_cast<int64_t>(round_active.size());
    } else {
      stats.inverted_before += inverted;
    }
    previous_worst = worst_positive;
    stats.active_hexes += static_cast<int64_t>(round_active.size());
    active.insert(active.end(), round_active.begin(), round_active.end());
    active_use.insert(active_use.end(), round_use.begin(), round_use.end());
    {
      // The hexes around the free nodes: children of the parents node-adjacent to the active ones
      // (a new node lies on its parent's closure, so every hex holding it is a child of a parent
      // sharing a node with that parent), one ring more per layer of nodes added below.
      std::vector<int32_t> candidates, candidate_use;
      {
        std::vector<int32_t> use_of_hex(current.hex_count(), -1);
        for (size_t u = 0; u < uses.size(); ++u)
          use_of_hex[index_of(uses[u].hex)] = static_cast<int32_t>(u);
        std::vector<uint8_t> taken(uses.size(), 0);
        std::vector<int32_t> near_uses, ring;
        for (size_t u = 0; u < uses.size(); ++u)
          if (round_parents[u]) ring.push_back(static_cast<int32_t>(u));
        for (int step = 0; step <= options.layers; ++step) {
          std::vector<int32_t> next;
          for (int32_t u : ring)
            for (int32_t v : current.hexes[index_of(uses[u].hex)])
              for (int32_t g : node_hexes(topology, v)) {
                const int32_t w = use_of_hex[g];
                if (w >= 0 && !taken[w]) {
                  taken[w] = 1;
                  near_uses.push_back(w);
                  next.push_back(w);
                }
              }
          ring = std::move(next);
        }
        std::sort(near_uses.begin(), near_uses.end());
        for (int32_t u : near_uses)
          for (int32_t c = pass.first_child[u];
               c < pass.first_child[u] + static_cast<int32_t>(uses[u].tmpl->children.size()); ++c) {
            candidates.push_back(c);
            candidate_use.push_back(u);
          }
      }

      // 2. Free nodes and where each came from.
      std::unordered_map<int32_t, NodeOrigin> origin_of;
      for (size_t a = 0; a < round_active.size(); ++a) {
        const int32_t u = round_use[a];
        const TemplatePlan& plan = uses[u].tmpl->plans[uses[u].symmetry];
        const int32_t child = round_active[a] - pass.first_child[u];
        for (int k = 0; k < 8; ++k) {
          const int32_t node = refined.hexes[round_active[a]][k];
          if (node < old_nodes) continue;
          origin_of.try_emplace(node, NodeOrigin{u, plan.children[child][k]});
        }
      }
      // The new nodes of the children around them may move too (PlacementOptions::layers): a poor
      // child often needs its neighbours to give way.
      for (int layer = 0; layer < options.layers; ++layer) {
        std::vector<std::pair<int32_t, NodeOrigin>> added;
        for (size_t k = 0; k < candidates.size(); ++k) {
          const HexCell& c = refined.hexes[candidates[k]];
          bool touches = false;
          for (int32_t v : c) touches = touches || origin_of.count(v);
          if (!touches) continue;
          const int32_t u = candidate_use[k];
          const TemplatePlan& plan = uses[u].tmpl->plans[uses[u].symmetry];
          const int32_t child = candidates[k] - pass.first_child[u];
          for (int v = 0; v < 8; ++v)
            if (c[v] >= old_nodes && !origin_of.count(c[v]))
              added.push_back({c[v], NodeOrigin{u, plan.children[child][v]}});
        }
        for (const auto& [node, o] : added) origin_of.try_emplace(node, o);
      }
      // Earlier passes' new nodes at the corners of the active children (ascending), and the
      // hexes around them that this pass left untouched: they join the problem (`candidates`).
      std::vector<int32_t> earlier;
      if (pass.input_nodes < old_nodes) {
        for (int32_t c : round_active)
          for (int32_t v : refined.hexes[c])
            if (v >= pass.input_nodes && v < old_nodes) earlier.push_back(v);
        std::sort(earlier.begin(), earlier.end());
        earlier.erase(std::unique(earlier.begin(), earlier.end()), earlier.end());
        // An untouched hex h of `current` is copied to h plus the children beyond one of the
        // refined hexes before it (plan_apply keeps the input order; uses ascend by hex).
        std::vector<int32_t> use_hexes(uses.size());
        for (size_t u = 0; u < uses.size(); ++u) use_hexes[u] = index_of(uses[u].hex);
        for (int32_t v : earlier)
          for (int32_t g : node_hexes(topology, v)) {
            const auto at = std::lower_bound(use_hexes.begin(), use_hexes.end(), g);
            if (at != use_hexes.end() && *at == g) continue;  // refined: its children are there
            const size_t k = static_cast<size_t>(at - use_hexes.begin());
            const int32_t copied =
                k == 0 ? g
                       : pass.first_child[k - 1] +
                             static_cast<int32_t>(uses[k - 1].tmpl->children.size()) +
                             (g - use_hexes[k - 1] - 1);
            candidates.push_back(copied);
          }
        std::sort(candidates.begin(), candidates.end());
        candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
      }
      NodeProblem problem;
      {
        std::vector<int32_t> nodes;
        for (const auto& [node, o] : origin_of) nodes.push_back(node);
        std::sort(nodes.begin(), nodes.end());
        ReferenceSlides slides(pass.reference, problem.geometry);
        std::vector<int32_t> around;
        // Earlier passes' nodes first (their ids are below this pass's): on the boundary of
        // `current`, they slide on the input patches of the input hexes around them.
        for (int32_t node : earlier) {
          around.clear();
          bool boundary = false;
          for (int32_t g : node_hexes(topology, node)) {
            around.push_back(original(g));
            for (int lf = 0; lf < 6 && !boundary; ++lf) {
              const int32_t f = topology.hex_face_ids[g][lf];
              if (!face_is_boundary(topology, f)) continue;
              const auto& q = topology.face_nodes[f];
              boundary = std::find(q.begin(), q.end(), node) != q.end();
            }
          }
          NodeSlide slide;
          if (boundary) {
            std::sort(around.begin(), around.end());
            around.erase(std::unique(around.begin(), around.end()), around.end());
            const std::optional<NodeSlide> s = slides.at(refined.points[node], around);
            if (!s) continue;  // at an input patch corner: stays
            slide = *s;
          }
          problem.nodes.push_back(node);
          problem.slides.push_back(slide);
        }
        for (int32_t node : nodes) {
          const NodeOrigin& o = origin_of.at(node);
          const TemplateUse& use = uses[o.use];
          const int32_t h = index_of(use.hex);
          const TemplatePlanNode& pn = use.tmpl->plans[use.symmetry].nodes[o.plan_node];
          // On the boundary of the refined mesh: the input hexes around the node's entity.
          boundary_input_hexes_around(pass, h, pn, around);
          NodeSlide slide;
          if (!around.empty()) {
            const std::optional<NodeSlide> s = slides.at(refined.points[node], around);
            if (!s) continue;  // at an input patch corner: stays
            slide = *s;
          }
          problem.nodes.push_back(node);
          problem.slides.push_back(slide);
        }
      }
      stats.free_nodes += static_cast<int64_t>(problem.nodes.size());
      node_problem_connect(problem, refined, candidates);

      NodeOptimizerOptions optimizer;
      optimizer.keep_positive = false;
      optimizer.max_sweeps = options.max_sweeps;
      optimizer.smooth_sweeps = options.smooth_sweeps;
      optimizer.threads = pass.threads;
      optimizer.max_edge_ratio = options.max_edge_ratio;
      std::vector<Eigen::Vector3d> start_points;
      start_points.reserve(problem.nodes.size());
      for (int32_t v : problem.nodes) start_points.push_back(refined.points[v]);
      JointAscentOptions joint_options;
      joint_options.max_iterations =
          options.method == PlacementMethod::untangle ? 0 : options.joint_iterations;
      joint_options.threads = pass.threads;
      joint_options.max_edge_ratio = options.max_edge_ratio;
      // The joint ascent where the sweeps leave the worst below the band's top (several nodes hold
      // it there, node_joint_ascent.hpp); where they lifted it past, the band's goal is reached.
      const SweepsAndAscentStats run = nodes_sweep_and_ascend(
          refined, problem, optimizer, joint_options,
          options.method == PlacementMethod::untangle ? std::numeric_limits<double>::infinity()
                                                      : top);
      stats.sweeps = std::max(stats.sweeps, run.sweeps);
      stats.joint_iterations += run.joint_iterations;
      for (size_t i = 0; i < problem.nodes.size(); ++i)
        stats.nodes_moved += refined.points[problem.nodes[i]] != start_points[i];
      changed = problem.hexes;
    }
  }
  if (active.empty()) return {};
  {
    // Every child once (a child of several rounds), ascending.
    std::vector<std::pair<int32_t, int32_t>> all;
    for (size_t a = 0; a < active.size(); ++a) all.push_back({active[a], active_use[a]});
    std::sort(all.begin(), all.end());
    all.erase(std::unique(all.begin(), all.end()), all.end());
    for (size_t a = 0; a < all.size(); ++a) {
      active[a] = all[a].first;
      active_use[a] = all[a].second;
    }
    active.resize(all.size());
    active_use.resize(all.size());
  }

  // 4. What is left inverted.
  std::vector<int32_t> failed;
  for (size_t a = 0; a < active.size(); ++a) {
    const double q = hex_scaled_jacobian(hex_points(refined, active[a]));
    stats.min_after = std::min(stats.min_after, q);
    const int32_t u = active_use[a];
    const bool was_inverted = parent_quality[u] > 0;  // a valid parent's child
    if (q > 0) continue;
    if (was_inverted) failed.push_back(u);
  }
  int64_t still_inverted = 0;
  for (size_t a = 0; a < active.size(); ++a)
    still_inverted += !(hex_scaled_jacobian(hex_points(refined, active[a])) > 0);
  stats.untangled += std::max<int64_t>(0, stats.inverted_before - still_inverted);
  stats.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (failed.empty() || pass.allow_inverted) return {};
  std::sort(failed.begin(), failed.end());
  failed.erase(std::unique(failed.begin(), failed.end()), failed.end());
  if (!pass.refuse) {
    std::vector<int32_t> parents;
    for (int32_t u : failed) parents.push_back(index_of(uses[u].hex));
    std::sort(parents.begin(), parents.end());
    return parents;
  }
  std::string list;
  for (size_t i = 0; i < failed.size() && i < 10; ++i) {
    const int32_t h = index_of(uses[failed[i]].hex);
    list += (i ? ", " : "") + std::to_string(original(h)) + " (" +
            std::to_string(parent_quality[failed[i]]) + ")";
  }
  throw PlacementError(
      "node placement: no placement of the new nodes gives every child a "
      "positive scaled Jacobian in input hexes (scaled Jacobian) " +
      list + (failed.size() > 10 ? ", ..." : "") +
      "; they are too distorted for the templates they need");
}

}  // namespace hexrefine
