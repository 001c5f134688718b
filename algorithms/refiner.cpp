#include "algorithms/refiner.hpp"

#include <array>

namespace hexrefine {

void stats_count_templates(RefineStats& stats, const std::vector<int32_t>& tags) {
  // One counter per tag value first: a string-keyed map lookup per hex would cost more than
  // the refinement itself on large meshes.
  std::array<int64_t, 10> known{};
  for (int32_t t : tags) {
    if (t >= 0 && t < static_cast<int32_t>(known.size()))
      ++known[t];
    else
      ++stats.hexes_per_template[template_tag_name(static_cast<TemplateTag>(t))];
  }
  for (size_t t = 0; t < known.size(); ++t)
    if (known[t])
      stats.hexes_per_template[template_tag_name(static_cast<TemplateTag>(t))] += known[t];
}

const char* template_tag_name(TemplateTag tag) {
  switch (tag) {
    case TemplateTag::untouched:
      return "untouched";
    case TemplateTag::t1_27:
      return "1-27";
    case TemplateTag::t1_13:
      return "1-13";
    case TemplateTag::t1_5:
      return "1-5";
    case TemplateTag::t1_4:
      return "1-4";
    case TemplateTag::t1_3:
      return "1-3";
    case TemplateTag::t1_3_adjust1:
      return "1-3-adj1";
    case TemplateTag::t1_3_adjust2:
      return "1-3-adj2";
    case TemplateTag::directional:
      return "directional";
    case TemplateTag::sheet:
      return "sheet";
  }
  return "unknown";
}

nlohmann::json refine_stats_to_json(const RefineStats& s) {
  nlohmann::json j;
  j["method"] = s.method;
  j["initial_hexes"] = s.initial_hexes;
  j["final_hexes"] = s.final_hexes;
  j["final_nodes"] = s.final_nodes;
  j["hexes_per_template"] = s.hexes_per_template;
  j["hexes_created"] = s.hexes_created;
  j["hexes_deleted"] = s.hexes_deleted;
  j["directional_hexes"] = s.directional_hexes;
  j["directional_groups"] = s.directional_groups;
  j["ranks"] = s.ranks;
  j["doublets_resolved"] = s.doublets_resolved;
  j["edges_split_by_propagation"] = s.edges_split_by_propagation;
  j["sheet_passes"] = s.sheet_passes;
  j["added_targets"] = s.added_targets;
  j["self_intersection_cases"] = s.self_intersection_cases;
  j["phase_seconds"] = s.phase_seconds;
  j["time_seconds"] = s.time_seconds;
  return j;
}

}  // namespace hexrefine
