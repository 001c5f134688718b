#include "mesh/hex_face_adjacency.hpp"

#include <gtest/gtest.h>

#include "mesh/io.hpp"
#include "mesh/topology.hpp"
#include "tests/cli_runner.hpp"
#include "tests/fixtures.hpp"

namespace hexrefine {
namespace {

/// The adjacency must say what topology_build says: the same neighbour across every local face,
/// the same boundary faces in the same order, the same non-manifold faces.
void expect_same_as_topology(const HexMesh& m, const HexFaceAdjacency& a) {
  const HexTopology t = topology_build(m, TopologyParts::faces);
  ASSERT_EQ(a.hex_neighbors.size(), m.hexes.size());
  for (int32_t h = 0; h < m.hex_count(); ++h)
    for (int lf = 0; lf < 6; ++lf)
      ASSERT_EQ(a.hex_neighbors[h][lf], hex_face_neighbor(t, h, lf)) << "hex " << h << " " << lf;
  const std::vector<int32_t> boundary = topology_boundary_faces(t);
  ASSERT_EQ(a.boundary_faces.size(), boundary.size());
  for (size_t i = 0; i < boundary.size(); ++i) {
    const HexFaceSlot& s = a.boundary_faces[i];
    EXPECT_EQ(t.hex_face_ids[s.hex][s.local_face], boundary[i]) << i;
  }
  ASSERT_EQ(a.nonmanifold_faces.size(), t.nonmanifold_faces.size());
  for (size_t i = 0; i < a.nonmanifold_faces.size(); ++i) {
    const HexFaceSlot& s = a.nonmanifold_faces[i];
    EXPECT_EQ(t.hex_face_ids[s.hex][s.local_face], t.nonmanifold_faces[i]);
    EXPECT_EQ(t.face_hexes[t.nonmanifold_faces[i]][0], s.hex);  // the lowest user
  }
  // Doublets: on a manifold mesh, the hexes h with a higher neighbour across two or more of
  // their faces (the neighbour array's definition, which the checker used before).
  if (!t.nonmanifold_faces.empty()) return;
  std::vector<int32_t> doublets;
  for (int32_t h = 0; h < m.hex_count(); ++h)
    for (int f = 0; f < 6; ++f) {
      const int32_t g = hex_face_neighbor(t, h, f);
      if (g <= h) continue;
      int uses = 0, first = -1;
      for (int e = 0; e < 6; ++e)
        if (hex_face_neighbor(t, h, e) == g) uses += 1, first = first < 0 ? e : first;
      if (uses >= 2 && first == f) doublets.push_back(h);
    }
  EXPECT_EQ(a.doublets, doublets);
}

/// `copies` disjoint unit cubes, each with a second hex sharing two of its faces (a doublet),
/// the hexes in a shuffled order so that pairs span the matching's node chunks.
HexMesh doublets_fixture(int copies) {
  HexMesh m;
  std::vector<HexCell> hexes;
  for (int k = 0; k < copies; ++k) {
    const HexMesh cube = fixture_brick(1, 1, 1);
    const int32_t o = m.point_count();
    for (const Eigen::Vector3d& p : cube.points)
      m.points.push_back(p + Eigen::Vector3d(3.0 * k, 0, 0));
    m.points.emplace_back(3.0 * k - 1, -1, 0);
    m.points.emplace_back(3.0 * k - 1, -1, 1);
    HexCell c = cube.hexes[0];
    for (int32_t& v : c) v += o;
    hexes.push_back(c);
    // Shares the cube's +x face {1,3,7,5} and +y face {2,6,7,3} (node ids of the cube).
    hexes.push_back({o + 3, o + 2, o + 8, o + 1, o + 7, o + 6, o + 9, o + 5});
  }
  // A fixed shuffle: hex i goes to (i * 7919) mod n (7919 is prime, n even and not a multiple).
  m.hexes.resize(hexes.size());
  for (size_t i = 0; i < hexes.size(); ++i) m.hexes[i * 7919 % hexes.size()] = hexes[i];
  return m;
}

TEST(HexFaceAdjacency, BrickCounts) {
  const int nx = 3, ny = 4, nz = 5;
  const HexMesh m = fixture_brick(nx, ny, nz);
  const HexFaceAdjacency a = hex_face_adjacency_build(m);
  EXPECT_EQ(static_cast<int>(a.boundary_faces.size()), 2 * (nx * ny + ny * nz + nx * nz));
  EXPECT_TRUE(a.nonmanifold_faces.empty());
  // The hex at (1, 1, 1) has the six neighbours one step along each axis.
  const int32_t h = fixture_brick_hex(nx, ny, 1, 1, 1);
  int neighbours = 0;
  for (int32_t g : a.hex_neighbors[h]) neighbours += g >= 0;
  EXPECT_EQ(neighbours, 6);
  expect_same_as_topology(m, a);
}

TEST(HexFaceAdjacency, NonManifoldFaceGoesToItsLowestHex) {
  HexMesh m = fixture_brick(1, 1, 2);  // two hexes stacked in z
  const HexCell c = m.hexes[0];
  m.hexes.push_back({c[4], c[5], c[6], c[7], c[0], c[1], c[2], c[3]});  // a third on the face
  const HexFaceAdjacency a = hex_face_adjacency_build(m);
  ASSERT_EQ(a.nonmanifold_faces.size(), 1u);
  EXPECT_EQ(a.nonmanifold_faces[0].hex, 0);
  // Without the neighbour array (a reader's manifold test): the same faces, no neighbours.
  const HexFaceAdjacency lean = hex_face_adjacency_build(m, 2, false);
  EXPECT_TRUE(lean.hex_neighbors.empty());
  ASSERT_EQ(lean.nonmanifold_faces.size(), 1u);
  EXPECT_EQ(lean.nonmanifold_faces[0].hex, 0);
  EXPECT_EQ(lean.nonmanifold_faces[0].local_face, a.nonmanifold_faces[0].local_face);
  EXPECT_EQ(lean.boundary_faces.size(), a.boundary_faces.size());
  // Hex 2 has hex 0's eight nodes: five faces pair it with hex 0, and on the face hexes 0, 1 and
  // 2 share, the third user points to the lowest: all six give hex 0.
  int to_hex0 = 0;
  for (int32_t g : a.hex_neighbors[2]) to_hex0 += g == 0;
  EXPECT_EQ(to_hex0, 6);
  expect_same_as_topology(m, a);
  // Hexes 0 and 2 share all six faces, five of them with no third user: one doublet, as hex 0.
  EXPECT_EQ(a.doublets, std::vector<int32_t>{0});
}

TEST(HexFaceAdjacency, DoubletsFoundWhileMatchingOnAnyThreadCount) {
  const int copies = 9000;  // 90,000 nodes: the matching's node chunks hold 32,768
  const HexMesh m = doublets_fixture(copies);
  const HexFaceAdjacency one = hex_face_adjacency_build(m, 1);
  ASSERT_EQ(one.doublets.size(), static_cast<size_t>(copies));
  EXPECT_TRUE(std::is_sorted(one.doublets.begin(), one.doublets.end()));
  expect_same_as_topology(m, one);
  EXPECT_EQ(hex_face_adjacency_build(m, 2, false).doublets, one.doublets);
  // The lower hex of each pair: both hexes of copy k sit at 2k * 7919 and (2k + 1) * 7919 mod n.
  const size_t n = m.hexes.size();
  std::vector<int32_t> lower;
  for (size_t k = 0; k < static_cast<size_t>(copies); ++k)
    lower.push_back(static_cast<int32_t>(std::min(2 * k * 7919 % n, (2 * k + 1) * 7919 % n)));
  std::sort(lower.begin(), lower.end());
  EXPECT_EQ(one.doublets, lower);
}

TEST(HexFaceAdjacency, SharedMeshesMatchTopologyOnAnyThreadCount) {
  for (const char* name : {"rockerarm.mesh", "ellipsoid.mesh", "sphere_conforming.mesh"}) {
    SCOPED_TRACE(name);
    const HexMesh m = mesh_read(shared_mesh(name));
    const HexFaceAdjacency one = hex_face_adjacency_build(m, 1);
    expect_same_as_topology(m, one);
    const HexFaceAdjacency two = hex_face_adjacency_build(m, 2);
    EXPECT_EQ(two.hex_neighbors, one.hex_neighbors);
    EXPECT_EQ(two.doublets, one.doublets);
    ASSERT_EQ(two.boundary_faces.size(), one.boundary_faces.size());
    for (size_t i = 0; i < one.boundary_faces.size(); ++i) {
      EXPECT_EQ(two.boundary_faces[i].hex, one.boundary_faces[i].hex);
      EXPECT_EQ(two.boundary_faces[i].local_face, one.boundary_faces[i].local_face);
    }
  }
}

}  // namespace
}  // namespace hexrefine
