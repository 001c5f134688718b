#include "algorithms/refiners/refiner.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <string>

#include "algorithms/placement/smoothing.hpp"
#include "algorithms/refiners/selective.hpp"
#include "algorithms/refiners/sheet.hpp"
#include "mesh/error.hpp"
#include "mesh/quality.hpp"

namespace hexrefine {

namespace {

using Clock = std::chrono::steady_clock;

/// Node placement plans a pass again at most this many times, each with the parents whose
/// children it could not make valid added to the targets (refine, below).
constexpr int placement_retries = 3;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

constexpr std::array<RefineMethod, 2> methods = {{
    {"selective",
     "the Selective Approach: element-by-element templates, directional refinement with ranking "
     "and propagation (Parrish)",
     selective_plan, true},
    {"sheet", "Harris-style sheet refinement: one dual sheet at a time, targets grown", sheet_plan,
     false},
}};

void targets_validate(const HexMesh& mesh, const Targets& targets, std::string_view method) {
  int32_t previous = -1;
  for (int32_t t : targets.hexes) {
    if (t < 0 || t >= mesh.hex_count())
      throw InputError(std::string(method) + ": target hex " + std::to_string(t) +
                       " is not in the mesh (0.." + std::to_string(mesh.hex_count() - 1) + ")");
    if (t <= previous)
      throw InputError(std::string(method) + ": targets must be ascending and unique (hex " +
                       std::to_string(t) + " after " + std::to_string(previous) + ")");
    previous = t;
  }
}

/// Refuses an input with hexes of scaled Jacobian <= 0, naming up to ten with their values.
void input_validate(const HexMesh& mesh, std::string_view method) {
  int64_t inverted = 0;
  std::string list;
  for (int32_t h = 0; h < mesh.hex_count(); ++h) {
    const double sj = hex_scaled_jacobian(hex_points(mesh, h));
    if (sj > 0) continue;
    if (++inverted <= 10)
      list += (list.empty() ? "" : ", ") + std::to_string(h) + " (" + std::to_string(sj) + ")";
  }
  if (inverted)
    throw InputError(std::string(method) + ": " + std::to_string(inverted) +
                     " input hexes have a scaled Jacobian <= 0 (inverted or degenerate), no "
                     "refinement of them can be valid: hex (scaled Jacobian) " +
                     list + (inverted > 10 ? ", ..." : "") +
                     " (allow_inverted, --allow-inverted, refines them anyway)");
}

/// The last resort of node placement (a valid input is never refused). Placement moves
/// only new nodes; where even the retargets leave children inverted (a transition template in a
/// parent whose own corners hold a child folded), the nodes around those children move too,
/// the parents' input nodes included, as smoothing moves them (algorithms/placement/smoothing.hpp:
/// interior nodes freely, boundary nodes sliding on the input's boundary surface, the mesh's
/// minimum never lowered, no valid hex inverted, the edge-ratio cap kept): the inverted
/// children and two layers of hexes around them are the region. Returns empty on success and
/// counts the children it made valid; throws OperationError naming the input hexes when some
/// stay inverted: the refinement has no valid placement the tool can find, which says nothing
/// against the input.
std::vector<int32_t> placement_fallback_untangle(HexMesh& refined,
                                                 const BoundaryReference& reference,
                                                 int32_t input_nodes, const RefineOptions& options,
                                                 RefineStats& stats) {
  std::vector<int32_t> inverted;
  const std::vector<double> before = mesh_scaled_jacobians(refined);
  for (int32_t h = 0; h < refined.hex_count(); ++h)
    if (!(before[h] > 0)) inverted.push_back(h);
  // Validity first: the sweeps visit every node of the region (visit_below 1) and, if the
  // edge-ratio cap holds a child inverted, run again without it over a wider region (an inverted
  // child has no quality to protect; a stretched edge shows in the report's max_edge_ratio). That
  // second run has no joint ascent: without the cap the ascent raises the scaled Jacobian by
  // collapsing edges (results/methods.md, "The placement fallback's uncapped run"), and every
  // later stage caps a hex at its ratio from here.
  SmoothOptions smoothing;  // the smoothing's default budget: the region is a few hundred hexes
  smoothing.region_hexes = inverted;
  smoothing.layers = 2;
  smoothing.visit_below = 1;
  smoothing.reference = &reference;
  smoothing.reference_nodes = input_nodes;
  smoothing.threads = options.threads;
  smoothing.max_edge_ratio = options.placement.max_edge_ratio;
  mesh_smooth(refined, smoothing);
  if (std::ranges::any_of(inverted, [&](int32_t h) {
        return !(hex_scaled_jacobian(hex_points(refined, h)) > 0);
      })) {
    smoothing.layers = 4;
    smoothing.max_edge_ratio = 0;
    smoothing.joint_iterations = 0;
    mesh_smooth(refined, smoothing);
  }
  const std::vector<double> after = mesh_scaled_jacobians(refined);
  const std::vector<int32_t>* original = mesh_find_attribute(refined, attribute_parent_hex);
  std::vector<int32_t> stuck;  // input hexes whose children stay inverted
  for (int32_t h : inverted) {
    if (after[h] > 0)
      ++stats.placement_fallback_untangled;
    else
      stuck.push_back(original ? (*original)[h] : h);
  }
  if (stuck.empty()) return {};
  std::sort(stuck.begin(), stuck.end());
  stuck.erase(std::unique(stuck.begin(), stuck.end()), stuck.end());
  std::string list;
  for (size_t i = 0; i < stuck.size() && i < 10; ++i)
    list += (i ? ", " : "") + std::to_string(stuck[i]);
  throw PlacementError(
      "node placement: " + std::to_string(stuck.size()) +
      " refined input hexes keep an inverted child after placement, " +
      std::to_string(placement_retries) +
      " retargets and the untangling of the nodes around them (input hexes " + list +
      (stuck.size() > 10 ? ", ..." : "") +
      "); the input passed the checker: this is a limit of the placement, not of the input");
}

}  // namespace

void refine_input_validate(const HexMesh& mesh, const Targets& targets,
                           const RefineOptions& options, std::string_view method) {
  targets_validate(mesh, targets, method);
  if (options.passes < 1)
    throw InputError(std::string(method) + ": passes must be at least 1, got " +
                     std::to_string(options.passes));
  if (options.threads < 1)
    throw InputError(std::string(method) + ": threads must be at least 1, got " +
                     std::to_string(options.threads));
  if (!options.allow_inverted) input_validate(mesh, method);
}

void stats_count_templates(RefineStats& stats, const std::vector<int32_t>& tags) {
  // One counter per tag value first: a string-keyed map lookup per hex would cost more than
  // the refinement itself on large meshes.
  std::array<int64_t, template_tag_count> known{};
  for (int32_t t : tags) {
    if (t >= 0 && t < template_tag_count)
      ++known[t];
    else
      ++stats.hexes_per_template[template_tag_name(static_cast<TemplateTag>(t))];
  }
  for (int t = 0; t < template_tag_count; ++t)
    if (known[t])
      stats.hexes_per_template[template_tag_name(static_cast<TemplateTag>(t))] += known[t];
}

void refine_stats_finish(RefineStats& stats, const HexMesh& mesh, double seconds) {
  stats.final_hexes = mesh.hex_count();
  stats.final_nodes = mesh.point_count();
  if (const std::vector<int32_t>* tags = mesh_find_attribute(mesh, attribute_template_tag))
    stats_count_templates(stats, *tags);
  stats.time_seconds = seconds;
  stats.phase_seconds["total"] = seconds;
}

std::span<const RefineMethod> refine_methods() {
  return methods;
}

PassBuffer pass_buffer_from_name(std::string_view name) {
  if (name == "layer") return PassBuffer::layer;
  if (name == "none") return PassBuffer::none;
  if (name == "transitions") return PassBuffer::transitions;
  throw InputError("unknown pass buffer '" + std::string(name) +
                   "' (expected layer, none or transitions)");
}

const RefineMethod& refine_method(std::string_view name) {
  std::string known;
  for (const RefineMethod& m : methods) {
    if (m.name == name) return m;
    known += (known.empty() ? "" : ", ") + std::string(m.name);
  }
  throw InputError("unknown refinement method '" + std::string(name) +
                   "' (expected one of: " + known + ")");
}

namespace {

/// The mesh the first pass refines: `mesh` itself, or (when it has a parent_hex attribute) a
/// copy without it in `copy`: the engine's rule drops the input's parent_hex, so the output's
/// names the input's hexes.
const HexMesh* refine_input_without_parent(const HexMesh& mesh, HexMesh& copy) {
  if (!mesh_find_attribute(mesh, attribute_parent_hex)) return &mesh;
  copy = mesh;
  std::erase_if(copy.attributes,
                [](const HexAttribute& a) { return a.name == attribute_parent_hex; });
  return &copy;
}

/// A pass's targets: `core`, and with `layered` (PassBuffer::layer) every face neighbour of the
/// core not in it, counted in stats.added_targets; ascending.
std::vector<int32_t> pass_targets_make(const HexMesh& current, const HexTopology& topology,
                                       const std::vector<int32_t>& core, bool layered,
                                       RefineStats& stats) {
  std::vector<int32_t> pass_targets = core;
  if (!layered) return pass_targets;
  std::vector<uint8_t> in_pass(static_cast<size_t>(current.hex_count()), 0);
  for (int32_t h : core) in_pass[h] = 1;
  for (int32_t h : core)
    for (int lf = 0; lf < 6; ++lf) {
      const int32_t g = hex_face_neighbor(topology, h, lf);
      if (g >= 0 && !in_pass[g]) {
        in_pass[g] = 1;
        pass_targets.push_back(g);
        ++stats.added_targets;
      }
    }
  std::sort(pass_targets.begin(), pass_targets.end());
  return pass_targets;
}

/// Node placement of one attempt at a pass (none for the thesis' trilinear placement): the
/// input's boundary is taken on the first attempt of the first pass (`first`), the last attempt
/// (`last`) ends with the fallback. Returns the parents whose children stay inverted.
std::vector<int32_t> pass_place(const HexMesh& mesh, const HexMesh& current,
                                const HexTopology& topology, const RefinementPlan& plan,
                                PlanApplyResult& applied, bool first, bool last,
                                const RefineOptions& options, BoundaryReference& reference,
                                RefineStats& stats) {
  if (options.placement.method == PlacementMethod::trilinear) return {};
  if (first) reference = boundary_reference_build(current, topology);
  const std::vector<int32_t>* original = mesh_find_attribute(current, attribute_parent_hex);
  const PlacementPass placement{
      current,
      topology,
      plan,
      applied.first_child,
      original ? std::span<const int32_t>(*original) : std::span<const int32_t>(),
      reference,
      options.allow_inverted,
      false,
      options.threads,
      mesh.point_count()};
  std::vector<int32_t> failed =
      place_new_nodes(placement, applied.mesh, options.placement, stats.placement);
  if (!failed.empty() && last)
    failed =
        placement_fallback_untangle(applied.mesh, reference, mesh.point_count(), options, stats);
  return failed;
}

/// After an attempt placement could not finish: the dropped plan's counts undone (its time and
/// the retargets kept), the `failed` parents added to the targets (ascending). Returns false
/// when none was new: the next plan would be the same.
bool pass_retarget(const std::vector<int32_t>& failed, const RefineStats& stats_before_plan,
                   std::vector<int32_t>& pass_targets, RefineStats& stats) {
  const std::map<std::string, double> seconds = stats.phase_seconds;
  const int64_t retargeted = stats.placement_retargets;
  stats = stats_before_plan;
  stats.phase_seconds = seconds;
  stats.placement_retargets = retargeted;
  const size_t before = pass_targets.size();
  for (int32_t h : failed)
    if (!std::binary_search(pass_targets.begin(), pass_targets.begin() + before, h))
      pass_targets.push_back(h);
  stats.placement_retargets += static_cast<int64_t>(pass_targets.size() - before);
  std::sort(pass_targets.begin(), pass_targets.end());
  return pass_targets.size() != before;
}

/// The plan and its application of one pass, placed (pass_place).
struct PassOutcome {
  RefinementPlan plan;
  PlanApplyResult applied;
};

/// One pass: plan, apply, place. A parent whose children placement cannot make valid (a
/// distorted hex under a transition template) becomes a target and the pass is planned again:
/// refined by a template of boxes, its children are images of boxes under its own map, and the
/// transition moves to its neighbours. At most placement_retries new plans; the counts of a
/// dropped plan are undone, its time is kept. `t`: when the pass started (its plan phase counts
/// from there).
PassOutcome pass_run(const RefineMethod& method, const HexMesh& mesh, const HexMesh& current,
                     const HexTopology& topology, std::vector<int32_t>& pass_targets,
                     bool first_pass, const RefineOptions& options,
                     const TemplateLibrary& templates, BoundaryReference& reference,
                     RefineStats& stats, Clock::time_point t) {
  const RefineStats stats_before_plan = stats;
  PassOutcome out;
  for (int attempt = 0;; ++attempt) {
    out.plan = method.plan(current, topology, pass_targets, options, stats, templates);
    stats.phase_seconds["plan"] += seconds_since(t);

    t = Clock::now();
    out.applied = plan_apply(current, topology, out.plan, options.threads,
                             placement_start_positions(options.placement.method));
    stats.phase_seconds["apply"] += seconds_since(t);

    t = Clock::now();
    const std::vector<int32_t> failed =
        pass_place(mesh, current, topology, out.plan, out.applied, first_pass && attempt == 0,
                   attempt == placement_retries, options, reference, stats);
    stats.phase_seconds["placement"] += seconds_since(t);
    if (failed.empty()) break;
    // Nothing new to refine: the next plan is the same, so let it refuse.
    if (!pass_retarget(failed, stats_before_plan, pass_targets, stats))
      attempt = placement_retries - 1;
    t = Clock::now();
  }
  return out;
}

/// The next pass's core: the children of this pass's core (with PassBuffer::transitions also of
/// every other hex this pass refined, which then count as added targets).
std::vector<int32_t> next_core_make(const RefineMethod& method, const RefineOptions& options,
                                    const HexMesh& current, const std::vector<int32_t>& core,
                                    const PassOutcome& pass, RefineStats& stats) {
  std::vector<uint8_t> in_core(static_cast<size_t>(current.hex_count()), 0);
  for (int32_t h : core) in_core[h] = 1;
  const bool transitions = method.uses_buffer && options.buffer == PassBuffer::transitions;
  std::vector<int32_t> next;
  for (size_t u = 0; u < pass.plan.uses.size(); ++u) {
    const TemplateUse& use = pass.plan.uses[u];
    const bool from_core = in_core[index_of(use.hex)];
    if (!from_core && !transitions) continue;
    const int32_t first = pass.applied.first_child[u];
    const int32_t count = static_cast<int32_t>(use.tmpl->children.size());
    for (int32_t c = first; c < first + count; ++c) next.push_back(c);
    if (!from_core) stats.added_targets += count;
  }
  return next;
}

}  // namespace

RefineResult refine(const RefineMethod& method, const HexMesh& mesh, const Targets& targets,
                    const RefineOptions& options, const TemplateLibrary& templates) {
  const auto t0 = Clock::now();
  const std::string name(method.name);
  refine_input_validate(mesh, targets, options, name);

  RefineResult result;
  RefineStats& stats = result.stats;
  stats.method = name;
  stats.initial_hexes = mesh.hex_count();
  for (const char* phase : {"plan", "apply", "placement"}) stats.phase_seconds[phase] = 0;

  // The mesh a pass refines: the input for the first pass, the previous pass's output after.
  HexMesh input_without_parent;
  const HexMesh* current = refine_input_without_parent(mesh, input_without_parent);
  HexMesh output;
  BoundaryReference reference;  // the input's boundary, where boundary nodes stay
  // `core`: the descendants of the user's targets in the current mesh (ascending).
  std::vector<int32_t> core = targets.hexes;
  const bool layered =
      method.uses_buffer && options.passes > 1 && options.buffer == PassBuffer::layer;
  for (int pass = 0; pass < options.passes; ++pass) {
    const auto t = Clock::now();
    const HexTopology topology = topology_build(*current);
    std::vector<int32_t> pass_targets = pass_targets_make(*current, topology, core, layered, stats);
    PassOutcome outcome = pass_run(method, mesh, *current, topology, pass_targets, pass == 0,
                                   options, templates, reference, stats, t);
    if (pass + 1 < options.passes)
      core = next_core_make(method, options, *current, core, outcome, stats);
    output = std::move(outcome.applied.mesh);
    current = &output;
  }
  result.mesh = std::move(output);
  refine_stats_finish(stats, result.mesh, seconds_since(t0));
  return result;
}

}  // namespace hexrefine
