/// \file
/// VTK legacy (.vtk) unstructured grids, ASCII and BINARY (big-endian), classic CELLS layout and
/// the 5.x OFFSETS/CONNECTIVITY layout on reading; and VTK XML unstructured grids (.vtu) with
/// ASCII data arrays. VTK_HEXAHEDRON (12) is hexrefine's order; VTK_VOXEL (11) is read with its
/// nodes 2/3 and 6/7 swapped.

#include <algorithm>
#include <cstring>

#include "mesh/atomic_file.hpp"
#include "mesh/io.hpp"
#include "mesh/io_text.hpp"

namespace hexrefine::io_detail {

namespace {

/// Byte size of a VTK legacy data type, 0 if unknown.
int vtk_type_size(std::string_view t) {
  if (t == "bit") return 0;
  if (t == "char" || t == "unsigned_char") return 1;
  if (t == "short" || t == "unsigned_short") return 2;
  if (t == "int" || t == "unsigned_int" || t == "float" || t == "vtktypeint32" ||
      t == "vtktypeuint32")
    return 4;
  if (t == "long" || t == "unsigned_long" || t == "double" || t == "vtktypeint64" ||
      t == "vtktypeuint64" || t == "vtkIdType")
    return 8;
  return 0;
}

bool vtk_type_is_integer(std::string_view t) {
  return t != "float" && t != "double";
}

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

/// Reads `count` numbers of VTK type `type` (ASCII tokens or big-endian binary) and hands each
/// to `sink` as a double (integers up to 2^53 are exact) or, when `as_integer`, as an int64.
/// ASCII reals must be finite unless `allow_nonfinite`.
template <class Sink>
void vtk_read_values(TextCursor& in, bool binary, std::string_view type, int64_t count,
                     const std::string& what, bool allow_nonfinite, Sink sink) {
  const int size = vtk_type_size(type);
  if (size == 0) in.fail("unsupported data type '" + TextCursor::shown(type) + "' for " + what);
  const bool is_int = vtk_type_is_integer(type);
  in.check_count(count, what + " value count", binary ? size : 2, INT64_MAX / 16);
  if (!binary) {
    for (int64_t i = 0; i < count; ++i) {
      if (is_int) {
        sink(static_cast<double>(0), in.integer(what));
      } else if (allow_nonfinite) {
        const std::string_view t = in.token(what);
        double v = 0;
        if (!TextCursor::parse_real(t, v) &&
            !(t == "nan" || t == "-nan" || t == "inf" || t == "-inf" || t == "NaN" || t == "Inf" ||
              t == "-Inf"))
          in.fail("expected " + what + " (a number), got '" + TextCursor::shown(t) + "'");
        sink(v, 0);
      } else {
        sink(in.real(what), 0);
      }
    }
    return;
  }
  in.rest_of_line();
  const char* p = in.raw(static_cast<size_t>(count) * size, what);
  // The type is resolved once, not compared as a string per value.
  enum class Binary { i8, u8, i16, u16, i32, u32, f32, f64, i64, u64 };
  const Binary kind = type == "char"                                         ? Binary::i8
                      : type == "unsigned_char"                              ? Binary::u8
                      : type == "short"                                      ? Binary::i16
                      : type == "unsigned_short"                             ? Binary::u16
                      : (type == "int" || type == "vtktypeint32")            ? Binary::i32
                      : (type == "unsigned_int" || type == "vtktypeuint32")  ? Binary::u32
                      : type == "float"                                      ? Binary::f32
                      : type == "double"                                     ? Binary::f64
                      : (type == "unsigned_long" || type == "vtktypeuint64") ? Binary::u64
                                                                             : Binary::i64;
  for (int64_t i = 0; i < count; ++i, p += size) {
    double d = 0;
    int64_t v = 0;
    switch (kind) {
      case Binary::i8:
        v = static_cast<signed char>(*p);
        break;
      case Binary::u8:
        v = static_cast<unsigned char>(*p);
        break;
      case Binary::i16:
        v = read_big_endian<int16_t>(p);
        break;
      case Binary::u16:
        v = read_big_endian<uint16_t>(p);
        break;
      case Binary::i32:
        v = read_big_endian<int32_t>(p);
        break;
      case Binary::u32:
        v = read_big_endian<uint32_t>(p);
        break;
      case Binary::f32:
        d = read_big_endian<float>(p);
        break;
      case Binary::f64:
        d = read_big_endian<double>(p);
        break;
      case Binary::i64:
      case Binary::u64: {
        const uint64_t u = read_big_endian<uint64_t>(p);
        if (kind == Binary::u64 && u > INT64_MAX) in.fail(what + ": value out of range");
        v = static_cast<int64_t>(u);
        break;
      }
    }
    if (!is_int && !allow_nonfinite && !std::isfinite(d))
      in.fail(what + " " + std::to_string(i) + " is NaN or infinite");
    sink(d, v);
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

struct VtkReadState {
  HexMesh mesh;
  std::vector<int32_t> hex_of_cell;  ///< per file cell: hex index or -1
};

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

HexMesh vtk_read(const std::string& path, const std::string& text) {
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
  mesh_check_read(st.mesh, path);
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

namespace hexrefine::io_detail {

void vtu_write(const std::string& path, const HexMesh& mesh,
               const std::vector<std::pair<std::string, std::vector<double>>>& cell_scalars) {
  file_write_atomically(path, [&](std::ostream& out) {
    TextWriter w(out);
    const size_t n = mesh.points.size(), m = mesh.hexes.size();
    w.text("<?xml version=\"1.0\"?>\n");
    w.text(
        "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
        "header_type=\"UInt64\">\n<UnstructuredGrid>\n");
    w.text("<Piece NumberOfPoints=\"").integer(static_cast<int64_t>(n));
    w.text("\" NumberOfCells=\"").integer(static_cast<int64_t>(m)).text("\">\n");
    w.text("<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n");
    for (const Eigen::Vector3d& p : mesh.points)
      w.real(p.x()).put(' ').real(p.y()).put(' ').real(p.z()).put('\n');
    w.text("</DataArray>\n</Points>\n<Cells>\n");
    w.text("<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
    for (const HexCell& c : mesh.hexes) {
      for (int k = 0; k < 8; ++k) w.integer(c[k]).put(k < 7 ? ' ' : '\n');
    }
    w.text("</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
    for (size_t h = 0; h < m; ++h) w.integer(8 * (static_cast<int64_t>(h) + 1)).put('\n');
    w.text("</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
    for (size_t h = 0; h < m; ++h) w.text("12\n");
    w.text("</DataArray>\n</Cells>\n");
    if (!mesh.attributes.empty() || !cell_scalars.empty()) {
      w.text("<CellData>\n");
      for (const HexAttribute& a : mesh.attributes) {
        w.text("<DataArray type=\"Int32\" Name=\"").text(a.name).text("\" format=\"ascii\">\n");
        for (int32_t v : a.values) w.integer(v).put('\n');
        w.text("</DataArray>\n");
      }
      for (const auto& [name, values] : cell_scalars) {
        w.text("<DataArray type=\"Float64\" Name=\"").text(name).text("\" format=\"ascii\">\n");
        for (double v : values) w.real(v).put('\n');
        w.text("</DataArray>\n");
      }
      w.text("</CellData>\n");
    }
    w.text("</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    w.flush();
  });
}

}  // namespace hexrefine::io_detail

namespace hexrefine::io_detail {

namespace {

/// Value of attribute `name` inside the tag text `tag` ("" if absent).
std::string xml_attribute(std::string_view tag, std::string_view name) {
  size_t p = 0;
  while ((p = tag.find(name, p)) != std::string_view::npos) {
    const bool starts = p > 0 && (tag[p - 1] == ' ' || tag[p - 1] == '\n' || tag[p - 1] == '\t' ||
                                  tag[p - 1] == '\r');
    size_t q = p + name.size();
    while (q < tag.size() && tag[q] == ' ') ++q;
    if (starts && q < tag.size() && tag[q] == '=') {
      ++q;
      while (q < tag.size() && tag[q] == ' ') ++q;
      if (q < tag.size() && (tag[q] == '"' || tag[q] == '\'')) {
        const size_t end = tag.find(tag[q], q + 1);
        if (end == std::string_view::npos) return "";
        return std::string(tag.substr(q + 1, end - q - 1));
      }
    }
    p += name.size();
  }
  return "";
}

int64_t line_of(std::string_view text, size_t pos) {
  int64_t line = 1;
  for (size_t i = 0; i < pos && i < text.size(); ++i)
    if (text[i] == '\n') ++line;
  return line;
}

}  // namespace

HexMesh vtu_read(const std::string& path, const std::string& text) {
  const std::string_view all(text);
  auto fail_at = [&](size_t pos, const std::string& message) -> void {
    throw InputError(error_at(path, line_of(all, pos), message));
  };
  if (all.find("<VTKFile") == std::string_view::npos ||
      xml_attribute(all.substr(all.find("<VTKFile"), 300), "type") != "UnstructuredGrid")
    fail_at(0, "expected a VTK XML file <VTKFile type=\"UnstructuredGrid\" ...>");
  if (all.find("<AppendedData") != std::string_view::npos)
    fail_at(all.find("<AppendedData"),
            "appended VTU data is not supported (write format=\"ascii\")");
  const size_t piece = all.find("<Piece");
  if (piece == std::string_view::npos) fail_at(0, "no <Piece> element");
  if (all.find("<Piece", piece + 1) != std::string_view::npos)
    fail_at(all.find("<Piece", piece + 1), "more than one <Piece> is not supported");
  const size_t piece_end = all.find('>', piece);
  if (piece_end == std::string_view::npos) fail_at(piece, "unterminated <Piece> tag");
  const std::string_view piece_tag = all.substr(piece, piece_end - piece);
  int64_t np = -1, nc = -1;
  if (!TextCursor::parse_integer(xml_attribute(piece_tag, "NumberOfPoints"), np) || np < 0 ||
      !TextCursor::parse_integer(xml_attribute(piece_tag, "NumberOfCells"), nc) || nc < 0)
    fail_at(piece, "<Piece> needs NumberOfPoints and NumberOfCells >= 0");
  const int64_t size = static_cast<int64_t>(text.size());
  if (np > size / 6 || nc > size / 6)
    fail_at(piece, "NumberOfPoints/NumberOfCells larger than the file (" + std::to_string(size) +
                       " bytes) can hold");

  VtkReadState st;
  std::vector<int64_t> connectivity, offsets, types;
  bool have_points = false;
  struct Pending {
    std::string name;
    size_t begin;
    int64_t line;
    std::string type;
  };
  std::vector<Pending> cell_arrays;
  // Section openings and line numbers are followed forward from one array to the next, so the
  // file is scanned once in all, not once per array.
  constexpr std::string_view section_names[4] = {"<Points", "<Cells", "<CellData", "<PointData"};
  int64_t section_at[4] = {-1, -1, -1, -1};  // last opening of each before `scanned`
  size_t scanned = 0;
  size_t line_pos = 0;  // line_no is the line of offset line_pos
  int64_t line_no = 1;
  auto line_at = [&](size_t pos) {
    if (pos < line_pos) return line_of(all, pos);
    line_no += std::count(all.begin() + static_cast<ptrdiff_t>(line_pos),
                          all.begin() + static_cast<ptrdiff_t>(pos), '\n');
    line_pos = pos;
    return line_no;
  };
  size_t p = piece_end;
  while ((p = all.find("<DataArray", p)) != std::string_view::npos) {
    const size_t tag_end = all.find('>', p);
    if (tag_end == std::string_view::npos) fail_at(p, "unterminated <DataArray> tag");
    const std::string_view tag = all.substr(p, tag_end - p);
    const size_t close = all.find("</DataArray>", tag_end);
    if (close == std::string_view::npos) fail_at(p, "<DataArray> without </DataArray>");
    const std::string name = xml_attribute(tag, "Name");
    const std::string format = xml_attribute(tag, "format");
    std::string type = xml_attribute(tag, "type");
    const std::string comps = xml_attribute(tag, "NumberOfComponents");
    // Which section holds this array: the nearest section opening before it. (No opening can
    // straddle p: the names hold '<' only first, and p is the '<' of "<DataArray".)
    const std::string_view before = all.substr(0, p);
    for (int k = 0; k < 4; ++k)
      for (size_t q = scanned; (q = before.find(section_names[k], q)) != std::string_view::npos;
           ++q)
        section_at[k] = static_cast<int64_t>(q);
    scanned = p;
    const int64_t in_points = section_at[0], in_cells = section_at[1], in_cell_data = section_at[2],
                  in_point_data = section_at[3];
    const int64_t section = std::max({in_points, in_cells, in_cell_data, in_point_data});
    if (format != "ascii")
      fail_at(p, "DataArray '" + name + "' has format \"" + format +
                     "\": only format=\"ascii\" VTU files are read");
    // The values end at the first nested element (VTK writes <InformationKey> after them).
    const size_t values_end = std::min(close, all.find('<', tag_end + 1));
    TextCursor in(path, all.substr(tag_end + 1, values_end - tag_end - 1));
    in.set_line(line_at(tag_end + 1));
    const std::string what = "values of DataArray '" + name + "'";
    static const std::pair<const char*, const char*> type_names[] = {
        {"Int8", "char"},     {"UInt8", "unsigned_char"},
        {"Int16", "short"},   {"UInt16", "unsigned_short"},
        {"Int32", "int"},     {"UInt32", "unsigned_int"},
        {"Int64", "long"},    {"UInt64", "unsigned_long"},
        {"Float32", "float"}, {"Float64", "double"}};
    std::string legacy_type;
    for (const auto& [x, l] : type_names)
      if (type == x) legacy_type = l;
    if (legacy_type.empty()) fail_at(p, "DataArray '" + name + "' has unknown type '" + type + "'");
    if (section == in_points && section >= 0) {
      if (comps != "3") fail_at(p, "Points DataArray needs NumberOfComponents=\"3\"");
      st.mesh.points.resize(static_cast<size_t>(np));
      int64_t i = 0;
      vtk_read_values(in, false, legacy_type, 3 * np, "point coordinate", false,
                      [&](double d, int64_t v) {
                        st.mesh.points[i / 3][i % 3] =
                            vtk_type_is_integer(legacy_type) ? static_cast<double>(v) : d;
                        ++i;
                      });
      have_points = true;
    } else if (section == in_cells && section >= 0) {
      std::vector<int64_t>* out = name == "connectivity" ? &connectivity
                                  : name == "offsets"    ? &offsets
                                  : name == "types"      ? &types
                                                         : nullptr;
      if (out == nullptr) fail_at(p, "unknown Cells DataArray '" + name + "'");
      while (!in.at_end()) {
        if (out->size() >= static_cast<size_t>(size)) in.fail("too many values");
        out->push_back(in.integer(what));
      }
    } else if (section == in_cell_data && section >= 0) {
      cell_arrays.push_back({name, tag_end + 1, in.line(), legacy_type});
      if (comps != "" && comps != "1") cell_arrays.back().type = "";  // multi-component: skipped
    }
    if (section >= 0 && !in.at_end() && (section == in_points || section == in_cells))
      in.fail("more values than expected in " + what);
    p = close;
  }
  if (!have_points) fail_at(piece, "no <Points> DataArray");
  if (static_cast<int64_t>(offsets.size()) != nc || static_cast<int64_t>(types.size()) != nc)
    fail_at(piece, "Cells offsets/types need NumberOfCells = " + std::to_string(nc) + " values");
  st.hex_of_cell.assign(static_cast<size_t>(nc), -1);
  int64_t start = 0;
  for (int64_t c = 0; c < nc; ++c) {
    const int64_t end = offsets[c];
    if (end < start || end > static_cast<int64_t>(connectivity.size()))
      fail_at(piece,
              "cell " + std::to_string(c) + ": offsets not increasing or beyond the connectivity");
    const int kind = vtk_cell_kind(types[c]);
    if (kind == -1)
      fail_at(piece,
              "cell " + std::to_string(c) + " has VTK type " + std::to_string(types[c]) +
                  ", a volume cell that is not a linear hexahedron (only hexes are supported)");
    if (kind == -2)
      fail_at(piece,
              "cell " + std::to_string(c) + " has unknown VTK type " + std::to_string(types[c]));
    if (kind == 1) {
      if (end - start != 8)
        fail_at(piece, "hexahedron " + std::to_string(c) + " has " + std::to_string(end - start) +
                           " nodes, expected 8");
      HexCell h;
      for (int k = 0; k < 8; ++k) {
        const int64_t v = connectivity[start + k];
        if (v < 0 || v >= np)
          fail_at(piece, "cell " + std::to_string(c) + " refers to point " + std::to_string(v) +
                             ", expected 0.." + std::to_string(np - 1));
        h[k] = static_cast<int32_t>(v);
      }
      if (types[c] == 11) std::swap(h[2], h[3]), std::swap(h[6], h[7]);
      st.hex_of_cell[c] = static_cast<int32_t>(st.mesh.hexes.size());
      st.mesh.hexes.push_back(h);
    }
    start = end;
  }
  for (const Pending& a : cell_arrays) {
    if (a.type.empty() || !vtk_type_is_integer(a.type) || a.name.empty() ||
        mesh_find_attribute(st.mesh, a.name))
      continue;
    const size_t close = std::min(all.find("</DataArray>", a.begin), all.find('<', a.begin));
    TextCursor in(path, all.substr(a.begin, close - a.begin));
    in.set_line(a.line);
    vtk_read_array(in, false, st, true, a.name, a.type, 1, nc);
    if (!in.at_end()) in.fail("more than NumberOfCells values in DataArray '" + a.name + "'");
  }
  mesh_check_read(st.mesh, path);
  return std::move(st.mesh);
}

}  // namespace hexrefine::io_detail
