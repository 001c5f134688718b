#include <gtest/gtest.h>

#include "cli_runner.hpp"
#include "io_test_support.hpp"
#include "mesh/error.hpp"
#include "mesh/io.hpp"

namespace hexrefine {
namespace {

TEST(IoAbaqus, RoundTripKeepsPointsCellsAndBlockId) {
  const auto dir = test_temp_dir("io_abaqus_roundtrip");
  const HexMesh m = io_test_brick();
  const std::string path = (dir / "brick.inp").string();
  mesh_write(path, m);
  const HexMesh r = mesh_read(path);
  io_expect_same_geometry(m, r, 1e-12);
  io_expect_same_geometry(m, r, 0);
  io_expect_same_attribute(m, r, attribute_block_id);
}

TEST(IoAbaqus, ReadsSharedCubeWithPositiveVolumes) {
  const HexMesh m = mesh_read(shared_mesh("abaqus_hex_2x2x2.inp"));
  ASSERT_EQ(m.hex_count(), 8);
  EXPECT_EQ(m.point_count(), 27);
  // C3D8 order equals ours: the first hex is the cube [0,0.5]^3 with node 0 at the origin and
  // node 6 at (0.5, 0.5, 0.5).
  EXPECT_EQ(m.points[m.hexes[0][0]], Eigen::Vector3d(0, 0, 0));
  EXPECT_EQ(m.points[m.hexes[0][1]], Eigen::Vector3d(0.5, 0, 0));
  EXPECT_EQ(m.points[m.hexes[0][3]], Eigen::Vector3d(0, 0.5, 0));
  EXPECT_EQ(m.points[m.hexes[0][6]], Eigen::Vector3d(0.5, 0.5, 0.5));
  EXPECT_EQ(*mesh_find_attribute(m, attribute_block_id), std::vector<int32_t>(8, 0));
}

TEST(IoAbaqus, ReadsContinuationGenerateAndSkipsShells) {
  const auto dir = test_temp_dir("io_abaqus_features");
  const auto p = dir / "f.inp";
  io_write_text(p,
                "** comment\n*Node\n10, 0, 0, 0\n11, 1, 0, 0\n12, 1, 1, 0\n13, 0, 1, 0\n"
                "14, 0, 0, 1\n15, 1, 0, 1\n16, 1, 1, 1\n17, 0, 1, 1\n"
                "*Element, type=C3D8R\n5, 10, 11, 12, 13,\n 14, 15, 16, 17\n"
                "*Element, type=S4R, elset=skin\n9, 10, 11, 12, 13\n"
                "*Elset, elset=Block_4, generate\n5, 5, 1\n*Material, name=steel\n");
  const HexMesh m = mesh_read(p.string());
  ASSERT_EQ(m.hex_count(), 1);
  EXPECT_EQ(m.hexes[0], (HexCell{0, 1, 2, 3, 4, 5, 6, 7}));
  EXPECT_EQ(*mesh_find_attribute(m, attribute_block_id), std::vector<int32_t>{4});
}

TEST(IoAbaqus, RefusesTetsUndefinedNodesAndShortRows) {
  const auto dir = test_temp_dir("io_abaqus_bad");
  const std::string nodes =
      "*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n3, 1, 1, 0\n4, 0, 1, 0\n"
      "5, 0, 0, 1\n6, 1, 0, 1\n7, 1, 1, 1\n8, 0, 1, 1\n";
  const std::pair<std::string, std::string> cases[] = {
      {nodes + "*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 5\n",
       ":10: element type C3D4 is a volume element"},
      {nodes + "*ELEMENT, TYPE=C3D8\n1, 1, 2, 3, 4, 5, 6, 7, 9\n",
       ":11: element 1 refers to undefined node 9"},
      {nodes + "*ELEMENT, TYPE=C3D8\n1, 1, 2, 3, 4, 5, 6, 7\n",
       ":11: C3D8 row needs an element id and 8 node ids"},
      {nodes + "*ELEMENT, TYPE=C3D8\n1, 1, 2, 3, 4, 5, 6, 7, 0\n", "undefined node 0"},
      {"*NODE\n1, 0, nan, 0\n", ":2: expected a finite node coordinate"},
      {"*NODE\n1, 0, 0, 0\n1, 1, 0, 0\n", ":3: node id 1 repeated"},
      {"hello\n", "no Abaqus keyword line"},
      {nodes + "*INCLUDE, INPUT=more.inp\n", ":10: *INCLUDE is not supported"},
  };
  io_expect_refusals(dir, ".inp", cases);
}

}  // namespace
}  // namespace hexrefine
