#include <catch2/catch.hpp>

#include <cmath>

#include "geomint/error.hpp"
#include "geomint/study.hpp"

using namespace geomint;

TEST_CASE("fit_order recovers a known power law and drops round-off", "[study]") {
  const auto hs = halving_sequence(0.2, 0.003);
  std::vector<double> e;
  for (double h : hs) e.push_back(3.7 * std::pow(h, 1.5));
  CHECK(fit_order(hs, e).slope == Approx(1.5).epsilon(1e-12));
  e.back() = 1e-16;  // a round-off point: dropped, fit unchanged
  const auto f = fit_order(hs, e);
  CHECK(f.points == static_cast<int>(hs.size()) - 1);
  CHECK(f.slope == Approx(1.5).epsilon(1e-12));
  CHECK(std::isnan(fit_order({0.1, 0.05}, {1e-2, 5e-3}).slope));  // fewer than three points
  const auto o = observed_orders(hs, e);
  CHECK(std::isnan(o[0]));
  CHECK(o[1] == Approx(1.5).epsilon(1e-12));
}

TEST_CASE("step_count lands exactly on T or refuses", "[study]") {
  CHECK(step_count(0.1, 50) == 500);
  CHECK(step_count(0.003125, 50) == 16000);
  CHECK_THROWS_AS(step_count(0.3, 50), InputError);
  CHECK_THROWS_AS(step_count(0, 50), InputError);
  CHECK_THROWS_AS(step_count(-0.1, 50), InputError);
  CHECK_THROWS_AS(step_count(60, 50), InputError);
  CHECK_THROWS_AS(step_count(std::nan(""), 50), InputError);
}
