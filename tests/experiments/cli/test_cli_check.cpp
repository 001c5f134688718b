#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "mesh/io.hpp"
#include "tests/cli_runner.hpp"
#include "tests/fixtures.hpp"

namespace hexrefine {
namespace {

nlohmann::json read_json(const std::filesystem::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

struct SharedMeshCase {
  const char* file;
  int64_t hexes;
  bool conformal;
  int64_t inverted;
};

// Hex counts from ../shared/meshes/README.md. bunny_voxel.mesh is a 2:1 octree of cubes of five
// sizes (edge 1/128 .. 1/8 of the box), not a conforming mesh: its T-junction nodes were also
// counted independently by a brute-force point-on-cube scan (7354).
const SharedMeshCase shared_cases[] = {
    {"ellipsoid.mesh", 6816, true, 0},
    {"rockerarm.mesh", 10600, true, 0},
    {"bunny_conforming.mesh", 26253, true, 0},
    {"bunny_voxel.mesh", 17088, false, 0},
    {"cube_minus_sphere_conforming.mesh", 9919, true, 0},
    {"sphere_conforming.mesh", 125, true, 0},
    {"sphere_projected_inverted.mesh", 111, true, 76},
    {"sphere_sculpt.e", 80, true, 0},  // README: "small"; 80 measured
    {"abaqus_hex_2x2x2.inp", 8, true, 0},
};

TEST(CliCheck, SharedMeshes) {
  const auto dir = test_temp_dir("cli_check_shared");
  for (const SharedMeshCase& c : shared_cases) {
    SCOPED_TRACE(c.file);
    const auto report = dir / (std::string(c.file) + ".json");
    const CliRun run =
        cli_run("check " + shared_mesh(c.file) + " --sheets --report " + report.string());
    const bool valid = c.conformal && c.inverted == 0;
    EXPECT_EQ(run.exit_code, valid ? 0 : 1) << run.output;
    ASSERT_TRUE(std::filesystem::exists(report)) << run.output;  // written even on exit 1
    const nlohmann::json j = read_json(report);
    EXPECT_EQ(j["hexes"], c.hexes);
    EXPECT_EQ(j["conformal"], c.conformal);
    EXPECT_EQ(j["inverted_hexes"], c.inverted);
    EXPECT_EQ(j["doublets"], 0);
    EXPECT_EQ(j["nonmanifold_faces"], 0);
    for (const char* key :
         {"nodes", "non_conformal_faces", "hanging_nodes", "min_scaled_jacobian",
          "mean_scaled_jacobian", "boundary_faces", "sheets", "self_intersecting_sheets"})
      EXPECT_TRUE(j.contains(key)) << key;
    if (c.conformal) {
      EXPECT_EQ(j["non_conformal_faces"], 0);
      EXPECT_EQ(j["hanging_nodes"], 0);
    }
    if (valid) {
      EXPECT_GT(j["min_scaled_jacobian"].get<double>(), 0.0);
      EXPECT_NE(run.output.find("valid"), std::string::npos);
    }
  }
}

TEST(CliCheck, InvertedSphereIsReportedWithFirstId) {
  // 76 hexes have a negative Jacobian sample (none exactly zero); 52 of them have negative
  // volume and 2 are inside out at all nine samples. The first is hex 33 (0-based).
  const auto dir = test_temp_dir("cli_check_inverted");
  const auto report = dir / "r.json";
  const CliRun run = cli_run("check " + shared_mesh("sphere_projected_inverted.mesh") +
                             " --report " + report.string());
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.output.find("76 inverted hexes, first at id 33"), std::string::npos) << run.output;
  const nlohmann::json j = read_json(report);
  EXPECT_EQ(j["first_inverted_hex"], 33);
  EXPECT_LT(j["min_scaled_jacobian"].get<double>(), -0.99);
  EXPECT_EQ(j["valid"], false);
}

TEST(CliCheck, OctreeVoxelBunnyHasHangingNodes) {
  const auto dir = test_temp_dir("cli_check_voxel");
  const auto report = dir / "r.json";
  const CliRun run =
      cli_run("check " + shared_mesh("bunny_voxel.mesh") + " --report " + report.string());
  EXPECT_EQ(run.exit_code, 1);
  const nlohmann::json j = read_json(report);
  EXPECT_EQ(j["hanging_nodes"], 7354);
  EXPECT_EQ(j["non_conformal_faces"], 11920);
  EXPECT_EQ(j["duplicate_nodes"], 0);
  EXPECT_NE(run.output.find("7354 hanging nodes"), std::string::npos) << run.output;
}

/// 2x1x1 brick whose hex at x in [1,2] is replaced by its 1-8 octree split (9 hexes, 31 nodes).
HexMesh brick_with_one_octree_split() {
  HexMesh m = fixture_brick(1, 1, 1);
  const HexMesh fine = fixture_brick(2, 2, 2, 0.5);
  const int32_t offset = m.point_count();
  for (const Eigen::Vector3d& p : fine.points) m.points.push_back(p + Eigen::Vector3d(1, 0, 0));
  for (HexCell c : fine.hexes) {
    for (int32_t& v : c) v += offset;
    m.hexes.push_back(c);
  }
  // Merge the fine grid's x = 1 corner nodes into the coarse hex's +x corners.
  std::vector<int32_t> map(m.points.size());
  for (int32_t i = 0; i < m.point_count(); ++i) {
    map[i] = i;
    for (int32_t j = 0; j < offset; ++j)
      if (i >= offset && (m.points[i] - m.points[j]).norm() < 1e-12) map[i] = j;
  }
  for (HexCell& c : m.hexes)
    for (int32_t& v : c) v = map[v];
  return m;
}

TEST(CliCheck, RefinedBrickAgainstReference) {
  const auto dir = test_temp_dir("cli_check_reference");
  const std::string reference = (dir / "reference.mesh").string();
  const std::string refined = (dir / "refined.mesh").string();
  mesh_write(reference, fixture_brick(2, 2, 2));
  mesh_write(refined, fixture_brick(4, 4, 4, 0.5));
  const auto report = dir / "r.json";
  const CliRun run = cli_run("check " + refined + " --reference " + reference +
                             " --sheets --report " + report.string());
  EXPECT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json j = read_json(report);
  EXPECT_EQ(j["hexes"], 64);
  EXPECT_EQ(j["conformal"], true);
  EXPECT_EQ(j["reference_compared"], true);
  EXPECT_EQ(j["reference_planar_faced"], true);
  EXPECT_LT(j["volume_relative_error"].get<double>(), 1e-14);
  EXPECT_LT(j["boundary_area_relative_error"].get<double>(), 1e-14);
  EXPECT_EQ(j["geometry_preserved"], true);
  EXPECT_EQ(j["sheets"], 12);  // 4 layers per axis
  EXPECT_EQ(j["self_intersecting_sheets"], 0);
  EXPECT_EQ(j["boundary_faces"], 96);
}

TEST(CliCheck, SheetsOnlyOnRequestAndThreadsGiveTheSameReport) {
  const auto dir = test_temp_dir("cli_check_threads");
  const std::string mesh = shared_mesh("rockerarm.mesh");
  nlohmann::json reports[2];
  for (int threads = 1; threads <= 2; ++threads) {
    const std::string count = threads == 1 ? "1" : "2";
    const auto report = dir / ("r" + count + ".json");
    // Appended piece by piece: GCC 12 warns (-Wrestrict, a false positive) on the one-line sum.
    std::string command = "check ";
    command += mesh;
    command += " --threads ";
    command += count;
    command += " --verbose --report ";
    command += report.string();
    const CliRun run = cli_run(command);
    EXPECT_EQ(run.exit_code, 0) << run.output;
    EXPECT_NE(run.output.find("hexrefine: check "), std::string::npos) << run.output;
    reports[threads - 1] = read_json(report);
    EXPECT_FALSE(reports[threads - 1].contains("sheets"));
    EXPECT_TRUE(reports[threads - 1]["stage_seconds"].contains("read"));
    reports[threads - 1].erase("stage_seconds");
    EXPECT_TRUE(reports[threads - 1]["stage_cpu_seconds"].contains("check"));
    reports[threads - 1].erase("stage_cpu_seconds");
    EXPECT_GT(reports[threads - 1]["peak_memory_mb"].get<double>(), 1.0);
    reports[threads - 1].erase("peak_memory_mb");
  }
  EXPECT_EQ(reports[0], reports[1]);
  EXPECT_EQ(reports[0]["hexes"], 10600);
}

TEST(CliCheck, OctreeSplitBesideUnsplitHex) {
  const auto dir = test_temp_dir("cli_check_split");
  const std::string reference = (dir / "reference.mesh").string();
  const std::string split = (dir / "split.mesh").string();
  mesh_write(reference, fixture_brick(2, 1, 1));
  const HexMesh m = brick_with_one_octree_split();
  ASSERT_EQ(m.hex_count(), 9);
  mesh_write(split, m);
  for (const bool with_reference : {false, true}) {
    SCOPED_TRACE(with_reference ? "with reference" : "without reference");
    const auto report = dir / "r.json";
    const CliRun run =
        cli_run("check " + split + (with_reference ? " --reference " + reference : std::string()) +
                " --report " + report.string());
    EXPECT_EQ(run.exit_code, 1) << run.output;
    EXPECT_NE(run.output.find("5 non-conformal faces"), std::string::npos) << run.output;
    EXPECT_NE(run.output.find("5 hanging nodes"), std::string::npos) << run.output;
    const nlohmann::json j = read_json(report);
    EXPECT_EQ(j["conformal"], false);
    EXPECT_EQ(j["non_conformal_faces"], 5);
    EXPECT_EQ(j["hanging_nodes"], 5);
    EXPECT_EQ(j["inverted_hexes"], 0);
    if (with_reference) {
      EXPECT_NEAR(j["boundary_area_relative_error"].get<double>(), 0.2, 1e-12);
      EXPECT_EQ(j["geometry_preserved"], false);
    }
  }
}

TEST(CliCheck, WorstHexesNameTheirPlaceTemplateAndParent) {
  // Rockerarm refined around one sphere: the worst hexes are children, each named with its
  // template and input hex, and the list is the report's too.
  const auto dir = test_temp_dir("cli_check_worst");
  const std::string refined = (dir / "refined.vtu").string();
  const CliRun refine = cli_run("refine " + shared_mesh("rockerarm.mesh") + " " + refined +
                                " --method selective --select sphere:0,0,0,5 --threads 1");
  ASSERT_EQ(refine.exit_code, 0) << refine.output;
  const auto report = dir / "r.json";
  const CliRun run = cli_run("check " + refined + " --worst 4 --report " + report.string());
  EXPECT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json j = read_json(report);
  ASSERT_EQ(j["worst_hexes"].size(), 4u);
  EXPECT_EQ(j["worst_hexes"][0]["scaled_jacobian"], j["min_scaled_jacobian"]);
  for (size_t k = 0; k < 4; ++k) {
    const nlohmann::json& w = j["worst_hexes"][k];
    if (k > 0) {
      EXPECT_GE(w["scaled_jacobian"], j["worst_hexes"][k - 1]["scaled_jacobian"]);
    }
    EXPECT_GE(w["boundary_faces"].get<int>(), 0);
    EXPECT_LE(w["boundary_faces"].get<int>(), 3);
    EXPECT_GE(w["attributes"]["refinement_level"].get<int>(), 1);  // a child, not an input hex
    EXPECT_GT(w["attributes"]["template_tag"].get<int>(), 0);
    EXPECT_NE(w["template"], "untouched");
    EXPECT_NE(
        run.output.find("worst: hex " + std::to_string(w["hex"].get<int>()) + ", scaled Jacobian"),
        std::string::npos)
        << run.output;
  }
  EXPECT_NE(run.output.find(", template "), std::string::npos) << run.output;
  EXPECT_NE(run.output.find(", from input hex "), std::string::npos) << run.output;
  EXPECT_TRUE(j["stage_seconds"].contains("worst"));
  // Without the option: no list.
  const auto plain = dir / "plain.json";
  EXPECT_EQ(cli_run("check " + refined + " --report " + plain.string()).exit_code, 0);
  EXPECT_FALSE(read_json(plain).contains("worst_hexes"));
  EXPECT_EQ(cli_run("check " + refined + " --worst 0").exit_code, 2);
  EXPECT_EQ(cli_run("check " + refined + " --worst x").exit_code, 2);
}

TEST(CliCheck, BadInputAndUsage) {
  const auto dir = test_temp_dir("cli_check_bad");
  EXPECT_EQ(cli_run("check").exit_code, 2);
  EXPECT_EQ(cli_run("check a.mesh b.mesh").exit_code, 2);
  EXPECT_EQ(cli_run("check " + shared_mesh("sphere_conforming.mesh") + " --bogus").exit_code, 2);
  const CliRun missing = cli_run("check " + (dir / "missing.mesh").string());
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.output.find("missing.mesh"), std::string::npos) << missing.output;
  const auto garbage = dir / "garbage.mesh";
  std::ofstream(garbage) << "MeshVersionFormatted 1\nDimension 3\nVertices\n2\n0 0 x 0\n";
  const auto report = dir / "r.json";
  EXPECT_EQ(cli_run("check " + garbage.string() + " --report " + report.string()).exit_code, 2);
  EXPECT_FALSE(std::filesystem::exists(report));  // nothing written for unreadable input
}

}  // namespace
}  // namespace hexrefine
