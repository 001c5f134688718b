#pragma once
/// \file
/// The reference hexahedron: the one vertex order, edge and face numbering used everywhere in
/// hexrefine. It is VTK's and Exodus II's HEX8 order; other orders are converted only inside the
/// file readers and writers.
///
/// ```
///            7 ----e6----- 6           z
///           /|            /|           |  y
///         e7 |          e5 |           | /
///         /  e11        /  e10         |/
///        4 ----e4----- 5   |           +----- x
///        |   |         |   |
///        |   3 ----e2--|-- 2           corners (x,y,z) in {0,1}^3:
///       e8  /         e9  /            0 (0,0,0)  1 (1,0,0)  2 (1,1,0)  3 (0,1,0)
///        | e3          | e1            4 (0,0,1)  5 (1,0,1)  6 (1,1,1)  7 (0,1,1)
///        |/            |/
///        0 ----e0----- 1
/// ```
///
/// Edges are grouped by direction (x: e0 e2 e4 e6, y: e1 e3 e5 e7, z: e8..e11) and each runs
/// from its lower to its higher corner along its axis. Faces are numbered -x, +x, -y, +y, -z, +z,
/// so face f is normal to axis f/2 and its opposite face is f^1; face nodes are ordered
/// counter-clockwise seen from outside (outward normal by the right-hand rule).

#include <array>
#include <cstdint>

namespace hexrefine {

/// Corner coordinates of the reference (unit) hex, per local vertex.
inline constexpr int hex_corner[8][3] = {
    {0, 0, 0},  // v0
    {1, 0, 0},  // v1
    {1, 1, 0},  // v2
    {0, 1, 0},  // v3
    {0, 0, 1},  // v4
    {1, 0, 1},  // v5
    {1, 1, 1},  // v6
    {0, 1, 1},  // v7
};

/// Local edges as (from, to) local vertices, oriented along +axis.
inline constexpr int hex_edges[12][2] = {
    {0, 1},  // e0  x  y=0 z=0
    {1, 2},  // e1  y  x=1 z=0
    {3, 2},  // e2  x  y=1 z=0
    {0, 3},  // e3  y  x=0 z=0
    {4, 5},  // e4  x  y=0 z=1
    {5, 6},  // e5  y  x=1 z=1
    {7, 6},  // e6  x  y=1 z=1
    {4, 7},  // e7  y  x=0 z=1
    {0, 4},  // e8  z  x=0 y=0
    {1, 5},  // e9  z  x=1 y=0
    {2, 6},  // e10 z  x=1 y=1
    {3, 7},  // e11 z  x=0 y=1
};

/// Axis (0 = x, 1 = y, 2 = z) of each local edge.
inline constexpr int hex_edge_axis[12] = {0, 1, 0, 1, 0, 1, 0, 1, 2, 2, 2, 2};

/// The four local edges parallel to each axis.
inline constexpr int hex_axis_edges[3][4] = {
    {0, 2, 4, 6},    // x
    {1, 3, 5, 7},    // y
    {8, 9, 10, 11},  // z
};

/// Local faces, counter-clockwise seen from outside.
inline constexpr int hex_faces[6][4] = {
    {0, 4, 7, 3},  // f0 -x
    {1, 2, 6, 5},  // f1 +x
    {0, 1, 5, 4},  // f2 -y
    {3, 7, 6, 2},  // f3 +y
    {0, 3, 2, 1},  // f4 -z
    {4, 5, 6, 7},  // f5 +z
};

/// The four local edges of each face, edge i joining face vertices i and i+1 (mod 4).
inline constexpr int hex_face_edges[6][4] = {
    {8, 7, 11, 3},   // f0
    {1, 10, 5, 9},   // f1
    {0, 9, 4, 8},    // f2
    {11, 6, 10, 2},  // f3
    {3, 2, 1, 0},    // f4
    {4, 5, 6, 7},    // f5
};

/// The two faces that contain each edge (lower face index first).
inline constexpr int hex_edge_faces[12][2] = {
    {2, 4},  // e0
    {1, 4},  // e1
    {3, 4},  // e2
    {0, 4},  // e3
    {2, 5},  // e4
    {1, 5},  // e5
    {3, 5},  // e6
    {0, 5},  // e7
    {0, 2},  // e8
    {1, 2},  // e9
    {1, 3},  // e10
    {0, 3},  // e11
};

/// Opposite face of each face (always f ^ 1).
inline constexpr int hex_opposite_face[6] = {1, 0, 3, 2, 5, 4};

/// The three local edges at each vertex, one per axis (x, y, z).
inline constexpr int hex_vertex_edges[8][3] = {
    {0, 3, 8},   // v0
    {0, 1, 9},   // v1
    {2, 1, 10},  // v2
    {2, 3, 11},  // v3
    {4, 7, 8},   // v4
    {4, 5, 9},   // v5
    {6, 5, 10},  // v6
    {6, 7, 11},  // v7
};

/// Local vertex at corner (x, y, z) of the reference cube, each coordinate 0 or 1.
constexpr int hex_vertex_at(int x, int y, int z) {
  for (int v = 0; v < 8; ++v)
    if (hex_corner[v][0] == x && hex_corner[v][1] == y && hex_corner[v][2] == z) return v;
  return -1;
}

/// Local edge joining local vertices a and b (either order), or -1 if they are not adjacent.
constexpr int hex_edge_joining(int a, int b) {
  for (int e = 0; e < 12; ++e)
    if ((hex_edges[e][0] == a && hex_edges[e][1] == b) ||
        (hex_edges[e][0] == b && hex_edges[e][1] == a))
      return e;
  return -1;
}

namespace convention_detail {
constexpr bool face_has_vertex(int f, int v) {
  for (int i = 0; i < 4; ++i)
    if (hex_faces[f][i] == v) return true;
  return false;
}
constexpr bool edges_well_formed() {
  for (int e = 0; e < 12; ++e) {
    const int a = hex_edges[e][0], b = hex_edges[e][1];
    int differing = 0, axis = -1;
    for (int k = 0; k < 3; ++k)
      if (hex_corner[a][k] != hex_corner[b][k]) ++differing, axis = k;
    if (differing != 1 || axis != hex_edge_axis[e]) return false;
    if (hex_corner[a][axis] != 0 || hex_corner[b][axis] != 1) return false;
    for (int f : hex_edge_faces[e])
      if (!face_has_vertex(f, a) || !face_has_vertex(f, b)) return false;
  }
  return true;
}
constexpr bool faces_well_formed() {
  for (int f = 0; f < 6; ++f) {
    const int axis = f / 2, side = f % 2;
    for (int i = 0; i < 4; ++i) {
      const int v = hex_faces[f][i];
      if (hex_corner[v][axis] != side) return false;
      const int e = hex_face_edges[f][i];
      const int w = hex_faces[f][(i + 1) % 4];
      const bool joins = (hex_edges[e][0] == v && hex_edges[e][1] == w) ||
                         (hex_edges[e][0] == w && hex_edges[e][1] == v);
      if (!joins) return false;
    }
    // Outward orientation: (p1 - p0) x (p3 - p0) points along the outward normal.
    const int* p0 = hex_corner[hex_faces[f][0]];
    const int* p1 = hex_corner[hex_faces[f][1]];
    const int* p3 = hex_corner[hex_faces[f][3]];
    const int u[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
    const int w[3] = {p3[0] - p0[0], p3[1] - p0[1], p3[2] - p0[2]};
    const int n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2],
                      u[0] * w[1] - u[1] * w[0]};
    const int expected = side == 0 ? -1 : 1;
    for (int k = 0; k < 3; ++k)
      if (n[k] != (k == axis ? expected : 0)) return false;
  }
  return true;
}
constexpr bool opposite_faces_disjoint() {
  for (int f = 0; f < 6; ++f) {
    if (hex_opposite_face[f] != (f ^ 1)) return false;
    for (int i = 0; i < 4; ++i)
      if (face_has_vertex(hex_opposite_face[f], hex_faces[f][i])) return false;
  }
  return true;
}
constexpr bool vertex_edges_well_formed() {
  for (int v = 0; v < 8; ++v)
    for (int k = 0; k < 3; ++k) {
      const int e = hex_vertex_edges[v][k];
      if (hex_edge_axis[e] != k) return false;
      if (hex_edges[e][0] != v && hex_edges[e][1] != v) return false;
    }
  return true;
}
}  // namespace convention_detail

static_assert(convention_detail::edges_well_formed(), "edge table disagrees with corners/faces");
static_assert(convention_detail::faces_well_formed(), "face table not outward or edges mismatched");
static_assert(convention_detail::opposite_faces_disjoint(), "opposite faces must share no vertex");
static_assert(convention_detail::vertex_edges_well_formed(), "vertex-edge table wrong");
static_assert(hex_vertex_at(1, 1, 1) == 6 && hex_edge_joining(3, 7) == 11, "lookups wrong");

}  // namespace hexrefine
