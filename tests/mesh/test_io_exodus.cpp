#include <gtest/gtest.h>
#include <netcdf.h>

#include <algorithm>
#include <bit>

#include "cli_runner.hpp"
#include "io_test_support.hpp"
#include "mesh/error.hpp"
#include "mesh/io.hpp"
#include "mesh/io_exodus_guard.hpp"

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

// The bulk arrays are written by hexrefine itself at the offsets of the header the library
// wrote (netCDF classic, big-endian): every variable lies inside the file, in file order
// without overlap, and the raw bytes hold the values, checked here without the library.
TEST(IoExodus, BulkDataLiesWhereTheHeaderSaysInBigEndian) {
  const auto dir = test_temp_dir("io_exodus_bulk");
  HexMesh m = io_test_brick();
  MeshWriteOptions o;
  std::vector<double> field(m.hexes.size());
  for (size_t h = 0; h < field.size(); ++h) field[h] = 0.5 + static_cast<double>(h) / 3.0;
  o.cell_scalars.push_back({"scaled_jacobian", field});
  const std::string path = (dir / "bulk.e").string();
  mesh_write(path, m, o);
  const std::string bytes = test_file_text(path);
  const auto layout =
      io_detail::netcdf_classic_layout(path, bytes, static_cast<int64_t>(bytes.size()));
  ASSERT_TRUE(layout.has_value());
  EXPECT_EQ(layout->records, 1u);  // one time step of element variables
  // The scalar field is the last element variable: after every attribute but block_id.
  const std::string values_name = "vals_elem_var" + std::to_string(m.attributes.size()) + "eb1";
  std::vector<io_detail::NetcdfVariableExtent> variables = layout->variables;
  std::sort(variables.begin(), variables.end(),
            [](const auto& a, const auto& b) { return a.begin < b.begin; });
  uint64_t previous_end = 0;
  const io_detail::NetcdfVariableExtent* coordx = nullptr;
  const io_detail::NetcdfVariableExtent* connect = nullptr;
  const io_detail::NetcdfVariableExtent* values = nullptr;
  for (const io_detail::NetcdfVariableExtent& v : variables) {
    EXPECT_GE(v.begin, previous_end) << v.name;
    EXPECT_LE(v.begin + v.size, bytes.size()) << v.name;
    previous_end = v.begin + v.size;
    if (v.name == "coordx") coordx = &v;
    if (v.name == "connect1") connect = &v;
    if (v.name == values_name) values = &v;
  }
  EXPECT_EQ(previous_end, bytes.size());  // the last record variable ends the file
  ASSERT_NE(coordx, nullptr);
  ASSERT_NE(connect, nullptr);
  ASSERT_NE(values, nullptr);
  auto big_endian = [&](uint64_t at, int width) {
    uint64_t v = 0;
    for (int k = 0; k < width; ++k) v = v << 8 | static_cast<unsigned char>(bytes.at(at + k));
    return v;
  };
  ASSERT_EQ(coordx->type, NC_DOUBLE);
  for (int32_t i = 0; i < m.point_count(); ++i)
    ASSERT_EQ(std::bit_cast<double>(big_endian(coordx->begin + 8 * i, 8)), m.points[i].x()) << i;
  ASSERT_EQ(connect->type, NC_INT);
  // One block (block_id 1 for the first hexes, see io_test_brick): its hexes in hex order.
  const std::vector<int32_t>& block = *mesh_find_attribute(m, attribute_block_id);
  std::vector<int32_t> first_block;
  for (int32_t h = 0; h < m.hex_count(); ++h)
    if (block[h] == block[0]) first_block.push_back(h);
  for (size_t k = 0; k < first_block.size(); ++k)
    for (int v = 0; v < 8; ++v)
      ASSERT_EQ(big_endian(connect->begin + 4 * (8 * k + v), 4),
                static_cast<uint64_t>(m.hexes[first_block[k]][v] + 1));
  ASSERT_EQ(values->type, NC_DOUBLE);
  for (size_t k = 0; k < first_block.size(); ++k)
    ASSERT_EQ(std::bit_cast<double>(big_endian(values->begin + 8 * k, 8)), field[first_block[k]]);
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
