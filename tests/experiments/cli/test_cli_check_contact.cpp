/// `hexrefine check` names self-contact (mesh/conformity.hpp): a note, exit 0; a gap stays a
/// defect, exit 1.

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

TEST(CliCheckContact, SelfContactIsANoteAndASplitCornerIsAGap) {
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
  const CliRun b = cli_run("check " + crack);
  EXPECT_EQ(b.exit_code, 1) << b.output;
  EXPECT_NE(b.output.find("2 non-conformal faces"), std::string::npos) << b.output;
  EXPECT_NE(b.output.find("1 duplicate nodes"), std::string::npos) << b.output;
}

}  // namespace
}  // namespace hexrefine
