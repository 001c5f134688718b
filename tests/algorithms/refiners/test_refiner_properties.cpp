/// \file
/// Property tests of both refiners (algorithms/refiners/selective.hpp,
/// algorithms/refiners/sheet.hpp) over random meshes and random target sets. Each case draws, from
/// std::mt19937_64(case index):
/// - a mesh: a jittered brick (1-4 hexes per axis, jitter 0-0.3), an O-grid cylinder (square
///   1-3, radial 1-2, 1-2 layers) or a twisted ring (8-10 layers, section 1-2 intervals);
/// - a target set: one hex, every hex, a random subset (each hex with probability 0.1-0.6) or
///   the hexes whose centroid lies in a random ball;
/// - the refiner: even cases selective, odd cases sheet.
/// Properties: the refiner either returns a mesh that mesh_check(out, &input) finds conformal,
/// with 0 inverted hexes and 0 doublets, or throws OperationError whose message names a hex;
/// the input is never modified; the same input gives a byte-identical output (points compared
/// exactly, hexes equal); refining every hex gives 27x the hexes.
///
/// CI runs 1,000 cases (500 per refiner). HEXREFINE_PROPERTY_CASES=N runs N cases (e.g. 50000
/// for the long run reported in results/robustness.md). A failure prints the case index and
/// description, so `HEXREFINE_PROPERTY_FIRST_CASE=i HEXREFINE_PROPERTY_CASES=1` replays it.

#include <gtest/gtest.h>

#include <cstdlib>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "algorithms/refiners/selective.hpp"
#include "algorithms/refiners/sheet.hpp"
#include "mesh/conformity.hpp"
#include "mesh/error.hpp"
#include "mesh/generators.hpp"

namespace hexrefine {
namespace {

int64_t env_int(const char* name, int64_t fallback) {
  const char* v = std::getenv(name);
  if (v == nullptr || *v == 0) return fallback;
  return std::strtoll(v, nullptr, 10);
}

struct PropertyCase {
  HexMesh mesh;
  Targets targets;
  bool sheet = false;
  bool all_hexes = false;
  std::string description;
};

/// Uniform integer in [lo, hi] from raw draws (platform-independent, unlike the std
/// distributions).
int draw_int(std::mt19937_64& rng, int lo, int hi) {
  return lo + static_cast<int>(rng() % static_cast<uint64_t>(hi - lo + 1));
}
double draw_unit(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

PropertyCase property_case(int64_t index) {
  std::mt19937_64 rng(static_cast<uint64_t>(index) * 0x9E3779B97F4A7C15ull + 7);
  PropertyCase c;
  std::ostringstream d;
  d << "case " << index << ": ";
  switch (draw_int(rng, 0, 2)) {
    case 0: {
      BrickParams p;
      p.dims = {draw_int(rng, 1, 4), draw_int(rng, 1, 4), draw_int(rng, 1, 4)};
      p.jitter = 0.3 * draw_unit(rng);
      p.seed = rng();
      c.mesh = generate_brick(p);
      d << "brick " << p.dims[0] << "x" << p.dims[1] << "x" << p.dims[2] << " jitter " << p.jitter
        << " seed " << p.seed;
      break;
    }
    case 1: {
      CylinderParams p;
      p.square_intervals = draw_int(rng, 1, 3);
      p.radial_intervals = draw_int(rng, 1, 2);
      p.layers = draw_int(rng, 1, 2);
      c.mesh = generate_cylinder(p);
      d << "cylinder " << p.square_intervals << "," << p.radial_intervals << " layers " << p.layers;
      break;
    }
    default: {
      TwistedRingParams p;
      p.around = draw_int(rng, 8, 10);
      p.section_intervals = draw_int(rng, 1, 2);
      c.mesh = generate_twisted_ring(p);
      d << "twisted ring around " << p.around << " section " << p.section_intervals;
      break;
    }
  }
  const int32_t n = c.mesh.hex_count();
  switch (draw_int(rng, 0, 3)) {
    case 0:
      c.targets.hexes = {static_cast<int32_t>(rng() % static_cast<uint64_t>(n))};
      d << ", one hex";
      break;
    case 1:
      for (int32_t h = 0; h < n; ++h) c.targets.hexes.push_back(h);
      c.all_hexes = true;
      d << ", all hexes";
      break;
    case 2: {
      const double p = 0.1 + 0.5 * draw_unit(rng);
      for (int32_t h = 0; h < n; ++h)
        if (draw_unit(rng) < p) c.targets.hexes.push_back(h);
      d << ", random subset p " << p;
      break;
    }
    default: {
      const Eigen::Vector3d centre = hex_centroid(c.mesh, static_cast<int32_t>(rng() % n));
      const auto [lo, hi] = mesh_bounding_box(c.mesh);
      const double r = (0.1 + 0.4 * draw_unit(rng)) * (hi - lo).norm();
      for (int32_t h = 0; h < n; ++h)
        if ((hex_centroid(c.mesh, h) - centre).norm() <= r) c.targets.hexes.push_back(h);
      d << ", ball radius " << r;
      break;
    }
  }
  if (c.targets.hexes.empty()) c.targets.hexes = {0};
  c.sheet = index % 2 == 1;
  d << ", " << c.targets.hexes.size() << " of " << n << " hexes, "
    << (c.sheet ? "sheet" : "selective");
  c.description = d.str();
  return c;
}

RefineResult property_refine(const PropertyCase& c) {
  const RefineOptions options;
  return c.sheet ? sheet_refine(c.mesh, c.targets, options)
                 : selective_refine(c.mesh, c.targets, options);
}

bool mesh_same_exactly(const HexMesh& a, const HexMesh& b) {
  if (a.points.size() != b.points.size() || a.hexes != b.hexes) return false;
  for (size_t i = 0; i < a.points.size(); ++i)
    for (int k = 0; k < 3; ++k)
      if (a.points[i][k] != b.points[i][k]) return false;
  if (a.attributes.size() != b.attributes.size()) return false;
  for (size_t i = 0; i < a.attributes.size(); ++i)
    if (a.attributes[i].name != b.attributes[i].name ||
        a.attributes[i].values != b.attributes[i].values)
      return false;
  return true;
}

struct PropertyTally {
  int64_t cases = 0, refined = 0, refused = 0, all_hexes = 0;
  int64_t refused_per_refiner[2] = {0, 0};
  std::vector<std::string> refused_examples;  ///< the first few refused cases
};

/// Runs cases [first, first + count); every violated property is a test failure naming the case.
PropertyTally property_run(int64_t first, int64_t count) {
  PropertyTally t;
  for (int64_t i = first; i < first + count; ++i) {
    const PropertyCase c = property_case(i);
    SCOPED_TRACE(c.description);
    const HexMesh before = c.mesh;
    ++t.cases;
    RefineResult r1;
    try {
      r1 = property_refine(c);
    } catch (const OperationError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("hex"), std::string::npos) << "refusal must name the hexes: " << msg;
      EXPECT_TRUE(mesh_same_exactly(before, c.mesh)) << "input modified by a refusal";
      ++t.refused, ++t.refused_per_refiner[c.sheet];
      if (t.refused_examples.size() < 5)
        t.refused_examples.push_back(c.description + ": " + msg.substr(0, 120));
      continue;
    } catch (const std::exception& e) {
      ADD_FAILURE() << "not an OperationError: " << e.what();
      continue;
    }
    ++t.refined;
    EXPECT_TRUE(mesh_same_exactly(before, c.mesh)) << "input modified";
    const MeshCheckReport report = mesh_check(r1.mesh, &c.mesh);
    EXPECT_TRUE(report.conformal) << report.non_conformal_faces << " non-conformal faces, "
                                  << report.hanging_nodes << " hanging nodes";
    EXPECT_EQ(report.inverted_hexes, 0) << "first at " << report.first_inverted_hex;
    EXPECT_EQ(report.doublets, 0);
    EXPECT_EQ(report.nonmanifold_faces, 0);
    if (c.all_hexes) {
      ++t.all_hexes;
      EXPECT_EQ(r1.mesh.hex_count(), 27 * c.mesh.hex_count());
    }
    const RefineResult r2 = property_refine(c);
    EXPECT_TRUE(mesh_same_exactly(r1.mesh, r2.mesh)) << "same input, different output";
    if (::testing::Test::HasFailure()) {
      ADD_FAILURE() << "stopping at the first failing case";
      break;
    }
  }
  return t;
}

TEST(RefinerProperties, RandomMeshesAndTargetsGiveValidOutputOrANamedRefusal) {
  const int64_t first = env_int("HEXREFINE_PROPERTY_FIRST_CASE", 0);
  const int64_t count = env_int("HEXREFINE_PROPERTY_CASES", 1000);
  const PropertyTally t = property_run(first, count);
  std::printf(
      "refiner properties: %lld cases from %lld: %lld refined, %lld refused (selective %lld, "
      "sheet %lld), %lld all-hex cases\n",
      static_cast<long long>(t.cases), static_cast<long long>(first),
      static_cast<long long>(t.refined), static_cast<long long>(t.refused),
      static_cast<long long>(t.refused_per_refiner[0]),
      static_cast<long long>(t.refused_per_refiner[1]), static_cast<long long>(t.all_hexes));
  for (const std::string& e : t.refused_examples) std::printf("  refused: %s\n", e.c_str());
  EXPECT_EQ(t.cases, count);
  // Most cases must refine: a refiner that refused everything would pass the other checks.
  EXPECT_GE(t.refined, t.cases * 3 / 4);
  EXPECT_GT(t.all_hexes, 0);
}

TEST(RefinerProperties, CasesAreReproducible) {
  const PropertyCase a = property_case(12345), b = property_case(12345);
  EXPECT_EQ(a.description, b.description);
  EXPECT_TRUE(mesh_same_exactly(a.mesh, b.mesh));
  EXPECT_EQ(a.targets.hexes, b.targets.hexes);
  // The three mesh kinds and four target kinds all occur in the first 100 cases.
  int bricks = 0, cylinders = 0, rings = 0, all = 0, ones = 0;
  for (int i = 0; i < 100; ++i) {
    const PropertyCase c = property_case(i);
    bricks += c.description.find("brick") != std::string::npos;
    cylinders += c.description.find("cylinder") != std::string::npos;
    rings += c.description.find("ring") != std::string::npos;
    all += c.all_hexes;
    ones += c.description.find("one hex") != std::string::npos;
  }
  EXPECT_GT(bricks, 10);
  EXPECT_GT(cylinders, 10);
  EXPECT_GT(rings, 10);
  EXPECT_GT(all, 5);
  EXPECT_GT(ones, 5);
}

}  // namespace
}  // namespace hexrefine
