/// \file
/// The hash grid over quads (mesh/quad_grid.hpp): point queries find exactly the quads whose
/// tolerance band holds the point, small and large quads mixed.

#include "mesh/quad_grid.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

namespace hexrefine {
namespace {

Quad square(double x, double y, double size, double z = 0) {
  return {Eigen::Vector3d(x, y, z), Eigen::Vector3d(x + size, y, z),
          Eigen::Vector3d(x + size, y + size, z), Eigen::Vector3d(x, y + size, z)};
}

TEST(QuadGrid, FindsTheQuadsWhoseBandHoldsThePoint) {
  // A 10 x 10 floor of unit squares, one large square 5 wide above it at z = 1, tolerance 0.01.
  std::vector<Quad> quads;
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j) quads.push_back(square(i, j, 1));
  quads.push_back(square(2, 2, 5, 1));
  const std::vector<double> tolerances(quads.size(), 0.01);
  const QuadGrid grid(quads, tolerances);
  auto found = [&](const Eigen::Vector3d& p) {
    std::vector<int32_t> out;
    grid.find(p, [&](int32_t i) {
      out.push_back(i);
      return false;  // keep visiting
    });
    std::sort(out.begin(), out.end());
    return out;
  };
  EXPECT_EQ(found(Eigen::Vector3d(3.5, 4.5, 0.005)), (std::vector<int32_t>{34}));
  EXPECT_EQ(found(Eigen::Vector3d(3.5, 4.5, 0.02)), (std::vector<int32_t>{}));     // above the band
  EXPECT_EQ(found(Eigen::Vector3d(3.0, 4.5, 0)), (std::vector<int32_t>{24, 34}));  // shared side
  EXPECT_EQ(found(Eigen::Vector3d(6.9, 6.9, 1.0)), (std::vector<int32_t>{100}));
  EXPECT_EQ(found(Eigen::Vector3d(7.02, 6.9, 1.0)), (std::vector<int32_t>{}));  // past its side
  EXPECT_EQ(found(Eigen::Vector3d(50, 50, 0)), (std::vector<int32_t>{}));       // outside all
  // A visitor that says yes stops the search and makes find say yes.
  int visits = 0;
  EXPECT_TRUE(grid.find(Eigen::Vector3d(3.0, 4.5, 0), [&](int32_t) { return ++visits > 0; }));
  EXPECT_EQ(visits, 1);
  // visit_cell lists at least the quads found there.
  std::vector<int32_t> in_cell;
  grid.visit_cell(Eigen::Vector3d(3.5, 4.5, 0), [&](int32_t i) {
    in_cell.push_back(i);
    return false;
  });
  EXPECT_NE(std::find(in_cell.begin(), in_cell.end(), 34), in_cell.end());
}

TEST(QuadGrid, EmptyGridFindsNothing) {
  const std::vector<Quad> quads;
  const std::vector<double> tolerances;
  const QuadGrid grid(quads, tolerances);
  EXPECT_FALSE(grid.find(Eigen::Vector3d::Zero(), [](int32_t) { return true; }));
  EXPECT_FALSE(grid.visit_cell(Eigen::Vector3d::Zero(), [](int32_t) { return true; }));
}

}  // namespace
}  // namespace hexrefine
