#include "geomint/stats.hpp"

#include <cmath>

#include <boost/math/distributions/binomial.hpp>

#include "geomint/error.hpp"

namespace geomint {

Interval clopper_pearson(long successes, long trials, double confidence) {
  require(successes >= 0 && successes <= trials, "clopper_pearson: need 0 <= successes <= trials");
  require(confidence > 0 && confidence < 1, "clopper_pearson: confidence must be in (0, 1)");
  if (trials == 0) return {};
  using boost::math::binomial_distribution;
  const double a = (1 - confidence) / 2, n = static_cast<double>(trials), k = static_cast<double>(successes);
  const auto method = binomial_distribution<>::clopper_pearson_exact_interval;
  return {binomial_distribution<>::find_lower_bound_on_p(n, k, a, method),
          binomial_distribution<>::find_upper_bound_on_p(n, k, a, method)};
}

MeanSe mean_se(const std::vector<double>& values) {
  MeanSe r;
  double sum = 0;
  for (double v : values)
    if (std::isfinite(v)) {
      sum += v;
      ++r.n;
    }
  if (r.n < 2) return r;
  r.mean = sum / static_cast<double>(r.n);
  double ss = 0;
  for (double v : values)
    if (std::isfinite(v)) ss += (v - r.mean) * (v - r.mean);
  r.se = std::sqrt(ss / static_cast<double>(r.n - 1) / static_cast<double>(r.n));
  return r;
}

}  // namespace geomint
