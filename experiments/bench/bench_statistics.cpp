#include "experiments/bench/bench_statistics.hpp"

#include <cmath>

namespace hexrefine {

namespace {

/// Number of orderings of n + m samples (no ties) whose U (pairs with the m-side larger) equals
/// u, for u = 0 .. n m: the recursion on whether the largest sample is on the m side (it then
/// beats all n) or on the n side.
std::vector<double> mann_whitney_counts(int n, int m) {
  // c[i][j][u] for every i <= n, j <= m (at most 13 x 13 x 145 values).
  std::vector<std::vector<std::vector<double>>> c(n + 1, std::vector<std::vector<double>>(m + 1));
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= m; ++j) {
      c[i][j].assign(static_cast<size_t>(i * j + 1), 0.0);
      if (i == 0 || j == 0) {
        c[i][j][0] = 1.0;
        continue;
      }
      for (int u = 0; u <= i * j; ++u) {
        double v = 0.0;
        if (u - i >= 0 && u - i <= i * (j - 1)) v += c[i][j - 1][u - i];  // largest on the m side
        if (u <= (i - 1) * j) v += c[i - 1][j][u];                        // largest on the n side
        c[i][j][u] = v;
      }
    }
  return c[n][m];
}

}  // namespace

double mann_whitney_p_greater(const std::vector<double>& base, const std::vector<double>& now) {
  const int n = static_cast<int>(base.size()), m = static_cast<int>(now.size());
  if (n == 0 || m == 0) return 1.0;
  double u = 0.0;
  for (double b : base)
    for (double x : now) u += x > b ? 1.0 : (x == b ? 0.5 : 0.0);
  if (n <= 12 && m <= 12) {
    const std::vector<double> counts = mann_whitney_counts(n, m);
    double total = 0.0, tail = 0.0;
    for (size_t k = 0; k < counts.size(); ++k) {
      total += counts[k];
      if (static_cast<double>(k) >= u - 1e-9) tail += counts[k];
    }
    return tail / total;
  }
  const double mean = 0.5 * n * m;
  const double sd = std::sqrt(static_cast<double>(n) * m * (n + m + 1) / 12.0);
  const double z = (u - 0.5 - mean) / sd;
  return 0.5 * std::erfc(z / std::sqrt(2.0));
}

}  // namespace hexrefine
