/// \file
/// The template optimiser (template_optimize.hpp): the offline computation of the table of
/// reference positions and the writer of its C++ source.
///
/// Sources (facts and formulas only):
/// - M. H. Parrish, "A Selective Approach to Conformal Refinement of Unstructured Hexahedral
///   Meshes", MS thesis, BYU, Appendix E: the templates and their face templates (1-9, 1-4, 1-3).
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
///  3. The adjustment rule (where the adjusted 1-3 templates' adjustment nodes go): a grid, each
///     point judged by the minimum of the L-shaped case refined at the reference positions, its
///     directional configurations optimised first (adjustment_rule_search); then step 2 again.
///  4. Each template's own best rule, by the same search on it alone: where it is above the
///     shared rule's minimum, the shared face is the constraint that stops the template there.
///  5. Directional configurations (template_reference_add_configurations): the composites a
///     corpus of refinements plans, each distinct configuration (template_configuration: a
///     canonical form under the 48 cube symmetries) optimised once over its movable nodes from
///     the composed positions.
///
/// A candidate table is tried by building its library (template_library_build) and refining
/// with it: nothing here changes the library the rest of the process uses.

#include "experiments/cli/template_optimize.hpp"

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

/// The SplitMix64 finaliser: the fixed pseudo-random sequence of the perturbed starts.
uint64_t mix(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

/// A standard template (its nodes and children: the reference positions are cleared by every
/// user here).
const HexTemplate& standard_template(TemplateTag tag) {
  return template_library_committed().of(tag);
}

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
  // Appended piece by piece: "{" + std::string trips GCC 12's -Wrestrict (a false positive).
  std::string out = "{";
  out += number(p[0]);
  out += ", ";
  out += number(p[1]);
  out += ", ";
  out += number(p[2]);
  out += "}";
  return out;
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
/// at the reference positions of `table`, its directional configurations optimised on the unit
/// cube first (added to `table`'s). The configurations are collected from a plan made with
/// `planned_with` (the composites' fixed nodes sit where its templates put them) and the case
/// is refined with `table`'s own library, left in `built` (the next candidate's `planned_with`:
/// see template_reference_optimize).
double adjustment_case_min(TemplateReferenceTable& table, const TemplateLibrary& planned_with,
                           std::unique_ptr<const TemplateLibrary>& built) {
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
      refine_method("selective").plan(mesh, topology, targets.hexes, options, stats, planned_with);
  std::vector<const HexTemplate*> composites;
  for (const auto& t : plan.owned) composites.push_back(t.get());
  TemplateReferenceTable with = table;
  with.configurations.clear();
  template_reference_add_configurations(with, composites);
  built = template_library_build(with);
  options.placement.configuration_table = true;
  const double min = mesh_min_scaled_jacobian(
      refine(refine_method("selective"), mesh, targets, options, *built).mesh);
  table.configurations = with.configurations;
  return min;
}

/// Step 2, the table's rows of the standard templates at table.rules: each template's exact
/// minimum, its movable nodes optimised at the rule (standard_at_rule) and their minimum, its own
/// rule the shared one (rule_bounds_find replaces it where a rule of its own does better).
void table_templates_fill(TemplateReferenceTable& table, double max_edge_ratio) {
  table.templates.clear();
  for (TemplateTag tag : template_standard_tags) {
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
}

/// Step 3, the adjustment rule: a grid (along from 1/3 to the face rule's, depth 0.6 to
/// 0.95), each point's L-shaped case with its configurations optimised (adjustment_case_min);
/// the first best kept, its objective in table.adjustment_case_min. Each candidate's case is
/// planned with the library of the candidate before it (the first with the committed one): the
/// optimiser has always collected a candidate's configurations from the templates in use when
/// it came to it, and the committed table is the result of that order.
void adjustment_rule_search(TemplateReferenceTable& table) {
  double best = -2;
  ReferenceRules chosen = table.rules;
  std::unique_ptr<const TemplateLibrary> previous;
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
      std::unique_ptr<const TemplateLibrary> built;
      const double m =
          adjustment_case_min(trial, previous ? *previous : template_library_committed(), built);
      previous = std::move(built);
      if (m > best + 1e-9) {
        best = m;
        chosen = trial.rules;
      }
    }
  table.rules = chosen;
  table.adjustment_case_min = best;
}

/// Step 4: each template's own best face rule, the bound the shared rule stops it at.
void rule_bounds_find(TemplateReferenceTable& table, double max_edge_ratio) {
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
}

}  // namespace

TemplateReferenceTable template_reference_optimize(double max_edge_ratio) {
  TemplateReferenceTable table;
  table.max_edge_ratio = max_edge_ratio;
  std::vector<double> shared;
  table.rules = rule_search(rule_tags, ReferenceRules{}, max_edge_ratio, shared);
  table_templates_fill(table, max_edge_ratio);
  adjustment_rule_search(table);
  table_templates_fill(table, max_edge_ratio);
  rule_bounds_find(table, max_edge_ratio);
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
       "(experiments/cli/template_optimize.cpp,\n"
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

std::string template_corpus_collect(const TemplateLibrary& templates,
                                    std::vector<std::unique_ptr<HexTemplate>>& out,
                                    std::vector<int64_t>& counts) {
  std::map<std::array<uint64_t, 2>, size_t> index;
  struct Case {
    std::array<int, 3> dims;
    double jitter;
    std::vector<std::string> select;
  };
  std::vector<Case> cases;
  auto random = [](double fraction, int seed) {
    char spec[64];
    std::snprintf(spec, sizeof spec, "random:%g,%d", fraction, seed);
    return std::string(spec);
  };
  // Many small bricks: the configurations are local, and rare ones are met by sampling often.
  for (int n : {5, 6, 8})
    for (double fraction : {0.05, 0.1, 0.15, 0.2, 0.3})
      for (int seed = 100; seed < (n == 8 ? 140 : 200); ++seed)
        cases.push_back({{n, n, n}, 0, {random(fraction, seed)}});
  // Seeds 1-6 only: the study's cases (seed 7) stay out of the corpus.
  for (int n : {6, 10, 16})
    for (double fraction : {0.01, 0.02, 0.03, 0.05, 0.08, 0.12, 0.2})
      for (int seed = 1; seed <= (n <= 10 ? 6 : 2); ++seed)
        cases.push_back({{n, n, n}, 0, {random(fraction, seed)}});
  for (double fraction : {0.01, 0.02, 0.03, 0.05, 0.08, 0.12, 0.2})
    for (int seed = 1; seed <= 6; ++seed)
      cases.push_back({{27, 27, 27}, 0, {random(fraction, seed)}});
  for (double fraction : {0.03, 0.05})
    for (int seed = 1; seed <= 2; ++seed)
      cases.push_back({{40, 40, 40}, 0, {random(fraction, seed)}});
  for (int seed = 1; seed <= 6; ++seed)
    cases.push_back({{16, 16, 16}, 0, {"blob:200," + std::to_string(seed)}});
  cases.push_back({{10, 10, 10}, 0, {"boundary:-1,0,0", "boundary:0,0,-1"}});
  for (int n : {10, 20}) {
    const double c = n / 2.0, r = 0.3 * n;
    cases.push_back({{n, n, n},
                     0,
                     {"sphere:" + std::to_string(c) + "," + std::to_string(c) + "," +
                      std::to_string(c) + "," + std::to_string(r)}});
  }
  RefineOptions options;
  options.placement.configuration_table = false;
  int64_t planned = 0;
  for (const Case& c : cases) {
    BrickParams p;
    p.dims = c.dims;
    p.size = {double(c.dims[0]), double(c.dims[1]), double(c.dims[2])};
    p.jitter = c.jitter;
    const HexMesh mesh = generate_brick(p);
    const HexTopology topology = topology_build(mesh);
    const std::vector<int32_t> targets = select_hexes(mesh, topology, c.select).hexes;
    if (targets.empty()) continue;
    for (const char* method : {"selective", "sheet"}) {
      RefineStats stats;
      RefinementPlan plan;
      try {
        plan = refine_method(method).plan(mesh, topology, targets, options, stats, templates);
      } catch (const OperationError&) {
        continue;
      }
      ++planned;
      for (auto& t : plan.owned) {
        if (t->tag != TemplateTag::directional && t->tag != TemplateTag::sheet) continue;
        const auto [it, inserted] = index.try_emplace(template_configuration(*t).hash, out.size());
        if (inserted) {
          out.push_back(std::move(t));
          counts.push_back(0);
        }
        ++counts[it->second];
      }
    }
  }
  // The description is data of the table (written into the committed .inc and the report): it
  // keeps the words the committed table was made with, the file included.
  return std::to_string(planned) +
         " plans (Selective Approach and sheet refinement) on generated bricks: 5^3, 6^3, 8^3 "
         "with random targets 5-30 % (seeds 100-199, 8^3 100-139); 6^3, 10^3, 16^3, 27^3 with "
         "1-20 %, 40^3 with 3 and 5 % (seeds 1-6); 16^3 blobs, the L-shaped case, spheres at "
         "10^3 and 20^3 (experiments/cli_templates.cpp)";
}

TemplateReferenceTable template_table_optimize() {
  TemplateReferenceTable table = template_reference_optimize(template_reference_edge_ratio);
  // The corpus is planned with the optimised rules and templates.
  const std::unique_ptr<const TemplateLibrary> optimised = template_library_build(table);
  std::vector<std::unique_ptr<HexTemplate>> composites;
  std::vector<int64_t> counts;
  table.corpus = template_corpus_collect(*optimised, composites, counts);
  std::vector<const HexTemplate*> pointers;
  for (const auto& t : composites) pointers.push_back(t.get());
  table.configurations.clear();
  table.corpus_hexes = table.corpus_configurations = 0;
  table.corpus_worst_min = 1;
  template_reference_add_configurations(table, pointers, counts);
  return table;
}

}  // namespace hexrefine
