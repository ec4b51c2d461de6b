// The main claims of the perturbed-Kepler comparison (geomint/kepler_anchor.hpp, experiments/kepler_anchor.cpp),
// as numbers that would be wrong if a scheme, the system or the study were: who wins, by how much, and why.
#include <catch2/catch.hpp>

#include <cmath>
#include <map>
#include <string>

#include "geomint/constants.hpp"
#include "geomint/kepler_anchor.hpp"

using namespace geomint;

namespace {
const char* kSecond = "contact-trapezoid";
const char* kSixth = "yoshida6a:contact-trapezoid";
const char* kRk4 = "odeint-rk4";

std::map<std::string, KeplerScore> scores_of(const KeplerAnchor& res, const std::string& setting) {
  std::map<std::string, KeplerScore> m;
  for (const auto& sc : res.scores)
    if (sc.setting == setting) m.emplace(sc.method, sc);
  return m;
}

std::vector<KeplerSetting> settings_named(std::initializer_list<std::string> names) {
  std::vector<KeplerSetting> out;
  for (const auto& s : kepler_anchor_settings())
    for (const auto& n : names)
      if (s.name == n) out.push_back(s);
  return out;
}
}  // namespace

TEST_CASE("kepler anchor: at tau = 0.5 both contact integrators keep the orbit's energy and RK4 loses the orbit",
          "[kepler][anchor]") {
  const auto res = kepler_anchor(settings_named({"anchor-1", "anchor-2"}), {kSecond, kSixth, kRk4});
  for (const char* setting : {"anchor-1", "anchor-2"}) {
    auto m = scores_of(res, setting);
    const auto &two = m.at(kSecond), &six = m.at(kSixth), &rk4 = m.at(kRk4);
    INFO(setting << ": max |dE| 2nd " << two.max_energy_err << ", 6th " << six.max_energy_err << ", RK4 " << rk4.max_energy_err
                 << "; max |dq| " << two.max_position_err << ", " << six.max_position_err << ", " << rk4.max_position_err
                 << "; max |dM/M| " << two.max_momentum_err << ", " << six.max_momentum_err << ", " << rk4.max_momentum_err
                 << " (reference within " << two.reference_err << ")");
    REQUIRE(two.failure.empty());
    REQUIRE(six.failure.empty());
    REQUIRE(rk4.failure.empty());
    // RK4's energy (E0 = -1/2) turns positive: the orbit escapes (measured |dE| 7.1 and 5.2, |dq| 83 and 120)
    CHECK(rk4.max_energy_err > 1);
    CHECK(rk4.max_position_err > 50);
    // the anchor's measure: sixth-order contact beats RK4 by > 100x (measured 110x, 180x), second order by > 10x
    // (29x, 13x); both keep the energy bounded, the sixth order within 0.07
    CHECK(six.max_energy_err < 0.07);
    CHECK(two.max_energy_err < 0.5);
    CHECK(rk4.max_energy_err > 100 * six.max_energy_err);
    CHECK(rk4.max_energy_err > 10 * two.max_energy_err);
    // at 12.6 steps per orbit every method has lost the orbital phase: |dq| = O(1) (a, the orbit, is 1)
    CHECK(six.max_position_err > 1);
    // the angular momentum law: sixth order within 2e-4, RK4 off by 70 .. 96 %
    CHECK(six.max_momentum_err < 2e-4);
    CHECK(rk4.max_momentum_err > 0.5);
  }
  // anchor-1 sits at the forcing's Nyquist limit: theta tau = pi, so f(t_j) = a sin(pi j) = 0 at every grid point
  // and the trapezoid in t (second order) integrates the unperturbed problem. Its angular momentum stays M(0), off
  // the law by exactly 1 - exp(2a/theta) wherever cos(theta t_j) = -1. The sixth order's stages fall between
  // the grid points and see the friction.
  auto m = scores_of(res, "anchor-1");
  const double a = -0.07, theta = geomint::two_pi;
  CHECK(std::abs(m.at(kSecond).max_momentum_err - (1 - std::exp(2 * a / theta))) < 1e-12);
  CHECK(m.at(kSixth).max_momentum_err < 0.01 * m.at(kSecond).max_momentum_err);
}

TEST_CASE("kepler anchor: in the error-analysis setting the sixth order wins by 380x over RK4, which beats the second",
          "[kepler][anchor]") {
  const auto res = kepler_anchor(settings_named({"error-e0", "error-e0.5"}), {kSecond, kSixth, kRk4});
  std::map<std::string, double> momentum_two, momentum_rk4;
  for (const char* setting : {"error-e0", "error-e0.5"}) {
    auto m = scores_of(res, setting);
    const auto &two = m.at(kSecond), &six = m.at(kSixth), &rk4 = m.at(kRk4);
    INFO(setting << ": max |dq| 2nd " << two.max_position_err << ", 6th " << six.max_position_err << ", RK4 "
                 << rk4.max_position_err << "; |q_2nd - q_6th| " << two.diff_to_sixth << "; reference within "
                 << two.reference_err);
    // tau = 0.05, T = 200 (32 orbits): 6th 2.5e-7 / 2.2e-4, RK4 3.0e-4 / 8.2e-2, 2nd 0.18 / 1.9 (e = 0 / 0.5)
    CHECK(rk4.max_position_err > 300 * six.max_position_err);
    CHECK(two.max_position_err > 20 * rk4.max_position_err);
    // the reference is far below what it measures
    CHECK(six.reference_err < 0.05 * six.max_position_err);
    // the anchor's own error estimate for the second order, |x_2nd - x_6th|, is its error to 0.1 %
    CHECK(std::abs(two.diff_to_sixth - two.max_position_err) < 1e-3 * two.max_position_err);
    momentum_two[setting] = two.max_momentum_err;
    momentum_rk4[setting] = rk4.max_momentum_err;
  }
  // The variational schemes' angular momentum evolves by a factor that depends on t_j and h only (a discrete Noether
  // law of their rotation-invariant 𝓛 with the friction force along the chord), so its error does not depend on
  // the orbit: the same 2.6e-5 at e = 0 and e = 0.5. RK4's grows 50-fold with the eccentricity.
  CHECK(std::abs(momentum_two["error-e0"] / momentum_two["error-e0.5"] - 1) < 1e-3);
  CHECK(momentum_rk4["error-e0.5"] > 10 * momentum_rk4["error-e0"]);
}

TEST_CASE("kepler anchor: unknown settings, methods and tolerances are refused before any run", "[kepler][anchor]") {
  const auto one = settings_named({"anchor-1"});
  CHECK_THROWS_WITH(kepler_anchor(one, {"nosuch"}), Catch::Contains("unknown scheme 'nosuch'"));
  CHECK_THROWS_WITH(kepler_anchor(one, {"nosuch:contact-trapezoid"}), Catch::Contains("unknown composition family"));
  CHECK_THROWS_WITH(kepler_anchor(one, {kRk4}, 1e-20), Catch::Contains("tol"));
  auto bad = one;
  bad.front().e = 1;
  CHECK_THROWS_WITH(kepler_anchor(bad, {kRk4}), Catch::Contains("e must be in [0, 1)"));
}
