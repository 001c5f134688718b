/// Nothing gets lost for speed: the output of a full 1-27 refinement (made here by a trilinear
/// split of a jittered brick, so no refiner is involved) is valid, and each mutation of it is
/// caught with the count it must give, on one and two threads, with and without the input as
/// the reference: a cracked copy (one interior face's nodes split), an inverted hex, a hanging
/// node, a doublet, a duplicate node, a collapsed edge.

#include <gtest/gtest.h>

#include <climits>
#include <string>

#include "mesh/conformity.hpp"
#include "mesh/error.hpp"
#include "mesh/hex_convention.hpp"
#include "mesh/quality.hpp"
#include "tests/fixtures.hpp"

namespace hexrefine {
namespace {

/// fixture_brick(n, n, n) with its interior nodes moved by up to a quarter spacing, and its 1-27
/// split by each hex's trilinear map (nodes shared by the split of neighbouring hexes: the
/// output of a full refinement, 27 n^3 hexes).
struct Refined {
  HexMesh input, output;
};

Refined refined_brick(int n) {
  Refined r;
  r.input = fixture_brick(n, n, n);
  uint32_t state = 12345;
  auto jitter = [&] {
    state = state * 1664525u + 1013904223u;
    return (static_cast<double>(state >> 8) / double(1 << 24) - 0.5) * 0.5;
  };
  for (Eigen::Vector3d& x : r.input.points)
    if (x.minCoeff() > 0 && x.maxCoeff() < n) x += Eigen::Vector3d(jitter(), jitter(), jitter());
  // Output nodes on the 3n + 1 lattice, placed by the trilinear map of the input hex they lie in.
  const int m = 3 * n + 1;
  auto node = [&](int i, int j, int k) { return static_cast<int32_t>(i + m * (j + m * k)); };
  r.output.points.resize(static_cast<size_t>(m) * m * m);
  for (int k = 0; k < m; ++k)
    for (int j = 0; j < m; ++j)
      for (int i = 0; i < m; ++i) {
        const int hi = std::min(i / 3, n - 1), hj = std::min(j / 3, n - 1),
                  hk = std::min(k / 3, n - 1);
        const std::array<Eigen::Vector3d, 8> p =
            hex_points(r.input, fixture_brick_hex(n, n, hi, hj, hk));
        const double u = i / 3.0 - hi, v = j / 3.0 - hj, w = k / 3.0 - hk;
        Eigen::Vector3d x = Eigen::Vector3d::Zero();
        for (int c = 0; c < 8; ++c)
          x += p[c] * ((hex_corner[c][0] ? u : 1 - u) * (hex_corner[c][1] ? v : 1 - v) *
                       (hex_corner[c][2] ? w : 1 - w));
        r.output.points[node(i, j, k)] = x;
      }
  for (int k = 0; k + 1 < m; ++k)
    for (int j = 0; j + 1 < m; ++j)
      for (int i = 0; i + 1 < m; ++i)
        r.output.hexes.push_back({node(i, j, k), node(i + 1, j, k), node(i + 1, j + 1, k),
                                  node(i, j + 1, k), node(i, j, k + 1), node(i + 1, j, k + 1),
                                  node(i + 1, j + 1, k + 1), node(i, j + 1, k + 1)});
  return r;
}

/// Runs `expect` on the check of `mesh` on one and two threads, without and with the input as
/// the reference; the reports must agree field for field across thread counts.
template <class Expect>
void check_everywhere(const HexMesh& mesh, const HexMesh& input, Expect expect) {
  for (const HexMesh* reference : {static_cast<const HexMesh*>(nullptr), &input}) {
    const MeshCheckReport one = mesh_check(mesh, reference, 1);
    const MeshCheckReport two = mesh_check(mesh, reference, 2);
    SCOPED_TRACE(reference ? "with the input as the reference" : "without a reference");
    EXPECT_EQ(nlohmann::json(one).dump(), nlohmann::json(two).dump());
    expect(one, reference != nullptr);
  }
}

constexpr int n = 6;  // 5,832 output hexes

TEST(ConformityMutations, TheRefinedMeshIsValid) {
  const Refined r = refined_brick(n);
  ASSERT_EQ(r.output.hex_count(), 27 * n * n * n);
  check_everywhere(r.output, r.input, [](const MeshCheckReport& c, bool) {
    EXPECT_TRUE(c.valid());
    EXPECT_EQ(c.non_conformal_faces, 0);
    EXPECT_EQ(c.hanging_nodes, 0);
    EXPECT_EQ(c.doublets, 0);
    EXPECT_EQ(c.duplicate_nodes, 0);
    EXPECT_EQ(c.inverted_hexes, 0);
    EXPECT_EQ(c.nonmanifold_boundary_edges, 0);
    EXPECT_EQ(c.boundary_faces, 6 * 9 * n * n);
    EXPECT_GT(c.min_scaled_jacobian, 0);
  });
}

TEST(ConformityMutations, CrackedFace) {
  // The middle output hex gets its own copies of the four nodes of its -x face.
  Refined r = refined_brick(n);
  const int m = 3 * n;
  const int32_t b = fixture_brick_hex(m, m, m / 2, m / 2, m / 2);
  for (int k = 0; k < 4; ++k) {
    int32_t& v = r.output.hexes[b][hex_faces[0][k]];
    r.output.points.push_back(r.output.points[v]);
    v = r.output.point_count() - 1;
  }
  check_everywhere(r.output, r.input, [](const MeshCheckReport& c, bool) {
    EXPECT_EQ(c.non_conformal_faces, 10);  // the crack and the four side faces, both sides each
    EXPECT_EQ(c.duplicate_nodes, 4);
    EXPECT_EQ(c.hanging_nodes, 0);
    EXPECT_FALSE(c.valid());
  });
}

TEST(ConformityMutations, InvertedHex) {
  Refined r = refined_brick(n);
  HexCell& c = r.output.hexes[1000];
  for (int v = 0; v < 4; ++v) std::swap(c[v], c[v + 4]);
  check_everywhere(r.output, r.input, [](const MeshCheckReport& c, bool) {
    EXPECT_EQ(c.inverted_hexes, 1);
    EXPECT_EQ(c.first_inverted_hex, 1000);
    EXPECT_TRUE(c.conformal);  // same faces, turned inside out
    EXPECT_FALSE(c.valid());
  });
}

TEST(ConformityMutations, HangingNode) {
  // A corner hex on the -x side split 1-8 with nodes of its own inside, beside its unsplit
  // neighbour: the corner hex's +x face (big) against the four small faces behind it.
  Refined r = refined_brick(n);
  const int m = 3 * n;
  const int32_t h = fixture_brick_hex(m, m, 0, 0, 0);
  const HexCell parent = r.output.hexes[h];
  const std::array<Eigen::Vector3d, 8> p = hex_points(r.output, h);
  auto at = [&](double u, double v, double w) {
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    for (int c = 0; c < 8; ++c)
      x += p[c] * ((hex_corner[c][0] ? u : 1 - u) * (hex_corner[c][1] ? v : 1 - v) *
                   (hex_corner[c][2] ? w : 1 - w));
    return x;
  };
  int32_t ids[3][3][3];
  for (auto& plane : ids)
    for (auto& row : plane)
      for (int32_t& id : row) id = -1;
  // Corner nodes keep the parent's ids (hex_corner order), the 19 others are new.
  for (int c = 0; c < 8; ++c)
    ids[2 * hex_corner[c][0]][2 * hex_corner[c][1]][2 * hex_corner[c][2]] = parent[c];
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i)
        if (ids[i][j][k] < 0) {
          ids[i][j][k] = r.output.point_count();
          r.output.points.push_back(at(i / 2.0, j / 2.0, k / 2.0));
        }
  std::vector<HexCell> children;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i)
        children.push_back({ids[i][j][k], ids[i + 1][j][k], ids[i + 1][j + 1][k], ids[i][j + 1][k],
                            ids[i][j][k + 1], ids[i + 1][j][k + 1], ids[i + 1][j + 1][k + 1],
                            ids[i][j + 1][k + 1]});
  r.output.hexes[h] = children[0];
  r.output.hexes.insert(r.output.hexes.end(), children.begin() + 1, children.end());
  check_everywhere(r.output, r.input, [](const MeshCheckReport& c, bool) {
    // Three interfaces (+x, +y, +z of the split hex), each a big face and four small ones.
    EXPECT_EQ(c.non_conformal_faces, 15);
    // Per interface 4 edge midpoints and a face centre; the midpoints of the three edges two
    // interfaces share counted once.
    EXPECT_EQ(c.hanging_nodes, 3 * 5 - 3);
    EXPECT_EQ(c.inverted_hexes, 0);
    EXPECT_FALSE(c.valid());
  });
}

TEST(ConformityMutations, Doublet) {
  // Two hexes of the refined mesh replaced by hexes sharing two faces: the corner hex (0,0,0)
  // and its +x neighbour become one hex and a copy wrapped around its +x and +y faces.
  HexMesh m = fixture_brick(1, 1, 1);
  m.points.emplace_back(-1, -1, 0);
  m.points.emplace_back(-1, -1, 1);
  m.hexes.push_back({3, 2, 8, 1, 7, 6, 9, 5});
  const HexMesh reference = m;
  check_everywhere(m, reference, [](const MeshCheckReport& c, bool) {
    EXPECT_EQ(c.doublets, 1);
    EXPECT_FALSE(c.valid());
  });
  // The same pair inside the refined mesh: its two hexes at the far corner, the doublet's second
  // hex folded onto the first one's +x and +y faces.
  Refined r = refined_brick(n);
  const int s = 3 * n;
  const int32_t a = fixture_brick_hex(s, s, s - 1, s - 1, s - 1);
  const HexCell c = r.output.hexes[a];
  const int32_t extra0 = r.output.point_count(), extra1 = extra0 + 1;
  r.output.points.push_back(r.output.points[c[0]] + Eigen::Vector3d(2, 2, 0));
  r.output.points.push_back(r.output.points[c[4]] + Eigen::Vector3d(2, 2, 0));
  // hex_corner order: the +x face {1,2,6,5} and +y face {3,7,6,2} of `a` become the new hex's
  // -x and -y faces.
  r.output.hexes.push_back({c[2], c[3], extra0, c[1], c[6], c[7], extra1, c[5]});
  check_everywhere(r.output, r.input, [](const MeshCheckReport& c, bool) {
    EXPECT_EQ(c.doublets, 1);
    EXPECT_FALSE(c.valid());
  });
}

TEST(ConformityMutations, DuplicateNode) {
  // A node copied with no hex using the copy: reported, no defect; then an interior node of a
  // hex replaced by its copy in that hex only: a crack along the hex's three faces at that node.
  Refined r = refined_brick(n);
  const int m = 3 * n;
  const int32_t h = fixture_brick_hex(m, m, m / 2, m / 2, m / 2);
  const int32_t v = r.output.hexes[h][6];
  r.output.points.push_back(r.output.points[v]);
  check_everywhere(r.output, r.input, [](const MeshCheckReport& c, bool) {
    EXPECT_EQ(c.duplicate_nodes, 1);
    EXPECT_EQ(c.unused_nodes, 1);
    EXPECT_TRUE(c.valid());
  });
  r.output.hexes[h][6] = r.output.point_count() - 1;
  check_everywhere(r.output, r.input, [](const MeshCheckReport& c, bool) {
    EXPECT_EQ(c.duplicate_nodes, 1);
    EXPECT_EQ(c.unused_nodes, 0);
    EXPECT_EQ(c.non_conformal_faces, 6);  // the hex's three faces at the node, and theirs
    EXPECT_FALSE(c.valid());
  });
}

TEST(ConformityMutations, CollapsedEdge) {
  // An interior output node moved onto its +z neighbour: the edge between them has length 0,
  // so every hex on it has a zero-length Jacobian column (scaled Jacobian 0: degenerate).
  Refined r = refined_brick(n);
  const int m = 3 * n;
  const int32_t h = fixture_brick_hex(m, m, m / 2, m / 2, m / 2);
  r.output.points[r.output.hexes[h][4]] = r.output.points[r.output.hexes[h][0]];
  check_everywhere(r.output, r.input, [](const MeshCheckReport& c, bool) {
    EXPECT_EQ(c.inverted_hexes, 4);  // the four hexes around the collapsed edge
    EXPECT_EQ(c.max_edge_ratio, hex_metric_max);
    EXPECT_EQ(c.duplicate_nodes, 1);
    EXPECT_FALSE(c.valid());
  });
}

TEST(ConformityMutations, EveryRepeatedNodePairAndBadIdIsNamed) {
  // The ids are checked in vector compares of the hex's two halves and their rotations: each of
  // the 28 node pairs repeated, and ids out of range at each corner, give mesh_validate_ids'
  // message naming the hex.
  const HexMesh good = fixture_brick(2, 1, 1);
  for (int i = 0; i < 8; ++i) {
    for (int j = i + 1; j < 8; ++j) {
      HexMesh m = good;
      m.hexes[1][j] = m.hexes[1][i];
      try {
        mesh_check(m);
        ADD_FAILURE() << i << " " << j << " accepted";
      } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()), "mesh: hex 1 repeats node " +
                                             std::to_string(m.hexes[1][i]) + " (degenerate hex)");
      }
    }
    for (const int32_t bad : {-1, good.point_count(), INT32_MAX}) {
      HexMesh m = good;
      m.hexes[1][i] = bad;
      try {
        mesh_check(m, nullptr, 2);
        ADD_FAILURE() << i << " " << bad << " accepted";
      } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()), "mesh: hex 1 refers to node " + std::to_string(bad) +
                                             ", expected 0.." +
                                             std::to_string(good.point_count() - 1));
      }
    }
  }
}

TEST(ConformityMutations, DuplicateNodesFarFromTheOrigin) {
  // The duplicate search compares float keys (projections) first: far from the origin (but
  // where doubles still resolve the tolerance), pairs at 0.5 and 0.9 of the tolerance are found
  // and pairs at 1.1 of it are not, along the projection's direction and across it; the count is
  // the definition's, by brute force.
  HexMesh m = fixture_brick(20, 20, 20);
  for (Eigen::Vector3d& x : m.points) x += Eigen::Vector3d(1e3, -3e3, 2e3);
  const auto [lo, hi] = mesh_bounding_box(m);
  const double tolerance = mesh_check_duplicate_tolerance * (hi - lo).norm();
  const Eigen::Vector3d along = Eigen::Vector3d(1.0, 0.7548776662, 0.5698402910).normalized();
  const Eigen::Vector3d across = along.cross(Eigen::Vector3d::UnitZ()).normalized();
  for (int i = 0; i < 60; ++i) {
    const double scale = (i % 3 == 0) ? 0.5 : (i % 3 == 1 ? 0.9 : 1.1);
    const Eigen::Vector3d direction = (i % 2 == 0) ? along : across;
    m.points.push_back(m.points[131 * i] + scale * tolerance * direction);
  }
  int64_t expected = 0;
  for (int32_t i = 0; i < m.point_count(); ++i)
    for (int32_t j = 0; j < i; ++j)
      if ((m.points[i] - m.points[j]).norm() <= tolerance) {
        ++expected;
        break;
      }
  EXPECT_EQ(expected, 40);
  EXPECT_EQ(mesh_check(m, nullptr, 1).duplicate_nodes, expected);
  EXPECT_EQ(mesh_check(m, nullptr, 2).duplicate_nodes, expected);
}

}  // namespace
}  // namespace hexrefine
