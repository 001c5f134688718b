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
/// Steps of one pass (place_new_nodes; steps 1 to 4 are one round, PlacementRound, and what the
/// rounds share is PlacementRounds):
///  0. new_nodes_move_to_start: the start positions (the engine's), corrected twice. A parent
///     whose children the reference positions stretch past the edge-ratio cap
///     (PlacementOptions::max_edge_ratio, or what the exact positions give the child if more: a
///     1-13 in a parent three times longer than wide, whose transition nodes the face rule
///     lifts) gets its new nodes at their exact positions (parents_past_cap_to_exact), so the
///     cap holds from the start rather than being restored by the optimizer
///     (docs/placement-and-smoothing.md, 'Where placement starts'). In a later pass, a new node
///     on a boundary face or edge of its parent is projected onto the input's boundary patch
///     that holds it (boundary_nodes_project, ReferenceSlides): the parent's face is a piece of
///     an input patch that its bilinear map reproduces only when the patch is planar or the
///     piece is a rectangle of the patch's parameters, and the reference positions of a 1-4
///     face make pieces that are not. PlacementMethod::reference stops here.
///  1. active_children_of_round (evaluated_parents_choose once per pass): the active children,
///     those whose scaled Jacobian is below (1 + PlacementOptions::active_band) times the pass's
///     worst positive child's, or not positive (PlacementMethod::untangle: only those not
///     positive, and no joint ascent in step 4). The reference positions are already the best
///     each template does on an undistorted parent (a brick's cubes: what is left poor there is
///     where templates meet), so optimisation pays where the pass is worst, and is kept to those
///     children and the hexes around them, not every new node. In rounds (steps 1 to 4 again):
///     the first from the start positions; then, while the worst child rises, the band around
///     the new worst, as long as each round fits what is left of a budget of
///     PlacementOptions::active_share of the pass's new hexes, so the optimisation's cost stays
///     a share of the refinement's; one round can leave a single poor child's neighbours as the
///     new worst, which the next round takes (docs/placement-and-smoothing.md, 'Where placement
///     starts'). In a later pass the first round also takes the children below
///     PlacementOptions::active_ratio times their parent's scaled Jacobian times their own on
///     the unit cube (HexTemplate::child_reference_quality): the parents there are the earlier
///     passes' children, distorted by the templates themselves, which the reference positions
///     suit least, and the band alone leaves them poor. Children of a parallelepiped by a
///     template of boxes equal their parent and are skipped without evaluating them; the others
///     are evaluated on `threads` threads (parallel.hpp), in later rounds only the hexes the last
///     round's problem held (children_scaled_jacobians_update).
///  2. problem_hexes_around_active_parents: the problem is local. The hexes around the free
///     nodes are the children of the parents around the active ones (node neighbours in the
///     refined mesh), gathered without building the output's topology.
///  3. free_nodes_gather: the free nodes, the new nodes of active children
///     (free_nodes_of_active_children). From the template node that made each (entity and local
///     index in its parent): strictly inside the parent, or on an interior face or edge of the
///     refined mesh: free (both sides share the node, so conformity holds); on a boundary face:
///     slides on the input's boundary patch that holds it (its bilinear patch, (u, v) in
///     [0,1]^2); on a boundary edge: slides along the input patch edge that holds it, or on the
///     input patch if the edge lies inside one (a later pass's edge); input nodes never move
///     (free_nodes_slides). So boundary nodes stay on the input's boundary surface, in the input
///     face they subdivide (the checker's conformity against the input still holds). In a later
///     pass the earlier passes' new nodes at the corners of active children are free too (those
///     on the boundary slide on the input patches of the input hexes around them;
///     earlier_nodes_and_their_hexes): they are new nodes of the refinement, and a transition
///     child of pass 1 refined again in pass 2 otherwise keeps the corners that made it poor,
///     its children compounding the loss.
///  4. free_nodes_sweep_and_ascend: the sweeps, worst node first, ties by id (the same result
///     for any --threads). Where they stop with every active child valid and the worst still
///     below the band's top, a joint ascent of the free interior nodes around the worst children
///     (node_joint_ascent.hpp: the transition nodes of one template move together, which one
///     node at a time cannot do when several hold the worst child at the same value), then the
///     sweeps again if it raised the minimum. Where the sweeps lifted the worst past the band's
///     top the round's goal is reached without it, and the ascent would cost time for nothing
///     (docs/placement-and-smoothing.md, 'The joint ascent in placement').
///  5. inverted_children_parents: a child of a valid parent still inverted after the sweeps: its
///     parent is returned, and the driver refines that parent as a target in a new plan of the
///     pass (refiner.cpp); when that does not help, a refusal (OperationError naming the input
///     hexes and their scaled Jacobians), unless allow_inverted.

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
/// Known limit: a child holding such an aliased node can stay above its exact ratio. Sending
/// the adjusting hexes to their exact positions too, or only their aliased nodes where no hex
/// holding them gets worse, fixes that but leaves a child inverted elsewhere: the children start
/// closer to their exact ratios, so their caps are tighter and the optimizer no longer untangles
/// what the looser caps let it untangle. So it is not done (docs/placement-and-smoothing.md,
/// 'The adjusting hexes keep their positions').
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

namespace {

/// What the steps of place_new_nodes share over the rounds of one pass: the pass and its
/// options, the parents whose children are evaluated, the children's scaled Jacobians, the
/// budget of the rounds after the first, and every round's active children (for step 5).
struct PlacementRounds {
  PlacementRounds(const PlacementPass& pass_in, HexMesh& refined_in,
                  const PlacementOptions& options_in, PlacementStats& stats_in)
      : pass(pass_in), refined(refined_in), options(options_in), stats(stats_in) {}

  const PlacementPass& pass;
  HexMesh& refined;
  const PlacementOptions& options;
  PlacementStats& stats;
  /// A later pass: the parents are earlier passes' children (steps 1 and 3).
  bool later = false;
  /// Per use: its parent's scaled Jacobian (1.0 where its children are not evaluated).
  std::vector<double> parent_quality;
  /// The uses whose children are evaluated, ascending.
  std::vector<int32_t> evaluated;
  /// Per hex of `refined`: its scaled Jacobian at the current positions (1.0 for the hexes that
  /// are not evaluated children).
  std::vector<double> quality;
  /// The hexes of the last round's problem: the only ones whose scaled Jacobian changed.
  std::vector<int32_t> changed;
  /// What the rounds after the first may still take, in children.
  int64_t budget = 0;
  /// The worst positive child of the last round.
  double previous_worst = -std::numeric_limits<double>::infinity();
  /// Every round's active children (hexes of `refined`) and their uses, in round order.
  std::vector<int32_t> active, active_use;
};

/// What the steps of one round share (steps 1 to 4 of the file comment).
struct PlacementRound {
  /// The band's top: (1 + active_band) times the pass's worst positive child.
  double top = 0;
  /// This round's active children (hexes of `refined`) and their uses.
  std::vector<int32_t> active, active_use;
  /// Per use: 1 if one of its children is active in this round.
  std::vector<uint8_t> parents;
  /// The problem's hexes (step 2, then step 3 adds earlier passes' hexes); `candidate_use` is
  /// the use of each of step 2's, in the same order.
  std::vector<int32_t> candidates, candidate_use;
  /// Per free node: the template node that made it (step 3).
  std::unordered_map<int32_t, NodeOrigin> origin_of;
  /// Earlier passes' new nodes at the corners of the active children, ascending (step 3).
  std::vector<int32_t> earlier;
  NodeProblem problem;
};

/// Step 0 (see the file comment): the parents the reference positions stretch past the cap go
/// to their exact positions (nothing to do where the start is the exact positions); in a later
/// pass, the boundary new nodes go onto the input's boundary patches.
void new_nodes_move_to_start(const PlacementPass& pass, HexMesh& refined,
                             const PlacementOptions& options, PlacementStats& stats) {
  if (placement_start_positions(options.method) == TemplatePositions::reference)
    stats.exact_parents += parents_past_cap_to_exact(pass, refined, options.max_edge_ratio);
  if (pass.input_nodes < pass.current.point_count()) boundary_nodes_project(pass, refined);
}

/// Step 1, once per pass: the parents whose children are evaluated (all but a parallelepiped
/// refined by a template of boxes, whose children equal it) and their scaled Jacobians, and
/// the budget of the rounds after the first.
void evaluated_parents_choose(PlacementRounds& run) {
  const HexMesh& current = run.pass.current;
  const auto& uses = run.pass.plan.uses;
  const PlacementOptions& options = run.options;
  std::unordered_map<const HexTemplate*, bool> boxes;
  run.parent_quality.assign(uses.size(), 1.0);
  for (size_t u = 0; u < uses.size(); ++u) {
    const HexCorners x = hex_points(current, index_of(uses[u].hex));
    const auto [it, inserted] = boxes.try_emplace(uses[u].tmpl, false);
    if (inserted) it->second = template_is_boxes(*uses[u].tmpl);
    if (it->second && hex_is_parallelepiped(x)) continue;
    run.parent_quality[u] = hex_scaled_jacobian(x);
    run.evaluated.push_back(static_cast<int32_t>(u));
  }
  run.later = run.pass.input_nodes < current.point_count();
  run.quality.assign(run.refined.hexes.size(), 1.0);
  run.budget = static_cast<int64_t>(std::max<double>(
      options.active_floor,
      options.active_share * static_cast<double>(run.refined.hex_count() - current.hex_count())));
}

/// Step 1: the children's scaled Jacobians at the current positions: every evaluated child's
/// in the first round (per chunk of parents: the same values for any thread count), after that
/// the hexes the previous round's problem held (the others did not change).
void children_scaled_jacobians_update(PlacementRounds& run, int round) {
  constexpr int64_t parents_per_chunk = 1024;
  const PlacementPass& pass = run.pass;
  const HexMesh& refined = run.refined;
  const auto& uses = pass.plan.uses;
  const std::vector<int32_t>& evaluated = run.evaluated;
  std::vector<double>& quality = run.quality;
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
    for (int32_t h : run.changed) quality[h] = hex_scaled_jacobian(hex_points(refined, h));
}

/// Step 1 of round `round` (0 first): the children's scaled Jacobians, the band's top, and the
/// round's active children into `r` and `run.active`. False when the rounds end: no child is
/// active, or after the first round the worst child did not rise (or the placement only
/// untangles), or the round does not fit what is left of the budget.
bool active_children_of_round(PlacementRounds& run, int round, PlacementRound& r) {
  const PlacementPass& pass = run.pass;
  const PlacementOptions& options = run.options;
  PlacementStats& stats = run.stats;
  const auto& uses = pass.plan.uses;
  const std::vector<double>& quality = run.quality;
  children_scaled_jacobians_update(run, round);
  double worst_positive = 1;
  for (int32_t u : run.evaluated)
    for (int32_t c = pass.first_child[u];
         c < pass.first_child[u] + static_cast<int32_t>(uses[u].tmpl->children.size()); ++c)
      if (quality[c] > 0) worst_positive = std::min(worst_positive, quality[c]);
  r.top = (1 + options.active_band) * worst_positive;
  r.parents.assign(uses.size(), 0);
  int64_t inverted = 0;
  for (int32_t u : run.evaluated) {
    const int32_t first = pass.first_child[u];
    const int32_t count = static_cast<int32_t>(uses[u].tmpl->children.size());
    const std::vector<double>& unit_cube = uses[u].tmpl->child_reference_quality;
    for (int32_t c = first; c < first + count; ++c) {
      const double q = quality[c];
      const bool poor =
          options.method != PlacementMethod::untangle &&
          (q < r.top || (round == 0 && run.later &&
                         q < options.active_ratio * run.parent_quality[u] * unit_cube[c - first]));
      if (!poor && q > 0) continue;
      r.active.push_back(c);
      r.active_use.push_back(u);
      r.parents[u] = 1;
      inverted += !(q > 0);
      if (round == 0) stats.min_before = std::min(stats.min_before, q);
    }
  }
  if (r.active.empty()) return false;
  // After the first round: only while the worst child rises and the round fits the budget.
  if (round > 0) {
    if (options.method == PlacementMethod::untangle || !(worst_positive > run.previous_worst) ||
        static_cast<int64_t>(r.active.size()) > run.budget)
      return false;
    run.budget -= static_cast<int64_t>(r.active.size());
  } else {
    stats.inverted_before += inverted;
  }
  run.previous_worst = worst_positive;
  stats.active_hexes += static_cast<int64_t>(r.active.size());
  run.active.insert(run.active.end(), r.active.begin(), r.active.end());
  run.active_use.insert(run.active_use.end(), r.active_use.begin(), r.active_use.end());
  return true;
}

/// Step 2: the hexes around the free nodes, into r.candidates (ascending by use) and
/// r.candidate_use: the children of the parents node-adjacent to the active ones (a new node
/// lies on its parent's closure, so every hex holding it is a child of a parent sharing a node
/// with that parent), one ring more per layer of nodes step 3 adds.
void problem_hexes_around_active_parents(const PlacementRounds& run, PlacementRound& r) {
  const PlacementPass& pass = run.pass;
  const HexMesh& current = pass.current;
  const HexTopology& topology = pass.topology;
  const auto& uses = pass.plan.uses;
  std::vector<int32_t> use_of_hex(current.hex_count(), -1);
  for (size_t u = 0; u < uses.size(); ++u)
    use_of_hex[index_of(uses[u].hex)] = static_cast<int32_t>(u);
  std::vector<uint8_t> taken(uses.size(), 0);
  std::vector<int32_t> near_uses, ring;
  for (size_t u = 0; u < uses.size(); ++u)
    if (r.parents[u]) ring.push_back(static_cast<int32_t>(u));
  for (int step = 0; step <= run.options.layers; ++step) {
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
      r.candidates.push_back(c);
      r.candidate_use.push_back(u);
    }
}

/// Step 3: the new nodes of the active children and where each came from, then those of the
/// step 2 hexes touching them, PlacementOptions::layers times (a poor child often needs its
/// neighbours to give way), into r.origin_of.
void free_nodes_of_active_children(const PlacementRounds& run, PlacementRound& r) {
  const PlacementPass& pass = run.pass;
  const HexMesh& refined = run.refined;
  const auto& uses = pass.plan.uses;
  const int32_t old_nodes = pass.current.point_count();
  for (size_t a = 0; a < r.active.size(); ++a) {
    const int32_t u = r.active_use[a];
    const TemplatePlan& plan = uses[u].tmpl->plans[uses[u].symmetry];
    const int32_t child = r.active[a] - pass.first_child[u];
    for (int k = 0; k < 8; ++k) {
      const int32_t node = refined.hexes[r.active[a]][k];
      if (node < old_nodes) continue;
      r.origin_of.try_emplace(node, NodeOrigin{u, plan.children[child][k]});
    }
  }
  for (int layer = 0; layer < run.options.layers; ++layer) {
    std::vector<std::pair<int32_t, NodeOrigin>> added;
    for (size_t k = 0; k < r.candidates.size(); ++k) {
      const HexCell& c = refined.hexes[r.candidates[k]];
      bool touches = false;
      for (int32_t v : c) touches = touches || r.origin_of.count(v);
      if (!touches) continue;
      const int32_t u = r.candidate_use[k];
      const TemplatePlan& plan = uses[u].tmpl->plans[uses[u].symmetry];
      const int32_t child = r.candidates[k] - pass.first_child[u];
      for (int v = 0; v < 8; ++v)
        if (c[v] >= old_nodes && !r.origin_of.count(c[v]))
          added.push_back({c[v], NodeOrigin{u, plan.children[child][v]}});
    }
    for (const auto& [node, o] : added) r.origin_of.try_emplace(node, o);
  }
}

/// Step 3, in a later pass: the earlier passes' new nodes at the corners of the active children
/// into r.earlier (ascending), and the hexes around them that this pass left untouched into
/// r.candidates (which is then sorted and unique; r.candidate_use no longer matches it).
void earlier_nodes_and_their_hexes(const PlacementRounds& run, PlacementRound& r) {
  const PlacementPass& pass = run.pass;
  const auto& uses = pass.plan.uses;
  const int32_t old_nodes = pass.current.point_count();
  if (!(pass.input_nodes < old_nodes)) return;
  for (int32_t c : r.active)
    for (int32_t v : run.refined.hexes[c])
      if (v >= pass.input_nodes && v < old_nodes) r.earlier.push_back(v);
  std::sort(r.earlier.begin(), r.earlier.end());
  r.earlier.erase(std::unique(r.earlier.begin(), r.earlier.end()), r.earlier.end());
  // An untouched hex h of `current` is copied to h plus the children beyond one of the
  // refined hexes before it (plan_apply keeps the input order; uses ascend by hex).
  std::vector<int32_t> use_hexes(uses.size());
  for (size_t u = 0; u < uses.size(); ++u) use_hexes[u] = index_of(uses[u].hex);
  for (int32_t v : r.earlier)
    for (int32_t g : node_hexes(pass.topology, v)) {
      const auto at = std::lower_bound(use_hexes.begin(), use_hexes.end(), g);
      if (at != use_hexes.end() && *at == g) continue;  // refined: its children are there
      const size_t k = static_cast<size_t>(at - use_hexes.begin());
      const int32_t copied = k == 0 ? g
                                    : pass.first_child[k - 1] +
                                          static_cast<int32_t>(uses[k - 1].tmpl->children.size()) +
                                          (g - use_hexes[k - 1] - 1);
      r.candidates.push_back(copied);
    }
  std::sort(r.candidates.begin(), r.candidates.end());
  r.candidates.erase(std::unique(r.candidates.begin(), r.candidates.end()), r.candidates.end());
}

/// Step 3: the problem's nodes and their slides, r.earlier first (their ids are below this
/// pass's), then r.origin_of's nodes ascending; a boundary node at an input patch corner stays
/// and is left out.
void free_nodes_slides(const PlacementRounds& run, PlacementRound& r) {
  const PlacementPass& pass = run.pass;
  const HexMesh& refined = run.refined;
  const HexTopology& topology = pass.topology;
  const auto& uses = pass.plan.uses;
  NodeProblem& problem = r.problem;
  std::vector<int32_t> nodes;
  for (const auto& [node, o] : r.origin_of) nodes.push_back(node);
  std::sort(nodes.begin(), nodes.end());
  ReferenceSlides slides(pass.reference, problem.geometry);
  std::vector<int32_t> around;
  // Earlier passes' nodes on the boundary of `current` slide on the input patches of the input
  // hexes around them.
  for (int32_t node : r.earlier) {
    around.clear();
    bool boundary = false;
    for (int32_t g : node_hexes(topology, node)) {
      around.push_back(pass_original(pass, g));
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
    const NodeOrigin& o = r.origin_of.at(node);
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

/// Step 3: the free nodes of the round (see the file comment) with their slides, and the
/// problem's hexes connected to them (r.problem).
void free_nodes_gather(PlacementRounds& run, PlacementRound& r) {
  free_nodes_of_active_children(run, r);
  earlier_nodes_and_their_hexes(run, r);
  free_nodes_slides(run, r);
  run.stats.free_nodes += static_cast<int64_t>(r.problem.nodes.size());
  node_problem_connect(r.problem, run.refined, r.candidates);
}

/// Step 4: the sweeps over r.problem, and the joint ascent where they leave the worst below the
/// band's top (several nodes hold it there, node_joint_ascent.hpp; where they lifted it past,
/// the band's goal is reached); run.changed becomes the problem's hexes.
void free_nodes_sweep_and_ascend(PlacementRounds& run, PlacementRound& r) {
  const PlacementOptions& options = run.options;
  HexMesh& refined = run.refined;
  PlacementStats& stats = run.stats;
  const NodeProblem& problem = r.problem;
  NodeOptimizerOptions optimizer;
  optimizer.keep_positive = false;
  optimizer.max_sweeps = options.max_sweeps;
  optimizer.smooth_sweeps = options.smooth_sweeps;
  optimizer.threads = run.pass.threads;
  optimizer.max_edge_ratio = options.max_edge_ratio;
  std::vector<Eigen::Vector3d> start_points;
  start_points.reserve(problem.nodes.size());
  for (int32_t v : problem.nodes) start_points.push_back(refined.points[v]);
  JointAscentOptions joint_options;
  joint_options.max_iterations =
      options.method == PlacementMethod::untangle ? 0 : options.joint_iterations;
  joint_options.threads = run.pass.threads;
  joint_options.max_edge_ratio = options.max_edge_ratio;
  const SweepsAndAscentStats sweeps = nodes_sweep_and_ascend(
      refined, problem, optimizer, joint_options,
      options.method == PlacementMethod::untangle ? std::numeric_limits<double>::infinity()
                                                  : r.top);
  stats.sweeps = std::max(stats.sweeps, sweeps.sweeps);
  stats.joint_iterations += sweeps.joint_iterations;
  for (size_t i = 0; i < problem.nodes.size(); ++i)
    stats.nodes_moved += refined.points[problem.nodes[i]] != start_points[i];
  run.changed = problem.hexes;
}

/// Step 5: every round's active children once (ascending), the statistics after placement, and
/// what is left inverted: the parents (ascending) of the valid parents' children still inverted
/// for the driver to refine (empty with allow_inverted); with `refuse`, a PlacementError naming
/// them instead. Adds the time since `start` to the statistics.
std::vector<int32_t> inverted_children_parents(PlacementRounds& run,
                                               std::chrono::steady_clock::time_point start) {
  const PlacementPass& pass = run.pass;
  const HexMesh& refined = run.refined;
  PlacementStats& stats = run.stats;
  const auto& uses = pass.plan.uses;
  std::vector<int32_t>& active = run.active;
  std::vector<int32_t>& active_use = run.active_use;
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
  std::vector<int32_t> failed;
  for (size_t a = 0; a < active.size(); ++a) {
    const double q = hex_scaled_jacobian(hex_points(refined, active[a]));
    stats.min_after = std::min(stats.min_after, q);
    const int32_t u = active_use[a];
    const bool was_inverted = run.parent_quality[u] > 0;  // a valid parent's child
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
    list += (i ? ", " : "") + std::to_string(pass_original(pass, h)) + " (" +
            std::to_string(run.parent_quality[failed[i]]) + ")";
  }
  throw PlacementError(
      "node placement: no placement of the new nodes gives every child a "
      "positive scaled Jacobian in input hexes (scaled Jacobian) " +
      list + (failed.size() > 10 ? ", ..." : "") +
      "; they are too distorted for the templates they need");
}

}  // namespace

std::vector<int32_t> place_new_nodes(const PlacementPass& pass, HexMesh& refined,
                                     const PlacementOptions& options, PlacementStats& stats) {
  if (options.method == PlacementMethod::trilinear) return {};
  const auto start = std::chrono::steady_clock::now();
  new_nodes_move_to_start(pass, refined, options, stats);  // 0
  if (options.method == PlacementMethod::reference) return {};
  PlacementRounds run(pass, refined, options, stats);
  evaluated_parents_choose(run);
  for (int round = 0;; ++round) {
    PlacementRound r;
    if (!active_children_of_round(run, round, r)) break;  // 1
    problem_hexes_around_active_parents(run, r);          // 2
    free_nodes_gather(run, r);                            // 3
    free_nodes_sweep_and_ascend(run, r);                  // 4
  }
  if (run.active.empty()) return {};
  return inverted_children_parents(run, start);  // 5
}

}  // namespace hexrefine
