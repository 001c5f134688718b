/// \file
/// Gmsh 4.1 writer, text or binary (the layout is described in io_gmsh.cpp, the reader). Hexes
/// are grouped into one volume entity per block_id (entity tag = the block's rank + 1, its
/// physical tag the block id when > 0) and tagged h + 1, so the reader restores their order;
/// every attribute and cell scalar is an $ElementData field.

#include <algorithm>

#include "mesh/atomic_file.hpp"
#include "mesh/io.hpp"
#include "mesh/io_text.hpp"

namespace hexrefine::io_detail {

void gmsh_write(const std::string& path, const HexMesh& mesh, bool binary,
                const std::vector<std::pair<std::string, std::vector<double>>>& cell_scalars) {
  static_assert(std::endian::native == std::endian::little,
                "the binary Gmsh writer assumes little-endian");
  static_assert(sizeof(Eigen::Vector3d) == 3 * sizeof(double), "points are written as one block");
  const size_t m = mesh.hexes.size(), n = mesh.points.size();
  // One volume entity per block id (entity tag = rank + 1), hexes grouped by entity.
  const HexBlocks groups = hex_blocks_group(mesh, 0);
  const std::vector<int32_t>& blocks = groups.ids;
  file_write_atomically(path, [&](std::ostream& out) {
    TextWriter w(out);
    // The numbers of a section: a token and its separator, or a binary int / size_t / double.
    auto int_value = [&](int64_t v, char separator) {
      if (binary)
        w.native(static_cast<int32_t>(v));
      else
        w.integer(v).put(separator);
    };
    auto size_value = [&](int64_t v, char separator) {
      if (binary)
        w.native(static_cast<uint64_t>(v));
      else
        w.integer(v).put(separator);
    };
    auto real = [&](double v, char separator) {
      if (binary)
        w.native(v);
      else
        w.real(v).put(separator);
    };
    auto section_end = [&](std::string_view end) {
      if (binary) w.put('\n');
      w.text(end);
    };
    w.text(binary ? "$MeshFormat\n4.1 1 8\n" : "$MeshFormat\n4.1 0 8\n");
    if (binary) w.native(int32_t{1}).put('\n');
    w.text("$EndMeshFormat\n$Entities\n");
    for (int k = 0; k < 3; ++k) size_value(0, ' ');
    size_value(static_cast<int64_t>(blocks.size()), '\n');
    for (size_t e = 0; e < blocks.size(); ++e) {
      Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
      for (size_t i = groups.starts[e]; i < groups.starts[e + 1]; ++i)
        for (int32_t v : mesh.hexes[groups.order[i]]) {
          lo = lo.cwiseMin(mesh.points[v]);
          hi = hi.cwiseMax(mesh.points[v]);
        }
      int_value(static_cast<int64_t>(e) + 1, ' ');
      for (int k = 0; k < 6; ++k) real(k < 3 ? lo[k] : hi[k - 3], ' ');
      size_value(blocks[e] > 0 ? 1 : 0, ' ');
      if (blocks[e] > 0) int_value(blocks[e], ' ');
      size_value(0, '\n');  // bounding surfaces
    }
    section_end("$EndEntities\n$Nodes\n");
    const int64_t n64 = static_cast<int64_t>(n), m64 = static_cast<int64_t>(m);
    size_value(1, ' ');
    size_value(n64, ' ');
    size_value(n ? 1 : 0, ' ');
    size_value(n64, '\n');
    int_value(3, ' ');
    int_value(1, ' ');
    int_value(0, ' ');
    size_value(n64, '\n');
    for (int64_t v = 1; v <= n64; ++v) size_value(v, '\n');
    if (binary) {
      w.native(mesh.points.empty() ? nullptr : mesh.points[0].data(), 3 * n);
    } else {
      for (const Eigen::Vector3d& p : mesh.points)
        w.real(p.x()).put(' ').real(p.y()).put(' ').real(p.z()).put('\n');
    }
    section_end("$EndNodes\n$Elements\n");
    size_value(static_cast<int64_t>(blocks.size()), ' ');
    size_value(m64, ' ');
    size_value(m ? 1 : 0, ' ');
    size_value(m64, '\n');
    for (size_t e = 0; e < blocks.size(); ++e) {
      const size_t i0 = groups.starts[e], j = groups.starts[e + 1];
      int_value(3, ' ');
      int_value(static_cast<int64_t>(e) + 1, ' ');
      int_value(5, ' ');
      size_value(static_cast<int64_t>(j - i0), '\n');
      for (size_t i = i0; i < j; ++i) {
        const int32_t h = groups.order[i];
        if (binary) {
          std::array<uint64_t, 9> row;
          row[0] = static_cast<uint64_t>(h) + 1;
          for (int k = 0; k < 8; ++k) row[k + 1] = static_cast<uint64_t>(mesh.hexes[h][k]) + 1;
          w.native(row.data(), row.size());
        } else {
          w.integer(int64_t{h} + 1);
          for (int32_t v : mesh.hexes[h]) w.put(' ').integer(int64_t{v} + 1);
          w.put('\n');
        }
      }
    }
    section_end("$EndElements\n");
    // $ElementData: the tag header is text in both encodings; binary rows are (int, double).
    auto data = [&](const std::string& name, auto value_of) {
      w.text("$ElementData\n1\n\"").text(name).text("\"\n1\n0\n3\n0\n1\n").integer(m64).put('\n');
      for (size_t h = 0; h < m; ++h) {
        if (binary) {
          w.native(static_cast<int32_t>(h + 1)).native(static_cast<double>(value_of(h)));
        } else {
          w.integer(static_cast<int64_t>(h) + 1).put(' ');
          if constexpr (std::is_integral_v<decltype(value_of(h))>)
            w.integer(value_of(h));
          else
            w.real(value_of(h));
          w.put('\n');
        }
      }
      section_end("$EndElementData\n");
    };
    if (m > 0) {
      for (const HexAttribute& a : mesh.attributes)
        data(a.name, [&](size_t h) { return int64_t{a.values[h]}; });
      for (const auto& scalar : cell_scalars)  // (clang 14 lambdas cannot capture bindings)
        data(scalar.first, [&](size_t h) { return scalar.second[h]; });
    }
    w.flush();
  });
}

}  // namespace hexrefine::io_detail
