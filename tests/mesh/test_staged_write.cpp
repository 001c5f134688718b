/// \file
/// mesh/staged_write.hpp: the mesh becomes the output only on commit(); without one nothing is
/// left (an existing file stays as it was); the writer's errors name the output, not the
/// staging file.

#include "mesh/staged_write.hpp"

#include <gtest/gtest.h>

#include <filesystem>

#include "cli_runner.hpp"
#include "fixtures.hpp"
#include "mesh/error.hpp"
#include "mesh/io.hpp"

namespace hexrefine {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> folder_names(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

TEST(StagedMeshWrite, OutputAppearsOnlyOnCommitWithTheBytesOfMeshWrite) {
  const auto dir = test_temp_dir("staged_commit");
  const HexMesh m = fixture_brick(3, 2, 2);
  const MeshWriteOptions options;  // outlives the writers
  for (const char* name : {"m.vtu", "m.e", "m.msh"}) {
    SCOPED_TRACE(name);
    const fs::path direct = dir / ("direct" + fs::path(name).extension().string());
    mesh_write(direct.string(), m);
    const fs::path out = dir / name;
    StagedMeshWrite staged(out.string(), m, options);
    staged.finish();
    EXPECT_FALSE(fs::exists(out));  // written, not yet committed
    staged.commit();
    ASSERT_TRUE(fs::exists(out));
    if (fs::path(name).extension() != ".e") {  // Exodus files carry their creation time
      EXPECT_EQ(test_file_text(out), test_file_text(direct));
    }
    EXPECT_EQ(mesh_read(out.string()).hexes, m.hexes);
    EXPECT_GT(staged.seconds(), 0.0);
  }
  EXPECT_EQ(folder_names(dir), (std::vector<std::string>{"direct.e", "direct.msh", "direct.vtu",
                                                         "m.e", "m.msh", "m.vtu"}));
}

TEST(StagedMeshWrite, WithoutCommitTheOldFileStaysAndNothingIsLeft) {
  const auto dir = test_temp_dir("staged_abandon");
  const fs::path out = dir / "m.vtu";
  mesh_write(out.string(), fixture_brick(1, 1, 1));
  const std::string good = test_file_text(out);
  {
    const HexMesh m = fixture_brick(4, 4, 4);
    const MeshWriteOptions options;
    StagedMeshWrite staged(out.string(), m, options);
    // Destroyed while (or after) writing: the verdict refused the mesh, or something threw.
  }
  EXPECT_EQ(test_file_text(out), good);
  EXPECT_EQ(folder_names(dir), std::vector<std::string>{"m.vtu"});
}

TEST(StagedMeshWrite, WriterErrorsNameTheOutputAndKeepTheirKind) {
  const auto dir = test_temp_dir("staged_error");
  const fs::path out = dir / "m.vtk";
  HexMesh bad = fixture_brick(2, 1, 1);
  bad.hexes[1][3] = 99;  // a node the mesh does not have
  const MeshWriteOptions options;
  StagedMeshWrite staged(out.string(), bad, options);
  try {
    staged.finish();
    FAIL() << "wrote a mesh with a bad node id";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(out.string() + ":"), std::string::npos) << message;
    EXPECT_EQ(message.find(".staged"), std::string::npos) << message;
  }
  EXPECT_TRUE(folder_names(dir).empty());
}

}  // namespace
}  // namespace hexrefine
