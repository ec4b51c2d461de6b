// Modified equations of compositions (modified/composed_residual.hpp): a composition's three-point residual is
// its own (it vanishes on the composition's steps), its stage problem is solved to every coefficient the engine
// reads, the composition of h/2 twice (h/3 three times) has the base scheme's modified equation at h/2 (h/3) —
// against the residual engine —, a composition of order p has F_1 ... F_{p-1} = 0 to round-off and F_p != 0 on
// every system and symmetric base, on the linear oscillator its F_k are the coefficients of the exact modified
// equation read off the composition's one-step matrix, and its discrete solutions follow the truncated modified
// equation at the slopes of its order.
// The table of max |F_k| (k = 1..p) for every system, base and family is printed (WARN):
//   build/tests/geomint_tests "[composition][modified][table]"
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "geomint/generic/composition.hpp"
#include "geomint/generic/composition_families.hpp"
#include "geomint/modified/automatic.hpp"
#include "geomint/modified/automatic_registry.hpp"
#include "geomint/registry.hpp"
#include "geomint/study.hpp"
#include "geomint/systems/knife_edge.hpp"
#include "geomint/systems/pendulum.hpp"

using namespace geomint;
using namespace geomint::modified;

namespace {

generic::CompositionFamily equal_steps(int s) {
  generic::CompositionFamily f{"equal" + std::to_string(s), "s equal steps h/s", 2, {}};
  for (int i = 0; i < s; ++i) f.weights.push_back(1.0L / s);
  return f;
}

// A point on the system's constraint: q, and v projected (the kinetic metric).
template <class Sys>
void point_of(const Sys& sys, Vec<double, Sys::dof>& q, Vec<double, Sys::dof>& v, std::mt19937& rng) {
  std::uniform_real_distribution<double> U(-1, 1);
  q = sys.template initial_position<double>();
  for (int i = 0; i < Sys::dof; ++i) {
    q(i) += 0.3 * U(rng);
    v(i) = 0.5 * U(rng);
  }
  v = generic::consistent_velocity(sys, 0.2, q, v);
}

// The composition of h/s s times against the base scheme's modified equation at h/s: F_k / s^k (and Z_k, phi_k).
template <class Sys, class G>
void check_equal_steps(const Sys& sys, const char* label) {
  constexpr int K = 4;
  std::mt19937 rng(11);
  for (int s : {1, 2, 3}) {
    const auto family = equal_steps(s);
    const ModifiedEquation<Sys, G, 6> base(sys), comp(sys, family);
    for (int trial = 0; trial < 3; ++trial) {
      Vec<double, Sys::dof> q, v;
      point_of(sys, q, v, rng);
      typename ModifiedEquation<Sys, G, 6>::Result rb, rc;
      base.evaluate(0.2, q, v, 0.3, K, rb, true);
      comp.evaluate(0.2, q, v, 0.3, K, rc, true);
      double scale = 0, diff = 0;
      for (int k = 0; k <= K; ++k) {
        const double f = std::pow(double(s), -k);
        scale = std::max({scale, rb.F[k].cwiseAbs().maxCoeff(), std::abs(rb.Z[k])});
        diff = std::max({diff, (rc.F[k] - f * rb.F[k]).cwiseAbs().maxCoeff(), std::abs(rc.Z[k] - f * rb.Z[k])});
        if constexpr (Sys::constraints > 0) diff = std::max(diff, (rc.phi[k] - f * rb.phi[k]).cwiseAbs().maxCoeff());
      }
      INFO(label << ", " << s << " steps of h/" << s << ": |F_k - F_k(base)/s^k| " << diff << " against |F| " << scale
                 << "; residual " << rc.residual);
      CHECK(diff <= 1e-13 * scale);
      CHECK(rc.residual <= 1e-13 * scale);
    }
  }
}

}  // namespace

TEST_CASE("a composition's residual vanishes on its steps: its stage points, constraint and action",
          "[composition][modified]") {
  // The composition steps (Newton on each stage's rows in position-momentum form); its three-point residual at
  // q_1 (each step's stage points solved from q_0, q_1 and q_1, q_2 alone) with the first stage's impulse of the
  // step from q_1 must vanish, and so must the discrete constraint and the action row.
  auto run = [](const auto& sys, auto g, const char* label) {
    using Sys = std::decay_t<decltype(sys)>;
    using G = decltype(g);
    constexpr int n = Sys::dof, m = Sys::constraints;
    for (const auto& family : generic::composition_families()) {
      const double h = 0.1;
      generic::Composition<Sys, G> c(sys, family, h);
      c.start(sys.template initial_position<double>(), sys.template initial_velocity<double>());
      std::vector<Vec<double, n>> q{c.state().q};
      std::vector<double> z{c.state().z};
      Vec<double, m> first = Vec<double, m>::Zero();
      for (int j = 0; j < 3; ++j) {
        c.step([&](std::size_t i, const auto&, const auto& out) {
          if (i == 0 && j == 2) first = out.lambda;
        });
        q.push_back(c.state().q);
        z.push_back(c.state().z);
      }
      const ComposedResidual<Sys, G> cr(family);
      const auto before = cr.step(sys, h, h, q[1], q[2], z[1], z[2]);
      const auto after = cr.step(sys, 2 * h, h, q[2], q[3], z[2], z[3]);
      const Vec<double, n> R = cr.residual(sys, 2 * h, h, before, after, first);
      const double p = generic::momentum(sys, 0.0, q[2], Vec<double, n>((q[3] - q[2]) / h)).cwiseAbs().maxCoeff();
      INFO(label << " " << family.name << ": residual " << R.cwiseAbs().maxCoeff() << " against |p| " << p
                 << ", stage iterations " << after.iterations);
      CHECK(R.cwiseAbs().maxCoeff() <= 1e-12 * p);
      if constexpr (m > 0) CHECK(after.phi.cwiseAbs().maxCoeff() <= 1e-13);
      if constexpr (G::contact) CHECK(std::abs(z[3] - z[2] - after.action) <= 1e-13);
    }
  };
  systems::Pendulum pendulum;
  systems::KnifeEdge knife;
  run(pendulum, generic::LaTrapezoid{}, "pendulum la-trapezoid");
  run(pendulum, generic::ContactTrapezoid{}, "pendulum contact-trapezoid");
  run(knife, generic::LaMidpoint{}, "knife-edge la-midpoint");
  run(knife, generic::ContactTrapezoid{}, "knife-edge contact-trapezoid");
}

TEST_CASE("the stage points are solved to every coefficient the engine reads, cold, warm and shifted",
          "[composition][modified]") {
  // Series in (eps, h) for q~(t + eps) and q~(t + eps + h) (random Taylor coefficients, precision P) as the engine
  // builds them: after the solve every coefficient of the interior rows below their precision is at round-off.
  using Sys = systems::Pendulum;
  using G = generic::ContactTrapezoid;
  using S = BiSeries<6, 9, 2>;
  const Sys sys;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(-1, 1);
  constexpr int P = 7;
  std::vector<double> c(10), d(10);
  for (auto& x : c) x = U(rng);
  for (auto& x : d) x = U(rng);
  auto series = [&](const std::vector<double>& a, double shift, int p) {
    S r;
    r.p = p;
    for (int j = 0; j <= 6; ++j)
      for (int k = 0; j + k < p; ++k) r.at(j, k) = a[static_cast<std::size_t>(j + k)] * std::pow(shift, k) * binomial(j + k, j);
    r.fit();
    return r;
  };
  const S T = S(0.3) + S::eps(), H = S::h();
  for (const auto& family : generic::composition_families()) {
    const ComposedResidual<Sys, G> cr(family);
    auto rows_ok = [&](const auto& st, int P, const char* how) {
      const auto R = cr.interior_rows(sys, T, H, st);
      double worst = 0, scale = 0;
      auto look = [&](const S& x, int p) {
        CHECK(x.p >= p);
        for (int j = 0; j <= 6; ++j)
          for (int k = -2; j + k < p; ++k) worst = std::max(worst, std::abs(x.coeff(j, k)));
      };
      for (const auto& x : R.node) look(x(0), P - 1);
      for (const auto& x : R.action) look(x, P - 2);
      for (const auto& x : st.Q) scale = std::max(scale, StageScalar<S>::size(x(0)));
      INFO(family.name << " (" << how << "): largest row coefficient " << worst << ", " << st.iterations << " iterations");
      CHECK(worst <= 1e-14 * scale);
    };
    Vec<S, 1> q0, q1;
    q0(0) = series(c, 0, P);
    q1(0) = series(c, 1, P);
    const auto cold = cr.step(sys, T, H, q0, q1, series(d, 0, P - 1), series(d, 1, P - 1));
    rows_ok(cold, P, "cold");
    // the engine's next order: the same endpoints with one more degree known, from the solution above
    Vec<S, 1> r0, r1;
    r0(0) = series(c, 0, P + 1);
    r1(0) = series(c, 1, P + 1);
    const auto warm = cr.step(sys, T, H, r0, r1, series(d, 0, P), series(d, 1, P), &cold);
    CHECK(warm.iterations <= 2);
    rows_ok(warm, P + 1, "warm");
    // the step before, from this one seen one step back
    Vec<S, 1> m0;
    m0(0) = series(c, -1, P);
    const auto back = cr.shifted_back(cold);
    const auto before = cr.step(sys, S(T - H), H, m0, q0, series(d, -1, P - 1), series(d, 0, P - 1), &back);
    CHECK(before.iterations <= 1);
    const auto direct = cr.step(sys, S(T - H), H, m0, q0, series(d, -1, P - 1), series(d, 0, P - 1));
    double diff = 0;
    for (std::size_t i = 0; i < direct.Q.size(); ++i)
      for (int j = 0; j <= 6; ++j)
        for (int k = 0; j + k < P; ++k) diff = std::max(diff, std::abs(before.Q[i](0).coeff(j, k) - direct.Q[i](0).coeff(j, k)));
    INFO(family.name << ": shifted start against a cold solve " << diff);
    CHECK(diff <= 1e-13);
  }
}

TEST_CASE("s steps of h/s as a composition: the base scheme's modified equation at h/s", "[composition][modified]") {
  // Its positions are the base scheme's at step h/s, so its modified equation is the base's at h/s: F_k / s^k,
  // Z_k / s^k, phi_k / s^k, computed here through the stage problem (s - 1 interior points) against the residual
  // engine (s = 1: no interior point).
  check_equal_steps<systems::Pendulum, generic::LaTrapezoid>(systems::Pendulum{}, "pendulum la-trapezoid");
  check_equal_steps<systems::Pendulum, generic::ContactTrapezoid>(systems::Pendulum{}, "pendulum contact-trapezoid");
  check_equal_steps<systems::KnifeEdge, generic::LaMidpoint>(systems::KnifeEdge{}, "knife-edge la-midpoint");
}

TEST_CASE("a composition of order p has F_1 ... F_{p-1} = 0 to round-off and F_p != 0, on every system and base",
          "[composition][modified][table]") {
  // At each system's initial data (t = 0, z = 0), K = min(p, 6). Round-off: the F_k of a composition are sums of
  // stage terms of the size of F_0 to F_p whose weights cancel (sum w_i^3 = 0, ...), computed in double: 1e-12 of
  // the largest |F_k| leaves a margin of 100 over the worst measured (6e-15, the knife edge). The same for the
  // contact z' (Z_k) and the modified constraint (phi_k, k >= 1).
  std::string table = "max_i |F_k| at the initial data (k = 0 .. min(p, 6)); kahanli8 (p = 8): F_1 .. F_6";
  for (const auto& sys : all_systems()) {
    const auto me = modified_system(sys);
    const ModifiedSystem& ms = *me;
    const auto x = sys.ode_initial_state({}, false);
    const std::vector<double> q(x.begin(), x.begin() + sys.dof), v(x.begin() + sys.dof, x.end());
    table += "\n" + sys.name + ":";
    for (const auto& base : sys.composition_bases()) {
      table += "\n  " + base;
      for (const auto& fam : generic::composition_families()) {
        const std::string name = generic::composition_name(fam.name, base);
        const int K = std::min(fam.order, registry_max_order);
        const ModifiedPoint P = ms.at({}, name, K, 0.0, q, v, 0.0, true);
        std::vector<double> F(static_cast<std::size_t>(K + 1)), other(static_cast<std::size_t>(K + 1), 0.0);
        double scale = 0;
        for (int k = 0; k <= K; ++k) {
          for (int i = 0; i < P.n; ++i) F[static_cast<std::size_t>(k)] = std::max(F[static_cast<std::size_t>(k)], std::abs(P.F_at(k, i)));
          if (P.contact) other[static_cast<std::size_t>(k)] = std::abs(P.Z[static_cast<std::size_t>(k)]);
          for (int c = 0; c < P.m; ++c)
            other[static_cast<std::size_t>(k)] =
                std::max(other[static_cast<std::size_t>(k)], std::abs(P.phi[static_cast<std::size_t>(k * P.m + c)]));
          scale = std::max({scale, F[static_cast<std::size_t>(k)], other[static_cast<std::size_t>(k)]});
        }
        char cell[48];
        std::snprintf(cell, sizeof cell, "\n    %-9s", fam.name.c_str());
        table += cell;
        for (int k = 0; k <= K; ++k) {
          std::snprintf(cell, sizeof cell, " %8.1e", F[static_cast<std::size_t>(k)]);
          table += cell;
        }
        double vanishing = 0;
        for (int k = 1; k < std::min(fam.order, K + 1); ++k)
          vanishing = std::max({vanishing, F[static_cast<std::size_t>(k)], other[static_cast<std::size_t>(k)]});
        INFO(name << " on " << sys.name << ": largest F_k, Z_k, phi_k below order " << fam.order << ": " << vanishing
                  << " against " << scale << "; F_p " << (fam.order <= K ? F[static_cast<std::size_t>(fam.order)] : 0.0)
                  << "; residual " << P.residual);
        CHECK(vanishing <= 1e-12 * scale);
        if (fam.order <= K) CHECK(F[static_cast<std::size_t>(fam.order)] > 1e-6 * scale);
        CHECK(P.residual <= 1e-12 * scale);
      }
    }
  }
  WARN(table);
}

TEST_CASE("oscillator: a composition's F_k are the coefficients of the modified equation of its one-step matrix",
          "[composition][modified]") {
  // On q'' + alpha q' + q = 0 a one-step map is a 2 x 2 matrix on (q, p), with eigenvalues r e^(+-i theta): it is the
  // time-h flow of q'' = -b q - a q' with a = -2 ln r / h, b = (theta^2 + ln^2 r) / h^2 (eigenvalues do not depend
  // on the coordinates (q, p) or (q, q')). The composition's matrix (its Newton steps, not the series) against the
  // series engine truncated at K: the remainder falls like h^(K+2) for K = 2, 4 (the odd F_k vanish), over
  // h = 0.4 .. 0.1 where it stays above the matrix's round-off.
  const SystemInfo& osc = find_system("oscillator");
  const ModifiedSystem& ms = find_modified_system("oscillator");
  const ParamValues pv{{"alpha", 0.5}};
  for (const char* name : {"yoshida4:la-trapezoid", "suzuki4:la-midpoint", "yoshida4:contact-trapezoid", "yoshida6a:la-trapezoid"}) {
    const auto Pq = ms.at(pv, name, 6, 0.0, {1.0}, {0.0}, 0.0, false), Pv = ms.at(pv, name, 6, 0.0, {0.0}, {1.0}, 0.0, false);
    const int p = osc.scheme(name).order;
    for (int K : {2, 4}) {
      std::vector<double> hs, ea, eb;
      for (double h : {0.4, 0.2, 0.1}) {
        const auto M = osc.one_step_matrix(pv, name, h, Path::generic);
        const double tr = static_cast<double>(M[0] + M[3]), det = static_cast<double>(M[0] * M[3] - M[1] * M[2]);
        const double r = std::sqrt(det), theta = std::atan2(std::sqrt(4 * det - tr * tr), tr);
        const double a = -2 * std::log(r) / h, b = (theta * theta + std::log(r) * std::log(r)) / (h * h);
        double Fa = 0, Fb = 0;
        for (int k = K; k >= 0; --k) {
          Fa = Fa * h + Pv.F_at(k, 0);
          Fb = Fb * h + Pq.F_at(k, 0);
        }
        hs.push_back(h);
        ea.push_back(std::abs(a + Fa));
        eb.push_back(std::abs(b + Fb));
      }
      const int expect = std::max(p, K + 2);
      const auto fa = fit_order(hs, ea, 1e-13), fb = fit_order(hs, eb, 1e-13);
      INFO(name << " K " << K << ": remainders of a " << ea[0] << " " << ea[1] << " " << ea[2] << " (slope " << fa.slope
                << "), of b " << eb[0] << " " << eb[1] << " " << eb[2] << " (slope " << fb.slope << "), expected " << expect);
      CHECK(fa.slope == Approx(expect).margin(0.3));
      CHECK(fb.slope == Approx(expect).margin(0.3));
    }
  }
}

TEST_CASE("discrete solutions of compositions follow their truncated modified equations at the slopes of their order",
          "[composition][modified][agreement]") {
  // max_j |q_j - q~_K(t_j)| over T = 2 (shooting start): the first F_k left out is F_p for K < p and F_(p+2) for
  // K = p (symmetric: the odd ones vanish), so the slopes are p and p + 2. Kept small for CI: yoshida4 (p = 4) at
  // K = 0 and 4 on the pendulum and at K = 4 on the knife edge, with the multiplier (the step's total impulse per
  // unit step) and the composition's discrete constraint along the modified solution. The knife edge from h = 0.1:
  // from 0.4 its constraint's slopes are 5.93 then 5.45 (fitted 5.69), from 0.1 5.69 then 5.86 (its F_5 and phi_5
  // vanish; the defect is the shooting start's Phi_h, which the modified flow keeps), and the run costs half as
  // much (the modified equation at h = 0.4 is stiffer for Odeint).
  struct Case {
    const char* system;
    const char* scheme;
    int K;
    double h0;
  };
  for (const Case& c : {Case{"pendulum", "yoshida4:la-trapezoid", 0, 0.4}, Case{"pendulum", "yoshida4:la-trapezoid", 4, 0.4},
                        Case{"knife-edge", "yoshida4:la-midpoint", 4, 0.1}}) {
    std::vector<double> hs, eq, em, ed;
    for (double h : {c.h0, c.h0 / 2, c.h0 / 4}) {
      const auto a = find_modified_system(c.system).agreement({{"alpha", 0.5}}, c.scheme, c.K, h, 2.0, 1e-13, AgreementStart::shooting);
      hs.push_back(h);
      eq.push_back(a.err_q);
      em.push_back(a.err_mu);
      ed.push_back(a.phi_d);
    }
    const int expect = c.K < 4 ? 4 : 6;
    // the total impulse of a step is not symmetric in it: its mu_k do not vanish for odd k (mu_1 = (1/2) d mu_0/dt)
    const auto f = fit_order(hs, eq, 1e-11);
    INFO(c.system << " " << c.scheme << " K " << c.K << ": errors " << eq[0] << " " << eq[1] << " " << eq[2] << ", slope "
                  << f.slope << ", expected " << expect);
    CHECK(f.slope == Approx(expect).margin(0.3));
    if (std::string(c.system) == "knife-edge") {
      const auto fm = fit_order(hs, em, 1e-11), fd = fit_order(hs, ed, 1e-13);
      INFO("multiplier " << em[0] << " " << em[1] << " " << em[2] << " (slope " << fm.slope << "), constraint " << ed[0] << " "
                         << ed[1] << " " << ed[2] << " (slope " << fd.slope << ")");
      CHECK(fm.slope == Approx(c.K + 1).margin(0.3));
      CHECK(fd.slope == Approx(expect).margin(0.3));
    }
  }
}

TEST_CASE("the formulas of a composition are refused in one line that says why", "[composition][modified]") {
  const SystemInfo& pendulum = find_system("pendulum");
  CHECK_NOTHROW(modified_scheme(pendulum, "yoshida4:la-trapezoid"));
  CHECK_THROWS_WITH(formula_scheme(pendulum, "yoshida4:la-trapezoid"),
                    Catch::Contains("is a composition") && Catch::Contains("numbers, not as formulas") &&
                        Catch::Contains("2 interior stage points"));
  CHECK_THROWS_AS(modified_scheme(pendulum, "yoshida4:la"), InputError);
}
