// The closed-form solution against a tight Boost.Odeint solution, in all three damping regimes.
#include <catch2/catch.hpp>

#include <cmath>

#include "geomint/systems/oscillator.hpp"
#include "geomint/reference.hpp"

using namespace geomint;

namespace {
// The oscillator system's closed-form solution (linear_oscillator_solution with b = 1).
LinearOscillatorSolution<double> oscillator_exact(double alpha, double q0, double p0, double t) {
  const auto x = systems::Oscillator{alpha, q0, p0}.exact<double>(t);
  return {x.q(0), x.v(0)};
}
}  // namespace

TEST_CASE("closed-form solution matches Odeint at tolerance 1e-13", "[oscillator][exact]") {
  // under-damped, near-critical on both sides, critical, over-damped
  const double regimes[] = {0.01, 0.1, 1.0, 2.0 - 1e-9, 2.0, 2.0 + 1e-9, 3.0, 10.0};
  std::vector<double> times;
  for (int j = 0; j <= 500; ++j) times.push_back(0.1 * j);
  for (double alpha : regimes) {
    const auto ref = oscillator_odeint(alpha, -0.25, 0.75, times, 1e-13);
    double worst = 0;
    for (size_t j = 0; j < times.size(); ++j) {
      const auto ex = oscillator_exact(alpha, -0.25, 0.75, times[j]);
      worst = std::max({worst, std::abs(ex.q - ref[j][0]), std::abs(ex.v - ref[j][1])});
    }
    INFO("alpha " << alpha);
    CHECK(worst < 1e-10);
  }
}

TEST_CASE("closed form: initial data and the ODE residual", "[oscillator][exact]") {
  for (double alpha : {0.5, 2.0, 4.0}) {
    const auto s0 = oscillator_exact(alpha, 0.3, -0.7, 0.0);
    CHECK(s0.q == Approx(0.3).epsilon(1e-15));
    CHECK(s0.v == Approx(-0.7).epsilon(1e-15));
    // q'' + alpha q' + q = 0 by a centred difference of v
    const double t = 1.3, d = 1e-5;
    const auto a = oscillator_exact(alpha, 0.3, -0.7, t), p = oscillator_exact(alpha, 0.3, -0.7, t + d),
               m = oscillator_exact(alpha, 0.3, -0.7, t - d);
    CHECK(std::abs((p.v - m.v) / (2 * d) + alpha * a.v + a.q) < 1e-8);
  }
}
