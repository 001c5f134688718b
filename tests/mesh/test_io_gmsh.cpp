#include <gtest/gtest.h>

#include <cstring>

#include "cli_runner.hpp"
#include "io_test_support.hpp"
#include "mesh/error.hpp"
#include "mesh/io.hpp"
#include "mesh/io_text.hpp"

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

TEST(IoGmsh, HexesOutOfTagOrderAndTheirDataAreReorderedTogether) {
  // Two hexes listed as tags 2, 1 (read in tag order), a field for tags 1, 2 and one for tag 2
  // only; then the same hexes in tag order, where the full field is taken over as it is.
  const auto dir = test_temp_dir("io_gmsh_order");
  std::string nodes;
  for (int i = 0; i < 12; ++i)
    nodes += std::to_string(i + 1) + " " + std::to_string(i & 1) + " " +
             std::to_string((i >> 1) & 1) + " " + std::to_string(i >> 2) + "\n";
  const std::string hex1 = "5 2 1 1 1 2 4 3 5 6 8 7\n", hex2 = "5 2 1 1 5 6 8 7 9 10 12 11\n";
  const std::string data =
      "$ElementData\n1\n\"level\"\n1\n0.0\n3\n0\n1\n2\n1 10\n2 20\n$EndElementData\n"
      "$ElementData\n1\n\"tag\"\n1\n0.0\n3\n0\n1\n1\n2 7\n$EndElementData\n";
  for (const bool swapped : {true, false}) {
    const auto p = dir / (swapped ? "swapped.msh" : "ordered.msh");
    io_write_text(p, "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n12\n" + nodes +
                         "$EndNodes\n$Elements\n2\n" +
                         (swapped ? "2 " + hex2 + "1 " + hex1 : "1 " + hex1 + "2 " + hex2) +
                         "$EndElements\n" + data);
    const HexMesh m = mesh_read(p.string());
    ASSERT_EQ(m.hex_count(), 2) << swapped;
    EXPECT_EQ(m.hexes[0], (HexCell{0, 1, 3, 2, 4, 5, 7, 6})) << swapped;
    EXPECT_EQ(m.hexes[1], (HexCell{4, 5, 7, 6, 8, 9, 11, 10})) << swapped;
    EXPECT_EQ(*mesh_find_attribute(m, "level"), (std::vector<int32_t>{10, 20})) << swapped;
    EXPECT_EQ(*mesh_find_attribute(m, "tag"), (std::vector<int32_t>{0, 7})) << swapped;
  }
}

TEST(IoGmsh, RefusesTetsUndefinedNodesAndOtherVersions) {
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
      {"$MeshFormat\n3.0 0 8\n$EndMeshFormat\n", "not supported (expected 4.1 or 2.2)"},
      {"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Elements\n0 0 0 0\n$EndElements\n",
       ":4: $Elements before $Nodes"},
      {head + "$Elements\n1 2 1 2\n3 1 5 2\n1 1 2 3 4 1 2 3 4\n1 1 2 3 4 1 2 3 4\n$EndElements\n",
       ":20: element tag 1 repeated or not positive"},
      {"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 100000000000 1 4\n",
       "node count 100000000000"},
  };
  io_expect_refusals(dir, ".msh", cases);
}

/// A binary Gmsh file built value by value, independently of the writer.
struct GmshBytes {
  std::string s;
  template <class T>
  GmshBytes& value(T v) {
    s.append(reinterpret_cast<const char*>(&v), sizeof v);
    return *this;
  }
  GmshBytes& sizes(std::initializer_list<uint64_t> vs) {
    for (uint64_t v : vs) value(v);
    return *this;
  }
  GmshBytes& ints(std::initializer_list<int32_t> vs) {
    for (int32_t v : vs) value(v);
    return *this;
  }
  GmshBytes& text(const std::string& t) {
    s += t;
    return *this;
  }
};

/// The head of a binary 4.1 file with 8-byte size_t: 40 bytes.
GmshBytes gmsh41_binary_head() {
  GmshBytes b;
  b.text("$MeshFormat\n4.1 1 8\n").ints({1}).text("\n$EndMeshFormat\n");
  return b;
}

/// Unit-cube corners with tags 101..108 (4.1 binary: 8 size_t tags, then 8 xyz).
void gmsh41_binary_cube_nodes(GmshBytes& b) {
  b.text("$Nodes\n").sizes({1, 8, 101, 108}).ints({3, 1, 0}).sizes({8});
  for (uint64_t t = 101; t <= 108; ++t) b.value(t);
  for (int i = 0; i < 8; ++i) {
    const int x = (i == 1 || i == 2 || i == 5 || i == 6), y = (i & 2) != 0, z = i >= 4;
    b.value(double(x)).value(double(y)).value(double(z));
  }
  b.text("\n$EndNodes\n");
}

TEST(IoGmsh, BinaryRoundTripKeepsPointsCellsAndAttributesExactly) {
  const auto dir = test_temp_dir("io_gmsh_binary_roundtrip");
  HexMesh m = io_test_brick();
  mesh_attribute(m, attribute_block_id)[0] = -3;
  const std::string path = (dir / "brick.msh").string();
  MeshWriteOptions o;
  o.binary = true;
  o.cell_scalars.emplace_back("scaled_jacobian", std::vector<double>(m.hexes.size(), 0.75));
  mesh_write(path, m, o);
  const std::string bytes = io_detail::file_read_all(path);
  const std::string head = gmsh41_binary_head().s;
  ASSERT_EQ(bytes.substr(0, head.size()), head);
  // 36 points: 8-byte tags then 24-byte coordinates, the first point's x right after the tags.
  const size_t nodes = bytes.find("$Nodes\n") + 7;
  uint64_t counts[4];
  std::memcpy(counts, bytes.data() + nodes, sizeof counts);
  EXPECT_EQ(counts[0], 1u);
  EXPECT_EQ(counts[1], 36u);
  EXPECT_EQ(counts[3], 36u);
  double x0;
  std::memcpy(&x0, bytes.data() + nodes + 32 + 12 + 8 + 36 * 8, 8);
  EXPECT_EQ(x0, m.points[0].x());
  const HexMesh r = mesh_read(path);
  io_expect_same_geometry(m, r, 0);
  ASSERT_EQ(r.attributes.size(), 3u);
  for (const HexAttribute& a : m.attributes) io_expect_same_attribute(m, r, a.name);
  // The text file of the same mesh reads to the same mesh.
  const std::string text_path = (dir / "brick_text.msh").string();
  mesh_write(text_path, m);
  const HexMesh t = mesh_read(text_path);
  io_expect_same_geometry(r, t, 0);
  for (const HexAttribute& a : m.attributes) io_expect_same_attribute(r, t, a.name);
}

TEST(IoGmsh, ReadsHandBuiltBinary41WithPhysicalTagsDataAndSkippedQuads) {
  const auto dir = test_temp_dir("io_gmsh_binary41");
  GmshBytes b = gmsh41_binary_head();
  // One surface entity (tag 4, no physical tag, 1 bounding curve) and one volume entity (tag 2,
  // physical tag 9, 1 bounding surface).
  b.text("$Entities\n").sizes({0, 0, 1, 1});
  b.ints({4});
  for (int k = 0; k < 6; ++k) b.value(0.0);
  b.sizes({0, 1}).ints({1});
  b.ints({2});
  for (int k = 0; k < 6; ++k) b.value(1.0);
  b.sizes({1}).ints({9}).sizes({1}).ints({4});
  b.text("\n$EndEntities\n");
  gmsh41_binary_cube_nodes(b);
  b.text("$Elements\n").sizes({2, 2, 1, 7});
  b.ints({2, 4, 3}).sizes({1}).sizes({1, 101, 102, 103, 104});                      // a quad
  b.ints({3, 2, 5}).sizes({1}).sizes({7, 101, 102, 103, 104, 105, 106, 107, 108});  // the hex
  b.text("\n$EndElements\n");
  b.text("$ElementData\n1\n\"template_tag\"\n1\n0.0\n3\n0\n1\n1\n").ints({7}).value(-4.0);
  b.text("\n$EndElementData\n");
  b.text("$Comment\n").value(uint64_t{0x0a24456e64}).text("\n$EndComment\n");  // binary junk
  const auto p = dir / "hand.msh";
  io_write_text(p, b.s);
  const HexMesh m = mesh_read(p.string());
  ASSERT_EQ(m.hex_count(), 1);
  EXPECT_EQ(m.hexes[0], (HexCell{0, 1, 2, 3, 4, 5, 6, 7}));
  EXPECT_EQ(m.points[2], Eigen::Vector3d(1, 1, 0));
  EXPECT_EQ(*mesh_find_attribute(m, attribute_block_id), std::vector<int32_t>{9});
  EXPECT_EQ(*mesh_find_attribute(m, attribute_template_tag), std::vector<int32_t>{-4});
}

TEST(IoGmsh, ReadsHandBuiltBinary22WithElementGroups) {
  const auto dir = test_temp_dir("io_gmsh_binary22");
  GmshBytes b;
  b.text("$MeshFormat\n2.2 1 8\n").ints({1}).text("\n$EndMeshFormat\n$Nodes\n8\n");
  for (int i = 0; i < 8; ++i)
    b.ints({200 + i}).value(double(i & 1)).value(double((i >> 1) & 1)).value(double(i >> 2));
  b.text("\n$EndNodes\n$Elements\n3\n");
  b.ints({3, 1, 2}).ints({1, 0, 0, 200, 201, 203, 202});  // a quad group: type, count, tags
  b.ints({5, 2, 2});                                      // two hexes with tags (physical, entity)
  b.ints({2, 9, 1, 200, 201, 203, 202, 204, 205, 207, 206});
  b.ints({3, 11, 1, 204, 205, 207, 206, 200, 201, 203, 202});
  b.text("\n$EndElements\n");
  const auto p = dir / "v22.msh";
  io_write_text(p, b.s);
  const HexMesh m = mesh_read(p.string());
  ASSERT_EQ(m.hex_count(), 2);
  EXPECT_EQ(m.hexes[0], (HexCell{0, 1, 3, 2, 4, 5, 7, 6}));
  EXPECT_EQ(m.hexes[1], (HexCell{4, 5, 7, 6, 0, 1, 3, 2}));
  EXPECT_EQ(*mesh_find_attribute(m, attribute_block_id), (std::vector<int32_t>{9, 11}));
}

TEST(IoGmsh, RefusesBadBinaryNamingTheByte) {
  const auto dir = test_temp_dir("io_gmsh_binary_bad");
  GmshBytes big;
  big.text("$MeshFormat\n4.1 1 8\n").value(int32_t{0x01000000}).text("\n$EndMeshFormat\n");
  GmshBytes truncated = gmsh41_binary_head();  // 8 nodes announced, 3 bytes of data follow
  truncated.text("$Nodes\n").sizes({1, 8, 1, 8}).ints({3, 1, 0}).sizes({8}).text("abc");
  GmshBytes nan = gmsh41_binary_head();
  nan.text("$Nodes\n").sizes({1, 1, 1, 1}).ints({3, 1, 0}).sizes({1, 1});
  nan.value(0.0).value(std::nan("")).value(0.0).text("\n$EndNodes\n");
  GmshBytes undefined = gmsh41_binary_head();
  gmsh41_binary_cube_nodes(undefined);
  undefined.text("$Elements\n").sizes({1, 1, 1, 1}).ints({3, 1, 5}).sizes({1});
  undefined.sizes({1, 101, 102, 103, 104, 105, 106, 107, 999}).text("\n$EndElements\n");
  // Byte offsets: the head is 40 bytes, "$Nodes\n" 7, each count 8, the block header 12.
  const size_t elements = undefined.s.find("$Elements\n") + 10 + 32 + 12 + 8;
  const std::pair<std::string, std::string> cases[] = {
      {big.s, "big-endian binary Gmsh files are not supported"},
      {"$MeshFormat\n4.1 1 6\n", "binary Gmsh data size 6: expected 4 or 8"},
      {"$MeshFormat\n4.1 2 8\n", "expected the file type (0 text, 1 binary) in 0..1, got 2"},
      {truncated.s, ": byte 55: node count 8 is more than the rest of the file (39 bytes)"},
      {nan.s, ": byte 115: expected node coordinate (a finite number)"},
      {undefined.s,
       ": byte " + std::to_string(elements) + ": hex element 1 refers to undefined node 999"},
  };
  io_expect_refusals(dir, ".msh", cases);
}

}  // namespace
}  // namespace hexrefine
