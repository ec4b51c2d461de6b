#include <catch2/catch.hpp>

#include <cmath>

#include "geomint/error.hpp"
#include "geomint/registry.hpp"
#include "geomint/study.hpp"
#include "geomint/sweep.hpp"

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

TEST_CASE("a fit reads only the band: above the reference's floor and below blow-up, at least three points",
          "[study][asymptotic][band]") {
  const auto hs = halving_sequence(0.2, 0.00313);  // 0.2 ... 0.003125: seven points
  std::vector<double> e;
  for (double h : hs) e.push_back(0.3 * std::pow(h, 4));
  // the coarsest run blew up (what a composition at too large a step does): with it the least-squares slope of
  // all finite points is far from any order; the band drops it
  e.front() = 1e112;
  CHECK(fit_order(hs, e).slope > 12);
  const FitBand band = fit_band(false, 1e-13, 1.0);  // Odeint at 1e-13, a solution of size 1
  CHECK(band.floor == Approx(1e-11));
  const auto f = fit_order(hs, e, band);
  CHECK(f.points == 6);
  CHECK(f.slope == Approx(4).epsilon(1e-12));
  const auto a = asymptotic_order(hs, e, band);
  CHECK(a.asymptotic());
  CHECK(a.slope == Approx(4).epsilon(1e-12));
  CHECK(a.dropped == 1);
  CHECK(a.describe().find("1 point outside") != std::string::npos);
  // the finest points at the reference's floor: only two left, so no order, and the report says so
  std::vector<double> g{2e-8, 3e-10, 4.9e-12, 3.8e-13, 4.4e-13, 1.5e-13, 3.4e-13};  // the pendulum's below
  CHECK(std::isnan(fit_order(hs, g, band).slope));
  CHECK(fit_order(hs, g, band).points == 2);
  const auto b = asymptotic_order(hs, g, band);
  CHECK_FALSE(b.asymptotic());
  // against a closed form the floor is round-off
  CHECK(fit_band(true, 1e-13, 1.0).floor == 1e-13);
}

TEST_CASE("convergence on the pendulum: no order fitted through the Odeint reference's floor", "[study][band]") {
  // yoshida6a:contact-trapezoid reaches the reference's 1e-13 accuracy by h = 0.025: its four finest errors read the
  // reference. A fit through them reported order 2.60 for a sixth-order method; only two points lie above the floor
  // (100 tol), so there is no order at these h, and the series says so.
  const SystemInfo& sys = find_system("pendulum");
  const auto hs = halving_sequence(0.1, 0.003);
  const auto study = convergence_study(sys, {{}}, {"yoshida6a:contact-trapezoid"}, hs, Path::fast,
                                       ReferenceKind::automatic, 1e-13, Sweep::world());
  REQUIRE(study.series.size() == 1);
  const auto& se = study.series.front();
  CHECK(se.band.floor == Approx(1e-11));
  int above = 0;
  for (double x : se.err) above += x > se.band.floor;
  INFO("errors: " << se.err[0] << " " << se.err[1] << " " << se.err[2] << " " << se.err[3] << " " << se.err[4] << " "
                  << se.err[5] << "; " << se.asymptotic.describe());
  CHECK(above < 3);
  CHECK(se.fit.points == above);
  CHECK(std::isnan(se.fit.slope));
  CHECK_FALSE(se.asymptotic.asymptotic());
  // the coarse points that are above the floor fall at the method's sixth order
  CHECK(std::log(se.err[0] / se.err[1]) / std::log(2.0) == Approx(6).margin(0.3));
}
