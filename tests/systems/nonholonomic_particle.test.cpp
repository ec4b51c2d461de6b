// The "add a system" example of docs/extending.md: the damped nonholonomic particle and its LA integrator.
#include <catch2/catch.hpp>

#include <cmath>

#include "geomint/reference.hpp"
#include "geomint/study.hpp"
#include "generic_checks.hpp"
#include "geomint/systems/nonholonomic_particle.hpp"

using namespace geomint;
using V3 = Eigen::Vector3d;
using systems::NonholonomicParticle;

TEST_CASE("particle: every step satisfies the forced discrete EL equations and the discrete constraint",
          "[example][system]") {
  const NonholonomicParticle P{2.0, 1.5, 0.2};
  const double h = 0.05;
  V3 q(1, 0.5, -0.3), v(0.2, -0.4, 0.2 * 0.5);  // a . v = -y x' + z' = 0 initially
  double worst_el = 0, worst_c = 0;
  for (int j = 0; j < 2000; ++j) {
    const V3 qj = q, vm = v;
    const double lm = systems::NonholonomicParticle::La::step(P, q, v, h);
    // literal: m v_{j-1} - m (1 + h alpha) v_j - h m w2 q_j - lambda a(q_j) = 0
    const V3 a(-qj(1), 0, 1);
    const V3 el = P.m * vm - P.m * (1 + h * P.alpha) * v - h * P.m * P.w2 * qj - P.m * lm * a;
    worst_el = std::max(worst_el, el.lpNorm<Eigen::Infinity>() / (P.m * (vm.norm() + h * P.w2 * qj.norm())));
    // round-off scale of a . v_j: v_j is v* minus its normal part, so its error is ~ eps |v*|
    worst_c = std::max(worst_c, std::abs(a.dot(v)) / (a.norm() * (vm.norm() + h * P.w2 * qj.norm() + v.norm())));
  }
  CHECK(worst_el < 1e-14);
  CHECK(worst_c < 1e-14);
}

TEST_CASE("particle: first order against the continuous Lagrange-d'Alembert equations", "[example][system]") {
  const NonholonomicParticle P{1.0, 1.0, 0.1};
  const double T = 10;
  const V3 q0(1, 0.5, -0.3), v0(0.2, -0.4, 0.2 * 0.5);
  const auto hs = halving_sequence(0.1, 0.003);
  std::vector<double> errs;
  for (double h : hs) {
    const long N = step_count(h, T);
    std::vector<double> times;
    for (long j = 0; j <= N; ++j) times.push_back(static_cast<double>(j) * h);
    const auto ref = odeint_dense<6>([&](const std::array<double, 6>& x, std::array<double, 6>& dx, double) { dx = P.rhs(x); },
                                     {q0(0), q0(1), q0(2), v0(0), v0(1), v0(2)}, times, 1e-12);
    // start: v_{-1} from the consistent velocity, as the Legendre start of (15) (LA: q_{-1} = q0 - h v0)
    V3 q = q0, v = v0;
    double err = 0;
    for (long j = 1; j <= N; ++j) {
      systems::NonholonomicParticle::La::step(P, q, v, h);
      const auto& r = ref[static_cast<size_t>(j)];
      err = std::max(err, (q - V3(r[0], r[1], r[2])).lpNorm<Eigen::Infinity>());
    }
    errs.push_back(err);
  }
  CHECK(fit_order(hs, errs).slope == Approx(1).margin(0.1));
}

TEST_CASE("particle: the continuous reference keeps its constraint and loses energy at rate alpha m |v|^2",
          "[example][system]") {
  const NonholonomicParticle P{1.0, 1.0, 0.1};
  const V3 q0(1, 0.5, -0.3), v0(0.2, -0.4, 0.2 * 0.5);
  std::vector<double> times;
  for (int j = 0; j <= 100; ++j) times.push_back(0.1 * j);
  const auto ref = odeint_dense<6>([&](const std::array<double, 6>& x, std::array<double, 6>& dx, double) { dx = P.rhs(x); },
                                   {q0(0), q0(1), q0(2), v0(0), v0(1), v0(2)}, times, 1e-12);
  for (const auto& r : ref) CHECK(std::abs(-r[1] * r[3] + r[5]) < 1e-9);
  CHECK_THROWS_AS((NonholonomicParticle{0, 1, 0.1}.validate()), InputError);
  CHECK_THROWS_AS((NonholonomicParticle{1, 1, -0.1}.validate()), InputError);
}

TEST_CASE("particle: the LA step is the fast path of the generic la scheme, equations from L and Phi",
          "[example][system][generic]") {
  systems::NonholonomicParticle sys;
  testing::check_all_fast_paths(sys, 0.05, 20000);
  testing::check_equations(sys);
}

TEST_CASE("particle: Newton's Jacobian, lambda columns from the rows, is the full forward pass's", "[generic][newton]") {
  testing::check_linearization(systems::NonholonomicParticle{}, 0.05);
}

TEST_CASE("particle: a kept Jacobian, its constraint block brought up to date, solves a step in one update, and with linear dynamics without a second evaluation",
          "[generic][newton]") {
  testing::check_kept_jacobian(systems::NonholonomicParticle{}, 0.05, 2000);  // ten times the horizon: the shortcut's check runs
}
