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

/// The name of an element block (Exodus block name, Gmsh or Abaqus physical name). A hex belongs
/// to the block of its block_id attribute; a block id without an entry here is unnamed.
struct BlockName {
  int32_t id = 0;
  std::string name;
};

/// A side set (Exodus side set, Gmsh physical surface, Abaqus *SURFACE, MEDIT quadrilateral
/// reference): faces of hexes as two flat arrays of one length, face k being local face
/// `faces[k]` (0..5, hex_convention.hpp's numbering, converted by readers and writers) of hex
/// `hexes[k]`. Faces may be interior (an interface between blocks); a face appears at most once
/// per (hex, face) pair, and both sides of an interior face may be listed.
struct SideSet {
  int64_t id = 0;    ///< > 0 in every format that numbers sets
  std::string name;  ///< empty when unnamed
  std::vector<int32_t> hexes;
  std::vector<int8_t> faces;
};

/// A node set (Exodus node set, Gmsh physical point or curve, Abaqus *NSET): distinct node ids.
/// `distribution_factors` is empty or has one value per node (Exodus' node set factors).
struct NodeSet {
  int64_t id = 0;
  std::string name;
  std::vector<int32_t> nodes;
  std::vector<double> distribution_factors;
};

/// Where a field lives: one tuple per node or one per hex.
enum class FieldLocation : uint8_t { node, hex };

/// A named float64 field (an Exodus nodal or element variable at one time step, VTK point or
/// cell data, Gmsh $NodeData / $ElementData): `values[i * components + c]` is component c of
/// node or hex i, so values.size() = count * components.
struct MeshField {
  std::string name;
  FieldLocation location = FieldLocation::node;
  int32_t components = 1;
  std::vector<double> values;
};

/// An all-hexahedral mesh. `hexes[h][i]` indexes `points`; vertex order as in hex_convention.hpp.
/// Invariant (checked by mesh_validate_ids): every id in [0, points.size()), every attribute has
/// hexes.size() values, every side set names hexes in range and faces 0..5, every node set names
/// nodes in range, every field has one tuple per node or hex.
///
/// Besides the geometry a mesh carries what an analysis needs from it: element blocks (the
/// block_id attribute, names in block_names), side sets, node sets and fields, plus the title
/// and the time of the fields (the time step read). Readers fill what their format holds;
/// writers write what it can hold and name the rest (mesh_write's result).
struct HexMesh {
  std::vector<Eigen::Vector3d> points;
  std::vector<HexCell> hexes;
  std::vector<HexAttribute> attributes;
  std::vector<BlockName> block_names;
  std::vector<SideSet> side_sets;
  std::vector<NodeSet> node_sets;
  std::vector<MeshField> fields;
  std::string title;        ///< Exodus title, or empty
  double field_time = 0.0;  ///< the time of `fields` (Exodus time value of the step read)

  int32_t point_count() const { return static_cast<int32_t>(points.size()); }
  int32_t hex_count() const { return static_cast<int32_t>(hexes.size()); }
};

/// The attribute named `name`, or nullptr.
const std::vector<int32_t>* mesh_find_attribute(const HexMesh& mesh, std::string_view name);

/// The attribute named `name`, created (filled with `fill`) if absent or resized if stale.
/// Creating an attribute may move the others: a reference held across a call that creates one
/// dangles (reserve mesh.attributes first).
std::vector<int32_t>& mesh_attribute(HexMesh& mesh, std::string_view name, int32_t fill = 0);

/// The name of block `id`, or "" when unnamed.
std::string_view mesh_block_name(const HexMesh& mesh, int32_t id);

/// The field named `name` at `location`, or nullptr.
const MeshField* mesh_find_field(const HexMesh& mesh, std::string_view name,
                                 FieldLocation location);

/// How a set is named in messages and reports: `side set 3 'inlet'`, `node set 10` (unnamed).
std::string side_set_label(const SideSet& set);
std::string node_set_label(const NodeSet& set);

/// True when the mesh carries nothing beyond points, hexes and attributes (no block names, sets,
/// fields or title): the fast paths of refine and convert skip the mapping then.
bool mesh_has_annotations(const HexMesh& mesh);

/// Throws InputError naming the hex if a node id is out of range, a hex repeats a node, or an
/// attribute has the wrong length, or a side set, node set or field is inconsistent (the set or
/// field and the entry named: "side set 2 'top': entry 5 names face 7 of hex 12, expected 0..5");
/// `what` names the source (e.g. the file). The first offending
/// hex by id is named, whatever `threads` (>= 1, how many check at once).
void mesh_validate_ids(const HexMesh& mesh, const std::string& what, int threads = 1);

/// Centroid (mean of the 8 corners) of hex `h`.
Eigen::Vector3d hex_centroid(const HexMesh& mesh, int32_t h);

/// The 8 corner positions of hex `h`.
std::array<Eigen::Vector3d, 8> hex_points(const HexMesh& mesh, int32_t h);

/// A part of a mesh as a mesh of its own: the hexes `hexes` (in that order) with their nodes
/// numbered compactly in order of first use; node_of[i] is the node of the whole mesh that local
/// node i is. No attributes, sets or fields. Precondition: mesh_validate_ids(mesh) holds, ids in
/// range.
struct SubMesh {
  HexMesh mesh;
  std::vector<int32_t> node_of;
};
SubMesh mesh_extract(const HexMesh& mesh, const std::vector<int32_t>& hexes);

/// Axis-aligned bounding box of all points (min, max); zero box for an empty mesh.
std::pair<Eigen::Vector3d, Eigen::Vector3d> mesh_bounding_box(const HexMesh& mesh);

}  // namespace hexrefine
