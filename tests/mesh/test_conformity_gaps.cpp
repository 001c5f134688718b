/// The checker on valid meshes nobody on this project shaped, and on the gaps it must still find
/// (mesh/conformity.hpp, "Without a reference"): every real mesh of ../shared/meshes passes
/// except the two that are not valid (those of several bodies with their bodies and interfaces
/// counted), a cracked copy of each fails, two bricks with unmerged nodes are two bodies and a
/// crack inside one still fails, T-junctions, self-contact, a
/// strongly warped face beside its neighbour (the former false alarm) and faces of a warped input
/// quad whose nodes slid on it.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <set>

#include "mesh/conformity.hpp"
#include "mesh/hex_convention.hpp"
#include "mesh/hex_face_adjacency.hpp"
#include "mesh/io.hpp"
#include "mesh/quad_patch.hpp"
#include "tests/cli_runner.hpp"
#include "tests/fixtures.hpp"

namespace hexrefine {
namespace {

/// Axis-aligned boxes (lo, hi) as hexes; nodes at equal coordinates are merged unless `merge` is
/// false for that box (then it gets nodes of its own).
HexMesh mesh_from_boxes(const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& boxes,
                        const std::vector<bool>& merge = {}) {
  HexMesh m;
  std::map<std::array<double, 3>, int32_t> ids;
  for (size_t b = 0; b < boxes.size(); ++b) {
    const auto& [lo, hi] = boxes[b];
    const bool merged = merge.empty() || merge[b];
    HexCell c;
    for (int v = 0; v < 8; ++v) {
      std::array<double, 3> x;
      for (int k = 0; k < 3; ++k) x[k] = hex_corner[v][k] ? hi[k] : lo[k];
      if (merged) {
        const auto [it, added] = ids.try_emplace(x, m.point_count());
        if (added) m.points.emplace_back(x[0], x[1], x[2]);
        c[v] = it->second;
      } else {
        c[v] = m.point_count();
        m.points.emplace_back(x[0], x[1], x[2]);
      }
    }
    m.hexes.push_back(c);
  }
  return m;
}

/// The boxes of an n x n x n split of the box (lo, lo + size).
void box_split(std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& boxes,
               const Eigen::Vector3d& lo, double size, int n) {
  const double h = size / n;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const Eigen::Vector3d a = lo + h * Eigen::Vector3d(i, j, k);
        boxes.push_back({a, a + Eigen::Vector3d::Constant(h)});
      }
}

/// The readable meshes of ../shared/meshes, by file name.
std::vector<std::string> shared_mesh_files() {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(shared_mesh(""))) {
    const std::string ext = entry.path().extension().string();
    if (ext == ".mesh" || ext == ".e" || ext == ".inp" || ext == ".vtu" || ext == ".vtk" ||
        ext == ".msh")
      names.push_back(entry.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

/// `mesh` with a crack: hex `b` gets copies of the four nodes of its local face `face`, so it no
/// longer shares that face with the hex across it, nor its four side faces with theirs.
HexMesh mesh_cracked(HexMesh mesh, int32_t b, int face) {
  for (int k = 0; k < 4; ++k) {
    int32_t& node = mesh.hexes[b][hex_faces[face][k]];
    mesh.points.push_back(mesh.points[node]);
    node = mesh.point_count() - 1;
  }
  return mesh;
}

/// The lowest hex whose six faces all have a neighbour, or -1.
int32_t mesh_first_interior_hex(const HexMesh& mesh) {
  const HexFaceAdjacency a = hex_face_adjacency_build(mesh);
  for (int32_t h = 0; h < mesh.hex_count(); ++h)
    if (std::all_of(a.hex_neighbors[h].begin(), a.hex_neighbors[h].end(),
                    [](int32_t n) { return n >= 0; }))
      return h;
  return -1;
}

TEST(ConformityGaps, EveryValidSharedMeshPassesAndACrackedCopyFails) {
  // Two of the shared meshes are not valid: sphere_projected_inverted.mesh by construction (76
  // inverted hexes), bunny_voxel.mesh because it is an octree grid with hanging nodes (4,970
  // nodes sit at the midpoint of a boundary edge, 122 boundary edges lie in four boundary
  // faces: counted independently by matching sorted face node sets).
  const std::set<std::string> invalid = {"sphere_projected_inverted.mesh", "bunny_voxel.mesh"};
  // The meshes of several bodies (parts glued or in contact along coincident faces whose nodes
  // are not merged): bodies, interface face pairs, interface nodes and self-contact faces,
  // measured. peridigm's 8 bodies are glued face on face (29 pairs, 58 faces: the "58
  // non-conformal faces" the checker reported before bodies), and 12 faces of its ring touch
  // another body with no node on a node (contact). exomerge's 5 blocks are a unit cube cut into
  // parts meshed apart and glued with non-matching faces (a small face on a big one: 400 pairs,
  // formerly 650 non-conformal faces and 610 hanging nodes). The beam and sphere of MFEM's
  // contact mesh touch at 3 nodes only. Every other mesh is one body with no interface.
  struct Bodies {
    int64_t bodies, interface_faces, interface_nodes, self_contact_faces;
  };
  const std::map<std::string, Bodies> several_bodies = {
      {"exo_peridigm_contact_ring.e", {8, 29, 342, 12}},
      {"exo_seacas_exomerge_results.e", {5, 400, 144, 0}},
      {"mfem_beam_sphere.mesh", {3, 0, 3, 0}}};
  const std::vector<std::string> names = shared_mesh_files();
  ASSERT_GE(names.size(), 13u);
  int cracked = 0;
  for (const std::string& name : names) {
    SCOPED_TRACE(name);
    const HexMesh mesh = mesh_read(shared_mesh(name));
    const MeshCheckReport r = mesh_check(mesh, nullptr, 2);
    EXPECT_EQ(r.valid(), !invalid.count(name));
    if (invalid.count(name)) continue;
    EXPECT_EQ(r.non_conformal_faces, 0);
    EXPECT_EQ(r.hanging_nodes, 0);
    EXPECT_EQ(r.duplicate_nodes, 0);
    const auto found = several_bodies.find(name);
    const Bodies expected = found != several_bodies.end() ? found->second : Bodies{1, 0, 0, 0};
    EXPECT_EQ(r.self_contact_faces, expected.self_contact_faces);
    EXPECT_EQ(r.bodies, expected.bodies);
    EXPECT_EQ(r.interface_faces, expected.interface_faces);
    EXPECT_EQ(r.interface_nodes, expected.interface_nodes);
    // The same mesh against itself as the reference (what a refinement of nothing gives).
    EXPECT_TRUE(mesh_check(mesh, &mesh).valid());

    const int32_t b = mesh_first_interior_hex(mesh);
    if (b < 0) continue;  // one-layer meshes: no interior hex to crack
    const HexMesh crack = mesh_cracked(mesh, b, 0);
    const MeshCheckReport c = mesh_check(crack, nullptr, 2);
    // The crack face from both sides and the four side faces of b with the faces of their
    // neighbours: five coincident pairs, each joined by a split node.
    EXPECT_EQ(c.non_conformal_faces, 10);
    EXPECT_EQ(c.hanging_nodes, 0);
    EXPECT_EQ(c.self_contact_faces, r.self_contact_faces);
    EXPECT_EQ(c.duplicate_nodes, 4);
    EXPECT_EQ(c.boundary_faces, r.boundary_faces + 10);
    // The cracked hex keeps its other four nodes, so its body and the interfaces are unchanged.
    EXPECT_EQ(c.bodies, r.bodies);
    EXPECT_EQ(c.interface_faces, r.interface_faces);
    EXPECT_EQ(c.interface_nodes, r.interface_nodes);
    EXPECT_FALSE(c.conformal);
    EXPECT_FALSE(c.valid());
    // Against the uncracked mesh as the reference the ten faces are off its boundary too.
    EXPECT_EQ(mesh_check(crack, &mesh).non_conformal_faces, 10);
    ++cracked;
  }
  EXPECT_GE(cracked, 9);
}

/// `a` and `b` in one mesh, `b`'s node ids after `a`'s: nothing merged.
HexMesh mesh_side_by_side(const HexMesh& a, const HexMesh& b) {
  HexMesh m = a;
  const int32_t offset = a.point_count();
  m.points.insert(m.points.end(), b.points.begin(), b.points.end());
  for (HexCell c : b.hexes) {
    for (int32_t& v : c) v += offset;
    m.hexes.push_back(c);
  }
  return m;
}

TEST(ConformityGaps, TwoBricksWithUnmergedNodesAreTwoBodiesAndAGapInsideOneStillFails) {
  // Two 2 x 2 x 2 bricks of unit hexes side by side along x, each with its own nodes: the shared
  // plane x = 2 holds 4 coincident face pairs and 9 coincident node pairs.
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> left, right;
  box_split(left, Eigen::Vector3d(0, 0, 0), 2, 2);
  box_split(right, Eigen::Vector3d(2, 0, 0), 2, 2);
  const HexMesh bricks = mesh_side_by_side(mesh_from_boxes(left), mesh_from_boxes(right));
  ASSERT_EQ(bricks.point_count(), 54);
  const MeshCheckReport r = mesh_check(bricks, nullptr, 2);
  EXPECT_EQ(r.bodies, 2);
  EXPECT_EQ(r.interface_faces, 4);
  EXPECT_EQ(r.interface_nodes, 9);
  EXPECT_EQ(r.non_conformal_faces, 0);
  EXPECT_EQ(r.duplicate_nodes, 0);
  EXPECT_EQ(r.hanging_nodes, 0);
  EXPECT_EQ(r.self_contact_faces, 0);
  EXPECT_EQ(r.boundary_faces, 2 * 24);
  EXPECT_TRUE(r.valid());
  const nlohmann::json j = r;
  EXPECT_EQ(j["bodies"], 2);
  EXPECT_EQ(j["interface_faces"], 4);
  EXPECT_EQ(j["interface_nodes"], 9);
  // Against itself as the reference the interface faces lie on the reference's boundary.
  EXPECT_TRUE(mesh_check(bricks, &bricks).valid());

  // The same bricks merged into one: one body, no interface.
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> both = left;
  both.insert(both.end(), right.begin(), right.end());
  const MeshCheckReport merged = mesh_check(mesh_from_boxes(both));
  EXPECT_EQ(merged.bodies, 1);
  EXPECT_EQ(merged.interface_faces, 0);
  EXPECT_EQ(merged.interface_nodes, 0);
  EXPECT_TRUE(merged.valid());

  // A crack inside the left brick: hex 0 gets its own copies of its +x face's nodes. It still
  // shares its other four nodes with its neighbours, so it stays in the left body, and the crack
  // is a gap as in a mesh of one body; the interface is unchanged.
  const HexMesh cracked = mesh_cracked(bricks, 0, 1);
  const MeshCheckReport c = mesh_check(cracked, nullptr, 2);
  EXPECT_EQ(c.bodies, 2);
  EXPECT_EQ(c.interface_faces, 4);
  EXPECT_EQ(c.interface_nodes, 9);
  // The crack face and the faces hex 0 shared with hexes 2 (+y) and 4 (+z), from both sides.
  EXPECT_EQ(c.non_conformal_faces, 6);
  EXPECT_EQ(c.duplicate_nodes, 4);
  EXPECT_FALSE(c.valid());
  // The same crack in the merged bricks gives the same defect counts.
  const MeshCheckReport m = mesh_check(mesh_cracked(mesh_from_boxes(both), 0, 1), nullptr, 2);
  EXPECT_EQ(m.non_conformal_faces, c.non_conformal_faces);
  EXPECT_EQ(m.duplicate_nodes, 4);
  EXPECT_FALSE(m.valid());
}

TEST(ConformityGaps, UnusedVerticesNeverMakeAMeshInvalid) {
  // ecr_dragon.mesh carries 13 vertices no hex uses, and hex 11999 has a boundary face whose
  // neighbour is warped by 0.2 of its diagonal: the former test called that face non-conformal.
  const MeshCheckReport r = mesh_check(mesh_read(shared_mesh("ecr_dragon.mesh")));
  EXPECT_EQ(r.unused_nodes, 13);
  EXPECT_EQ(r.non_conformal_faces, 0);
  EXPECT_TRUE(r.valid());
}

TEST(ConformityGaps, StronglyWarpedFaceBesideItsNeighbourIsNoGap) {
  // Two unit cubes side by side; the top corner (0,0,1) of the first raised to z = 3, so the
  // corners of its top face spread 0.58 out of their plane, more than the distance (0.5) from
  // the second cube's top centroid to that face. The former test, a centroid within the warp of
  // another boundary face, called the second top face non-conformal.
  HexMesh m = fixture_brick(2, 1, 1);
  int32_t raised = -1;
  for (int32_t v = 0; v < m.point_count(); ++v)
    if (m.points[v] == Eigen::Vector3d(0, 0, 1)) raised = v;
  ASSERT_GE(raised, 0);
  m.points[raised].z() = 3;
  const Quad top = {m.points[m.hexes[0][4]], m.points[m.hexes[0][5]], m.points[m.hexes[0][6]],
                    m.points[m.hexes[0][7]]};
  const Eigen::Vector3d neighbour_centroid(1.5, 0.5, 1);
  ASSERT_TRUE(quad_within(top, neighbour_centroid,
                          mesh_check_surface_tolerance * quad_diameter(top) + quad_warp(top)));
  const MeshCheckReport r = mesh_check(m);
  EXPECT_EQ(r.inverted_hexes, 0);
  EXPECT_EQ(r.non_conformal_faces, 0);
  EXPECT_EQ(r.self_contact_faces, 0);
  EXPECT_TRUE(r.valid());
}

TEST(ConformityGaps, FlatHexIsNoGapThoughItsTwoFacesCoincide) {
  // One hex 1e-9 thick: its top and bottom faces lie within the tolerance of each other and
  // face away from each other, but the hex lies between them (condition 3), so they are a
  // (thin) boundary, not a gap.
  HexMesh m = fixture_brick(1, 1, 1);
  for (Eigen::Vector3d& x : m.points) x.z() *= 1e-9;
  const MeshCheckReport r = mesh_check(m);
  EXPECT_GT(r.min_scaled_jacobian, 0);
  EXPECT_EQ(r.non_conformal_faces, 0);
  EXPECT_EQ(r.self_contact_faces, 0);
  EXPECT_TRUE(r.valid());
}

TEST(ConformityGaps, TJunctionOfA1To27SplitIsOneGap) {
  // A unit cube beside one split 3 x 3 x 3: the big face and the nine small faces behind it.
  // The middle small faces share no node with the big face; they are in the gap because the
  // corner ones are (one contact patch).
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> boxes = {
      {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 1, 1)}};
  box_split(boxes, Eigen::Vector3d(1, 0, 0), 1.0, 3);
  const HexMesh m = mesh_from_boxes(boxes);
  const HexMesh reference = fixture_brick(2, 1, 1);
  for (const HexMesh* ref : {static_cast<const HexMesh*>(nullptr), &reference}) {
    SCOPED_TRACE(ref ? "with reference" : "without reference");
    const MeshCheckReport r = mesh_check(m, ref);
    EXPECT_EQ(r.non_conformal_faces, 10);
    EXPECT_EQ(r.hanging_nodes, 12);  // 8 on the big face's edges, 4 inside it
    EXPECT_EQ(r.self_contact_faces, 0);
    EXPECT_FALSE(r.valid());
  }
}

TEST(ConformityGaps, InteriorOctreeSplitIsAClosedPocket) {
  // The middle hex of a 3 x 3 x 3 brick split 1-8: six big faces and 24 small ones enclose
  // nothing; 12 edge midpoints and 6 face centres hang.
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> boxes;
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) {
        const Eigen::Vector3d lo(i, j, k);
        if (i == 1 && j == 1 && k == 1)
          box_split(boxes, lo, 1.0, 2);
        else
          boxes.push_back({lo, lo + Eigen::Vector3d::Constant(1)});
      }
  const HexMesh m = mesh_from_boxes(boxes);
  const HexMesh reference = fixture_brick(3, 3, 3);
  for (const HexMesh* ref : {static_cast<const HexMesh*>(nullptr), &reference}) {
    SCOPED_TRACE(ref ? "with reference" : "without reference");
    const MeshCheckReport r = mesh_check(m, ref);
    EXPECT_EQ(r.boundary_faces, 54 + 30);
    EXPECT_EQ(r.non_conformal_faces, 30);
    EXPECT_EQ(r.hanging_nodes, 18);
    EXPECT_EQ(r.nonmanifold_boundary_edges, 0);
    EXPECT_FALSE(r.valid());
  }
}

TEST(ConformityGaps, SelfContactIsReportedAndNoDefect) {
  // A half-size cube standing on the middle of a 2 x 2 x 1 box, with nodes of its own: its
  // bottom face lies on the box's top face, they face each other, and no node joins them.
  const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> boxes = {
      {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(2, 2, 1)},
      {Eigen::Vector3d(0.5, 0.5, 1), Eigen::Vector3d(1.5, 1.5, 2)}};
  const MeshCheckReport r = mesh_check(mesh_from_boxes(boxes));
  EXPECT_EQ(r.self_contact_faces, 2);
  EXPECT_EQ(r.non_conformal_faces, 0);
  EXPECT_EQ(r.hanging_nodes, 0);
  EXPECT_TRUE(r.conformal);
  EXPECT_TRUE(r.valid());
  EXPECT_EQ(nlohmann::json(r)["self_contact_faces"], 2);
  // Moved to the box's corner the cube shares the node (2, 2, 1) with it: a gap (the cube's
  // bottom face is one side of a T-junction pocket), not a contact.
  const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> corner = {
      {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(2, 2, 1)},
      {Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(2, 2, 2)}};
  const MeshCheckReport g = mesh_check(mesh_from_boxes(corner));
  EXPECT_EQ(g.self_contact_faces, 0);
  EXPECT_EQ(g.non_conformal_faces, 2);
  EXPECT_EQ(g.hanging_nodes, 3);  // (2,1,1) and (1,2,1) on the box face's edges, (1,1,1) inside
  EXPECT_FALSE(g.valid());
  // With nodes of its own at the same place the cube shares no node with the box: two bodies
  // glued at a corner on a corner (a non-matching interface, as where parts meshed apart are
  // glued), which is valid; the crack a split corner node would be inside one body is tested by
  // the cracked meshes above.
  const MeshCheckReport s = mesh_check(mesh_from_boxes(corner, {true, false}));
  EXPECT_EQ(s.bodies, 2);
  EXPECT_EQ(s.interface_faces, 1);
  EXPECT_EQ(s.interface_nodes, 1);
  EXPECT_EQ(s.non_conformal_faces, 0);
  EXPECT_EQ(s.duplicate_nodes, 0);
  EXPECT_EQ(s.hanging_nodes, 0);
  EXPECT_TRUE(s.valid());
}

/// Trilinear map of hex `h` of `mesh` from the unit cube.
Eigen::Vector3d hex_map(const HexMesh& mesh, int32_t h, double u, double v, double w) {
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  for (int c = 0; c < 8; ++c)
    x += mesh.points[mesh.hexes[h][c]] *
         ((hex_corner[c][0] ? u : 1 - u) * (hex_corner[c][1] ? v : 1 - v) *
          (hex_corner[c][2] ? w : 1 - w));
  return x;
}

TEST(ConformityGaps, NodesSlidOnAStronglyWarpedInputQuadStayOnItAndOffIsOff) {
  // The input: one hex whose top face is warped by 0.18 of its diagonal (corner (1,1,1) raised
  // to 1.5). The output: its 3 x 3 x 3 split by the trilinear map, then every new node of the
  // top face slid on the top patch to other parameters (the footprints of the top children are
  // no longer parameter rectangles, so their centroids leave the patch), as smoothing does.
  HexMesh input = fixture_brick(1, 1, 1);
  input.points[7].z() = 1.5;  // node 7 is corner (1,1,1) of the brick
  const Quad top = {input.points[input.hexes[0][4]], input.points[input.hexes[0][5]],
                    input.points[input.hexes[0][6]], input.points[input.hexes[0][7]]};
  ASSERT_GT(quad_relative_warp(top), 0.15);
  HexMesh out;
  auto id = [](int i, int j, int k) { return static_cast<int32_t>(i + 4 * (j + 4 * k)); };
  for (int k = 0; k <= 3; ++k)
    for (int j = 0; j <= 3; ++j)
      for (int i = 0; i <= 3; ++i) {
        double u = i / 3.0, v = j / 3.0;
        if (k == 3 && i > 0 && i < 3) u += (j == 1 ? 0.08 : -0.05);  // slid on the patch
        if (k == 3 && j > 0 && j < 3) v += (i == 2 ? -0.07 : 0.04);
        out.points.push_back(k == 3 ? quad_point(top, u, v) : hex_map(input, 0, u, v, k / 3.0));
      }
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i)
        out.hexes.push_back({id(i, j, k), id(i + 1, j, k), id(i + 1, j + 1, k), id(i, j + 1, k),
                             id(i, j, k + 1), id(i + 1, j, k + 1), id(i + 1, j + 1, k + 1),
                             id(i, j + 1, k + 1)});
  // The slide is real: some top child's centroid is off the patch by more than 1e-6 of its size.
  double worst = 0;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector3d centroid =
          (out.points[id(i, j, 3)] + out.points[id(i + 1, j, 3)] + out.points[id(i + 1, j + 1, 3)] +
           out.points[id(i, j + 1, 3)]) /
          4.0;
      worst = std::max(worst, quad_distance(top, centroid));
    }
  ASSERT_GT(worst, 1e-4 * quad_diameter(top));
  const MeshCheckReport r = mesh_check(out, &input);
  EXPECT_EQ(r.inverted_hexes, 0);
  EXPECT_EQ(r.non_conformal_faces, 0);
  EXPECT_TRUE(r.valid());
  // Off is off: one slid node lifted off the patch by twice the patch's warp.
  HexMesh lifted = out;
  lifted.points[id(1, 1, 3)] += 2 * quad_warp(top) * quad_unit_normal(top);
  const MeshCheckReport off = mesh_check(lifted, &input);
  EXPECT_EQ(off.non_conformal_faces, 4);  // the four top faces around the node
  EXPECT_FALSE(off.valid());
}

}  // namespace
}  // namespace hexrefine
