/// \file
/// Robustness of the readers (mesh/io*.cpp): the in-memory entry point mesh_read_from_memory
/// agrees with mesh_read; a header that claims 10^12 items is refused with an InputError before
/// anything is allocated (one case per format; a std::bad_alloc or length_error would fail the
/// test); and every input the fuzzers (tests/fuzz/) found crashing, hanging or over-allocating is
/// kept in tests/fuzz/crashes/<format>/ and must now be refused with an InputError.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "io_test_support.hpp"
#include "mesh/error.hpp"
#include "mesh/io.hpp"

namespace hexrefine {
namespace {

/// The InputError message of reading `bytes` as `name`; fails the test if the bytes are accepted
/// or end in any other exception.
std::string refusal_of(const std::string& name, const std::string& bytes) {
  try {
    const HexMesh m = mesh_read_from_memory(name, bytes);
    ADD_FAILURE() << name << ": accepted (" << m.hex_count() << " hexes)";
  } catch (const InputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << name << ": not an InputError: " << e.what();
  }
  return "";
}

TEST(IoFuzzRegressions, MemoryReaderMatchesFileReaderInEveryFormat) {
  const auto dir = test_temp_dir("io_fuzz_memory");
  const HexMesh m = io_test_brick();
  for (const char* name : {"m.mesh", "m.vtk", "m.vtu", "m.msh", "m.e", "m.inp"}) {
    const std::string p = (dir / name).string();
    mesh_write(p, m);
    const HexMesh from_file = mesh_read(p);
    const HexMesh from_memory = mesh_read_from_memory(name, test_file_text(p));
    SCOPED_TRACE(name);
    EXPECT_EQ(from_memory.hex_count(), 12);
    io_expect_same_geometry(from_file, from_memory, 0.0);
    ASSERT_EQ(from_file.attributes.size(), from_memory.attributes.size());
    for (size_t a = 0; a < from_file.attributes.size(); ++a)
      EXPECT_EQ(from_file.attributes[a].values, from_memory.attributes[a].values);
  }
  // The Exodus path goes through a temporary file; it must be gone afterwards (also when the
  // read fails) and the message must name the caller's source, not the temporary file.
  // A private temporary folder (TMPDIR) so that other processes (parallel tests, fuzzers) writing
  // their own temporary files cannot disturb the count.
  const auto private_tmp = std::filesystem::temp_directory_path() / "hexrefine_test_memory_tmp";
  std::filesystem::remove_all(private_tmp);
  std::filesystem::create_directories(private_tmp);
  const char* old_tmpdir = std::getenv("TMPDIR");
  const std::string saved = old_tmpdir ? old_tmpdir : "";
  ::setenv("TMPDIR", private_tmp.c_str(), 1);
  auto memory_files = [&] {
    int n = 0;
    for (const auto& e : std::filesystem::directory_iterator(private_tmp))
      n += e.path().filename().string().rfind("hexrefine_memory_", 0) == 0;
    return n;
  };
  const std::string msg = refusal_of("given.e", "CDF\x02 truncated");
  const int left = memory_files();
  if (old_tmpdir)
    ::setenv("TMPDIR", saved.c_str(), 1);
  else
    ::unsetenv("TMPDIR");
  EXPECT_EQ(msg.rfind("given.e: ", 0), 0u) << msg;
  EXPECT_EQ(left, 0);
  EXPECT_NE(refusal_of("given.stl", "solid").find("unknown mesh format"), std::string::npos);
}

/// One header per format and count that claims 10^12 (or, where the field is 32-bit, 2^31 - 1)
/// items in a file of a few bytes.
TEST(IoFuzzRegressions, HugeClaimedCountsAreRefusedBeforeAllocatingInEveryFormat) {
  const std::string medit = "MeshVersionFormatted 2\nDimension 3\n";
  const std::string vtk_head = "# vtk DataFile Version 3.0\nx\nASCII\nDATASET UNSTRUCTURED_GRID\n";
  const std::string vtk_bin_head =
      "# vtk DataFile Version 3.0\nx\nBINARY\nDATASET UNSTRUCTURED_GRID\n";
  const std::string vtk_points =
      "POINTS 8 double\n0 0 0 1 0 0 1 1 0 0 1 0 0 0 1 1 0 1 1 1 1 0 1 1\n";
  const std::string gmsh22 = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n";
  const std::string gmsh41 = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
  struct Case {
    const char* name;
    std::string bytes;
    const char* expected;  ///< part of the message
  };
  const Case cases[] = {
      {"vertices.mesh", medit + "Vertices\n1000000000000\n0 0 0 0\n", "vertex count 1000000000000"},
      {"hexahedra.mesh", medit + "Vertices\n1\n0 0 0 0\nHexahedra\n1000000000000\n1 1",
       "hexahedron count 1000000000000"},
      {"quads.mesh", medit + "Quadrilaterals\n1000000000000\n1 2 3 4 0\n",
       "Quadrilaterals count 1000000000000"},
      {"points.vtk", vtk_head + "POINTS 1000000000000 double\n0 0 0\n", "1000000000000"},
      {"cells.vtk",
       vtk_head + vtk_points + "CELLS 1000000000000 9000000000000\n8 0 1 2 3 4 5 6 7\n",
       "1000000000000"},
      {"types.vtk",
       vtk_head + vtk_points + "CELLS 1 9\n8 0 1 2 3 4 5 6 7\nCELL_TYPES 1000000000000\n12\n",
       "1000000000000"},
      {"points_binary.vtk", vtk_bin_head + "POINTS 1000000000000 double\n\x01\x02",
       "1000000000000"},
      {"points.vtu",
       "<VTKFile type=\"UnstructuredGrid\"><UnstructuredGrid><Piece "
       "NumberOfPoints=\"1000000000000\" "
       "NumberOfCells=\"1\">",
       "larger than the file"},
      {"cells.vtu",
       "<VTKFile type=\"UnstructuredGrid\"><UnstructuredGrid><Piece NumberOfPoints=\"8\" "
       "NumberOfCells=\"1000000000000\">",
       "larger than the file"},
      {"nodes22.msh", gmsh22 + "$Nodes\n1000000000000\n1 0 0 0\n", "1000000000000"},
      {"elements22.msh", gmsh22 + "$Nodes\n1\n1 0 0 0\n$EndNodes\n$Elements\n1000000000000\n",
       "1000000000000"},
      {"nodes41.msh", gmsh41 + "$Nodes\n1 1000000000000 1 1000000000000\n", "1000000000000"},
      {"elements41.msh",
       gmsh41 + "$Nodes\n0 0 0 0\n$EndNodes\n$Elements\n1 1000000000000 1 1000000000000\n",
       "1000000000000"},
      {"block41.msh", gmsh41 + "$Nodes\n1 1 1 1\n3 1 0 1000000000000\n1\n0 0 0\n", "1000000000000"},
      {"elset_range.inp",
       "*NODE\n1, 0, 0, 0\n*ELSET, ELSET=BLOCK_1, GENERATE\n1, 1000000000000, 1\n",
       "bad ELSET GENERATE range"},
  };
  for (const Case& c : cases) {
    const std::string msg = refusal_of(c.name, c.bytes);
    EXPECT_EQ(msg.rfind(c.name, 0), 0u) << c.name << ": message must name the source: " << msg;
    EXPECT_NE(msg.find(c.expected), std::string::npos) << c.name << ": " << msg;
  }
}

TEST(IoFuzzRegressions, AbaqusGenerateRowsCannotAllocateQuadratically) {
  // Each row alone is within the per-row bound (a range no longer than the file), but 2,000 of
  // them used to list 2,000 x file-size ids (about 2 GB of ids for a 100 KB file).
  std::string text = "*NODE\n1, 0, 0, 0\n*ELSET, ELSET=BLOCK_1, GENERATE\n";
  const std::string row = "1, 40000, 1\n";
  for (int i = 0; i < 4000; ++i) text += row;
  const std::string msg = refusal_of("sets.inp", text);
  EXPECT_NE(msg.find("ELSET GENERATE rows list"), std::string::npos) << msg;
  EXPECT_NE(msg.find("sets.inp:"), std::string::npos) << msg;
}

TEST(IoFuzzRegressions, ExodusHeaderClaimingHugeCountsIsRefused) {
  const auto dir = test_temp_dir("io_fuzz_exodus");
  const std::string p = (dir / "b.e").string();
  mesh_write(p, fixture_brick(1, 1, 1));
  const std::string good = test_file_text(p);
  ASSERT_EQ(mesh_read_from_memory("b.e", good).hex_count(), 1);
  // netCDF classic header: a dimension is its name (padded to 4 bytes) and a 32-bit big-endian
  // length. Set num_nodes / num_elem to 2^31 - 1 (the largest the format holds).
  for (const std::string dim : {"num_nodes", "num_elem"}) {
    std::string bytes = good;
    std::string key(4, '\0');
    key[3] = static_cast<char>(dim.size());
    key += dim;
    key.append((4 - dim.size() % 4) % 4, '\0');
    const size_t at = bytes.find(key);
    ASSERT_NE(at, std::string::npos) << dim;
    bytes.replace(at + key.size(), 4, std::string("\x7f\xff\xff\xff", 4));
    const std::string msg = refusal_of("huge_" + dim + ".e", bytes);
    EXPECT_EQ(msg.rfind("huge_" + dim + ".e: ", 0), 0u) << msg;
  }
}

/// Every file in tests/fuzz/crashes/<format>/ once crashed a reader, over-allocated or hung under
/// the fuzzers; its extension gives the format. Now each must be refused with an InputError.
TEST(IoFuzzRegressions, EveryCommittedFuzzFindingIsRefused) {
  const std::filesystem::path root =
      std::filesystem::path(HEXREFINE_SOURCE_DIR) / "tests/fuzz/crashes";
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(root))
    if (entry.is_regular_file() && entry.path().filename() != "README.md")
      files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  ASSERT_FALSE(files.empty()) << root;
  for (const auto& f : files) {
    SCOPED_TRACE(f.string());
    EXPECT_THROW(mesh_read(f.string()), InputError);
    const std::string msg = refusal_of(f.filename().string(), test_file_text(f.string()));
    EXPECT_FALSE(msg.empty());
  }
}

}  // namespace
}  // namespace hexrefine
