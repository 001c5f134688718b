/// \file
/// Local node optimization: one node at a time, raise the worst scaled Jacobian of the hexes
/// around it.
///
/// Sources (formulas and facts only):
/// - L. A. Freitag, P. Plassmann, "Local optimization-based simplicial mesh untangling and
///   improvement", IJNME 49 (2000) 109-125: optimize one free node at a time to maximize the
///   minimum quality of the elements around it (a max-min problem); untangling is the same
///   problem with a signed measure, whose minimum is negative while a neighbour is inverted.
/// - G. Kreisselmeier, R. Steinhauser, "Systematic control design by optimizing a vector
///   performance index" (1979): the KS function m - log(sum exp(-beta (s_i - m))) / beta, a
///   smooth lower bound of min s_i whose gradient is the softmax-weighted sum of the gradients.
/// - P. M. Knupp, "Algebraic mesh quality metrics", SIAM J. Sci. Comput. 23 (2001) 193-218: the
///   inverse mean ratio |A|_F^2 / (3 det(A)^(2/3)) of a corner matrix A (1 for a scaled
///   rotation, unbounded as det(A) -> 0+), a barrier objective for smoothing.
/// - L. A. Freitag, "On combining Laplacian and optimization-based mesh smoothing techniques",
///   AMD Trends in Unstructured Mesh Generation 220 (1997) 37-43: "smart" Laplacian (a move is
///   kept only if the local quality does not get worse), optimization only where it does not
///   suffice.
///
/// Per visit of a node (positions of the other nodes fixed; nodes whose worst hex is already at
/// or above visit_below are not visited):
///  1. (smoothing) the Laplacian candidate, tried as a full, half and quarter move, then one
///     damped Newton step on the sum of inverse mean ratios of the corner matrices that depend on
///     a free node;
///  2. ascent of the KS soft minimum of the nine scaled-Jacobian samples of every hex around
///     the node (analytic gradients: hex_scaled_jacobian_gradients), the gradient projected onto
///     the node's slide (the tangent plane of its patch, the direction of its segment), a step
///     length searched from 5 % of the local edge length, the candidate projected back onto the
///     slide (closest point on the patch or segment, or on the nearest of several).
/// Every candidate goes through one guard: the worst hex around the node must improve (or, for
/// the Laplacian and Newton candidates, stay and the sum of their scaled Jacobians rise), and
/// with keep_positive no hex with a positive scaled Jacobian may become non-positive. Hexes
/// elsewhere do not change, so the minimum over the problem never decreases. With a surface
/// guard (NodeProblem::surface) the visit must also end with every boundary face at the node on
/// the reference surface as the checker tests it; else it goes back to the latest position it
/// passed through that does (its start does).
/// Sweeps visit the active nodes worst first (counting sort of the local minimum, ties by node
/// id); the movable nodes of the hexes around a node that moved become active for the next
/// sweep; they stop after max_sweeps, when no node is active, or when a sweep moved no node by
/// more than 1e-7 of its local edge length or improved neither the minimum (by 1e-9) nor the
/// mean (by 1e-6).
/// Threads: a sweep is cut into levels of its worst-first order (a node one level above the
/// highest earlier node it shares a hex with; the level scheduling of a sparse triangular solve
/// applied to Gauss-Seidel). A visit reads and writes only its node and what lies in the hexes
/// around it, so visiting level by level replays the serial sweep exactly, and the nodes of one
/// level, which share no hex, are visited by several workers (each with its own scratch) at
/// once. One thread visits in the worst-first order itself (no levels to build). Output is
/// bit-identical for any thread count.

#include "algorithms/placement/node_optimizer.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

#include "mesh/hex_convention.hpp"
#include "mesh/parallel.hpp"
#include "mesh/quality.hpp"

namespace hexrefine {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

void hex_scaled_jacobian_gradients(const std::array<Vec3, 8>& p, int vertex,
                                   std::array<double, 9>& samples, std::array<Vec3, 9>& gradients) {
  auto sample = [&](const std::array<Vec3, 3>& a, const std::array<double, 3>& c, int j) {
    const double l0 = a[0].norm(), l1 = a[1].norm(), l2 = a[2].norm();
    const double lengths = l0 * l1 * l2;
    gradients[j].setZero();
    if (!(lengths > std::numeric_limits<double>::min())) {
      samples[j] = 0.0;
      return;
    }
    const std::array<Vec3, 3> cofactor = {a[1].cross(a[2]), a[2].cross(a[0]), a[0].cross(a[1])};
    const double s = a[0].dot(cofactor[0]) / lengths;
    samples[j] = std::clamp(s, -1.0, 1.0);
    const double squared[3] = {l0 * l0, l1 * l1, l2 * l2};
    for (int k = 0; k < 3; ++k)
      if (c[k] != 0) gradients[j] += c[k] * (cofactor[k] / lengths - s * a[k] / squared[k]);
  };
  for (int v = 0; v < 8; ++v) {
    std::array<Vec3, 3> a;
    std::array<double, 3> c{};
    for (int k = 0; k < 3; ++k) {
      const int e = hex_vertex_edges[v][k];
      a[k] = p[hex_edges[e][1]] - p[hex_edges[e][0]];
      c[k] = (hex_edges[e][1] == vertex) - (hex_edges[e][0] == vertex);
    }
    sample(a, c, v);
  }
  std::array<Vec3, 3> a;
  std::array<double, 3> c{};
  for (int k = 0; k < 3; ++k) {
    a[k].setZero();
    for (int e : hex_axis_edges[k]) {
      a[k] += p[hex_edges[e][1]] - p[hex_edges[e][0]];
      c[k] += 0.25 * ((hex_edges[e][1] == vertex) - (hex_edges[e][0] == vertex));
    }
    a[k] /= 4.0;
  }
  sample(a, c, 8);
}

bool node_faces_on_surface(const NodeProblem& problem, const HexMesh& mesh, int32_t i) {
  if (!problem.surface || problem.node_face_offsets.empty()) return true;
  for (int32_t k = problem.node_face_offsets[i]; k < problem.node_face_offsets[i + 1]; ++k) {
    const auto& f = problem.faces[problem.node_face[k]];
    if (!reference_surface_holds_face(*problem.surface, {mesh.points[f[0]], mesh.points[f[1]],
                                                         mesh.points[f[2]], mesh.points[f[3]]}))
      return false;
  }
  return true;
}

double hex_edge_ratio_cap(const HexCorners& p, double limit) {
  if (!(limit > 0)) return std::numeric_limits<double>::infinity();
  return std::max(limit, hex_edge_ratio(p) * (1 + 1e-9));
}

void node_problem_connect(NodeProblem& problem, const HexMesh& mesh,
                          const std::vector<int32_t>& candidates) {
  const int32_t n = static_cast<int32_t>(problem.nodes.size());
  std::vector<int32_t> local(mesh.points.size(), -1);
  for (int32_t i = 0; i < n; ++i) local[problem.nodes[i]] = i;
  problem.hexes.clear();
  problem.node_hex_offsets.assign(static_cast<size_t>(n) + 1, 0);
  for (int32_t h : candidates) {
    bool touches = false;
    for (int32_t v : mesh.hexes[h])
      if (local[v] >= 0) {
        touches = true;
        ++problem.node_hex_offsets[local[v] + 1];
      }
    if (touches) problem.hexes.push_back(h);
  }
  for (int32_t i = 0; i < n; ++i) problem.node_hex_offsets[i + 1] += problem.node_hex_offsets[i];
  problem.node_hex.resize(problem.node_hex_offsets[n]);
  std::vector<int32_t> cursor(problem.node_hex_offsets.begin(), problem.node_hex_offsets.end() - 1);
  problem.hex_local_nodes.resize(problem.hexes.size());
  for (size_t k = 0; k < problem.hexes.size(); ++k) {
    const HexCell& c = mesh.hexes[problem.hexes[k]];
    for (int corner = 0; corner < 8; ++corner) {
      const int32_t j = local[c[corner]];
      problem.hex_local_nodes[k][corner] = j;
      if (j >= 0) problem.node_hex[cursor[j]++] = static_cast<int32_t>(k);
    }
  }
}

namespace {

/// What the workers of one nodes_optimize call share: per problem hex its scaled Jacobian, per
/// movable node its start and slide state, and the phase. A worker writes only the entries of the
/// node it visits and of the hexes around it, so workers visiting nodes that share no hex never
/// touch the same entry.
struct OptimizerShared {
  std::vector<double> quality;
  std::vector<double> edge_cap;  // per problem hex: hex_edge_ratio_cap
  std::vector<Vec3> start;
  std::vector<SlideState> state;
  bool soft_phase = false;
  double beta = 60.0;
};

/// One worker: the visits of one thread, with its own scratch buffers, over `shared`.
/// Length: a class, not a function; its methods are short, the candidates and the guard of one
/// node visit, kept in one class because they share the worker's scratch and its deferred
/// surface guard.
class Optimizer {
 public:
  /// `initialize`: this first worker fills `shared` (qualities, start positions, every sliding
  /// node put on its slide); the others only bind to it.
  Optimizer(HexMesh& mesh, const NodeProblem& problem, const NodeOptimizerOptions& options,
            OptimizerShared& shared, bool initialize)
      : mesh_(mesh),
        problem_(problem),
        options_(options),
        quality_(shared.quality),
        start_(shared.start),
        state_(shared.state),
        shared_(shared) {
    size_t valence = 0;
    for (size_t i = 0; i < problem.nodes.size(); ++i)
      valence = std::max(valence, static_cast<size_t>(problem.node_hex_offsets[i + 1] -
                                                      problem.node_hex_offsets[i]));
    trial_.resize(valence);
    if (!initialize) return;
    quality_.resize(problem.hexes.size());
    mesh_scaled_jacobians(mesh, problem.hexes, quality_);
    shared.edge_cap.resize(problem.hexes.size());
    for (size_t k = 0; k < problem.hexes.size(); ++k)
      shared.edge_cap[k] =
          hex_edge_ratio_cap(hex_points(mesh, problem.hexes[k]), options.max_edge_ratio);
    state_.resize(problem.nodes.size());
    start_.resize(problem.nodes.size());
    for (size_t i = 0; i < problem.nodes.size(); ++i) start_[i] = mesh.points[problem.nodes[i]];
    for (size_t i = 0; i < problem.nodes.size(); ++i) slide_start(static_cast<int32_t>(i));
  }

  const std::vector<double>& quality() const { return quality_; }
  const std::vector<Vec3>& start() const { return start_; }

  /// Lowest scaled Jacobian of the hexes around local node i.
  double local_min(int32_t i) const {
    double m = 1.0;
    for (int32_t k = problem_.node_hex_offsets[i]; k < problem_.node_hex_offsets[i + 1]; ++k)
      m = std::min(m, quality_[problem_.node_hex[k]]);
    return m;
  }

  /// Mean length of the edges at local node i (the step-size unit).
  double scale(int32_t i) const {
    double sum = 0;
    int count = 0;
    const int32_t node = problem_.nodes[i];
    for_each_hex(i, [&](int32_t, const HexCell& c, int vertex) {
      for (int k = 0; k < 3; ++k) {
        const int e = hex_vertex_edges[vertex][k];
        const int w = hex_edges[e][0] == vertex ? hex_edges[e][1] : hex_edges[e][0];
        sum += (mesh_.points[c[w]] - mesh_.points[node]).norm();
        ++count;
      }
    });
    return count ? sum / count : 0.0;
  }

  /// Visits local node i once; returns the distance it moved.
  double visit(int32_t i) {
    const Vec3 before = mesh_.points[problem_.nodes[i]];
    if (!(local_min(i) < options_.visit_below)) return 0.0;
    // The surface guard (NodeProblem::surface) projects onto patches and costs more than a
    // candidate's quality: it is asked once, of where the visit ends, and only if that fails
    // of the positions the visit went through, latest first (the visit's start passed it).
    guard_deferred_ = problem_.surface && !problem_.node_face_offsets.empty() &&
                      problem_.node_face_offsets[i + 1] > problem_.node_face_offsets[i];
    visited_.clear();
    visited_quality_.clear();
    if (guard_deferred_) remember_visited(i, before, state_[i]);
    if (options_.laplacian) laplacian(i);
    if (options_.mean_ratio) mean_ratio_newton(i);
    if (options_.ascent) ascent(i);
    if (guard_deferred_) {
      guard_deferred_ = false;
      if (visited_.size() > 1 && !node_faces_on_surface(problem_, mesh_, i)) {
        size_t k = visited_.size() - 1;
        while (k > 0) {
          --k;
          restore_visited(i, k);
          if (k == 0 || node_faces_on_surface(problem_, mesh_, i)) break;
        }
      }
    }
    return (mesh_.points[problem_.nodes[i]] - before).norm();
  }

  template <class Visit>
  void for_each_hex(int32_t i, const Visit& visit) const {
    const int32_t node = problem_.nodes[i];
    for (int32_t k = problem_.node_hex_offsets[i]; k < problem_.node_hex_offsets[i + 1]; ++k) {
      const int32_t local_hex = problem_.node_hex[k];
      const HexCell& c = mesh_.hexes[problem_.hexes[local_hex]];
      int vertex = 0;
      while (c[vertex] != node) ++vertex;
      visit(local_hex, c, vertex);
    }
  }

 private:
  // --- slides ------------------------------------------------------------------------------

  const NodeSlide& slide(int32_t i) const { return problem_.slides[i]; }

  /// The point of the slide of node i nearest to x, and the state there (`s` starts as the
  /// node's current state: the projection's warm start).
  Vec3 slide_project(int32_t i, const Vec3& x, SlideState& s) const {
    return hexrefine::slide_project(slide(i), problem_.geometry, x, s);
  }

  /// Puts node i on its slide (the position it starts from).
  void slide_start(int32_t i) {
    if (slide(i).kind == SlideKind::free) return;
    const int32_t node = problem_.nodes[i];
    SlideState s;
    const Vec3 x = slide_project(i, mesh_.points[node], s);
    state_[i] = s;
    if (x != mesh_.points[node]) {
      // A node an earlier ascent left at the edge of the surface guard (on its slide up to
      // the projection's rounding) stays rather than be projected across that edge.
      if (!problem_.node_face_offsets.empty()) {
        const Vec3 keep = mesh_.points[node];
        mesh_.points[node] = x;
        const bool on_surface = node_faces_on_surface(problem_, mesh_, i);
        mesh_.points[node] = keep;
        if (!on_surface) return;
      }
      double m;
      trial_min(i, x, m);
      commit(i, x, s);
    }
  }

  /// The gradient g projected onto the tangent of node i's slide at its current state.
  Vec3 slide_tangent(int32_t i, const Vec3& g) const {
    return hexrefine::slide_tangent(slide(i), problem_.geometry, state_[i], g);
  }

  // --- guard -------------------------------------------------------------------------------

  /// The hexes around local node i with the node at x: false if keep_positive forbids it, or if
  /// some hex is at or below `at_least` (the evaluation stops there: the candidate cannot be
  /// kept); the new local minimum and the change of the sum of scaled Jacobians. The values stay
  /// in trial_ for commit().
  bool trial_min(int32_t i, const Vec3& x, double& local_min, double* sum_gain = nullptr,
                 double at_least = -std::numeric_limits<double>::infinity()) {
    const int32_t node = problem_.nodes[i];
    const Vec3 keep = mesh_.points[node];
    mesh_.points[node] = x;
    bool allowed = true;
    local_min = 1.0;
    double gain = 0;
    size_t t = 0;
    const int32_t first = problem_.node_hex_offsets[i], end = problem_.node_hex_offsets[i + 1];
    std::array<double, 2> pair{};
    std::array<HexCorners, 2> corners;
    for (int32_t k = first; k < end; ++k) {
      const int32_t local_hex = problem_.node_hex[k];
      const int lane = (k - first) % 2;
      // Two hexes per evaluation (the kernel's two lanes); an early stop wastes at most one.
      if (lane == 0) {
        corners[0] = hex_points(mesh_, problem_.hexes[local_hex]);
        corners[1] = hex_points(mesh_, problem_.hexes[problem_.node_hex[std::min(k + 1, end - 1)]]);
        pair = hex_scaled_jacobian_pair(corners[0], corners[1]);
      }
      const double q = pair[lane];
      // A hex stretched past its edge-ratio cap counts as inverted: not allowed.
      const double cap = shared_.edge_cap[local_hex];
      if (cap != std::numeric_limits<double>::infinity() && !(hex_edge_ratio(corners[lane]) <= cap))
        allowed = false;
      trial_[t++] = q;
      local_min = std::min(local_min, q);
      gain += q - quality_[local_hex];
      if (options_.keep_positive && quality_[local_hex] > 0 && !(q > 0)) allowed = false;
      if (!allowed || !(q > at_least)) {
        allowed = false;
        break;
      }
    }
    if (allowed && !guard_deferred_) allowed = node_faces_on_surface(problem_, mesh_, i);
    mesh_.points[node] = keep;
    if (sum_gain) *sum_gain = gain;
    return allowed;
  }

  void commit(int32_t i, const Vec3& x, const SlideState& s) {
    mesh_.points[problem_.nodes[i]] = x;
    state_[i] = s;
    size_t t = 0;
    for (int32_t k = problem_.node_hex_offsets[i]; k < problem_.node_hex_offsets[i + 1]; ++k)
      quality_[problem_.node_hex[k]] = trial_[t++];
    if (guard_deferred_) remember_visited(i, x, s);
  }

  /// Tries x0 + t (x - x0), t = 1, 1/2, 1/4, projected onto the slide; keeps the first whose
  /// local minimum does not drop and whose minimum or sum of scaled Jacobians rises.
  bool try_towards(int32_t i, const Vec3& x) {
    const Vec3 x0 = mesh_.points[problem_.nodes[i]];
    const double floor = local_min(i);
    for (double t : {1.0, 0.5, 0.25}) {
      SlideState s = state_[i];
      const Vec3 candidate = slide_project(i, x0 + t * (x - x0), s);
      if (candidate == x0) return false;
      double m, gain;
      if (trial_min(i, candidate, m, &gain, std::nextafter(floor, -1.0)) && m >= floor &&
          (m > floor + 1e-12 || gain > 1e-12)) {
        commit(i, candidate, s);
        return true;
      }
    }
    return false;
  }

  // --- candidates --------------------------------------------------------------------------

  void laplacian(int32_t i) {
    Vec3 target = Vec3::Zero();
    std::array<int32_t, 64> seen{};
    int count = 0;
    for_each_hex(i, [&](int32_t, const HexCell& c, int vertex) {
      for (int k = 0; k < 3; ++k) {
        const int e = hex_vertex_edges[vertex][k];
        const int32_t w = c[hex_edges[e][0] == vertex ? hex_edges[e][1] : hex_edges[e][0]];
        if (std::find(seen.begin(), seen.begin() + count, w) != seen.begin() + count ||
            count == static_cast<int>(seen.size()))
          continue;
        seen[count++] = w;
        target += mesh_.points[w];
      }
    });
    if (count) try_towards(i, target / count);
  }

  /// Sum of inverse mean ratios of the corner matrices that depend on node i with the node at
  /// x; +inf if one has det <= 0 (the barrier). `gradient` (if given) receives d/dx.
  double mean_ratio(int32_t i, const Vec3& x, Vec3* gradient) {
    const int32_t node = problem_.nodes[i];
    const Vec3 keep = mesh_.points[node];
    mesh_.points[node] = x;
    double sum = 0;
    if (gradient) gradient->setZero();
    bool finite = true;
    for_each_hex(i, [&](int32_t local_hex, const HexCell&, int vertex) {
      if (!finite) return;
      const HexCorners p = hex_points(mesh_, problem_.hexes[local_hex]);
      int corners[4] = {vertex, 0, 0, 0};
      for (int k = 0; k < 3; ++k) {
        const int e = hex_vertex_edges[vertex][k];
        corners[k + 1] = hex_edges[e][0] == vertex ? hex_edges[e][1] : hex_edges[e][0];
      }
      for (int v : corners) {
        const Mat3 a = hex_corner_jacobian(p, v);
        const double det = a.determinant();
        const double f = a.squaredNorm();
        if (!(det > 1e-14 * f * std::sqrt(f))) {
          finite = false;
          return;
        }
        const double g = std::cbrt(det * det);
        sum += f / (3.0 * g);
        if (gradient) {
          Vec3 c;
          for (int k = 0; k < 3; ++k) {
            const int e = hex_vertex_edges[v][k];
            c[k] = (hex_edges[e][1] == vertex) - (hex_edges[e][0] == vertex);
          }
          const Mat3 dmu = (2.0 / (3.0 * g)) * (a - (f / 3.0) * a.inverse().transpose());
          *gradient += dmu * c;
        }
      }
    });
    mesh_.points[node] = keep;
    return finite ? sum : std::numeric_limits<double>::infinity();
  }

  /// One damped Newton step on mean_ratio (free nodes; the Hessian by differences of the
  /// analytic gradient, eigenvalues clamped positive, backtracking while the sum does not fall).
  void mean_ratio_newton(int32_t i) {
    if (slide(i).kind != SlideKind::free) return;
    const double h = scale(i);
    if (!(h > 0)) return;
    const Vec3 x = mesh_.points[problem_.nodes[i]];
    Vec3 gradient;
    const double value = mean_ratio(i, x, &gradient);
    if (!std::isfinite(value) || gradient.norm() * h <= 1e-12 * value) return;
    const double delta = 1e-6 * h;
    Mat3 hessian;
    for (int j = 0; j < 3; ++j) {
      Vec3 shifted;
      if (!std::isfinite(mean_ratio(i, x + delta * Vec3::Unit(j), &shifted))) return;
      hessian.col(j) = (shifted - gradient) / delta;
    }
    Eigen::SelfAdjointEigenSolver<Mat3> eigen(0.5 * (hessian + hessian.transpose()));
    Vec3 lambda = eigen.eigenvalues();
    const double largest = lambda.cwiseAbs().maxCoeff();
    if (!(largest > 0)) return;
    for (int k = 0; k < 3; ++k) lambda[k] = std::max(lambda[k], 1e-6 * largest);
    const Mat3& v = eigen.eigenvectors();
    Vec3 step = -(v * lambda.cwiseInverse().asDiagonal() * v.transpose() * gradient);
    if (step.norm() > 0.5 * h) step *= 0.5 * h / step.norm();
    for (int halving = 0; halving < 20; ++halving, step *= 0.5)
      if (mean_ratio(i, x + step, nullptr) < value) {
        try_towards(i, x + step);
        return;
      }
  }

  /// KS soft minimum of the samples of the hexes around node i at its current position, and its
  /// gradient with respect to the node.
  double soft_min(int32_t i, Vec3& gradient) {
    const double beta = shared_.beta;
    samples_.clear();
    sample_gradients_.clear();
    for_each_hex(i, [&](int32_t local_hex, const HexCell&, int vertex) {
      std::array<double, 9> s;
      std::array<Vec3, 9> g;
      hex_scaled_jacobian_gradients(hex_points(mesh_, problem_.hexes[local_hex]), vertex, s, g);
      for (int j = 0; j < 9; ++j) {
        samples_.push_back(s[j]);
        sample_gradients_.push_back(g[j]);
      }
    });
    double m = 1.0;
    for (double s : samples_) m = std::min(m, s);
    double sum = 0;
    gradient.setZero();
    for (size_t j = 0; j < samples_.size(); ++j) {
      const double w = std::exp(-beta * (samples_[j] - m));
      sum += w;
      gradient += w * sample_gradients_[j];
    }
    gradient /= sum;
    return m - std::log(sum) / beta;
  }

  /// soft_min with node i at x (no gradient).
  double soft_min_at(int32_t i, const Vec3& x) {
    const int32_t node = problem_.nodes[i];
    const Vec3 keep = mesh_.points[node];
    mesh_.points[node] = x;
    Vec3 unused;
    const double value = soft_min(i, unused);
    mesh_.points[node] = keep;
    return value;
  }

  /// Ascent on node i: the KS soft minimum's gradient projected on the slide, a step searched
  /// from 5 % of the local edge length. The max-min phase keeps a step when the worst hex around
  /// the node improves; the smooth phase when the soft minimum (low beta) rises and keep_positive
  /// allows it.
  void ascent(int32_t i) {
    double current = shared_.soft_phase ? 0.0 : local_min(i);
    if (!shared_.soft_phase && current >= 1.0 - 1e-12) return;
    const double h = scale(i);
    if (!(h > 0)) return;
    double step = 0.05 * h;
    for (int iteration = 0; iteration < options_.ascent_steps; ++iteration) {
      Vec3 gradient;
      const double soft = soft_min(i, gradient);
      if (shared_.soft_phase) current = soft;
      const Vec3 direction = slide_tangent(i, gradient);
      if (!(direction.norm() > 1e-12 / h)) return;
      const Vec3 unit = direction.normalized();
      const Vec3 x = mesh_.points[problem_.nodes[i]];
      bool moved = false;
      for (int halving = 0; halving < 8; ++halving, step *= 0.5) {
        SlideState s = state_[i];
        const Vec3 candidate = slide_project(i, x + step * unit, s);
        if (candidate == x) continue;
        double m;
        const bool better =
            shared_.soft_phase
                ? soft_min_at(i, candidate) > current + 1e-12 && trial_min(i, candidate, m)
                : trial_min(i, candidate, m, nullptr, current + 1e-12);
        if (!better) continue;
        commit(i, candidate, s);
        if (!shared_.soft_phase) current = m;
        moved = true;
        step = std::min(2 * step, 0.25 * h);
        break;
      }
      if (!moved) return;
    }
  }

 public:
  /// Switches between the smooth phase (soft minimum with `beta` must rise) and the max-min
  /// phase (the true minimum must rise; beta 60 shapes the direction).
  void set_phase(bool soft, double beta) {
    shared_.soft_phase = soft;
    shared_.beta = beta;
  }
  /// Records where node i is in this visit and the qualities of the hexes around it there.
  void remember_visited(int32_t i, const Vec3& x, const SlideState& s) {
    visited_.push_back({x, s});
    for (int32_t k = problem_.node_hex_offsets[i]; k < problem_.node_hex_offsets[i + 1]; ++k)
      visited_quality_.push_back(quality_[problem_.node_hex[k]]);
  }

  /// Puts node i back at the visit's k-th recorded position with the qualities it had there
  /// (copied, not recomputed: only node i moved during the visit, so they are exact).
  void restore_visited(int32_t i, size_t k) {
    mesh_.points[problem_.nodes[i]] = visited_[k].first;
    state_[i] = visited_[k].second;
    const int32_t first = problem_.node_hex_offsets[i],
                  count = problem_.node_hex_offsets[i + 1] - first;
    for (int32_t j = 0; j < count; ++j)
      quality_[problem_.node_hex[first + j]] = visited_quality_[k * count + j];
  }

  /// Moves node i to x (a saved position), its state and the qualities updated.
  void restore(int32_t i, const Vec3& x) {
    SlideState s = state_[i];
    slide_project(i, x, s);
    double m;
    trial_min(i, x, m);
    commit(i, x, s);
  }

 private:
  HexMesh& mesh_;
  const NodeProblem& problem_;
  const NodeOptimizerOptions& options_;
  std::vector<double>& quality_;
  std::vector<Vec3>& start_;
  std::vector<SlideState>& state_;
  OptimizerShared& shared_;
  std::vector<double> trial_, samples_;  // this worker's scratch
  bool guard_deferred_ = false;          // in a visit whose surface guard runs at its end
  std::vector<std::pair<Vec3, SlideState>> visited_;  // where the visit went, its start first
  std::vector<double> visited_quality_;  // per visited_ entry, the qualities around the node
  std::vector<Vec3> sample_gradients_;
};

void min_mean(const std::vector<double>& q, double& min, double& mean) {
  min = 1.0;
  mean = 1.0;
  if (q.empty()) return;
  double sum = 0;
  for (double x : q) min = std::min(min, x), sum += x;
  mean = sum / static_cast<double>(q.size());
}

/// What the sweeps of one nodes_optimize call share: the workers (the first one also serves the
/// serial parts), the worst-first order and its levels, the active nodes, and the phase.
struct NodeSweeps {
  NodeSweeps(const NodeProblem& problem_in, const NodeOptimizerOptions& options_in,
             std::vector<Optimizer>& workers_in)
      : problem(problem_in),
        options(options_in),
        workers(workers_in),
        threads(static_cast<int>(workers_in.size())),
        n(static_cast<int32_t>(problem_in.nodes.size())),
        active(n, 1),
        next_active(n, 0),
        level(n, -1) {}

  const NodeProblem& problem;
  const NodeOptimizerOptions& options;
  std::vector<Optimizer>& workers;
  int threads;
  int32_t n;
  /// Worst-first order by a counting sort on the quantised local minimum (linear, stable by id).
  static constexpr int buckets = 4096;
  std::vector<int32_t> bucket_offsets = std::vector<int32_t>(buckets + 1), order, keys;
  /// Per node: 1 if it is visited in this sweep, in the next one.
  std::vector<char> active, next_active;
  /// Per node its level in the current sweep (-1: not reached yet); the sweep's nodes by level.
  std::vector<int32_t> level, level_offsets, by_level;
  /// Per worker: the largest move of this sweep over the local edge length.
  std::vector<double> largest_relative_move;
  /// The smooth phase runs its sweeps to the end (its soft objective).
  bool soft = false;
};

/// The active nodes into s.order, worst first (ties by id); false when none is active.
bool active_nodes_order_worst_first(NodeSweeps& s) {
  const Optimizer& optimizer = s.workers.front();
  constexpr int buckets = NodeSweeps::buckets;
  std::fill(s.bucket_offsets.begin(), s.bucket_offsets.end(), 0);
  s.keys.clear();
  for (int32_t i = 0; i < s.n; ++i) {
    if (!s.active[i]) continue;
    const double q = std::clamp(optimizer.local_min(i), -1.0, 1.0);
    s.keys.push_back(std::min(buckets - 1, static_cast<int>((q + 1.0) * 0.5 * buckets)));
    ++s.bucket_offsets[s.keys.back() + 1];
  }
  if (s.keys.empty()) return false;
  for (int b = 0; b < buckets; ++b) s.bucket_offsets[b + 1] += s.bucket_offsets[b];
  s.order.resize(s.keys.size());
  size_t k = 0;
  for (int32_t i = 0; i < s.n; ++i)
    if (s.active[i]) s.order[s.bucket_offsets[s.keys[k++]]++] = i;
  return true;
}

/// Worker w visits every stride-th node of nodes[begin, end), from `begin`; the nodes around
/// a node that moved become active for the next sweep.
void nodes_visit(NodeSweeps& s, Optimizer& worker, int64_t w, const std::vector<int32_t>& nodes,
                 int64_t begin, int64_t end, int64_t stride) {
  const NodeProblem& problem = s.problem;
  for (int64_t at = begin; at < end; at += stride) {
    const int32_t i = nodes[at];
    // A node visit() would leave (its worst hex at or above visit_below) costs no scale.
    if (!(worker.local_min(i) < s.options.visit_below)) continue;
    const double h = worker.scale(i);
    const double moved = worker.visit(i);
    if (!(moved > 0)) continue;
    if (h > 0) s.largest_relative_move[w] = std::max(s.largest_relative_move[w], moved / h);
    // Moves below a thousandth of the local edge length do not wake the neighbours.
    if (h > 0 && moved < 1e-3 * h) continue;
    for (int32_t m = problem.node_hex_offsets[i]; m < problem.node_hex_offsets[i + 1]; ++m)
      for (int32_t j : problem.hex_local_nodes[problem.node_hex[m]])
        if (j >= 0) std::atomic_ref<char>(s.next_active[j]).store(1, std::memory_order_relaxed);
  }
}

/// Visits s.order level by level on s.threads workers. A node's level is one above the highest
/// level of the nodes before it in the order that share a hex with it. A visit reads and writes
/// only its own node, the nodes and hexes around it: visiting level by level, each node sees
/// exactly what it would see in the serial sweep (the nodes before it that it depends on are in
/// lower levels, those after it in higher ones), so the result is the serial sweep's, bit for
/// bit, and the nodes of one level, which share no hex, can be visited in any order on any
/// number of threads.
void active_nodes_visit_by_levels(NodeSweeps& s) {
  const NodeProblem& problem = s.problem;
  Optimizer& optimizer = s.workers.front();
  std::vector<int32_t>& level = s.level;
  std::vector<int32_t>& level_offsets = s.level_offsets;
  std::vector<int32_t>& by_level = s.by_level;
  int32_t levels = 0;
  for (int32_t i : s.order) {
    int32_t l = 0;
    for (int32_t m = problem.node_hex_offsets[i]; m < problem.node_hex_offsets[i + 1]; ++m)
      for (int32_t j : problem.hex_local_nodes[problem.node_hex[m]])
        if (j >= 0 && j != i && level[j] >= l) l = level[j] + 1;
    level[i] = l;
    levels = std::max(levels, l + 1);
  }
  level_offsets.assign(static_cast<size_t>(levels) + 1, 0);
  for (int32_t i : s.order) ++level_offsets[level[i] + 1];
  for (int32_t l = 0; l < levels; ++l) level_offsets[l + 1] += level_offsets[l];
  by_level.resize(s.order.size());
  for (int32_t i : s.order) by_level[level_offsets[level[i]]++] = i;
  for (int32_t i : s.order) level[i] = -1;
  for (int32_t l = levels; l > 0; --l) level_offsets[l] = level_offsets[l - 1];
  level_offsets[0] = 0;
  const int threads = s.threads;
  for (int32_t l = 0; l < levels; ++l) {
    // The nodes visit() would leave (their worst hex at or above visit_below, which
    // within a level only their own visit changes) cost nothing: dropped first, so that
    // the threads share the nodes that do cost.
    int64_t end = level_offsets[l];
    for (int64_t at = level_offsets[l]; at < level_offsets[l + 1]; ++at)
      if (optimizer.local_min(by_level[at]) < s.options.visit_below) by_level[end++] = by_level[at];
    const int64_t begin = level_offsets[l], size = end - begin;
    // Small levels are not worth a thread.
    if (size < 64) {
      nodes_visit(s, optimizer, 0, by_level, begin, end, 1);
      continue;
    }
    // Worker w visits every threads-th node from begin + w: the worst nodes, which cost
    // most, are spread over the workers.
    parallel_chunks(threads, threads, 1, [&](int64_t w, int64_t, int64_t) {
      nodes_visit(s, s.workers[w], w, by_level, begin + w, end, threads);
    });
  }
}

/// Sweeps (at most max_sweeps) from the initially active nodes (options.initially_active
/// outside the smooth phase, else every node), until no node is active, no node moved by more
/// than 1e-7 of its local edge length, or (max-min phase) a sweep improved neither the minimum
/// (by 1e-9) nor the mean (by 1e-6). Adds the sweeps to stats.sweeps.
void nodes_sweep(NodeSweeps& s, int max_sweeps, NodeOptimizerStats& stats) {
  const NodeOptimizerOptions& options = s.options;
  Optimizer& optimizer = s.workers.front();
  if (!s.soft && options.initially_active.size() == static_cast<size_t>(s.n))
    std::copy(options.initially_active.begin(), options.initially_active.end(), s.active.begin());
  else
    std::fill(s.active.begin(), s.active.end(), 1);
  double current_min, current_mean;
  min_mean(optimizer.quality(), current_min, current_mean);
  for (int sweep = 0; sweep < max_sweeps; ++sweep) {
    if (!active_nodes_order_worst_first(s)) break;
    std::fill(s.next_active.begin(), s.next_active.end(), 0);
    s.largest_relative_move.assign(static_cast<size_t>(s.threads), 0.0);
    if (s.threads == 1)
      nodes_visit(s, optimizer, 0, s.order, 0, static_cast<int64_t>(s.order.size()), 1);
    else
      active_nodes_visit_by_levels(s);
    s.active.swap(s.next_active);
    ++stats.sweeps;
    double sweep_min, sweep_mean;
    min_mean(optimizer.quality(), sweep_min, sweep_mean);
    const bool stalled = sweep_min - current_min <= 1e-9 && sweep_mean - current_mean <= 1e-6;
    current_min = sweep_min;
    current_mean = sweep_mean;
    const double largest =
        *std::max_element(s.largest_relative_move.begin(), s.largest_relative_move.end());
    if (largest <= 1e-7 || (stalled && !s.soft)) break;
  }
}

}  // namespace

NodeOptimizerStats nodes_optimize(HexMesh& mesh, const NodeProblem& problem,
                                  const NodeOptimizerOptions& options) {
  NodeOptimizerStats stats;
  const int32_t n = static_cast<int32_t>(problem.nodes.size());
  const int threads = std::max(options.threads, 1);
  OptimizerShared shared;
  std::vector<Optimizer> workers;
  workers.reserve(static_cast<size_t>(threads));
  for (int t = 0; t < threads; ++t) workers.emplace_back(mesh, problem, options, shared, t == 0);
  Optimizer& optimizer = workers.front();
  min_mean(optimizer.quality(), stats.min_before, stats.mean_before);

  NodeSweeps sweeps(problem, options, workers);
  std::vector<Vec3> saved;
  if (options.smooth_sweeps > 0) {
    for (int32_t node : problem.nodes) saved.push_back(mesh.points[node]);
    sweeps.soft = true;
    optimizer.set_phase(true, options.smooth_beta);
    nodes_sweep(sweeps, options.smooth_sweeps, stats);
    sweeps.soft = false;
  }
  optimizer.set_phase(false, 60.0);
  nodes_sweep(sweeps, options.max_sweeps, stats);
  if (!saved.empty()) {
    double min_now, mean_now;
    min_mean(optimizer.quality(), min_now, mean_now);
    if (min_now < stats.min_before) {
      // The smooth phase led somewhere worse: start again from where it started.
      for (int32_t i = 0; i < n; ++i) optimizer.restore(i, saved[i]);
      nodes_sweep(sweeps, options.max_sweeps, stats);
    }
  }
  min_mean(optimizer.quality(), stats.min_after, stats.mean_after);
  for (int32_t i = 0; i < n; ++i)
    if (mesh.points[problem.nodes[i]] != optimizer.start()[i]) ++stats.nodes_moved;
  return stats;
}

}  // namespace hexrefine
