/// \file
/// Abaqus input files (.inp), flat (no *PART/*INSTANCE assembly semantics: every *NODE and
/// *ELEMENT block is read into one mesh). C3D8 (any suffix: R, I, H, T..., also DC3D8) is the
/// linear hex, whose node order is VTK's: nodes 1-4 one face, 5-8 the opposite face with 5 above
/// 1 (checked against abaqus_hex_2x2x2.inp, whose hexes all have positive volume in this order).
/// Other 3D continuum elements (names containing "3D": C3D4, C3D6, C3D20R...) are refused;
/// shells, beams, masses and the like are skipped. Element sets named BLOCK_<integer> give
/// block_id (case-insensitive); hexes in none get 0. *INCLUDE is refused; other keywords are
/// skipped. The format has no counts, so a file cut at a line end reads as a smaller mesh.

#include <algorithm>

#include "mesh/atomic_file.hpp"
#include "mesh/io.hpp"
#include "mesh/io_text.hpp"

namespace hexrefine::io_detail {

namespace {

std::string upper(std::string_view s) {
  std::string u(s);
  for (char& c : u)
    if (c >= 'a' && c <= 'z') c = static_cast<char>(c - 32);
  return u;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
    s.remove_suffix(1);
  return s;
}

/// Splits at commas into `out` (trimmed fields; a trailing comma gives no empty last field).
/// The caller reuses `out` from line to line, so data lines allocate nothing.
void split_commas(std::string_view line, std::vector<std::string_view>& out) {
  out.clear();
  size_t start = 0;
  while (start <= line.size()) {
    const size_t comma = line.find(',', start);
    const size_t end = comma == std::string_view::npos ? line.size() : comma;
    const std::string_view f = trim(line.substr(start, end - start));
    if (!(comma == std::string_view::npos && f.empty() && !out.empty())) out.push_back(f);
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
}

/// Value of keyword parameter `key` (e.g. TYPE) in a keyword line's fields, "" if absent.
std::string keyword_parameter(const std::vector<std::string_view>& fields, std::string_view key) {
  for (size_t i = 1; i < fields.size(); ++i) {
    const size_t eq = fields[i].find('=');
    if (eq == std::string_view::npos) continue;
    if (upper(trim(fields[i].substr(0, eq))) == key)
      return std::string(trim(fields[i].substr(eq + 1)));
  }
  return "";
}

bool keyword_flag(const std::vector<std::string_view>& fields, std::string_view key) {
  for (size_t i = 1; i < fields.size(); ++i)
    if (upper(fields[i]) == key) return true;
  return false;
}

/// BLOCK_<n> -> true and n.
bool block_of_set_name(const std::string& name, int32_t& block) {
  const std::string u = upper(name);
  if (u.rfind("BLOCK_", 0) != 0) return false;
  int64_t v = 0;
  if (!TextCursor::parse_integer(std::string_view(u).substr(6), v) || v < INT32_MIN ||
      v > INT32_MAX)
    return false;
  block = static_cast<int32_t>(v);
  return true;
}

struct AbaqusSet {
  std::string name;
  int32_t block;
  std::vector<int64_t> element_ids;
  std::vector<int64_t> lines;
};

}  // namespace

HexMesh abaqus_read(const std::string& path, std::string_view text) {
  TextCursor in(path, text);
  HexMesh mesh;
  std::vector<int64_t> node_ids, node_lines;
  std::vector<int64_t> element_ids, element_lines;
  std::vector<std::array<int64_t, 8>> element_nodes;
  std::vector<int32_t> element_block;
  std::vector<AbaqusSet> sets;
  enum class Mode { skip, node, hex, other_element, elset } mode = Mode::skip;
  int32_t current_block = 0;
  bool generate = false;
  int64_t generated = 0;  // ids listed by GENERATE rows so far
  const int64_t generate_limit = 4 * static_cast<int64_t>(text.size()) + 1024;
  bool saw_keyword = false;
  std::vector<std::string_view> fields, f;  // reused for every line
  while (in.remaining() > 0) {
    const int64_t line_no = in.line();
    std::string_view line = trim(in.rest_of_line());
    auto fail_line = [&](const std::string& message) {
      throw InputError(error_at(path, line_no, message));
    };
    if (line.empty() || line.substr(0, 2) == "**") continue;
    if (line[0] == '*') {
      saw_keyword = true;
      split_commas(line.substr(1), fields);
      const std::string key = upper(fields[0]);
      mode = Mode::skip;
      if (key == "INCLUDE")
        fail_line("*INCLUDE is not supported (skipping it would silently drop part of the mesh)");
      if (key == "NODE") {
        mode = Mode::node;
      } else if (key == "ELEMENT") {
        const std::string type = upper(keyword_parameter(fields, "TYPE"));
        if (type.empty()) fail_line("*ELEMENT needs TYPE=...");
        const size_t at = type.find("C3D8");
        const bool hex = (at == 0 || (at == 1 && type[0] == 'D')) &&
                         std::all_of(type.begin() + at + 4, type.end(),
                                     [](char c) { return c >= 'A' && c <= 'Z'; });
        if (!hex && type.find("3D") != std::string::npos)
          fail_line(
              "element type " + type +
              " is a volume element that is not a linear hexahedron (only C3D8 is supported)");
        mode = hex ? Mode::hex : Mode::other_element;
        const std::string set = keyword_parameter(fields, "ELSET");
        current_block = 0;
        if (!set.empty()) block_of_set_name(set, current_block);
      } else if (key == "ELSET") {
        const std::string name = keyword_parameter(fields, "ELSET");
        if (name.empty()) fail_line("*ELSET needs ELSET=name");
        int32_t block = 0;
        if (block_of_set_name(name, block)) {
          mode = Mode::elset;
          sets.push_back({name, block, {}, {}});
          generate = keyword_flag(fields, "GENERATE");
        }
      }
      continue;
    }
    if (mode == Mode::skip) continue;
    // Data lines; element rows may continue on the next line after a trailing comma.
    std::string joined;
    if ((mode == Mode::hex || mode == Mode::other_element) && line.back() == ',') {
      joined = line;
      while (in.remaining() > 0 && !joined.empty() && joined.back() == ',') {
        const std::string_view next = trim(in.rest_of_line());
        if (!next.empty() && next[0] == '*') in.fail("element row ends with ',' before a keyword");
        joined += next;
      }
      line = joined;
    }
    split_commas(line, f);
    auto integer = [&](std::string_view t, const char* what) {
      int64_t v = 0;
      if (!TextCursor::parse_integer(t, v))
        throw InputError(error_at(
            path, line_no,
            std::string("expected ") + what + " (an integer), got '" + TextCursor::shown(t) + "'"));
      return v;
    };
    if (mode == Mode::node) {
      if (f.size() < 4)
        throw InputError(error_at(
            path, line_no, "node row needs id, x, y, z (" + std::to_string(f.size()) + " fields)"));
      node_ids.push_back(integer(f[0], "node id"));
      node_lines.push_back(line_no);
      Eigen::Vector3d p;
      for (int k = 0; k < 3; ++k)
        if (!TextCursor::parse_real(f[1 + k], p[k]))
          throw InputError(error_at(
              path, line_no,
              "expected a finite node coordinate, got '" + TextCursor::shown(f[1 + k]) + "'"));
      mesh.points.push_back(p);
    } else if (mode == Mode::hex) {
      if (f.size() != 9)
        throw InputError(error_at(path, line_no,
                                  "C3D8 row needs an element id and 8 node ids, got " +
                                      std::to_string(f.size()) + " fields"));
      element_ids.push_back(integer(f[0], "element id"));
      element_lines.push_back(line_no);
      std::array<int64_t, 8> nodes;
      for (int k = 0; k < 8; ++k) nodes[k] = integer(f[1 + k], "node id");
      element_nodes.push_back(nodes);
      element_block.push_back(current_block);
    } else if (mode == Mode::elset) {
      AbaqusSet& s = sets.back();
      if (generate) {
        if (f.size() < 2 || f.size() > 3)
          throw InputError(error_at(path, line_no, "ELSET GENERATE row needs start, end[, step]"));
        const int64_t a = integer(f[0], "first element id"), b = integer(f[1], "last element id");
        const int64_t step = f.size() == 3 ? integer(f[2], "step") : 1;
        if (step < 1 || b < a || (b - a) / step > static_cast<int64_t>(text.size()))
          throw InputError(error_at(path, line_no, "bad ELSET GENERATE range"));
        // Every id must name a hex row of the file, so all sets together cannot sensibly list
        // more ids than a few per byte; without this bound many short GENERATE rows would
        // allocate quadratically in the file size.
        generated += (b - a) / step + 1;
        if (generated > generate_limit)
          throw InputError(error_at(path, line_no,
                                    "ELSET GENERATE rows list " + std::to_string(generated) +
                                        " element ids, more than the file (" +
                                        std::to_string(text.size()) + " bytes) can define"));
        for (int64_t e = a; e <= b; e += step)
          s.element_ids.push_back(e), s.lines.push_back(line_no);
      } else {
        for (std::string_view t : f)
          if (!t.empty())
            s.element_ids.push_back(integer(t, "element id")), s.lines.push_back(line_no);
      }
    }
  }
  if (!saw_keyword) in.fail("no Abaqus keyword line (*NODE, *ELEMENT) found");
  if (items_sort_by_permutation_ids(mesh.points, node_ids)) node_lines.clear();
  IdIndex nodes;
  if (const int64_t bad = nodes.build(node_ids); bad >= 0)
    throw InputError(
        error_at(path, node_lines[bad],
                 "node id " + std::to_string(node_ids[bad]) + " repeated or not positive"));
  IdIndex elements;
  if (const int64_t bad = elements.build(element_ids); bad >= 0)
    throw InputError(
        error_at(path, element_lines[bad],
                 "element id " + std::to_string(element_ids[bad]) + " repeated or not positive"));
  if (element_nodes.size() > INT32_MAX || mesh.points.size() > INT32_MAX)
    in.fail("too many nodes or elements");
  mesh.hexes.resize(element_nodes.size());
  for (size_t e = 0; e < element_nodes.size(); ++e)
    for (int k = 0; k < 8; ++k) {
      const int64_t i = nodes.find(element_nodes[e][k]);
      if (i < 0)
        throw InputError(error_at(path, element_lines[e],
                                  "element " + std::to_string(element_ids[e]) +
                                      " refers to undefined node " +
                                      std::to_string(element_nodes[e][k])));
      mesh.hexes[e][k] = static_cast<int32_t>(i);
    }
  for (const AbaqusSet& s : sets)
    for (size_t i = 0; i < s.element_ids.size(); ++i) {
      const int64_t e = elements.find(s.element_ids[i]);
      if (e < 0)
        throw InputError(error_at(path, s.lines[i],
                                  "element set " + s.name + " names undefined hex element " +
                                      std::to_string(s.element_ids[i])));
      element_block[e] = s.block;
    }
  mesh.attributes.push_back({std::string(attribute_block_id), std::move(element_block)});
  return mesh;
}

void abaqus_write(const std::string& path, const HexMesh& mesh) {
  const std::vector<int32_t>* block = mesh_find_attribute(mesh, attribute_block_id);
  file_write_atomically(path, [&](std::ostream& out) {
    TextWriter w(out);
    w.text("*HEADING\nhexrefine mesh\n*NODE\n");
    for (size_t i = 0; i < mesh.points.size(); ++i) {
      const Eigen::Vector3d& p = mesh.points[i];
      w.integer(static_cast<int64_t>(i) + 1).text(", ").real(p.x()).text(", ").real(p.y());
      w.text(", ").real(p.z()).put('\n');
    }
    w.text("*ELEMENT, TYPE=C3D8\n");
    for (size_t h = 0; h < mesh.hexes.size(); ++h) {
      w.integer(static_cast<int64_t>(h) + 1);
      for (int32_t v : mesh.hexes[h]) w.text(", ").integer(int64_t{v} + 1);
      w.put('\n');
    }
    if (block != nullptr) {
      const HexBlocks groups = hex_blocks_group(mesh, 0);
      for (size_t b = 0; b < groups.ids.size(); ++b) {
        w.text("*ELSET, ELSET=BLOCK_").integer(groups.ids[b]).put('\n');
        for (size_t i = groups.starts[b]; i < groups.starts[b + 1]; ++i) {
          const bool last = i + 1 == groups.starts[b + 1];
          w.integer(int64_t{groups.order[i]} + 1);
          w.text((last || (i % 16) == 15) ? "\n" : ", ");
        }
      }
    }
    w.flush();
  });
}

}  // namespace hexrefine::io_detail
