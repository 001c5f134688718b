/// \file
/// Gmsh ASCII meshes (.msh): format 4.1 read and write, 2.2 (also 2.0/2.1) read. Gmsh element
/// type 5 (8-node hexahedron) has VTK's node order (nodes 0-3 at reference z = -1
/// counter-clockwise, 4-7 above them), so nodes are copied as they are. Binary .msh files are
/// refused. Nodes and hexes are ordered by tag when their tags are a permutation of 1..n (gmsh
/// itself may list nodes out of tag order), otherwise by file order. The writer gives hex h the
/// tag h + 1 and groups hexes into one volume entity per block_id, so the order survives.

#include <algorithm>
#include <map>

#include "mesh/atomic_file.hpp"
#include "mesh/io.hpp"
#include "mesh/io_text.hpp"

namespace hexrefine::io_detail {

namespace {

/// Nodes of Gmsh element type t (0 if unknown); `volume` set for 3D elements.
int gmsh_element_nodes(int64_t t, bool& volume) {
  static const int nodes[] = {0, 2,  3,  4,  4, 8,  6,  5,  3,  6,  9, 10, 27, 18, 14, 1,
                              8, 20, 15, 13, 9, 10, 12, 15, 15, 21, 4, 5,  6,  20, 35, 56};
  volume = t == 4 || t == 5 || t == 6 || t == 7 || t == 11 || t == 12 || t == 13 || t == 14 ||
           t == 17 || t == 18 || t == 19 || t == 29 || t == 30 || t == 31 || t == 92 || t == 93;
  if (t == 92) return 64;
  if (t == 93) return 125;
  if (t < 1 || t > 31) return 0;
  return nodes[t];
}

/// A string tag: a "quoted string" that may span several tokens.
std::string gmsh_string(TextCursor& in) {
  std::string s(in.token("a quoted string"));
  if (s.empty() || s[0] != '"')
    in.fail("expected a quoted string, got '" + TextCursor::shown(s) + "'");
  while (s.size() < 2 || s.back() != '"') {
    if (s.size() > 1000) in.fail("unterminated quoted string");
    s += " ";
    s += in.token("the end of a quoted string");
  }
  return s.substr(1, s.size() - 2);
}

struct GmshRead {
  HexMesh mesh;
  std::vector<int64_t> node_tags;
  std::vector<int64_t> hex_tags;
  std::vector<std::array<int64_t, 8>> hex_nodes;
  std::vector<int64_t> hex_lines;
  std::vector<int32_t> hex_block;
  struct Data {
    std::string name;
    std::vector<std::pair<int64_t, double>> values;  // element tag, value
    int64_t line;
  };
  std::vector<Data> element_data;
};

/// Reads one element row of type `type` (tag then nodes); keeps it if it is a hex.
void gmsh_element_row(TextCursor& in, GmshRead& g, int64_t type, int64_t tag, int32_t block) {
  bool volume = false;
  const int n = gmsh_element_nodes(type, volume);
  if (n == 0) in.fail("unknown Gmsh element type " + std::to_string(type));
  if (volume && type != 5)
    in.fail("element " + std::to_string(tag) + " has Gmsh type " + std::to_string(type) +
            ", a volume element that is not a linear hexahedron (only type 5 is supported)");
  if (type != 5) {
    for (int k = 0; k < n; ++k) in.integer("node tag");
    return;
  }
  std::array<int64_t, 8> nodes;
  const int64_t line = in.line();
  for (int k = 0; k < 8; ++k) nodes[k] = in.integer("node tag");
  g.hex_tags.push_back(tag);
  g.hex_nodes.push_back(nodes);
  g.hex_lines.push_back(line);
  g.hex_block.push_back(block);
}

void gmsh_skip_section(TextCursor& in, std::string_view name) {
  const std::string end = "$End" + std::string(name.substr(1));
  const std::string expected = "'" + end + "'";
  while (in.token(expected) != end) {
  }
}

}  // namespace

HexMesh gmsh_read(const std::string& path, const std::string& text) {
  TextCursor in(path, text);
  GmshRead g;
  in.expect("$MeshFormat");
  const double version = in.real("the format version");
  const int64_t file_type = in.integer("the file type");
  in.integer("the data size");
  if (file_type != 0) in.fail("binary Gmsh files are not supported (save as ASCII)");
  const bool v4 = version >= 4.05 && version < 5;
  if (!v4 && !(version >= 2 && version < 3))
    in.fail("Gmsh format " + std::to_string(version) + " is not supported (expected 4.1 or 2.2)");
  in.expect("$EndMeshFormat");
  std::map<int64_t, int32_t> volume_physical;  // volume entity tag -> first physical tag
  bool have_nodes = false, have_elements = false;
  while (!in.at_end()) {
    const std::string_view section = in.token("a section");
    if (section == "$Entities" && v4) {
      int64_t counts[4];
      for (int64_t& c : counts) c = in.count("entity count", 4);
      for (int dim = 0; dim < 4; ++dim)
        for (int64_t e = 0; e < counts[dim]; ++e) {
          const int64_t tag = in.integer("entity tag");
          for (int k = 0; k < (dim == 0 ? 3 : 6); ++k) in.real("entity bounding box");
          const int64_t nphys = in.count("physical tag count", 2);
          for (int64_t k = 0; k < nphys; ++k) {
            const int64_t phys = in.integer("physical tag");
            if (dim == 3 && k == 0) {
              if (phys < INT32_MIN || phys > INT32_MAX) in.fail("physical tag out of range");
              volume_physical[tag] = static_cast<int32_t>(phys);
            }
          }
          if (dim > 0) {
            const int64_t nb = in.count("bounding entity count", 2);
            for (int64_t k = 0; k < nb; ++k) in.integer("bounding entity tag");
          }
        }
      in.expect("$EndEntities");
    } else if (section == "$Nodes") {
      if (have_nodes) in.fail("second $Nodes section");
      have_nodes = true;
      if (v4) {
        const int64_t blocks = in.count("node block count", 8);
        const int64_t total = in.count("node count", 8);
        in.integer("min node tag");
        in.integer("max node tag");
        g.node_tags.reserve(static_cast<size_t>(total));
        g.mesh.points.reserve(static_cast<size_t>(total));
        for (int64_t b = 0; b < blocks; ++b) {
          const int64_t dim = in.integer_in("entity dimension", 0, 3);
          in.integer("entity tag");
          const int64_t parametric = in.integer_in("parametric flag", 0, 1);
          const int64_t n = in.count("nodes in block", 8);
          if (static_cast<int64_t>(g.node_tags.size()) + n > total)
            in.fail("node blocks hold more than the " + std::to_string(total) + " nodes announced");
          for (int64_t i = 0; i < n; ++i) g.node_tags.push_back(in.integer("node tag"));
          for (int64_t i = 0; i < n; ++i) {
            Eigen::Vector3d p;
            for (int k = 0; k < 3; ++k) p[k] = in.real("node coordinate");
            if (parametric)
              for (int64_t k = 0; k < dim; ++k) in.real("parametric coordinate");
            g.mesh.points.push_back(p);
          }
        }
        if (static_cast<int64_t>(g.node_tags.size()) != total)
          in.fail("node blocks hold " + std::to_string(g.node_tags.size()) + " nodes, " +
                  std::to_string(total) + " announced");
      } else {
        const int64_t n = in.count("node count", 8);
        g.node_tags.reserve(static_cast<size_t>(n));
        g.mesh.points.resize(static_cast<size_t>(n));
        for (int64_t i = 0; i < n; ++i) {
          g.node_tags.push_back(in.integer("node tag"));
          for (int k = 0; k < 3; ++k) g.mesh.points[i][k] = in.real("node coordinate");
        }
      }
      in.expect("$EndNodes");
    } else if (section == "$Elements") {
      if (have_elements) in.fail("second $Elements section");
      have_elements = true;
      if (v4) {
        const int64_t blocks = in.count("element block count", 8);
        const int64_t total = in.count("element count", 4);
        in.integer("min element tag");
        in.integer("max element tag");
        int64_t seen = 0;
        for (int64_t b = 0; b < blocks; ++b) {
          const int64_t dim = in.integer_in("entity dimension", 0, 3);
          const int64_t entity = in.integer("entity tag");
          const int64_t type = in.integer("element type");
          const int64_t n = in.count("elements in block", 4);
          seen += n;
          if (seen > total)
            in.fail("element blocks hold more than the " + std::to_string(total) +
                    " elements announced");
          int32_t block = 0;
          if (dim == 3) {
            const auto it = volume_physical.find(entity);
            if (it != volume_physical.end()) block = it->second;
          }
          for (int64_t i = 0; i < n; ++i) {
            const int64_t tag = in.integer("element tag");
            gmsh_element_row(in, g, type, tag, block);
          }
        }
        if (seen != total)
          in.fail("element blocks hold " + std::to_string(seen) + " elements, " +
                  std::to_string(total) + " announced");
      } else {
        const int64_t n = in.count("element count", 8);
        for (int64_t i = 0; i < n; ++i) {
          const int64_t tag = in.integer("element tag");
          const int64_t type = in.integer("element type");
          const int64_t ntags = in.integer_in("tag count", 0, 64);
          int32_t block = 0;
          for (int64_t k = 0; k < ntags; ++k) {
            const int64_t t = in.integer("element tag value");
            if (k == 0) {
              if (t < INT32_MIN || t > INT32_MAX) in.fail("physical tag out of range");
              block = static_cast<int32_t>(t);
            }
          }
          gmsh_element_row(in, g, type, tag, block);
        }
      }
      in.expect("$EndElements");
    } else if (section == "$ElementData") {
      GmshRead::Data d;
      d.line = in.line();
      const int64_t nstrings = in.integer_in("string tag count", 0, 64);
      for (int64_t k = 0; k < nstrings; ++k) {
        const std::string s = gmsh_string(in);
        if (k == 0) d.name = s;
      }
      const int64_t nreals = in.integer_in("real tag count", 0, 64);
      for (int64_t k = 0; k < nreals; ++k) in.real("real tag");
      const int64_t nints = in.integer_in("integer tag count", 3, 64);
      int64_t components = 1, count = 0;
      for (int64_t k = 0; k < nints; ++k) {
        const int64_t v = in.integer("integer tag");
        if (k == 1) components = v;
        if (k == 2) count = v;
      }
      if (components < 1 || components > 9)
        in.fail("bad component count " + std::to_string(components));
      in.check_count(count, "element data count", 2 * (1 + components));
      const bool keep = components == 1 && !d.name.empty();
      if (keep) d.values.reserve(static_cast<size_t>(count));
      for (int64_t i = 0; i < count; ++i) {
        const int64_t tag = in.integer("element tag");
        for (int64_t c = 0; c < components; ++c) {
          const std::string_view t = in.token("element data value");
          double v = 0;
          if (!TextCursor::parse_real(t, v)) v = 0.5;  // NaN/inf: not an integer attribute
          if (keep) d.values.emplace_back(tag, v);
        }
      }
      in.expect("$EndElementData");
      if (keep) g.element_data.push_back(std::move(d));
    } else if (!section.empty() && section[0] == '$' && section.substr(0, 4) != "$End") {
      gmsh_skip_section(in, section);
    } else {
      in.fail("expected a section such as $Nodes or $Elements, got '" + TextCursor::shown(section) +
              "'");
    }
  }
  if (!have_nodes || !have_elements) in.fail("expected $Nodes and $Elements sections");

  items_sort_by_permutation_ids(g.mesh.points, g.node_tags);
  IdIndex nodes;
  if (const int64_t bad = nodes.build(g.node_tags); bad >= 0)
    in.fail("node tag " + std::to_string(g.node_tags[bad]) + " repeated or not positive");
  if (g.hex_tags.size() > INT32_MAX) in.fail("too many hexes");
  const size_t m = g.hex_tags.size();
  // Order: by tag when the hex tags are exactly 1..m, else file order.
  std::vector<int32_t> slot = id_permutation_slots(g.hex_tags);
  if (slot.empty())
    for (size_t i = 0; i < m; ++i) slot.push_back(static_cast<int32_t>(i));
  g.mesh.hexes.resize(m);
  std::vector<int32_t> block(m);
  for (size_t i = 0; i < m; ++i) {
    for (int k = 0; k < 8; ++k) {
      const int64_t v = nodes.find(g.hex_nodes[i][k]);
      if (v < 0)
        throw InputError(error_at(path, g.hex_lines[i],
                                  "hex element " + std::to_string(g.hex_tags[i]) +
                                      " refers to undefined node " +
                                      std::to_string(g.hex_nodes[i][k])));
      g.mesh.hexes[slot[i]][k] = static_cast<int32_t>(v);
    }
    block[slot[i]] = g.hex_block[i];
  }
  g.mesh.attributes.push_back({std::string(attribute_block_id), std::move(block)});
  IdIndex hexes;
  if (const int64_t bad = hexes.build(g.hex_tags); bad >= 0)
    throw InputError(
        error_at(path, g.hex_lines[bad],
                 "element tag " + std::to_string(g.hex_tags[bad]) + " repeated or not positive"));
  for (const GmshRead::Data& d : g.element_data) {
    std::vector<int32_t> values(m, 0);
    bool integral = true;
    for (const auto& [tag, v] : d.values) {
      const int64_t i = hexes.find(tag);
      if (i < 0) continue;  // data of a skipped element
      if (v != std::floor(v) || v < INT32_MIN || v > INT32_MAX)
        integral = false;
      else
        values[slot[i]] = static_cast<int32_t>(v);
    }
    if (!integral) continue;
    if (mesh_find_attribute(g.mesh, d.name) != nullptr) {
      // block_id from $ElementData overrides the physical tags (it also holds ids <= 0); other
      // repeated names are later time steps of a field already read.
      if (d.name == attribute_block_id && d.line > 0)
        mesh_attribute(g.mesh, d.name) = std::move(values);
      continue;
    }
    g.mesh.attributes.push_back({d.name, std::move(values)});
  }
  mesh_check_read(g.mesh, path);
  return std::move(g.mesh);
}

void gmsh_write(const std::string& path, const HexMesh& mesh,
                const std::vector<std::pair<std::string, std::vector<double>>>& cell_scalars) {
  const std::vector<int32_t>* block = mesh_find_attribute(mesh, attribute_block_id);
  const size_t m = mesh.hexes.size(), n = mesh.points.size();
  // One volume entity per block id (entity tag = rank + 1), hexes grouped by entity.
  std::vector<std::pair<int32_t, int32_t>> order(m);
  for (size_t h = 0; h < m; ++h) order[h] = {block ? (*block)[h] : 0, static_cast<int32_t>(h)};
  std::sort(order.begin(), order.end());
  std::vector<int32_t> blocks;
  for (const auto& [b, h] : order)
    if (blocks.empty() || blocks.back() != b) blocks.push_back(b);
  file_write_atomically(path, [&](std::ostream& out) {
    TextWriter w(out);
    w.text("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n");
    w.text("$Entities\n0 0 0 ").integer(static_cast<int64_t>(blocks.size())).put('\n');
    size_t i = 0;
    for (size_t e = 0; e < blocks.size(); ++e) {
      Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
      for (; i < m && order[i].first == blocks[e]; ++i)
        for (int32_t v : mesh.hexes[order[i].second]) {
          lo = lo.cwiseMin(mesh.points[v]);
          hi = hi.cwiseMax(mesh.points[v]);
        }
      w.integer(static_cast<int64_t>(e) + 1);
      for (int k = 0; k < 6; ++k) w.put(' ').real(k < 3 ? lo[k] : hi[k - 3]);
      if (blocks[e] > 0)
        w.text(" 1 ").integer(blocks[e]).text(" 0\n");
      else
        w.text(" 0 0\n");
    }
    const int64_t n64 = static_cast<int64_t>(n), m64 = static_cast<int64_t>(m);
    w.text("$EndEntities\n$Nodes\n");
    w.text("1 ").integer(n64).text(n ? " 1 " : " 0 ").integer(n64).put('\n');
    w.text("3 1 0 ").integer(n64).put('\n');
    for (int64_t v = 1; v <= n64; ++v) w.integer(v).put('\n');
    for (const Eigen::Vector3d& p : mesh.points)
      w.real(p.x()).put(' ').real(p.y()).put(' ').real(p.z()).put('\n');
    w.text("$EndNodes\n$Elements\n");
    w.integer(static_cast<int64_t>(blocks.size())).put(' ').integer(m64);
    w.text(m ? " 1 " : " 0 ").integer(m64).put('\n');
    i = 0;
    for (size_t e = 0; e < blocks.size(); ++e) {
      size_t j = i;
      while (j < m && order[j].first == blocks[e]) ++j;
      w.text("3 ").integer(static_cast<int64_t>(e) + 1).text(" 5 ");
      w.integer(static_cast<int64_t>(j - i)).put('\n');
      for (; i < j; ++i) {
        const int32_t h = order[i].second;
        w.integer(int64_t{h} + 1);
        for (int32_t v : mesh.hexes[h]) w.put(' ').integer(int64_t{v} + 1);
        w.put('\n');
      }
    }
    w.text("$EndElements\n");
    auto data_header = [&](const std::string& name) {
      w.text("$ElementData\n1\n\"").text(name).text("\"\n1\n0\n3\n0\n1\n").integer(m64).put('\n');
    };
    if (m > 0) {
      for (const HexAttribute& a : mesh.attributes) {
        data_header(a.name);
        for (size_t h = 0; h < m; ++h)
          w.integer(static_cast<int64_t>(h) + 1).put(' ').integer(a.values[h]).put('\n');
        w.text("$EndElementData\n");
      }
      for (const auto& [name, values] : cell_scalars) {
        data_header(name);
        for (size_t h = 0; h < m; ++h)
          w.integer(static_cast<int64_t>(h) + 1).put(' ').real(values[h]).put('\n');
        w.text("$EndElementData\n");
      }
    }
    w.flush();
  });
}

}  // namespace hexrefine::io_detail
