#pragma once
/// \file
/// Flat storage of an all-hex mesh: points and 8-node hexes in the order of hex_convention.hpp,
/// int32 ids, and optional per-hex integer attributes carried through I/O.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace hexrefine {

using HexCell = std::array<int32_t, 8>;

/// A named per-hex integer array (size = number of hexes).
struct HexAttribute {
  std::string name;
  std::vector<int32_t> values;
};

/// Names of the attributes hexrefine itself writes and reads.
inline constexpr std::string_view attribute_block_id = "block_id";
inline constexpr std::string_view attribute_template_tag = "template_tag";
inline constexpr std::string_view attribute_refinement_level = "refinement_level";
/// The input hex each output hex of a refinement came from (untouched hexes: their own id), so
/// fields and materials map from parents to children.
inline constexpr std::string_view attribute_parent_hex = "parent_hex";

/// An all-hexahedral mesh. `hexes[h][i]` indexes `points`; vertex order as in hex_convention.hpp.
/// Invariant (checked by mesh_validate_ids): every id in [0, points.size()), every attribute has
/// hexes.size() values.
struct HexMesh {
  std::vector<Eigen::Vector3d> points;
  std::vector<HexCell> hexes;
  std::vector<HexAttribute> attributes;

  int32_t point_count() const { return static_cast<int32_t>(points.size()); }
  int32_t hex_count() const { return static_cast<int32_t>(hexes.size()); }
};

/// The attribute named `name`, or nullptr.
const std::vector<int32_t>* mesh_find_attribute(const HexMesh& mesh, std::string_view name);

/// The attribute named `name`, created (filled with `fill`) if absent or resized if stale.
/// Creating an attribute may move the others: a reference held across a call that creates one
/// dangles (reserve mesh.attributes first).
std::vector<int32_t>& mesh_attribute(HexMesh& mesh, std::string_view name, int32_t fill = 0);

/// Throws InputError naming the hex if a node id is out of range, a hex repeats a node, or an
/// attribute has the wrong length; `what` names the source (e.g. the file). The first offending
/// hex by id is named, whatever `threads` (>= 1, how many check at once).
void mesh_validate_ids(const HexMesh& mesh, const std::string& what, int threads = 1);

/// Centroid (mean of the 8 corners) of hex `h`.
Eigen::Vector3d hex_centroid(const HexMesh& mesh, int32_t h);

/// The 8 corner positions of hex `h`.
std::array<Eigen::Vector3d, 8> hex_points(const HexMesh& mesh, int32_t h);

/// A part of a mesh as a mesh of its own: the hexes `hexes` (in that order) with their nodes
/// numbered compactly in order of first use; node_of[i] is the node of the whole mesh that local
/// node i is. No attributes. Precondition: mesh_validate_ids(mesh) holds, ids in range.
struct SubMesh {
  HexMesh mesh;
  std::vector<int32_t> node_of;
};
SubMesh mesh_extract(const HexMesh& mesh, const std::vector<int32_t>& hexes);

/// Axis-aligned bounding box of all points (min, max); zero box for an empty mesh.
std::pair<Eigen::Vector3d, Eigen::Vector3d> mesh_bounding_box(const HexMesh& mesh);

}  // namespace hexrefine
