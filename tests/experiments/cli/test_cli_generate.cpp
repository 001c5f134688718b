#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "mesh/generators.hpp"
#include "tests/cli_runner.hpp"

#include "mesh/io.hpp"

namespace hexrefine {
namespace {

// "generate ARGS" with the word OUT (if any) replaced by `out`.
std::string generate_args(const std::string& args, const std::string& out) {
  std::string result = "generate ";
  const size_t at = args.find("OUT");
  if (at == std::string::npos) return result + args;
  result.append(args, 0, at);
  result += out;
  result.append(args, at + 3, std::string::npos);
  return result;
}

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
      {"brick OUT --dims 2,2,2 --jitter 0.5", "jitter"},
      {"brick OUT --dims 2,2,2 --seed -3", "--seed"},
      {"brick OUT --dims 2,2,2 --size 1,0,1", "size LY"},
      {"brick OUT --dims 2,2,2 --bogus 1", "--bogus"},
      {"brick OUT --dims 2147483647,2147483647,2147483647", "32-bit ids"},
      {"brick --dims 2,2,2", "output path"},
      {"gear OUT --inner-radius 1 --root-radius 0.5 --tip-radius 2", "root_radius"},
      {"gear OUT --radii 1,0.5,2", "--radii"},
      {"gear OUT --teeth 2.5", "--teeth"},
      {"cylinder OUT --square-intervals 0 --radial-intervals 3", "square_intervals"},
      {"twisted-ring OUT --around 4", "around"},
      {"stepped OUT --tread 0", "tread"},
      {"sphere OUT", "unknown kind"},
      {"twisted_ring OUT --around 4", "around"},
  };
  for (const auto& c : cases) {
    const std::string args = generate_args(c.args, out);
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
  const auto dir = test_temp_dir("cli_generate_ok");
  const struct {
    std::string args;
    int32_t hexes;
  } cases[] = {
      {"brick OUT --dims 3,4,5 --size 3,2,1 --jitter 0.3 --seed 9", 60},
      {"gear OUT", 8568},
      {"gear OUT --teeth 5 --body-radial 2 --tooth-radial 2 --tooth-tangential 2 "
       "--gap-tangential 3 --layers 2",
       2 * 5 * (5 * 2 + 2 * 2)},
      {"cylinder OUT --square-intervals 2 --radial-intervals 1 --layers 3", 3 * (4 + 4 * 2)},
      {"brick OUT", 1},
      {"twisted-ring OUT --around 8", 8},
      {"stepped OUT", 1188},
  };
  int i = 0;
  for (const auto& c : cases) {
    std::string name = "m";
    name += std::to_string(i++);
    name += ".vtk";
    const std::string out = (dir / name).string();
    const std::string args = generate_args(c.args, out);
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
}

}  // namespace
}  // namespace hexrefine
