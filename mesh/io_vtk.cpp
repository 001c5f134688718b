/// \file
/// VTK legacy (.vtk) unstructured grids, ASCII and BINARY (big-endian), classic CELLS layout and
/// the 5.x OFFSETS/CONNECTIVITY layout on reading (VTK XML files: io_vtu.cpp). VTK_HEXAHEDRON
/// (12) is hexrefine's order; VTK_VOXEL (11) is read with its nodes 2/3 and 6/7 swapped.

#include <algorithm>
#include <cmath>
#include <cstring>

#include "mesh/atomic_file.hpp"
#include "mesh/io.hpp"
#include "mesh/io_text.hpp"
#include "mesh/io_vtk_common.hpp"

namespace hexrefine::io_detail {

/// Classification of VTK cell types: 1 = the hex (or voxel), 0 = point/line/surface (skipped),
/// -1 = other volume cells (refused), -2 = unknown.
int vtk_cell_kind(int64_t type) {
  switch (type) {
    case 11:
    case 12:
      return 1;
    case 1:
    case 2:
    case 3:
    case 4:
    case 5:
    case 6:
    case 7:
    case 8:
    case 9:
    case 21:
    case 22:
    case 23:
    case 28:
    case 30:
    case 31:
    case 32:
    case 34:
    case 35:
    case 36:
    case 37:
    case 68:
    case 69:
    case 70:
      return 0;
    case 10:
    case 13:
    case 14:
    case 15:
    case 16:
    case 24:
    case 25:
    case 26:
    case 27:
    case 29:
    case 33:
    case 38:
    case 42:
    case 71:
    case 72:
    case 73:
    case 74:
      return -1;
    default:
      return -2;
  }
}

void vtk_skip_values(TextCursor& in, bool binary, std::string_view type, int64_t count,
                     const std::string& what) {
  if (!binary) {
    in.check_count(count, what + " value count", 2, INT64_MAX / 16);
    for (int64_t i = 0; i < count; ++i) in.token(what);
    return;
  }
  vtk_read_values(in, binary, type, count, what, true, [](double, int64_t) {});
}

/// Reads one attribute array of a CELL_DATA or POINT_DATA block: integer single-component cell
/// arrays become hex attributes, everything else is skipped.
void vtk_read_array(TextCursor& in, bool binary, VtkReadState& st, bool cell_data,
                    const std::string& name, std::string_view type, int64_t components,
                    int64_t tuples) {
  if (components < 1 || components > 1024) in.fail("array '" + name + "': bad component count");
  if (tuples > INT64_MAX / 2048) in.fail("array '" + name + "': tuple count too large");
  const int64_t count = components * tuples;
  const std::string what = "values of array '" + name + "'";
  const bool keep = cell_data && components == 1 && vtk_type_size(type) > 0 &&
                    vtk_type_is_integer(type) && !mesh_find_attribute(st.mesh, name);
  if (!keep) {
    vtk_skip_values(in, binary, type, count, what);
    return;
  }
  in.check_count(count, what + " value count", binary ? vtk_type_size(type) : 2, INT64_MAX / 16);
  std::vector<int32_t> values(st.mesh.hexes.size());
  int64_t i = 0;
  vtk_read_values(in, binary, type, count, what, false, [&](double, int64_t v) {
    const int32_t h = st.hex_of_cell[i++];
    if (v < INT32_MIN || v > INT32_MAX) in.fail(what + ": " + std::to_string(v) + " exceeds int32");
    if (h >= 0) values[h] = static_cast<int32_t>(v);
  });
  st.mesh.attributes.push_back({name, std::move(values)});
}

namespace {

/// Reads the arrays after "CELL_DATA n" / "POINT_DATA n" until the next block keyword.
/// A FIELD block (after its keyword): arrays whose tuple count equals `cell_count` are kept as cell
/// data; the others, and all of them when cell_count < 0 (dataset-level data such as TIME), are
/// read and skipped. An array may be followed by its METADATA lines.
void vtk_read_field(TextCursor& in, bool binary, VtkReadState& st, int64_t cell_count) {
  in.token("field name");
  const int64_t arrays = in.integer_in("field array count", 0, 1 << 20);
  for (int64_t a = 0; a < arrays; ++a) {
    const std::string name(in.token("array name"));
    const int64_t components = in.integer("component count");
    const int64_t tuples = in.integer("tuple count");
    if (tuples < 0 || tuples > INT32_MAX) in.fail("array '" + name + "': bad tuple count");
    const std::string_view type = in.token("data type");
    vtk_read_array(in, binary, st, cell_count >= 0 && tuples == cell_count, name, type, components,
                   tuples);
    if (in.peek() == "METADATA") {
      in.token("METADATA");
      while (!in.at_end() && !in.rest_of_line().empty()) {
      }
    }
  }
}

void vtk_read_data_block(TextCursor& in, bool binary, VtkReadState& st, bool cell_data, int64_t n) {
  while (!in.at_end()) {
    const std::string_view key = in.peek();
    if (key == "CELL_DATA" || key == "POINT_DATA") return;
    in.token("array keyword");
    if (key == "SCALARS") {
      const std::string name(in.token("array name"));
      const std::string_view type = in.token("data type");
      int64_t components = 1;
      if (in.peek() != "LOOKUP_TABLE" && TextCursor::parse_integer(in.peek(), components))
        in.integer_in("component count", 1, 4);
      if (in.peek() == "LOOKUP_TABLE") in.token("LOOKUP_TABLE"), in.token("lookup table name");
      vtk_read_array(in, binary, st, cell_data, name, type, components, n);
    } else if (key == "FIELD") {
      vtk_read_field(in, binary, st, cell_data ? n : -1);
    } else if (key == "VECTORS" || key == "NORMALS" || key == "TENSORS" || key == "TENSORS6") {
      const std::string name(in.token("array name"));
      const std::string_view type = in.token("data type");
      const int64_t c = key == "TENSORS" ? 9 : key == "TENSORS6" ? 6 : 3;
      vtk_read_array(in, binary, st, false, name, type, c, n);
    } else if (key == "TEXTURE_COORDINATES") {
      const std::string name(in.token("array name"));
      const int64_t dim = in.integer_in("dimension", 1, 3);
      const std::string_view type = in.token("data type");
      vtk_read_array(in, binary, st, false, name, type, dim, n);
    } else if (key == "COLOR_SCALARS") {
      const std::string name(in.token("array name"));
      const int64_t c = in.integer_in("component count", 1, 4);
      vtk_read_array(in, binary, st, false, name, binary ? "unsigned_char" : "float", c, n);
    } else if (key == "LOOKUP_TABLE") {
      const std::string name(in.token("table name"));
      const int64_t size = in.integer("table size");
      vtk_read_array(in, binary, st, false, name, binary ? "unsigned_char" : "float", 4, size);
    } else if (key == "GLOBAL_IDS" || key == "PEDIGREE_IDS") {
      const std::string name(in.token("array name"));
      const std::string_view type = in.token("data type");
      vtk_read_array(in, binary, st, false, name, type, 1, n);
    } else if (key == "METADATA") {
      while (!in.at_end() && !in.rest_of_line().empty()) {
      }
    } else {
      in.fail("unknown keyword '" + TextCursor::shown(key) + "' in " +
              (cell_data ? "CELL_DATA" : "POINT_DATA"));
    }
  }
}

}  // namespace

HexMesh vtk_read(const std::string& path, std::string_view text, const FileBytes* file) {
  TextCursor in(path, text);
  const std::string_view first = in.rest_of_line();
  if (first.substr(0, 14) != "# vtk DataFile")
    in.fail("expected the VTK legacy header '# vtk DataFile Version ...'");
  in.rest_of_line();  // title
  const std::string_view mode = in.token("ASCII or BINARY");
  if (mode != "ASCII" && mode != "BINARY")
    in.fail("expected ASCII or BINARY, got '" + TextCursor::shown(mode) + "'");
  const bool binary = mode == "BINARY";
  in.expect("DATASET");
  const std::string_view dataset = in.token("UNSTRUCTURED_GRID");
  if (dataset != "UNSTRUCTURED_GRID")
    in.fail("only DATASET UNSTRUCTURED_GRID is supported, got '" + TextCursor::shown(dataset) +
            "'");

  VtkReadState st;
  // Cells as they are read: the node count of each, and the nodes of those with eight (the only
  // ones CELL_TYPES can make hexes), in file order. No 64-bit copy of the lists: for 11.4 M hexes
  // those were 1.7 GB beside the 0.4 GB the hexes need.
  std::vector<int32_t> nodes_of_cell;
  std::vector<HexCell> eight;
  bool have_points = false, have_cells = false, have_types = false;
  // The file's pages already read leave the resident memory section by section.
  size_t released = 0;
  auto release_read = [&] {
    if (file == nullptr || in.position() <= released) return;
    file->release(text.substr(released, in.position() - released));
    released = in.position();
  };
  // Node v of cell c, kept as a 32-bit id: refused here when no point can have it (the range
  // against the points is checked where the cell becomes a hex).
  auto cell_node = [&](int64_t c, int64_t v) {
    if (v < 0 || v > INT32_MAX)
      in.fail("cell " + std::to_string(c) + " refers to point " + std::to_string(v) +
              (have_points ? ", expected 0.." + std::to_string(st.mesh.points.size() - 1) : ""));
    return static_cast<int32_t>(v);
  };
  auto add_cell = [&](int64_t nodes) {
    if (nodes_of_cell.size() >= INT32_MAX) in.fail("too many cells");
    nodes_of_cell.push_back(static_cast<int32_t>(nodes));
  };
  while (!in.at_end()) {
    const std::string_view key = in.token("a section keyword");
    if (key == "POINTS") {
      const int64_t n = in.integer("point count");
      const std::string_view type = in.token("point data type");
      in.check_count(n, "point count", 3 * (binary ? std::max(1, vtk_type_size(type)) : 2));
      st.mesh.points.resize(static_cast<size_t>(n));
      int64_t i = 0;
      vtk_read_values(in, binary, type, 3 * n, "point coordinate", false, [&](double d, int64_t v) {
        st.mesh.points[i / 3][i % 3] = vtk_type_is_integer(type) ? static_cast<double>(v) : d;
        ++i;
      });
      have_points = true;
    } else if (key == "CELLS") {
      if (have_cells) in.fail("a second CELLS section");
      const int64_t a = in.integer("cell count");
      const int64_t b = in.integer("cell list size");
      if (in.peek() == "OFFSETS") {  // VTK 5.x layout: a offsets, b connectivity entries
        in.token("OFFSETS");
        const std::string_view ot = in.token("offset data type");
        in.check_count(a, "offset count", binary ? 4 : 2);
        std::vector<int64_t> offsets;
        offsets.reserve(static_cast<size_t>(a));
        vtk_read_values(in, binary, ot, a, "cell offset", false,
                        [&](double, int64_t v) { offsets.push_back(v); });
        if (offsets.empty() || offsets[0] != 0) in.fail("cell offsets must start with 0");
        in.expect("CONNECTIVITY");
        const std::string_view ct = in.token("connectivity data type");
        in.check_count(b, "connectivity size", binary ? 4 : 2);
        for (size_t c = 1; c < offsets.size(); ++c)
          if (offsets[c] < offsets[c - 1] || offsets[c] > b)
            in.fail("cell offsets not increasing or beyond the connectivity at cell " +
                    std::to_string(c - 1));
        // Cell c holds entries offsets[c] .. offsets[c + 1] (the last: up to b).
        const int64_t cells = static_cast<int64_t>(offsets.size()) - 1;
        for (int64_t c = 0; c < cells; ++c) add_cell(offsets[c + 1] - offsets[c]);
        eight.reserve(
            static_cast<size_t>(std::count(nodes_of_cell.begin(), nodes_of_cell.end(), 8)));
        int64_t c = 0, at = 0;
        HexCell h{};
        vtk_read_values(in, binary, ct, b, "cell connectivity", false, [&](double, int64_t v) {
          while (c < cells && at >= offsets[c + 1]) ++c;
          if (c < cells && nodes_of_cell[c] == 8) {
            h[at - offsets[c]] = cell_node(c, v);
            if (at - offsets[c] == 7) eight.push_back(h);
          }
          ++at;
        });
      } else {  // classic layout: a cells, b = sum of (1 + nodes) integers
        in.check_count(a, "cell count", binary ? 8 : 4);
        in.check_count(b, "cell list size", binary ? 4 : 2, INT32_MAX);
        nodes_of_cell.reserve(static_cast<size_t>(a));
        eight.reserve(static_cast<size_t>(std::min(a, b / 9)));  // a hex takes 9 entries
        // Walks the list: a node count, then that many node ids, cell after cell.
        int64_t c = 0, at = 0, left = -1;
        HexCell h{};
        auto cell_count = [&](int64_t v) {
          if (c == a) in.fail("CELLS list size " + std::to_string(b) + " does not match its cells");
          if (v < 0 || v > b - at - 1)
            in.fail("cell " + std::to_string(c) + " claims " + std::to_string(v) +
                    " nodes, more than the CELLS list holds");
          add_cell(v);
        };
        if (binary) {  // big-endian int32s read where they lie, a cell at a time
          in.rest_of_line();
          const char* p = in.raw(static_cast<size_t>(b) * 4, "cell list");
          while (at < b) {
            const int64_t k = read_big_endian<int32_t>(p + 4 * at);
            cell_count(k);
            if (k == 8) {
              for (int j = 0; j < 8; ++j)
                h[j] = cell_node(c, read_big_endian<int32_t>(p + 4 * (at + 1 + j)));
              eight.push_back(h);
            }
            at += 1 + k;
            ++c;
          }
        } else {
          vtk_read_values(in, binary, "int", b, "cell list", false, [&](double, int64_t v) {
            if (left < 0) {  // a cell's node count
              cell_count(v);
              left = v;
            } else {
              if (nodes_of_cell[c] == 8) h[8 - left] = cell_node(c, v);
              --left;
            }
            if (left == 0) {
              if (nodes_of_cell[c] == 8) eight.push_back(h);
              ++c;
              left = -1;
            }
            ++at;
          });
        }
        if (c < a)
          in.fail("CELLS list ends at cell " + std::to_string(c) + " of " + std::to_string(a));
      }
      have_cells = true;
      release_read();
    } else if (key == "CELL_TYPES") {
      const int64_t n = in.integer("cell type count");
      in.check_count(n, "cell type count", binary ? 4 : 2);
      if (!have_cells) in.fail("CELL_TYPES before CELLS");
      if (have_types) in.fail("a second CELL_TYPES section");
      if (static_cast<int64_t>(nodes_of_cell.size()) != n)
        in.fail("CELL_TYPES count " + std::to_string(n) + " differs from the CELLS count " +
                std::to_string(nodes_of_cell.size()));
      // The hexes are built now so that cell data can be mapped to them: the eight-node cells
      // that are hexes, moved down within the same array.
      st.hex_of_cell.assign(static_cast<size_t>(n), -1);
      const int64_t np = static_cast<int64_t>(st.mesh.points.size());
      int64_t c = 0;
      size_t next_eight = 0, hexes = 0;
      vtk_read_values(in, binary, "int", n, "cell type", false, [&](double, int64_t type) {
        const int kind = vtk_cell_kind(type);
        const int32_t nodes = nodes_of_cell[c];
        const size_t slot = next_eight;
        if (nodes == 8) ++next_eight;
        if (kind == -1)
          in.fail("cell " + std::to_string(c) + " has VTK type " + std::to_string(type) +
                  ", a volume cell that is not a linear hexahedron (only hexes are supported)");
        if (kind == -2)
          in.fail("cell " + std::to_string(c) + " has unknown VTK type " + std::to_string(type));
        if (kind != 0) {
          if (nodes != 8)
            in.fail("hexahedron " + std::to_string(c) + " has " + std::to_string(nodes) +
                    " nodes, expected 8");
          HexCell h = eight[slot];
          for (int k = 0; k < 8; ++k)
            if (h[k] >= np)
              in.fail("cell " + std::to_string(c) + " refers to point " + std::to_string(h[k]) +
                      ", expected 0.." + std::to_string(np - 1));
          if (type == 11) std::swap(h[2], h[3]), std::swap(h[6], h[7]);
          st.hex_of_cell[c] = static_cast<int32_t>(hexes);
          eight[hexes++] = h;
        }
        ++c;
      });
      eight.resize(hexes);
      st.mesh.hexes = std::move(eight);
      std::vector<int32_t>().swap(nodes_of_cell);
      have_types = true;
      release_read();
    } else if (key == "CELL_DATA" || key == "POINT_DATA") {
      const int64_t n = in.integer("data count");
      if (key == "CELL_DATA" && (!have_types || n != static_cast<int64_t>(st.hex_of_cell.size())))
        in.fail("CELL_DATA count " + std::to_string(n) + " does not match the " +
                std::to_string(st.hex_of_cell.size()) + " cells read before it");
      if (key == "POINT_DATA" && n != static_cast<int64_t>(st.mesh.points.size()))
        in.fail("POINT_DATA count " + std::to_string(n) + " does not match the point count");
      vtk_read_data_block(in, binary, st, key == "CELL_DATA", n);
      release_read();
    } else if (key == "FIELD") {  // dataset-level field data (e.g. TIME): skipped
      vtk_read_field(in, binary, st, -1);
    } else if (key == "METADATA") {
      while (!in.at_end() && !in.rest_of_line().empty()) {
      }
    } else {
      in.fail("unknown keyword '" + TextCursor::shown(key) + "'");
    }
  }
  if (!have_points) in.fail("no POINTS section");
  if (!have_types) in.fail("no CELLS / CELL_TYPES sections");
  return std::move(st.mesh);
}

void vtk_write(const std::string& path, const HexMesh& mesh, const bool binary,
               const std::vector<std::pair<std::string, std::vector<double>>>& cell_scalars) {
  static_assert(sizeof(Eigen::Vector3d) == 3 * sizeof(double), "points must be packed xyz");
  file_write_atomically(path, [&](std::ostream& out) {
    TextWriter w(out);
    const size_t n = mesh.points.size(), m = mesh.hexes.size();
    w.text("# vtk DataFile Version 3.0\nhexrefine mesh\n");
    w.text(binary ? "BINARY\n" : "ASCII\n");
    w.text("DATASET UNSTRUCTURED_GRID\nPOINTS ").integer(static_cast<int64_t>(n));
    w.text(" double\n");
    if (binary) {
      // The points are one packed array of 3n doubles: swapped into the buffer in one pass.
      w.big_endian(n ? mesh.points[0].data() : nullptr, 3 * n).put('\n');
    } else {
      for (const Eigen::Vector3d& p : mesh.points)
        w.real(p.x()).put(' ').real(p.y()).put(' ').real(p.z()).put('\n');
    }
    w.text("CELLS ").integer(static_cast<int64_t>(m)).put(' ');
    w.integer(9 * static_cast<int64_t>(m)).put('\n');
    for (const HexCell& c : mesh.hexes) {
      if (binary) {
        const int32_t row[9] = {8, c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]};
        w.big_endian(row, 9);
      } else {
        w.put('8');
        for (int32_t v : c) w.put(' ').integer(v);
        w.put('\n');
      }
    }
    if (binary) w.put('\n');
    w.text("CELL_TYPES ").integer(static_cast<int64_t>(m)).put('\n');
    const int32_t hexahedron = 12;
    for (size_t h = 0; h < m; ++h) {
      if (binary)
        w.big_endian(&hexahedron, 1);
      else
        w.text("12\n");
    }
    if (binary) w.put('\n');
    if (m > 0 && (!mesh.attributes.empty() || !cell_scalars.empty())) {
      w.text("CELL_DATA ").integer(static_cast<int64_t>(m)).put('\n');
      for (const HexAttribute& a : mesh.attributes) {
        w.text("SCALARS ").text(a.name).text(" int 1\nLOOKUP_TABLE default\n");
        if (binary) {
          w.big_endian(a.values.data(), a.values.size()).put('\n');
        } else {
          for (int32_t v : a.values) w.integer(v).put('\n');
        }
      }
      for (const auto& [name, values] : cell_scalars) {
        w.text("SCALARS ").text(name).text(" double 1\nLOOKUP_TABLE default\n");
        if (binary) {
          w.big_endian(values.data(), values.size()).put('\n');
        } else {
          for (double v : values) w.real(v).put('\n');
        }
      }
    }
    w.flush();
  });
}

}  // namespace hexrefine::io_detail
