#pragma once
/// \file
/// Joint ascent of the free nodes of a local problem (node_optimizer.hpp): every free node moves
/// at once along a quasi-Newton direction of a smooth lower bound of the worst scaled Jacobian.
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
  /// The variables are the free nodes of the problem's hexes whose scaled Jacobian is within
  /// `band` (>= 0; 2: every free node) of the worst one with a free corner, and of `rings` rings
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
};

struct JointAscentStats {
  int iterations = 0;
  int64_t free_nodes = 0;  ///< problem nodes with SlideKind::free
  int64_t hexes = 0;       ///< problem hexes with a free corner: the objective's hexes
  /// Minimum scaled Jacobian over those hexes before and after (1 if none).
  double min_before = 1, min_after = 1;
};

/// Moves the free nodes (SlideKind::free) of `problem` in `mesh` together, to raise the minimum
/// scaled Jacobian of the problem's hexes that have a free corner; sliding and fixed nodes stay.
/// Keeps the iterate with the highest true minimum, so the minimum never decreases and, when it
/// is positive at the start, no hex inverts; does nothing when it is not positive (untangling is
/// the node-by-node optimizer's). Deterministic, the same for any options.threads.
/// Preconditions: `problem` was connected (node_problem_connect) on `mesh`.
JointAscentStats nodes_ascend_jointly(HexMesh& mesh, const NodeProblem& problem,
                                      const JointAscentOptions& options);

struct SweepsAndAscentStats {
  int sweeps = 0;            ///< of both rounds
  int joint_iterations = 0;  ///< of the joint ascent (0 if it did not run)
};

/// What node placement and smoothing both do: nodes_optimize with `sweeps`; then, unless
/// sweeps.max_sweeps or joint.max_iterations is 0 or the sweeps left the minimum over the
/// problem's hexes at or above `ascend_below`, nodes_ascend_jointly; and if that raised the
/// minimum, nodes_optimize again, its first sweep visiting only the nodes the ascent moved and
/// those sharing a hex with them (the others are where the first round left them). The joint
/// ascent leaves the sliding nodes where they were and its worst hexes balanced: node by node,
/// the sweeps can raise the minimum again from there. (`ascend_below`: node placement's band,
/// whose goal the sweeps may reach alone.)
SweepsAndAscentStats nodes_sweep_and_ascend(
    HexMesh& mesh, const NodeProblem& problem, NodeOptimizerOptions sweeps,
    const JointAscentOptions& joint, double ascend_below = std::numeric_limits<double>::infinity());

}  // namespace hexrefine
