#include <gtest/gtest.h>

#include "cli_runner.hpp"
#include "io_test_support.hpp"
#include "mesh/error.hpp"
#include "mesh/io.hpp"

namespace hexrefine {
namespace {

TEST(IoExodus, RoundTripIsExactAndKeepsBlocksAndOrder) {
  const auto dir = test_temp_dir("io_exodus_roundtrip");
  const HexMesh m = io_test_brick();
  const std::string path = (dir / "brick.e").string();
  mesh_write(path, m);
  const HexMesh r = mesh_read(path);
  io_expect_same_geometry(m, r, 0);
  io_expect_same_attribute(m, r, attribute_block_id);
  // Every other attribute travels as an element variable (parent_hex, so that fields map from
  // parents to children): exactly, in hex order.
  for (const HexAttribute& a : m.attributes) io_expect_same_attribute(m, r, a.name);
  EXPECT_EQ(r.attributes.size(), m.attributes.size());
}

// The writer reserves free header space before the library defines anything, so that no later
// definition moves the variables already placed (netCDF-3 moves every variable, written or not,
// whenever the header outgrows its space). The layout shows it: the first variable, the one-byte
// reserve, begins after at least 64 KiB of header. Read from the raw CDF-2 header entry of that
// variable: name, no dimensions, no attributes, type, size, then its 8-byte big-endian offset.
TEST(IoExodus, HeaderSpaceIsReservedSoDefinitionsMoveNoData) {
  const auto dir = test_temp_dir("io_exodus_header_space");
  const std::string path = (dir / "brick.e").string();
  mesh_write(path, io_test_brick());
  const std::string bytes = test_file_text(path);
  ASSERT_EQ(bytes.substr(0, 4), std::string("CDF\x02", 4));  // 64-bit offsets
  const std::string name = "hexrefine_header_reserve";
  const size_t at = bytes.find(name);
  ASSERT_NE(at, std::string::npos);
  size_t p = at + (name.size() + 3) / 4 * 4;  // the name, padded to 4 bytes
  auto be = [&](size_t width) {
    uint64_t v = 0;
    for (size_t k = 0; k < width; ++k) v = v << 8 | static_cast<unsigned char>(bytes.at(p + k));
    p += width;
    return v;
  };
  EXPECT_EQ(be(4), 0u);  // no dimensions: a scalar
  EXPECT_EQ(be(4), 0u);  // ABSENT attribute list
  EXPECT_EQ(be(4), 0u);
  EXPECT_EQ(be(4), 2u);  // NC_CHAR
  be(4);                 // its padded size
  const uint64_t begin = be(8);
  EXPECT_GE(begin, 65536u);
  EXPECT_LT(begin, bytes.size());
  EXPECT_EQ(mesh_read(path).hex_count(), io_test_brick().hex_count());
}

TEST(IoExodus, ParentHexIsAnElementVariableAndFloatFieldsAreNotAttributes) {
  const auto dir = test_temp_dir("io_exodus_variables");
  HexMesh m = io_test_brick();
  std::vector<int32_t>& parent = mesh_attribute(m, attribute_parent_hex);
  for (int32_t h = 0; h < m.hex_count(); ++h) parent[h] = 1000 - 3 * h;
  MeshWriteOptions o;
  o.cell_scalars.push_back({"scaled_jacobian", std::vector<double>(m.hexes.size(), 0.25)});
  const std::string path = (dir / "v.e").string();
  mesh_write(path, m, o);
  const HexMesh r = mesh_read(path);
  io_expect_same_attribute(m, r, attribute_parent_hex);
  EXPECT_EQ(mesh_find_attribute(r, "scaled_jacobian"), nullptr);  // not integral: a field
}

TEST(IoExodus, NonPositiveBlockIdsSurviveThroughBlockNames) {
  const auto dir = test_temp_dir("io_exodus_negative");
  HexMesh m = io_test_brick();
  mesh_attribute(m, attribute_block_id)[0] = -1;  // EX_INVALID_ID as an Exodus id
  mesh_attribute(m, attribute_block_id)[4] = 0;
  const std::string path = (dir / "neg.e").string();
  mesh_write(path, m);
  const HexMesh r = mesh_read(path);
  io_expect_same_geometry(m, r, 0);
  io_expect_same_attribute(m, r, attribute_block_id);
}

TEST(IoExodus, MeshWithoutBlocksIsBlockOne) {
  const auto dir = test_temp_dir("io_exodus_noblock");
  const HexMesh m = fixture_brick(2, 1, 1);
  const std::string path = (dir / "b.exo").string();
  mesh_write(path, m);
  const HexMesh r = mesh_read(path);
  io_expect_same_geometry(m, r, 0);
  EXPECT_EQ(*mesh_find_attribute(r, attribute_block_id), std::vector<int32_t>(2, 1));
}

TEST(IoExodus, ReadsSculptSphere) {
  const HexMesh m = mesh_read(shared_mesh("sphere_sculpt.e"));
  EXPECT_EQ(m.hex_count(), 80);  // as counted by meshio
  EXPECT_EQ(m.point_count(), 149);
}

TEST(IoExodus, RefusesNonNetcdfAndTruncatedFiles) {
  const auto dir = test_temp_dir("io_exodus_bad");
  io_write_text(dir / "text.e", "this is not netcdf\n");
  EXPECT_THROW(mesh_read((dir / "text.e").string()), InputError);
  const std::string good = (dir / "good.e").string();
  mesh_write(good, io_test_brick());
  std::ifstream in(good, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (size_t cut : {size_t{4}, size_t{100}, bytes.size() / 2, bytes.size() - 8}) {
    const auto p = dir / ("cut" + std::to_string(cut) + ".e");
    io_write_text(p, bytes.substr(0, cut));
    try {
      mesh_read(p.string());
      ADD_FAILURE() << "truncated file accepted at " << cut;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(p.string()), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace hexrefine
