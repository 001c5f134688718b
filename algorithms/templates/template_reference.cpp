/// \file
/// Reference positions of template nodes (see template_reference.hpp for what they are and why
/// they keep the output conformal), the committed table, and the offline optimisation behind it.
///
/// Sources (facts and formulas only):
/// - M. H. Parrish, "A Selective Approach to Conformal Refinement of Unstructured Hexahedral
///   Meshes", MS thesis, BYU, Appendix E: the templates and their face templates (1-9, 1-4, 1-3);
///   their node positions (thirds, halves) are the thesis', which these replace where they are
///   free to move.
/// - L. A. Freitag, P. Plassmann, IJNME 49 (2000) 109-125: the max-min problem on the quality of
///   the elements around free nodes, solved here on the unit cube once per template by the node
///   optimizer and joint ascent that node placement uses on meshes (node_optimizer.hpp,
///   node_joint_ascent.hpp).
///
/// Steps of the optimisation (template_reference_optimize, `hexrefine templates --optimize`):
///  1. The face rule: the one free choice shared between templates is where the two transition
///     nodes of a 1-4 face go (ReferenceRules), since 1-13, 1-5 and 1-4 (and the directional
///     steps) all carry that face and any two of them may meet across it. The objective: the
///     sorted vector of the three templates' minima, compared lexicographically (1e-7), each
///     template's movable nodes optimised at every trial rule; a rule that stretches a child
///     past max(cap, its edge ratio at the exact positions) is infeasible. A grid over
///     along in [0.28, 0.45], across in [0.42, 0.75] (steps 1/96), then a pattern search from
///     its best (steps 1/192 halved to 1e-4, moves tried in a fixed order, the first that
///     improves kept).
///  2. Each template's movable nodes at that rule (template_reference_optimize_nodes: the node
///     optimizer's sweeps and the joint ascent in rounds, from the exact positions, then a
///     compass search that lifts the other children without lowering the minimum).
///  3. Each template's own best rule, by the same search on it alone: where it is above the
///     shared rule's minimum, the shared face is the constraint that stops the template there.
///  4. Directional configurations (template_reference_add_configurations): the composites a
///     corpus of refinements plans, each distinct configuration (template_configuration: a
///     canonical form under the 48 cube symmetries) optimised once over its movable nodes from
///     the composed positions.

#include "algorithms/templates/template_reference.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <sstream>

#include "algorithms/placement/node_joint_ascent.hpp"
#include "algorithms/placement/node_optimizer.hpp"
#include "algorithms/refiners/refiner.hpp"
#include "mesh/error.hpp"
#include "mesh/generators.hpp"
#include "mesh/hex_convention.hpp"
#include "mesh/quality.hpp"
#include "mesh/selection.hpp"
#include "mesh/topology.hpp"

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
struct TableConfiguration {
  uint64_t hash0, hash1;
  int32_t nodes, first, count;
  double composed_min, reference_min;
  int64_t seen;
};

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

const HexTemplate& standard_template(TemplateTag tag) {
  switch (tag) {
    case TemplateTag::t1_27:
      return template_1_27();
    case TemplateTag::t1_13:
      return template_1_13();
    case TemplateTag::t1_5:
      return template_1_5();
    case TemplateTag::t1_4:
      return template_1_4();
    case TemplateTag::t1_3:
      return template_1_3();
    case TemplateTag::t1_3_adjust1:
      return template_1_3_adjust1();
    case TemplateTag::t1_3_adjust2:
      return template_1_3_adjust2();
    case TemplateTag::t1_9:
      return template_1_9();
    default:
      throw OperationError(std::string("no standard template ") + template_tag_name(tag));
  }
}

constexpr std::array<TemplateTag, 8> standard_tags = {
    TemplateTag::t1_27, TemplateTag::t1_13,        TemplateTag::t1_5,         TemplateTag::t1_4,
    TemplateTag::t1_3,  TemplateTag::t1_3_adjust1, TemplateTag::t1_3_adjust2, TemplateTag::t1_9};

/// The templates whose faces carry the 1-4 face template, whose minima the shared rule trades.
constexpr std::array<TemplateTag, 3> rule_tags = {TemplateTag::t1_13, TemplateTag::t1_5,
                                                  TemplateTag::t1_4};

/// The minimum scaled Jacobian of the children at the reference positions (no validation: a
/// directional configuration with adjusted cells leaves wedges to its neighbours).
double reference_min(const HexTemplate& t) {
  double m = 1;
  for (const auto& c : t.children) {
    HexCorners x;
    for (int k = 0; k < 8; ++k) {
      const auto& r = template_node_reference(t, static_cast<size_t>(c[k]));
      x[k] = Eigen::Vector3d(r[0], r[1], r[2]);
    }
    m = std::min(m, hex_scaled_jacobian(x));
  }
  return m;
}

std::vector<uint8_t> movable_flags(const HexTemplate& t) {
  std::vector<uint8_t> out(t.nodes.size());
  for (size_t i = 0; i < t.nodes.size(); ++i) out[i] = template_node_movable(t, i);
  return out;
}

/// A standard template at `rule`, its movable nodes optimised from their exact positions. `min`:
/// the minimum of its children, or -2 when the rule itself stretches a child past
/// max(cap, its edge ratio at the exact positions) (the rule is then infeasible).
HexTemplate standard_at_rule(TemplateTag tag, const ReferenceRules& rule, double cap, double& min) {
  HexTemplate t = standard_template(tag);
  t.reference.clear();
  std::vector<double> limit;
  for (const auto& c : t.children) {
    HexCorners x;
    for (int k = 0; k < 8; ++k) {
      const auto& r = t.nodes[c[k]].ref;
      x[k] = Eigen::Vector3d(r[0], r[1], r[2]);
    }
    limit.push_back(hex_edge_ratio_cap(x, cap));
  }
  template_reference_set(t, rule, {});
  min = template_reference_optimize_nodes(t, movable_flags(t), cap);
  for (size_t c = 0; c < t.children.size(); ++c) {
    HexCorners x;
    for (int k = 0; k < 8; ++k) {
      const auto& r = t.reference[t.children[c][k]];
      x[k] = Eigen::Vector3d(r[0], r[1], r[2]);
    }
    if (!(hex_edge_ratio(x) <= limit[c])) min = -2;
  }
  return t;
}

/// True if `a` (ascending minima) beats `b` lexicographically by more than the tolerance.
bool minima_better(const std::vector<double>& a, const std::vector<double>& b) {
  for (size_t i = 0; i < a.size() && i < b.size(); ++i) {
    if (a[i] > b[i] + 1e-7) return true;
    if (a[i] < b[i] - 1e-7) return false;
  }
  return false;
}

/// Grid and pattern search of the face rule (along, across) maximising the ascending minima of
/// `tags`, the other rules as in `start`.
ReferenceRules rule_search(std::span<const TemplateTag> tags, const ReferenceRules& start,
                           double cap, std::vector<double>& best) {
  auto evaluate = [&](const ReferenceRules& r) {
    std::vector<double> mins;
    for (TemplateTag tag : tags) {
      double m;
      standard_at_rule(tag, r, cap, m);
      mins.push_back(m);
    }
    std::sort(mins.begin(), mins.end());
    return mins;
  };
  // A grid first (the objective has many local optima: each template's minimum is held by
  // different children in different parts of the plane), then a pattern search from its best.
  ReferenceRules rule = start;
  best = evaluate(rule);
  for (int i = 0; i <= 16; ++i)
    for (int j = 0; j <= 32; ++j) {
      ReferenceRules trial = rule;
      trial.along = 0.28 + i / 96.0;
      trial.across = 0.42 + j / 96.0;
      const std::vector<double> mins = evaluate(trial);
      if (!minima_better(mins, best)) continue;
      rule = trial;
      best = mins;
    }
  for (double step = 1.0 / 192.0; step > 1e-4;) {
    bool improved = false;
    for (const auto& [da, dc] :
         {std::pair{1.0, 0.0}, std::pair{-1.0, 0.0}, std::pair{0.0, 1.0}, std::pair{0.0, -1.0}}) {
      ReferenceRules trial = rule;
      trial.along += da * step;
      trial.across += dc * step;
      if (!(trial.along > 0.05 && trial.along < 0.45 && trial.across > 0.05 && trial.across < 0.95))
        continue;
      const std::vector<double> mins = evaluate(trial);
      if (!minima_better(mins, best)) continue;
      rule = trial;
      best = mins;
      improved = true;
      break;
    }
    if (!improved) step /= 2;
  }
  return rule;
}

std::string number(double x) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.17g", x);
  return buffer;
}

std::string position(const std::array<double, 3>& p) {
  return "{" + number(p[0]) + ", " + number(p[1]) + ", " + number(p[2]) + "}";
}

const char* tag_enumerator(TemplateTag tag) {
  switch (tag) {
    case TemplateTag::t1_27:
      return "t1_27";
    case TemplateTag::t1_13:
      return "t1_13";
    case TemplateTag::t1_5:
      return "t1_5";
    case TemplateTag::t1_4:
      return "t1_4";
    case TemplateTag::t1_3:
      return "t1_3";
    case TemplateTag::t1_3_adjust1:
      return "t1_3_adjust1";
    case TemplateTag::t1_3_adjust2:
      return "t1_3_adjust2";
    case TemplateTag::t1_9:
      return "t1_9";
    default:
      return "untouched";
  }
}

/// The directional configurations the library looks up: the committed table's, until
/// template_reference_install replaces them.
std::vector<TemplateReferenceConfiguration>& active_configurations() {
  static std::vector<TemplateReferenceConfiguration> table = [] {
    std::vector<TemplateReferenceConfiguration> out;
    for (const TableConfiguration& row : table_configurations) {
      TemplateReferenceConfiguration c;
      c.hash = {row.hash0, row.hash1};
      c.nodes = row.nodes;
      c.composed_min = row.composed_min;
      c.reference_min = row.reference_min;
      c.seen = row.seen;
      c.movable.assign(table_configuration_positions.begin() + row.first,
                       table_configuration_positions.begin() + row.first + row.count);
      out.push_back(std::move(c));
    }
    return out;
  }();
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

void template_reference_from_table(HexTemplate& t) {
  for (const TableTemplate& row : table_templates) {
    if (row.tag != t.tag) continue;
    std::vector<std::array<double, 3>> interior(
        table_template_positions.begin() + row.first,
        table_template_positions.begin() + row.first + row.count);
    if (interior.empty()) {
      // No movable node: the face rule alone (every node at its exact position if none).
      template_reference_set(t, template_reference_rules(), {});
      size_t movable = 0;
      for (size_t i = 0; i < t.nodes.size(); ++i) movable += template_node_movable(t, i);
      if (movable) throw OperationError("template reference table: no row for movable nodes");
    } else {
      template_reference_set(t, template_reference_rules(), interior);
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

bool template_reference_from_configurations(HexTemplate& t) {
  const std::vector<TemplateReferenceConfiguration>& table = active_configurations();
  if (table.empty()) return false;
  const TemplateConfiguration c = template_configuration(t);
  const auto at = std::lower_bound(table.begin(), table.end(), c.hash,
                                   [](const TemplateReferenceConfiguration& row,
                                      const std::array<uint64_t, 2>& h) { return row.hash < h; });
  if (at == table.end() || at->hash != c.hash || at->nodes != static_cast<int32_t>(t.nodes.size()))
    return false;
  std::vector<int32_t> movable;
  for (int32_t i : c.order)
    if (template_node_movable(t, static_cast<size_t>(i))) movable.push_back(i);
  if (movable.size() != at->movable.size()) return false;
  if (t.reference.empty())
    for (const TemplateNode& n : t.nodes) t.reference.push_back(n.ref);
  const CubeSymmetry& s = cube_symmetries()[c.symmetry];
  for (size_t k = 0; k < movable.size(); ++k)
    t.reference[movable[k]] = symmetry_inverse(s, at->movable[k]);
  return true;
}

namespace {

/// KS soft minimum of `samples` (beta 30): a smooth lower bound of their minimum that every
/// sample near the bottom raises.
double soft_minimum(const std::vector<double>& samples) {
  constexpr double beta = 30;
  double m = 1;
  for (double x : samples) m = std::min(m, x);
  double sum = 0;
  for (double x : samples) sum += std::exp(-beta * (x - m));
  return m - std::log(sum) / beta;
}

/// Second phase of template_reference_optimize_nodes: among the positions that keep every child
/// at or above `floor` (the max-min phase's minimum) and within its edge-ratio cap, a compass
/// search (each coordinate of each movable node by +-step, step 1/48 halved to 1e-7, a move kept
/// when it raises the soft minimum of every scaled-Jacobian sample of every child). The max-min
/// optimum is rarely unique: where fixed nodes hold the worst children at a bound (1-5's end
/// children at 1/sqrt(3)), the free nodes may reach it from positions that crush the other
/// children (1-5's two interior nodes drawn together, edge ratio 16); this lifts those.
void lift_above_floor(HexMesh& cube, const std::vector<int32_t>& nodes,
                      const std::vector<double>& cap, double floor) {
  std::vector<double> samples;
  auto evaluate = [&](double& value) {
    samples.clear();
    for (int32_t h = 0; h < cube.hex_count(); ++h) {
      const HexCorners x = hex_points(cube, h);
      std::array<double, 9> s;
      hex_scaled_jacobian_samples(x, s);
      for (double v : s) {
        if (!(v >= floor)) return false;
        samples.push_back(v);
      }
      if (!(hex_edge_ratio(x) <= cap[h])) return false;
    }
    value = soft_minimum(samples);
    return true;
  };
  double best;
  if (!evaluate(best)) return;
  for (double step = 1.0 / 48.0; step > 1e-7;) {
    bool improved = false;
    for (int32_t node : nodes)
      for (int k = 0; k < 3; ++k)
        for (double sign : {1.0, -1.0}) {
          double& x = cube.points[node][k];
          const double keep = x;
          x = keep + sign * step;
          double value;
          if (x > 1e-6 && x < 1 - 1e-6 && evaluate(value) && value > best + 1e-13) {
            best = value;
            improved = true;
          } else {
            x = keep;
          }
        }
    if (!improved) step /= 2;
  }
}

}  // namespace

double template_reference_optimize_nodes(HexTemplate& t, const std::vector<uint8_t>& movable,
                                         double max_edge_ratio) {
  HexMesh cube;
  for (size_t i = 0; i < t.nodes.size(); ++i) {
    const auto& r = template_node_reference(t, i);
    cube.points.emplace_back(r[0], r[1], r[2]);
  }
  std::vector<int32_t> all;
  for (const auto& c : t.children) {
    HexCell cell;
    for (int k = 0; k < 8; ++k) cell[k] = c[k];
    all.push_back(cube.hex_count());
    cube.hexes.push_back(cell);
  }
  auto cube_min = [&] {
    double m = 1;
    for (int32_t h : all) m = std::min(m, hex_scaled_jacobian(hex_points(cube, h)));
    return m;
  };
  NodeProblem problem;
  for (size_t i = 0; i < t.nodes.size(); ++i)
    if (movable.at(i)) {
      problem.nodes.push_back(static_cast<int32_t>(i));
      problem.slides.push_back({});
    }
  if (!problem.nodes.empty()) {
    node_problem_connect(problem, cube, all);
    NodeOptimizerOptions sweeps;
    sweeps.keep_positive = false;
    sweeps.max_sweeps = 100;
    sweeps.max_edge_ratio = max_edge_ratio;
    JointAscentOptions joint;
    joint.max_iterations = 300;
    joint.stall_iterations = 50;
    joint.band = 2;
    joint.max_seeds = std::numeric_limits<int32_t>::max();
    joint.max_edge_ratio = max_edge_ratio;
    // Per child: the edge ratio no result may exceed (from the given start).
    std::vector<double> cap;
    for (int32_t h : all) cap.push_back(hex_edge_ratio_cap(hex_points(cube, h), max_edge_ratio));
    // (A child at its cap may creep by the optimizer's rounding allowance, 1e-9 per call.)
    auto feasible = [&] {
      for (int32_t h : all)
        if (!(hex_edge_ratio(hex_points(cube, h)) <= cap[h] * (1 + 1e-6))) return false;
      return true;
    };
    // Local ascents from the given start and from 12 perturbations of it (amplitudes 0.03,
    // 0.08, 0.15 of the cube, a fixed pseudo-random sequence): one start's ascent stops where
    // the edge-ratio caps pin it (1-5 from the exact positions: 0.40 where 0.577 is reachable).
    const std::vector<Eigen::Vector3d> given = cube.points;
    std::vector<Eigen::Vector3d> best_points = given;
    double best_min = -2;
    for (int start = 0; start < 13; ++start) {
      cube.points = given;
      if (start > 0) {
        const double amplitude = std::array{0.03, 0.08, 0.15}[start % 3];
        for (int32_t node : problem.nodes)
          for (int k = 0; k < 3; ++k) {
            const uint64_t r = mix(static_cast<uint64_t>(start) * 1000003u +
                                   static_cast<uint64_t>(node) * 3u + static_cast<uint64_t>(k));
            const double unit = double(r >> 11) * 0x1.0p-53 * 2.0 - 1.0;
            cube.points[node][k] = std::clamp(given[node][k] + amplitude * unit, 0.02, 0.98);
          }
      }
      double previous = cube_min();
      for (int round = 0; round < 20; ++round) {
        nodes_sweep_and_ascend(cube, problem, sweeps, joint);
        const double now = cube_min();
        const bool rising = now > previous + 1e-9;
        previous = std::max(previous, now);
        if (!rising) break;
      }
      const double now = cube_min();
      if (feasible() && now > best_min + 1e-9) {
        best_min = now;
        best_points = cube.points;
      }
    }
    cube.points = best_points;
    if (best_min > -2) lift_above_floor(cube, problem.nodes, cap, cube_min());
  }
  t.reference.resize(t.nodes.size());
  for (size_t i = 0; i < t.nodes.size(); ++i)
    t.reference[i] = {cube.points[i][0], cube.points[i][1], cube.points[i][2]};
  return cube_min();
}

namespace {

/// The adjustment rule's objective: the minimum scaled Jacobian of the L-shaped case (the
/// thesis' G-1 on a 4 x 4 x 4 brick of unit cubes: the hexes on faces x = 0 and z = 0 refined)
/// at the reference positions of `table` (installed), its directional configurations optimised
/// on the unit cube first (added to `table`'s and installed).
double adjustment_case_min(TemplateReferenceTable& table) {
  BrickParams p;
  p.dims = {4, 4, 4};
  p.size = {4, 4, 4};
  const HexMesh mesh = generate_brick(p);
  const HexTopology topology = topology_build(mesh);
  Targets targets{select_hexes(mesh, topology, {"boundary:-1,0,0", "boundary:0,0,-1"}).hexes};
  RefineOptions options;
  options.placement.method = PlacementMethod::reference;
  options.placement.configuration_table = false;
  RefineStats stats;
  RefinementPlan plan =
      refine_method("selective").plan(mesh, topology, targets.hexes, options, stats);
  std::vector<const HexTemplate*> composites;
  for (const auto& t : plan.owned) composites.push_back(t.get());
  TemplateReferenceTable with = table;
  with.configurations.clear();
  template_reference_add_configurations(with, composites);
  template_reference_install(with);
  options.placement.configuration_table = true;
  const double min =
      mesh_min_scaled_jacobian(refine(refine_method("selective"), mesh, targets, options).mesh);
  table.configurations = with.configurations;
  return min;
}

}  // namespace

TemplateReferenceTable template_reference_optimize(double max_edge_ratio) {
  TemplateReferenceTable table;
  table.max_edge_ratio = max_edge_ratio;
  std::vector<double> shared;
  table.rules = rule_search(rule_tags, ReferenceRules{}, max_edge_ratio, shared);
  auto entries = [&] {
    table.templates.clear();
    for (TemplateTag tag : standard_tags) {
      TemplateReferenceEntry e;
      e.tag = tag;
      HexTemplate exact = standard_template(tag);
      exact.reference.clear();
      e.trilinear_min = template_validate(exact);
      const HexTemplate t = standard_at_rule(tag, table.rules, max_edge_ratio, e.reference_min);
      for (size_t i = 0; i < t.nodes.size(); ++i)
        if (template_node_movable(t, i)) e.interior.push_back(t.reference[i]);
      e.own_rule = table.rules;
      e.own_rule_min = e.reference_min;
      table.templates.push_back(std::move(e));
    }
  };
  entries();
  // The adjustment rule: a grid (along from 1/3 to the face rule's, depth 0.6 to 0.95), each
  // point's L-shaped case with its configurations optimised; the first best kept.
  double best = -2;
  ReferenceRules chosen = table.rules;
  for (int i = 0; i <= 4; ++i)
    for (int j = 0; j <= 14; ++j) {
      TemplateReferenceTable trial = table;
      trial.rules.adjustment_along = 1.0 / 3.0 + i * (table.rules.along - 1.0 / 3.0) / 4.0;
      trial.rules.adjustment_depth = 0.6 + j * 0.025;
      for (TemplateReferenceEntry& e : trial.templates)
        if (e.tag == TemplateTag::t1_3_adjust1 || e.tag == TemplateTag::t1_3_adjust2) {
          HexTemplate t = standard_template(e.tag);
          t.reference.clear();
          template_reference_set(t, trial.rules, {});
          e.reference_min = template_validate(t, TemplatePositions::reference);
        }
      const double m = adjustment_case_min(trial);
      if (m > best + 1e-9) {
        best = m;
        chosen = trial.rules;
      }
    }
  table.rules = chosen;
  table.adjustment_case_min = best;
  entries();
  // Each template's own best face rule: the bound the shared rule stops it at.
  for (TemplateReferenceEntry& e : table.templates) {
    if (std::find(rule_tags.begin(), rule_tags.end(), e.tag) == rule_tags.end()) continue;
    std::vector<double> own;
    const std::array<TemplateTag, 1> alone = {e.tag};
    const ReferenceRules r = rule_search(alone, table.rules, max_edge_ratio, own);
    if (own[0] > e.reference_min) {
      e.own_rule = r;
      e.own_rule_min = own[0];
    }
  }
  template_reference_install(table);
  return table;
}

void template_reference_add_configurations(TemplateReferenceTable& table,
                                           std::span<const HexTemplate* const> composites,
                                           std::span<const int64_t> counts) {
  std::map<std::array<uint64_t, 2>, size_t> index;
  for (size_t i = 0; i < table.configurations.size(); ++i) index[table.configurations[i].hash] = i;
  // The cap: the most stretched child the thesis' positions give.
  for (const HexTemplate* composite : composites)
    for (const auto& c : composite->children) {
      HexCorners x;
      for (int k = 0; k < 8; ++k) {
        const auto& r = composite->nodes[c[k]].ref;
        x[k] = Eigen::Vector3d(r[0], r[1], r[2]);
      }
      table.configuration_edge_ratio = std::max(table.configuration_edge_ratio, hex_edge_ratio(x));
    }
  for (size_t k = 0; k < composites.size(); ++k) {
    const HexTemplate* composite = composites[k];
    const int64_t count = counts.empty() ? 1 : counts[k];
    if (composite->tag != TemplateTag::directional && composite->tag != TemplateTag::sheet)
      continue;
    table.corpus_hexes += count;
    const TemplateConfiguration c = template_configuration(*composite);
    const auto [it, inserted] = index.try_emplace(c.hash, table.configurations.size());
    if (!inserted) {
      table.configurations[it->second].seen += count;
      continue;
    }
    ++table.corpus_configurations;
    TemplateReferenceConfiguration out;
    out.hash = c.hash;
    out.nodes = static_cast<int32_t>(composite->nodes.size());
    out.seen = count;
    HexTemplate t = *composite;
    out.composed_min = reference_min(t);
    const std::vector<uint8_t> movable = movable_flags(t);
    out.reference_min =
        template_reference_optimize_nodes(t, movable, table.configuration_edge_ratio);
    const CubeSymmetry& s = cube_symmetries()[c.symmetry];
    for (int32_t i : c.order)
      if (movable[i]) out.movable.push_back(cube_symmetry_apply(s, t.reference[i]));
    table.configurations.push_back(std::move(out));
  }
  // Only the configurations whose optimisation raised the minimum need a row.
  for (const TemplateReferenceConfiguration& c : table.configurations) {
    const bool raised = c.reference_min > c.composed_min + 1e-9 && !c.movable.empty();
    table.corpus_worst_min =
        std::min(table.corpus_worst_min, raised ? c.reference_min : c.composed_min);
  }
  std::erase_if(table.configurations, [](const TemplateReferenceConfiguration& c) {
    return !(c.reference_min > c.composed_min + 1e-9) || c.movable.empty();
  });
  std::sort(table.configurations.begin(), table.configurations.end(),
            [](const auto& a, const auto& b) { return a.hash < b.hash; });
}

std::string template_reference_table_source(const TemplateReferenceTable& table) {
  std::ostringstream o;
  o << "// Generated by `hexrefine templates --optimize OUT` "
       "(algorithms/templates/template_reference.cpp,\n"
       "// template_reference_optimize): do not edit. The rules and the standard templates'\n"
       "// movable nodes maximise the minimum scaled Jacobian on the unit cube under an "
       "edge-ratio\n"
       "// cap; the directional configurations were collected from: "
    << table.corpus << ".\n";
  o << "constexpr double table_face_along = " << number(table.rules.along) << ";\n";
  o << "constexpr double table_face_across = " << number(table.rules.across) << ";\n";
  o << "constexpr double table_adjustment_along = " << number(table.rules.adjustment_along)
    << ";\n";
  o << "constexpr double table_adjustment_depth = " << number(table.rules.adjustment_depth)
    << ";\n";
  o << "constexpr double table_adjustment_case_min = " << number(table.adjustment_case_min)
    << ";\n";
  o << "constexpr double table_max_edge_ratio = " << number(table.max_edge_ratio) << ";\n";
  o << "constexpr double table_configuration_edge_ratio = "
    << number(table.configuration_edge_ratio) << ";\n";
  o << "constexpr const char* table_corpus = \"" << table.corpus << "\";\n";
  o << "constexpr int64_t table_corpus_hexes = " << table.corpus_hexes << ";\n";
  o << "constexpr int64_t table_corpus_configurations = " << table.corpus_configurations << ";\n";
  o << "constexpr double table_corpus_worst_min = " << number(table.corpus_worst_min) << ";\n";
  std::vector<std::array<double, 3>> positions;
  o << "constexpr std::array<TableTemplate, " << table.templates.size() << "> table_templates{{\n";
  for (const TemplateReferenceEntry& e : table.templates) {
    o << "    {TemplateTag::" << tag_enumerator(e.tag) << ", " << positions.size() << ", "
      << e.interior.size() << ", " << number(e.trilinear_min) << ", " << number(e.reference_min)
      << ", " << number(e.own_rule_min) << ", " << number(e.own_rule.along) << ", "
      << number(e.own_rule.across) << "},\n";
    positions.insert(positions.end(), e.interior.begin(), e.interior.end());
  }
  o << "}};\n";
  o << "constexpr std::array<TablePosition, " << positions.size()
    << "> table_template_positions{{\n";
  for (const auto& p : positions) o << "    " << position(p) << ",\n";
  o << "}};\n";
  positions.clear();
  o << "constexpr std::array<TableConfiguration, " << table.configurations.size()
    << "> table_configurations{{\n";
  for (const TemplateReferenceConfiguration& c : table.configurations) {
    o << "    {" << c.hash[0] << "ull, " << c.hash[1] << "ull, " << c.nodes << ", "
      << positions.size() << ", " << c.movable.size() << ", " << number(c.composed_min) << ", "
      << number(c.reference_min) << ", " << c.seen << "},\n";
    positions.insert(positions.end(), c.movable.begin(), c.movable.end());
  }
  o << "}};\n";
  o << "constexpr std::array<TablePosition, " << positions.size()
    << "> table_configuration_positions{{\n";
  for (const auto& p : positions) o << "    " << position(p) << ",\n";
  o << "}};\n";
  return o.str();
}

TemplateReferenceTable template_reference_committed() {
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

void template_reference_install(const TemplateReferenceTable& table) {
  for (const TemplateReferenceEntry& e : table.templates) {
    HexTemplate t = standard_template(e.tag);
    t.reference.clear();
    template_reference_set(t, table.rules, e.interior);
    bool moved = false;
    for (size_t i = 0; i < t.nodes.size(); ++i) moved = moved || t.reference[i] != t.nodes[i].ref;
    if (!moved) t.reference.clear();
    template_set_reference(e.tag, std::move(t.reference));
  }
  active_configurations() = table.configurations;
}

}  // namespace hexrefine
