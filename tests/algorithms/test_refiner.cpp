#include "algorithms/refiner.hpp"

#include <gtest/gtest.h>

#include <set>

namespace hexrefine {
namespace {

TEST(Refiner, TemplateNamesAreDistinct) {
  std::set<std::string> names;
  for (int t = 0; t <= static_cast<int>(TemplateTag::sheet); ++t)
    names.insert(template_tag_name(static_cast<TemplateTag>(t)));
  EXPECT_EQ(names.size(), 10u);
  EXPECT_STREQ(template_tag_name(TemplateTag::t1_3_adjust2), "1-3-adj2");
}

TEST(Refiner, StatsToJsonCarriesEveryField) {
  RefineStats s;
  s.method = "selective";
  s.initial_hexes = 1000;
  s.final_hexes = 8060;
  s.hexes_per_template["1-27"] = 5130;
  const nlohmann::json j = refine_stats_to_json(s);
  EXPECT_EQ(j.at("final_hexes").get<int>(), 8060);
  EXPECT_EQ(j.at("hexes_per_template").at("1-27").get<int>(), 5130);
  EXPECT_EQ(j.at("method").get<std::string>(), "selective");
}

}  // namespace
}  // namespace hexrefine
