#include "mesh/boundary_surface.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "mesh/generators.hpp"
#include "mesh/hex_convention.hpp"
#include "tests/fixtures.hpp"

namespace hexrefine {
namespace {

/// Extruded L: a 4x4x2 brick without the 2x2x2 block at i >= 2, j >= 2 (its unused nodes stay).
HexMesh l_prism() {
  const HexMesh brick = fixture_brick(4, 4, 2);
  HexMesh m;
  m.points = brick.points;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i)
        if (i < 2 || j < 2) m.hexes.push_back(brick.hexes[fixture_brick_hex(4, 4, i, j, k)]);
  return m;
}

std::vector<int32_t> sorted_counts(const SurfacePatches& p) {
  std::vector<int32_t> c = p.patch_face_counts;
  std::sort(c.begin(), c.end());
  return c;
}

/// Every OpenMesh face lists the nodes of its hex face in hex_faces order.
void expect_faces_map_back(const HexMesh& m, const HexTopology& t, const BoundarySurface& s) {
  ASSERT_EQ(s.face_count(), static_cast<int32_t>(s.surface.n_faces()));
  ASSERT_EQ(s.vertex_node.size(), s.surface.n_vertices());
  for (int32_t i = 0; i < s.face_count(); ++i) {
    EXPECT_TRUE(face_is_boundary(t, s.face_id[i]));
    EXPECT_EQ(t.hex_face_ids[s.face_hex[i]][s.face_local[i]], s.face_id[i]);
    int k = 0;
    for (SurfaceMesh::VertexHandle v : s.surface.fv_range(SurfaceMesh::FaceHandle(i))) {
      ASSERT_LT(k, 4);
      EXPECT_EQ(s.vertex_node[v.idx()], m.hexes[s.face_hex[i]][hex_faces[s.face_local[i]][k]]);
      ++k;
    }
    EXPECT_EQ(k, 4);
  }
}

bool surface_is_closed(const SurfaceMesh& m) {
  for (SurfaceMesh::HalfedgeHandle he : m.halfedges())
    if (m.is_boundary(he)) return false;
  return true;
}

int euler_characteristic(const SurfaceMesh& m) {
  return static_cast<int>(m.n_vertices()) - static_cast<int>(m.n_edges()) +
         static_cast<int>(m.n_faces());
}

TEST(BoundarySurface, BrickIsClosedWithSixPatches) {
  const int nx = 3, ny = 4, nz = 5;
  const HexMesh m = fixture_brick(nx, ny, nz);
  const HexTopology t = topology_build(m);
  const BoundarySurface s = boundary_surface_build(m, t);
  EXPECT_EQ(s.face_count(), 2 * (nx * ny + ny * nz + nx * nz));
  EXPECT_EQ(static_cast<int>(s.surface.n_vertices()),
            (nx + 1) * (ny + 1) * (nz + 1) - (nx - 1) * (ny - 1) * (nz - 1));
  EXPECT_EQ(s.split_face_count, 0);
  EXPECT_TRUE(surface_is_closed(s.surface));
  EXPECT_EQ(euler_characteristic(s.surface), 2);
  expect_faces_map_back(m, t, s);

  const SurfacePatches p = boundary_surface_patches(s);
  ASSERT_EQ(p.patch_count(), 6);
  EXPECT_EQ(sorted_counts(p),
            (std::vector<int32_t>{nx * ny, nx * ny, nx * nz, nx * nz, ny * nz, ny * nz}));
  // A patch is one side of the brick: all its faces have the same local face index.
  for (int32_t i = 0; i < s.face_count(); ++i)
    for (int32_t j = 0; j < s.face_count(); ++j)
      if (p.face_patch[i] == p.face_patch[j]) {
        EXPECT_EQ(s.face_local[i], s.face_local[j]);
      }
  // Above 90 degrees the brick's edges are no longer features.
  EXPECT_EQ(boundary_surface_patches(s, 100.0).patch_count(), 1);
}

TEST(BoundarySurface, OpenMeshNormalsPointOutward) {
  const HexMesh m = fixture_brick(2, 2, 2);
  const HexTopology t = topology_build(m);
  BoundarySurface s = boundary_surface_build(m, t);
  s.surface.request_face_normals();
  s.surface.update_face_normals();
  const Eigen::Vector3d centre(1, 1, 1);
  for (int32_t i = 0; i < s.face_count(); ++i) {
    const auto n = s.surface.normal(SurfaceMesh::FaceHandle(i));
    const Eigen::Vector3d c = hex_centroid(m, s.face_hex[i]);
    EXPECT_GT(Eigen::Vector3d(n[0], n[1], n[2]).dot(c - centre), 0.0);
    const Eigen::Vector3d u = face_unit_normal(m, t, s.face_id[i]);
    EXPECT_NEAR(u.dot(Eigen::Vector3d(n[0], n[1], n[2])), 1.0, 1e-12);
  }
}

TEST(BoundarySurface, LShapedPrismHasEightPatches) {
  const HexMesh m = l_prism();
  const HexTopology t = topology_build(m);
  const BoundarySurface s = boundary_surface_build(m, t);
  EXPECT_EQ(s.face_count(), 12 + 12 + 8 + 8 + 4 + 4 + 4 + 4);
  EXPECT_TRUE(surface_is_closed(s.surface));
  EXPECT_EQ(euler_characteristic(s.surface), 2);
  EXPECT_EQ(s.split_face_count, 0);
  expect_faces_map_back(m, t, s);
  const SurfacePatches p = boundary_surface_patches(s);
  ASSERT_EQ(p.patch_count(), 8);
  EXPECT_EQ(sorted_counts(p), (std::vector<int32_t>{4, 4, 4, 4, 8, 8, 12, 12}));
}

TEST(BoundarySurface, SteppedModelHasTenPatches) {
  // Left, bottom, top, front and back (staircase outlines), 3 risers and 2 treads.
  const HexMesh m = generate_stepped(SteppedParams{});
  const HexTopology t = topology_build(m);
  const BoundarySurface s = boundary_surface_build(m, t);
  EXPECT_TRUE(surface_is_closed(s.surface));
  EXPECT_EQ(euler_characteristic(s.surface), 2);
  const SurfacePatches p = boundary_surface_patches(s);
  ASSERT_EQ(p.patch_count(), 10);
  EXPECT_EQ(sorted_counts(p), (std::vector<int32_t>{24, 24, 36, 36, 36, 99, 99, 108, 108, 156}));
}

TEST(BoundarySurface, CurvedSideStaysOnePatchBelowFeatureAngle) {
  // A brick bent around the z axis: 12 hexes over 90 degrees, 7.5 degrees between neighbours.
  HexMesh m = fixture_brick(12, 1, 1);
  for (Eigen::Vector3d& p : m.points) {
    const double angle = p.x() / 12.0 * std::numbers::pi / 2, r = 5.0 + p.y();
    p = Eigen::Vector3d(r * std::cos(angle), r * std::sin(angle), p.z());
  }
  const HexTopology t = topology_build(m);
  const BoundarySurface s = boundary_surface_build(m, t);
  // Inner and outer curved sides, top, bottom and the two ends.
  const SurfacePatches p = boundary_surface_patches(s, 30.0);
  EXPECT_EQ(p.patch_count(), 6);
  EXPECT_EQ(sorted_counts(p), (std::vector<int32_t>{1, 1, 12, 12, 12, 12}));
  // Below 7.5 degrees every curved-side face is its own patch (top and bottom are flat).
  EXPECT_EQ(boundary_surface_patches(s, 5.0).patch_count(), 2 + 2 + 12 + 12);
}

TEST(BoundarySurface, EdgeContactIsSplitNotDropped) {
  // Two cubes touching along one edge: four boundary faces at that edge.
  HexMesh m = fixture_brick(2, 2, 1);
  m.hexes = {m.hexes[fixture_brick_hex(2, 2, 0, 0, 0)], m.hexes[fixture_brick_hex(2, 2, 1, 1, 0)]};
  const HexTopology t = topology_build(m);
  const BoundarySurface s = boundary_surface_build(m, t);
  EXPECT_EQ(s.face_count(), 12);
  EXPECT_GE(s.split_face_count, 1);
  expect_faces_map_back(m, t, s);
  const SurfacePatches p = boundary_surface_patches(s);
  EXPECT_EQ(static_cast<int32_t>(p.face_patch.size()), 12);
  EXPECT_EQ(p.patch_count(), 12);  // coplanar faces of the two cubes share only a vertex
}

TEST(BoundarySurface, EmptyMesh) {
  const HexMesh m;
  const BoundarySurface s = boundary_surface_build(m, topology_build(m));
  EXPECT_EQ(s.face_count(), 0);
  EXPECT_EQ(boundary_surface_patches(s).patch_count(), 0);
}

}  // namespace
}  // namespace hexrefine
