#include <gtest/gtest.h>

#include "cli_runner.hpp"
#include "io_test_support.hpp"
#include "mesh/error.hpp"
#include "mesh/io.hpp"

namespace hexrefine {
namespace {

TEST(IoMedit, RoundTripKeepsPointsCellsAndBlockId) {
  const auto dir = test_temp_dir("io_medit_roundtrip");
  const HexMesh m = io_test_brick();
  const std::string path = (dir / "brick.mesh").string();
  mesh_write(path, m);
  const HexMesh r = mesh_read(path);
  io_expect_same_geometry(m, r, 1e-12);
  io_expect_same_geometry(m, r, 0);  // shortest round-trip digits: exact
  io_expect_same_attribute(m, r, attribute_block_id);
  EXPECT_EQ(mesh_find_attribute(r, attribute_template_tag), nullptr);  // MEDIT has one tag only
}

TEST(IoMedit, ReadsSharedMeshesWithReadmeHexCounts) {
  const std::pair<const char*, int> cases[] = {
      {"ellipsoid.mesh", 6816},
      {"rockerarm.mesh", 10600},
      {"bunny_conforming.mesh", 26253},
      {"bunny_voxel.mesh", 17088},
      {"cube_minus_sphere_conforming.mesh", 9919},
      {"sphere_conforming.mesh", 125},
      {"sphere_projected_inverted.mesh", 111},
  };
  for (const auto& [name, hexes] : cases) {
    const HexMesh m = mesh_read(shared_mesh(name));
    EXPECT_EQ(m.hex_count(), hexes) << name;
  }
  const HexMesh rocker = mesh_read(shared_mesh("rockerarm.mesh"));
  EXPECT_EQ(rocker.point_count(), 12751);  // its Quadrilaterals section is skipped
  const HexMesh sphere = mesh_read(shared_mesh("sphere_conforming.mesh"));
  EXPECT_EQ(sphere.point_count(), 216);
}

TEST(IoMedit, SkipsTheShortQuadsSpellingOfTheSurfaceSection) {
  const auto dir = test_temp_dir("io_medit_quads");
  const auto p = dir / "quads.mesh";
  io_write_text(p,
                "MeshVersionFormatted 1\nDimension 3\nVertices\n8\n0 0 0 0\n1 0 0 0\n1 1 0 0\n"
                "0 1 0 0\n0 0 1 0\n1 0 1 0\n1 1 1 0\n0 1 1 0\nQuads\n1\n1 2 3 4 7\n"
                "Hexahedra\n1\n1 2 3 4 5 6 7 8 3\nEnd\n");
  const HexMesh m = mesh_read(p.string());
  EXPECT_EQ(m.hex_count(), 1);
  EXPECT_EQ(m.point_count(), 8);
  EXPECT_EQ((*mesh_find_attribute(m, attribute_block_id))[0], 3);
}

TEST(IoMedit, RefusesTetrahedraNamingThem) {
  const auto dir = test_temp_dir("io_medit_tets");
  const auto p = dir / "tet.mesh";
  io_write_text(p,
                "MeshVersionFormatted 1\nDimension 3\nVertices\n4\n0 0 0 0\n1 0 0 0\n0 1 0 0\n"
                "0 0 1 0\nTetrahedra\n1\n1 2 3 4 0\nEnd\n");
  try {
    mesh_read(p.string());
    FAIL() << "tetrahedra accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("Tetrahedra"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("tet.mesh:10"), std::string::npos) << e.what();
  }
}

TEST(IoMedit, RefusesBadIdsCountsAndCoordinatesWithLine) {
  const auto dir = test_temp_dir("io_medit_bad");
  const std::string head = "MeshVersionFormatted 1\nDimension 3\nVertices\n8\n";
  std::string verts;
  for (int i = 0; i < 8; ++i)
    verts += std::to_string(i & 1) + " " + std::to_string((i >> 1) & 1) + " " +
             std::to_string(i >> 2) + " 0\n";
  const std::pair<std::string, std::string> cases[] = {
      {head + verts + "Hexahedra\n1\n1 2 4 3 5 6 8 0 1\nEnd\n",
       ":15: expected vertex id in 1..8, got 0"},
      {head + verts + "Hexahedra\n1\n1 2 4 3 5 6 8 9 1\nEnd\n",
       ":15: expected vertex id in 1..8, got 9"},
      {head + verts + "Hexahedra\n1\n1 2 4 3 5 6 8\n", "hexahedron count 1 is more than the rest"},
      {head + verts + "Hexahedra\n-1\n", ":14: expected hexahedron count >= 0"},
      {head + verts + "Hexahedra\n1000000000000\n", "hexahedron count 1000000000000 exceeds"},
      {head + verts + "Hexahedra\n100000\n1 2 4 3 5 6 8 7 1\n", "more than the rest of the file"},
      {"MeshVersionFormatted 1\nDimension 3\nVertices\n1000000000000\n0 0 0 0\n", "vertex count"},
      {head + "0 0 nan 0\n" + verts.substr(8),
       ":5: expected vertex coordinate (a finite number), got 'nan'"},
      {head + "0 0 1e999 0\n" + verts.substr(8), ":5: expected vertex coordinate"},
      {head + verts + "Hexahedra\n1\n1 2 4 3 5 6 8 7 1\n", "expected a section keyword or End"},
      {head + verts + "Banana\n", "unknown MEDIT section 'Banana'"},
  };
  io_expect_refusals(dir, ".mesh", cases);
}

}  // namespace
}  // namespace hexrefine
