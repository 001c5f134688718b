#include "experiments/bench/bench_statistics.hpp"

#include <gtest/gtest.h>

namespace hexrefine {
namespace {

TEST(BenchStatistics, ExactTailsOfSmallSamples) {
  // n = m = 3: 20 orderings; complete separation is one of them.
  EXPECT_NEAR(mann_whitney_p_greater({1, 2, 3}, {4, 5, 6}), 1.0 / 20.0, 1e-15);
  EXPECT_NEAR(mann_whitney_p_greater({4, 5, 6}, {1, 2, 3}), 1.0, 1e-15);
  // U = 7 of 9: orderings with U >= 7 are 4 of 20 (U = 9, 8, and two with 7).
  EXPECT_NEAR(mann_whitney_p_greater({100, 110, 90}, {95, 150, 120}), 4.0 / 20.0, 1e-15);
  // n = m = 4: 70 orderings.
  EXPECT_NEAR(mann_whitney_p_greater({1, 2, 3, 4}, {5, 6, 7, 8}), 1.0 / 70.0, 1e-15);
  // n = 1, m = 2: U = 2 needs the one base sample below both: 1 of 3 orderings.
  EXPECT_NEAR(mann_whitney_p_greater({0}, {1, 2}), 1.0 / 3.0, 1e-15);
}

TEST(BenchStatistics, TiesCountHalfAndEmptySidesGiveOne) {
  // All equal: U = n m / 2 = 4.5; P(U >= 4.5) over the 20 orderings: U in 5..9 (10 of 20).
  EXPECT_NEAR(mann_whitney_p_greater({1, 1, 1}, {1, 1, 1}), 10.0 / 20.0, 1e-15);
  EXPECT_EQ(mann_whitney_p_greater({}, {1, 2}), 1.0);
  EXPECT_EQ(mann_whitney_p_greater({1, 2}, {}), 1.0);
}

TEST(BenchStatistics, NormalApproximationBeyondTwelveSamples) {
  std::vector<double> base, now;
  for (int i = 0; i < 20; ++i) base.push_back(i), now.push_back(i + 100);
  EXPECT_LT(mann_whitney_p_greater(base, now), 1e-7);
  std::vector<double> mixed;
  for (int i = 0; i < 20; ++i) mixed.push_back(i + 0.5);
  const double p = mann_whitney_p_greater(base, mixed);
  EXPECT_GT(p, 0.3);
  EXPECT_LT(p, 0.6);
}

}  // namespace
}  // namespace hexrefine
