#pragma once
/// \file
/// One pass of the Selective Approach, shared by selective.cpp (marking, doublets, element by
/// element, the plan) and selective_directional.cpp (ranking, directional refinement,
/// propagation). Internal to the algorithms library; see selective.cpp for the steps.

#include <cstdint>
#include <string>
#include <unordered_set>
#include <vector>

#include "algorithms/refiners/refiner.hpp"
#include "algorithms/refiners/selective_cells.hpp"
#include "mesh/topology.hpp"

namespace hexrefine::selective_detail {

enum Role : uint8_t { kUntouched = 0, kTarget = 1, kElement = 2, kDirectional = 3 };

/// Why an edge was split to avoid a doublet (Appendix F and the rules this implementation adds);
/// counted per rule in RefineStats::doublets_by_rule under doublet_rule_name.
enum class DoubletRule : uint8_t {
  three_faces,      ///< the thesis' rule: an adjustment at an edge shared by fewer than 4 faces
  boundary_face,    ///< an adjustment whose merged face would be a boundary face
  two_adjustments,  ///< two hexes adjusting at one edge
  directional_neighbour,  ///< a directional neighbour across a merged face
  cell_three_faces,       ///< inside a hex: a directional adjustment at a cell edge of < 4 faces
  cell_one_face_twice,    ///< inside a hex: two directional adjustments collapsing one face
  input_edge_retry,       ///< an input edge split by a restarted pass (the cases above at a cell)
};
const char* doublet_rule_name(DoubletRule rule);

/// Thrown when directional refinement meets adjustments it can only avoid by splitting input
/// edges (Appendix F): the pass starts again with those edges split from the outset. The pass
/// skips such cells and goes on to collect every such edge it meets before throwing (two
/// adjustments collapsing one face stop it at once), so a mesh that needs many costs a few
/// restarts rather than one per edge. The edges a skipped cell's neighbours then name may be
/// more than one-at-a-time restarts would split: a few more hexes, never an invalid mesh (the
/// last pass runs clean).
struct InputEdgeSplitNeeded {
  std::vector<int32_t> edges;
};

/// A segment between two keyed nodes (ordered), for the split state of edges made by
/// directional steps.
struct SegmentKey {
  NodeKey a, b;
  bool operator==(const SegmentKey& o) const = default;
};
struct SegmentKeyHash {
  size_t operator()(const SegmentKey& k) const {
    NodeKeyHash h;
    return h(k.a) * 31 + h(k.b);
  }
};
inline SegmentKey segment_key(const NodeKey& a, const NodeKey& b) {
  return node_key_less(a, b) ? SegmentKey{a, b} : SegmentKey{b, a};
}

class SelectivePass {
 public:
  /// `forced_splits`: input edges split from the outset (found by earlier attempts); every
  /// template from `templates`.
  SelectivePass(const HexMesh& mesh, const HexTopology& topology,
                const std::vector<int32_t>& targets, const RefineOptions& options,
                RefineStats& stats, const std::vector<int32_t>& forced_splits,
                const TemplateLibrary& templates)
      : mesh_(mesh),
        topo_(topology),
        targets_(targets),
        options_(options),
        stats_(stats),
        forced_splits_(forced_splits),
        templates_(templates),
        cells_refiner_(mesh, topology) {}

  /// Decides the pass (Parrish, Table 5-1) and returns its plan.
  RefinementPlan run();

 private:
  struct Decision {
    int32_t di;
    int32_t cell;
    TemplateChoice choice;
    std::array<bool, 12> split;
  };
  struct AliasPair {
    NodeKey from, to;
    int8_t edge;  // local edge of the cell at which the adjustment sits
  };

  // selective.cpp
  void mark();
  void resolve_doublets();
  void choose();
  void count_doublet(DoubletRule rule);
  /// A hex with split mask `mask` is refined directionally: no template matches.
  bool is_directional(uint16_t mask) const;
  void adjustment_aliases(const TemplateCell& cell, const TemplateChoice& c,
                          std::vector<AliasPair>& out) const;
  void register_adjustments(const TemplateCell& cell, const TemplateChoice& c);
  RefinementPlan assemble();

  /// The (directional index, input axis) pairs of one rank, in the order the ranking met them.
  using Rank = std::vector<std::pair<int32_t, int8_t>>;

  // selective_directional.cpp
  /// The thesis' ranking system: each directional hex's cells start whole; the
  /// rounds of (hex, direction) pairs in processing order, by rank (or, without ranking, local
  /// x, y, z), hex after hex or rank after rank (RefineOptions::directional_order).
  void rank();
  /// Per directional index: its group (face-connected directional hexes), counted in stats.
  std::vector<int32_t> directional_groups();
  /// The rounds of the ablation without ranking: local x, y, z in turn, hex after hex
  /// (`by_hex`) or each local direction for every hex.
  void rounds_without_ranking(bool by_hex);
  /// The ranks: seeds by decreasing split count, then group, hex, direction, each grown through
  /// opposite edges of adjacent faces; rank_of[3 * di + d] the rank of pair (di, d).
  std::vector<Rank> ranks_build(const std::vector<int32_t>& group, std::vector<int32_t>& rank_of);
  /// The thesis' loop: each hex's directions by increasing rank, one step each, hex after hex.
  void rounds_by_hex(const std::vector<int32_t>& rank_of);
  /// Rank after rank; a hex met twice by one rank (a self-intersecting sheet) refines those
  /// directions in successive rounds.
  void rounds_by_rank(const std::vector<Rank>& members);
  void refine_directional();
  bool cell_edge_split(const TemplateCell& c, int le) const;
  /// The input edge that local edge `le` of cell `c` lies on, or -1.
  int32_t cell_edge_input_edge(const TemplateCell& c, int le) const;
  /// Chooses the templates of hex di's cells in direction `axis`; returns true if it split an
  /// edge to avoid a doublet (the round must choose again).
  bool decide(int32_t di, int axis, std::vector<Decision>& out);
  void apply(const Decision& d, std::vector<TemplateCell>& next);

  const HexMesh& mesh_;
  const HexTopology& topo_;
  const std::vector<int32_t>& targets_;
  const RefineOptions& options_;
  RefineStats& stats_;
  const std::vector<int32_t>& forced_splits_;
  const TemplateLibrary& templates_;
  CellRefiner cells_refiner_;
  std::vector<uint8_t> split_;  // per input edge
  std::vector<uint8_t> role_;   // per input hex
  std::vector<TemplateChoice> element_choice_;
  std::vector<int32_t> touched_;      // non-target hexes with split edges
  std::vector<int32_t> directional_;  // input hex of each directional index
  std::vector<int32_t> directional_index_;
  std::vector<std::vector<TemplateCell>> cells_;  // per directional hex: its current cells
  // Rounds of (directional index, input axis), in processing order.
  std::vector<std::vector<std::pair<int32_t, int8_t>>> rounds_;
  std::unordered_set<SegmentKey, SegmentKeyHash> split_segments_;
  std::vector<int32_t> needed_input_edges_;  // of the current round (InputEdgeSplitNeeded)
};

/// Split mask of hex h (bit e: local edge e split).
inline uint16_t hex_split_mask(const HexTopology& topo, const std::vector<uint8_t>& split,
                               int32_t h) {
  uint16_t m = 0;
  for (int e = 0; e < 12; ++e)
    if (split[topo.hex_edge_ids[h][e]]) m |= static_cast<uint16_t>(1u << e);
  return m;
}

}  // namespace hexrefine::selective_detail
