#include "mesh/io_vtu_data.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "io_test_support.hpp"
#include "mesh/error.hpp"
#include "mesh/io.hpp"

namespace hexrefine {
namespace {

using io_detail::base64_encode;
using io_detail::VtuBlockFormat;

/// `size` as a little-endian header integer of `bytes` bytes.
std::string header(uint64_t size, int bytes) {
  std::string out(static_cast<size_t>(bytes), '\0');
  std::memcpy(out.data(), &size, static_cast<size_t>(bytes));
  return out;
}

/// One hex (unit cube) as a VTU whose five arrays are written by `array(type, name, data)`.
template <class Array>
std::string unit_cube_vtu(const std::string& file_attributes, Array array,
                          const std::string& appended = "") {
  double points[24] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
  int32_t connectivity[8] = {0, 1, 2, 3, 4, 5, 6, 7};
  int64_t offsets[1] = {8};
  uint8_t types[1] = {12};
  int32_t block[1] = {7};
  auto bytes = [](const void* p, size_t n) { return std::string(static_cast<const char*>(p), n); };
  std::string s = "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" " +
                  file_attributes +
                  ">\n<UnstructuredGrid>\n<Piece NumberOfPoints=\"8\" "
                  "NumberOfCells=\"1\">\n<Points>\n" +
                  array("Float64\" NumberOfComponents=\"3", "Points", bytes(points, 192)) +
                  "</Points>\n<Cells>\n" + array("Int32", "connectivity", bytes(connectivity, 32)) +
                  array("Int64", "offsets", bytes(offsets, 8)) +
                  array("UInt8", "types", bytes(types, 1)) + "</Cells>\n<CellData>\n" +
                  array("Int32", "block_id", bytes(block, 4)) +
                  "</CellData>\n</Piece>\n</UnstructuredGrid>\n" + appended + "</VTKFile>\n";
  return s;
}

void expect_unit_cube(const HexMesh& m) {
  ASSERT_EQ(m.hex_count(), 1);
  EXPECT_EQ(m.hexes[0], (HexCell{0, 1, 2, 3, 4, 5, 6, 7}));
  EXPECT_EQ(m.points[6], Eigen::Vector3d(1, 1, 1));
  EXPECT_EQ(*mesh_find_attribute(m, attribute_block_id), std::vector<int32_t>{7});
}

TEST(IoVtuData, Base64MatchesRfc4648) {
  EXPECT_EQ(base64_encode(""), "");
  EXPECT_EQ(base64_encode("f"), "Zg==");
  EXPECT_EQ(base64_encode("fo"), "Zm8=");
  EXPECT_EQ(base64_encode("foobar"), "Zm9vYmFy");
}

TEST(IoVtuData, InlineBinaryWithHeaderAndDataEncodedSeparatelyOrTogether) {
  const auto dir = test_temp_dir("io_vtu_inline");
  for (int header_bytes : {4, 8})
    for (bool together : {false, true}) {
      SCOPED_TRACE(std::to_string(header_bytes) + (together ? " together" : " separate"));
      auto array = [&](const std::string& type, const std::string& name, const std::string& d) {
        const std::string h = header(d.size(), header_bytes);
        const std::string encoded =
            together ? base64_encode(h + d) : base64_encode(h) + base64_encode(d);
        return "<DataArray type=\"" + type + "\" Name=\"" + name + "\" format=\"binary\">\n  " +
               encoded + "\n</DataArray>\n";
      };
      const std::string type = header_bytes == 4 ? "UInt32" : "UInt64";
      const auto p =
          dir / ("cube" + std::to_string(header_bytes) + (together ? "t" : "s") + ".vtu");
      io_write_text(p, unit_cube_vtu("header_type=\"" + type + "\"", array));
      expect_unit_cube(mesh_read(p.string()));
    }
}

TEST(IoVtuData, AppendedRawAndBase64WithAndWithoutZlib) {
  const auto dir = test_temp_dir("io_vtu_appended");
  for (bool zlib : {false, true})
    for (bool base64 : {false, true}) {
      SCOPED_TRACE(std::string(zlib ? "zlib" : "plain") + (base64 ? " base64" : " raw"));
      std::string data;
      auto array = [&](const std::string& type, const std::string& name, const std::string& d) {
        const std::string offset = std::to_string(data.size());
        std::string block =
            zlib ? io_detail::vtu_block_compress(d.data(), d.size()) : header(d.size(), 8) + d;
        if (base64 && zlib) {
          // Header (3 + blocks integers) and compressed data encoded separately, as VTK does.
          uint64_t blocks = 0;
          std::memcpy(&blocks, block.data(), 8);
          const size_t h = (3 + blocks) * 8;
          block = base64_encode(block.substr(0, h)) + base64_encode(block.substr(h));
        } else if (base64) {
          block = base64_encode(block.substr(0, 8)) + base64_encode(block.substr(8));
        }
        data += block;
        return "<DataArray type=\"" + type + "\" Name=\"" + name +
               "\" format=\"appended\" offset=\"" + offset + "\"/>\n";
      };
      const std::string attributes =
          std::string("header_type=\"UInt64\" byte_order=\"LittleEndian\"") +
          (zlib ? " compressor=\"vtkZLibDataCompressor\"" : "");
      // The arrays must be made before the appended section that holds them.
      std::string text = unit_cube_vtu(attributes, array);
      const std::string appended = std::string("<AppendedData encoding=\"") +
                                   (base64 ? "base64" : "raw") + "\">\n  _" + data +
                                   "\n</AppendedData>\n";
      text.insert(text.rfind("</VTKFile>"), appended);
      const auto p =
          dir / (std::string("cube") + (zlib ? "z" : "p") + (base64 ? "b" : "r") + ".vtu");
      io_write_text(p, text);
      expect_unit_cube(mesh_read(p.string()));
    }
}

TEST(IoVtuData, RawCellsArraysReadInTheFileMixedWithTextAndCheckedAsDecodedOnes) {
  // Raw appended <Cells> arrays are read where they lie in the file; with a partner in another
  // encoding they are decoded like it; either way every value is checked as a decoded one is.
  const auto dir = test_temp_dir("io_vtu_cells_in_file");
  // `text_names`: arrays written as ASCII; `replace`: name -> (type, raw bytes) overrides.
  auto write = [&](const std::string& file, const std::set<std::string>& text_names,
                   const std::map<std::string, std::pair<std::string, std::string>>& replace) {
    std::string data;
    auto array = [&](const std::string& type, const std::string& name, const std::string& d) {
      if (text_names.count(name))
        return "<DataArray type=\"" + type + "\" Name=\"" + name + "\" format=\"ascii\">" +
               (name == "offsets" ? "8" : "12") + "</DataArray>\n";
      const auto it = replace.find(name);
      const std::string& t = it == replace.end() ? type : it->second.first;
      const std::string& bytes = it == replace.end() ? d : it->second.second;
      const std::string offset = std::to_string(data.size());
      data += header(bytes.size(), 8) + bytes;
      return "<DataArray type=\"" + t + "\" Name=\"" + name + "\" format=\"appended\" offset=\"" +
             offset + "\"/>\n";
    };
    std::string text = unit_cube_vtu("header_type=\"UInt64\"", array);
    text.insert(text.rfind("</VTKFile>"),
                "<AppendedData encoding=\"raw\">\n_" + data + "\n</AppendedData>\n");
    const auto p = dir / file;
    io_write_text(p, text);
    return p.string();
  };
  auto raw = [](auto... values) {
    std::string out;
    for (auto v : {values...}) out.append(reinterpret_cast<const char*>(&v), sizeof v);
    return out;
  };
  expect_unit_cube(mesh_read(write("all.vtu", {}, {})));
  expect_unit_cube(mesh_read(write("mixed.vtu", {"offsets", "types"}, {})));
  expect_unit_cube(mesh_read(write("mixed_types.vtu", {"types"}, {})));
  auto refused = [&](const std::string& path, const std::string& expected) {
    try {
      mesh_read(path);
      ADD_FAILURE() << path << " accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  const std::string wide = raw(int64_t{0}, int64_t{1}, int64_t{2}, int64_t{3}, int64_t{4},
                               int64_t{5}, int64_t{6}, int64_t{5000000000});
  refused(write("wide.vtu", {}, {{"connectivity", {"Int64", wide}}}),
          "'connectivity' holds 5000000000, out of range");
  refused(write("wide_mixed.vtu", {"types"}, {{"connectivity", {"Int64", wide}}}),
          "'connectivity' holds 5000000000, out of range");
  refused(write("beyond.vtu", {}, {{"connectivity", {"Int32", raw(0, 1, 2, 3, 4, 5, 6, 8)}}}),
          "cell 0 refers to point 8, expected 0..7");
  refused(write("huge_offset.vtu", {}, {{"offsets", {"UInt64", raw(~uint64_t{0})}}}),
          "value 18446744073709551615 too large");
  refused(write("tetra.vtu", {}, {{"types", {"UInt8", raw(uint8_t{10})}}}),
          "cell 0 has VTK type 10, a volume cell that is not a linear hexahedron");
  refused(write("two_offsets.vtu", {}, {{"offsets", {"Int64", raw(int64_t{4}, int64_t{8})}}}),
          "Cells offsets/types need NumberOfCells = 1 values");
  // Points: Float64 copied as they are, Float32 converted; a NaN refused in both.
  std::vector<double> points = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0,
                                0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
  points[16] = std::nan("");
  const std::vector<float> narrow(points.begin(), points.end());
  const std::string vector_type = "\" NumberOfComponents=\"3";
  refused(write("nan64.vtu", {},
                {{"Points",
                  {"Float64" + vector_type,
                   std::string(reinterpret_cast<const char*>(points.data()), 192)}}}),
          "point 5 has a NaN or infinite coordinate");
  refused(write("nan32.vtu", {},
                {{"Points",
                  {"Float32" + vector_type,
                   std::string(reinterpret_cast<const char*>(narrow.data()), 96)}}}),
          "point 5 has a NaN or infinite coordinate");
}

TEST(IoVtuData, TruncatedOrForeignBinaryIsRefusedWithFileAndByte) {
  const auto dir = test_temp_dir("io_vtu_bad");
  const HexMesh m = io_test_brick();
  const std::string path = (dir / "good.vtu").string();
  mesh_write(path, m);
  std::ifstream in(path, std::ios::binary);
  const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  const auto cut = dir / "cut.vtu";
  io_write_text(cut, text.substr(0, text.size() * 2 / 3));
  try {
    mesh_read(cut.string());
    FAIL() << "truncated VTU accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cut.vtu: byte "), std::string::npos) << e.what();
  }
  std::string big = text;
  big.replace(big.find("LittleEndian"), 12, "BigEndian");
  const auto be = dir / "big.vtu";
  io_write_text(be, big);
  EXPECT_THROW(mesh_read(be.string()), InputError);
  std::string lz4 = text;
  lz4.replace(lz4.find("header_type"), 0, "compressor=\"vtkLZ4DataCompressor\" ");
  const auto l = dir / "lz4.vtu";
  io_write_text(l, lz4);
  try {
    mesh_read(l.string());
    FAIL() << "lz4 accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("vtkLZ4DataCompressor"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace hexrefine
