/// `hexrefine check` names self-contact (mesh/conformity.hpp): a note, exit 0; a gap stays a
/// defect, exit 1; several bodies in contact are named with their interfaces, exit 0.

#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "mesh/io.hpp"
#include "tests/cli_runner.hpp"

namespace hexrefine {
namespace {

/// Two hexes with nodes of their own: a 2 x 2 x 1 box and a unit cube on it, at (x0, y0).
HexMesh box_with_cube(double x0, double y0) {
  HexMesh m;
  auto add = [&](const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
    HexCell c;
    for (int v = 0; v < 8; ++v) {
      const int bits[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                              {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
      c[v] = m.point_count();
      m.points.emplace_back(bits[v][0] ? hi.x() : lo.x(), bits[v][1] ? hi.y() : lo.y(),
                            bits[v][2] ? hi.z() : lo.z());
    }
    m.hexes.push_back(c);
  };
  add({0, 0, 0}, {2, 2, 1});
  add({x0, y0, 1}, {x0 + 1, y0 + 1, 2});
  return m;
}

TEST(CliCheckContact, SelfContactIsANoteAndASplitCornerIsAGapInOneBody) {
  const auto dir = test_temp_dir("cli_check_contact");
  const std::string contact = (dir / "contact.mesh").string();
  const std::string crack = (dir / "crack.mesh").string();
  mesh_write(contact, box_with_cube(0.5, 0.5));  // no node in common, no corner on a corner
  mesh_write(crack, box_with_cube(1, 1));        // the cube's corner on the box's corner
  const auto report = dir / "r.json";
  const CliRun a = cli_run("check " + contact + " --report " + report.string());
  EXPECT_EQ(a.exit_code, 0) << a.output;
  EXPECT_NE(a.output.find("note: 2 boundary faces touch another part of the boundary "
                          "(self-contact"),
            std::string::npos)
      << a.output;
  std::ifstream in(report);
  EXPECT_EQ(nlohmann::json::parse(in)["self_contact_faces"], 2);
  // The two hexes share no node: two bodies glued corner on corner, named, exit 0.
  const CliRun b = cli_run("check " + crack);
  EXPECT_EQ(b.exit_code, 0) << b.output;
  EXPECT_NE(b.output.find("2 bodies, 1 interface face pairs, 1 interface nodes"), std::string::npos)
      << b.output;
  // The cube's corner (2, 2, 1) made the box's node: one body, and the small face on the big one
  // is a T-junction pocket, a gap (the cube's own copy of the node stays, unused: 1 duplicate).
  HexMesh joined = box_with_cube(1, 1);
  joined.hexes[1][2] = joined.hexes[0][6];
  const std::string pocket = (dir / "pocket.mesh").string();
  mesh_write(pocket, joined);
  const CliRun c = cli_run("check " + pocket);
  EXPECT_EQ(c.exit_code, 1) << c.output;
  EXPECT_NE(c.output.find("2 non-conformal faces"), std::string::npos) << c.output;
  EXPECT_NE(c.output.find("1 duplicate nodes"), std::string::npos) << c.output;
  EXPECT_EQ(c.output.find(" bodies, "), std::string::npos) << c.output;
}

TEST(CliCheckContact, BodiesInContactAreNamedAndValid) {
  // MFEM's beam-sphere contact mesh: three bodies touching along coincident faces whose nodes
  // are not merged (../shared/meshes/README.md); counts measured.
  const auto dir = test_temp_dir("cli_check_bodies");
  const auto report = dir / "r.json";
  const CliRun run =
      cli_run("check " + shared_mesh("mfem_beam_sphere.mesh") + " --report " + report.string());
  EXPECT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("3 bodies, 0 interface face pairs, 3 interface nodes"),
            std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find("valid: conformal"), std::string::npos) << run.output;
  EXPECT_EQ(run.output.find("INVALID"), std::string::npos) << run.output;
  std::ifstream in(report);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["bodies"], 3);
  EXPECT_EQ(j["interface_faces"], 0);  // they touch at 3 nodes only
  EXPECT_EQ(j["interface_nodes"], 3);
  EXPECT_EQ(j["non_conformal_faces"], 0);
  EXPECT_EQ(j["duplicate_nodes"], 0);
  EXPECT_EQ(j["valid"], true);
  // A mesh of one body names no bodies.
  const CliRun one = cli_run("check " + shared_mesh("sphere_conforming.mesh"));
  EXPECT_EQ(one.exit_code, 0) << one.output;
  EXPECT_EQ(one.output.find(" bodies, "), std::string::npos) << one.output;
}

}  // namespace
}  // namespace hexrefine
