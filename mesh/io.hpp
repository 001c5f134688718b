#pragma once
/// \file
/// Reading and writing hex meshes: MEDIT (.mesh), VTK legacy (.vtk, ASCII or BINARY), VTK XML
/// unstructured grid (.vtu), Gmsh (.msh: 4.1 read and write, 2.2 read; text or binary), Exodus II
/// (.e, .exo) and Abaqus input (.inp). The format is chosen by the file extension.
///
/// Vertex order: all six formats store a linear hexahedron in the order of hex_convention.hpp
/// (0-3 one face counter-clockwise, 4-7 the opposite face with 4 above 0): VTK_HEXAHEDRON, Exodus
/// HEX8, Gmsh type 5, Abaqus C3D8 and MEDIT Hexahedra all agree, so no reordering is needed. The
/// one exception is VTK_VOXEL (type 11, read only), whose nodes 2/3 and 6/7 are swapped; the VTK
/// reader reorders it into a hex.
///
/// Elements that are not hexes: surface, line and point elements (boundary annotations such as
/// MEDIT Quadrilaterals, Gmsh surface entities, VTK quads) are skipped silently; volume elements
/// that are not linear hexes (tetrahedra, prisms, pyramids, 20/27-node hexes, polyhedra) are
/// refused with an InputError naming the element, because dropping them would silently give a
/// mesh with holes.
///
/// Per-hex attributes (HexMesh::attributes):
/// - VTK legacy, VTU: every attribute as an int cell-data array; on reading, every
///   single-component integer cell array becomes an attribute (float arrays are skipped).
/// - MEDIT: the hex reference tag is block_id (0 when the mesh has none).
/// - Gmsh 4.1: block_id > 0 is the physical tag of the hex's volume entity; every attribute
///   (block_id included, so zero and negative ids survive) is also written as an $ElementData
///   field. On reading, block_id comes from the physical tag (0 without one) and is overridden by
///   an $ElementData field of that name; every single-component $ElementData field whose values
///   are all integers becomes an attribute.
/// - Exodus II: written in netCDF classic storage, read in classic and netCDF-4 (HDF5) storage.
///   One element block per block_id (id 1 when the mesh has no block_id). Hexes keep
///   their order through the element id map (written as hex index + 1; when a file's element ids
///   are a permutation of 1..n the reader orders hexes by id). Every other attribute (parent_hex,
///   template_tag, ...) and every cell scalar is an element variable at one time step; on
///   reading, element variables whose values are all integers become attributes.
/// - Abaqus: one `*ELSET, ELSET=BLOCK_<id>` per block_id; on reading, elsets named
///   `BLOCK_<integer>` (any case) give block_id, other hexes get 0.
/// Other attributes are dropped by MEDIT and Abaqus.
///
/// Every reader calls mesh_validate_ids, refuses faces shared by more than two hexes, NaN or
/// infinite coordinates, counts that the file is too small to hold (checked before allocating),
/// and names the file and line (or entity) in its InputError.

#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "mesh/hex_mesh.hpp"

namespace hexrefine {

enum class MeshFormat { medit, vtk_legacy, vtu, gmsh, exodus, abaqus };

/// Format from the extension (case-insensitive): .mesh .vtk .vtu .msh .e/.exo .inp; InputError
/// naming the path otherwise.
MeshFormat mesh_format_of(const std::string& path);

struct MeshWriteOptions {
  bool binary = false;  ///< VTK legacy: BINARY instead of ASCII; Gmsh: binary (file type 1)
  /// VTU: text (format="ascii") instead of the default appended raw binary data.
  bool ascii = false;
  /// VTU: zlib-compress the appended data (vtkZLibDataCompressor); ignored with `ascii`.
  bool compress = false;
  /// Extra per-hex double fields (e.g. "scaled_jacobian"), written as cell data where the format
  /// has it (VTK, VTU; Gmsh as $ElementData). Each needs hex_count() values.
  std::vector<std::pair<std::string, std::vector<double>>> cell_scalars;
};

struct MeshReadOptions {
  /// Refuse a mesh with a face shared by more than two hexes (mesh_require_manifold). Only a
  /// caller that matches the faces itself right after reading, and refuses the same way, turns it
  /// off: `hexrefine check`, whose checker counts non-manifold faces (matching the faces of an
  /// 11.4 M-hex mesh twice cost a second).
  bool manifold_test = true;
  /// Which time step's fields to read where a format holds several (Exodus; Gmsh data blocks
  /// with a time step): 0 the last, K >= 1 the K-th (Exodus' numbering). A step the file does not
  /// have is an InputError naming the steps it has.
  int64_t time_step = 0;
  /// When set, receives one line per thing the file holds that the mesh cannot carry (e.g.
  /// "global variable 'energy'", "239 info records"): the caller warns and reports them.
  std::vector<std::string>* dropped = nullptr;
};

/// Reads a hex mesh; the format follows from the extension. Throws InputError
/// "path:line: what was expected" on bad input, and for ids out of range or repeated in a hex.
HexMesh mesh_read(const std::string& path, const MeshReadOptions& options = {});

/// Throws InputError "path: non-manifold mesh: face with nodes a b c d (0-based) is shared by
/// more than two hexes (N such faces)" when a face is. Precondition: mesh_validate_ids holds.
void mesh_require_manifold(const HexMesh& mesh, const std::string& path);

/// Reads a hex mesh from the bytes of a file held in memory (fuzzing, tests, data received by
/// other means). `name` gives the format by its extension (as mesh_read) and names the source in
/// messages; the checks are those of mesh_read. Exodus II needs a file for its library: the bytes
/// are written to a temporary file in the system temp folder, read and removed.
HexMesh mesh_read_from_memory(const std::string& name, std::string_view bytes);

/// What each format can hold of a mesh's annotations (HexMesh): one row per format in io.cpp,
/// from which mesh_write names what it drops.
struct MeshFormatHolds {
  bool block_names = false;
  bool side_sets = false;
  bool node_sets = false;
  bool node_fields = false;
  bool hex_fields = false;
  bool node_set_distribution_factors = false;
  bool title = false;
};
MeshFormatHolds mesh_format_holds(MeshFormat format);

/// What writing `mesh` in `format` leaves out, one line each ("side set 1 'inlet'", "nodal field
/// 'temperature'", "title"), in the order of the mesh's lists; empty when the format holds all.
std::vector<std::string> mesh_format_drops(const HexMesh& mesh, MeshFormat format);

/// Writes `mesh` atomically (temporary file + rename). Throws InputError for a mesh the format
/// cannot hold (e.g. a bad attribute name), OperationError if the file cannot be written.
/// ASCII formats print each double in the shortest decimal form that reads back as the same
/// double (std::to_chars), so coordinates read back exactly.
/// @return what the format could not hold (mesh_format_drops): the caller warns and reports it,
///   so nothing is dropped silently.
std::vector<std::string> mesh_write(const std::string& path, const HexMesh& mesh,
                                    const MeshWriteOptions& options = {});

}  // namespace hexrefine
