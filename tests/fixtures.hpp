#pragma once
/// \file
/// Small hand-built meshes shared by the tests (one cube, n x m x k bricks, the L-shaped case).

#include "mesh/hex_mesh.hpp"

namespace hexrefine {

/// Unit-spaced nx x ny x nz brick, nodes numbered x fastest, hexes x fastest.
inline HexMesh fixture_brick(int nx, int ny, int nz, double h = 1.0) {
  HexMesh m;
  auto id = [&](int i, int j, int k) {
    return static_cast<int32_t>(i + (nx + 1) * (j + (ny + 1) * k));
  };
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) m.points.emplace_back(i * h, j * h, k * h);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        m.hexes.push_back({id(i, j, k), id(i + 1, j, k), id(i + 1, j + 1, k), id(i, j + 1, k),
                           id(i, j, k + 1), id(i + 1, j, k + 1), id(i + 1, j + 1, k + 1),
                           id(i, j + 1, k + 1)});
  return m;
}

/// Id of hex (i, j, k) in fixture_brick(nx, ny, nz).
inline int32_t fixture_brick_hex(int nx, int ny, int i, int j, int k) {
  return i + nx * (j + ny * k);
}

}  // namespace hexrefine
