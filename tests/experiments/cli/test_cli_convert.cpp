#include <gtest/gtest.h>

#include <fstream>
#include <iterator>

#include "cli_runner.hpp"
#include "mesh/io.hpp"
#include "mesh/quality.hpp"

namespace hexrefine {
namespace {

TEST(CliConvert, ConvertsSharedMeshToEveryFormat) {
  const auto dir = test_temp_dir("cli_convert_all");
  for (const char* ext : {".vtk", ".vtu", ".msh", ".e", ".inp", ".mesh"}) {
    const std::string out = (dir / (std::string("rocker") + ext)).string();
    const CliRun r = cli_run("convert " + shared_mesh("rockerarm.mesh") + " " + out);
    ASSERT_EQ(r.exit_code, 0) << ext << ": " << r.output;
    EXPECT_NE(r.output.find("10600 hexes"), std::string::npos) << r.output;
    EXPECT_EQ(mesh_read(out).hex_count(), 10600) << ext;
  }
  for (const char* ext : {".vtk", ".msh"}) {
    const std::string bin = (dir / (std::string("rocker_bin") + ext)).string();
    const CliRun r = cli_run("convert " + shared_mesh("rockerarm.mesh") + " " + bin + " --binary");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const HexMesh binary = mesh_read(bin);
    EXPECT_EQ(binary.hex_count(), 10600) << ext;
    EXPECT_EQ(binary.points, mesh_read(shared_mesh("rockerarm.mesh")).points) << ext;
  }
  std::ifstream msh((dir / "rocker_bin.msh").string(), std::ios::binary);
  std::string head(20, ' ');
  msh.read(head.data(), 20);
  EXPECT_EQ(head, "$MeshFormat\n4.1 1 8\n");
}

/// The values of the double cell array `name` in an ASCII VTK legacy file written by hexrefine.
std::vector<double> vtk_cell_doubles(const std::string& path, const std::string& name) {
  std::ifstream in(path);
  std::string word;
  while (in >> word)
    if (word == "SCALARS" && (in >> word) && word == name) break;
  std::vector<double> out;
  std::string type, lookup, table;
  in >> type >> word >> lookup >> table;  // "double 1 LOOKUP_TABLE default"
  double v;
  while (in >> v) out.push_back(v);
  return out;
}

TEST(CliConvert, VtkOutputCarriesScaledJacobian) {
  const auto dir = test_temp_dir("cli_convert_quality");
  const std::string out = (dir / "sphere.vtk").string();
  const CliRun r = cli_run("convert " + shared_mesh("sphere_projected_inverted.mesh") + " " + out);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const HexMesh m = mesh_read(shared_mesh("sphere_projected_inverted.mesh"));
  const std::vector<double> expected = mesh_scaled_jacobians(m);
  const std::vector<double> written = vtk_cell_doubles(out, "scaled_jacobian");
  ASSERT_EQ(written.size(), 111u);
  for (size_t h = 0; h < written.size(); ++h) EXPECT_EQ(written[h], expected[h]) << h;
  int bad = 0;
  for (double q : written) bad += q <= 0;
  EXPECT_EQ(bad, 76);  // the README: 76 of its hexes are inverted or degenerate
}

TEST(CliConvert, VtuEncodingSwitches) {
  const auto dir = test_temp_dir("cli_convert_vtu");
  const std::string in = shared_mesh("rockerarm.mesh");
  const std::string zlib = (dir / "z.vtu").string(), text = (dir / "t.vtu").string();
  ASSERT_EQ(cli_run("convert " + in + " " + zlib + " --compress").exit_code, 0);
  ASSERT_EQ(cli_run("convert " + in + " " + text + " --ascii").exit_code, 0);
  std::ifstream z(zlib, std::ios::binary), t(text, std::ios::binary);
  const std::string zs{std::istreambuf_iterator<char>(z), std::istreambuf_iterator<char>()};
  const std::string ts{std::istreambuf_iterator<char>(t), std::istreambuf_iterator<char>()};
  EXPECT_NE(zs.find("compressor=\"vtkZLibDataCompressor\""), std::string::npos);
  EXPECT_NE(ts.find("format=\"ascii\""), std::string::npos);
  EXPECT_EQ(mesh_read(zlib).hex_count(), 10600);
  EXPECT_EQ(mesh_read(text).hex_count(), 10600);
  // The switches belong to their formats and exclude each other.
  const CliRun wrong = cli_run("convert " + in + " " + (dir / "x.vtk").string() + " --compress");
  EXPECT_EQ(wrong.exit_code, 2);
  EXPECT_NE(wrong.output.find(".vtu output only"), std::string::npos) << wrong.output;
  EXPECT_EQ(cli_run("convert " + in + " " + zlib + " --ascii --compress").exit_code, 2);
}

TEST(CliConvert, BadInputExitsTwoNamingTheFile) {
  const auto dir = test_temp_dir("cli_convert_bad");
  const auto bad = dir / "broken.mesh";
  std::ofstream(bad) << "MeshVersionFormatted 1\nDimension 3\nVertices\n2\n0 0 0 0\n";
  const std::string out = (dir / "out.vtk").string();
  CliRun r = cli_run("convert " + bad.string() + " " + out);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("broken.mesh"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(out));
  r = cli_run("convert " + shared_mesh("sphere_conforming.mesh") + " " + (dir / "x.stl").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("x.stl"), std::string::npos) << r.output;
  r = cli_run("convert " + shared_mesh("sphere_conforming.mesh"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  r = cli_run("convert " + shared_mesh("sphere_conforming.mesh") + " " + (dir / "x.vtu").string() +
              " --binary");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--binary applies to .vtk and .msh output only"), std::string::npos)
      << r.output;
  r = cli_run("convert " + (dir / "missing.mesh").string() + " " + out);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("missing.mesh"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace hexrefine
