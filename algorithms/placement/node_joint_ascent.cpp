/// \file
/// Joint ascent of the free (and optionally the sliding) nodes of a local problem: all of them
/// move at once to raise a smooth lower bound of the minimum scaled Jacobian.
///
/// Sources (formulas and facts only):
/// - G. Kreisselmeier, R. Steinhauser, "Systematic control design by optimizing a vector
///   performance index" (1979): KS(s) = m - log(sum_i exp(-beta (s_i - m))) / beta, m = min s_i,
///   lies in [m - log(n) / beta, m]; its gradient is the softmax-weighted mean of the gradients.
/// - J. Nocedal, "Updating quasi-Newton matrices with limited storage", Math. Comp. 35 (1980)
///   773-782: L-BFGS, the two-loop recursion over the last few (step, gradient change) pairs,
///   and J. Nocedal, S. Wright, "Numerical Optimization" (2006), ch. 3 and 7: backtracking under
///   the Armijo condition, a pair kept only when its curvature s.y is positive.
/// - P. Knupp, "Hexahedral and tetrahedral mesh untangling", Eng. Comput. 17 (2001) 261-268, and
///   the Mesquite toolkit's global solvers: optimizing every free vertex of a mesh at once, which
///   reaches configurations a vertex-at-a-time sweep cannot when several vertices hold the
///   worst element together.
///
/// Steps:
///  1. The variables: the problem's free nodes (interior nodes), and with options.slide its
///     sliding nodes (otherwise they keep their place, their slides are the node-by-node
///     optimizer's), of the worst hexes (at most max_seeds of those within `band` of the worst
///     sample a variable moves) and of `rings` rings of hexes around them. A sliding variable's
///     gradient is projected onto its slide's tangent and every iterate puts it back onto its
///     slide (projected quasi-Newton: the step kept is the projected one, and the L-BFGS pair is
///     taken from it). The objective's hexes: those with a variable corner, with those of their
///     nine scaled-Jacobian samples (corners, centre: the samples whose minimum is
///     hex_scaled_jacobian) that a variable moves; a sample no variable moves is a constant.
///  2. KS of those samples and its analytic gradient (hex by hex, the sample gradients of
///     hex_scaled_jacobian_gradients weighted and summed, then gathered node by node).
///  3. L-BFGS iterations maximising KS: the two-loop direction (steepest ascent, scaled to move
///     the fastest node a fiftieth of the mean edge length, when there is no history or the
///     direction does not ascend), every step capped at a quarter of the mean edge length,
///     backtracking until the Armijo condition holds; a step that inverts a hex lowers KS
///     sharply and is cut back like any other.
///     They stop after max_iterations, after stall_iterations without the minimum rising, or
///     when KS stops rising.
///     An iterate that stretches a hex past its edge-ratio cap (hex_edge_ratio_cap) is
///     infeasible: its KS is -inf, and the line search cuts the step back as for an inversion.
///  4. The iterate with the highest true minimum is kept; the start if none beats it (checked
///     with hex_scaled_jacobian itself).
/// Threads evaluate chunks of hexes and gather chunks of nodes; every sum is taken in a fixed
/// order, so the result is the same for any thread count.

#include "algorithms/placement/node_joint_ascent.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>

#include "mesh/hex_convention.hpp"
#include "mesh/parallel.hpp"
#include "mesh/quality.hpp"

namespace hexrefine {

namespace {

using Vec3 = Eigen::Vector3d;
using Corners = std::array<Vec3, 8>;

/// The scaled-Jacobian sample of the columns `a` (corner or centre matrix); with `weight`
/// non-zero, adds weight * d sample / d a_k to gradient[k]. 0 where a column has zero length.
double column_sample(const std::array<Vec3, 3>& a, double weight, std::array<Vec3, 3>* gradient) {
  const double l0 = a[0].norm(), l1 = a[1].norm(), l2 = a[2].norm();
  const double lengths = l0 * l1 * l2;
  if (!(lengths > std::numeric_limits<double>::min())) return 0.0;
  const std::array<Vec3, 3> cofactor = {a[1].cross(a[2]), a[2].cross(a[0]), a[0].cross(a[1])};
  const double s = a[0].dot(cofactor[0]) / lengths;
  if (gradient && weight != 0) {
    const double squared[3] = {l0 * l0, l1 * l1, l2 * l2};
    for (int k = 0; k < 3; ++k)
      (*gradient)[k] += weight * (cofactor[k] / lengths - s * a[k] / squared[k]);
  }
  return std::clamp(s, -1.0, 1.0);
}

/// The nine samples of a hex (corners 0..7, centre), as hex_scaled_jacobian_samples orders
/// them; with `weights`, gradient[v] = sum_s weights[s] d sample_s / d p[v].
void hex_samples(const Corners& p, std::array<double, 9>& samples,
                 const std::array<double, 9>* weights = nullptr, Corners* gradient = nullptr) {
  if (gradient)
    for (Vec3& g : *gradient) g.setZero();
  for (int v = 0; v < 8; ++v) {
    std::array<Vec3, 3> a, g{Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
    for (int k = 0; k < 3; ++k) {
      const int e = hex_vertex_edges[v][k];
      a[k] = p[hex_edges[e][1]] - p[hex_edges[e][0]];
    }
    samples[v] = column_sample(a, weights ? (*weights)[v] : 0.0, gradient ? &g : nullptr);
    if (!gradient) continue;
    for (int k = 0; k < 3; ++k) {
      const int e = hex_vertex_edges[v][k];
      (*gradient)[hex_edges[e][1]] += g[k];
      (*gradient)[hex_edges[e][0]] -= g[k];
    }
  }
  std::array<Vec3, 3> a, g{Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
  for (int k = 0; k < 3; ++k) {
    a[k].setZero();
    for (int e : hex_axis_edges[k]) a[k] += p[hex_edges[e][1]] - p[hex_edges[e][0]];
    a[k] /= 4.0;
  }
  samples[8] = column_sample(a, weights ? (*weights)[8] : 0.0, gradient ? &g : nullptr);
  if (!gradient) return;
  for (int k = 0; k < 3; ++k)
    for (int e : hex_axis_edges[k]) {
      (*gradient)[hex_edges[e][1]] += 0.25 * g[k];
      (*gradient)[hex_edges[e][0]] -= 0.25 * g[k];
    }
}

constexpr int64_t chunk_hexes = 512;

/// The twelve edge lengths of a hex (hex_edges order) and which are the shortest and the
/// longest: the feasibility test (the edge-ratio cap) and the cap sample both read them, so an
/// evaluation takes them once per hex.
struct HexEdgeLengths {
  std::array<double, 12> length;
  int shortest = 0, longest = 0;
  /// hex_edge_ratio's value, bit for bit (the same norms, the same quotient).
  double ratio() const {
    if (!(length[shortest] > 0.0)) return hex_metric_max;
    return std::min(length[longest] / length[shortest], hex_metric_max);
  }
};

HexEdgeLengths hex_edge_lengths(const Corners& p) {
  HexEdgeLengths l;
  for (int e = 0; e < 12; ++e) {
    l.length[e] = (p[hex_edges[e][1]] - p[hex_edges[e][0]]).norm();
    if (l.length[e] < l.length[l.shortest]) l.shortest = e;
    if (l.length[e] > l.length[l.longest]) l.longest = e;
  }
  return l;
}

/// The edge-ratio sample of a hex whose cap is finite: sharpness (1 - ratio / cap), where the
/// ratio (hex_edge_ratio) is within the last 1/sharpness of its cap and its longest or shortest
/// edge has a variable end (`vars`: per corner its variable, -1 for none), else +inf (no sample:
/// far from the cap, or a constant no variable changes, which could only hold the soft minimum's
/// reference down). It joins the scaled Jacobian samples in the soft minimum, so an iterate nearing
/// a hex's cap is steered along the cap instead of being cut back to nothing by the line search (a
/// hex the sweeps left at its cap otherwise stops the ascent at its first step). With `gradient`,
/// adds weight * d sample / d p[v] to gradient[v]. -inf for a zero-length edge (an infeasible
/// point).
constexpr double cap_sample_sharpness = 20;
double hex_cap_sample(const Corners& p, const HexEdgeLengths& lengths, double cap,
                      const std::array<int32_t, 8>& vars, double weight = 0,
                      Corners* gradient = nullptr) {
  if (!std::isfinite(cap)) return std::numeric_limits<double>::infinity();
  const std::array<double, 12>& length = lengths.length;
  const int shortest = lengths.shortest, longest = lengths.longest;
  if (!(length[shortest] > 0)) return -std::numeric_limits<double>::infinity();
  const double ratio = length[longest] / length[shortest];
  const double sharpness = cap_sample_sharpness;
  if (ratio < (1 - 1 / sharpness) * cap) return std::numeric_limits<double>::infinity();
  const auto edge_moves = [&](int e) {
    return vars[hex_edges[e][0]] >= 0 || vars[hex_edges[e][1]] >= 0;
  };
  if (!edge_moves(longest) && !edge_moves(shortest)) return std::numeric_limits<double>::infinity();
  if (gradient && weight != 0) {
    // d ratio = ratio (d L_long / L_long - d L_short / L_short), d L = u / L on the edge's end.
    const double scale = -weight * sharpness / cap * ratio;
    for (const auto& [e, sign] : {std::pair{longest, 1.0}, std::pair{shortest, -1.0}}) {
      const Vec3 u = (p[hex_edges[e][1]] - p[hex_edges[e][0]]) / (length[e] * length[e]);
      (*gradient)[hex_edges[e][1]] += scale * sign * u;
      (*gradient)[hex_edges[e][0]] -= scale * sign * u;
    }
  }
  return sharpness * (1 - ratio / cap);
}

/// The samples of a hex that move when the corners marked in `moves` do: bit v (corner v) when
/// v or one of its three edge neighbours moves, bit 8 (the centre) when any corner does. A sample
/// that does not move is a constant of the problem: left out of the objective, its value cannot
/// hold the ascent back.
uint16_t sample_mask(const std::array<bool, 8>& moves) {
  uint16_t mask = 0;
  for (int v = 0; v < 8; ++v) {
    bool m = moves[v];
    for (int k = 0; k < 3; ++k) {
      const int e = hex_vertex_edges[v][k];
      m = m || moves[hex_edges[e][0]] || moves[hex_edges[e][1]];
    }
    if (m) mask |= static_cast<uint16_t>(1u << v);
  }
  if (mask) mask |= 1u << 8;
  return mask;
}

/// exp(-z), z >= 0, taken as 0 beyond z = 40 (below 5e-18, nothing next to the minimum's 1):
/// most samples lie far above the minimum, and their exponentials and gradients are skipped.
double weight(double z) {
  return z < 40.0 ? std::exp(-z) : 0.0;
}

/// The objective of one joint ascent (step 1 of the file comment: its variables and hexes) and
/// its evaluation (step 2); nodes_ascend_jointly runs steps 3 and 4 on it.
/// Length: a class, not a function; its methods are short, kept in one class because the
/// evaluation and its gradient share the per-hex buffers the constructor sizes.
class JointProblem {
 public:
  JointProblem(HexMesh& mesh, const NodeProblem& problem, const JointAscentOptions& options)
      : mesh_(mesh), problem_(problem), options_(options) {
    const std::vector<int32_t> var_of = variables_choose();
    sliding_guard_faces_collect();
    // Where each sliding variable is on its slide: the projections' warm starts.
    states_.resize(sliding_.size());
    for (size_t k = 0; k < sliding_.size(); ++k)
      hexrefine::slide_project(problem.slides[var_problem_[sliding_[k]]], problem.geometry,
                               mesh_.points[nodes_[sliding_[k]]], states_[k]);
    objective_hexes_build(var_of);
    evaluation_buffers_size();
  }

  int64_t variables() const { return static_cast<int64_t>(nodes_.size()) * 3; }
  int64_t sliding() const { return static_cast<int64_t>(sliding_.size()); }
  int64_t hexes() const { return static_cast<int64_t>(hexes_.size()); }
  double mean_edge() const { return mean_edge_; }

  Eigen::VectorXd position() const {
    Eigen::VectorXd x(variables());
    for (size_t v = 0; v < nodes_.size(); ++v) x.segment<3>(3 * v) = mesh_.points[nodes_[v]];
    return x;
  }
  /// Puts the variables back at x exactly, a point set_position() made (no projection again:
  /// the start and the best iterate are restored bit for bit).
  void restore(const Eigen::VectorXd& x) {
    for (size_t v = 0; v < nodes_.size(); ++v) mesh_.points[nodes_[v]] = x.segment<3>(3 * v);
  }

  /// Puts the variables at x, each sliding one at the point of its slide nearest to its entry
  /// of x: the mesh then holds the projection of x (position() reads it back).
  void set_position(const Eigen::VectorXd& x) {
    for (size_t v = 0; v < nodes_.size(); ++v) mesh_.points[nodes_[v]] = x.segment<3>(3 * v);
    for (size_t k = 0; k < sliding_.size(); ++k) {
      const int32_t v = sliding_[k];
      mesh_.points[nodes_[v]] = hexrefine::slide_project(
          problem_.slides[var_problem_[v]], problem_.geometry, x.segment<3>(3 * v), states_[k]);
    }
  }

  /// Whether the boundary faces of the sliding variables lie on the reference surface at the
  /// positions the last set_position() or evaluate() made (NodeProblem::surface; true without).
  /// Asked only of a step the line search would accept: the test projects onto patches and
  /// costs more than the step's KS.
  bool faces_on_surface() const {
    for (int32_t f : guard_faces_) {
      const auto& q = problem_.faces[f];
      if (!reference_surface_holds_face(
              *problem_.surface,
              {mesh_.points[q[0]], mesh_.points[q[1]], mesh_.points[q[2]], mesh_.points[q[3]]}))
        return false;
    }
    return true;
  }

  /// Drops from the guard the faces failing at the current positions.
  void unguard_failing_faces() {
    std::erase_if(guard_faces_, [&](int32_t f) {
      const auto& q = problem_.faces[f];
      return !reference_surface_holds_face(
          *problem_.surface,
          {mesh_.points[q[0]], mesh_.points[q[1]], mesh_.points[q[2]], mesh_.points[q[3]]});
    });
  }

  /// At x: KS (-inf where a sample is not finite or a hex is past its edge-ratio cap: an
  /// infeasible point), the minimum sample and, with `gradient`,
  /// d KS / d x.
  double evaluate(const Eigen::VectorXd& x, double& min, Eigen::VectorXd* gradient) {
    set_position(x);
    const int64_t count = static_cast<int64_t>(hexes_.size());
    parallel_chunks(threads_, count, chunk_hexes, [&](int64_t c, int64_t b, int64_t e) {
      double m = std::numeric_limits<double>::infinity();
      for (int64_t h = b; h < e; h += 2) {
        const int64_t g = std::min(h + 1, e - 1);  // an odd chunk end evaluates its last twice
        const Corners ph = hex_points(mesh_, hexes_[h]), pg = hex_points(mesh_, hexes_[g]);
        hex_scaled_jacobian_samples_pair(ph, pg, samples_[h], samples_[g]);
        // Past its edge-ratio cap a hex makes the point infeasible, like a non-finite sample.
        for (const auto& [k, pk] : {std::pair<int64_t, const Corners&>{h, ph}, {g, pg}}) {
          if (!std::isfinite(edge_caps_[k])) continue;  // no cap: no test, no cap sample
          const HexEdgeLengths lengths = hex_edge_lengths(pk);
          if (!(lengths.ratio() <= edge_caps_[k])) m = -std::numeric_limits<double>::infinity();
          if (options_.cap_samples)
            cap_samples_[k] = hex_cap_sample(pk, lengths, edge_caps_[k], hex_vars_[k]);
        }
      }
      double cap_min = std::numeric_limits<double>::infinity();
      for (int64_t h = b; h < e; ++h) {
        for (int k = 0; k < 9; ++k) {
          if (!(masks_[h] >> k & 1)) continue;
          const double s = samples_[h][k];
          m = std::isfinite(s) ? std::min(m, s) : -std::numeric_limits<double>::infinity();
        }
        cap_min = std::min(cap_min, cap_samples_[h]);
      }
      chunk_min_[c] = m;
      chunk_cap_min_[c] = cap_min;
    });
    min = std::numeric_limits<double>::infinity();
    for (double m : chunk_min_) min = std::min(min, m);
    if (!std::isfinite(min)) return -std::numeric_limits<double>::infinity();

    // The soft minimum's reference: the least of the scaled Jacobian and cap samples (`min`,
    // returned, is the scaled Jacobians' alone: what the ascent keeps the best iterate by).
    double floor = min;
    for (double m : chunk_cap_min_) floor = std::min(floor, m);
    if (!std::isfinite(floor)) return -std::numeric_limits<double>::infinity();
    const double beta = options_.beta;
    parallel_chunks(threads_, count, chunk_hexes, [&](int64_t c, int64_t b, int64_t e) {
      double sum = 0;
      for (int64_t h = b; h < e; ++h) {
        for (int k = 0; k < 9; ++k)
          if (masks_[h] >> k & 1) sum += weight(beta * (samples_[h][k] - floor));
        sum += weight(beta * (cap_samples_[h] - floor));
      }
      chunk_sum_[c] = sum;
    });
    double sum = 0;
    for (double s : chunk_sum_) sum += s;
    const double ks = floor - std::log(sum) / beta;
    last_floor_ = floor;
    last_sum_ = sum;
    if (gradient) gradient_at_last(*gradient);
    return ks;
  }

  /// d KS / d x at the point of the last evaluate() (its samples, soft-minimum reference and
  /// sum); sliding variables' entries on their slides' tangents.
  void gradient_at_last(Eigen::VectorXd& gradient) {
    const int64_t count = static_cast<int64_t>(hexes_.size());
    const double beta = options_.beta, floor = last_floor_, sum = last_sum_;
    parallel_chunks(threads_, count, chunk_hexes, [&](int64_t, int64_t b, int64_t e) {
      std::array<double, 9> weights, unused;
      for (int64_t h = b; h < e; ++h) {
        bool any = false;
        for (int s = 0; s < 9; ++s) {
          weights[s] = masks_[h] >> s & 1 ? weight(beta * (samples_[h][s] - floor)) / sum : 0.0;
          any = any || weights[s] != 0;
        }
        const double cap_weight = weight(beta * (cap_samples_[h] - floor)) / sum;
        if (any || cap_weight != 0) {
          const Corners p = hex_points(mesh_, hexes_[h]);
          hex_samples(p, unused, &weights, &hex_gradient_[h]);
          if (cap_weight != 0)
            hex_cap_sample(p, hex_edge_lengths(p), edge_caps_[h], hex_vars_[h], cap_weight,
                           &hex_gradient_[h]);
        } else {
          for (Vec3& g : hex_gradient_[h]) g.setZero();
        }
      }
    });
    gradient.resize(variables());
    parallel_chunks(threads_, static_cast<int64_t>(nodes_.size()), 4096,
                    [&](int64_t, int64_t b, int64_t e) {
                      for (int64_t v = b; v < e; ++v) {
                        Vec3 g = Vec3::Zero();
                        for (int32_t k = var_offsets_[v]; k < var_offsets_[v + 1]; ++k)
                          g += hex_gradient_[var_items_[k].first][var_items_[k].second];
                        gradient.segment<3>(3 * v) = g;
                      }
                    });
    // A sliding node moves only within its slide's tangent space.
    for (size_t k = 0; k < sliding_.size(); ++k) {
      const int32_t v = sliding_[k];
      gradient.segment<3>(3 * v) =
          hexrefine::slide_tangent(problem_.slides[var_problem_[v]], problem_.geometry, states_[k],
                                   Vec3(gradient.segment<3>(3 * v)));
    }
  }

  /// The largest node displacement of the step d.
  double largest_move(const Eigen::VectorXd& d) const {
    double largest = 0;
    for (int64_t v = 0; v < d.size() / 3; ++v)
      largest = std::max(largest, d.segment<3>(3 * v).norm());
    return largest;
  }

  /// The true minimum (hex_scaled_jacobian) over the objective's hexes.
  double true_min() const {
    double m = 1.0;
    for (int32_t h : hexes_) m = std::min(m, hex_scaled_jacobian(hex_points(mesh_, h)));
    return m;
  }

 private:
  /// The variables (nodes_, var_problem_, sliding_): the moving nodes of the worst hexes within
  /// options.band of the worst sample a variable moves (at most max_seeds of them), and of
  /// `rings` rings of hexes around them. Returns per problem node its variable (-1: none).
  std::vector<int32_t> variables_choose() {
    const NodeProblem& problem = problem_;
    const JointAscentOptions& options = options_;
    // With options.slide the sliding nodes are variables like the free ones.
    // A slide without items (none is built so, but a caller could) would move freely: left out.
    const auto moves = [&](int32_t i) {
      if (i < 0) return false;
      const NodeSlide& slide = problem.slides[i];
      return slide.kind == SlideKind::free || (options.slide && slide.count > 0);
    };
    const int32_t n = static_cast<int32_t>(problem.nodes.size());
    std::vector<uint8_t> chosen(n, 0);
    // Per problem hex its worst sample that a variable moves (2: none, never a seed).
    std::vector<double> quality(problem.hexes.size(), 2.0);
    double worst = 1.0;
    for (size_t j = 0; j < problem.hexes.size(); ++j) {
      std::array<bool, 8> moving{};
      for (int c = 0; c < 8; ++c) moving[c] = moves(problem.hex_local_nodes[j][c]);
      const uint16_t mask = sample_mask(moving);
      if (!mask) continue;
      std::array<double, 9> samples;
      hex_scaled_jacobian_samples(hex_points(mesh_, problem.hexes[j]), samples);
      for (int k = 0; k < 9; ++k)
        if (mask >> k & 1) quality[j] = std::min(quality[j], samples[k]);
      worst = std::min(worst, quality[j]);
    }
    // The seeds: within the band, at most max_seeds of them, the worst first (ties by index).
    std::vector<std::pair<double, int32_t>> seeds;
    for (size_t j = 0; j < problem.hexes.size(); ++j)
      if (quality[j] <= 1.0 && quality[j] < worst + options.band)
        seeds.push_back({quality[j], static_cast<int32_t>(j)});
    if (static_cast<int64_t>(seeds.size()) > options.max_seeds) {
      std::nth_element(seeds.begin(), seeds.begin() + options.max_seeds, seeds.end());
      seeds.resize(static_cast<size_t>(options.max_seeds));
    }
    std::vector<int32_t> front;
    for (const auto& [unused, j] : seeds) {
      for (int32_t i : problem.hex_local_nodes[j])
        if (i >= 0 && !chosen[i]) chosen[i] = 1, front.push_back(i);
    }
    for (int ring = 0; ring < options.rings; ++ring) {
      std::vector<int32_t> next;
      for (int32_t i : front)
        for (int32_t k = problem.node_hex_offsets[i]; k < problem.node_hex_offsets[i + 1]; ++k)
          for (int32_t j : problem.hex_local_nodes[problem.node_hex[k]])
            if (j >= 0 && !chosen[j]) chosen[j] = 1, next.push_back(j);
      front.swap(next);
    }
    std::vector<int32_t> var_of(n, -1);
    for (int32_t i = 0; i < n; ++i)
      if (chosen[i] && moves(i)) {
        var_of[i] = static_cast<int32_t>(nodes_.size());
        nodes_.push_back(problem.nodes[i]);
        var_problem_.push_back(i);
        if (problem.slides[i].kind != SlideKind::free) sliding_.push_back(var_of[i]);
      }
    return var_of;
  }

  /// The boundary faces of the sliding variables, each once (guard_faces_): an accepted step
  /// keeps them on the reference surface (NodeProblem::surface), or the line search cuts it.
  void sliding_guard_faces_collect() {
    const NodeProblem& problem = problem_;
    if (!problem.surface || problem.node_face_offsets.empty()) return;
    for (int32_t v : sliding_)
      for (int32_t k = problem.node_face_offsets[var_problem_[v]];
           k < problem.node_face_offsets[var_problem_[v] + 1]; ++k)
        guard_faces_.push_back(problem.node_face[k]);
    std::sort(guard_faces_.begin(), guard_faces_.end());
    guard_faces_.erase(std::unique(guard_faces_.begin(), guard_faces_.end()), guard_faces_.end());
  }

  /// The objective's hexes (those with a variable corner, problem order) with their edge-ratio
  /// caps, corner variables and moving samples, and per variable its (hex, corner) pairs.
  void objective_hexes_build(const std::vector<int32_t>& var_of) {
    const NodeProblem& problem = problem_;
    for (size_t j = 0; j < problem.hexes.size(); ++j) {
      std::array<int32_t, 8> vars;
      bool any = false;
      for (int c = 0; c < 8; ++c) {
        const int32_t i = problem.hex_local_nodes[j][c];
        vars[c] = i >= 0 ? var_of[i] : -1;
        any = any || vars[c] >= 0;
      }
      if (!any) continue;
      std::array<bool, 8> corner_moves;
      for (int c = 0; c < 8; ++c) corner_moves[c] = vars[c] >= 0;
      hexes_.push_back(problem.hexes[j]);
      edge_caps_.push_back(
          hex_edge_ratio_cap(hex_points(mesh_, problem.hexes[j]), options_.max_edge_ratio));
      hex_vars_.push_back(vars);
      masks_.push_back(sample_mask(corner_moves));
    }
    // Variable -> (objective hex, corner), CSR, in hex order.
    var_offsets_.assign(nodes_.size() + 1, 0);
    for (const auto& vars : hex_vars_)
      for (int32_t v : vars)
        if (v >= 0) ++var_offsets_[v + 1];
    for (size_t v = 0; v < nodes_.size(); ++v) var_offsets_[v + 1] += var_offsets_[v];
    var_items_.resize(var_offsets_.back());
    std::vector<int32_t> cursor(var_offsets_.begin(), var_offsets_.end() - 1);
    for (size_t h = 0; h < hex_vars_.size(); ++h)
      for (int c = 0; c < 8; ++c)
        if (hex_vars_[h][c] >= 0) var_items_[cursor[hex_vars_[h][c]]++] = {int32_t(h), c};
  }

  /// The evaluation's buffers, the mean edge length of the objective's hexes (the step unit),
  /// and the threads an evaluation uses.
  void evaluation_buffers_size() {
    samples_.resize(hexes_.size());
    cap_samples_.assign(hexes_.size(), std::numeric_limits<double>::infinity());
    hex_gradient_.resize(hexes_.size());
    const int64_t chunks = parallel_chunk_count(static_cast<int64_t>(hexes_.size()), chunk_hexes);
    chunk_min_.resize(chunks);
    chunk_cap_min_.resize(chunks);
    chunk_sum_.resize(chunks);
    double edges = 0;
    for (int32_t h : hexes_) {
      const Corners p = hex_points(mesh_, h);
      for (const auto& e : hex_edges) edges += (p[e[1]] - p[e[0]]).norm();
    }
    mean_edge_ = hexes_.empty() ? 0.0 : edges / (12.0 * static_cast<double>(hexes_.size()));
    // Threads start per evaluation: below a few thousand hexes that costs more than it saves.
    threads_ = hexes_.size() < 8 * chunk_hexes ? 1 : std::max(options_.threads, 1);
  }

  HexMesh& mesh_;
  const NodeProblem& problem_;
  const JointAscentOptions& options_;
  std::vector<int32_t> nodes_;        // variable -> mesh node
  std::vector<int32_t> var_problem_;  // variable -> problem node
  std::vector<int32_t> sliding_;      // the sliding variables, ascending
  std::vector<SlideState> states_;    // per sliding variable
  std::vector<int32_t> hexes_;        // objective hexes (mesh ids)
  std::vector<double> edge_caps_;     // per objective hex: hex_edge_ratio_cap
  std::vector<int32_t> guard_faces_;  // NodeProblem::faces a sliding variable is a corner of
  std::vector<std::array<int32_t, 8>> hex_vars_;  // per objective hex: corner variables
  std::vector<uint16_t> masks_;       // per objective hex: its samples that move (sample_mask)
  std::vector<int32_t> var_offsets_;  // variable -> var_items_
  std::vector<std::pair<int32_t, int>> var_items_;  // (objective hex, corner)
  std::vector<std::array<double, 9>> samples_;      // per objective hex
  std::vector<Corners> hex_gradient_;               // per objective hex, per corner
  std::vector<double> cap_samples_;                 // per objective hex: hex_cap_sample
  std::vector<double> chunk_min_, chunk_cap_min_, chunk_sum_;
  double mean_edge_ = 0, last_floor_ = 0, last_sum_ = 1;
  int threads_ = 1;
};

/// Per problem node: 1 if it, or a problem node sharing a hex with it, is no longer at
/// `before` (per problem node).
std::vector<uint8_t> nodes_moved_and_around(const HexMesh& mesh, const NodeProblem& problem,
                                            const std::vector<Vec3>& before) {
  const size_t n = problem.nodes.size();
  std::vector<uint8_t> out(n, 0);
  for (size_t i = 0; i < n; ++i) {
    if (mesh.points[problem.nodes[i]] == before[i]) continue;
    for (int32_t k = problem.node_hex_offsets[i]; k < problem.node_hex_offsets[i + 1]; ++k)
      for (int32_t j : problem.hex_local_nodes[problem.node_hex[k]])
        if (j >= 0) out[j] = 1;
  }
  return out;
}

/// The pairs (s, y) of f = -KS the L-BFGS history keeps, oldest first.
using AscentHistory = std::deque<std::pair<Eigen::VectorXd, Eigen::VectorXd>>;

/// Step 3's quasi-Newton direction: the two-loop recursion on f = -KS (gradient -g) over
/// `history`, d = -H (-g). `alpha`: scratch of the recursion.
Eigen::VectorXd ascent_direction_two_loop(const AscentHistory& history,
                                          const Eigen::VectorXd& gradient,
                                          std::vector<double>& alpha) {
  Eigen::VectorXd d = gradient;
  alpha.assign(history.size(), 0.0);
  for (int k = static_cast<int>(history.size()) - 1; k >= 0; --k) {
    const auto& [s, y] = history[k];
    alpha[k] = s.dot(d) / y.dot(s);
    d -= alpha[k] * y;
  }
  if (!history.empty()) {
    const auto& [s, y] = history.back();
    d *= s.dot(y) / y.dot(y);
  }
  for (size_t k = 0; k < history.size(); ++k) {
    const auto& [s, y] = history[k];
    d += (alpha[k] - y.dot(d) / y.dot(s)) * s;
  }
  return d;
}

/// Step 3's line search from x (KS `value`, gradient `gradient`) along d: the step is capped so
/// that no node moves more than `cap`, then halved (at most 30 times) until the Armijo
/// condition holds and the guarded faces stay on the surface. True if a step was accepted:
/// `trial` (before the slides' projection), its KS and its minimum are then that step's.
bool ascent_step_search(JointProblem& joint, const Eigen::VectorXd& x, const Eigen::VectorXd& d,
                        const Eigen::VectorXd& gradient, double value, double cap,
                        Eigen::VectorXd& trial, double& trial_value, double& trial_min) {
  // A sliding variable's entry of d keeps the component normal to its slide that L-BFGS's
  // history gives it (the projection takes it out): projecting d onto the tangents first
  // measured lower (docs/placement-and-smoothing.md, 'Smoothing's joint ascent').
  double t = 1.0;
  const double largest = joint.largest_move(d);
  if (largest > cap) t = cap / largest;
  const double slope = d.dot(gradient);
  for (int halving = 0; halving < 30; ++halving, t *= 0.5) {
    trial = x + t * d;
    trial_value = joint.evaluate(trial, trial_min, nullptr);
    if (trial_value >= value + 1e-4 * t * slope && joint.faces_on_surface()) return true;
  }
  return false;
}

}  // namespace

SweepsAndAscentStats nodes_sweep_and_ascend(HexMesh& mesh, const NodeProblem& problem,
                                            NodeOptimizerOptions sweeps,
                                            const JointAscentOptions& joint, double ascend_below) {
  SweepsAndAscentStats stats;
  const NodeOptimizerStats first = nodes_optimize(mesh, problem, sweeps);
  stats.sweeps = first.sweeps;
  if (sweeps.max_sweeps <= 0 || joint.max_iterations <= 0) return stats;
  if (!(first.min_after < ascend_below)) return stats;
  // Each round ascends with a sharper soft minimum: after the sweeps many hexes sit next to the
  // minimum, and KS's log(n) / beta gap would let the ascent trade the minimum for them.
  JointAscentOptions round_options = joint;
  double reached = first.min_after;
  for (int round = 0; round < std::max(joint.rounds, 1); ++round) {
    std::vector<Vec3> before;
    before.reserve(problem.nodes.size());
    for (int32_t v : problem.nodes) before.push_back(mesh.points[v]);
    const JointAscentStats ascent = nodes_ascend_jointly(mesh, problem, round_options);
    stats.joint_iterations += ascent.iterations;
    if (!(ascent.min_after > ascent.min_before)) break;
    ++stats.joint_rounds;
    sweeps.initially_active = nodes_moved_and_around(mesh, problem, before);
    const NodeOptimizerStats again = nodes_optimize(mesh, problem, sweeps);
    stats.sweeps += again.sweeps;
    if (!(again.min_after > reached + joint.round_gain) || !(again.min_after < ascend_below)) break;
    reached = again.min_after;
    round_options.beta *= joint.round_beta_growth;
  }
  return stats;
}

JointAscentStats nodes_ascend_jointly(HexMesh& mesh, const NodeProblem& problem,
                                      const JointAscentOptions& options) {
  JointAscentStats stats;
  JointProblem joint(mesh, problem, options);
  stats.sliding_nodes = joint.sliding();
  stats.free_nodes = joint.variables() / 3 - stats.sliding_nodes;
  stats.hexes = joint.hexes();
  if (joint.hexes() == 0 || joint.variables() == 0) return stats;
  const Eigen::VectorXd start = joint.position();
  stats.min_before = joint.true_min();
  stats.min_after = stats.min_before;
  if (!(stats.min_before > 0) || options.max_iterations <= 0) return stats;

  Eigen::VectorXd x = start, gradient, best = start;
  double min, best_min;
  double value = joint.evaluate(x, min, &gradient);
  if (!std::isfinite(value)) {  // the start past a cap: nothing to ascend from
    joint.restore(start);
    return stats;
  }
  // A face the start's projection already takes past the surface guard (a node the sweeps
  // left at the guard's edge, moved by the projection's rounding) is not guarded: the others
  // must keep passing. Should the end fail the check there, the pipeline pins it and smooths
  // again.
  joint.unguard_failing_faces();
  best_min = min;
  const double cap = 0.25 * joint.mean_edge();
  AscentHistory history;
  std::vector<double> alpha;
  int flat = 0, since_best = 0;
  for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
    Eigen::VectorXd d = ascent_direction_two_loop(history, gradient, alpha);
    if (history.empty() || !(d.dot(gradient) > 0)) {
      history.clear();
      const double largest = joint.largest_move(gradient);
      if (!(largest > 0)) break;
      d = gradient * (0.02 * joint.mean_edge() / largest);
    }
    Eigen::VectorXd trial, trial_gradient;
    double trial_value = -std::numeric_limits<double>::infinity(), trial_min = 0;
    const bool accepted =
        ascent_step_search(joint, x, d, gradient, value, cap, trial, trial_value, trial_min);
    ++stats.iterations;
    if (!accepted) {
      if (history.empty()) break;
      history.clear();  // a poor quasi-Newton model: steepest ascent next
      continue;
    }
    joint.gradient_at_last(trial_gradient);
    if (joint.sliding() > 0) trial = joint.position();             // where the slides put the step
    Eigen::VectorXd s = trial - x, y = gradient - trial_gradient;  // y of f = -KS
    if (s.dot(y) > 1e-12 * s.norm() * y.norm()) {
      history.emplace_back(std::move(s), std::move(y));
      if (static_cast<int>(history.size()) > std::max(options.memory, 1)) history.pop_front();
    }
    flat = trial_value - value < 1e-9 ? flat + 1 : 0;
    x = std::move(trial);
    gradient = std::move(trial_gradient);
    value = trial_value;
    if (trial_min > best_min) {
      since_best = trial_min > best_min + 1e-5 ? 0 : since_best + 1;
      best_min = trial_min;
      best = x;
    } else {
      ++since_best;
    }
    // KS can keep rising by the samples next to the minimum while the minimum itself stays.
    if (flat >= 5 || since_best >= options.stall_iterations) break;
  }
  joint.restore(best);
  stats.min_after = joint.true_min();
  if (stats.min_after < stats.min_before) {
    joint.restore(start);
    stats.min_after = stats.min_before;
  }
  return stats;
}

}  // namespace hexrefine
