#pragma once
/// \file
/// The interface both refiners share (the Selective Approach and Harris-style sheet refinement):
/// the same targets, options, result and statistics, so experiments compare like with like.

#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "mesh/hex_mesh.hpp"

namespace hexrefine {

/// Template tag written per output hex (attribute "template_tag"). Untouched hexes keep 0.
enum class TemplateTag : int32_t {
  untouched = 0,
  t1_27 = 1,
  t1_13 = 2,
  t1_5 = 3,
  t1_4 = 4,
  t1_3 = 5,
  t1_3_adjust1 = 6,
  t1_3_adjust2 = 7,
  directional = 8,  ///< produced by directional refinement (several templates in sequence)
  sheet = 9,        ///< produced by sheet refinement passes
};

/// Short name used in reports ("1-27", "1-3-adj1", ...).
const char* template_tag_name(TemplateTag tag);

struct RefineStats;
/// Fills stats.hexes_per_template from a list of per-hex template tags (values outside the
/// enumeration are counted under template_tag_name's name for them).
void stats_count_templates(RefineStats& stats, const std::vector<int32_t>& tags);

/// The hexes selected for refinement: ascending, unique ids into the input mesh.
struct Targets {
  std::vector<int32_t> hexes;
};

struct RefineOptions {
  bool ranking = true;      ///< Selective: rank directions across directional groups.
  bool propagation = true;  ///< Selective: propagation scheme after each directional step.
  bool ebe_only = false;    ///< Selective: element-by-element only (as Schneiders).
  int passes = 1;           ///< Refine the region this many times.
  bool buffer = false;      ///< Add the previous pass's transition layer to the next targets.
  bool allow_inverted = false;
  /// Threads for applying whole-hex templates (the assembly of the output). The output is
  /// identical for every count: node ids are claimed in hex order first, then the positions
  /// and children are written in parallel. 1: everything in the calling thread.
  int threads = 1;
};

/// Statistics of one refinement. Fields a method does not use stay zero.
struct RefineStats {
  std::string method;
  int64_t initial_hexes = 0;
  int64_t final_hexes = 0;
  int64_t final_nodes = 0;
  std::map<std::string, int64_t> hexes_per_template;  ///< output hexes by template name
  int64_t hexes_created = 0;
  int64_t hexes_deleted = 0;
  int64_t directional_hexes = 0;
  int64_t directional_groups = 0;
  int64_t ranks = 0;
  int64_t doublets_resolved = 0;
  int64_t edges_split_by_propagation = 0;
  int64_t sheet_passes = 0;
  int64_t added_targets = 0;
  int64_t self_intersection_cases = 0;
  std::map<std::string, double> phase_seconds;  ///< marking, element_by_element, ranking, ...
  double time_seconds = 0;                      ///< refinement only, no I/O
};

nlohmann::json refine_stats_to_json(const RefineStats& s);

/// Output of a refiner: the new mesh (with attribute "template_tag" and "refinement_level"),
/// and its statistics.
struct RefineResult {
  HexMesh mesh;
  RefineStats stats;
};

}  // namespace hexrefine
