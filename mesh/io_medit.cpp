/// \file
/// MEDIT ASCII (.mesh, "MeshVersionFormatted 1|2", Dimension 3). Vertices and elements number
/// from 1 and each row ends with an integer reference tag; the Hexahedra tag is block_id. Hex
/// vertex order is the same as VTK's (see shared/meshes/README.md), so rows are copied as they are.

#include <fstream>

#include "mesh/atomic_file.hpp"
#include "mesh/io.hpp"
#include "mesh/io_text.hpp"

namespace hexrefine::io_detail {

namespace {

/// Sections we know: element rows with `nodes` vertex ids (plus a reference tag), or rows of
/// `ints` integers / `reals` reals without a tag. `volume` marks non-hex volume elements.
struct MeditSection {
  const char* name;
  int nodes;  ///< vertex ids per row (then one reference tag), or -1
  int ints;   ///< plain integers per row (no tag)
  int reals;  ///< plain reals per row
  bool volume;
};

constexpr MeditSection medit_sections[] = {
    {"Edges", 2, 0, 0, false},
    {"Triangles", 3, 0, 0, false},
    {"Quadrilaterals", 4, 0, 0, false},
    // The short spelling some hex-meshing research codes write (e.g. the planar-hex-mesh
    // dataset's big_buddy.mesh): the same rows. Skipping it is safe; refusing a valid mesh is
    // not.
    {"Quads", 4, 0, 0, false},
    {"Tetrahedra", 4, 0, 0, true},
    {"Prisms", 6, 0, 0, true},
    {"Pyramids", 5, 0, 0, true},
    {"Corners", -1, 1, 0, false},
    {"Ridges", -1, 1, 0, false},
    {"RequiredVertices", -1, 1, 0, false},
    {"RequiredEdges", -1, 1, 0, false},
    {"RequiredTriangles", -1, 1, 0, false},
    {"RequiredQuadrilaterals", -1, 1, 0, false},
    {"Normals", -1, 0, 3, false},
    {"NormalAtVertices", -1, 2, 0, false},
    {"Tangents", -1, 0, 3, false},
    {"TangentAtVertices", -1, 2, 0, false},
    {"TetrahedraP2", 10, 0, 0, true},
    {"HexahedraQ2", 27, 0, 0, true},
};

}  // namespace

HexMesh medit_read(const std::string& path, std::string_view text) {
  TextCursor in(path, text, '#');
  HexMesh mesh;
  std::vector<int32_t>& block = mesh_attribute(mesh, attribute_block_id);
  bool have_vertices = false;
  in.expect("MeshVersionFormatted");
  in.integer_in("the MEDIT format version", 1, 4);
  while (true) {
    const std::string_view key = in.token("a section keyword or End");
    if (TextCursor::same_word(key, "End")) break;
    if (TextCursor::same_word(key, "Dimension")) {
      in.integer_in("dimension 3", 3, 3);
    } else if (TextCursor::same_word(key, "Vertices")) {
      if (have_vertices) in.fail("second Vertices section");
      const int64_t n = in.count("vertex count", 8);
      mesh.points.resize(static_cast<size_t>(n));
      for (int64_t i = 0; i < n; ++i) {
        for (int k = 0; k < 3; ++k) mesh.points[i][k] = in.real("vertex coordinate");
        in.integer("vertex reference tag");
      }
      have_vertices = true;
    } else if (TextCursor::same_word(key, "Hexahedra")) {
      const int64_t n = in.count("hexahedron count", 18);
      const int64_t nv = have_vertices ? static_cast<int64_t>(mesh.points.size()) : INT32_MAX;
      const size_t first = mesh.hexes.size();
      if (static_cast<int64_t>(first) + n > INT32_MAX) in.fail("too many hexahedra");
      mesh.hexes.resize(first + static_cast<size_t>(n));
      block.resize(mesh.hexes.size());
      for (int64_t i = 0; i < n; ++i) {
        HexCell& c = mesh.hexes[first + i];
        for (int k = 0; k < 8; ++k)
          c[k] = static_cast<int32_t>(in.integer_in("vertex id", 1, nv) - 1);
        block[first + i] =
            static_cast<int32_t>(in.integer_in("hexahedron reference tag", INT32_MIN, INT32_MAX));
      }
    } else {
      const MeditSection* s = nullptr;
      for (const MeditSection& c : medit_sections)
        if (TextCursor::same_word(key, c.name)) s = &c;
      if (s == nullptr)
        in.fail("unknown MEDIT section '" + TextCursor::shown(key) +
                "' (expected Vertices, Hexahedra, a surface section or End)");
      const int per_row = (s->nodes > 0 ? s->nodes + 1 : 0) + s->ints + s->reals;
      const int64_t n = in.count(std::string(s->name) + " count", 2 * per_row);
      if (s->volume && n > 0)
        in.fail("the mesh has " + std::to_string(n) + " " + s->name +
                ": only linear hexahedra are supported (skipping them would leave holes)");
      const std::string entry = std::string(s->name) + " entry";
      for (int64_t i = 0; i < n; ++i) {
        for (int k = 0; k < s->nodes + s->ints + (s->nodes > 0 ? 1 : 0); ++k) in.integer(entry);
        for (int k = 0; k < s->reals; ++k) in.real(entry);
      }
    }
  }
  if (!have_vertices) in.fail("no Vertices section before End");
  return mesh;
}

void medit_write(const std::string& path, const HexMesh& mesh) {
  const std::vector<int32_t>* block = mesh_find_attribute(mesh, attribute_block_id);
  file_write_atomically(path, [&](std::ostream& out) {
    TextWriter w(out);
    w.text("MeshVersionFormatted 2\nDimension 3\nVertices\n");
    w.integer(static_cast<int64_t>(mesh.points.size())).put('\n');
    for (const Eigen::Vector3d& p : mesh.points)
      w.real(p.x()).put(' ').real(p.y()).put(' ').real(p.z()).text(" 0\n");
    w.text("Hexahedra\n").integer(static_cast<int64_t>(mesh.hexes.size())).put('\n');
    for (size_t h = 0; h < mesh.hexes.size(); ++h) {
      for (int32_t v : mesh.hexes[h]) w.integer(int64_t{v} + 1).put(' ');
      w.integer(block ? (*block)[h] : 0).put('\n');
    }
    w.text("End\n");
    w.flush();
  });
}

}  // namespace hexrefine::io_detail
