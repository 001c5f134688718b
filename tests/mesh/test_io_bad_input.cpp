// Bad input of every kind and in every format must end in an InputError naming the file: random
// bytes, truncated and corrupted copies of real files, huge counts. Never a crash, never another
// exception type, never a mesh that silently lost hexes (except where the format itself has no
// counts: an Abaqus file cut at a line end is a valid, smaller file).

#include <gtest/gtest.h>

#include <fstream>
#include <random>

#include "cli_runner.hpp"
#include "io_test_support.hpp"
#include "mesh/error.hpp"
#include "mesh/io.hpp"

namespace hexrefine {
namespace {

const char* const io_extensions[] = {".mesh", ".vtk", ".vtu", ".msh", ".e", ".inp"};

std::string io_file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

/// Reads `path`; returns the hex count, or -1 after an InputError that names the file. Any other
/// exception fails the test.
int io_read_or_refuse(const std::string& path) {
  try {
    return mesh_read(path).hex_count();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    return -1;
  } catch (const std::exception& e) {
    ADD_FAILURE() << path << ": not an InputError: " << e.what();
    return -2;
  }
}

TEST(IoBadInput, RandomBytesAreRefusedInEveryFormat) {
  const auto dir = test_temp_dir("io_bad_random");
  std::mt19937 rng(12345);
  const std::string prefixes[] = {
      "",
      "MeshVersionFormatted 1\nDimension 3\nVertices\n",
      "# vtk DataFile Version 3.0\nx\nBINARY\nDATASET UNSTRUCTURED_GRID\nPOINTS ",
      "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n",
      "CDF\x01",
      "*NODE\n"};
  int refused = 0, runs = 0;
  for (const char* ext : io_extensions)
    for (int i = 0; i < 60; ++i) {
      std::string bytes = prefixes[i % 6];
      const int n = static_cast<int>(rng() % 3000);
      for (int k = 0; k < n; ++k) bytes.push_back(static_cast<char>(rng() & 0xff));
      std::string name = "r";
      name += std::to_string(i);
      name += ext;
      const std::string p = (dir / name).string();
      io_write_text(p, bytes);
      ++runs;
      if (io_read_or_refuse(p) == -1) ++refused;
    }
  EXPECT_EQ(refused, runs);
}

TEST(IoBadInput, TruncatedAndCorruptedCopiesNeverCrashOrLoseHexes) {
  const auto dir = test_temp_dir("io_bad_truncated");
  const HexMesh original = mesh_read(shared_mesh("sphere_conforming.mesh"));
  HexMesh m = original;
  mesh_attribute(m, attribute_template_tag, 3);
  std::mt19937 rng(777);
  for (const char* ext : io_extensions)
    for (bool binary : {false, true}) {
      if (binary && std::string(ext) != ".vtk") continue;
      const std::string good = (dir / (std::string("good") + (binary ? "b" : "") + ext)).string();
      MeshWriteOptions o;
      o.binary = binary;
      mesh_write(good, m, o);
      const std::string bytes = io_file_bytes(good);
      int refused = 0;
      for (int i = 0; i < 40; ++i) {
        const size_t cut = i < 20 ? bytes.size() * i / 20 : rng() % bytes.size();
        const std::string p = (dir / ("cut" + std::to_string(i) + ext)).string();
        io_write_text(p, bytes.substr(0, cut));
        const int hexes = io_read_or_refuse(p);
        if (hexes == -1)
          ++refused;
        else if (std::string(ext) == ".inp")
          EXPECT_LE(hexes, m.hex_count()) << p;
        else
          EXPECT_EQ(hexes, m.hex_count()) << p << " cut at " << cut << " of " << bytes.size();
      }
      EXPECT_GE(refused, 20) << ext;  // most cuts must be refused
      for (int i = 0; i < 40; ++i) {
        std::string corrupt = bytes;
        for (int k = 0; k < 1 + i % 4; ++k)
          corrupt[rng() % corrupt.size()] = static_cast<char>(rng() & 0xff);
        const std::string p = (dir / ("flip" + std::to_string(i) + ext)).string();
        io_write_text(p, corrupt);
        io_read_or_refuse(p);  // may be accepted (a changed digit is still a mesh); must not crash
      }
    }
}

TEST(IoBadInput, HugeCountsAreRefusedBeforeAllocating) {
  const auto dir = test_temp_dir("io_bad_huge");
  const std::pair<const char*, std::string> cases[] = {
      {".mesh", "MeshVersionFormatted 1\nDimension 3\nVertices\n1000000000000\n0 0 0 0\n"},
      {".mesh", "MeshVersionFormatted 1\nDimension 3\nVertices\n2000000000\n0 0 0 0\n"},
      {".vtk",
       "# vtk DataFile Version 3.0\nx\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 1000000000000 "
       "double\n0 0 0\n"},
      {".vtk",
       "# vtk DataFile Version 3.0\nx\nBINARY\nDATASET UNSTRUCTURED_GRID\nPOINTS 500000000 "
       "double\n0 0 0\n"},
      {".vtu",
       "<VTKFile type=\"UnstructuredGrid\"><UnstructuredGrid><Piece "
       "NumberOfPoints=\"1000000000000\" NumberOfCells=\"1\">"},
      {".msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n1000000000000\n1 0 0 0\n"},
      {".msh", "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Elements\n1 1000000000 1 1\n"},
  };
  int i = 0;
  for (const auto& [ext, text] : cases) {
    const std::string p = (dir / ("huge" + std::to_string(i++) + ext)).string();
    io_write_text(p, text);
    EXPECT_EQ(io_read_or_refuse(p), -1) << text;
  }
}

TEST(IoBadInput, NonManifoldMeshIsRefusedNamingAFace) {
  const auto dir = test_temp_dir("io_bad_nonmanifold");
  HexMesh m = fixture_brick(1, 1, 2);
  // A third hex on the face between the two: 4 new top nodes above the shared face.
  const HexCell& lower = m.hexes[0];
  HexCell extra;
  for (int k = 0; k < 4; ++k) {
    extra[k] = lower[4 + k];
    m.points.push_back(m.points[lower[4 + k]] + Eigen::Vector3d(0.1, 0.1, 0.5));
    extra[4 + k] = m.point_count() - 1;
  }
  m.hexes.push_back(extra);
  const std::string p = (dir / "nm.mesh").string();
  mesh_write(p, m);
  try {
    mesh_read(p);
    FAIL() << "non-manifold mesh accepted";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("nm.mesh"), std::string::npos) << msg;
    EXPECT_NE(msg.find("non-manifold"), std::string::npos) << msg;
    EXPECT_NE(msg.find("face with nodes"), std::string::npos) << msg;
  }
}

}  // namespace
}  // namespace hexrefine
