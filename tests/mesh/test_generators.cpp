#include "mesh/generators.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "mesh/conformity.hpp"
#include "mesh/dual.hpp"
#include "mesh/error.hpp"
#include "mesh/hex_convention.hpp"
#include "mesh/quality.hpp"
#include "mesh/selection.hpp"
#include "mesh/topology.hpp"
#include "tests/fixtures.hpp"

namespace hexrefine {
namespace {

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

// Sheet counts from mesh/dual.hpp.
struct SheetCount {
  int sheets = 0;
  int self_intersecting = 0;
};

SheetCount sheets_count(const HexMesh& m, const HexTopology& t) {
  const DualSheets d = dual_build(m, t);
  SheetCount out;
  out.sheets = d.sheet_count();
  for (const SheetInfo& s : d.sheets) out.self_intersecting += s.self_intersecting;
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

// Interior edges by valence (index = number of hexes around the edge, up to 8).
std::array<int, 9> interior_edge_valences(const HexTopology& t) {
  std::array<int, 9> count{};
  for (int32_t e = 0; e < t.edge_count(); ++e)
    if (!edge_is_boundary(t, e)) ++count[std::min<size_t>(edge_hexes(t, e).size(), 8)];
  return count;
}

// --- gear --------------------------------------------------------------------------------

TEST(GenerateGear, DefaultIsTheThesisSizeWithBlocks) {
  const GearParams p;
  const HexMesh m = generate_gear(p);
  EXPECT_EQ(m.hex_count(), 8568);  // thesis: 8,569 (table), 8,568 (text)
  EXPECT_EQ(m.point_count(), (144 * 8 + 24 * 4 * 3) * 8);
  const std::vector<int32_t>* block = mesh_find_attribute(m, attribute_block_id);
  ASSERT_NE(block, nullptr);
  EXPECT_EQ(std::count(block->begin(), block->end(), gear_block_body), 7 * 144 * 7);
  EXPECT_EQ(std::count(block->begin(), block->end(), gear_block_teeth), 7 * 24 * 9);
  const Selection teeth = select_hexes(m, topology_build(m), {"block:2"});
  EXPECT_EQ(teeth.hexes.size(), 7u * 24u * 9u);
  for (int32_t h : teeth.hexes) EXPECT_EQ((*block)[h], gear_block_teeth);
  // Teeth lie outside the root circle, the body inside it.
  for (int32_t h = 0; h < m.hex_count(); ++h) {
    const Eigen::Vector3d c = hex_centroid(m, h);
    const double r = std::hypot(c.x(), c.y());
    if ((*block)[h] == gear_block_teeth) {
      EXPECT_GT(r, p.root_radius);
      EXPECT_LT(r, p.tip_radius);
    } else {
      EXPECT_GT(r, p.inner_radius);
      EXPECT_LT(r, p.root_radius);
    }
  }
  const auto [lo, hi] = mesh_bounding_box(m);
  double r_min = 1e9, r_max = 0.0;
  for (const Eigen::Vector3d& x : m.points) {
    r_min = std::min(r_min, std::hypot(x.x(), x.y()));
    r_max = std::max(r_max, std::hypot(x.x(), x.y()));
  }
  EXPECT_NEAR(r_min, p.inner_radius, 1e-12);
  EXPECT_NEAR(r_max, p.tip_radius, 1e-12);
  EXPECT_DOUBLE_EQ(lo.z(), 0.0);
  EXPECT_DOUBLE_EQ(hi.z(), p.thickness);
  const double q = mesh_min_scaled_jacobian(m);
  EXPECT_GT(q, 0.0);
  std::printf("gear (default): %d hexes, %d nodes, min scaled Jacobian %.4f\n", m.hex_count(),
              m.point_count(), q);

  const HexTopology t = topology_build(m);
  EXPECT_TRUE(t.nonmanifold_faces.empty());
  boundary_edges_closed(t);
  // 7 layers + 7 body rings + 144 radial chords + 24 teeth x 3 tooth rows.
  const SheetCount s = sheets_count(m, t);
  EXPECT_EQ(s.sheets, 7 + 7 + 144 + 24 * 3);
  EXPECT_EQ(s.self_intersecting, 0);
}

TEST(GenerateGear, SmallGearCountsAndBadParameters) {
  GearParams p;
  p.teeth = 5;
  p.layers = 2;
  p.body_radial = 2;
  p.tooth_radial = 2;
  p.tooth_tangential = 2;
  p.gap_tangential = 3;
  const HexMesh m = generate_gear(p);
  EXPECT_EQ(m.hex_count(), 2 * 5 * (5 * 2 + 2 * 2));
  EXPECT_EQ(m.point_count(), 3 * (25 * 3 + 5 * 3 * 2));
  EXPECT_GT(mesh_min_scaled_jacobian(m), 0.0);
  boundary_edges_closed(topology_build(m));

  GearParams bad;
  bad.tip_radius = 0.9;
  try {
    generate_gear(bad);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("tip_radius"), std::string::npos) << e.what();
  }
  bad = GearParams{};
  bad.teeth = 2;
  EXPECT_THROW(generate_gear(bad), InputError);
  bad = GearParams{};
  bad.tip_fraction = 0.0;
  EXPECT_THROW(generate_gear(bad), InputError);
  bad = GearParams{};
  bad.teeth = 2000000000;  // too many ids: refused before any allocation
  EXPECT_THROW(generate_gear(bad), InputError);
  TwistedRingParams ring;
  ring.section_intervals = 2147483647;
  EXPECT_THROW(generate_twisted_ring(ring), InputError);
  SteppedParams stepped;
  stepped.depth = 2147483647;
  EXPECT_THROW(generate_stepped(stepped), InputError);
  CylinderParams cylinder;
  cylinder.square_intervals = 100000;
  EXPECT_THROW(generate_cylinder(cylinder), InputError);
}

// --- cylinder ----------------------------------------------------------------------------

TEST(GenerateCylinder, OGridCountsValencesAndSheets) {
  const CylinderParams p;  // n = 4, m = 3, 4 layers
  const HexMesh m = generate_cylinder(p);
  EXPECT_EQ(m.hex_count(), 4 * (16 + 4 * 4 * 3));
  EXPECT_EQ(m.point_count(), 5 * (25 + 16 * 3));
  for (const Eigen::Vector3d& x : m.points)
    EXPECT_LE(std::hypot(x.x(), x.y()), p.radius * (1 + 1e-12));
  const double q = mesh_min_scaled_jacobian(m);
  EXPECT_GT(q, 0.0);
  std::printf("cylinder (default): %d hexes, min scaled Jacobian %.4f\n", m.hex_count(), q);

  const HexTopology t = topology_build(m);
  boundary_edges_closed(t);
  // The square's four corner lines are the irregular interior edges (valence 3); an O-grid has
  // no valence-5 edge.
  const std::array<int, 9> v = interior_edge_valences(t);
  EXPECT_EQ(v[3], 4 * (p.layers));
  EXPECT_EQ(v[5], 0);
  EXPECT_EQ(v[1] + v[2] + v[6] + v[7] + v[8], 0);
  EXPECT_GT(v[4], 0);
  const SheetCount s = sheets_count(m, t);
  EXPECT_EQ(s.sheets, 2 * 4 + 3 + 4);
  EXPECT_EQ(s.self_intersecting, 0);

  CylinderParams bad;
  bad.core = 0.8;
  try {
    generate_cylinder(bad);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("core"), std::string::npos) << e.what();
  }
  bad = CylinderParams{};
  bad.radial_intervals = 0;
  EXPECT_THROW(generate_cylinder(bad), InputError);
}

// --- twisted ring ------------------------------------------------------------------------

TEST(GenerateTwistedRing, OneSelfIntersectingSheetAndClosedConnectivity) {
  const TwistedRingParams p;  // 16 around, 1 x 1 section
  const HexMesh m = generate_twisted_ring(p);
  EXPECT_EQ(m.hex_count(), 16);
  EXPECT_EQ(m.point_count(), 16 * 4);  // no extra closing layer: layer 16 is layer 0
  // The last hex closes onto layer 0, a quarter turn on: its top node (a, b) is layer 0's
  // (1 - b, a) = ids (1 - b) + 2 a.
  const HexCell& last = m.hexes.back();
  EXPECT_EQ(last[4], 1);  // (0,0) -> (1,0)
  EXPECT_EQ(last[5], 0);  // (0,1) -> (0,0)
  EXPECT_EQ(last[6], 2);  // (1,1) -> (0,1)
  EXPECT_EQ(last[7], 3);  // (1,0) -> (1,1)
  const double q = mesh_min_scaled_jacobian(m);
  EXPECT_GT(q, 0.0);
  std::printf("twisted ring (default): %d hexes, min scaled Jacobian %.4f\n", m.hex_count(), q);

  const HexTopology t = topology_build(m);
  EXPECT_TRUE(t.nonmanifold_faces.empty());
  EXPECT_EQ(boundary_edges_closed(t), 4 * 16 + 4 * 16);
  // Boundary faces are all on the section's perimeter: none is across the ring direction
  // (local faces 4 and 5, the faces normal to the ring edges).
  const std::vector<int32_t> boundary = topology_boundary_faces(t);
  EXPECT_EQ(boundary.size(), 4u * 16u);
  for (int32_t f : boundary) EXPECT_LT(t.face_local[f][0], 4) << "face " << f;
  for (int32_t h = 0; h < m.hex_count(); ++h) {
    EXPECT_GE(hex_face_neighbor(t, h, 4), 0);
    EXPECT_GE(hex_face_neighbor(t, h, 5), 0);
  }
  const SheetCount s = sheets_count(m, t);
  EXPECT_EQ(s.sheets, 16 + 1);
  EXPECT_EQ(s.self_intersecting, 1);
}

TEST(GenerateTwistedRing, LargerSectionsHaveCeilHalfSelfIntersectingSheets) {
  for (int sections : {2, 3, 4}) {
    TwistedRingParams p;
    p.around = 12;
    p.section_intervals = sections;
    const HexMesh m = generate_twisted_ring(p);
    EXPECT_EQ(m.hex_count(), 12 * sections * sections);
    EXPECT_EQ(m.point_count(), 12 * (sections + 1) * (sections + 1));
    EXPECT_GT(mesh_min_scaled_jacobian(m), 0.0);
    const HexTopology t = topology_build(m);
    EXPECT_EQ(topology_boundary_faces(t).size(), static_cast<size_t>(4 * sections * 12));
    boundary_edges_closed(t);
    const SheetCount s = sheets_count(m, t);
    const int twisted = (sections + 1) / 2;
    EXPECT_EQ(s.sheets, 12 + twisted) << sections;
    EXPECT_EQ(s.self_intersecting, twisted) << sections;
  }
  TwistedRingParams bad;
  bad.around = 7;
  try {
    generate_twisted_ring(bad);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("around"), std::string::npos) << e.what();
  }
  bad = TwistedRingParams{};
  bad.section_size = 1.5;
  EXPECT_THROW(generate_twisted_ring(bad), InputError);
}

// --- stepped -----------------------------------------------------------------------------

TEST(GenerateStepped, TableSixOneModel) {
  const SteppedParams p;
  const HexMesh m = generate_stepped(p);
  EXPECT_EQ(m.hex_count(), 1188);
  // Node columns per z level: 14 (levels 0-3), 12 (4-6), 10 (7-9); 13 rows along y.
  EXPECT_EQ(m.point_count(), (4 * 14 + 3 * 12 + 3 * 10) * 13);
  const auto [lo, hi] = mesh_bounding_box(m);
  EXPECT_EQ(lo, Eigen::Vector3d(0, 0, 0));
  EXPECT_EQ(hi, Eigen::Vector3d(13, 12, 9));
  EXPECT_DOUBLE_EQ(mesh_min_scaled_jacobian(m), 1.0);  // thesis: initial minimum quality 1.0

  const HexTopology t = topology_build(m);
  boundary_edges_closed(t);
  // "boundary:1,0,0": hexes with a boundary face facing +x (the three risers).
  std::vector<uint8_t> target(m.hex_count(), 0), marked(m.point_count(), 0);
  int riser_faces = 0;
  std::vector<double> riser_x;
  for (int32_t f : topology_boundary_faces(t)) {
    const auto& fn = t.face_nodes[f];
    const Eigen::Vector3d n =
        (m.points[fn[1]] - m.points[fn[0]]).cross(m.points[fn[3]] - m.points[fn[0]]).normalized();
    if (n.x() < 0.999) continue;
    ++riser_faces;
    target[t.face_hexes[f][0]] = 1;
    if (std::find(riser_x.begin(), riser_x.end(), m.points[fn[0]].x()) == riser_x.end())
      riser_x.push_back(m.points[fn[0]].x());
  }
  EXPECT_EQ(riser_faces, 3 * 3 * 12);
  // The refine command's selection picks the same hexes.
  const Selection selected = select_hexes(m, t, {"boundary:1,0,0"});
  ASSERT_EQ(selected.hexes.size(), static_cast<size_t>(riser_faces));
  for (int32_t h : selected.hexes) EXPECT_TRUE(target[h]) << h;
  std::sort(riser_x.begin(), riser_x.end());
  EXPECT_EQ(riser_x, (std::vector<double>{9, 11, 13}));  // three surfaces make the right side
  for (int32_t h = 0; h < m.hex_count(); ++h)
    if (target[h])
      for (int32_t n : m.hexes[h]) marked[n] = 1;
  // A transition hex is singly connected if its marked corners are one vertex, one edge or one
  // face; at each step's inner corner they are two faces (the hex under the tread, beside the
  // riser above): 2 corners x 12 along y.
  int multiply = 0;
  for (int32_t h = 0; h < m.hex_count(); ++h) {
    if (target[h]) continue;
    int count = 0;
    for (int32_t n : m.hexes[h]) count += marked[n];
    bool single = count <= 1;
    for (int e = 0; e < 12 && count == 2; ++e)
      single |= marked[m.hexes[h][hex_edges[e][0]]] && marked[m.hexes[h][hex_edges[e][1]]];
    for (int f = 0; f < 6 && count == 4; ++f) {
      int on = 0;
      for (int v : hex_faces[f]) on += marked[m.hexes[h][v]];
      single |= on == 4;
    }
    if (!single) {
      ++multiply;
      EXPECT_EQ(count, 6) << "hex " << h;
      const Eigen::Vector3d c = hex_centroid(m, h);
      EXPECT_TRUE((c.x() == 11.5 && c.z() == 2.5) || (c.x() == 9.5 && c.z() == 5.5))
          << c.transpose();
    }
  }
  EXPECT_EQ(multiply, 2 * 12);
}

TEST(GenerateStepped, CountsFollowParametersAndBadParameters) {
  SteppedParams p;
  p.steps = 2;
  p.step_layers = 1;
  p.depth = 1;
  p.top_width = 1;
  p.tread = 1;
  p.cell = 0.5;
  const HexMesh m = generate_stepped(p);
  EXPECT_EQ(m.hex_count(), 3);  // the L of fixtures: 2 at the bottom, 1 on top
  EXPECT_EQ(m.point_count(), 3 * 2 + 3 * 2 + 2 * 2);
  EXPECT_EQ(mesh_bounding_box(m).second, Eigen::Vector3d(1.0, 0.5, 1.0));
  boundary_edges_closed(topology_build(m));
  SteppedParams bad;
  bad.tread = 0;
  try {
    generate_stepped(bad);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("tread"), std::string::npos) << e.what();
  }
  bad = SteppedParams{};
  bad.cell = std::nan("");
  EXPECT_THROW(generate_stepped(bad), InputError);
}

// --- all --------------------------------------------------------------------------------

TEST(Generators, DefaultsPassTheMeshCheck) {
  BrickParams brick;
  brick.dims = {5, 4, 3};
  brick.jitter = 0.4;
  const struct {
    const char* name;
    HexMesh mesh;
    double volume;  ///< exact volume where the shape is a polyhedron; < 0 otherwise
  } cases[] = {
      {"brick", generate_brick(brick), 1.0},  // jitter keeps the boundary, hence the volume
      {"gear", generate_gear(GearParams{}), -1.0},
      {"cylinder", generate_cylinder(CylinderParams{}), -1.0},
      {"twisted ring", generate_twisted_ring(TwistedRingParams{}), -1.0},
      {"stepped", generate_stepped(SteppedParams{}), 1188.0},
  };
  for (const auto& c : cases) {
    const MeshCheckReport r = mesh_check(c.mesh);
    EXPECT_TRUE(r.valid()) << c.name;
    EXPECT_TRUE(r.conformal) << c.name;
    EXPECT_EQ(r.inverted_hexes, 0) << c.name;
    EXPECT_EQ(r.duplicate_nodes, 0) << c.name;
    EXPECT_EQ(r.unused_nodes, 0) << c.name;
    EXPECT_EQ(r.nonmanifold_boundary_edges, 0) << c.name;
    EXPECT_GT(r.volume, 0.0) << c.name;
    if (c.volume > 0.0) {
      EXPECT_NEAR(r.volume, c.volume, 1e-9 * c.volume) << c.name;
    }
  }
}

}  // namespace
}  // namespace hexrefine
