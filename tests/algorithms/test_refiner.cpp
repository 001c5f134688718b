#include "algorithms/refiner.hpp"

#include <gtest/gtest.h>

#include <random>
#include <set>

#include "algorithms/selective.hpp"
#include "algorithms/sheet.hpp"
#include "mesh/generators.hpp"
#include "mesh/hex_mesh.hpp"

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

TEST(Refiner, OutputDoesNotDependOnTheThreadCount) {
  // Node ids are claimed in hex order before the positions and children are written in
  // parallel: 1, 2 and 3 threads give bit-identical meshes, for both refiners, on a full
  // refinement, a radial region (transitions, directional hexes) and random targets on a
  // jittered brick.
  BrickParams plain;
  plain.dims = {6, 6, 6};
  BrickParams jittered = plain;
  jittered.jitter = 0.2;
  jittered.seed = 5;
  const HexMesh a = generate_brick(plain), b = generate_brick(jittered);
  std::vector<std::pair<const HexMesh*, Targets>> cases;
  Targets all, radial, random;
  for (int32_t h = 0; h < a.hex_count(); ++h) {
    all.hexes.push_back(h);
    if ((hex_centroid(a, h) - Eigen::Vector3d(1, 0, 1)).norm() < 0.5) radial.hexes.push_back(h);
  }
  std::mt19937 rng(11);
  std::bernoulli_distribution pick(0.1);
  for (int32_t h = 0; h < b.hex_count(); ++h)
    if (pick(rng)) random.hexes.push_back(h);
  cases = {{&a, all}, {&a, radial}, {&b, random}};
  int compared = 0;
  for (const auto& [mesh, targets] : cases) {
    for (auto refine :
         {&selective_refine,
          static_cast<RefineResult (*)(const HexMesh&, const Targets&, const RefineOptions&)>(
              &sheet_refine)}) {
      RefineOptions one;
      const RefineResult serial = refine(*mesh, targets, one);
      for (int threads : {2, 3}) {
        RefineOptions many;
        many.threads = threads;
        const RefineResult parallel = refine(*mesh, targets, many);
        ASSERT_EQ(serial.mesh.hexes, parallel.mesh.hexes);
        ASSERT_EQ(serial.mesh.points.size(), parallel.mesh.points.size());
        for (size_t i = 0; i < serial.mesh.points.size(); ++i)
          ASSERT_EQ(serial.mesh.points[i], parallel.mesh.points[i]) << "node " << i;
        ASSERT_EQ(serial.mesh.attributes.size(), parallel.mesh.attributes.size());
        for (size_t k = 0; k < serial.mesh.attributes.size(); ++k)
          ASSERT_EQ(serial.mesh.attributes[k].values, parallel.mesh.attributes[k].values);
        ++compared;
      }
    }
  }
  EXPECT_EQ(compared, 3 * 2 * 2);
}

}  // namespace
}  // namespace hexrefine
