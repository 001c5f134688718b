#pragma once
/// \file
/// Joint ascent of the free nodes of a local problem (node_optimizer.hpp), and optionally of its
/// sliding nodes on their slides: every variable moves at once along a quasi-Newton direction of
/// a smooth lower bound of the worst scaled Jacobian.
/// What one node at a time cannot do: where the worst hex's corners are held at the same value
/// by several nodes (a transition child in a flat or long parent, a layer that must thicken as a
/// whole), no single move raises the minimum, and node-by-node max-min sweeps stop there. See
/// node_joint_ascent.cpp.

#include <cstdint>
#include <limits>

#include "algorithms/placement/node_optimizer.hpp"
#include "mesh/hex_mesh.hpp"

namespace hexrefine {

struct JointAscentOptions {
  /// KS sharpness (> 0): the soft minimum weighs a scaled-Jacobian sample by exp(-beta (s -
  /// min)); 60 lets samples within about 0.05 of the minimum share the ascent.
  double beta = 60;
  int max_iterations = 100;  ///< >= 0: quasi-Newton iterations (one gradient each)
  int memory = 8;            ///< L-BFGS correction pairs (>= 1)
  /// >= 1: stop after this many iterations without the minimum rising by 1e-5.
  int stall_iterations = 30;
  /// The variables are the free (and with `slide` the sliding) nodes of the problem's hexes
  /// whose scaled Jacobian is within `band` (>= 0; 2: every such node) of the worst one with a
  /// moving corner, and of `rings` rings
  /// of hexes around them: where the KS weights are not negligible, and room for a layer of
  /// hexes to move as a whole.
  double band = 0.25;
  int rings = 3;  ///< >= 0
  /// >= 1: at most this many hexes of the band seed the variables, the worst ones: after the
  /// sweeps many hexes may sit just above the minimum (those the sweeps stopped visiting at
  /// SmoothOptions::visit_below), and the ascent is for the worst few clusters, not for all.
  int64_t max_seeds = 64;
  /// No iterate may give an objective hex an edge ratio above hex_edge_ratio_cap(its start,
  /// max_edge_ratio) (node_optimizer.hpp; <= 0: no cap): such an iterate is infeasible.
  double max_edge_ratio = 20;
  int threads = 1;  ///< >= 1: threads for the hex evaluations (same result for any)
  /// The sliding nodes (SlideKind patch, segment and their unions) of the chosen hexes are
  /// variables too: their gradient is projected onto the tangent of their slide and every
  /// iterate puts them back onto it (slide_project), so they stay on the boundary surface by
  /// construction. false: they keep their place (node placement, whose sliding nodes are few and
  /// whose sweeps slide them). Smoothing sets it: the worst children left by the sweeps mostly
  /// sit next to the boundary (docs/placement-and-smoothing.md, 'Smoothing's joint ascent'), and
  /// their parent's boundary corners must move with the interior nodes for the minimum to rise.
  bool slide = false;
  /// A hex whose edge ratio nears its cap (within the last twentieth) adds a sample to the soft
  /// minimum that falls to 0 at the cap (node_joint_ascent.cpp), so the ascent is steered along
  /// the cap. false: the cap is only a wall, and a hex the sweeps left at its cap stops the
  /// ascent at its first step (docs/placement-and-smoothing.md, 'Smoothing'). Smoothing sets it;
  /// node placement and the template table's optimizer (`hexrefine templates --optimize`) keep
  /// the wall, so that the committed table and the placement figures (results/placement.md)
  /// stay reproducible.
  bool cap_samples = false;
  /// >= 1: rounds of nodes_sweep_and_ascend (ascent, then sweeps from the nodes it moved), each
  /// with beta `round_beta_growth` (>= 1) times the last, while a round raises the minimum over
  /// the problem's hexes by more than `round_gain`. One ascent stalls where many hexes sit near
  /// the minimum: the sweeps move its worst hexes, and a sharper restart goes on from there
  /// (docs/placement-and-smoothing.md, 'Smoothing').
  int rounds = 1;
  double round_beta_growth = 2;  ///< >= 1: beta of a round over the last one's
  double round_gain = 1e-4;      ///< >= 0: a round raising the minimum by no more ends them
};

struct JointAscentStats {
  int iterations = 0;
  int64_t free_nodes = 0;     ///< variables with SlideKind::free
  int64_t sliding_nodes = 0;  ///< variables on a slide (JointAscentOptions::slide)
  int64_t hexes = 0;          ///< problem hexes with a variable corner: the objective's hexes
  /// Minimum scaled Jacobian over those hexes before and after (1 if none).
  double min_before = 1, min_after = 1;
};

/// Moves the free nodes (SlideKind::free) of `problem` in `mesh` together, and with
/// options.slide its sliding nodes on their slides, to raise the minimum scaled Jacobian of the
/// problem's hexes that have a moving corner; the other nodes stay.
/// Keeps the iterate with the highest true minimum, so the minimum never decreases and, when it
/// is positive at the start, no hex inverts; does nothing when it is not positive (untangling is
/// the node-by-node optimizer's). Deterministic, the same for any options.threads.
/// Preconditions: `problem` was connected (node_problem_connect) on `mesh`.
JointAscentStats nodes_ascend_jointly(HexMesh& mesh, const NodeProblem& problem,
                                      const JointAscentOptions& options);

struct SweepsAndAscentStats {
  int sweeps = 0;            ///< of the first sweeps and of every round
  int joint_iterations = 0;  ///< of the joint ascent, every round (0 if it did not run)
  int joint_rounds = 0;      ///< rounds whose ascent raised the minimum
};

/// What node placement and smoothing both do: nodes_optimize with `sweeps`; then, unless
/// sweeps.max_sweeps or joint.max_iterations is 0 or the sweeps left the minimum over the
/// problem's hexes at or above `ascend_below`, up to joint.rounds rounds of nodes_ascend_jointly
/// and, if that raised the minimum, nodes_optimize again, its first sweep visiting only the nodes
/// the ascent moved and those sharing a hex with them (the others are where the previous sweeps
/// left them); the rounds stop once one raises the minimum by no more than joint.round_gain or
/// reaches `ascend_below`. The joint ascent leaves its worst hexes balanced (and, without
/// joint.slide, the sliding nodes where they were): node by node, the sweeps can raise the
/// minimum again from there. (`ascend_below`: node placement's band, whose goal the sweeps may
/// reach alone.)
SweepsAndAscentStats nodes_sweep_and_ascend(
    HexMesh& mesh, const NodeProblem& problem, NodeOptimizerOptions sweeps,
    const JointAscentOptions& joint, double ascend_below = std::numeric_limits<double>::infinity());

}  // namespace hexrefine
