// Error bars: Clopper–Pearson intervals (values from the literature, exact coverage computed from the binomial
// distribution) and standard errors; the anomaly summary carries them.
#include <catch2/catch.hpp>

#include <cmath>

#include <boost/math/distributions/binomial.hpp>

#include "geomint/constants.hpp"
#include "geomint/foucault_ensemble.hpp"
#include "geomint/stats.hpp"

using namespace geomint;
using Catch::Detail::Approx;

TEST_CASE("Clopper-Pearson intervals match published values", "[stats]") {
  // 95 % exact intervals (e.g. Brown, Cai & DasGupta 2001; any statistics package)
  const Interval a = clopper_pearson(0, 10);
  CHECK(a.lo == 0);
  CHECK(a.hi == Approx(0.308497).epsilon(1e-5));  // 1 - 0.025^(1/10)
  const Interval b = clopper_pearson(5, 10);
  CHECK(b.lo == Approx(0.187086).epsilon(1e-5));
  CHECK(b.hi == Approx(0.812914).epsilon(1e-5));
  const Interval c = clopper_pearson(10, 10);
  CHECK(c.lo == Approx(0.691503).epsilon(1e-5));
  CHECK(c.hi == 1);
  // 0 of 1000: the rule of three, 3/n, is the one-sided 95 % bound; the two-sided 97.5 % one is 3.7/n
  CHECK(clopper_pearson(0, 1000).hi == Approx(1 - std::pow(0.025, 1e-3)).epsilon(1e-9));
  CHECK(std::isnan(clopper_pearson(0, 0).lo));
  CHECK_THROWS_AS(clopper_pearson(3, 2), InputError);
}

TEST_CASE("Clopper-Pearson intervals cover the true p at least 95 % of the time", "[stats]") {
  // Exact coverage: sum of the binomial probabilities of the counts whose interval contains p. If the bounds
  // were swapped or used alpha instead of alpha/2, coverage would fall below 0.95 for some p.
  for (long n : {20L, 64L, 1000L})
    for (double p : {0.003, 0.015, 0.05, 0.26, 0.5, 0.9}) {
      boost::math::binomial_distribution<> B(static_cast<double>(n), p);
      double coverage = 0;
      for (long k = 0; k <= n; ++k) {
        const Interval ci = clopper_pearson(k, n);
        if (ci.lo <= p && p <= ci.hi) coverage += boost::math::pdf(B, static_cast<double>(k));
      }
      INFO("n = " << n << ", p = " << p);
      CHECK(coverage >= 0.95);
      CHECK(coverage < 0.999);  // and not trivially wide
    }
}

TEST_CASE("standard error of a mean", "[stats]") {
  const MeanSe m = mean_se({1, 2, 3, 4, std::nan("")});
  CHECK(m.n == 4);
  CHECK(m.mean == 2.5);
  CHECK(m.se == Approx(std::sqrt(5.0 / 3.0 / 4.0)));  // s^2 = 5/3
  CHECK(std::isnan(mean_se({1}).se));
}

TEST_CASE("the anomaly summary carries intervals around every probability and errors of every mean", "[stats][foucault]") {
  systems::FoucaultPendulum base;  // the hour of the paper: P(jump > 1 deg) ~ 0.26 per run at h = 0.1
  const auto runs = run_anomaly_ensemble(base, anomaly_cases({0.1}, {1e-3}, {"contact-nh"}, {systems::Foucault::name}, 40),
                                         0.1 * geomint::pi / 180, 2);
  const auto cells = summarize_anomaly(base, runs, 0.1 * geomint::pi / 180);
  REQUIRE(cells.size() == 1);
  const auto& c = cells[0];
  for (std::size_t k = 0; k < 3; ++k) {
    const long over = std::lround(c.p_jump[k] * 40);
    const Interval expect = clopper_pearson(over, 40);
    CHECK(c.p_jump_ci[k].lo == expect.lo);
    CHECK(c.p_jump_ci[k].hi == expect.hi);
    CHECK(c.p_jump_ci[k].lo <= c.p_jump[k]);
    CHECK(c.p_jump[k] <= c.p_jump_ci[k].hi);
  }
  CHECK(c.p_jump[0] > 0);  // the case measures something
  CHECK(c.mean_jumps_se[0] > 0);
  CHECK(c.mean_jumps_se[0] < c.mean_jumps[0]);
  CHECK(c.p_energy_loss_ci.lo <= c.p_energy_loss);
  CHECK(c.p_energy_loss <= c.p_energy_loss_ci.hi);
}
