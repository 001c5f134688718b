#include "algorithms/templates/cube_symmetry.hpp"

#include <algorithm>
#include <cmath>

#include "mesh/hex_convention.hpp"

namespace hexrefine {

namespace {

std::array<CubeSymmetry, 48> symmetries_make() {
  std::array<CubeSymmetry, 48> out{};
  std::array<int8_t, 3> perm = {0, 1, 2};
  int n = 0;
  do {
    // Sign of the permutation: even for the identity and the two 3-cycles.
    const bool even = (perm[0] == 0 && perm[1] == 1) || (perm[0] == 1 && perm[1] == 2) ||
                      (perm[0] == 2 && perm[1] == 0);
    for (int flips = 0; flips < 8; ++flips) {
      CubeSymmetry s{};
      s.axis = perm;
      bool negative = !even;
      for (int k = 0; k < 3; ++k) {
        s.flip[k] = (flips >> k) & 1;
        negative ^= s.flip[k];
      }
      s.reflection = negative;
      for (int v = 0; v < 8; ++v) {
        const std::array<double, 3> q = cube_symmetry_apply(
            s, {double(hex_corner[v][0]), double(hex_corner[v][1]), double(hex_corner[v][2])});
        s.vertex[v] = static_cast<int8_t>(
            hex_vertex_at(int(std::lround(q[0])), int(std::lround(q[1])), int(std::lround(q[2]))));
      }
      for (int e = 0; e < 12; ++e)
        s.edge[e] = static_cast<int8_t>(
            hex_edge_joining(s.vertex[hex_edges[e][0]], s.vertex[hex_edges[e][1]]));
      for (int f = 0; f < 6; ++f)
        for (int g = 0; g < 6; ++g) {
          int matched = 0;
          for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j) matched += s.vertex[hex_faces[f][i]] == hex_faces[g][j];
          if (matched == 4) s.face[f] = static_cast<int8_t>(g);
        }
      out[n++] = s;
    }
  } while (std::next_permutation(perm.begin(), perm.end()));
  return out;
}

}  // namespace

const std::array<CubeSymmetry, 48>& cube_symmetries() {
  static const std::array<CubeSymmetry, 48> table = symmetries_make();
  return table;
}

std::array<double, 3> cube_symmetry_apply(const CubeSymmetry& s, const std::array<double, 3>& p) {
  std::array<double, 3> q{};
  for (int k = 0; k < 3; ++k) q[k] = s.flip[k] ? 1.0 - p[s.axis[k]] : p[s.axis[k]];
  return q;
}

uint16_t cube_symmetry_edge_mask(const CubeSymmetry& s, uint16_t canonical_mask) {
  uint16_t out = 0;
  for (int e = 0; e < 12; ++e)
    if (canonical_mask & (1u << e)) out |= static_cast<uint16_t>(1u << s.edge[e]);
  return out;
}

}  // namespace hexrefine
