#include "mesh/selection.hpp"

#include <gtest/gtest.h>

#include <fstream>

#include "mesh/error.hpp"
#include "mesh/generators.hpp"
#include "tests/cli_runner.hpp"
#include "tests/fixtures.hpp"

namespace hexrefine {
namespace {

class SelectionTest : public ::testing::Test {
 protected:
  HexMesh mesh = fixture_brick(4, 3, 2);  // hexes x fastest; centroids at (i+.5, j+.5, k+.5)
  HexTopology topology = topology_build(mesh);

  Selection select(const std::vector<std::string>& specs) {
    return select_hexes(mesh, topology, specs);
  }
  std::string error_of(const std::vector<std::string>& specs) {
    try {
      select(specs);
    } catch (const InputError& e) {
      return e.what();
    }
    return "(no InputError)";
  }
  std::string write_file(const std::string& name, const std::string& text) {
    const auto dir = test_temp_dir("selection_" + name);
    const std::string path = (dir / name).string();
    std::ofstream(path) << text;
    return path;
  }
  int32_t hex(int i, int j, int k) { return fixture_brick_hex(4, 3, i, j, k); }
};

TEST_F(SelectionTest, AllSelectsEveryHex) {
  const Selection s = select({"all"});
  ASSERT_EQ(s.hexes.size(), 24u);
  for (int32_t h = 0; h < 24; ++h) EXPECT_EQ(s.hexes[h], h);
  EXPECT_TRUE(s.warning.empty());
}

TEST_F(SelectionTest, BoxIsInclusiveOnCentroids) {
  // Centroid x in {0.5, 1.5} (1.5 on the bound), y = 0.5, any z.
  const Selection s = select({"box:0,0,0,1.5,1,2"});
  EXPECT_EQ(s.hexes,
            (std::vector<int32_t>{hex(0, 0, 0), hex(1, 0, 0), hex(0, 0, 1), hex(1, 0, 1)}));
}

TEST_F(SelectionTest, SphereUsesCentroidDistance) {
  // Centre at the centroid of hex (1,1,0); radius 1 reaches its 4 in-plane neighbours and the
  // one above (distance 1 exactly), not the diagonal ones (sqrt 2).
  const Selection s = select({"sphere:1.5,1.5,0.5,1"});
  EXPECT_EQ(s.hexes, (std::vector<int32_t>{hex(1, 0, 0), hex(0, 1, 0), hex(1, 1, 0), hex(2, 1, 0),
                                           hex(1, 2, 0), hex(1, 1, 1)}));
}

TEST_F(SelectionTest, BoundaryDirectionSelectsOneSide) {
  const Selection left = select({"boundary:-1,0,0"});
  ASSERT_EQ(left.hexes.size(), 6u);  // the i = 0 column: 3 x 2 hexes
  for (int32_t h : left.hexes) EXPECT_EQ(h % 4, 0);
  const Selection top = select({"boundary:0,0,5"});
  EXPECT_EQ(top.hexes.size(), 12u);
  for (int32_t h : top.hexes) EXPECT_GE(h, 12);
  // Up to 89 degrees only the +x side counts; at 90 the perpendicular sides count too, and in a
  // brick two layers thick every hex touches the top or the bottom.
  EXPECT_EQ(select({"boundary:1,0,0,89"}).hexes.size(), 6u);
  EXPECT_EQ(select({"boundary:1,0,0,90"}).hexes.size(), 24u);
}

TEST_F(SelectionTest, BoundaryOnTiltedDirection) {
  // (1,0,1) is 45 degrees from +x and +z: nothing within 30, both sides within 46.
  EXPECT_TRUE(select({"boundary:1,0,1"}).hexes.empty());
  const Selection s = select({"boundary:1,0,1,46"});
  std::vector<int32_t> expected;
  for (int32_t h = 0; h < 24; ++h)
    if (h % 4 == 3 || h >= 12) expected.push_back(h);
  EXPECT_EQ(s.hexes, expected);
}

TEST_F(SelectionTest, SpecsAreUnitedSortedUnique) {
  const std::string file = write_file("ids.txt", "23 0\n5  # comment 7\n\n0\n");
  const Selection s = select({"hexes:" + file, "box:0,0,0,1,1,1"});
  EXPECT_EQ(s.hexes, (std::vector<int32_t>{0, 5, 23}));
}

TEST_F(SelectionTest, HexesFileErrorsNameFileAndLine) {
  const std::string bad = write_file("bad.txt", "1 2\n3 x4\n");
  EXPECT_EQ(error_of({"hexes:" + bad}), bad + ":2: expected a hex id, got 'x4'");
  const std::string range = write_file("range.txt", "1\n\n24\n");
  EXPECT_EQ(error_of({"hexes:" + range}), range + ":3: hex id 24 out of range [0, 24)");
  const std::string negative = write_file("negative.txt", "-1\n");
  EXPECT_EQ(error_of({"hexes:" + negative}), negative + ":1: hex id -1 out of range [0, 24)");
  EXPECT_NE(error_of({"hexes:/nonexistent/ids.txt"}).find("/nonexistent/ids.txt"),
            std::string::npos);
}

TEST_F(SelectionTest, BlockUsesBlockIdAttribute) {
  EXPECT_NE(error_of({"block:1"}).find("no block_id attribute"), std::string::npos);
  std::vector<int32_t>& block = mesh_attribute(mesh, attribute_block_id, 0);
  block[3] = 7;
  block[10] = 2;
  block[11] = 7;
  EXPECT_EQ(select({"block:7"}).hexes, (std::vector<int32_t>{3, 11}));
  EXPECT_EQ(select({"block:2,7"}).hexes, (std::vector<int32_t>{3, 10, 11}));
  EXPECT_EQ(select({"block:0"}).hexes.size(), 21u);
  EXPECT_TRUE(select({"block:5"}).hexes.empty());
}

TEST(Selection, GearTeethByBlock) {
  const GearParams p;
  const HexMesh gear = generate_gear(p);
  const HexTopology t = topology_build(gear);
  const Selection teeth = select_hexes(gear, t, {"block:2"});
  EXPECT_EQ(static_cast<int>(teeth.hexes.size()),
            p.layers * p.teeth * p.tooth_tangential * p.tooth_radial);
  EXPECT_EQ(select_hexes(gear, t, {"block:1,2"}).hexes.size(), gear.hexes.size());
}

TEST(Selection, SteppedRightSurfaceIsTheRisers) {
  const SteppedParams p;
  const HexMesh m = generate_stepped(p);
  const HexTopology t = topology_build(m);
  // Three risers, each step_layers x depth hexes; treads and the top face the +z direction.
  EXPECT_EQ(static_cast<int>(select_hexes(m, t, {"boundary:1,0,0"}).hexes.size()),
            p.steps * p.step_layers * p.depth);
  EXPECT_EQ(static_cast<int>(select_hexes(m, t, {"boundary:0,0,1"}).hexes.size()),
            (p.top_width + 2 * p.tread) * p.depth);
}

TEST_F(SelectionTest, EmptyResultIsAWarningNotAnError) {
  const Selection s = select({"sphere:100,100,100,1", "box:50,50,50,60,60,60"});
  EXPECT_TRUE(s.hexes.empty());
  EXPECT_EQ(s.warning, "selection 'sphere:100,100,100,1', 'box:50,50,50,60,60,60' matches no hex");
}

TEST_F(SelectionTest, MalformedSpecsNameTheSpec) {
  const std::vector<std::string> bad = {"",
                                        "everything",
                                        "all:1",
                                        "box:0,0,0,1,1",
                                        "box:1,0,0,0,1,1",
                                        "box:0,0,0,1,1,nan",
                                        "sphere:0,0,0,-1",
                                        "sphere:0,0,0",
                                        "boundary:0,0,0",
                                        "boundary:1,0,0,200",
                                        "boundary:1,0",
                                        "block:",
                                        "block:1,x",
                                        "block:1,",
                                        "hexes:",
                                        "cube:1,2,3"};
  for (const std::string& spec : bad) {
    const std::string message = error_of({spec});
    EXPECT_NE(message.find("'" + spec + "'"), std::string::npos) << spec << " -> " << message;
  }
}

}  // namespace
}  // namespace hexrefine
