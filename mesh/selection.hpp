#pragma once
/// \file
/// Target selection for `hexrefine refine --select SPEC`: which hexes a refiner is asked to
/// refine. Several SPECs are united.
///
/// SPEC forms (numbers as in cli_parse_double, ids 0-based):
/// - `all`                          every hex;
/// - `hexes:FILE`                   ids listed in FILE, separated by whitespace; `#` starts a
///                                  comment to the end of the line;
/// - `box:x0,y0,z0,x1,y1,z1`        hexes whose centroid lies in the box, bounds inclusive
///                                  (x0 <= x1, y0 <= y1, z0 <= z1);
/// - `sphere:cx,cy,cz,r`            hexes whose centroid is within distance r >= 0 of the centre;
/// - `boundary:nx,ny,nz[,deg]`      hexes with a boundary face whose outward unit normal is within
///                                  deg (default 30, in [0, 180]) of the direction (nx, ny, nz)
///                                  (non-zero): `boundary:-1,0,0` is the left surface;
/// - `block:ID[,ID...]`             hexes whose `block_id` attribute is one of the ids;
/// - `random:FRACTION,SEED`          scattered hexes: each with probability FRACTION in (0, 1],
///                                  drawn in hex order from std::mt19937_64(SEED) (uniform from the
///                                  top 53 bits: the same set on every platform);
/// - `blob:COUNT,SEED`              a grown blob: from a hex drawn by std::mt19937_64(SEED)
///                                  (raw % hex count), the first COUNT hexes of a breadth-first
///                                  walk across faces (neighbours in local face order);
/// - `surface:RANK[,DEG]`           the hexes on one surface of the boundary: the boundary's
///                                  patches at feature angle DEG (default 30; boundary_surface.hpp)
///                                  by decreasing face count, RANK 0 the largest.

#include <cstdint>
#include <string>
#include <vector>

#include "mesh/hex_mesh.hpp"
#include "mesh/topology.hpp"

namespace hexrefine {

struct Selection {
  std::vector<int32_t> hexes;  ///< ascending, unique
  std::string warning;         ///< non-empty when the selection matches no hex
};

/// Unites the hexes selected by `specs`. Throws InputError naming the spec when it is malformed,
/// naming "FILE:line" for a bad token or an out-of-range id in a hexes file (or the file when it
/// cannot be read), and when `block:` is used on a mesh without a block_id attribute. An empty
/// result is not an error: `warning` says which specs matched nothing and callers leave the mesh
/// as it is. Precondition: `topology` was built from `mesh`.
Selection select_hexes(const HexMesh& mesh, const HexTopology& topology,
                       const std::vector<std::string>& specs);

/// As above; the faces are built (TopologyParts::faces) only when a `boundary:`, `blob:` or
/// `surface:` spec needs them.
Selection select_hexes(const HexMesh& mesh, const std::vector<std::string>& specs);

}  // namespace hexrefine
