#include "mesh/topology.hpp"

#include <gtest/gtest.h>

#include "tests/fixtures.hpp"

namespace hexrefine {
namespace {

TEST(Topology, OneCube) {
  const HexMesh m = fixture_brick(1, 1, 1);
  const HexTopology t = topology_build(m);
  EXPECT_EQ(t.edge_count(), 12);
  EXPECT_EQ(t.face_count(), 6);
  EXPECT_EQ(topology_boundary_faces(t).size(), 6u);
  for (int32_t e = 0; e < 12; ++e) {
    EXPECT_EQ(edge_hexes(t, e).size(), 1u);
    EXPECT_EQ(edge_face_count(t, e), 2);
    EXPECT_TRUE(edge_is_boundary(t, e));
  }
  EXPECT_TRUE(t.nonmanifold_faces.empty());
}

TEST(Topology, BrickCounts) {
  const int nx = 3, ny = 4, nz = 5;
  const HexMesh m = fixture_brick(nx, ny, nz);
  const HexTopology t = topology_build(m);
  const int edges = nx * (ny + 1) * (nz + 1) + (nx + 1) * ny * (nz + 1) + (nx + 1) * (ny + 1) * nz;
  const int faces = (nx + 1) * ny * nz + nx * (ny + 1) * nz + nx * ny * (nz + 1);
  const int boundary = 2 * (nx * ny + ny * nz + nx * nz);
  EXPECT_EQ(t.edge_count(), edges);
  EXPECT_EQ(t.face_count(), faces);
  EXPECT_EQ(static_cast<int>(topology_boundary_faces(t).size()), boundary);
  // Interior edge valence 4, interior node has 8 hexes.
  int valence4 = 0;
  for (int32_t e = 0; e < t.edge_count(); ++e) valence4 += edge_hexes(t, e).size() == 4;
  EXPECT_EQ(valence4,
            (nx - 1) * (ny - 1) * nz + (nx - 1) * ny * (nz - 1) + nx * (ny - 1) * (nz - 1));
  // Every hex's faces point back to it, and neighbours are consistent.
  for (int32_t h = 0; h < m.hex_count(); ++h)
    for (int lf = 0; lf < 6; ++lf) {
      const int32_t f = t.hex_face_ids[h][lf];
      EXPECT_TRUE(t.face_hexes[f][0] == h || t.face_hexes[f][1] == h);
      const int32_t n = hex_face_neighbor(t, h, lf);
      if (n >= 0) {
        EXPECT_EQ(hex_local_face(t, n, f), lf ^ 1);  // structured brick: opposite side
      }
    }
}

TEST(Topology, NonManifoldFaceIsRecorded) {
  HexMesh m = fixture_brick(1, 1, 2);  // two hexes stacked in z
  // A third hex glued on the shared face, mirrored below it (overlapping the first).
  HexCell c = m.hexes[0];
  m.hexes.push_back({c[4], c[5], c[6], c[7], c[0], c[1], c[2], c[3]});
  const HexTopology t = topology_build(m);
  ASSERT_EQ(t.nonmanifold_faces.size(), 1u);
}

}  // namespace
}  // namespace hexrefine
