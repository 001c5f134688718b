#pragma once
/// \file
/// Mesh generators: the structured and block-structured all-hex meshes the experiments and tests
/// run on (bricks, a gear-like part, an O-grid cylinder, a twisted ring with a self-intersecting
/// sheet, the stepped model of the thesis' Table 6-1). Each is a free function taking a small
/// parameter struct; every parameter has a documented default and range, and a value outside it
/// is an InputError naming the parameter. Every generated hex has positive corner Jacobians
/// (scaled Jacobian > 0) and the vertex order of hex_convention.hpp.
///
/// Orientation words used by the experiments (the thesis' cases) for bricks and the stepped
/// model: "left" = x-min, "right" = x-max, "front" = y-min, "back" = y-max, "bottom" = z-min,
/// "top" = z-max; so the "top front right vertex" of an LX x LY x LZ brick is (LX, 0, LZ).

#include <array>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "mesh/hex_mesh.hpp"

namespace hexrefine {

/// An axis-aligned brick of NX x NY x NZ hexes spanning [0,LX] x [0,LY] x [0,LZ].
struct BrickParams {
  std::array<int, 3> dims{1, 1, 1};           ///< hexes per axis, each >= 1
  std::array<double, 3> size{1.0, 1.0, 1.0};  ///< extent per axis, each > 0
  /// Random displacement of interior nodes, per axis, as a fraction of that axis' spacing:
  /// uniform in [-jitter, +jitter] * spacing; 0 <= jitter < 0.5. Boundary nodes never move, so
  /// the six faces stay planar.
  double jitter = 0.0;
  uint64_t seed = 1;  ///< seed of the std::mt19937_64 that draws the jitter
};

/// Node id of grid node (i, j, k), 0 <= i <= NX etc.: numbered x fastest, then y, then z
/// (i + (NX+1) * (j + (NY+1) * k)), as tests/fixtures.hpp's fixture_brick.
inline int32_t brick_node(const std::array<int, 3>& dims, int i, int j, int k) {
  return static_cast<int32_t>(i + (dims[0] + 1) * (j + (dims[1] + 1) * k));
}

/// Hex id of cell (i, j, k), 0 <= i < NX etc.: x fastest (i + NX * (j + NY * k)). Its local
/// vertex 0 is node (i, j, k) and its local axes are the global x, y, z.
inline int32_t brick_hex(const std::array<int, 3>& dims, int i, int j, int k) {
  return static_cast<int32_t>(i + dims[0] * (j + dims[1] * k));
}

/// The brick. Jitter is drawn from std::mt19937_64(seed) (three draws per interior node, nodes
/// in id order, axes x, y, z; uniform u = (raw >> 11) * 2^-53, so the numbers are the same on
/// every platform). A hex left with a non-positive corner Jacobian has the displacements of its
/// nodes halved, repeatedly, until every hex is valid (always reached: zero displacement is the
/// regular grid). Deterministic: same parameters, same points.
HexMesh generate_brick(const BrickParams& params);

/// A gear-like part: a toothed annulus in the xy-plane extruded along z over [0, thickness].
/// The body is an annulus inner_radius <= r <= root_radius meshed with body_radial x
/// (teeth * (tooth_tangential + gap_tangential)) quads; on the root circle every tooth stands on
/// tooth_tangential of those intervals and is meshed with tooth_radial x tooth_tangential quads
/// whose sides taper linearly from the root to tip_fraction of the root width at the tip.
/// Hex count = layers * teeth * ((tooth_tangential + gap_tangential) * body_radial +
/// tooth_tangential * tooth_radial). The defaults give 7 * 24 * (6 * 7 + 3 * 3) = 8,568 hexes
/// (the thesis' gear has 8,569; its text says 8,568).
/// Attribute block_id: 1 for the body, 2 for the teeth (selection `block:2`).
struct GearParams {
  int teeth = 24;             ///< >= 3
  double inner_radius = 0.5;  ///< > 0
  double root_radius = 1.0;   ///< > inner_radius
  double tip_radius = 1.25;   ///< > root_radius
  double thickness = 0.3;     ///< > 0
  int layers = 7;             ///< hex layers through the thickness, >= 1
  int body_radial = 7;        ///< radial intervals of the body, >= 1
  int tooth_radial = 3;       ///< radial intervals of a tooth, >= 1
  int tooth_tangential = 3;   ///< intervals across a tooth, >= 1
  int gap_tangential = 3;     ///< intervals across the gap between teeth, >= 1
  double tip_fraction = 0.6;  ///< tip width / root width of a tooth, in (0, 1]
};

/// Block ids of generate_gear.
inline constexpr int32_t gear_block_body = 1;
inline constexpr int32_t gear_block_teeth = 2;

HexMesh generate_gear(const GearParams& params);

/// A cylinder of radius `radius` about the z-axis over [0, height], its section an O-grid
/// ("butterfly"): a central square_intervals x square_intervals block (half-side core * radius)
/// and four outer blocks of square_intervals x radial_intervals quads joining the square's sides
/// to quarter arcs of the circle. The four edges through the square's corners have valence 3
/// (irregular); every other interior edge has valence 4. An O-grid has no interior edge of
/// valence 5. Hexes = layers * (n^2 + 4 n m); dual sheets = 2 n + m + layers (n chords across
/// the square per direction, m closed rings, one sheet per layer).
struct CylinderParams {
  double radius = 1.0;       ///< > 0
  double height = 1.0;       ///< > 0
  int square_intervals = 4;  ///< n, >= 1
  int radial_intervals = 3;  ///< m, >= 1
  int layers = 4;            ///< >= 1
  double core = 0.45;        ///< half-side of the square / radius, in (0, 0.7)
};

HexMesh generate_cylinder(const CylinderParams& params);

/// A closed ring of hexes about the z-axis: `around` layers of section_intervals^2 hexes, the
/// square section (side section_size, centred on the circle of radius ring_radius, spanned by
/// the radial and z directions) turning a quarter turn about the ring's centre line over the
/// full circuit. The last layer's nodes are the first layer's, rotated: section node (a, b) of
/// layer `around` is node (m - b, a) of layer 0 (m = section_intervals), so the two in-section
/// directions join. Sheets: `around` section slabs (one per layer) plus ceil(m / 2) sheets made
/// of the in-section chords, every one of them self-intersecting (its hexes on the section's
/// diagonals have two of their three directions in it). Default m = 1: exactly one
/// self-intersecting sheet, which holds every hex. There are no boundary faces across the ring
/// direction: the boundary is the 4 m * around faces of the section's perimeter.
struct TwistedRingParams {
  double ring_radius = 1.0;   ///< > 0
  double section_size = 0.5;  ///< in (0, ring_radius)
  int around = 16;            ///< hex layers around the ring, >= 8
  int section_intervals = 1;  ///< m, >= 1
};

HexMesh generate_twisted_ring(const TwistedRingParams& params);

/// The stepped model standing in for the thesis' Table 6-1 model (1,188 hexes, all unit cubes,
/// initial minimum quality 1.0): a staircase of `steps` steps, each `step_layers` hex layers
/// tall, extruded `depth` hexes along y. Step s (s = 0 at the bottom) spans
/// top_width + tread * (steps - 1 - s) hexes along x, so the bottom step is the widest and the
/// right (x-max) boundary is made of `steps` vertical surfaces (risers) joined by treads; all
/// steps share the left face x = 0. The inner corner of each step (where a riser meets the tread
/// below) gives multiply-connected transition hexes when the right boundary is refined.
/// Hexes = depth * step_layers * sum over s of the widths; defaults: 12 * 3 * (9 + 11 + 13) =
/// 1,188 in a 13 x 12 x 9 bounding box of `cell`-sized cubes.
struct SteppedParams {
  int steps = 3;        ///< >= 1
  int step_layers = 3;  ///< hex layers per step, >= 1
  int depth = 12;       ///< hexes along y, >= 1
  int top_width = 9;    ///< hexes along x of the top step, >= 1
  int tread = 2;        ///< extra hexes along x of each lower step, >= 1
  double cell = 1.0;    ///< hex edge length, > 0
};

HexMesh generate_stepped(const SteppedParams& params);

// The parameter structs as JSON (case files, reports): every field under its own name, missing
// fields keep their defaults.
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(BrickParams, dims, size, jitter, seed)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(GearParams, teeth, inner_radius, root_radius,
                                                tip_radius, thickness, layers, body_radial,
                                                tooth_radial, tooth_tangential, gap_tangential,
                                                tip_fraction)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(CylinderParams, radius, height, square_intervals,
                                                radial_intervals, layers, core)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(TwistedRingParams, ring_radius, section_size,
                                                around, section_intervals)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(SteppedParams, steps, step_layers, depth, top_width,
                                                tread, cell)

/// One parameter of a generator as the front ends see it: the CLI's `generate` option
/// (--name, '_' written '-') and the case files' "mesh" key.
struct GeneratorField {
  std::string name;  ///< the parameter struct's field
  std::string help;  ///< meaning and range
};

/// A generator for the front ends: its parameters in one table, built from its parameter
/// struct (the JSON conversion above gives each field's kind and default).
struct Generator {
  std::string name;  ///< "brick", "gear", "cylinder", "twisted-ring", "stepped"
  std::string description;
  std::vector<GeneratorField> fields;
  nlohmann::json defaults;  ///< the parameter struct's defaults as JSON
  /// Builds the mesh from complete, kind-checked parameters (generator_params).
  HexMesh (*generate)(const nlohmann::json& params);
};

/// Every generator, in a fixed order.
const std::vector<Generator>& generators();

/// The generator called `name` ("twisted_ring" is accepted for "twisted-ring"); InputError
/// listing the known names otherwise.
const Generator& generator_find(std::string_view name);

/// Checks `given` (an object of parameter name -> value) against the generator's fields: every
/// key a field, every value of the field's kind (an integer, >= 0 where the default is unsigned;
/// a number; three integers; three numbers). Returns the complete parameters (defaults filled
/// in). Throws InputError "`where`/key: what was expected". Ranges are checked by the generator.
nlohmann::json generator_params(const Generator& generator, const nlohmann::json& given,
                                const std::string& where);

}  // namespace hexrefine
