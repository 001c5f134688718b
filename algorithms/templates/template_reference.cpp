/// \file
/// Reference positions of template nodes (see template_reference.hpp for what they are and why
/// they keep the output conformal): the rules, the committed table the library reads, the
/// canonical form of the directional configurations, and the libraries built from a table.
///
/// Sources (facts and formulas only):
/// - M. H. Parrish, "A Selective Approach to Conformal Refinement of Unstructured Hexahedral
///   Meshes", MS thesis, BYU, Appendix E: the templates and their face templates (1-9, 1-4, 1-3);
///   their node positions (thirds, halves) are the thesis', which these replace where they are
///   free to move.
///
/// The table is computed offline by the template optimiser (experiments/cli/template_optimize.hpp,
/// `hexrefine templates --optimize`); nothing here optimises, and nothing changes a library once
/// built: a refinement that should use another table is given another library.

#include "algorithms/templates/template_reference.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "mesh/error.hpp"
#include "mesh/hex_convention.hpp"

namespace hexrefine {

namespace {

/// A standard template's row: its movable nodes are table_template_positions[first .. first +
/// count), in node order; the minima are the report's.
struct TableTemplate {
  TemplateTag tag;
  int32_t first, count;
  double trilinear_min, reference_min, own_rule_min, own_along, own_across;
};
using TablePosition = std::array<double, 3>;
/// A directional configuration's row (ascending (hash0, hash1)): its movable nodes, in the
/// canonical order, are table_configuration_positions[first .. first + count).
using TableConfiguration = TemplateLibrary::ConfigurationRow;

#include "algorithms/templates/template_reference_table.inc"

constexpr double kOnBoundary = 1e-12;

bool is_extreme(double x) {
  return std::abs(x) < kOnBoundary || std::abs(x - 1.0) < kOnBoundary;
}

uint64_t mix(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

using Code = std::array<int64_t, 3>;

Code symmetry_code(const CubeSymmetry& s, const Code& c) {
  Code out{};
  for (int k = 0; k < 3; ++k)
    out[k] = s.flip[k] ? template_param_unit - c[s.axis[k]] : c[s.axis[k]];
  return out;
}

/// The point whose image under s is q.
std::array<double, 3> symmetry_inverse(const CubeSymmetry& s, const std::array<double, 3>& q) {
  std::array<double, 3> p{};
  for (int k = 0; k < 3; ++k) p[s.axis[k]] = s.flip[k] ? 1.0 - q[k] : q[k];
  return p;
}

/// Index of a standard template's tag in template_standard_tags (TemplateLibrary::standard),
/// -1 for a tag with no standard template.
int standard_index(TemplateTag tag) {
  for (size_t i = 0; i < template_standard_tags.size(); ++i)
    if (template_standard_tags[i] == tag) return static_cast<int>(i);
  return -1;
}

/// The mask table of `set` over the templates of `library`, in place.
void library_mask_table_fill(TemplateLibrary& library, TemplateSet set) {
  std::vector<const HexTemplate*> templates;
  for (TemplateTag tag : template_set_tags(set)) templates.push_back(&library.of(tag));
  template_mask_table_fill(templates, library.masks[static_cast<int>(set)]);
}

/// The standard templates of `library` at `table`'s reference positions and their mask tables.
void library_templates_build(TemplateLibrary& library, const TemplateReferenceTable& table) {
  for (size_t i = 0; i < template_standard_tags.size(); ++i)
    library.standard[i] = template_standard_build(template_standard_tags[i], table);
  for (TemplateSet set : {TemplateSet::element_by_element, TemplateSet::sheet_directional})
    library_mask_table_fill(library, set);
}

/// The committed table's rules and standard templates' rows, without its configurations (what
/// the committed library builds its templates from; it reads the configurations in place).
TemplateReferenceTable committed_templates() {
  TemplateReferenceTable table;
  table.rules = template_reference_rules();
  table.adjustment_case_min = table_adjustment_case_min;
  table.max_edge_ratio = table_max_edge_ratio;
  table.configuration_edge_ratio = table_configuration_edge_ratio;
  table.corpus = table_corpus;
  table.corpus_hexes = table_corpus_hexes;
  table.corpus_configurations = table_corpus_configurations;
  table.corpus_worst_min = table_corpus_worst_min;
  for (const TableTemplate& row : table_templates) {
    TemplateReferenceEntry e;
    e.tag = row.tag;
    e.trilinear_min = row.trilinear_min;
    e.reference_min = row.reference_min;
    e.own_rule_min = row.own_rule_min;
    e.own_rule = table.rules;
    e.own_rule.along = row.own_along;
    e.own_rule.across = row.own_across;
    e.interior.assign(table_template_positions.begin() + row.first,
                      table_template_positions.begin() + row.first + row.count);
    table.templates.push_back(std::move(e));
  }
  return table;
}

}  // namespace

ReferenceRules template_reference_rules() {
  ReferenceRules r;
  r.along = table_face_along;
  r.across = table_face_across;
  r.adjustment_along = table_adjustment_along;
  r.adjustment_depth = table_adjustment_depth;
  return r;
}

bool template_node_movable(const HexTemplate& t, size_t i) {
  const TemplateNode& n = t.nodes[i];
  if (n.adjustment_edge >= 0 || n.shared) return false;
  for (double x : n.ref)
    if (!(x > kOnBoundary && x < 1.0 - kOnBoundary)) return false;
  return true;
}

void template_reference_set(HexTemplate& t, const ReferenceRules& rules,
                            std::span<const std::array<double, 3>> interior) {
  auto fail = [&](const std::string& why) {
    throw OperationError(std::string("template ") + template_tag_name(t.tag) +
                         " reference positions: " + why);
  };
  const uint16_t mask = template_split_edges(t);
  std::vector<std::array<double, 3>> reference(t.nodes.size());
  size_t next = 0;
  for (size_t i = 0; i < t.nodes.size(); ++i) {
    const TemplateNode& n = t.nodes[i];
    std::array<double, 3> r = n.ref;
    if (template_node_movable(t, i)) {
      if (!interior.empty()) {
        if (next >= interior.size()) fail("too few interior positions");
        r = interior[next];
      }
      ++next;
    } else if (n.adjustment_edge >= 0) {
      // (x, y, z): x along the adjusted (canonical x-) edge, y and z at depth 5/6 or 1/6.
      r[0] = n.adjustment_index == 0 ? rules.adjustment_along : 1.0 - rules.adjustment_along;
      for (int k = 1; k < 3; ++k) {
        if (std::abs(r[k] - 5.0 / 6.0) < 1e-12)
          r[k] = rules.adjustment_depth;
        else if (std::abs(r[k] - 1.0 / 6.0) < 1e-12)
          r[k] = 1.0 - rules.adjustment_depth;
        else
          fail("an adjustment node off the depths 1/6, 5/6");
      }
    } else if (!n.shared) {
      int extreme = 0, fixed_axis = -1;
      for (int k = 0; k < 3; ++k)
        if (is_extreme(r[k])) {
          ++extreme;
          fixed_axis = k;
        }
      if (extreme == 1) {
        const int lf = 2 * fixed_axis + (r[fixed_axis] > 0.5 ? 1 : 0);
        int split = 0, edge = -1;
        for (int fe : hex_face_edges[lf])
          if ((mask >> fe) & 1) {
            ++split;
            edge = fe;
          }
        if (split == 1) {
          // A 1-4 face: u along the split edge, v away from it.
          const int along = hex_edge_axis[edge];
          const int across = 3 - fixed_axis - along;
          const bool edge_at_zero = hex_corner[hex_edges[edge][0]][across] == 0;
          const bool thirds =
              std::abs(r[along] - 1.0 / 3.0) < 1e-12 || std::abs(r[along] - 2.0 / 3.0) < 1e-12;
          if (!thirds || std::abs(r[across] - 0.5) > 1e-12)
            fail("a 1-4 face node off (1/3 or 2/3, 1/2)");
          r[along] = r[along] < 0.5 ? rules.along : 1.0 - rules.along;
          r[across] = edge_at_zero ? rules.across : 1.0 - rules.across;
        } else if (split != 4) {
          fail("a face node on a face with " + std::to_string(split) + " split edges");
        }
      }
    }
    reference[i] = r;
  }
  if (!interior.empty() && next != interior.size())
    fail(std::to_string(interior.size()) + " interior positions for " + std::to_string(next) +
         " movable nodes");
  t.reference = std::move(reference);
}

void template_reference_from_table(HexTemplate& t, const TemplateReferenceTable& table) {
  for (const TemplateReferenceEntry& row : table.templates) {
    if (row.tag != t.tag) continue;
    if (row.interior.empty()) {
      // No movable node: the face rule alone (every node at its exact position if none).
      template_reference_set(t, table.rules, {});
      size_t movable = 0;
      for (size_t i = 0; i < t.nodes.size(); ++i) movable += template_node_movable(t, i);
      if (movable) throw OperationError("template reference table: no row for movable nodes");
    } else {
      template_reference_set(t, table.rules, row.interior);
    }
    if (t.reference.size() == t.nodes.size()) {
      bool moved = false;
      for (size_t i = 0; i < t.nodes.size(); ++i) moved = moved || t.reference[i] != t.nodes[i].ref;
      if (!moved) t.reference.clear();
    }
    return;
  }
}

TemplateConfiguration template_configuration(const HexTemplate& t) {
  // Exact positions are multiples of 1 / template_param_unit, which rounding recovers; a node
  // nested deeper rounds to the nearest (the same every time it is met).
  const size_t n = t.nodes.size();
  std::vector<Code> code(n);
  for (size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k)
      code[i][k] = std::llround(t.nodes[i].ref[k] * double(template_param_unit));
  // The frame, a function of the node set alone: first the symmetries that make the mapped
  // positions' first and second moments per axis (exact integer sums) least, lexicographically
  // (a handful: O(n) once, then 48 constant-time candidates); among them the one whose
  // order-independent hash of the mapped positions is least (the first on a tie, which only a
  // configuration with a symmetry of its own has, whose images are then the same set).
  using Wide = __int128;
  std::array<Wide, 3> first{}, second{};
  for (const Code& c : code)
    for (int k = 0; k < 3; ++k) {
      first[k] += c[k];
      second[k] += Wide(c[k]) * c[k];
    }
  const Wide count = static_cast<Wide>(n), unit = template_param_unit;
  auto moments = [&](const CubeSymmetry& sym) {
    std::array<Wide, 6> m{};
    for (int k = 0; k < 3; ++k) {
      const int a = sym.axis[k];
      m[k] = sym.flip[k] ? count * unit - first[a] : first[a];
      m[3 + k] = sym.flip[k] ? count * unit * unit - 2 * unit * first[a] + second[a] : second[a];
    }
    return m;
  };
  std::array<Wide, 6> least_moments{};
  std::vector<int> candidates;
  for (int s = 0; s < 48; ++s) {
    const std::array<Wide, 6> m = moments(cube_symmetries()[s]);
    if (candidates.empty() || m < least_moments) {
      least_moments = m;
      candidates.assign(1, s);
    } else if (m == least_moments) {
      candidates.push_back(s);
    }
  }
  TemplateConfiguration out;
  out.symmetry = static_cast<int8_t>(candidates[0]);
  if (candidates.size() > 1) {
    uint64_t least = 0;
    for (size_t k = 0; k < candidates.size(); ++k) {
      uint64_t sum = 0;
      for (const Code& c : code) {
        const Code m = symmetry_code(cube_symmetries()[candidates[k]], c);
        sum += mix(static_cast<uint64_t>(m[0]) ^
                   mix(static_cast<uint64_t>(m[1]) ^ mix(static_cast<uint64_t>(m[2]))));
      }
      if (k == 0 || sum < least) {
        least = sum;
        out.symmetry = static_cast<int8_t>(candidates[k]);
      }
    }
  }
  const CubeSymmetry& s = cube_symmetries()[out.symmetry];
  std::vector<Code> mapped(n);
  for (size_t i = 0; i < n; ++i) mapped[i] = symmetry_code(s, code[i]);
  out.order.resize(n);
  for (size_t i = 0; i < n; ++i) out.order[i] = static_cast<int32_t>(i);
  std::sort(out.order.begin(), out.order.end(),
            [&](int32_t a, int32_t b) { return mapped[a] < mapped[b]; });
  std::vector<int32_t> rank(n);
  for (size_t k = 0; k < n; ++k) rank[out.order[k]] = static_cast<int32_t>(k);
  std::vector<std::array<int32_t, 8>> children;
  for (const auto& c : t.children) {
    std::array<int32_t, 8> r{};
    for (int k = 0; k < 8; ++k) r[k] = rank[c[k]];
    std::sort(r.begin(), r.end());
    children.push_back(r);
  }
  std::sort(children.begin(), children.end());
  for (int h = 0; h < 2; ++h) {
    uint64_t x = mix(0x51ED27A3ull + static_cast<uint64_t>(h)) ^ mix(n);
    for (int32_t i : out.order)
      for (int k = 0; k < 3; ++k) x = mix(x ^ static_cast<uint64_t>(mapped[i][k]));
    x = mix(x ^ children.size());
    for (const auto& c : children)
      for (int32_t r : c) x = mix(x ^ static_cast<uint64_t>(r));
    out.hash[h] = x;
  }
  return out;
}

const HexTemplate& TemplateLibrary::of(TemplateTag tag) const {
  const int i = standard_index(tag);
  if (i < 0) throw OperationError(std::string("no standard template ") + template_tag_name(tag));
  return standard[static_cast<size_t>(i)];
}

std::unique_ptr<const TemplateLibrary> template_library_build(const TemplateReferenceTable& table) {
  // Default-initialised (not value-initialised: the mask tables' empty choices are written
  // once, by their member initialisers).
  std::unique_ptr<TemplateLibrary> library(new TemplateLibrary);
  library_templates_build(*library, table);
  for (const TemplateReferenceConfiguration& c : table.configurations) {
    const auto first = static_cast<int32_t>(library->configuration_position_storage.size());
    library->configuration_row_storage.push_back({c.hash[0], c.hash[1], c.nodes, first,
                                                  static_cast<int32_t>(c.movable.size()),
                                                  c.composed_min, c.reference_min, c.seen});
    library->configuration_position_storage.insert(library->configuration_position_storage.end(),
                                                   c.movable.begin(), c.movable.end());
  }
  library->configuration_rows = library->configuration_row_storage;
  library->configuration_positions = library->configuration_position_storage;
  return library;
}

const TemplateLibrary& template_library_committed() {
  static const std::unique_ptr<const TemplateLibrary> library = [] {
    std::unique_ptr<TemplateLibrary> committed(new TemplateLibrary);
    library_templates_build(*committed, committed_templates());
    committed->configuration_rows = table_configurations;
    committed->configuration_positions = table_configuration_positions;
    return committed;
  }();
  return *library;
}

bool template_reference_from_configurations(HexTemplate& t, const TemplateLibrary& templates) {
  const std::span<const TableConfiguration> table = templates.configuration_rows;
  if (table.empty()) return false;
  const TemplateConfiguration c = template_configuration(t);
  const auto at =
      std::lower_bound(table.begin(), table.end(), c.hash,
                       [](const TableConfiguration& row, const std::array<uint64_t, 2>& h) {
                         return std::array<uint64_t, 2>{row.hash0, row.hash1} < h;
                       });
  if (at == table.end() || std::array<uint64_t, 2>{at->hash0, at->hash1} != c.hash ||
      at->nodes != static_cast<int32_t>(t.nodes.size()))
    return false;
  std::vector<int32_t> movable;
  for (int32_t i : c.order)
    if (template_node_movable(t, static_cast<size_t>(i))) movable.push_back(i);
  if (movable.size() != static_cast<size_t>(at->count)) return false;
  if (t.reference.empty())
    for (const TemplateNode& n : t.nodes) t.reference.push_back(n.ref);
  const CubeSymmetry& s = cube_symmetries()[c.symmetry];
  for (size_t k = 0; k < movable.size(); ++k)
    t.reference[movable[k]] = symmetry_inverse(s, templates.configuration_positions[at->first + k]);
  return true;
}

TemplateReferenceTable template_reference_committed() {
  TemplateReferenceTable table = committed_templates();
  for (const TableConfiguration& row : table_configurations) {
    TemplateReferenceConfiguration c;
    c.hash = {row.hash0, row.hash1};
    c.nodes = row.nodes;
    c.composed_min = row.composed_min;
    c.reference_min = row.reference_min;
    c.seen = row.seen;
    c.movable.assign(table_configuration_positions.begin() + row.first,
                     table_configuration_positions.begin() + row.first + row.count);
    table.configurations.push_back(std::move(c));
  }
  return table;
}

}  // namespace hexrefine
