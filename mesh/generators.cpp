#include "mesh/generators.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "mesh/error.hpp"
#include "mesh/hex_convention.hpp"

namespace hexrefine {

namespace {

template <class T>
void param_require(bool ok, const char* generator, const char* name, T value, const char* range) {
  if (ok) return;
  std::ostringstream s;
  s << generator << ": parameter " << name << " = " << value << " is out of range: expected "
    << range;
  throw InputError(s.str());
}

// Guards the int32 ids: more nodes than int32 can number is bad input, not an overflow.
void count_require(int64_t count, const char* generator, const char* what) {
  if (count <= std::numeric_limits<int32_t>::max() / 2) return;
  throw InputError(std::string(generator) + ": parameters give " + std::to_string(count) + " " +
                   what + ", more than hexrefine's 32-bit ids can hold");
}

// Corner Jacobians relative to the product of the edge lengths must be at least this: the same
// sign test as "scaled Jacobian > 0", with a margin so that round-off in another implementation
// of the metric cannot flip a nearly flat corner.
constexpr double corner_min_scaled = 1e-6;

// True if every corner of the hex has a positive scaled Jacobian: at vertex v the three edges
// along +x, +y, +z (hex_vertex_edges, oriented by hex_edges) form a right-handed frame.
bool hex_corners_positive(const std::array<Eigen::Vector3d, 8>& p) {
  for (int v = 0; v < 8; ++v) {
    Eigen::Vector3d e[3];
    double length_product = 1.0;
    for (int k = 0; k < 3; ++k) {
      const int le = hex_vertex_edges[v][k];
      e[k] = p[hex_edges[le][1]] - p[hex_edges[le][0]];
      length_product *= e[k].norm();
    }
    if (!(length_product > 0.0)) return false;
    if (!(e[0].dot(e[1].cross(e[2])) > corner_min_scaled * length_product)) return false;
  }
  return true;
}

// Uniform double in [0, 1) from the top 53 bits of one raw draw: the std distributions are
// implementation-defined, this is not.
double unit_uniform(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

}  // namespace

HexMesh generate_brick(const BrickParams& params) {
  const char* gen = "generate_brick";
  const char* axis_dims[3] = {"dims NX", "dims NY", "dims NZ"};
  const char* axis_size[3] = {"size LX", "size LY", "size LZ"};
  for (int a = 0; a < 3; ++a) {
    param_require(params.dims[a] >= 1, gen, axis_dims[a], params.dims[a], ">= 1");
    param_require(std::isfinite(params.size[a]) && params.size[a] > 0.0, gen, axis_size[a],
                  params.size[a], "a finite number > 0");
  }
  param_require(params.jitter >= 0.0 && params.jitter < 0.5, gen, "jitter", params.jitter,
                "0 <= jitter < 0.5");
  const std::array<int, 3>& d = params.dims;
  count_require(int64_t{d[0] + 1} * (d[1] + 1) * (d[2] + 1), gen, "nodes");

  HexMesh m;
  std::array<double, 3> h;
  for (int a = 0; a < 3; ++a) h[a] = params.size[a] / d[a];
  m.points.reserve(static_cast<size_t>(d[0] + 1) * (d[1] + 1) * (d[2] + 1));
  // The last node of a row is placed at the size itself, not at n * h, so faces are exact.
  auto coordinate = [&](int a, int i) { return i == d[a] ? params.size[a] : i * h[a]; };
  for (int k = 0; k <= d[2]; ++k)
    for (int j = 0; j <= d[1]; ++j)
      for (int i = 0; i <= d[0]; ++i)
        m.points.emplace_back(coordinate(0, i), coordinate(1, j), coordinate(2, k));
  m.hexes.reserve(static_cast<size_t>(d[0]) * d[1] * d[2]);
  for (int k = 0; k < d[2]; ++k)
    for (int j = 0; j < d[1]; ++j)
      for (int i = 0; i < d[0]; ++i) {
        HexCell c;
        for (int v = 0; v < 8; ++v)
          c[v] = brick_node(d, i + hex_corner[v][0], j + hex_corner[v][1], k + hex_corner[v][2]);
        m.hexes.push_back(c);
      }
  if (params.jitter == 0.0) return m;

  // Interior nodes only: boundary nodes stay on their planes.
  std::mt19937_64 rng(params.seed);
  const std::vector<Eigen::Vector3d> grid = m.points;
  std::vector<Eigen::Vector3d> offset(m.points.size(), Eigen::Vector3d::Zero());
  for (int k = 1; k < d[2]; ++k)
    for (int j = 1; j < d[1]; ++j)
      for (int i = 1; i < d[0]; ++i) {
        const int32_t n = brick_node(d, i, j, k);
        for (int a = 0; a < 3; ++a)
          offset[n][a] = params.jitter * h[a] * (2.0 * unit_uniform(rng) - 1.0);
        m.points[n] = grid[n] + offset[n];
      }

  // Pull back: halve the offsets of every node of an invalid hex and recheck only the hexes
  // around the nodes that moved. After 60 halvings an offset is below round-off and is zeroed,
  // which restores the (valid) regular grid locally, so the loop always ends.
  std::vector<int32_t> check(m.hexes.size());
  for (size_t i = 0; i < check.size(); ++i) check[i] = static_cast<int32_t>(i);
  std::vector<uint8_t> queued(m.hexes.size(), 0), moved(m.points.size(), 0);
  std::vector<int32_t> moved_nodes;
  for (int round = 0; !check.empty(); ++round) {
    moved_nodes.clear();
    for (int32_t hx : check)
      if (!hex_corners_positive(hex_points(m, hx)))
        for (int32_t n : m.hexes[hx])
          if (!moved[n] && offset[n] != Eigen::Vector3d::Zero()) {
            moved[n] = 1;
            moved_nodes.push_back(n);
          }
    check.clear();
    for (int32_t n : moved_nodes) {
      moved[n] = 0;
      offset[n] = round < 60 ? Eigen::Vector3d(0.5 * offset[n]) : Eigen::Vector3d::Zero();
      m.points[n] = grid[n] + offset[n];
      const int i = n % (d[0] + 1), j = (n / (d[0] + 1)) % (d[1] + 1),
                k = n / ((d[0] + 1) * (d[1] + 1));
      for (int dk = -1; dk <= 0; ++dk)
        for (int dj = -1; dj <= 0; ++dj)
          for (int di = -1; di <= 0; ++di) {
            const int32_t hx = brick_hex(d, i + di, j + dj, k + dk);  // interior node: in range
            if (!queued[hx]) queued[hx] = 1, check.push_back(hx);
          }
    }
    for (int32_t hx : check) queued[hx] = 0;
  }
  return m;
}

}  // namespace hexrefine
