/// \file
/// VTK legacy (.vtk) unstructured grids, ASCII and BINARY (big-endian), classic CELLS layout and
/// the 5.x OFFSETS/CONNECTIVITY layout on reading (VTK XML files: io_vtu.cpp). VTK_HEXAHEDRON
/// (12) is hexrefine's order; VTK_VOXEL (11) is read with its nodes 2/3 and 6/7 swapped.

#include <algorithm>
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

HexMesh vtk_read(const std::string& path, std::string_view text) {
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
  std::vector<int64_t> offsets, connectivity, types;
  bool have_points = false, have_cells = false, have_types = false;
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
      const int64_t a = in.integer("cell count");
      const int64_t b = in.integer("cell list size");
      if (in.peek() == "OFFSETS") {  // VTK 5.x layout: a offsets, b connectivity entries
        in.token("OFFSETS");
        const std::string_view ot = in.token("offset data type");
        in.check_count(a, "offset count", binary ? 4 : 2);
        offsets.reserve(static_cast<size_t>(a));
        vtk_read_values(in, binary, ot, a, "cell offset", false,
                        [&](double, int64_t v) { offsets.push_back(v); });
        in.expect("CONNECTIVITY");
        const std::string_view ct = in.token("connectivity data type");
        in.check_count(b, "connectivity size", binary ? 4 : 2);
        connectivity.reserve(static_cast<size_t>(b));
        vtk_read_values(in, binary, ct, b, "cell connectivity", false,
                        [&](double, int64_t v) { connectivity.push_back(v); });
        if (offsets.empty() || offsets[0] != 0) in.fail("cell offsets must start with 0");
      } else {  // classic layout: a cells, b = sum of (1 + nodes) integers
        in.check_count(a, "cell count", binary ? 8 : 4);
        in.check_count(b, "cell list size", binary ? 4 : 2, INT32_MAX);
        std::vector<int64_t> list;
        list.reserve(static_cast<size_t>(b));
        vtk_read_values(in, binary, "int", b, "cell list", false,
                        [&](double, int64_t v) { list.push_back(v); });
        offsets.reserve(static_cast<size_t>(a) + 1);
        offsets.push_back(0);
        size_t p = 0;
        for (int64_t c = 0; c < a; ++c) {
          if (p >= list.size())
            in.fail("CELLS list ends at cell " + std::to_string(c) + " of " + std::to_string(a));
          const int64_t k = list[p++];
          if (k < 0 || k > static_cast<int64_t>(list.size() - p))
            in.fail("cell " + std::to_string(c) + " claims " + std::to_string(k) +
                    " nodes, more than the CELLS list holds");
          connectivity.insert(connectivity.end(), list.begin() + p, list.begin() + p + k);
          p += k;
          offsets.push_back(static_cast<int64_t>(connectivity.size()));
        }
        if (p != list.size())
          in.fail("CELLS list size " + std::to_string(b) + " does not match its cells");
      }
      for (size_t c = 1; c < offsets.size(); ++c)
        if (offsets[c] < offsets[c - 1] || offsets[c] > static_cast<int64_t>(connectivity.size()))
          in.fail("cell offsets not increasing or beyond the connectivity at cell " +
                  std::to_string(c - 1));
      have_cells = true;
    } else if (key == "CELL_TYPES") {
      const int64_t n = in.integer("cell type count");
      in.check_count(n, "cell type count", binary ? 4 : 2);
      types.reserve(static_cast<size_t>(n));
      vtk_read_values(in, binary, "int", n, "cell type", false,
                      [&](double, int64_t v) { types.push_back(v); });
      if (!have_cells) in.fail("CELL_TYPES before CELLS");
      if (static_cast<int64_t>(offsets.size()) != n + 1)
        in.fail("CELL_TYPES count " + std::to_string(n) + " differs from the CELLS count " +
                std::to_string(offsets.size() - 1));
      // Build the hexes now so that cell data can be mapped to them.
      st.hex_of_cell.assign(static_cast<size_t>(n), -1);
      const int64_t np = static_cast<int64_t>(st.mesh.points.size());
      for (int64_t c = 0; c < n; ++c) {
        const int kind = vtk_cell_kind(types[c]);
        const int64_t nodes = offsets[c + 1] - offsets[c];
        if (kind == 0) continue;
        if (kind == -1)
          in.fail("cell " + std::to_string(c) + " has VTK type " + std::to_string(types[c]) +
                  ", a volume cell that is not a linear hexahedron (only hexes are supported)");
        if (kind == -2)
          in.fail("cell " + std::to_string(c) + " has unknown VTK type " +
                  std::to_string(types[c]));
        if (nodes != 8)
          in.fail("hexahedron " + std::to_string(c) + " has " + std::to_string(nodes) +
                  " nodes, expected 8");
        HexCell h;
        for (int k = 0; k < 8; ++k) {
          const int64_t v = connectivity[offsets[c] + k];
          if (v < 0 || v >= np)
            in.fail("cell " + std::to_string(c) + " refers to point " + std::to_string(v) +
                    ", expected 0.." + std::to_string(np - 1));
          h[k] = static_cast<int32_t>(v);
        }
        if (types[c] == 11) std::swap(h[2], h[3]), std::swap(h[6], h[7]);
        if (st.mesh.hexes.size() >= INT32_MAX) in.fail("too many hexes");
        st.hex_of_cell[c] = static_cast<int32_t>(st.mesh.hexes.size());
        st.mesh.hexes.push_back(h);
      }
      have_types = true;
    } else if (key == "CELL_DATA" || key == "POINT_DATA") {
      const int64_t n = in.integer("data count");
      if (key == "CELL_DATA" && (!have_types || n != static_cast<int64_t>(st.hex_of_cell.size())))
        in.fail("CELL_DATA count " + std::to_string(n) + " does not match the " +
                std::to_string(st.hex_of_cell.size()) + " cells read before it");
      if (key == "POINT_DATA" && n != static_cast<int64_t>(st.mesh.points.size()))
        in.fail("POINT_DATA count " + std::to_string(n) + " does not match the point count");
      vtk_read_data_block(in, binary, st, key == "CELL_DATA", n);
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
