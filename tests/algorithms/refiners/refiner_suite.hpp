#pragma once
/// \file
/// Checks shared by the tests of both refiners. refiner_suite_run runs a refiner on the common
/// cases (full bricks, the L-shaped case, a radial region, gear teeth, an O-grid cylinder) and
/// asserts with the project's checker (mesh_check against the input) that every output is
/// conformal, valid and doublet-free, and that targets are refined 1-27 (27 children each, or
/// more for methods that grow the region). refiner_suite_check is a checker-independent
/// topological check (faces shared by at most two hexes, boundary faces on the input's boundary)
/// for axis-aligned boxes.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "algorithms/refiners/refiner.hpp"
#include "mesh/conformity.hpp"
#include "mesh/generators.hpp"
#include "mesh/hex_convention.hpp"
#include "mesh/quality.hpp"
#include "mesh/topology.hpp"

namespace hexrefine {

struct RefinerSuiteVerdict {
  int64_t nonmanifold_faces = 0;
  int64_t interior_boundary_faces = 0;  ///< boundary faces of the output not on the input boundary
  int64_t inverted_hexes = 0;
  int64_t doublets = 0;  ///< pairs of hexes sharing two or more faces
  double min_scaled_jacobian = 2.0;
  bool conformal() const { return nonmanifold_faces == 0 && interior_boundary_faces == 0; }
};

/// `on_input_boundary(p)` says whether a point lies on the input's boundary surface.
inline RefinerSuiteVerdict refiner_suite_check(
    const HexMesh& out, const std::function<bool(const Eigen::Vector3d&)>& on_input_boundary) {
  RefinerSuiteVerdict v;
  const HexTopology t = topology_build(out);
  v.nonmanifold_faces = static_cast<int64_t>(t.nonmanifold_faces.size());
  for (int32_t f : topology_boundary_faces(t)) {
    bool ok = true;
    for (int32_t n : t.face_nodes[f]) ok = ok && on_input_boundary(out.points[n]);
    if (!ok) ++v.interior_boundary_faces;
  }
  for (int32_t h = 0; h < out.hex_count(); ++h) {
    const double sj = hex_scaled_jacobian(hex_points(out, h));
    if (!(sj > 0)) ++v.inverted_hexes;
    v.min_scaled_jacobian = std::min(v.min_scaled_jacobian, sj);
    // Doublets: a neighbour met through two faces.
    std::array<int32_t, 6> nb;
    for (int lf = 0; lf < 6; ++lf) nb[lf] = hex_face_neighbor(t, h, lf);
    for (int a = 0; a < 6; ++a)
      for (int b = a + 1; b < 6; ++b)
        if (nb[a] >= 0 && nb[a] == nb[b] && nb[a] > h) ++v.doublets;
  }
  return v;
}

/// Boundary test of an axis-aligned box [lo, hi].
inline std::function<bool(const Eigen::Vector3d&)> refiner_suite_box(const Eigen::Vector3d& lo,
                                                                     const Eigen::Vector3d& hi) {
  return [lo, hi](const Eigen::Vector3d& p) {
    for (int k = 0; k < 3; ++k)
      if (std::abs(p[k] - lo[k]) < 1e-9 || std::abs(p[k] - hi[k]) < 1e-9) return true;
    return false;
  };
}

using RefinerFn = std::function<RefineResult(const HexMesh&, const Targets&, const RefineOptions&)>;

/// Options with the thesis' node placement (every new node at its parent's trilinear map of the
/// template's position): for the tests of the thesis' numbers and of exact geometry.
/// Every hex of `m` as targets (full refinement).
inline Targets targets_all_hexes(const HexMesh& m) {
  Targets t;
  for (int32_t h = 0; h < m.hex_count(); ++h) t.hexes.push_back(h);
  return t;
}

inline RefineOptions refine_options_trilinear() {
  RefineOptions o;
  o.placement.method = PlacementMethod::trilinear;
  return o;
}

struct RefinerSuiteCase {
  std::string name;
  HexMesh mesh;
  std::vector<int32_t> targets;
  int64_t expected_hexes = -1;  ///< exact output size when both methods must agree, else -1
};

inline std::vector<RefinerSuiteCase> refiner_suite_cases() {
  std::vector<RefinerSuiteCase> out;
  auto within = [](const HexMesh& m, const Eigen::Vector3d& c, double r) {
    std::vector<int32_t> t;
    for (int32_t h = 0; h < m.hex_count(); ++h)
      if ((hex_centroid(m, h) - c).norm() <= r) t.push_back(h);
    return t;
  };
  for (int n : {1, 3}) {
    BrickParams bp;
    bp.dims = {n, n, n};
    HexMesh m = generate_brick(bp);
    std::vector<int32_t> all(m.hex_count());
    for (int32_t h = 0; h < m.hex_count(); ++h) all[h] = h;
    out.push_back({"full brick " + std::to_string(n), m, all, 27L * n * n * n});
  }
  {
    BrickParams bp;
    bp.dims = {10, 10, 10};
    HexMesh m = generate_brick(bp);
    std::vector<int32_t> t;
    for (int32_t h = 0; h < m.hex_count(); ++h)
      if (h % 10 == 0 || h / 100 == 0) t.push_back(h);
    out.push_back({"L-shaped 10x10x10", m, t, -1});
    out.push_back({"radial r 0.5, interval 10", m, within(m, {1, 1, 1}, 0.5), -1});
  }
  {
    HexMesh gear = generate_gear({});
    std::vector<int32_t> teeth;
    const auto* block = mesh_find_attribute(gear, attribute_block_id);
    for (int32_t h = 0; h < gear.hex_count(); ++h)
      if (block && (*block)[h] == 2) teeth.push_back(h);
    // Table H-1: no multiply-connected transitions, both methods give the same mesh.
    out.push_back({"gear teeth", gear, teeth, -1});
  }
  {
    HexMesh cyl = generate_cylinder({});
    out.push_back({"O-grid cylinder", cyl, within(cyl, {0, 0, 0.5}, 0.5), -1});
  }
  return out;
}

/// Runs `refine` on every suite case and checks each output with mesh_check. Returns the output
/// sizes (for comparisons between methods).
inline std::vector<int64_t> refiner_suite_run(const RefinerFn& refine) {
  std::vector<int64_t> sizes;
  for (const RefinerSuiteCase& c : refiner_suite_cases()) {
    const RefineResult r = refine(c.mesh, {c.targets}, {});
    const MeshCheckReport k = mesh_check(r.mesh, &c.mesh);
    EXPECT_TRUE(k.valid()) << c.name;
    EXPECT_TRUE(k.conformal) << c.name;
    EXPECT_EQ(k.inverted_hexes, 0) << c.name;
    EXPECT_EQ(k.doublets, 0) << c.name;
    EXPECT_EQ(r.stats.initial_hexes, c.mesh.hex_count()) << c.name;
    EXPECT_EQ(r.stats.final_hexes, r.mesh.hex_count()) << c.name;
    EXPECT_GE(r.mesh.hex_count(), 27 * static_cast<int64_t>(c.targets.size())) << c.name;
    if (c.expected_hexes >= 0) {
      EXPECT_EQ(r.mesh.hex_count(), c.expected_hexes) << c.name;
    }
    const auto* tag = mesh_find_attribute(r.mesh, attribute_template_tag);
    const auto* level = mesh_find_attribute(r.mesh, attribute_refinement_level);
    EXPECT_TRUE(tag && level) << c.name;
    sizes.push_back(r.mesh.hex_count());
  }
  return sizes;
}

}  // namespace hexrefine
