#include "algorithms/refiners/refiner.hpp"

#include <gtest/gtest.h>

#include <random>
#include <set>

#include "algorithms/refiners/selective.hpp"
#include "algorithms/refiners/sheet.hpp"
#include "mesh/error.hpp"
#include "mesh/generators.hpp"
#include "mesh/hex_mesh.hpp"

namespace hexrefine {
namespace {

TEST(Refiner, MethodsAreRegisteredOnceByName) {
  ASSERT_EQ(refine_methods().size(), 2u);
  EXPECT_EQ(refine_method("selective").name, "selective");
  EXPECT_EQ(refine_method("sheet").plan, &sheet_plan);
  EXPECT_TRUE(refine_method("selective").uses_buffer);
  EXPECT_FALSE(refine_method("sheet").uses_buffer);
  try {
    refine_method("selectiv");
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("selective, sheet"), std::string::npos) << e.what();
  }
}

TEST(Refiner, StatsAndOptionsRoundTripThroughJson) {
  RefineStats s;
  s.method = "selective";
  s.initial_hexes = 1000;
  s.final_hexes = 8060;
  s.hexes_per_template["1-27"] = 5130;
  s.doublets_by_rule["edge_of_three_faces"] = 2;
  s.placement.untangled = 3;
  const nlohmann::json j = s;
  EXPECT_EQ(j.at("final_hexes").get<int>(), 8060);
  EXPECT_EQ(j.at("hexes_per_template").at("1-27").get<int>(), 5130);
  EXPECT_EQ(j.at("placement").at("untangled").get<int>(), 3);
  EXPECT_EQ(j.at("method").get<std::string>(), "selective");
  EXPECT_EQ(j.get<RefineStats>().doublets_by_rule.at("edge_of_three_faces"), 2);
  RefineOptions o;
  o.passes = 3;
  o.placement.method = PlacementMethod::trilinear;
  const nlohmann::json oj = o;
  EXPECT_EQ(oj.at("placement").at("method"), "trilinear");
  const RefineOptions back = oj.get<RefineOptions>();
  EXPECT_EQ(back.passes, 3);
  EXPECT_EQ(back.placement.method, PlacementMethod::trilinear);
  // Missing keys keep their defaults.
  EXPECT_TRUE(nlohmann::json::object().get<RefineOptions>().ranking);
}

TEST(Refiner, RefusesBadTargetsOptionsAndInvertedInputNamingTheHexes) {
  const HexMesh m = generate_brick({{2, 2, 2}});
  const RefineMethod& method = refine_method("selective");
  EXPECT_THROW(refine(method, m, {{3, 1}}, {}), InputError);  // not ascending
  EXPECT_THROW(refine(method, m, {{1, 1}}, {}), InputError);  // repeated
  EXPECT_THROW(refine(method, m, {{8}}, {}), InputError);     // out of range
  RefineOptions zero;
  zero.passes = 0;
  EXPECT_THROW(refine(method, m, {{0}}, zero), InputError);
  HexMesh inverted = m;
  std::swap(inverted.points[13], inverted.points[26]);  // the centre node onto a corner's place
  try {
    refine(refine_method("sheet"), inverted, {{0}}, {});
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("scaled Jacobian <= 0"), std::string::npos) << what;
    EXPECT_NE(what.find("7 ("), std::string::npos) << what;  // hex 7 and its value
  }
  RefineOptions allow;
  allow.allow_inverted = true;
  allow.placement.method = PlacementMethod::trilinear;
  EXPECT_NO_THROW(refine(method, inverted, {{0}}, allow));
}

TEST(Refiner, ParentHexNamesTheInputHexAcrossPasses) {
  // Two passes on one corner hex of a 2x2x2 brick: every output hex names the input hex it
  // lies in, and an input parent_hex attribute (a refined mesh refined again) is replaced.
  HexMesh m = generate_brick({{2, 2, 2}});
  m.attributes.push_back({std::string(attribute_parent_hex), std::vector<int32_t>(8, 42)});
  RefineOptions o;
  o.passes = 2;
  // Trilinear positions keep every child inside its input hex exactly (optimized placement may
  // move nodes on the faces between input hexes, which the buffer layer now refines).
  o.placement.method = PlacementMethod::trilinear;
  const RefineResult r = selective_refine(m, {{0}}, o);
  const auto& parent = *mesh_find_attribute(r.mesh, attribute_parent_hex);
  std::vector<int64_t> per_parent(8, 0);
  for (int32_t h = 0; h < r.mesh.hex_count(); ++h) {
    ASSERT_GE(parent[h], 0);
    ASSERT_LT(parent[h], 8);
    ++per_parent[parent[h]];
    const Eigen::Vector3d c = hex_centroid(r.mesh, h);
    const Eigen::Vector3d lo = hex_points(m, parent[h])[0];
    for (int k = 0; k < 3; ++k) {
      EXPECT_GE(c[k], lo[k]);
      EXPECT_LE(c[k], lo[k] + 0.5);
    }
  }
  EXPECT_EQ(per_parent[0], 27 * 27);
  int64_t total = 0;
  for (int64_t n : per_parent) total += n;
  EXPECT_EQ(total, r.mesh.hex_count());
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
