#pragma once
/// \file
/// What the VTK legacy and VTU readers share: data type names and sizes, the cell-type
/// classification, the ASCII/big-endian value reader and the cell-data attribute reader.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "mesh/hex_mesh.hpp"
#include "mesh/io_text.hpp"

namespace hexrefine::io_detail {

/// Byte size of a VTK legacy data type, 0 if unknown.
inline int vtk_type_size(std::string_view t) {
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

inline bool vtk_type_is_integer(std::string_view t) {
  return t != "float" && t != "double";
}

/// Classification of VTK cell types: 1 = the hex (or voxel), 0 = point/line/surface (skipped),
/// -1 = other volume cells (refused), -2 = unknown.
int vtk_cell_kind(int64_t type);

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

struct VtkReadState {
  HexMesh mesh;
  std::vector<int32_t> hex_of_cell;  ///< per file cell: hex index or -1
};

/// Reads one attribute array of a CELL_DATA or POINT_DATA block: integer single-component cell
/// arrays become hex attributes, everything else is skipped.
void vtk_read_array(TextCursor& in, bool binary, VtkReadState& st, bool cell_data,
                    const std::string& name, std::string_view type, int64_t components,
                    int64_t tuples);

}  // namespace hexrefine::io_detail
