#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "mesh/generators.hpp"
#include "tests/cli_runner.hpp"

#if __has_include("mesh/io.hpp")
#include "mesh/io.hpp"
#define HEXREFINE_HAVE_IO 1
#endif

namespace hexrefine {
namespace {

TEST(CliGenerate, BadUsageExitsTwoAndWritesNothing) {
  const auto dir = test_temp_dir("cli_generate_bad");
  const std::string out = (dir / "b.vtk").string();
  const struct {
    const char* args;
    const char* message;
  } cases[] = {
      {"brick OUT --dims 2,0,2", "dims NY"},
      {"brick OUT --dims 2,2", "--dims"},
      {"brick OUT --dims 2,x,2", "--dims"},
      {"brick OUT", "--dims"},
      {"brick OUT --dims 2,2,2 --jitter 0.5", "jitter"},
      {"brick OUT --dims 2,2,2 --seed -3", "--seed"},
      {"brick OUT --dims 2,2,2 --size 1,0,1", "size LY"},
      {"brick OUT --dims 2,2,2 --bogus 1", "--bogus"},
      {"brick OUT --dims 2147483647,2147483647,2147483647", "32-bit ids"},
      {"brick --dims 2,2,2", "output path"},
      {"gear OUT --radii 1,0.5,2", "root_radius"},
      {"cylinder OUT --intervals 0,3", "square_intervals"},
      {"twisted-ring OUT --around 4", "around"},
      {"stepped OUT --tread 0", "tread"},
      {"sphere OUT", "unknown kind"},
  };
  for (const auto& c : cases) {
    std::string args = std::string("generate ") + c.args;
    if (const size_t at = args.find("OUT"); at != std::string::npos) args.replace(at, 3, out);
    const CliRun r = cli_run(args);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.output;
    EXPECT_NE(r.output.find(c.message), std::string::npos) << args << "\n" << r.output;
    EXPECT_FALSE(std::filesystem::exists(out)) << args;
  }
  EXPECT_EQ(cli_run("generate").exit_code, 2);
  const CliRun help = cli_run("generate --help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.output.find("twisted-ring"), std::string::npos);
}

TEST(CliGenerate, WritesReadableMeshes) {
#ifndef HEXREFINE_HAVE_IO
  GTEST_SKIP() << "mesh/io.hpp (mesh_write/mesh_read) has not landed yet";
#else
  const auto dir = test_temp_dir("cli_generate_ok");
  const struct {
    std::string args;
    int32_t hexes;
  } cases[] = {
      {"brick OUT --dims 3,4,5 --size 3,2,1 --jitter 0.3 --seed 9", 60},
      {"gear OUT", 8568},
      {"gear OUT --teeth 5 --intervals 2,2,2,3 --layers 2", 2 * 5 * (5 * 2 + 2 * 2)},
      {"cylinder OUT --intervals 2,1 --layers 3", 3 * (4 + 4 * 2)},
      {"twisted-ring OUT --around 8", 8},
      {"stepped OUT", 1188},
  };
  int i = 0;
  for (const auto& c : cases) {
    const std::string out = (dir / ("m" + std::to_string(i++) + ".vtk")).string();
    std::string args = "generate " + c.args;
    args.replace(args.find("OUT"), 3, out);
    const CliRun r = cli_run(args);
    ASSERT_EQ(r.exit_code, 0) << args << "\n" << r.output;
    const HexMesh m = mesh_read(out);
    EXPECT_EQ(m.hex_count(), c.hexes) << args;
  }
  // The file holds exactly the generator's mesh.
  BrickParams p;
  p.dims = {3, 4, 5};
  p.size = {3, 2, 1};
  p.jitter = 0.3;
  p.seed = 9;
  const HexMesh expected = generate_brick(p);
  const HexMesh m = mesh_read((dir / "m0.vtk").string());
  EXPECT_EQ(m.hexes, expected.hexes);
  ASSERT_EQ(m.point_count(), expected.point_count());
  for (int32_t n = 0; n < m.point_count(); ++n)
    EXPECT_TRUE(m.points[n].isApprox(expected.points[n], 1e-12)) << n;
#endif
}

}  // namespace
}  // namespace hexrefine
