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

TEST_CASE("the asymptotic-range rule: an order where the local orders agree, pre-asymptotic where they drift",
          "[study][asymptotic]") {
  // e = h + 40 h^2: second order at large h, first order below h ~ 1/40, the crossover in between
  auto series = [](double h_max, int halvings) {
    std::vector<double> hs, e;
    for (int k = 0; k <= halvings; ++k) {
      hs.push_back(h_max / std::pow(2.0, k));
      e.push_back(hs.back() + 40 * hs.back() * hs.back());
    }
    return std::make_pair(hs, e);
  };
  {
    // through the crossover (local orders 1.74 1.58 1.42 1.26 1.15): no three finest points agree within 0.1
    const auto [hs, e] = series(0.1, 5);
    const auto a = asymptotic_order(hs, e);
    CHECK(a.status == AsymptoticOrder::Status::pre_asymptotic);
    CHECK(a.points == 2);
    REQUIRE(a.local_orders.size() == 5);
    CHECK(a.local_orders.back() == Approx(std::log((hs[4] + 40 * hs[4] * hs[4]) / e[5]) / std::log(2.0)));
    CHECK(a.describe().find("pre-asymptotic") != std::string::npos);
  }
  {
    // far below it (40 h <= 0.01): local orders within 0.01 of 1
    const auto [hs, e] = series(2.5e-4, 5);
    const auto a = asymptotic_order(hs, e);
    CHECK(a.status == AsymptoticOrder::Status::asymptotic);
    CHECK(a.points == 6);
    CHECK(a.slope == Approx(1).margin(0.01));
    CHECK(a.h_max == hs.front());
    CHECK(a.h_min == hs.back());
  }
  {
    // a pure power law with its finest point at round-off: that point is dropped, the rest is the order
    auto [hs, e] = series(0.1, 5);
    for (std::size_t i = 0; i < hs.size(); ++i) e[i] = 3 * std::pow(hs[i], 2);
    e.back() = 1e-16;
    e[1] = std::nan("");  // a failed run: dropped too
    const auto a = asymptotic_order(hs, e);
    CHECK(a.asymptotic());
    CHECK(a.points == 4);
    CHECK(a.slope == Approx(2).epsilon(1e-12));
  }
  CHECK(asymptotic_order({0.1, 0.05}, {1e-3, std::nan("")}).status == AsymptoticOrder::Status::too_few_points);
}
