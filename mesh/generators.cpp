#include "mesh/generators.hpp"

#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "mesh/error.hpp"
#include "mesh/hex_convention.hpp"
#include "mesh/quality.hpp"

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
// Counts are computed in double so that products of large parameters cannot overflow.
void count_require(double count, const char* generator, const char* what) {
  if (count <= std::numeric_limits<int32_t>::max() / 2) return;
  std::ostringstream s;
  s << generator << ": parameters give " << count << " " << what
    << ", more than hexrefine's 32-bit ids can hold";
  throw InputError(s.str());
}

// Validity threshold on hex_scaled_jacobian: positive with a margin, so that round-off in a later
// re-evaluation (another platform, a file round trip) cannot flip a nearly flat hex to <= 0.
constexpr double hex_min_valid_scaled_jacobian = 1e-6;

bool hex_is_valid(const std::array<Eigen::Vector3d, 8>& p) {
  return hex_scaled_jacobian(p) > hex_min_valid_scaled_jacobian;
}

// Throws OperationError naming the first hex with a non-positive corner: a generator that
// reaches this has parameters at the edge of its range and must not hand out an inverted mesh.
void mesh_require_valid(const HexMesh& mesh, const char* generator) {
  for (int32_t h = 0; h < mesh.hex_count(); ++h)
    if (!hex_is_valid(hex_points(mesh, h)))
      throw OperationError(std::string(generator) + ": hex " + std::to_string(h) +
                           " has a non-positive scaled Jacobian with these parameters");
}

// Uniform double in [0, 1) from the top 53 bits of one raw draw: the std distributions are
// implementation-defined, this is not.
double unit_uniform(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

// A planar quad mesh in the xy-plane, quads counter-clockwise seen from +z.
struct QuadMesh {
  std::vector<Eigen::Vector2d> points;
  std::vector<std::array<int32_t, 4>> quads;
  std::vector<int32_t> blocks;
};

// Extrudes along z over [0, height] in `layers` layers: node id = layer * points + 2D id, hexes
// layer by layer in quad order; block ids (if any) become attribute block_id.
HexMesh quad_mesh_extrude(const QuadMesh& q, double height, int layers) {
  HexMesh m;
  const int32_t n2 = static_cast<int32_t>(q.points.size());
  m.points.reserve(static_cast<size_t>(n2) * (layers + 1));
  for (int l = 0; l <= layers; ++l) {
    const double z = height * l / layers;
    for (const Eigen::Vector2d& p : q.points) m.points.emplace_back(p.x(), p.y(), z);
  }
  m.hexes.reserve(q.quads.size() * layers);
  for (int l = 0; l < layers; ++l) {
    const int32_t lo = l * n2, hi = (l + 1) * n2;
    for (const auto& c : q.quads)
      m.hexes.push_back(
          {lo + c[0], lo + c[1], lo + c[2], lo + c[3], hi + c[0], hi + c[1], hi + c[2], hi + c[3]});
  }
  if (!q.blocks.empty()) {
    std::vector<int32_t>& block = mesh_attribute(m, attribute_block_id);
    for (int l = 0; l < layers; ++l)
      for (size_t i = 0; i < q.blocks.size(); ++i) block[l * q.blocks.size() + i] = q.blocks[i];
  }
  return m;
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
  count_require((d[0] + 1.0) * (d[1] + 1.0) * (d[2] + 1.0), gen, "nodes");

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
      if (!hex_is_valid(hex_points(m, hx)))
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

HexMesh generate_gear(const GearParams& p) {
  const char* gen = "generate_gear";
  param_require(p.teeth >= 3, gen, "teeth", p.teeth, ">= 3");
  param_require(std::isfinite(p.inner_radius) && p.inner_radius > 0.0, gen, "inner_radius",
                p.inner_radius, "> 0");
  param_require(std::isfinite(p.root_radius) && p.root_radius > p.inner_radius, gen, "root_radius",
                p.root_radius, "> inner_radius");
  param_require(std::isfinite(p.tip_radius) && p.tip_radius > p.root_radius, gen, "tip_radius",
                p.tip_radius, "> root_radius");
  param_require(std::isfinite(p.thickness) && p.thickness > 0.0, gen, "thickness", p.thickness,
                "> 0");
  param_require(p.layers >= 1, gen, "layers", p.layers, ">= 1");
  param_require(p.body_radial >= 1, gen, "body_radial", p.body_radial, ">= 1");
  param_require(p.tooth_radial >= 1, gen, "tooth_radial", p.tooth_radial, ">= 1");
  param_require(p.tooth_tangential >= 1, gen, "tooth_tangential", p.tooth_tangential, ">= 1");
  param_require(p.gap_tangential >= 1, gen, "gap_tangential", p.gap_tangential, ">= 1");
  param_require(p.tip_fraction > 0.0 && p.tip_fraction <= 1.0, gen, "tip_fraction", p.tip_fraction,
                "0 < tip_fraction <= 1");
  const int64_t pitch = int64_t{p.tooth_tangential} + p.gap_tangential;
  const int64_t around = pitch * p.teeth;
  count_require((static_cast<double>(around) * (p.body_radial + 1.0) +
                 static_cast<double>(p.teeth) * (p.tooth_tangential + 1.0) * p.tooth_radial) *
                    (p.layers + 1.0),
                gen, "nodes");

  const int32_t n = static_cast<int32_t>(around);
  const double dtheta = 2.0 * std::numbers::pi / n;
  QuadMesh q;
  // Body: ring r (0 = inner circle) holds nodes r * n + i at angle i * dtheta.
  for (int r = 0; r <= p.body_radial; ++r) {
    const double radius =
        r == p.body_radial ? p.root_radius
                           : p.inner_radius + (p.root_radius - p.inner_radius) * r / p.body_radial;
    for (int32_t i = 0; i < n; ++i)
      q.points.emplace_back(radius * std::cos(i * dtheta), radius * std::sin(i * dtheta));
  }
  // Quads run radially out then counter-clockwise, so e_r x e_theta = +z.
  for (int r = 0; r < p.body_radial; ++r)
    for (int32_t i = 0; i < n; ++i) {
      const int32_t i1 = (i + 1) % n;
      q.quads.push_back({r * n + i, (r + 1) * n + i, (r + 1) * n + i1, r * n + i1});
      q.blocks.push_back(gear_block_body);
    }
  // Teeth: tooth T stands on root intervals [T * pitch, T * pitch + tooth_tangential). Its side
  // nodes keep their arc offset from the tooth's centre line, scaled linearly from 1 at the root
  // to tip_fraction at the tip.
  const int w = p.tooth_tangential;
  std::vector<int32_t> node((w + 1) * (p.tooth_radial + 1));
  for (int tooth = 0; tooth < p.teeth; ++tooth) {
    const int32_t first = static_cast<int32_t>(tooth * pitch);
    const double centre = (first + 0.5 * w) * dtheta;
    for (int t = 0; t <= p.tooth_radial; ++t)
      for (int a = 0; a <= w; ++a) {
        if (t == 0) {
          node[a] = p.body_radial * n + (first + a) % n;
          continue;
        }
        const double f = static_cast<double>(t) / p.tooth_radial;
        const double radius =
            t == p.tooth_radial ? p.tip_radius : p.root_radius + (p.tip_radius - p.root_radius) * f;
        const double arc =
            (a - 0.5 * w) * dtheta * p.root_radius * (1.0 + (p.tip_fraction - 1.0) * f);
        const double angle = centre + arc / radius;
        node[t * (w + 1) + a] = static_cast<int32_t>(q.points.size());
        q.points.emplace_back(radius * std::cos(angle), radius * std::sin(angle));
      }
    for (int t = 0; t < p.tooth_radial; ++t)
      for (int a = 0; a < w; ++a) {
        q.quads.push_back({node[t * (w + 1) + a], node[(t + 1) * (w + 1) + a],
                           node[(t + 1) * (w + 1) + a + 1], node[t * (w + 1) + a + 1]});
        q.blocks.push_back(gear_block_teeth);
      }
  }
  HexMesh m = quad_mesh_extrude(q, p.thickness, p.layers);
  mesh_require_valid(m, gen);
  return m;
}

HexMesh generate_cylinder(const CylinderParams& p) {
  const char* gen = "generate_cylinder";
  param_require(std::isfinite(p.radius) && p.radius > 0.0, gen, "radius", p.radius, "> 0");
  param_require(std::isfinite(p.height) && p.height > 0.0, gen, "height", p.height, "> 0");
  param_require(p.square_intervals >= 1, gen, "square_intervals", p.square_intervals, ">= 1");
  param_require(p.radial_intervals >= 1, gen, "radial_intervals", p.radial_intervals, ">= 1");
  param_require(p.layers >= 1, gen, "layers", p.layers, ">= 1");
  param_require(p.core > 0.0 && p.core < 0.7, gen, "core", p.core, "0 < core < 0.7");
  const int64_t n64 = p.square_intervals, m64 = p.radial_intervals;
  count_require(
      (double(n64 + 1) * double(n64 + 1) + 4.0 * double(n64) * double(m64)) * (p.layers + 1.0), gen,
      "nodes");

  const int n = p.square_intervals, m = p.radial_intervals;
  const double a = p.core * p.radius;
  QuadMesh q;
  // Square: node (i, j) = i + (n + 1) j at (-a + 2a i/n, -a + 2a j/n).
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) q.points.emplace_back(-a + 2.0 * a * i / n, -a + 2.0 * a * j / n);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int32_t v = i + (n + 1) * j;
      q.quads.push_back({v, v + 1, v + 1 + (n + 1), v + (n + 1)});
    }
  // The square's perimeter counter-clockwise from corner (-a, -a): 4n nodes.
  const int32_t perimeter_count = 4 * n;
  std::vector<int32_t> perimeter(perimeter_count);
  for (int s = 0; s < n; ++s) {
    perimeter[s] = s;                              // bottom, x increasing
    perimeter[n + s] = n + (n + 1) * s;            // right, y increasing
    perimeter[2 * n + s] = (n - s) + (n + 1) * n;  // top, x decreasing
    perimeter[3 * n + s] = (n + 1) * (n - s);      // left, y decreasing
  }
  // Ring r (1..m) node k blends perimeter node k with the circle point at equal angles (corner
  // k = 0 at -135 degrees), so each outer block maps a square side onto a quarter arc.
  auto ring = [&](int r, int32_t k) {
    k %= perimeter_count;
    return r == 0 ? perimeter[k] : (n + 1) * (n + 1) + (r - 1) * perimeter_count + k;
  };
  for (int r = 1; r <= m; ++r) {
    const double t = static_cast<double>(r) / m;
    for (int32_t k = 0; k < perimeter_count; ++k) {
      const double angle = -0.75 * std::numbers::pi + 2.0 * std::numbers::pi * k / perimeter_count;
      const Eigen::Vector2d circle(p.radius * std::cos(angle), p.radius * std::sin(angle));
      q.points.push_back(r == m ? circle
                                : Eigen::Vector2d((1.0 - t) * q.points[perimeter[k]] + t * circle));
    }
  }
  for (int r = 0; r < m; ++r)
    for (int32_t k = 0; k < perimeter_count; ++k)
      q.quads.push_back({ring(r, k), ring(r + 1, k), ring(r + 1, k + 1), ring(r, k + 1)});
  HexMesh mesh = quad_mesh_extrude(q, p.height, p.layers);
  mesh_require_valid(mesh, gen);
  return mesh;
}

HexMesh generate_twisted_ring(const TwistedRingParams& p) {
  const char* gen = "generate_twisted_ring";
  param_require(std::isfinite(p.ring_radius) && p.ring_radius > 0.0, gen, "ring_radius",
                p.ring_radius, "> 0");
  param_require(
      std::isfinite(p.section_size) && p.section_size > 0.0 && p.section_size < p.ring_radius, gen,
      "section_size", p.section_size, "0 < section_size < ring_radius");
  param_require(p.around >= 8, gen, "around", p.around, ">= 8");
  param_require(p.section_intervals >= 1, gen, "section_intervals", p.section_intervals, ">= 1");
  count_require((p.section_intervals + 1.0) * (p.section_intervals + 1.0) * p.around, gen, "nodes");
  const int64_t per_layer64 =
      (int64_t{p.section_intervals} + 1) * (int64_t{p.section_intervals} + 1);

  const int m = p.section_intervals, k_count = p.around;
  const int32_t per_layer = static_cast<int32_t>(per_layer64);
  HexMesh mesh;
  mesh.points.reserve(static_cast<size_t>(per_layer) * k_count);
  // Layer k at ring angle phi = 2 pi k / K holds node (a, b) = k * (m+1)^2 + a + (m+1) b; its
  // section offset (radial s, axial w) is turned by psi = (pi / 2) k / K.
  for (int k = 0; k < k_count; ++k) {
    const double phi = 2.0 * std::numbers::pi * k / k_count;
    const double psi = 0.5 * std::numbers::pi * k / k_count;
    for (int b = 0; b <= m; ++b)
      for (int a = 0; a <= m; ++a) {
        const double s0 = (static_cast<double>(a) / m - 0.5) * p.section_size;
        const double w0 = (static_cast<double>(b) / m - 0.5) * p.section_size;
        const double s = s0 * std::cos(psi) - w0 * std::sin(psi);
        const double w = s0 * std::sin(psi) + w0 * std::cos(psi);
        mesh.points.emplace_back((p.ring_radius + s) * std::cos(phi),
                                 (p.ring_radius + s) * std::sin(phi), w);
      }
  }
  // Layer K is layer 0 turned a quarter: its node (a, b) sits where layer 0's (m - b, a) is.
  auto node = [&](int k, int a, int b) {
    if (k == k_count) return static_cast<int32_t>((m - b) + (m + 1) * a);
    return static_cast<int32_t>(k * per_layer + a + (m + 1) * b);
  };
  // Local x along the section's w, local y along s, local z around the ring: e_z x e_r = e_phi.
  for (int k = 0; k < k_count; ++k)
    for (int b = 0; b < m; ++b)
      for (int a = 0; a < m; ++a)
        mesh.hexes.push_back({node(k, a, b), node(k, a, b + 1), node(k, a + 1, b + 1),
                              node(k, a + 1, b), node(k + 1, a, b), node(k + 1, a, b + 1),
                              node(k + 1, a + 1, b + 1), node(k + 1, a + 1, b)});
  mesh_require_valid(mesh, gen);
  return mesh;
}

HexMesh generate_stepped(const SteppedParams& p) {
  const char* gen = "generate_stepped";
  param_require(p.steps >= 1, gen, "steps", p.steps, ">= 1");
  param_require(p.step_layers >= 1, gen, "step_layers", p.step_layers, ">= 1");
  param_require(p.depth >= 1, gen, "depth", p.depth, ">= 1");
  param_require(p.top_width >= 1, gen, "top_width", p.top_width, ">= 1");
  param_require(p.tread >= 1, gen, "tread", p.tread, ">= 1");
  param_require(std::isfinite(p.cell) && p.cell > 0.0, gen, "cell", p.cell, "> 0");
  const int64_t nx64 = p.top_width + int64_t{p.tread} * (p.steps - 1);
  const int64_t nz64 = int64_t{p.steps} * p.step_layers;
  count_require((double(nx64) + 1.0) * (p.depth + 1.0) * (double(nz64) + 1.0), gen, "nodes");

  // A cut of the bounding grid: cell (i, j, k) is kept if i < width of its step. Kept nodes
  // are renumbered in grid order (x fastest), hexes kept in grid order.
  const std::array<int, 3> dims = {static_cast<int>(nx64), p.depth, static_cast<int>(nz64)};
  auto width = [&](int k) { return p.top_width + p.tread * (p.steps - 1 - k / p.step_layers); };
  std::vector<int32_t> id(static_cast<size_t>(dims[0] + 1) * (dims[1] + 1) * (dims[2] + 1), -1);
  for (int k = 0; k < dims[2]; ++k)
    for (int j = 0; j < dims[1]; ++j)
      for (int i = 0; i < width(k); ++i)
        for (int v = 0; v < 8; ++v)
          id[brick_node(dims, i + hex_corner[v][0], j + hex_corner[v][1], k + hex_corner[v][2])] =
              0;
  HexMesh mesh;
  for (int k = 0; k <= dims[2]; ++k)
    for (int j = 0; j <= dims[1]; ++j)
      for (int i = 0; i <= dims[0]; ++i) {
        int32_t& x = id[brick_node(dims, i, j, k)];
        if (x < 0) continue;
        x = mesh.point_count();
        mesh.points.emplace_back(i * p.cell, j * p.cell, k * p.cell);
      }
  for (int k = 0; k < dims[2]; ++k)
    for (int j = 0; j < dims[1]; ++j)
      for (int i = 0; i < width(k); ++i) {
        HexCell c;
        for (int v = 0; v < 8; ++v)
          c[v] = id[brick_node(dims, i + hex_corner[v][0], j + hex_corner[v][1],
                               k + hex_corner[v][2])];
        mesh.hexes.push_back(c);
      }
  return mesh;
}

}  // namespace hexrefine
