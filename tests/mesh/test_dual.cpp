#include "mesh/dual.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "mesh/generators.hpp"
#include "mesh/hex_convention.hpp"
#include "tests/fixtures.hpp"

namespace hexrefine {
namespace {

/// A closed ring of `n` hexes around the z axis with a 1x1 square section. With `twist`, the
/// section turns a quarter turn over the ring, so station n's corner i is station 0's corner
/// i+1: the connectivity closes up rotated. Local z runs along the ring.
HexMesh ring(int n, bool twist) {
  HexMesh m;
  const double radius = 4.0;
  const double su[4] = {-0.5, 0.5, 0.5, -0.5}, sv[4] = {-0.5, -0.5, 0.5, 0.5};
  for (int k = 0; k < n; ++k) {
    const double theta = 2 * std::numbers::pi * k / n;
    const double phi = twist ? (std::numbers::pi / 2) * k / n : 0.0;
    for (int i = 0; i < 4; ++i) {
      // Section coordinates rotated by phi, u radial and v along z.
      const double u = su[i] * std::cos(phi) - sv[i] * std::sin(phi);
      const double v = su[i] * std::sin(phi) + sv[i] * std::cos(phi);
      m.points.emplace_back((radius + u) * std::cos(theta), (radius + u) * std::sin(theta), v);
    }
  }
  auto node = [&](int k, int i) {
    if (k < n) return static_cast<int32_t>(4 * k + i);
    return static_cast<int32_t>(twist ? (i + 1) % 4 : i);  // station n is station 0
  };
  for (int k = 0; k < n; ++k)
    m.hexes.push_back({node(k, 0), node(k, 1), node(k, 2), node(k, 3), node(k + 1, 0),
                       node(k + 1, 1), node(k + 1, 2), node(k + 1, 3)});
  return m;
}

/// 3x3x3 unit brick whose centre hex is pillowed: the centre hex shrinks to [1.25, 1.75]^3 and six
/// hexes join its faces to the old faces, adding one closed sheet of 6 hexes and 8 edges.
HexMesh pillowed_brick() {
  HexMesh m = fixture_brick(3, 3, 3);
  const int32_t centre = fixture_brick_hex(3, 3, 1, 1, 1);
  const HexCell outer = m.hexes[centre];
  HexCell inner{};
  for (int v = 0; v < 8; ++v) {
    inner[v] = m.point_count();
    m.points.push_back(Eigen::Vector3d(1.25 + 0.5 * hex_corner[v][0], 1.25 + 0.5 * hex_corner[v][1],
                                       1.25 + 0.5 * hex_corner[v][2]));
  }
  m.hexes[centre] = inner;
  for (int f = 0; f < 6; ++f) {
    // Inner face (counter-clockwise seen from the pillow side) at the bottom, outer face on top:
    // a positively oriented hex whose local z edges are the pillow's radial edges.
    const int* fv = hex_faces[f];
    m.hexes.push_back({inner[fv[0]], inner[fv[1]], inner[fv[2]], inner[fv[3]], outer[fv[0]],
                       outer[fv[1]], outer[fv[2]], outer[fv[3]]});
  }
  return m;
}

TEST(Dual, BrickSheetsAndChords) {
  const int nx = 3, ny = 4, nz = 5;
  const HexMesh m = fixture_brick(nx, ny, nz);
  const HexTopology t = topology_build(m);
  const DualSheets d = dual_build(m, t);
  ASSERT_EQ(d.sheet_count(), nx + ny + nz);
  ASSERT_EQ(d.chord_count(), nx * ny + ny * nz + nx * nz);
  ASSERT_EQ(static_cast<int32_t>(d.edge_sheet.size()), t.edge_count());
  ASSERT_EQ(static_cast<int32_t>(d.face_chord.size()), t.face_count());
  const int hexes_per_axis[3] = {ny * nz, nx * nz, nx * ny};
  const int edges_per_axis[3] = {(ny + 1) * (nz + 1), (nx + 1) * (nz + 1), (nx + 1) * (ny + 1)};
  int sheets_per_axis[3] = {0, 0, 0};
  for (int32_t s = 0; s < d.sheet_count(); ++s) {
    EXPECT_FALSE(d.sheets[s].self_intersecting);
    EXPECT_FALSE(d.sheets[s].closed);
    const int32_t h0 = sheet_hexes(d, s)[0];
    int axis = -1;
    for (int a = 0; a < 3; ++a)
      if (d.hex_sheet[h0][a] == s) axis = a;
    ASSERT_GE(axis, 0);
    ++sheets_per_axis[axis];
    EXPECT_EQ(d.sheets[s].hex_count, hexes_per_axis[axis]);
    EXPECT_EQ(d.sheets[s].edge_count, edges_per_axis[axis]);
    EXPECT_EQ(static_cast<int>(sheet_hexes(d, s).size()), hexes_per_axis[axis]);
  }
  EXPECT_EQ(sheets_per_axis[0], nx);  // x edges: one sheet per slab i
  EXPECT_EQ(sheets_per_axis[1], ny);
  EXPECT_EQ(sheets_per_axis[2], nz);
  // Hexes in the same i-slab share their x sheet; different slabs do not.
  EXPECT_EQ(d.hex_sheet[fixture_brick_hex(nx, ny, 1, 0, 0)][0],
            d.hex_sheet[fixture_brick_hex(nx, ny, 1, 3, 4)][0]);
  EXPECT_NE(d.hex_sheet[fixture_brick_hex(nx, ny, 1, 0, 0)][0],
            d.hex_sheet[fixture_brick_hex(nx, ny, 2, 0, 0)][0]);
  const int chord_hexes[3] = {nx, ny, nz};
  for (int32_t h = 0; h < m.hex_count(); ++h)
    for (int a = 0; a < 3; ++a) {
      const ChordInfo& c = d.chords[d.hex_chord[h][a]];
      EXPECT_EQ(c.hex_count, chord_hexes[a]);
      EXPECT_FALSE(c.closed);
      EXPECT_EQ(sheet_of_edge(d, t.hex_edge_ids[h][hex_axis_edges[a][2]]), d.hex_sheet[h][a]);
      EXPECT_EQ(chord_of_face(d, t.hex_face_ids[h][2 * a + 1]), d.hex_chord[h][a]);
    }
  // Ids in order of first appearance: edge 0 is in sheet 0, face 0 in chord 0.
  EXPECT_EQ(sheet_of_edge(d, 0), 0);
  EXPECT_EQ(chord_of_face(d, 0), 0);
}

TEST(Dual, SingleHex) {
  const HexMesh m = fixture_brick(1, 1, 1);
  const DualSheets d = dual_build(m, topology_build(m));
  EXPECT_EQ(d.sheet_count(), 3);
  EXPECT_EQ(d.chord_count(), 3);
  for (const SheetInfo& s : d.sheets) {
    EXPECT_EQ(s.hex_count, 1);
    EXPECT_EQ(s.edge_count, 4);
  }
}

TEST(Dual, TwistedRingHasOneSelfIntersectingSheet) {
  const HexMesh m = ring(8, true);
  const HexTopology t = topology_build(m);
  ASSERT_EQ(t.edge_count(), 64);
  const DualSheets d = dual_build(m, t);
  // Section edges: the quarter turn joins the x and y classes into one sheet of 32 edges; the
  // ring edges of each hex are a sheet of their own (a slab across the ring).
  ASSERT_EQ(d.sheet_count(), 1 + 8);
  int self_intersecting = 0;
  for (int32_t s = 0; s < d.sheet_count(); ++s) {
    self_intersecting += d.sheets[s].self_intersecting;
    const bool section = d.sheets[s].edge_count == 32;
    EXPECT_EQ(d.sheets[s].self_intersecting, section);
    EXPECT_EQ(d.sheets[s].hex_count, section ? 8 : 1);
    EXPECT_EQ(d.sheets[s].edge_count, section ? 32 : 4);
    EXPECT_FALSE(d.sheets[s].closed);  // 1x1 section: every edge is on the boundary
  }
  EXPECT_EQ(self_intersecting, 1);
  for (int32_t h = 0; h < 8; ++h) {
    EXPECT_EQ(d.hex_sheet[h][0], d.hex_sheet[h][1]);
    EXPECT_NE(d.hex_sheet[h][0], d.hex_sheet[h][2]);
    EXPECT_TRUE(d.sheets[d.hex_sheet[h][0]].self_intersecting);
  }
  // The ring chord (through the station faces) is closed; the side faces are boundary faces of
  // one hex each, so every hex has its own x and y chord (the twist joins no faces).
  ASSERT_EQ(d.chord_count(), 1 + 8 + 8);
  EXPECT_TRUE(d.chords[d.hex_chord[0][2]].closed);
  EXPECT_EQ(d.chords[d.hex_chord[0][2]].hex_count, 8);
  EXPECT_NE(d.hex_chord[0][0], d.hex_chord[0][1]);
  EXPECT_FALSE(d.chords[d.hex_chord[0][0]].closed);
  EXPECT_EQ(d.chords[d.hex_chord[0][0]].hex_count, 1);
}

TEST(Dual, UntwistedRingHasClosedRingChord) {
  const HexMesh m = ring(8, false);
  const HexTopology t = topology_build(m);
  const DualSheets d = dual_build(m, t);
  ASSERT_EQ(d.sheet_count(), 2 + 8);  // x and y sheets around the ring, one slab per hex
  for (const SheetInfo& s : d.sheets) {
    EXPECT_FALSE(s.self_intersecting);
    EXPECT_FALSE(s.closed);
    EXPECT_EQ(s.hex_count, s.edge_count == 16 ? 8 : 1);
  }
  EXPECT_EQ(d.sheets[d.hex_sheet[0][0]].edge_count, 16);
  EXPECT_EQ(d.sheets[d.hex_sheet[0][2]].edge_count, 4);
  ASSERT_EQ(d.chord_count(), 1 + 8 + 8);  // the ring chord, one chord per hex for x and for y
  int closed = 0;
  for (const ChordInfo& c : d.chords) closed += c.closed;
  EXPECT_EQ(closed, 1);
  EXPECT_TRUE(d.chords[d.hex_chord[3][2]].closed);
  EXPECT_EQ(d.chords[d.hex_chord[3][2]].hex_count, 8);
}

TEST(Dual, PillowedCentreHexAddsClosedSheet) {
  const HexMesh m = pillowed_brick();
  ASSERT_EQ(m.hex_count(), 33);
  const HexTopology t = topology_build(m);
  ASSERT_TRUE(t.nonmanifold_faces.empty());
  const DualSheets d = dual_build(m, t);
  // The 9 brick sheets pass through the pillow into the inner hex; the pillow is one more.
  ASSERT_EQ(d.sheet_count(), 10);
  int closed = 0, self = 0;
  int32_t pillow = -1;
  for (int32_t s = 0; s < d.sheet_count(); ++s) {
    self += d.sheets[s].self_intersecting;
    if (d.sheets[s].closed) {
      ++closed;
      pillow = s;
    }
  }
  EXPECT_EQ(self, 0);
  ASSERT_EQ(closed, 1);
  EXPECT_EQ(d.sheets[pillow].hex_count, 6);
  EXPECT_EQ(d.sheets[pillow].edge_count, 8);
  const auto pillow_hexes = sheet_hexes(d, pillow);
  ASSERT_EQ(pillow_hexes.size(), 6u);
  for (int i = 0; i < 6; ++i) EXPECT_EQ(pillow_hexes[i], 27 + i);  // the six new hexes
  for (int32_t h = 27; h < 33; ++h) EXPECT_EQ(d.hex_sheet[h][2], pillow);
  // The middle x sheet now holds 9 - 1 + 1 + 4 (pillow hexes on the y and z faces) hexes.
  const int32_t centre = fixture_brick_hex(3, 3, 1, 1, 1);
  EXPECT_EQ(d.sheets[d.hex_sheet[centre][0]].hex_count, 9 - 1 + 1 + 4);
  // The inner hex's chords continue outward through the pillow; around the inner hex the pillow
  // hexes form three closed rings of four (one around each axis).
  int closed_chords = 0;
  for (const ChordInfo& c : d.chords)
    if (c.closed) {
      ++closed_chords;
      EXPECT_EQ(c.hex_count, 4);
    }
  EXPECT_EQ(closed_chords, 3);
  EXPECT_FALSE(d.chords[d.hex_chord[centre][0]].closed);
  EXPECT_EQ(d.chords[d.hex_chord[centre][0]].hex_count, 5);  // 2 brick + pillow + inner + pillow
}

TEST(Dual, GeneratedTwistedRing) {
  // generate_twisted_ring documents: `around` slabs plus ceil(m / 2) self-intersecting sheets.
  for (const int m : {1, 2, 3}) {
    TwistedRingParams p;
    p.section_intervals = m;
    const HexMesh mesh = generate_twisted_ring(p);
    const DualSheets d = dual_build(mesh, topology_build(mesh));
    const int twisted = (m + 1) / 2;
    ASSERT_EQ(d.sheet_count(), p.around + twisted) << "m = " << m;
    int self = 0, slab_hexes = 0, twisted_hexes = 0;
    for (const SheetInfo& s : d.sheets) {
      EXPECT_FALSE(s.closed);
      self += s.self_intersecting;
      (s.self_intersecting ? twisted_hexes : slab_hexes) += s.hex_count;
    }
    EXPECT_EQ(self, twisted) << "m = " << m;
    EXPECT_EQ(slab_hexes, mesh.hex_count());  // every hex in exactly one slab
    EXPECT_GE(twisted_hexes, mesh.hex_count());
  }
}

TEST(Dual, GeneratedCylinder) {
  // O-grid: 2 n sheets across the square, m rings, one sheet per layer (generators.hpp).
  CylinderParams p;
  p.square_intervals = 3;  // sizes chosen so the three kinds of sheet have distinct hex counts
  p.radial_intervals = 2;
  p.layers = 2;
  const HexMesh mesh = generate_cylinder(p);
  const HexTopology t = topology_build(mesh);
  const DualSheets d = dual_build(mesh, t);
  ASSERT_EQ(d.sheet_count(), 2 * p.square_intervals + p.radial_intervals + p.layers);
  const int n = p.square_intervals, m = p.radial_intervals;
  const int section = n * n + 4 * n * m;
  int layer_sheets = 0, ring_sheets = 0, across_sheets = 0;
  for (const SheetInfo& s : d.sheets) {
    EXPECT_FALSE(s.self_intersecting);
    EXPECT_FALSE(s.closed);  // every sheet reaches the top, bottom or side
    if (s.hex_count == section) {
      ++layer_sheets;
    } else if (s.hex_count == p.layers * 4 * n) {
      ++ring_sheets;  // one ring of the outer blocks, through all layers
    } else if (s.hex_count == p.layers * (n + 2 * m)) {
      ++across_sheets;  // across the square and the two outer blocks it ends in
    }
  }
  EXPECT_EQ(layer_sheets, p.layers);
  EXPECT_EQ(ring_sheets, m);
  EXPECT_EQ(across_sheets, 2 * n);
}

TEST(Dual, EmptyMesh) {
  const HexMesh m;
  const DualSheets d = dual_build(m, topology_build(m));
  EXPECT_EQ(d.sheet_count(), 0);
  EXPECT_EQ(d.chord_count(), 0);
  EXPECT_EQ(d.sheet_hex_offsets.size(), 1u);
}

}  // namespace
}  // namespace hexrefine
