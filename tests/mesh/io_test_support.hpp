#pragma once
/// \file
/// Shared by the tests/mesh/test_io_*.cpp files: a jittered brick carrying attributes, and
/// comparisons of a mesh with the one read back.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <span>
#include <string>

#include "fixtures.hpp"
#include "mesh/error.hpp"
#include "mesh/hex_mesh.hpp"
#include "mesh/io.hpp"

namespace hexrefine {

/// fixture_brick(3, 2, 2) with every point moved by a deterministic irrational-looking amount
/// (so ASCII round trips are exercised on digits that are not short decimals), plus
/// block_id in {1, 2, 7} by x column, template_tag = hex index * 3 - 5 (negative values too),
/// refinement_level = k.
inline HexMesh io_test_brick() {
  HexMesh m = fixture_brick(3, 2, 2);
  for (size_t i = 0; i < m.points.size(); ++i) {
    const double t = static_cast<double>(i);
    m.points[i] += Eigen::Vector3d(0.1 * std::sin(1.3 * t + 0.7), 0.1 * std::cos(2.1 * t),
                                   0.1 * std::sin(0.37 * t * t)) /
                   3.0;
  }
  mesh_attribute(m, attribute_block_id);
  mesh_attribute(m, attribute_template_tag);
  mesh_attribute(m, attribute_refinement_level);
  // Fetched after all three exist: mesh_attribute may reallocate the attribute list.
  auto& block = mesh_attribute(m, attribute_block_id);
  auto& tag = mesh_attribute(m, attribute_template_tag);
  auto& level = mesh_attribute(m, attribute_refinement_level);
  for (int32_t h = 0; h < m.hex_count(); ++h) {
    const int i = h % 3, k = h / 6;
    block[h] = i == 0 ? 1 : i == 1 ? 2 : 7;
    tag[h] = h * 3 - 5;
    level[h] = k;
  }
  return m;
}

/// Points equal to `tolerance` (0: exactly), hexes equal.
inline void io_expect_same_geometry(const HexMesh& a, const HexMesh& b, double tolerance) {
  ASSERT_EQ(a.points.size(), b.points.size());
  ASSERT_EQ(a.hexes.size(), b.hexes.size());
  for (size_t i = 0; i < a.points.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      if (tolerance == 0)
        ASSERT_EQ(a.points[i][k], b.points[i][k]) << "point " << i;
      else
        ASSERT_NEAR(a.points[i][k], b.points[i][k], tolerance) << "point " << i;
    }
  for (size_t h = 0; h < a.hexes.size(); ++h) ASSERT_EQ(a.hexes[h], b.hexes[h]) << "hex " << h;
}

/// The attribute `name` of `b` equals that of `a`.
inline void io_expect_same_attribute(const HexMesh& a, const HexMesh& b, std::string_view name) {
  const auto* va = mesh_find_attribute(a, name);
  const auto* vb = mesh_find_attribute(b, name);
  ASSERT_NE(va, nullptr) << name;
  ASSERT_NE(vb, nullptr) << name << " was not read back";
  EXPECT_EQ(*va, *vb) << name;
}

inline void io_write_text(const std::filesystem::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

/// Writes each (text, expected) case to `dir`/badN`extension` and checks that mesh_read refuses it
/// with an InputError whose message names the file and contains `expected`.
inline void io_expect_refusals(const std::filesystem::path& dir, const std::string& extension,
                               std::span<const std::pair<std::string, std::string>> cases) {
  int i = 0;
  for (const auto& [text, expected] : cases) {
    const auto p = dir / ("bad" + std::to_string(i++) + extension);
    io_write_text(p, text);
    try {
      mesh_read(p.string());
      ADD_FAILURE() << "accepted: " << expected;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(p.string()), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  }
}

}  // namespace hexrefine
