#pragma once
/// \file
/// The 48 symmetries of the cube (rotations and reflections): how a template given in canonical
/// orientation is turned onto a hex whose split edges are elsewhere. Each symmetry is stored as
/// its action on coordinates and, derived from it, on the local vertices, edges and faces of
/// mesh/hex_convention.hpp.

#include <array>
#include <cstdint>

namespace hexrefine {

/// One symmetry of the cube: reference point p maps to q[k] = flip[k] ? 1 - p[axis[k]] :
/// p[axis[k]].
struct CubeSymmetry {
  std::array<int8_t, 3> axis;
  std::array<bool, 3> flip;
  bool reflection;               ///< determinant -1 (children must be re-oriented)
  std::array<int8_t, 8> vertex;  ///< canonical local vertex -> actual local vertex
  std::array<int8_t, 12> edge;   ///< canonical local edge -> actual local edge
  std::array<int8_t, 6> face;    ///< canonical local face -> actual local face
};

/// The 48 symmetries: the 6 axis permutations in lexicographic order, each with the 8 flip
/// patterns (bit k flips axis k); index 0 is the identity, 24 are reflections.
const std::array<CubeSymmetry, 48>& cube_symmetries();

/// Maps a reference point by a symmetry.
std::array<double, 3> cube_symmetry_apply(const CubeSymmetry& s, const std::array<double, 3>& p);

/// Bit mask of local edges (bit e = local edge e) mapped by a symmetry.
uint16_t cube_symmetry_edge_mask(const CubeSymmetry& s, uint16_t canonical_mask);

/// Vertex order of a child hex after a reflection: swapping local vertices 1 <-> 3 and 5 <-> 7
/// turns a mirrored (negatively oriented) hex back to positive orientation.
inline constexpr std::array<int8_t, 8> hex_reflected_order = {0, 3, 2, 1, 4, 7, 6, 5};

}  // namespace hexrefine
