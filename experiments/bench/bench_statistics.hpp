#pragma once
/// \file
/// The test behind `hexrefine bench-compare`'s flags: a timing is called slower (or faster) only
/// when the change is beyond the run-to-run spread of repeated measurements, as airspeed velocity
/// (asv) does. The test is the one-sided Mann-Whitney U test (rank-sum test; no assumption on
/// the distribution of timings, which is skewed by interference from other processes):
/// U counts the pairs (base sample, new sample) in which the new one is larger (ties count 1/2);
/// the p-value is exact (the distribution of U over all orderings, no ties assumed) up to 12
/// samples per side and from the normal approximation with continuity correction beyond.
/// With 3 samples per side the smallest possible p is 1/20 = 0.05: every new sample slower than
/// every base sample.

#include <vector>

namespace hexrefine {

/// P(U >= observed) under the hypothesis that both samples come from one distribution, where U
/// counts the pairs with now > base: small when `now` is systematically larger. 1 when either
/// side is empty.
double mann_whitney_p_greater(const std::vector<double>& base, const std::vector<double>& now);

}  // namespace hexrefine
