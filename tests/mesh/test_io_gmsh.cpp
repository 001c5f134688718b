#include <gtest/gtest.h>

#include "cli_runner.hpp"
#include "io_test_support.hpp"
#include "mesh/error.hpp"
#include "mesh/io.hpp"

namespace hexrefine {
namespace {

TEST(IoGmsh, RoundTripKeepsPointsCellsAndAllAttributes) {
  const auto dir = test_temp_dir("io_gmsh_roundtrip");
  HexMesh m = io_test_brick();
  mesh_attribute(m, attribute_block_id)[0] = -3;  // survives through $ElementData
  const std::string path = (dir / "brick.msh").string();
  MeshWriteOptions o;
  o.cell_scalars.emplace_back("scaled_jacobian", std::vector<double>(m.hexes.size(), 0.75));
  mesh_write(path, m, o);
  const HexMesh r = mesh_read(path);
  io_expect_same_geometry(m, r, 1e-12);
  io_expect_same_geometry(m, r, 0);
  ASSERT_EQ(r.attributes.size(), 3u);  // scaled_jacobian is not integral: not an attribute
  for (const HexAttribute& a : m.attributes) io_expect_same_attribute(m, r, a.name);
}

TEST(IoGmsh, Reads22WithPhysicalTagsAndSkipsQuads) {
  const auto dir = test_temp_dir("io_gmsh_22");
  const auto p = dir / "v22.msh";
  std::string nodes;
  for (int i = 0; i < 8; ++i)
    nodes += std::to_string(100 + i) + " " + std::to_string(i & 1) + " " +
             std::to_string((i >> 1) & 1) + " " + std::to_string(i >> 2) + "\n";
  io_write_text(p,
                "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n3 9 \"steel part\"\n"
                "$EndPhysicalNames\n$Nodes\n8\n" +
                    nodes +
                    "$EndNodes\n$Elements\n2\n7 3 2 1 1 100 101 103 102\n"
                    "8 5 2 9 1 100 101 103 102 104 105 107 106\n$EndElements\n");
  const HexMesh m = mesh_read(p.string());
  ASSERT_EQ(m.hex_count(), 1);
  EXPECT_EQ(m.hexes[0], (HexCell{0, 1, 3, 2, 4, 5, 7, 6}));
  EXPECT_EQ(*mesh_find_attribute(m, attribute_block_id), std::vector<int32_t>{9});
}

TEST(IoGmsh, RefusesTetsBinaryAndUndefinedNodes) {
  const auto dir = test_temp_dir("io_gmsh_bad");
  const std::string head =
      "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n"
      "0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n";
  const std::pair<std::string, std::string> cases[] = {
      {head + "$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3 4\n$EndElements\n",
       ":19: element 1 has Gmsh type 4"},
      {head + "$Elements\n1 1 1 1\n3 1 5 1\n1 1 2 3 4 1 2 3 9\n$EndElements\n", "undefined node 9"},
      {head + "$Elements\n1 1 1 1\n3 1 5 1\n1 1 2 3 4 1 2 3\n$EndElements\n", "expected node tag"},
      {head + "$Elements\n1 1 1 1\n3 1 99 1\n1 1 2\n$EndElements\n",
       "unknown Gmsh element type 99"},
      {"$MeshFormat\n4.1 1 8\n$EndMeshFormat\n", "binary Gmsh files are not supported"},
      {"$MeshFormat\n3.0 0 8\n$EndMeshFormat\n", "not supported (expected 4.1 or 2.2)"},
      {"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 100000000000 1 4\n",
       "node count 100000000000"},
  };
  io_expect_refusals(dir, ".msh", cases);
}

}  // namespace
}  // namespace hexrefine
