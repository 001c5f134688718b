/// Exactness of every format's coordinates (bit for bit, -0.0 and subnormals included), the
/// shortest-form text the ASCII writers print, and the writers' buffer (io_text.hpp TextWriter)
/// across its flush boundaries; and how the readers get a file's bytes (file_read_all, FileBytes).
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <thread>

#include "cli_runner.hpp"
#include "io_test_support.hpp"
#include "mesh/io.hpp"
#include "mesh/io_text.hpp"

namespace hexrefine {
namespace {

/// Doubles whose decimal form is awkward: not short decimals, the extremes of the range,
/// subnormals, negative zero, neighbours of 1, integers near 2^53.
const double awkward_values[] = {0.1,
                                 1.0 / 3.0,
                                 -1.0 / 3.0,
                                 2.0 / 3.0,
                                 0.30000000000000004,
                                 1e-300,
                                 -0.0,
                                 0.0,
                                 5e-324,
                                 -5e-324,
                                 2.2250738585072014e-308,  // smallest normal
                                 2.2250738585072009e-308,  // largest subnormal
                                 1.7976931348623157e308,
                                 -1.7976931348623157e308,
                                 std::nextafter(1.0, 2.0),
                                 std::nextafter(1.0, 0.0),
                                 9007199254740991.0,  // 2^53 - 1
                                 9007199254740992.0,
                                 1e23,
                                 123456789.125,
                                 3.141592653589793,
                                 -2.718281828459045,
                                 1e-7,
                                 4.35,
                                 100.0,
                                 -1.5e-5,
                                 6.02214076e23};
constexpr size_t awkward_count = sizeof(awkward_values) / sizeof(awkward_values[0]);

/// fixture_brick(2, 2, 2) (27 points) whose 81 coordinates run through awkward_values; the
/// connectivity and block_id are kept, the geometry is not a valid mesh (readers do not check it).
HexMesh io_awkward_brick() {
  HexMesh m = fixture_brick(2, 2, 2);
  for (size_t i = 0; i < m.points.size(); ++i)
    for (int k = 0; k < 3; ++k) m.points[i][k] = awkward_values[(3 * i + k) % awkward_count];
  std::vector<int32_t>& block = mesh_attribute(m, attribute_block_id);
  for (size_t h = 0; h < block.size(); ++h) block[h] = static_cast<int32_t>(h % 3) - 1;
  return m;
}

void io_expect_bit_exact_points(const HexMesh& a, const HexMesh& b) {
  ASSERT_EQ(a.points.size(), b.points.size());
  for (size_t i = 0; i < a.points.size(); ++i)
    for (int k = 0; k < 3; ++k)
      ASSERT_EQ(std::bit_cast<uint64_t>(a.points[i][k]), std::bit_cast<uint64_t>(b.points[i][k]))
          << "point " << i << " coordinate " << k << ": wrote " << a.points[i][k] << ", read "
          << b.points[i][k];
  ASSERT_EQ(a.hexes, b.hexes);
}

struct ExactCase {
  const char* name;
  const char* file;
  bool binary;
};

class IoExact : public ::testing::TestWithParam<ExactCase> {};

TEST_P(IoExact, AwkwardCoordinatesRoundTripBitExact) {
  const ExactCase& c = GetParam();
  const auto dir = test_temp_dir(std::string("io_exact_") + c.name);
  const HexMesh m = io_awkward_brick();
  ASSERT_EQ(m.points.size(), 27u);
  const std::string path = (dir / c.file).string();
  MeshWriteOptions options;
  options.binary = c.binary;
  mesh_write(path, m, options);
  const HexMesh r = mesh_read(path);
  io_expect_bit_exact_points(m, r);
  // -0.0 and 0.0 compare equal as doubles: the bit test above is what tells them apart.
  EXPECT_TRUE(std::signbit(r.points[2][0]));  // coordinate 6 of the list is -0.0
  EXPECT_EQ(r.points[2][2], 5e-324);
}

INSTANTIATE_TEST_SUITE_P(
    AllFormats, IoExact,
    ::testing::Values(ExactCase{"medit", "a.mesh", false}, ExactCase{"vtk_ascii", "a.vtk", false},
                      ExactCase{"vtk_binary", "a.vtk", true}, ExactCase{"vtu", "a.vtu", false},
                      ExactCase{"gmsh", "a.msh", false}, ExactCase{"abaqus", "a.inp", false},
                      ExactCase{"exodus", "a.e", false}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(IoExactText, MeditPrintsTheShortestRoundTripForm) {
  const auto dir = test_temp_dir("io_exact_shortest");
  HexMesh m = fixture_brick(1, 1, 1);
  m.points[0] = {0.1, 1.0 / 3.0, -0.0};
  m.points[1] = {1e-300, 5e-324, 1.7976931348623157e308};
  m.points[2] = {1.0, -2.5, 1e23};
  const std::string path = (dir / "one.mesh").string();
  mesh_write(path, m);
  const std::string text = test_file_text(path);
  const std::string expected_head =
      "MeshVersionFormatted 2\nDimension 3\nVertices\n8\n"
      "0.1 0.3333333333333333 -0 0\n"
      "1e-300 5e-324 1.7976931348623157e+308 0\n"
      "1 -2.5 1e+23 0\n";
  EXPECT_EQ(text.substr(0, expected_head.size()), expected_head);
  EXPECT_NE(text.find("Hexahedra\n1\n1 2 4 3 5 6 8 7 0\nEnd\n"), std::string::npos) << text;
}

TEST(IoExactText, LargeFilesCrossTheWriterBufferExactly) {
  // 31^3 points: the MEDIT file (about 1.8 MB) and the binary VTK file (about 2 MB) both fill
  // the 1 MiB writer buffer more than once.
  const auto dir = test_temp_dir("io_exact_large");
  HexMesh m = fixture_brick(30, 30, 30);
  for (size_t i = 0; i < m.points.size(); ++i)
    m.points[i] += Eigen::Vector3d(std::sin(0.7 * static_cast<double>(i)),
                                   std::cos(1.1 * static_cast<double>(i)), 1.0 / (3.0 + i)) /
                   7.0;
  for (const auto& [file, binary] :
       {std::pair{"big.mesh", false}, std::pair{"big.vtk", true}, std::pair{"big.msh", false}}) {
    const std::string path = (dir / file).string();
    MeshWriteOptions options;
    options.binary = binary;
    mesh_write(path, m, options);
    EXPECT_GT(std::filesystem::file_size(path), io_detail::TextWriter::capacity) << file;
    const HexMesh r = mesh_read(path);
    io_expect_bit_exact_points(m, r);
  }
}

TEST(IoTextWriter, MatchesNaiveFormattingAcrossFlushes) {
  std::ostringstream out;
  std::string expected;
  io_detail::TextWriter w(out);
  auto naive_real = [&](double v) {
    char b[64];
    expected.append(b, std::to_chars(b, b + sizeof b, v).ptr);
  };
  // 300,000 numbers (several MiB) so that flushes fall at many different offsets in a number.
  for (int i = 0; i < 100000; ++i) {
    const double v = std::ldexp(1.0 + i / 7.0, (i % 200) - 100) * ((i & 1) ? -1 : 1);
    w.real(v).put(' ');
    naive_real(v);
    expected += ' ';
    const int64_t k = int64_t{i} * 2654435761 - 4000000000000;
    w.integer(k).text(", ");
    expected += std::to_string(k) + ", ";
    w.integer(INT64_MIN).put('\n');
    expected += std::to_string(INT64_MIN) + "\n";
  }
  // A text longer than the whole buffer.
  const std::string long_text(3 * io_detail::TextWriter::capacity + 17, 'x');
  w.text(long_text);
  expected += long_text;
  // Big-endian arrays crossing the buffer end.
  std::vector<double> d(200000);
  for (size_t i = 0; i < d.size(); ++i) d[i] = 1.0 / (1.0 + static_cast<double>(i));
  w.big_endian(d.data(), d.size());
  for (double v : d) {
    const auto u = std::bit_cast<uint64_t>(v);
    for (int b = 7; b >= 0; --b) expected.push_back(static_cast<char>((u >> (8 * b)) & 0xff));
  }
  const int32_t ints[3] = {1, -2, 0x01020304};
  w.big_endian(ints, 3);
  expected += std::string("\0\0\0\1\xff\xff\xff\xfe\1\2\3\4", 12);
  w.flush();
  const std::string got = out.str();
  ASSERT_EQ(got.size(), expected.size());
  EXPECT_TRUE(got == expected);
}

TEST(IoTextWriter, ReadBigEndianInvertsTheWriter) {
  std::ostringstream out;
  io_detail::TextWriter w(out);
  const double d = -1.0 / 3.0;
  const int16_t s = -12345;
  const uint64_t u = 0x0102030405060708ull;
  w.big_endian(&d, 1).big_endian(&s, 1).big_endian(&u, 1);
  w.flush();
  const std::string b = out.str();
  ASSERT_EQ(b.size(), 18u);
  EXPECT_EQ(b[10], '\x01');  // most significant byte first
  EXPECT_EQ(io_detail::read_big_endian<double>(b.data()), d);
  EXPECT_EQ(io_detail::read_big_endian<int16_t>(b.data() + 8), s);
  EXPECT_EQ(io_detail::read_big_endian<uint64_t>(b.data() + 10), u);
}

TEST(IoTextCursor, CountsTheNewlinesOfBinaryBlocksOfAnyLength) {
  // The byte-lane count against a plain one, across its 4,080-byte blocks and their tails, on
  // data that is all newlines (each lane at its 255 limit) and on random bytes.
  std::mt19937 random(7);
  std::string bytes(20000, '\n');
  for (int fill = 0; fill < 2; ++fill) {
    if (fill == 1)
      for (char& c : bytes) c = static_cast<char>(random());
    for (size_t n : {0, 1, 15, 16, 17, 4079, 4080, 4081, 8160, 12345, 20000}) {
      const size_t plain = static_cast<size_t>(std::count(bytes.begin(), bytes.begin() + n, '\n'));
      EXPECT_EQ(io_detail::bytes_count_newlines(bytes.data(), n), plain) << fill << " " << n;
    }
  }
  EXPECT_EQ(io_detail::bytes_count_newlines(std::string(20000, '\n').data(), 20000), 20000u);
}

TEST(IoReadAll, ReadsEmptyAndMultiPieceFilesWhole) {
  const auto dir = test_temp_dir("io_read_all");
  const auto empty = dir / "empty.txt";
  io_write_text(empty, "");
  EXPECT_EQ(io_detail::file_read_all(empty.string()), "");
  std::string big(300000, '\0');
  for (size_t i = 0; i < big.size(); ++i) big[i] = static_cast<char>(i * 7 + (i >> 9));
  const auto p = dir / "big.bin";
  io_write_text(p, big);
  EXPECT_TRUE(io_detail::file_read_all(p.string()) == big);
  EXPECT_THROW(io_detail::file_read_all((dir / "missing").string()), InputError);
}

TEST(HexBlocksGroup, GroupsByBlockIdAscendingWithDenseAndWideIds) {
  HexMesh m = fixture_brick(3, 2, 1);                                         // 6 hexes
  EXPECT_EQ(io_detail::hex_blocks_group(m, 5).ids, std::vector<int32_t>{5});  // no block_id
  auto& block = mesh_attribute(m, attribute_block_id);
  for (const std::vector<int32_t>& ids :
       {std::vector<int32_t>{2, -1, 2, -5, -1, 2},
        std::vector<int32_t>{INT32_MAX, -1, INT32_MAX, INT32_MIN, -1, INT32_MAX}}) {
    block = ids;  // the second spans 2^32 ids: the sorting path
    const io_detail::HexBlocks g = io_detail::hex_blocks_group(m, 0);
    ASSERT_EQ(g.ids.size(), 3u);
    EXPECT_EQ(g.ids, (std::vector<int32_t>{ids[3], ids[1], ids[0]}));
    EXPECT_EQ(g.order, (std::vector<int32_t>{3, 1, 4, 0, 2, 5}));
    EXPECT_EQ(g.starts, (std::vector<size_t>{0, 1, 3, 6}));
  }
  EXPECT_TRUE(io_detail::hex_blocks_group(HexMesh{}, 1).ids.empty());
}

TEST(IoFileBytes, MapsRegularFilesAndReadsPipes) {
  const auto dir = test_temp_dir("io_file_bytes");
  std::string big(300000, '\0');
  for (size_t i = 0; i < big.size(); ++i) big[i] = static_cast<char>(i * 11 + (i >> 7));
  const auto p = dir / "big.bin";
  io_write_text(p, big);
  EXPECT_TRUE(io_detail::FileBytes(p.string()).view() == big);
  {
    // Released pages of a mapping read back the same bytes (faulted in again from the file);
    // a slice outside the mapping, or of a copied file, is left alone.
    const io_detail::FileBytes mapped(p.string());
    mapped.release(mapped.view().substr(1000, 200000));
    mapped.release(mapped.view());
    mapped.release(std::string_view(big));
    EXPECT_TRUE(mapped.view() == big);
  }
  const auto empty = dir / "empty.bin";
  io_write_text(empty, "");
  EXPECT_EQ(io_detail::FileBytes(empty.string()).view(), "");
  try {
    io_detail::FileBytes missing((dir / "missing.mesh").string());
    FAIL() << "a missing file was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("missing.mesh"), std::string::npos) << e.what();
  }
  try {
    io_detail::FileBytes folder(dir.string());
    FAIL() << "a folder was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("it is a folder"), std::string::npos) << e.what();
  }
  // A pipe cannot be mapped: it is read from the descriptor FileBytes opened (opening it again
  // would wait for another writer), and mesh_read takes a mesh from it whole.
  const auto fifo = dir / "pipe.mesh";
  std::filesystem::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.string().c_str(), 0600), 0);
  const HexMesh brick = io_test_brick();
  const auto source = dir / "brick.mesh";
  mesh_write(source.string(), brick);
  const std::string text = io_detail::file_read_all(source.string());
  std::thread writer([&] { std::ofstream(fifo, std::ios::binary) << text; });
  HexMesh read;
  try {
    read = mesh_read(fifo.string());
  } catch (...) {
    std::ifstream release(fifo);  // lets a writer still waiting for a reader finish
    writer.join();
    throw;
  }
  writer.join();
  io_expect_same_geometry(brick, read, 0);
}

}  // namespace
}  // namespace hexrefine
