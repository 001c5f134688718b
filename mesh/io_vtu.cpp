/// \file
/// VTK XML unstructured grid (.vtu) reader: every encoding ParaView and meshio write (ascii,
/// inline binary, appended raw or base64; zlib or not; io_vtu_data.hpp). VTK_HEXAHEDRON (12) is
/// hexrefine's order; VTK_VOXEL (11) is read with its nodes 2/3 and 6/7 swapped. The writer is
/// io_vtu_write.cpp.

#include <algorithm>
#include <cmath>
#include <cstring>
#include <type_traits>

#include "mesh/io.hpp"
#include "mesh/io_text.hpp"
#include "mesh/io_vtk_common.hpp"
#include "mesh/io_vtu_data.hpp"

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

/// An integer array of <Cells> left in the (mapped) file, raw and uncompressed: its values are
/// read where they lie when the hexes are built, so an 11 M-hex file's connectivity, offsets and
/// types are not first copied into arrays of their own (as large as the hexes, and fresh memory
/// costs about as much to fault in as to fill).
struct CellsArrayInFile {
  std::string_view bytes;
  size_t tag = 0;          ///< position of its <DataArray> tag, for messages
  int size = 0;            ///< bytes per value: 1, 2, 4 or 8
  bool is_signed = false;  ///< char, short, int, long (else the unsigned types)
  int64_t count() const { return static_cast<int64_t>(bytes.size()) / size; }
  /// Value i (< count()); InputError naming `what` for an unsigned 64-bit value beyond int64.
  [[gnu::always_inline]] int64_t at(int64_t i, const std::string& path,
                                    const std::string& what) const {
    const char* p = bytes.data() + i * size;
    auto load = [&](auto zero) {
      decltype(zero) v;
      std::memcpy(&v, p, sizeof v);
      return v;
    };
    switch (size) {
      case 1:
        return is_signed ? int64_t{load(int8_t{})} : int64_t{load(uint8_t{})};
      case 2:
        return is_signed ? int64_t{load(int16_t{})} : int64_t{load(uint16_t{})};
      case 4:
        return is_signed ? int64_t{load(int32_t{})} : int64_t{load(uint32_t{})};
      default: {
        if (is_signed) return load(int64_t{});
        const uint64_t v = load(uint64_t{});
        if (v > static_cast<uint64_t>(INT64_MAX)) too_large(v, path, what);
        return static_cast<int64_t>(v);
      }
    }
  }
  [[noreturn, gnu::noinline, gnu::cold]] static void too_large(uint64_t v, const std::string& path,
                                                               const std::string& what) {
    throw InputError(path + ": " + what + ": value " + std::to_string(v) + " too large");
  }
};

/// Calls f(value as double, value as int64) for each of the `count` little-endian values of
/// VTK type `type` (legacy name) in `bytes`; InputError naming `what` if the sizes differ.
template <class F>
void vtu_binary_values(const std::string& path, std::string_view bytes, std::string_view type,
                       int64_t count, const std::string& what, F f) {
  const int size = vtk_type_size(type);
  if (size <= 0 || count < 0 || static_cast<int64_t>(bytes.size()) != count * size)
    throw InputError(path + ": " + what + ": " + std::to_string(bytes.size()) +
                     " bytes of data, expected " + std::to_string(count) + " values of " +
                     std::to_string(size) + " bytes");
  auto each = [&](auto zero) {
    using T = decltype(zero);
    for (int64_t i = 0; i < count; ++i) {
      T v;
      std::memcpy(&v, bytes.data() + i * static_cast<int64_t>(sizeof(T)), sizeof(T));
      if constexpr (std::is_floating_point_v<T>) {
        f(static_cast<double>(v), 0);
      } else {
        if constexpr (std::is_same_v<T, uint64_t>)
          if (v > static_cast<uint64_t>(INT64_MAX))
            throw InputError(path + ": " + what + ": value " + std::to_string(v) + " too large");
        f(static_cast<double>(v), static_cast<int64_t>(v));
      }
    }
  };
  if (type == "char")
    each(int8_t{});
  else if (type == "unsigned_char")
    each(uint8_t{});
  else if (type == "short")
    each(int16_t{});
  else if (type == "unsigned_short")
    each(uint16_t{});
  else if (type == "int")
    each(int32_t{});
  else if (type == "unsigned_int")
    each(uint32_t{});
  else if (type == "long")
    each(int64_t{});
  else if (type == "unsigned_long")
    each(uint64_t{});
  else if (type == "float")
    each(float{});
  else
    each(double{});
}

int64_t line_of(std::string_view text, size_t pos) {
  int64_t line = 1;
  for (size_t i = 0; i < pos && i < text.size(); ++i)
    if (text[i] == '\n') ++line;
  return line;
}

}  // namespace

HexMesh vtu_read(const std::string& path, std::string_view text, const FileBytes* file) {
  const std::string_view all(text);
  auto fail_at = [&](size_t pos, const std::string& message) -> void {
    throw InputError(error_at(path, line_of(all, pos), message));
  };
  if (all.find("<VTKFile") == std::string_view::npos ||
      xml_attribute(all.substr(all.find("<VTKFile"), 300), "type") != "UnstructuredGrid")
    fail_at(0, "expected a VTK XML file <VTKFile type=\"UnstructuredGrid\" ...>");
  // The binary encodings (io_vtu_data.hpp): header integers, compressor, appended data.
  const size_t file_tag = all.find("<VTKFile");
  const std::string_view file_tag_text = all.substr(file_tag, all.find('>', file_tag) - file_tag);
  const std::string byte_order = xml_attribute(file_tag_text, "byte_order");
  if (!byte_order.empty() && byte_order != "LittleEndian")
    fail_at(file_tag, "byte_order=\"" + byte_order + "\": only LittleEndian data is read");
  const std::string header_type = xml_attribute(file_tag_text, "header_type");
  if (!header_type.empty() && header_type != "UInt32" && header_type != "UInt64")
    fail_at(file_tag, "header_type=\"" + header_type + "\": expected UInt32 or UInt64");
  const std::string compressor = xml_attribute(file_tag_text, "compressor");
  if (!compressor.empty() && compressor != "vtkZLibDataCompressor")
    fail_at(file_tag, "compressor=\"" + compressor +
                          "\": only vtkZLibDataCompressor (zlib) compressed data is read");
  const VtuBlockFormat block_format{header_type == "UInt64" ? 8 : 4, !compressor.empty()};
  // Appended data starts after the '_' that ends the XML part; XML is searched before it only.
  const size_t appended = all.find("<AppendedData");
  size_t appended_start = std::string_view::npos;
  bool appended_base64 = false;
  if (appended != std::string_view::npos) {
    const size_t tag_close = all.find('>', appended);
    if (tag_close == std::string_view::npos) fail_at(appended, "unterminated <AppendedData> tag");
    const std::string encoding =
        xml_attribute(all.substr(appended, tag_close - appended), "encoding");
    if (encoding != "raw" && encoding != "base64")
      fail_at(appended, "<AppendedData encoding=\"" + encoding + "\">: expected raw or base64");
    appended_base64 = encoding == "base64";
    appended_start = all.find('_', tag_close);
    if (appended_start == std::string_view::npos)
      fail_at(appended, "<AppendedData> without its '_' marker");
    ++appended_start;
  }
  const std::string_view xml = all.substr(0, appended);
  const size_t piece = xml.find("<Piece");
  if (piece == std::string_view::npos) fail_at(0, "no <Piece> element");
  if (xml.find("<Piece", piece + 1) != std::string_view::npos)
    fail_at(xml.find("<Piece", piece + 1), "more than one <Piece> is not supported");
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
  // Connectivity and types as Int32 (a point id or a cell type outside it is refused where it is
  // read), offsets as Int64: a 10 M-hex file's arrays in half the memory of Int64 throughout.
  std::vector<int32_t> connectivity, types;
  std::vector<int64_t> offsets;
  // Slots 0, 1, 2: connectivity, offsets, types. Raw uncompressed integer arrays stay in the
  // file (cells_in_file[slot].size > 0) and are read there when the hexes are built.
  std::array<CellsArrayInFile, 3> cells_in_file{};
  const std::string cells_names[3] = {"connectivity", "offsets", "types"};
  auto cells_append = [&](int slot, int64_t v, size_t tag) {
    if (slot == 1) return offsets.push_back(v);
    if (v < INT32_MIN || v > INT32_MAX)
      fail_at(tag, "DataArray '" + cells_names[slot] + "' holds " + std::to_string(v) +
                       ", out of range");
    (slot == 0 ? connectivity : types).push_back(static_cast<int32_t>(v));
  };
  auto cells_reserve = [&](int slot, size_t n) {
    slot == 1 ? offsets.reserve(n) : (slot == 0 ? connectivity : types).reserve(n);
  };
  bool have_points = false;
  struct Pending {
    std::string name;
    size_t begin;
    int64_t line;
    std::string type;
    std::string bytes;           ///< the decoded values of a binary array
    std::string_view file_data;  ///< or, raw and uncompressed, its values in the file itself
    bool in_file = false;
    bool binary = false;
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
  while ((p = xml.find("<DataArray", p)) != std::string_view::npos) {
    const size_t tag_end = xml.find('>', p);
    if (tag_end == std::string_view::npos) fail_at(p, "unterminated <DataArray> tag");
    const std::string_view tag = all.substr(p, tag_end - p);
    const bool self_closing = !tag.empty() && tag.back() == '/';
    const size_t close = self_closing ? tag_end : xml.find("</DataArray>", tag_end);
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
    if (format != "ascii" && format != "binary" && format != "appended")
      fail_at(p, "DataArray '" + name + "' has format \"" + format +
                     "\": expected ascii, binary or appended");
    // The values end at the first nested element (VTK writes <InformationKey> after them).
    const size_t values_end = self_closing ? tag_end : std::min(close, all.find('<', tag_end + 1));
    const bool binary = format != "ascii";
    std::string bytes;      // a binary array's decoded values
    std::string_view data;  // its values: `bytes`, or the file's own bytes (raw, uncompressed)
    bool in_file = false;
    if (format == "binary") {
      bytes = vtu_block_decode_base64(all.substr(tag_end + 1, values_end - tag_end - 1),
                                      block_format, path, tag_end + 1);
    } else if (format == "appended") {
      int64_t offset = -1;
      if (appended_start == std::string_view::npos ||
          !TextCursor::parse_integer(xml_attribute(tag, "offset"), offset) || offset < 0 ||
          static_cast<uint64_t>(offset) > all.size() - appended_start)
        fail_at(p, "appended DataArray '" + name +
                       "' needs an offset inside <AppendedData> (offset=\"" +
                       xml_attribute(tag, "offset") + "\")");
      const size_t at = appended_start + static_cast<size_t>(offset);
      if (appended_base64) {
        const size_t length = vtu_block_base64_length(all.substr(at), block_format, path, at);
        bytes = vtu_block_decode_base64(all.substr(at, length), block_format, path, at);
      } else if (!block_format.zlib) {
        data = vtu_block_raw_data(all.substr(at), block_format, path, at, nullptr);  // no copy
        in_file = true;
      } else {
        bytes = vtu_block_decode_raw(all.substr(at), block_format, path, at, nullptr);
      }
    }
    if (!in_file) data = bytes;
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
      auto store = [&](double d, int64_t v) {
        st.mesh.points[i / 3][i % 3] =
            vtk_type_is_integer(legacy_type) ? static_cast<double>(v) : d;
        ++i;
      };
      static_assert(sizeof(Eigen::Vector3d) == 3 * sizeof(double));
      if (binary && legacy_type == "double" &&
          data.size() == static_cast<size_t>(np) * sizeof(Eigen::Vector3d)) {
        // Float64, as the points are held: one copy, then the finiteness test.
        std::memcpy(static_cast<void*>(st.mesh.points.data()), data.data(), data.size());
        for (int64_t k = 0; k < np; ++k)
          if (!st.mesh.points[k].allFinite())
            throw InputError(path + ": point " + std::to_string(k) +
                             " has a NaN or infinite coordinate");
      } else if (binary)
        vtu_binary_values(path, data, legacy_type, 3 * np, "point coordinates",
                          [&](double d, int64_t v) {
                            if (!std::isfinite(d))
                              throw InputError(path + ": point " + std::to_string(i / 3) +
                                               " has a NaN or infinite coordinate");
                            store(d, v);
                          });
      else
        vtk_read_values(in, false, legacy_type, 3 * np, "point coordinate", false, store);
      if (in_file && file) file->release(data);
      have_points = true;
    } else if (section == in_cells && section >= 0) {
      const int slot = name == "connectivity" ? 0
                       : name == "offsets"    ? 1
                       : name == "types"      ? 2
                                              : -1;
      if (slot < 0) fail_at(p, "unknown Cells DataArray '" + name + "'");
      if (binary) {
        const int value_size = vtk_type_size(legacy_type);
        if (value_size <= 0 || data.size() % static_cast<size_t>(value_size) != 0)
          fail_at(p, what + ": " + std::to_string(data.size()) + " bytes, not whole values");
        if (in_file && vtk_type_is_integer(legacy_type)) {
          cells_in_file[slot] = CellsArrayInFile{data, p, value_size,
                                                 legacy_type == "char" || legacy_type == "short" ||
                                                     legacy_type == "int" || legacy_type == "long"};
        } else {
          cells_reserve(slot, data.size() / static_cast<size_t>(value_size));
          vtu_binary_values(path, data, legacy_type, static_cast<int64_t>(data.size()) / value_size,
                            what, [&](double, int64_t v) { cells_append(slot, v, p); });
          if (in_file && file) file->release(data);
        }
      }
      size_t read = 0;
      while (!binary && !in.at_end()) {
        if (read++ >= static_cast<size_t>(size)) in.fail("too many values");
        cells_append(slot, in.integer(what), p);
      }
    } else if (section == in_cell_data && section >= 0) {
      cell_arrays.push_back({name, tag_end + 1, in.line(), legacy_type, std::move(bytes),
                             in_file ? data : std::string_view(), in_file, binary});
      if (comps != "" && comps != "1") cell_arrays.back().type = "";  // multi-component: skipped
    }
    if (!binary && section >= 0 && !in.at_end() && (section == in_points || section == in_cells))
      in.fail("more values than expected in " + what);
    p = close;
  }
  if (!have_points) fail_at(piece, "no <Points> DataArray");
  // Arrays left in the file whose partners were not (encodings mixed within <Cells>) are read
  // into arrays after all, as the others were.
  const bool all_in_file = cells_in_file[0].size && cells_in_file[1].size && cells_in_file[2].size;
  for (int slot = 0; slot < 3 && !all_in_file; ++slot) {
    const CellsArrayInFile& a = cells_in_file[slot];
    if (!a.size) continue;
    const std::string what = "values of DataArray '" + cells_names[slot] + "'";
    cells_reserve(slot, static_cast<size_t>(a.count()));
    for (int64_t i = 0; i < a.count(); ++i) cells_append(slot, a.at(i, path, what), a.tag);
    if (file) file->release(a.bytes);
  }
  // The hexes from the cells: `connectivity(i)`, `offset(c)`, `type(c)` give the arrays' values
  // wherever they are (in the file, range-checked as they are read, or decoded above).
  auto build = [&](int64_t connectivity_count, int64_t offset_count, int64_t type_count,
                   auto connectivity_at, auto offset_at, auto type_at) {
    if (offset_count != nc || type_count != nc)
      fail_at(piece, "Cells offsets/types need NumberOfCells = " + std::to_string(nc) + " values");
    st.hex_of_cell.assign(static_cast<size_t>(nc), -1);
    st.mesh.hexes.reserve(static_cast<size_t>(nc));
    int64_t start = 0;
    for (int64_t c = 0; c < nc; ++c) {
      const int64_t end = offset_at(c);
      if (end < start || end > connectivity_count)
        fail_at(piece, "cell " + std::to_string(c) +
                           ": offsets not increasing or beyond the connectivity");
      const int32_t type = type_at(c);
      const int kind = vtk_cell_kind(type);
      if (kind == -1)
        fail_at(piece,
                "cell " + std::to_string(c) + " has VTK type " + std::to_string(type) +
                    ", a volume cell that is not a linear hexahedron (only hexes are supported)");
      if (kind == -2)
        fail_at(piece,
                "cell " + std::to_string(c) + " has unknown VTK type " + std::to_string(type));
      if (kind == 1) {
        if (end - start != 8)
          fail_at(piece, "hexahedron " + std::to_string(c) + " has " + std::to_string(end - start) +
                             " nodes, expected 8");
        HexCell h;
        for (int k = 0; k < 8; ++k) {
          const int64_t v = connectivity_at(start + k);
          if (v < 0 || v >= np)
            fail_at(piece, "cell " + std::to_string(c) + " refers to point " + std::to_string(v) +
                               ", expected 0.." + std::to_string(np - 1));
          h[k] = static_cast<int32_t>(v);
        }
        if (type == 11) std::swap(h[2], h[3]), std::swap(h[6], h[7]);
        st.hex_of_cell[c] = static_cast<int32_t>(st.mesh.hexes.size());
        st.mesh.hexes.push_back(h);
      } else {
        for (int64_t i = start; i < end; ++i) connectivity_at(i);  // range-checked all the same
      }
      start = end;
    }
    for (int64_t i = start; i < connectivity_count; ++i) connectivity_at(i);
  };
  if (all_in_file) {
    const CellsArrayInFile &cells = cells_in_file[0], &ends = cells_in_file[1],
                           &kinds = cells_in_file[2];
    const std::string what[3] = {"values of DataArray 'connectivity'",
                                 "values of DataArray 'offsets'", "values of DataArray 'types'"};
    auto int32_value = [&](int slot, int64_t i) {
      const int64_t v = cells_in_file[slot].at(i, path, what[slot]);
      if (v < INT32_MIN || v > INT32_MAX)
        fail_at(cells_in_file[slot].tag, "DataArray '" + cells_names[slot] + "' holds " +
                                             std::to_string(v) + ", out of range");
      return static_cast<int32_t>(v);
    };
    build(
        cells.count(), ends.count(), kinds.count(),
        [&](int64_t i) { return int64_t{int32_value(0, i)}; },
        [&](int64_t c) { return ends.at(c, path, what[1]); },
        [&](int64_t c) { return int32_value(2, c); });
    if (file)
      for (const CellsArrayInFile& a : cells_in_file) file->release(a.bytes);
  } else {
    build(
        static_cast<int64_t>(connectivity.size()), static_cast<int64_t>(offsets.size()),
        static_cast<int64_t>(types.size()), [&](int64_t i) { return int64_t{connectivity[i]}; },
        [&](int64_t c) { return offsets[c]; }, [&](int64_t c) { return types[c]; });
  }
  // The hexes hold the cells now: the file's arrays go before the attributes are built.
  std::vector<int32_t>().swap(connectivity);
  std::vector<int32_t>().swap(types);
  std::vector<int64_t>().swap(offsets);
  for (const Pending& a : cell_arrays) {
    if (a.type.empty() || !vtk_type_is_integer(a.type) || a.name.empty() ||
        mesh_find_attribute(st.mesh, a.name))
      continue;
    if (a.binary) {
      std::vector<int32_t> values(st.mesh.hexes.size());
      int64_t i = 0;
      const std::string what = "DataArray '" + a.name + "'";
      vtu_binary_values(
          path, a.in_file ? a.file_data : a.bytes, a.type, nc, what, [&](double, int64_t v) {
            if (v < INT32_MIN || v > INT32_MAX)
              throw InputError(path + ": " + what + ": " + std::to_string(v) + " exceeds int32");
            const int32_t h = st.hex_of_cell[i++];
            if (h >= 0) values[h] = static_cast<int32_t>(v);
          });
      if (a.in_file && file) file->release(a.file_data);
      st.mesh.attributes.push_back({a.name, std::move(values)});
      continue;
    }
    const size_t close = std::min(all.find("</DataArray>", a.begin), all.find('<', a.begin));
    TextCursor in(path, all.substr(a.begin, close - a.begin));
    in.set_line(a.line);
    vtk_read_array(in, false, st, true, a.name, a.type, 1, nc);
    if (!in.at_end()) in.fail("more than NumberOfCells values in DataArray '" + a.name + "'");
  }
  return std::move(st.mesh);
}

}  // namespace hexrefine::io_detail
