/// \file
/// Guarded node smoothing of all-hex meshes.
///
/// Sources (formulas and facts only):
/// - P. M. Knupp, "Achieving finite element mesh quality via optimization of the Jacobian matrix
///   norm and associated quantities, Part II", IJNME 48 (2000) 1165-1185: corner Jacobian matrices
///   of a hex, barrier objectives that are infinite on inverted corners, the ideal (unit cube)
///   corner matrix.
/// - P. M. Knupp, "Algebraic mesh quality metrics", SIAM J. Sci. Comput. 23 (2001) 193-218: the
///   mean ratio of a corner matrix A against the identity, |A|_F^2 / (3 det(A)^(2/3)) in its
///   inverse form (1 for a scaled rotation, growing without bound as det(A) -> 0+).
/// - L. A. Freitag, "On combining Laplacian and optimization-based mesh smoothing techniques",
///   AMD Trends in Unstructured Mesh Generation 220 (1997) 37-43: "smart" Laplacian (a move is
///   kept only if the local quality does not get worse) and optimisation of the minimum quality
///   around a node only where the cheap Laplacian move does not suffice.
///
/// Steps of mesh_smooth:
///  1. Classify nodes from the boundary faces around them (mesh_classify_smooth_nodes: interior,
///     planar, curved, feature); the movable nodes are the interior and planar nodes of the region
///     hexes. All of them are active for the first sweep.
///  2. Per sweep, order the active movable nodes worst-first (lowest scaled Jacobian of their
///     hexes) by a counting sort on the quantised quality (ties by node id: deterministic, linear).
///  3. Visit each node (Gauss-Seidel: moves are seen at once by later nodes). Every candidate
///     position (projected onto the plane for planar nodes) goes through one rule, the guard:
///     no hex with a positive scaled Jacobian becomes non-positive, every hex around the node stays
///     >= the node's current local minimum, and the local minimum or the sum of the scaled
///     Jacobians around the node rises. Hexes elsewhere are unchanged, hence the mesh minimum never
///     decreases, and a mesh that cannot be improved (e.g. perfect boxes) is left as it is.
///     - laplacian: the mean of the edge neighbours, tried as a full, half and quarter move.
///     - optimize: (a) the Laplacian candidate (cheap, and it untangles where (b) cannot start);
///       (b) one damped Newton step on the sum of inverse mean ratios of the corner matrices that
///       depend on the node (analytic gradient, Hessian by differences of the gradient, eigenvalues
///       clamped positive, backtracking while the sum does not fall); (c) three ascent steps on a
///       soft minimum of the scaled-Jacobian samples of the hexes around the node
///       (central-difference gradient, backtracking until the true local minimum rises), which
///       targets exactly the quantity the thesis reports.
///     Nodes of the hexes around a node that moved become active for the next sweep.
///  4. Stop after max_sweeps, when no node is active, or when a sweep moves no node by more than
///     1e-7 of its local edge length or improves neither the minimum (by 1e-9) nor the mean (by
///     1e-6).

#include "algorithms/smoothing.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "mesh/error.hpp"
#include "mesh/hex_convention.hpp"
#include "mesh/quality.hpp"

namespace hexrefine {

namespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Corners = std::array<Vec3, 8>;

/// Corner sample at vertex v: columns are the +axis edge vectors at v (the Jacobian of the
/// trilinear map there; identity for the unit cube).
Mat3 corner_matrix(const Corners& p, int v) {
  Mat3 a;
  for (int k = 0; k < 3; ++k) {
    const int e = hex_vertex_edges[v][k];
    a.col(k) = p[hex_edges[e][1]] - p[hex_edges[e][0]];
  }
  return a;
}

/// The 9 samples whose minimum is hex_scaled_jacobian (mesh/quality.hpp): corners 0..7, then the
/// centre, each det(A) / (|a1| |a2| |a3|) clamped to [-1, 1] (0 for a zero-length column). The
/// ascent needs every sample, not only the minimum; the guard itself uses hex_scaled_jacobian.
void corners_scaled_jacobian_samples(const Corners& p, double* samples) {
  auto scaled = [](const Mat3& a) {
    const double lengths = a.col(0).norm() * a.col(1).norm() * a.col(2).norm();
    if (!(lengths > std::numeric_limits<double>::min())) return 0.0;
    return std::clamp(a.determinant() / lengths, -1.0, 1.0);
  };
  for (int v = 0; v < 8; ++v) samples[v] = scaled(corner_matrix(p, v));
  Mat3 centre = Mat3::Zero();
  for (int k = 0; k < 3; ++k)
    for (int e : hex_axis_edges[k]) centre.col(k) += p[hex_edges[e][1]] - p[hex_edges[e][0]];
  samples[8] = scaled(centre / 4.0);
}

/// Local vertex of node n in hex cell c (precondition: n is in c).
int cell_local_vertex(const HexCell& c, int32_t n) {
  int i = 0;
  while (c[i] != n) ++i;
  return i;
}

/// Projector onto the plane of unit normal `n` (identity for a zero normal).
Mat3 normal_projector(const Vec3& n) {
  return Mat3::Identity() - n * n.transpose();
}

/// Unit tangents of the plane of unit normal n, exact for axis-aligned normals.
std::array<Vec3, 2> normal_tangents(const Vec3& n) {
  int axis = 0;
  for (int k = 1; k < 3; ++k)
    if (std::abs(n[k]) < std::abs(n[axis])) axis = k;
  const Vec3 t1 = n.cross(Vec3::Unit(axis)).normalized();
  return {t1, n.cross(t1)};
}

class Smoother {
 public:
  Smoother(HexMesh& mesh, const HexTopology& topology, const SmoothNodeClasses& classes,
           SmoothMethod method)
      : mesh_(mesh), topology_(topology), classes_(classes), method_(method) {
    const int32_t nn = topology.node_count;
    // Edge neighbours (CSR) for the Laplacian target and the local length scale.
    neighbour_offsets_.assign(static_cast<size_t>(nn) + 1, 0);
    for (const auto& e : topology.edge_nodes)
      ++neighbour_offsets_[e[0] + 1], ++neighbour_offsets_[e[1] + 1];
    for (int32_t n = 0; n < nn; ++n) neighbour_offsets_[n + 1] += neighbour_offsets_[n];
    neighbours_.resize(neighbour_offsets_[nn]);
    std::vector<int32_t> cursor(neighbour_offsets_.begin(), neighbour_offsets_.end() - 1);
    for (const auto& e : topology.edge_nodes) {
      neighbours_[cursor[e[0]]++] = e[1];
      neighbours_[cursor[e[1]]++] = e[0];
    }
    size_t valence = 0;
    for (int32_t n = 0; n < nn; ++n) valence = std::max(valence, node_hexes(topology, n).size());
    trial_quality_.resize(valence);
    trial_samples_.resize(valence * 9);
    quality_.resize(mesh.hexes.size());
    for (int32_t h = 0; h < mesh.hex_count(); ++h) quality_[h] = hex_quality(h);
    input_ = mesh.points;
  }

  /// Scaled Jacobian of every hex at the current positions (kept up to date by every move).
  const std::vector<double>& quality() const { return quality_; }

  /// Node positions before smoothing.
  const std::vector<Vec3>& input_points() const { return input_; }

  /// Visits node n once; returns the distance it moved.
  double node_visit(int32_t n) {
    const Vec3 start = mesh_.points[n];
    if (method_ == SmoothMethod::laplacian) {
      node_laplacian(n);
    } else {
      // The Laplacian candidate is cheap and untangles where the barrier objective cannot start
      // (an inverted corner makes the mean ratio infinite).
      node_laplacian(n);
      node_mean_ratio_newton(n);
      node_min_ascent(n);
    }
    return (mesh_.points[n] - start).norm();
  }

  /// Lowest scaled Jacobian of the hexes around node n (current positions).
  double node_local_min(int32_t n) const {
    double m = 1.0;
    for (int32_t h : node_hexes(topology_, n)) m = std::min(m, quality_[h]);
    return m;
  }

  /// Mean length of the edges at node n (the step-size unit).
  double node_scale(int32_t n) const {
    double sum = 0;
    const int32_t b = neighbour_offsets_[n], e = neighbour_offsets_[n + 1];
    for (int32_t i = b; i < e; ++i) sum += (mesh_.points[neighbours_[i]] - mesh_.points[n]).norm();
    return e > b ? sum / (e - b) : 0.0;
  }

 private:
  double hex_quality(int32_t h) const { return hex_scaled_jacobian(hex_points(mesh_, h)); }

  bool node_is_planar(int32_t n) const { return classes_.kind[n] == SmoothNodeKind::planar; }

  /// Puts a candidate back onto the node's plane (the plane through its input position, which the
  /// node never leaves), so rounding never accumulates off the plane.
  Vec3 node_constrain(int32_t n, const Vec3& x) const {
    if (!node_is_planar(n)) return x;
    const Vec3& normal = classes_.normal[n];
    return x - (x - input_[n]).dot(normal) * normal;
  }

  /// Evaluates the hexes around n with n at x. Returns false if a hex with a positive scaled
  /// Jacobian would become non-positive; `local_min` receives the new local minimum and
  /// `sum_gain` (if given) the change of the sum of their scaled Jacobians. The trial values stay
  /// in trial_quality_ for node_commit.
  bool node_trial(int32_t n, const Vec3& x, double& local_min, double* sum_gain = nullptr) {
    const Vec3 keep = mesh_.points[n];
    mesh_.points[n] = x;
    bool valid = true;
    local_min = 1.0;
    double gain = 0;
    size_t i = 0;
    for (int32_t h : node_hexes(topology_, n)) {
      const double q = hex_quality(h);
      trial_quality_[i++] = q;
      local_min = std::min(local_min, q);
      gain += q - quality_[h];
      if (quality_[h] > 0 && !(q > 0)) valid = false;
    }
    if (sum_gain) *sum_gain = gain;
    mesh_.points[n] = keep;
    return valid;
  }

  void node_commit(int32_t n, const Vec3& x) {
    mesh_.points[n] = x;
    size_t i = 0;
    for (int32_t h : node_hexes(topology_, n)) quality_[h] = trial_quality_[i++];
  }

  /// Tries x0 + t (x - x0) for t = 1, 1/2, 1/4 and keeps the first that passes the guard and
  /// improves: the local minimum does not drop and either it or the sum of the scaled Jacobians
  /// around n rises (so a mesh of perfect boxes, graded or not, is left as it is). Returns true
  /// if a move was made.
  bool node_try_towards(int32_t n, const Vec3& x) {
    const Vec3 x0 = mesh_.points[n];
    const double floor = node_local_min(n);
    for (double t : {1.0, 0.5, 0.25}) {
      const Vec3 candidate = node_constrain(n, x0 + t * (x - x0));
      if (candidate == x0) return false;
      double local_min, gain;
      if (node_trial(n, candidate, local_min, &gain) && local_min >= floor &&
          (local_min > floor + 1e-12 || gain > 1e-12)) {
        node_commit(n, candidate);
        return true;
      }
    }
    return false;
  }

  void node_laplacian(int32_t n) {
    const int32_t b = neighbour_offsets_[n], e = neighbour_offsets_[n + 1];
    if (e == b) return;
    Vec3 target = Vec3::Zero();
    for (int32_t i = b; i < e; ++i) target += mesh_.points[neighbours_[i]];
    target /= static_cast<double>(e - b);
    node_try_towards(n, target);
  }

  /// Sum of inverse mean ratios |A|_F^2 / (3 det(A)^(2/3)) over the corner matrices that depend
  /// on node n, with n at x; +inf if one of them has det(A) <= 0 (the barrier). `gradient`, if
  /// given, receives d/dx: with A's column k = coefficient c_k times x plus constants (c_k in
  /// {-1, 0, 1}), dmu/dx = G c where G = dmu/dA = 2/(3 g) (A - |A|_F^2 / 3 A^-T), g = det^(2/3).
  double node_mean_ratio(int32_t n, const Vec3& x, Vec3* gradient) {
    const Vec3 keep = mesh_.points[n];
    mesh_.points[n] = x;
    double sum = 0;
    if (gradient) gradient->setZero();
    for (int32_t h : node_hexes(topology_, n)) {
      const HexCell& cell = mesh_.hexes[h];
      const int i = cell_local_vertex(cell, n);
      const Corners p = hex_points(mesh_, h);
      int corners[4] = {i, 0, 0, 0};
      for (int k = 0; k < 3; ++k) {
        const int e = hex_vertex_edges[i][k];
        corners[k + 1] = hex_edges[e][0] == i ? hex_edges[e][1] : hex_edges[e][0];
      }
      for (int v : corners) {
        const Mat3 a = corner_matrix(p, v);
        const double det = a.determinant();
        const double f = a.squaredNorm();
        if (!(det > 1e-14 * f * std::sqrt(f))) {
          mesh_.points[n] = keep;
          return std::numeric_limits<double>::infinity();
        }
        const double g = std::cbrt(det * det);
        sum += f / (3.0 * g);
        if (gradient) {
          Vec3 c;
          for (int k = 0; k < 3; ++k) {
            const int e = hex_vertex_edges[v][k];
            c[k] = hex_edges[e][1] == i ? 1.0 : (hex_edges[e][0] == i ? -1.0 : 0.0);
          }
          const Mat3 inverse_transpose = a.inverse().transpose();
          const Mat3 dmu = (2.0 / (3.0 * g)) * (a - (f / 3.0) * inverse_transpose);
          *gradient += dmu * c;
        }
      }
    }
    mesh_.points[n] = keep;
    return sum;
  }

  void node_mean_ratio_newton(int32_t n) {
    const double scale = node_scale(n);
    if (!(scale > 0)) return;
    const Vec3 x0 = mesh_.points[n];
    const Mat3 projector =
        node_is_planar(n) ? normal_projector(classes_.normal[n]) : Mat3::Identity();
    const Mat3 normal_block = Mat3::Identity() - projector;
    Vec3 x = x0, gradient;
    double value = node_mean_ratio(n, x, &gradient);
    if (!std::isfinite(value)) return;  // an inverted corner: the ascent below untangles
    const double delta = 1e-6 * scale;
    for (int iteration = 0; iteration < newton_iterations; ++iteration) {
      const Vec3 g = projector * gradient;
      if (g.norm() * scale <= 1e-12 * value) break;
      Mat3 hessian;
      bool finite = true;
      for (int j = 0; j < 3; ++j) {
        Vec3 shifted_gradient;
        const double shifted = node_mean_ratio(n, x + delta * Vec3::Unit(j), &shifted_gradient);
        if (!std::isfinite(shifted)) finite = false;
        hessian.col(j) = (shifted_gradient - gradient) / delta;
      }
      Vec3 step;
      if (finite) {
        // Work in the plane for planar nodes; the normal block only keeps the matrix regular.
        const Mat3 reduced = projector * (0.5 * (hessian + hessian.transpose())) * projector +
                             normal_block * hessian.norm();
        Eigen::SelfAdjointEigenSolver<Mat3> eigen(reduced);
        Vec3 lambda = eigen.eigenvalues();
        const double largest = lambda.cwiseAbs().maxCoeff();
        if (!(largest > 0)) break;
        for (int k = 0; k < 3; ++k) lambda[k] = std::max(lambda[k], 1e-6 * largest);
        const Mat3& v = eigen.eigenvectors();
        step = -(v * lambda.cwiseInverse().asDiagonal() * v.transpose() * g);
      } else {
        step = -g * (scale / g.norm()) * 0.1;
      }
      step = projector * step;
      if (step.norm() > 0.5 * scale) step *= 0.5 * scale / step.norm();
      double t = 1.0, next_value = value;
      Vec3 next_gradient;
      for (int halving = 0; halving < 20; ++halving, t *= 0.5) {
        next_value = node_mean_ratio(n, x + t * step, &next_gradient);
        if (next_value < value) break;
      }
      if (!(next_value < value)) break;
      x += t * step;
      value = next_value;
      gradient = next_gradient;
      if (t * step.norm() < 1e-10 * scale) break;
    }
    if (x != x0) node_try_towards(n, x);
  }

  /// Soft minimum m - log(sum exp(-beta (s - m))) / beta of the scaled-Jacobian samples of the
  /// hexes around n with n at x (m: their true minimum, returned in `hard_min`).
  double node_soft_min(int32_t n, const Vec3& x) {
    constexpr double beta = 40.0;
    const Vec3 keep = mesh_.points[n];
    mesh_.points[n] = x;
    size_t count = 0;
    double m = 1.0;
    for (int32_t h : node_hexes(topology_, n)) {
      corners_scaled_jacobian_samples(hex_points(mesh_, h), &trial_samples_[count]);
      for (int k = 0; k < 9; ++k) m = std::min(m, trial_samples_[count + k]);
      count += 9;
    }
    mesh_.points[n] = keep;
    double sum = 0;
    for (size_t i = 0; i < count; ++i) sum += std::exp(-beta * (trial_samples_[i] - m));
    return m - std::log(sum) / beta;
  }

  void node_min_ascent(int32_t n) {
    double local_min = node_local_min(n);
    if (local_min >= 1.0 - 1e-12) return;
    const double scale = node_scale(n);
    if (!(scale > 0)) return;
    Vec3 directions[3];
    int direction_count = 3;
    if (node_is_planar(n)) {
      const auto t = normal_tangents(classes_.normal[n]);
      directions[0] = t[0];
      directions[1] = t[1];
      direction_count = 2;
    } else {
      for (int k = 0; k < 3; ++k) directions[k] = Vec3::Unit(k);
    }
    const double delta = 1e-6 * scale;
    double step = 0.05 * scale;
    for (int iteration = 0; iteration < ascent_iterations; ++iteration) {
      const Vec3 x = mesh_.points[n];
      Vec3 gradient = Vec3::Zero();
      for (int k = 0; k < direction_count; ++k) {
        const double up = node_soft_min(n, x + delta * directions[k]);
        const double down = node_soft_min(n, x - delta * directions[k]);
        gradient += (up - down) / (2 * delta) * directions[k];
      }
      if (!(gradient.norm() > 1e-12 / scale)) return;
      const Vec3 direction = gradient.normalized();
      bool moved = false;
      for (int halving = 0; halving < 10; ++halving, step *= 0.5) {
        const Vec3 candidate = node_constrain(n, x + step * direction);
        double candidate_min;
        if (node_trial(n, candidate, candidate_min) && candidate_min > local_min + 1e-12) {
          node_commit(n, candidate);
          local_min = candidate_min;
          moved = true;
          step = std::min(2 * step, 0.25 * scale);
          break;
        }
      }
      if (!moved) return;
    }
  }

  // One Newton step and three ascent steps per visit: the sweeps iterate anyway, and a neighbour
  // that moves changes the local problem, so converging each visit fully is wasted work.
  static constexpr int newton_iterations = 1, ascent_iterations = 3;
  HexMesh& mesh_;
  const HexTopology& topology_;
  const SmoothNodeClasses& classes_;
  SmoothMethod method_;
  std::vector<int32_t> neighbour_offsets_, neighbours_;
  std::vector<double> quality_, trial_quality_, trial_samples_;
  std::vector<Vec3> input_;  ///< planar nodes slide in the plane through their input position
};

void stats_min_mean(const std::vector<double>& quality, double& min, double& mean) {
  min = 1.0;
  mean = 1.0;
  if (quality.empty()) return;
  double sum = 0;
  for (double q : quality) min = std::min(min, q), sum += q;
  mean = sum / static_cast<double>(quality.size());
}

}  // namespace

const char* smooth_method_name(SmoothMethod m) {
  return m == SmoothMethod::laplacian ? "laplacian" : "optimize";
}

SmoothNodeClasses mesh_classify_smooth_nodes(const HexMesh& mesh, const HexTopology& topology,
                                             double feature_angle_degrees) {
  const int32_t nn = topology.node_count;
  SmoothNodeClasses c;
  c.kind.assign(nn, SmoothNodeKind::interior);
  c.normal.assign(nn, Vec3::Zero());
  const double feature_cos = std::cos(feature_angle_degrees * std::numbers::pi / 180.0);
  auto raise = [&](int32_t n, SmoothNodeKind k) { c.kind[n] = std::max(c.kind[n], k); };
  const std::vector<int32_t> boundary = topology_boundary_faces(topology);
  std::vector<Vec3> face_normal(boundary.size(), Vec3::Zero());
  for (size_t b = 0; b < boundary.size(); ++b) {
    const auto& f = topology.face_nodes[boundary[b]];
    const Vec3 d1 = mesh.points[f[2]] - mesh.points[f[0]];
    const Vec3 d2 = mesh.points[f[3]] - mesh.points[f[1]];
    const Vec3 cross = d1.cross(d2);
    const double size2 = std::max(d1.squaredNorm(), d2.squaredNorm());
    if (!(cross.norm() > 1e-12 * size2)) {
      for (int32_t n : f) raise(n, SmoothNodeKind::feature);  // zero area: no usable normal
      continue;
    }
    face_normal[b] = cross.normalized();
    for (int32_t n : f) {
      if (c.normal[n].isZero()) {
        c.normal[n] = face_normal[b];
        raise(n, SmoothNodeKind::planar);
        continue;
      }
      const double cosine = c.normal[n].dot(face_normal[b]);
      if (cosine < feature_cos)
        raise(n, SmoothNodeKind::feature);
      else if (c.normal[n].cross(face_normal[b]).norm() > 1e-9 || cosine < 0)
        raise(n, SmoothNodeKind::curved);
    }
  }
  // Coplanarity: parallel normals are not enough (a staircase of parallel faces is not a plane).
  for (size_t b = 0; b < boundary.size(); ++b) {
    if (face_normal[b].isZero()) continue;
    const auto& f = topology.face_nodes[boundary[b]];
    const double size = std::max((mesh.points[f[2]] - mesh.points[f[0]]).norm(),
                                 (mesh.points[f[3]] - mesh.points[f[1]]).norm());
    for (int32_t n : f) {
      if (c.kind[n] != SmoothNodeKind::planar) continue;
      for (int32_t m : f)
        if (std::abs((mesh.points[m] - mesh.points[n]).dot(c.normal[n])) > 1e-9 * size)
          raise(n, SmoothNodeKind::curved);
    }
  }
  // Faces shared by more than two hexes: the boundary is not a surface there; keep them fixed.
  for (int32_t f : topology.nonmanifold_faces)
    for (int32_t n : topology.face_nodes[f]) raise(n, SmoothNodeKind::feature);
  for (int32_t n = 0; n < nn; ++n)
    if (c.kind[n] != SmoothNodeKind::planar) c.normal[n].setZero();
  return c;
}

SmoothStats mesh_smooth(HexMesh& mesh, const SmoothOptions& options) {
  const auto clock_start = std::chrono::steady_clock::now();
  if (options.max_sweeps < 0)
    throw InputError("mesh_smooth: max_sweeps must be >= 0, got " +
                     std::to_string(options.max_sweeps));
  if (!(options.feature_angle_degrees > 0 && options.feature_angle_degrees < 180))
    throw InputError("mesh_smooth: feature angle must be in (0, 180) degrees, got " +
                     std::to_string(options.feature_angle_degrees));
  mesh_validate_ids(mesh, "mesh_smooth");
  for (int32_t n = 0; n < mesh.point_count(); ++n)
    if (!mesh.points[n].allFinite())
      throw InputError("mesh_smooth: node " + std::to_string(n) + " has a non-finite coordinate");
  for (int32_t h : options.region_hexes)
    if (h < 0 || h >= mesh.hex_count())
      throw InputError("mesh_smooth: region hex " + std::to_string(h) + " out of range 0.." +
                       std::to_string(mesh.hex_count() - 1));

  SmoothStats stats;
  const HexTopology topology = topology_build(mesh);
  const SmoothNodeClasses classes =
      mesh_classify_smooth_nodes(mesh, topology, options.feature_angle_degrees);

  std::vector<char> in_region(mesh.points.size(), options.region_hexes.empty() ? 1 : 0);
  for (int32_t h : options.region_hexes)
    for (int32_t n : mesh.hexes[h]) in_region[n] = 1;
  std::vector<int32_t> movable;
  for (int32_t n = 0; n < mesh.point_count(); ++n)
    if (in_region[n] && !node_hexes(topology, n).empty() &&
        (classes.kind[n] == SmoothNodeKind::interior || classes.kind[n] == SmoothNodeKind::planar))
      movable.push_back(n);

  Smoother smoother(mesh, topology, classes, options.method);
  stats_min_mean(smoother.quality(), stats.min_scaled_jacobian_before,
                 stats.mean_scaled_jacobian_before);
  double current_min = stats.min_scaled_jacobian_before,
         current_mean = stats.mean_scaled_jacobian_before;

  // Worst-first order by a counting sort on the quantised local minimum (linear, stable by id).
  // Only active nodes are visited: those whose hexes changed since their last visit.
  constexpr int buckets = 4096;
  std::vector<int32_t> bucket_offsets(buckets + 1), order, keys;
  std::vector<char> active(mesh.points.size(), 0), next_active(mesh.points.size(), 0);
  for (int32_t n : movable) active[n] = 1;
  for (int sweep = 0; sweep < options.max_sweeps; ++sweep) {
    std::fill(bucket_offsets.begin(), bucket_offsets.end(), 0);
    keys.clear();
    for (int32_t n : movable) {
      if (!active[n]) continue;
      const double q = std::clamp(smoother.node_local_min(n), -1.0, 1.0);
      keys.push_back(std::min(buckets - 1, static_cast<int>((q + 1.0) * 0.5 * buckets)));
      ++bucket_offsets[keys.back() + 1];
    }
    if (keys.empty()) break;
    for (int b = 0; b < buckets; ++b) bucket_offsets[b + 1] += bucket_offsets[b];
    order.resize(keys.size());
    size_t i = 0;
    for (int32_t n : movable)
      if (active[n]) order[bucket_offsets[keys[i++]]++] = n;

    std::fill(next_active.begin(), next_active.end(), 0);
    double largest_relative_move = 0;
    for (int32_t n : order) {
      const double scale = smoother.node_scale(n);
      const double moved = smoother.node_visit(n);
      if (!(moved > 0)) continue;
      if (scale > 0) largest_relative_move = std::max(largest_relative_move, moved / scale);
      for (int32_t h : node_hexes(topology, n))
        for (int32_t m : mesh.hexes[h]) next_active[m] = 1;
    }
    active.swap(next_active);
    ++stats.sweeps;
    double sweep_min, sweep_mean;
    stats_min_mean(smoother.quality(), sweep_min, sweep_mean);
    const bool stalled = sweep_min - current_min <= 1e-9 && sweep_mean - current_mean <= 1e-6;
    current_min = sweep_min;
    current_mean = sweep_mean;
    if (largest_relative_move <= 1e-7 || stalled) break;
  }

  stats_min_mean(smoother.quality(), stats.min_scaled_jacobian_after,
                 stats.mean_scaled_jacobian_after);
  for (int32_t n = 0; n < mesh.point_count(); ++n)
    if (mesh.points[n] != smoother.input_points()[n]) ++stats.nodes_moved;
  stats.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - clock_start).count();
  return stats;
}

std::vector<int32_t> mesh_refined_hexes(const HexMesh& mesh) {
  std::vector<int32_t> out;
  const std::vector<int32_t>* tags = mesh_find_attribute(mesh, attribute_template_tag);
  if (!tags) return out;
  for (int32_t h = 0; h < static_cast<int32_t>(tags->size()); ++h)
    if ((*tags)[h] != 0) out.push_back(h);
  return out;
}

}  // namespace hexrefine
