// The continuous equations the core derives from L, F and Phi by automatic differentiation, against each
// system's hand-written equations; and the Herglotz form against the Lagrange–d'Alembert form (the same
// motion, so the contact schemes and the LA schemes share one reference).
#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <tuple>

#include "geomint/generic/system.hpp"
#include "geomint/systems/forced_oscillator.hpp"
#include "geomint/systems/foucault.hpp"
#include "geomint/systems/knife_edge.hpp"
#include "geomint/systems/nonholonomic_particle.hpp"
#include "geomint/systems/oscillator.hpp"
#include "geomint/systems/pendulum.hpp"

using namespace geomint;

namespace {

template <class Sys>
void check_equations(const Sys& sys) {
  constexpr int n = Sys::dof;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  double worst_rhs = 0, worst_herglotz = 0;
  for (int k = 0; k < 100; ++k) {
    const double t = 10 * std::abs(u(rng));
    Vec<double, n> q, v;
    for (int i = 0; i < n; ++i) {
      q(i) = u(rng);
      v(i) = u(rng);
    }
    if (q.norm() < 0.1) continue;
    v = generic::consistent_velocity(sys, t, q, v);  // on the constraint, where the equations are compared
    const auto a = generic::acceleration(sys, t, q, v);
    Vec<double, n> hand;
    sys.rhs(t, q, v, hand);
    worst_rhs = std::max(worst_rhs, (a.a - hand).template lpNorm<Eigen::Infinity>() / (1 + hand.norm()));
    if constexpr (generic::has_herglotz_v<Sys>) {
      const auto b = generic::herglotz_acceleration(sys, t, q, v, u(rng));
      worst_herglotz = std::max(worst_herglotz, (a.a - b.a).template lpNorm<Eigen::Infinity>() / (1 + hand.norm()));
    }
  }
  INFO(Sys::name << ": AD vs hand " << worst_rhs << ", Herglotz vs LA " << worst_herglotz);
  CHECK(worst_rhs < 1e-13);
  CHECK(worst_herglotz < 1e-13);
}

}  // namespace

TEST_CASE("equations derived from the Lagrangian equal the hand-written ones, in both forms", "[generic][equations]") {
  check_equations(systems::Oscillator{});
  check_equations(systems::ForcedOscillator{});
  check_equations(systems::Pendulum{});
  systems::Foucault f;
  f.scene.Omega = 0.05;  // a visible constraint force
  check_equations(f);
  check_equations(systems::NonholonomicParticle{});
  check_equations(systems::KnifeEdge{});
}

TEST_CASE("the kinetic-metric projection puts the initial velocity on the constraint", "[generic][equations]") {
  systems::KnifeEdge k;
  k.I = 3;  // a metric that is not a multiple of the identity
  const Vec<double, 3> q(0.3, -0.2, 0.7), v(1.0, 0.4, -0.5);
  const Vec<double, 3> w = generic::consistent_velocity(k, 0.0, q, v);
  CHECK(std::abs(generic::constraint<systems::KnifeEdge, double>(k, 0.0, q, w)(0)) < 1e-15);
  // the change is M^{-1} A^T mu: M-orthogonal to the constraint's kernel, here the heading rate is untouched
  CHECK(w(2) == Approx(v(2)).epsilon(1e-15));
}

TEST_CASE("closed-form solutions solve their equations", "[generic][equations]") {
  // d/dt of the exact velocity (central difference, h = 1e-4: error ~ h^2 |q''''| ~ 1e-8) equals the acceleration
  auto check = [](const auto& sys, double t) {
    const double e = 1e-4;
    const auto x = sys.template exact<double>(t), xp = sys.template exact<double>(t + e), xm = sys.template exact<double>(t - e);
    const auto a = generic::acceleration(sys, t, x.q, x.v);
    CHECK(((xp.v - xm.v) / (2 * e) - a.a).norm() < 1e-8);
    CHECK(((xp.q - xm.q) / (2 * e) - x.v).norm() < 1e-8);
  };
  systems::ForcedOscillator f;
  for (double t : {0.0, 3.3, 40.0}) check(f, t);
  f.dq0 = 0.2;
  f.dv0 = -0.1;
  for (double t : {0.5, 7.0}) check(f, t);
  check(systems::Oscillator{}, 2.0);
  systems::Foucault fo;
  fo.scene.alpha = 0.1;
  for (double t : {1.0, 30.0}) check(fo, t);
}
