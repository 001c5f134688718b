/// \file
/// VTK XML unstructured grid (.vtu) writer: appended raw binary data by default (zlib-compressed
/// on request), or ASCII. Hexes as VTK_HEXAHEDRON (12), whose node order is hexrefine's; every
/// attribute and cell scalar as cell data. The reader is io_vtu.cpp.

#include <algorithm>
#include <bit>

#include "mesh/atomic_file.hpp"
#include "mesh/io.hpp"
#include "mesh/io_text.hpp"
#include "mesh/io_vtk_common.hpp"
#include "mesh/io_vtu_data.hpp"

namespace hexrefine::io_detail {

namespace {

/// The binary VTU: every array in <AppendedData encoding="raw">, each a block (UInt64 byte
/// count, then the little-endian values; zlib blocks with `compress`). Connectivity and offsets
/// are Int32 while the offsets fit (8 x hexes <= 2^31 - 1), else Int64.
void vtu_write_appended(std::ostream& out, const HexMesh& mesh,
                        const std::vector<std::pair<std::string, std::vector<double>>>& scalars,
                        bool compress) {
  static_assert(std::endian::native == std::endian::little, "the VTU writer assumes little-endian");
  const size_t n = mesh.points.size(), m = mesh.hexes.size();
  const bool wide = 8 * static_cast<uint64_t>(m) > static_cast<uint64_t>(INT32_MAX);
  std::vector<uint8_t> types(m, 12);
  std::vector<int64_t> offsets64;
  std::vector<int32_t> offsets32;
  std::vector<int64_t> connectivity64;
  if (wide) {
    offsets64.resize(m);
    connectivity64.resize(8 * m);
    for (size_t h = 0; h < m; ++h) {
      offsets64[h] = 8 * static_cast<int64_t>(h + 1);
      for (int k = 0; k < 8; ++k) connectivity64[8 * h + k] = mesh.hexes[h][k];
    }
  } else {
    offsets32.resize(m);
    for (size_t h = 0; h < m; ++h) offsets32[h] = 8 * static_cast<int32_t>(h + 1);
  }
  // The arrays in file order: their XML before the offset, data, bytes. HexCell is 8 packed
  // int32 and a point 3 packed doubles, so both are written straight from the mesh.
  static_assert(sizeof(HexCell) == 32 && sizeof(Eigen::Vector3d) == 24);
  struct Array {
    std::string xml;
    const void* data;
    size_t bytes;
  };
  const std::string index = wide ? "Int64" : "Int32";
  std::vector<Array> arrays = {
      {"<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\"", mesh.points.data(),
       24 * n},
      {"</Points>\n<Cells>\n<DataArray type=\"" + index + "\" Name=\"connectivity\"",
       wide ? static_cast<const void*>(connectivity64.data()) : mesh.hexes.data(),
       (wide ? 64 : 32) * m},
      {"<DataArray type=\"" + index + "\" Name=\"offsets\"",
       wide ? static_cast<const void*>(offsets64.data()) : offsets32.data(), (wide ? 8 : 4) * m},
      {"<DataArray type=\"UInt8\" Name=\"types\"", types.data(), m}};
  const bool cell_data = !mesh.attributes.empty() || !scalars.empty();
  for (size_t i = 0; i < mesh.attributes.size(); ++i)
    arrays.push_back({std::string(i == 0 ? "</Cells>\n<CellData>\n" : "") +
                          "<DataArray type=\"Int32\" Name=\"" + mesh.attributes[i].name + "\"",
                      mesh.attributes[i].values.data(), 4 * m});
  for (size_t i = 0; i < scalars.size(); ++i)
    arrays.push_back(
        {std::string(i == 0 && mesh.attributes.empty() ? "</Cells>\n<CellData>\n" : "") +
             "<DataArray type=\"Float64\" Name=\"" + scalars[i].first + "\"",
         scalars[i].second.data(), 8 * m});
  std::vector<std::string> compressed;
  if (compress)
    for (const Array& a : arrays) compressed.push_back(vtu_block_compress(a.data, a.bytes));
  std::string xml =
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" "
      "byte_order=\"LittleEndian\" header_type=\"UInt64\"";
  if (compress) xml += " compressor=\"vtkZLibDataCompressor\"";
  xml += ">\n<UnstructuredGrid>\n<Piece NumberOfPoints=\"" + std::to_string(n) +
         "\" NumberOfCells=\"" + std::to_string(m) + "\">\n";
  uint64_t offset = 0;
  for (size_t i = 0; i < arrays.size(); ++i) {
    xml += arrays[i].xml + " format=\"appended\" offset=\"" + std::to_string(offset) + "\"/>\n";
    offset += compress ? compressed[i].size() : 8 + arrays[i].bytes;
  }
  xml += cell_data ? "</CellData>\n" : "</Cells>\n";
  xml += "</Piece>\n</UnstructuredGrid>\n<AppendedData encoding=\"raw\">\n_";
  out.write(xml.data(), static_cast<std::streamsize>(xml.size()));
  for (size_t i = 0; i < arrays.size(); ++i) {
    if (compress) {
      out.write(compressed[i].data(), static_cast<std::streamsize>(compressed[i].size()));
      continue;
    }
    const uint64_t bytes = arrays[i].bytes;
    out.write(reinterpret_cast<const char*>(&bytes), 8);
    out.write(static_cast<const char*>(arrays[i].data), static_cast<std::streamsize>(bytes));
  }
  const std::string tail = "\n</AppendedData>\n</VTKFile>\n";
  out.write(tail.data(), static_cast<std::streamsize>(tail.size()));
}

}  // namespace

void vtu_write(const std::string& path, const HexMesh& mesh,
               const std::vector<std::pair<std::string, std::vector<double>>>& cell_scalars,
               bool ascii, bool compress) {
  if (!ascii) {
    file_write_atomically(
        path, [&](std::ostream& out) { vtu_write_appended(out, mesh, cell_scalars, compress); });
    return;
  }
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
