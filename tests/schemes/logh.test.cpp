// The logH leapfrog and its compositions (generic/logh.hpp) on the Kepler problem: the separable form held to the
// system's L and force, symmetry, the two-body laws at round-off at every step size, the phase order in t, and the
// angular-momentum law with friction (and its loss when the friction is applied over the kick's dt).
//
// What is checked independently of the scheme's own formulas: the separable pieces (T, dT/dp, U, grad ln U, the
// integral of the friction) against the system's Lagrangian and force by automatic differentiation and quadrature;
// the scheme against the exact Kepler solution (Kepler's equation) and, with friction, against Boost.Odeint on the
// system's hand-written equations — a wrong substep (a sign, a half step, a friction interval, W) shows as a lost
// law or a wrong order.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "geomint/constants.hpp"
#include "geomint/generic/composition_families.hpp"
#include "geomint/generic/logh.hpp"
#include "geomint/generic/system.hpp"
#include "geomint/registry.hpp"
#include "geomint/study.hpp"
#include "geomint/systems/kepler.hpp"

using namespace geomint;
using geomint::generic::FrictionOver;
using geomint::generic::Logh;
using Kep = geomint::systems::Kepler;
using V2 = Vec<double, 2>;

namespace {


Kep kepler(double e, double alpha = 0, double a = 0) {
  Kep k;
  k.e = e;
  k.alpha = alpha;
  k.a = a;
  return k;
}

// The exact unperturbed orbit from the pericentre (semi-major axis 1, mean motion 1): E - e sin E = t.
V2 exact_position(double e, double t) {
  double E = t + e * std::sin(t);
  for (int i = 0; i < 50; ++i) {
    const double d = (E - e * std::sin(E) - t) / (1 - e * std::cos(E));
    E -= d;
    if (std::abs(d) < 1e-16 * (1 + std::abs(E))) break;
  }
  return V2(std::cos(E) - e, std::sqrt(1 - e * e) * std::sin(E));
}

struct Laws {
  double E, M, A1, A2;
};
Laws laws(const V2& q, const V2& p) {
  const double r = q.norm(), M = q(0) * p(1) - q(1) * p(0);
  return {p.squaredNorm() / 2 - 1 / r, M, p(1) * M - q(0) / r, -p(0) * M - q(1) / r};
}

Logh<Kep> started(const Kep& k, double h, const generic::CompositionFamily* f = nullptr,
                  FrictionOver over = FrictionOver::drift) {
  Logh<Kep> s(k, h, f, over);
  s.start(k.initial_position<double>(), k.initial_velocity<double>());
  return s;
}

std::vector<double> output_times(double orbits, int per_orbit) {
  std::vector<double> t;
  const long n = std::lround(orbits * per_orbit);
  for (long i = 1; i <= n; ++i) t.push_back(static_cast<double>(i) * two_pi / per_orbit);
  return t;
}

}  // namespace

TEST_CASE("logh: Kepler's separable form is its Lagrangian and its force", "[logh]") {
  const Kep k = kepler(0.4, 1e-3, -0.07);
  for (const auto& [t, q, v] : {std::tuple{0.3, V2(0.7, -0.2), V2(0.1, 1.3)}, std::tuple{2.9, V2(-1.4, 0.5), V2(-0.6, -0.2)}}) {
    const V2 p = generic::momentum(k, t, q, v);
    CHECK((p - v).norm() < 1e-15);
    CHECK((k.kinetic_gradient(p) - v).norm() < 1e-15);
    // L = T + U for p = dL/dq': the separable Hamiltonian is L's Legendre transform
    CHECK(std::abs(k.kinetic(p) + k.attraction(q) - k.lagrangian(t, q, v)) < 1e-14);
    const V2 g = generic::gradient<2, double>(
        [&](const auto& Q) {
          using std::log;
          return log(k.attraction(Q));
        },
        q);
    CHECK((k.log_attraction_gradient(q) - g).norm() < 1e-14);
    // the force is -gamma(t) p, gamma = d/dt of the declared integral (5-point Gauss–Legendre on [t, t + 0.1] of
    // the system's own friction: its error, ~(0.1 theta)^10/10^6 here, is round-off)
    CHECK((k.force(t, q, v) + k.friction(t) * p).norm() < 1e-15);
    const double x[5] = {-0.9061798459386640, -0.5384693101056831, 0, 0.5384693101056831, 0.9061798459386640};
    const double w[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665, 0.2369268850561891};
    double quad = 0;
    for (int i = 0; i < 5; ++i) quad += 0.05 * w[i] * k.friction(t + 0.05 * (1 + x[i]));
    CHECK(std::abs(k.damping_integral(t, t + 0.1) - quad) < 1e-15);
  }
}

// a = -0.07: the drift split about its friction (time-dependent); a = 0: the drift's exact flow, merged between stages
TEST_CASE("logh: a step of -h undoes a step of h, with friction, for the leapfrog and its composition", "[logh]") {
  for (const auto& [fam, a] : {std::pair{"", -0.07}, std::pair{"yoshida4", -0.07}, std::pair{"", 0.0}, std::pair{"yoshida4", 0.0}}) {
    const Kep k = kepler(0.9, 1e-2, a);
    const generic::CompositionFamily* f = *fam ? &generic::find_composition_family(fam) : nullptr;
    Logh<Kep> s = started(k, 0.05, f);
    for (int j = 0; j < 7; ++j) s.step();
    Logh<Kep>::State x = s.state(), y = x;
    s.step(y, 0.05);
    s.step(y, -0.05);
    INFO(fam << ", a = " << a);
    CHECK((y.q - x.q).norm() < 1e-14);
    CHECK((y.p - x.p).norm() < 1e-13);
    CHECK(std::abs(y.t - x.t) < 1e-14);
    CHECK(std::abs(y.B - x.B) < 1e-13);
  }
}

// Round-off over 10^3 orbits: the map keeps the Kepler orbit exactly, so all that moves E and A is the rounding of
// q and p, a few ulp a step, walking like sqrt(N) eps over N = 1000 k steps; E = T - U and A are computed from
// terms up to U_max = 1/(1 - e) while |E| = 1/2, which magnifies it by 2/(1 - e) (3.3 at e = 0.4, 20 at e = 0.9).
// The bound is 10 sqrt(N) eps 2/(1 - e): 1.3e-12 .. 5.2e-12 at e = 0.4, 7.9e-12 .. 3.2e-11 at e = 0.9 (measured:
// 2e-14 .. 2.7e-13 and 2e-14 .. 1.3e-12), far below the O(h^2) error of a fixed-step second-order map (the
// trapezoid's Laplace–Runge–Lenz vector turns by 0.017 over 10^2 orbits at k = 512: docs/speed-accuracy.md).
TEST_CASE("logh on pure Kepler: energy and the Laplace–Runge–Lenz vector at round-off over 1000 orbits at every step",
          "[logh]") {
  for (double e : {0.4, 0.9}) {
    for (int k : {32, 128, 512}) {
      const Kep kep = kepler(e);
      Logh<Kep> s = started(kep, two_pi / k);
      const Laws l0 = laws(s.state().q, s.state().p);
      double dE = 0, dA = 0, dM = 0;
      s.run_to(output_times(1000, 1), [&](std::size_t, const Logh<Kep>::State& x) {
        const Laws l = laws(x.q, x.p);
        dE = std::max(dE, std::abs(l.E / l0.E - 1));
        dA = std::max(dA, std::hypot(l.A1 - l0.A1, l.A2 - l0.A2));
        dM = std::max(dM, std::abs(l.M / l0.M - 1));
      });
      const double bound = 10 * std::sqrt(1000.0 * k) * 2.2e-16 * 2 / (1 - e);
      INFO("e = " << e << ", k = " << k << ": energy " << dE << ", LRL " << dA << ", M " << dM << " (bound " << bound << ")");
      CHECK(dE < bound);
      CHECK(dA < bound);
      CHECK(dM < bound);
    }
  }
}

// The phase error max |q(t_i) - q_exact(t_i)| at 8 output times an orbit over 10 orbits (reached by partial steps
// of the method itself), fitted on its asymptotic range (study.hpp's rule): 2 for the leapfrog, 4 for yoshida4,
// 6 for yoshida6a.
TEST_CASE("logh on pure Kepler: the phase error's order in t is the method's", "[logh]") {
  struct Case {
    const char* family;
    int order;
    std::vector<int> ks;
  };
  for (double e : {0.4, 0.9}) {
    for (const Case& c : {Case{"", 2, {64, 128, 256, 512, 1024}}, Case{"yoshida4", 4, {32, 64, 128, 256}},
                          Case{"yoshida6a", 6, {16, 32, 64, 128}}}) {
      std::vector<double> hs, errs;
      for (int k : c.ks) {
        const Kep kep = kepler(e);
        const generic::CompositionFamily* f = *c.family ? &generic::find_composition_family(c.family) : nullptr;
        Logh<Kep> s = started(kep, two_pi / k, f);
        double err = 0;
        s.run_to(output_times(10, 8), [&](std::size_t, const Logh<Kep>::State& x) {
          err = std::max(err, (x.q - exact_position(e, x.t)).norm());
        });
        hs.push_back(two_pi / k);
        errs.push_back(err);
      }
      const auto fit = asymptotic_order(hs, errs, 0.25, 1e-12);
      INFO("e = " << e << ", " << (*c.family ? c.family : "leapfrog") << ": " << fit.describe());
      REQUIRE(fit.asymptotic());
      CHECK(std::abs(fit.slope - c.order) < 0.3);
    }
  }
}

// With friction f(t) = alpha + a sin(theta t): the drifts and the kick keep M = q x p, and the friction scales it
// by exp(-int f) over exactly the intervals t advances over, so M(t_i) = M(0) exp(-int_0^{t_i} f) holds to
// round-off (~sqrt(4N) ulp for the 4N scalings of N steps). Applied over the kick's dt = s/U instead, it acts over
// intervals that do not tile [0, t]: the law is then off by O(h^2).
TEST_CASE("logh with friction: the angular-momentum law at round-off, and over the kick's dt it is lost", "[logh]") {
  for (const auto& [e, a] : {std::pair{0.4, -0.07}, std::pair{0.9, -0.07}, std::pair{0.4, 0.0}}) {
    const Kep kep = kepler(e, 1e-3, a);
    auto worst = [&](FrictionOver over, int k, const char* fam) {
      const generic::CompositionFamily* f = *fam ? &generic::find_composition_family(fam) : nullptr;
      Logh<Kep> s = started(kep, two_pi / k, f, over);
      const double M0 = laws(s.state().q, s.state().p).M;
      double err = 0;
      s.run_to(output_times(100, 8), [&](std::size_t, const Logh<Kep>::State& x) {
        err = std::max(err, std::abs(laws(x.q, x.p).M / (M0 * kep.angular_momentum_factor(x.t)) - 1));
      });
      return err;
    };
    for (int k : {32, 256}) {
      const double drift = worst(FrictionOver::drift, k, ""), y4 = worst(FrictionOver::drift, k, "yoshida4"),
                   kick = worst(FrictionOver::kick, k, "");
      INFO("e = " << e << ", a = " << a << ", k = " << k << ": over the drift " << drift << " (yoshida4 " << y4 << "), over the kick " << kick);
      CHECK(drift < 1e-12);
      CHECK(y4 < 1e-12);
      CHECK(kick > 1e-7);
    }
  }
}

// With friction the scheme still converges at its order to the continuous equations (Odeint on the system's
// hand-written right-hand side): the friction's placement in the drift is consistent, not only law-keeping.
TEST_CASE("logh with friction converges at order 2 (leapfrog) and 4 (yoshida4) to the continuous equations", "[logh]") {
  for (const double a : {-0.07, 0.0}) {
  const double e = 0.4, alpha = 1e-2;
  const SystemInfo& sys = find_system("kepler");
  const double T = 3 * two_pi;
  const ParamValues pv{{"a", a}, {"alpha", alpha}, {"e", e}, {"T", T}};
  const long n_out = 24;
  const Reference ref = sys.reference(pv, T / n_out, n_out, ReferenceKind::odeint_rhs, 1e-13);
  const auto times = output_times(3, 8);
  for (const auto& [fam, order, ks] : {std::tuple{"", 2, std::vector<int>{64, 128, 256, 512}},
                                       std::tuple{"yoshida4", 4, std::vector<int>{32, 64, 128, 256}}}) {
    std::vector<double> hs, errs;
    for (int k : ks) {
      const Kep kep = kepler(e, alpha, a);
      const generic::CompositionFamily* f = *fam ? &generic::find_composition_family(fam) : nullptr;
      Logh<Kep> s = started(kep, two_pi / k, f);
      double err = 0;
      s.run_to(times, [&](std::size_t i, const Logh<Kep>::State& x) {
        const std::size_t r = 2 * (i + 1);
        err = std::max(err, std::hypot(x.q(0) - ref.q[r], x.q(1) - ref.q[r + 1]));
      });
      hs.push_back(two_pi / k);
      errs.push_back(err);
    }
    const auto fit = asymptotic_order(hs, errs, 0.25, 1e-10);
    INFO((*fam ? fam : "leapfrog") << ", a = " << a << ": " << fit.describe());
    REQUIRE(fit.asymptotic());
    CHECK(std::abs(fit.slope - order) < 0.3);
  }
  }
}
