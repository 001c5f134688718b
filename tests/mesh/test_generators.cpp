#include "mesh/generators.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <random>
#include <vector>

#include "mesh/error.hpp"
#include "mesh/hex_convention.hpp"
#include "mesh/topology.hpp"
#include "tests/fixtures.hpp"

#if __has_include("mesh/quality.hpp")
#include "mesh/quality.hpp"
#define HEXREFINE_HAVE_QUALITY 1
#endif

namespace hexrefine {
namespace {

// Minimum scaled Jacobian over all hexes.
double mesh_min_scaled_jacobian(const HexMesh& m) {
  double lo = 2.0;
#ifdef HEXREFINE_HAVE_QUALITY
  for (int32_t h = 0; h < m.hex_count(); ++h)
    lo = std::min(lo, hex_scaled_jacobian(hex_points(m, h)));
#else
  // Until mesh/quality.hpp lands: min over corners of det of the three unit edge vectors.
  for (int32_t h = 0; h < m.hex_count(); ++h) {
    const auto p = hex_points(m, h);
    for (int v = 0; v < 8; ++v) {
      Eigen::Vector3d e[3];
      for (int k = 0; k < 3; ++k) {
        const int le = hex_vertex_edges[v][k];
        e[k] = (p[hex_edges[le][1]] - p[hex_edges[le][0]]).normalized();
      }
      lo = std::min(lo, e[0].dot(e[1].cross(e[2])));
    }
  }
#endif
  return lo;
}

// Every boundary edge lies in exactly two boundary faces (a closed boundary surface); returns the
// number of boundary edges.
int boundary_edges_closed(const HexTopology& t) {
  std::vector<int> uses(t.edge_count(), 0);
  for (int32_t f : topology_boundary_faces(t)) {
    const int32_t h = t.face_hexes[f][0];
    const int lf = t.face_local[f][0];
    for (int i = 0; i < 4; ++i) ++uses[t.hex_edge_ids[h][hex_face_edges[lf][i]]];
  }
  int edges = 0;
  for (int32_t e = 0; e < t.edge_count(); ++e) {
    if (uses[e] == 0) continue;
    ++edges;
    EXPECT_EQ(uses[e], 2) << "boundary edge " << e;
  }
  return edges;
}

// Private dual-sheet counter (union-find of each hex's four parallel edges); a sheet is
// self-intersecting if one hex has two of its directions in it.
struct SheetCount {
  int sheets = 0;
  int self_intersecting = 0;
};

SheetCount sheets_count(const HexMesh& m, const HexTopology& t) {
  std::vector<int32_t> parent(t.edge_count());
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (int32_t h = 0; h < m.hex_count(); ++h)
    for (int a = 0; a < 3; ++a)
      for (int i = 1; i < 4; ++i)
        parent[find(t.hex_edge_ids[h][hex_axis_edges[a][i]])] =
            find(t.hex_edge_ids[h][hex_axis_edges[a][0]]);
  SheetCount out;
  std::vector<uint8_t> self(t.edge_count(), 0);
  for (int32_t e = 0; e < t.edge_count(); ++e) out.sheets += find(e) == e;
  for (int32_t h = 0; h < m.hex_count(); ++h) {
    int32_t root[3];
    for (int a = 0; a < 3; ++a) root[a] = find(t.hex_edge_ids[h][hex_axis_edges[a][0]]);
    for (int a = 0; a < 3; ++a)
      for (int b = a + 1; b < 3; ++b)
        if (root[a] == root[b]) self[root[a]] = 1;
  }
  for (uint8_t s : self) out.self_intersecting += s;
  return out;
}

// --- brick -------------------------------------------------------------------------------

TEST(GenerateBrick, CountsNumberingAndExtent) {
  BrickParams p;
  p.dims = {3, 4, 5};
  p.size = {3.0, 2.0, 1.0};
  const HexMesh m = generate_brick(p);
  EXPECT_EQ(m.point_count(), 4 * 5 * 6);
  EXPECT_EQ(m.hex_count(), 60);
  // Same numbering as fixture_brick (x fastest), scaled.
  const HexMesh f = fixture_brick(3, 4, 5);
  ASSERT_EQ(m.hexes, f.hexes);
  for (int32_t n = 0; n < m.point_count(); ++n)
    EXPECT_TRUE(m.points[n].isApprox(
        Eigen::Vector3d(f.points[n].x(), f.points[n].y() * 0.5, f.points[n].z() * 0.2), 1e-15));
  EXPECT_EQ(m.points[brick_node(p.dims, 3, 0, 5)], Eigen::Vector3d(3.0, 0.0, 1.0));
  EXPECT_EQ(brick_hex(p.dims, 2, 3, 4), fixture_brick_hex(3, 4, 2, 3, 4));
  const auto [lo, hi] = mesh_bounding_box(m);
  EXPECT_EQ(lo, Eigen::Vector3d(0, 0, 0));
  EXPECT_EQ(hi, Eigen::Vector3d(3.0, 2.0, 1.0));
  EXPECT_DOUBLE_EQ(mesh_min_scaled_jacobian(m), 1.0);
  const HexTopology t = topology_build(m);
  EXPECT_EQ(boundary_edges_closed(t),
            2 * 2 * (3 * 4 + 4 * 5 + 3 * 5));  // closed quad surface: E = 2F
  const SheetCount s = sheets_count(m, t);
  EXPECT_EQ(s.sheets, 3 + 4 + 5);
  EXPECT_EQ(s.self_intersecting, 0);
}

TEST(GenerateBrick, RefusesBadParametersNamingThem) {
  BrickParams p;
  p.dims = {2, 0, 2};
  try {
    generate_brick(p);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("dims NY"), std::string::npos) << e.what();
  }
  p.dims = {2, 2, 2};
  p.size = {1.0, -1.0, 1.0};
  EXPECT_THROW(generate_brick(p), InputError);
  p.size = {1.0, 1.0, 1.0};
  p.jitter = 0.5;
  try {
    generate_brick(p);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("jitter"), std::string::npos) << e.what();
  }
  p.jitter = -0.1;
  EXPECT_THROW(generate_brick(p), InputError);
  p.jitter = 0.0;
  p.dims = {2000, 2000, 2000};
  EXPECT_THROW(generate_brick(p), InputError);
}

TEST(GenerateBrick, JitterMovesOnlyInteriorNodesAndKeepsHexesValid) {
  BrickParams p;
  p.dims = {6, 5, 4};
  p.size = {6.0, 5.0, 4.0};
  p.jitter = 0.45;
  p.seed = 7;
  const HexMesh m = generate_brick(p);
  const HexMesh g = fixture_brick(6, 5, 4);
  ASSERT_EQ(m.hexes, g.hexes);
  int moved = 0;
  for (int k = 0; k <= 4; ++k)
    for (int j = 0; j <= 5; ++j)
      for (int i = 0; i <= 6; ++i) {
        const int32_t n = brick_node(p.dims, i, j, k);
        const bool interior = i > 0 && i < 6 && j > 0 && j < 5 && k > 0 && k < 4;
        const Eigen::Vector3d d = m.points[n] - g.points[n];
        if (!interior) {
          EXPECT_EQ(d, Eigen::Vector3d::Zero()) << "boundary node " << n;
        } else {
          EXPECT_LE(d.cwiseAbs().maxCoeff(), 0.45);
          moved += d != Eigen::Vector3d::Zero();
        }
      }
  EXPECT_EQ(moved, 5 * 4 * 3);
  const double q = mesh_min_scaled_jacobian(m);
  EXPECT_GT(q, 0.0);
  EXPECT_LT(q, 1.0);
  std::printf("brick 6x5x4 jitter 0.45 seed 7: min scaled Jacobian %.4f\n", q);
}

TEST(GenerateBrick, LargeJitterIsPulledBackToValid) {
  // Jitter 0.49 on a thin-slab brick inverts hexes before the pull-back.
  BrickParams p;
  p.dims = {10, 10, 10};
  p.size = {1.0, 1.0, 0.2};
  p.jitter = 0.49;
  for (uint64_t seed : {1u, 2u, 3u}) {
    p.seed = seed;
    const HexMesh m = generate_brick(p);
    // The raw draws (no pull-back) do invert hexes, and the generator changed exactly those.
    HexMesh raw = fixture_brick(10, 10, 10, 0.1);
    for (Eigen::Vector3d& x : raw.points) x.z() *= 0.2;
    std::mt19937_64 rng(seed);
    for (int k = 1; k < 10; ++k)
      for (int j = 1; j < 10; ++j)
        for (int i = 1; i < 10; ++i)
          for (int axis = 0; axis < 3; ++axis) {
            const double u = static_cast<double>(rng() >> 11) * 0x1.0p-53;
            raw.points[brick_node(p.dims, i, j, k)][axis] +=
                0.49 * (axis == 2 ? 0.02 : 0.1) * (2.0 * u - 1.0);
          }
    EXPECT_LT(mesh_min_scaled_jacobian(raw), 0.0) << "seed " << seed;
    int changed = 0;
    for (int32_t n = 0; n < m.point_count(); ++n)
      changed += !m.points[n].isApprox(raw.points[n], 1e-12);
    EXPECT_GT(changed, 0);
    EXPECT_LT(changed, 729);
    const double q = mesh_min_scaled_jacobian(m);
    EXPECT_GT(q, 0.0) << "seed " << seed;
    std::printf("brick 10^3 jitter 0.49 seed %d: min scaled Jacobian %.4f\n",
                static_cast<int>(seed), q);
  }
}

TEST(GenerateBrick, JitterIsDeterministic) {
  BrickParams p;
  p.dims = {4, 4, 4};
  p.jitter = 0.3;
  p.seed = 42;
  const HexMesh a = generate_brick(p), b = generate_brick(p);
  EXPECT_EQ(a.points, b.points);
  p.seed = 43;
  const HexMesh c = generate_brick(p);
  EXPECT_NE(a.points, c.points);
  // The first interior node, (1,1,1), takes the first three draws of mt19937_64(42): pins the
  // draw order and the raw -> [0,1) conversion.
  std::mt19937_64 rng(42);
  const int32_t n = brick_node(p.dims, 1, 1, 1);
  for (int axis = 0; axis < 3; ++axis) {
    const double u = static_cast<double>(rng() >> 11) * 0x1.0p-53;
    EXPECT_DOUBLE_EQ(a.points[n][axis], 0.25 + 0.3 * 0.25 * (2.0 * u - 1.0));
  }
}

}  // namespace
}  // namespace hexrefine
