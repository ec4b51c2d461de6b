#pragma once
// Error bars for ensemble statistics: exact (Clopper–Pearson) binomial confidence intervals for
// probabilities estimated from counts, and standard errors of means.
#include <cstddef>
#include <limits>
#include <vector>

#include "geomint/error.hpp"

namespace geomint {

struct Interval {
  double lo = missing_value, hi = missing_value;
};

// The two-sided Clopper–Pearson interval for p from `successes` in `trials` (Boost.Math's binomial
// find_lower/upper_bound_on_p, clopper_pearson_exact_interval, alpha/2 on each side): it covers the true p
// with probability >= confidence for every p. 0 successes give lo = 0, all give hi = 1; no trials: NaN.
Interval clopper_pearson(long successes, long trials, double confidence = 0.95);

// Mean of the finite values and its standard error s / sqrt(n) (s: sample standard deviation); NaN with
// fewer than two values.
struct MeanSe {
  double mean = missing_value, se = missing_value;
  std::size_t n = 0;
};
MeanSe mean_se(const std::vector<double>& values);

}  // namespace geomint
