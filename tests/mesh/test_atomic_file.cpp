/// \file
/// mesh/atomic_file.hpp: a failed write never damages an existing good file and never leaves a
/// temporary file behind; a successful one replaces the file as a whole.

#include "mesh/atomic_file.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "cli_runner.hpp"
#include "fixtures.hpp"
#include "mesh/error.hpp"
#include "mesh/io.hpp"

namespace hexrefine {
namespace {

namespace fs = std::filesystem;

int folder_entries(const fs::path& dir) {
  int n = 0;
  for (const auto& e : fs::directory_iterator(dir)) n += static_cast<int>(!e.path().empty());
  return n;
}

TEST(AtomicFile, GoodFileSurvivesAWriterThatThrowsMidway) {
  const auto dir = test_temp_dir("atomic_throw");
  const fs::path p = dir / "report.json";
  file_write_atomically(p.string(), [](std::ostream& os) { os << "{\"good\": true}\n"; });
  ASSERT_EQ(test_file_text(p), "{\"good\": true}\n");
  // A writer that has already written 1 MB when it fails: the failure propagates unchanged.
  EXPECT_THROW(file_write_atomically(p.string(),
                                     [](std::ostream& os) {
                                       const std::string chunk(1024, 'x');
                                       for (int i = 0; i < 1024; ++i) os << chunk;
                                       throw std::runtime_error("writer failed");
                                     }),
               std::runtime_error);
  EXPECT_EQ(test_file_text(p), "{\"good\": true}\n");
  EXPECT_EQ(folder_entries(dir), 1);  // no temporary file left
}

TEST(AtomicFile, GoodMeshSurvivesAFailedMeshWrite) {
  const auto dir = test_temp_dir("atomic_mesh");
  for (const char* name : {"m.mesh", "m.vtk", "m.vtu", "m.msh", "m.e", "m.inp"}) {
    const fs::path p = dir / name;
    mesh_write(p.string(), fixture_brick(2, 1, 1));
    const std::string good = test_file_text(p);
    ASSERT_FALSE(good.empty());
    // A mesh the writer refuses (a hex names node 99 of 12): InputError, the old file stays.
    HexMesh bad = fixture_brick(2, 1, 1);
    bad.hexes[1][3] = 99;
    EXPECT_THROW(mesh_write(p.string(), bad), InputError) << name;
    EXPECT_EQ(test_file_text(p), good) << name;
    EXPECT_EQ(mesh_read(p.string()).hex_count(), 2) << name;
  }
  EXPECT_EQ(folder_entries(dir), 6);
}

TEST(AtomicFile, SuccessfulWriteReplacesTheWholeFile) {
  const auto dir = test_temp_dir("atomic_replace");
  const fs::path p = dir / "a.txt";
  file_write_atomically(p.string(), [](std::ostream& os) { os << std::string(5000, 'a'); });
  file_write_atomically(p.string(), [](std::ostream& os) { os << "short\n"; });
  EXPECT_EQ(test_file_text(p), "short\n");
  EXPECT_EQ(folder_entries(dir), 1);
}

TEST(AtomicFile, MissingFolderIsOperationErrorNamingThePath) {
  const auto dir = test_temp_dir("atomic_missing");
  const std::string p = (dir / "nowhere" / "a.txt").string();
  try {
    file_write_atomically(p, [](std::ostream& os) { os << "x"; });
    FAIL() << "wrote into a missing folder";
  } catch (const OperationError& e) {
    EXPECT_NE(std::string(e.what()).find(p), std::string::npos) << e.what();
  }
  EXPECT_EQ(folder_entries(dir), 0);
}

}  // namespace
}  // namespace hexrefine
