#pragma once
/// \file
/// Harris-style sheet refinement (Parrish, BYU MS thesis, chapter 2, chapter 4, Appendices C, D,
/// E, G; after Harris' template-based sheet refinement). See sheet.cpp for the steps and the
/// reading of the thesis this implementation makes.

#include <cstdint>
#include <functional>
#include <vector>

#include "algorithms/refiners/refiner.hpp"
#include "mesh/hex_mesh.hpp"
#include "mesh/topology.hpp"

namespace hexrefine {

/// What one direction of one hex needs in a sheet pass, from which of its four parallel edges
/// (the edges of local axis k) are split.
enum class SheetPattern : int8_t {
  none,                ///< no edge split: the hex is not touched in this direction
  one_to_five,         ///< one edge split: directional 1-5
  one_to_four,         ///< two edges on one face split: directional 1-4
  one_to_three,        ///< all four split: directional 1-3
  multiply_connected,  ///< three, or two diagonal: no directional template (Harris had none)
};

/// The pattern of local axis `axis` (0..2) of a hex whose split local edges are the bits of
/// `split_mask` (bit e = local edge e of hex_convention.hpp; bits of other axes are ignored).
SheetPattern hex_axis_pattern(uint16_t split_mask, int axis);

/// Split mask of hex `h`: bit e set when both end nodes of local edge e are marked.
/// `node_marked` has one entry per mesh node.
uint16_t hex_split_mask(const HexMesh& mesh, const std::vector<uint8_t>& node_marked, int32_t h);

/// True if some direction of the hex (split mask as above) is multiply connected.
bool hex_is_multiply_connected(uint16_t split_mask);

/// Harris' marking and target growth on the original mesh.
struct SheetMarking {
  std::vector<uint8_t> node_marked;  ///< per node: 1 if a node of a (grown) target hex
  std::vector<uint8_t> hex_target;   ///< per hex: 1 if a target, given or added
  int64_t added_targets = 0;         ///< hexes added to remove multiply-connected transitions
};

/// Marks the nodes of the targets, then adds every hex that is a multiply-connected transition
/// (hex_is_multiply_connected of its split mask) to the targets, marking its nodes, until none
/// is left. Worklist over the hexes around newly marked nodes: linear in the size of the grown
/// region. Precondition: `targets` valid for `mesh` (ascending, unique, in range), `topology`
/// built from `mesh`.
SheetMarking sheet_mark(const HexMesh& mesh, const HexTopology& topology, const Targets& targets);

/// Called after every sheet round with the whole intermediate mesh (conformal by construction)
/// and the round index; for tests and figures. Assembling the mesh costs a copy per round.
using SheetRoundObserver = std::function<void(const HexMesh& mesh, int round)>;

/// Decides one pass of sheet refinement (RefinePlanFn): per refined hex, the composite template of
/// its rounds (sheet_rounds.cpp). Every refined hex is tagged TemplateTag::sheet. A dual sheet
/// crossing itself in a fully refined hex is handled (both directions in one pass, template 1-9);
/// stats.self_intersection_cases counts the refined hexes a dual sheet crosses itself in. Throws
/// OperationError naming the sheet and hexes for a case it refuses (a sheet crossing itself in a
/// transition hex that it must refine in two directions, or neighbours whose sheets would split
/// their shared face in different passes). The composites' reference positions and
/// configurations are `templates`'.
RefinementPlan sheet_plan(const HexMesh& mesh, const HexTopology& topology,
                          const std::vector<int32_t>& targets, const RefineOptions& options,
                          RefineStats& stats, const TemplateLibrary& templates);

/// refine(refine_method("sheet"), mesh, targets, options).
RefineResult sheet_refine(const HexMesh& mesh, const Targets& targets,
                          const RefineOptions& options);

/// As above, with an observer of the intermediate meshes (the round-by-round formulation).
RefineResult sheet_refine(const HexMesh& mesh, const Targets& targets, const RefineOptions& options,
                          const SheetRoundObserver& observer);

/// How the sheet passes are scheduled and watched (tests, figures, studies).
struct SheetControl {
  SheetRoundObserver observer;  ///< called after every round, if set
  /// Harris' order: one sheet piece per round, in piece order, instead of all the pieces that
  /// share no hex together. Same result; one copy of the refined region per sheet (slower).
  bool one_sheet_per_round = false;
  /// Replay each hex configuration's rounds once on the reference cube and apply the result as
  /// one composite template (the default, sheet_plan; the same mesh up to rounding in transition
  /// hexes, whose later nodes are placed by the input hex's map instead of the intermediate
  /// hex's). false, an observer or one_sheet_per_round: every round is a plan applied to the
  /// whole mesh, building every intermediate mesh and its topology (Harris' formulation, as the
  /// thesis timed it); then no node placement runs (options.placement is ignored).
  bool composites = true;
};

/// As above, with a schedule and an observer.
RefineResult sheet_refine(const HexMesh& mesh, const Targets& targets, const RefineOptions& options,
                          const SheetControl& control);

}  // namespace hexrefine
