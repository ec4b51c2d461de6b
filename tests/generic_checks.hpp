#pragma once
// Checks every system of the generic core gets, as templates: its AD-derived equations against its
// hand-written ones (and the Herglotz form against the Lagrange–d'Alembert form), and its closed-form fast
// paths against the generic schemes step by step. One test file per system includes this, so touching one
// system header rebuilds one test file.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <tuple>
#include <vector>

#include "geomint/generic/system_schemes.hpp"
#include "geomint/generic/stepper.hpp"

namespace geomint::testing {

// ---- equations

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


// A closed-form solution solves the equations derived from L: d/dt of the exact velocity (central difference,
// e = 1e-4: error ~ e^2 |q^(4)| ~ 1e-8) equals the acceleration, and d/dt of q the velocity.
template <class Sys>
void check_exact_solves(const Sys& sys, double t) {
  const double e = 1e-4;
  const auto x = sys.template exact<double>(t), xp = sys.template exact<double>(t + e), xm = sys.template exact<double>(t - e);
  const auto a = generic::acceleration(sys, t, x.q, x.v);
  INFO(Sys::name << " at t = " << t);
  CHECK(((xp.v - xm.v) / (2 * e) - a.a).norm() < 1e-8);
  CHECK(((xp.q - xm.q) / (2 * e) - x.v).norm() < 1e-8);
}

// ---- fast paths
// Every hand-derived step is the fast path of a generic scheme: over a long run the two agree step by step
// to round-off growth. Bound: one unit of eps * max|x| per step (linear growth, the worst case for the
// phase error of a neutrally stable oscillation; both sides round a few times per step, independently).
// The measured differences are far below it (printed with -s), while any error in a formula — an O(h)
// term — would exceed it by orders of magnitude.

struct Difference {
  double q = 0, p = 0, z = 0, qmax = 0, pmax = 0;
  long steps = 0;
};

template <class Sys, class G, class C>
Difference compare(const Sys& sys, double h, long N) {
  constexpr int n = Sys::dof, m = Sys::constraints;
  Difference d;
  d.steps = N;
  generic::Stepper<Sys, G> st(sys, h);
  st.start(sys.template initial_position<double>(), sys.template initial_velocity<double>());
  sys.template run_fast<C>(h, N, [&](const generic::StepView<double, n, m>& v) {
    if (v.j > 0) st.step();
    const auto& s = st.state();
    REQUIRE(s.j == v.j);
    d.q = std::max(d.q, (s.q - v.q).template lpNorm<Eigen::Infinity>());
    d.p = std::max(d.p, (s.p - v.p).template lpNorm<Eigen::Infinity>());
    d.z = std::max(d.z, std::abs(s.z - v.z));
    d.qmax = std::max(d.qmax, v.q.template lpNorm<Eigen::Infinity>());
    d.pmax = std::max(d.pmax, v.p.template lpNorm<Eigen::Infinity>());
  });
  return d;
}

template <class Sys>
void check_all_fast_paths(const Sys& sys, double h, long N) {
  const double eps = std::numeric_limits<double>::epsilon();
  std::apply([&](auto... fp) {
    (([&] {
       using C = decltype(fp);
       using G = typename C::solves;
       const auto d = compare<Sys, G, C>(sys, h, N);
       const double bound_q = double(N) * eps * d.qmax, bound_p = double(N) * eps * d.pmax;
       INFO(Sys::name << ": " << C::name << " vs generic " << generic::scheme_name<G>()
                      << " over " << N << " steps: |dq| " << d.q << " (bound " << bound_q << "), |dp| " << d.p
                      << " (bound " << bound_p << "), |dz| " << d.z);
       CHECK(d.q <= bound_q);
       CHECK(d.p <= bound_p);
       CHECK(d.z <= bound_p * h * 10);  // z accumulates h L per step: |L| <~ |p|^2 ~ 10 |p| here
       WARN(Sys::name << " " << C::name << ": |dq| = " << d.q << " = " << d.q / bound_q
                      << " of the bound, |dp| = " << d.p << " = " << d.p / bound_p << " of the bound");
       if constexpr (generic::has_run_positions<Sys, C>::value) {
         // the positions alone are the same run: every q_j and t_j to the bit
         constexpr int n = Sys::dof;
         std::vector<Vec<double, n>> q;
         std::vector<double> t;
         sys.template run_fast<C>(h, N, [&](const generic::StepView<double, n, Sys::constraints>& v) {
           q.push_back(v.q);
           t.push_back(v.t);
         });
         long count = 0, differ = 0;
         sys.template run_positions<C>(h, N, [&](long j, double tj, const Vec<double, n>& qj) {
           const auto k = static_cast<std::size_t>(j);
           if (j != count++ || k >= q.size() || !(qj.array() == q[k].array()).all() || tj != t[k]) ++differ;
         });
         INFO(Sys::name << " " << C::name << ": run_positions differs from run_fast at " << differ << " of " << count
                        << " steps");
         CHECK(count == N + 1);
         CHECK(differ == 0);
       }
     }()),
     ...);
  }, typename Sys::fast_paths{});
}

// ---- the Newton linearization
// The stepper differentiates a step's rows in the unknowns they depend on nonlinearly, q_{j+1} (with z_{j+1} of an
// implicit-z quadrature solved inside the rows, so a function of q_{j+1}), and
// takes the lambda columns from the rows' own -A^T (StepRows::dynamics_lambda). That must be the Jacobian a
// forward pass in all K directions gives, entry for entry (the same operations on the same values in every
// direction), for every scheme, at states along a run (lambda not 0) and at unknowns off the solution.
template <class Sys>
void check_linearization(const Sys& sys, double h) {
  std::apply([&](auto... g) {
    (([&] {
       using G = decltype(g);
       using St = generic::Stepper<Sys, G>;
       constexpr int n = Sys::dof, m = Sys::constraints, K = St::K;
       using D = Dual<double, K>;
       St st(sys, h);
       st.start(sys.template initial_position<double>(), sys.template initial_velocity<double>());
       std::mt19937 rng(5);
       std::uniform_real_distribution<double> u(-1, 1);
       long mismatches = 0, entries = 0;
       for (int k = 0; k < 6; ++k) {
         st.step();
         const auto& s = st.state();
         Vec<double, K> x;
         for (int i = 0; i < n; ++i) x(i) = s.q(i) + 0.01 * u(rng);
         if constexpr (St::nz == 1) x(n) = s.z + 0.01 * u(rng);
         for (int i = 0; i < m; ++i) x(K - m + i) = s.lambda(i) + 0.01 * u(rng);
         const auto fast = st.linearized_at(x);
         // the full pass, written out here from the scheme's rows
         Vec<D, K> X;
         for (int i = 0; i < K; ++i) X(i) = D::variable(x(i), i);
         D z1 = D(s.z);
         if constexpr (St::nz == 1) z1 = X(n);
         if constexpr (St::eliminate_z) {
           // z_{j+1} solved from q_{j+1} alone (no lambda): its q-derivatives in the duals of q, zero in the lambda
           // directions. In those duals, not in D: Eigen sums the Lagrangian's squared norms in an order that depends
           // on the scalar's cost, so a dual with more directions may round the solved value differently (1 ulp).
           using DQ = Dual<double, n>;
           Vec<DQ, n> Q1;
           for (int i = 0; i < n; ++i) Q1(i) = DQ::variable(x(i), i);
           const DQ zq = st.template solved_z<DQ>(Q1);
           z1 = D(zq.v);
           for (int i = 0; i < n; ++i) z1.d[static_cast<std::size_t>(i)] = zq.d[static_cast<std::size_t>(i)];
         }
         Vec<D, m> lambda;
         if constexpr (m > 0) lambda = X.template tail<m>();
         const auto rows = G::template rows<Sys, D>(sys, D(s.t), D(h), Vec<D, n>(s.q.template cast<D>()),
                                                    Vec<D, n>(s.p.template cast<D>()), D(s.z),
                                                    Vec<D, n>(X.template head<n>()), z1, lambda);
         Vec<D, K> R;
         R.template head<n>() = rows.dynamics;
         if constexpr (St::nz == 1) R(n) = rows.action;
         if constexpr (m > 0) R.template tail<m>() = rows.constraint;
         auto same = [&](double a, double b) {
           ++entries;
           if (!(a == b)) ++mismatches;
         };
         for (int r = 0; r < K; ++r) {
           same(fast.R(r), R(r).v);
           for (int c = 0; c < K; ++c) same(fast.lin.J(r, c), R(r).d[std::size_t(c)]);
         }
         for (int i = 0; i < n; ++i) {
           same(fast.out.p_next(i), rows.p_next(i).v);
           for (int c = 0; c < K; ++c) same(fast.lin.dP(i, c), rows.p_next(i).d[std::size_t(c)]);
         }
         same(fast.out.z_next, rows.z_next.v);
         for (int c = 0; c < K; ++c) same(fast.lin.dZ(c), rows.z_next.d[std::size_t(c)]);
         // a kept Jacobian's constraint rows and multiplier columns brought up to date at x: Newton's own Jacobian's
         // entries (the same dual type), and nothing else written
         typename St::MatK kept = St::MatK::Constant(std::numeric_limits<double>::quiet_NaN());
         const bool refreshed = st.refresh_constraint_block(x, kept);
         same(refreshed ? 1 : 0, m > 0 ? 1 : 0);
         for (int r = 0; r < K; ++r)
           for (int c = 0; c < K; ++c) {
             const bool constraint_row = r >= K - m && c < n, lambda_column = r < n && c >= K - m;
             if (constraint_row || lambda_column)
               same(kept(r, c), fast.lin.J(r, c));
             else if (!std::isnan(kept(r, c)))
               same(kept(r, c), std::numeric_limits<double>::quiet_NaN());
           }
       }
       INFO(Sys::name << " " << generic::scheme_name<G>() << ": " << mismatches << " of " << entries
                      << " entries differ from the full forward pass");
       CHECK(mismatches == 0);
     }()),
     ...);
  }, generic::AllSchemesTuple{});
}

// ---- two steppers side by side
// Two steppers of one system started from its initial data and stepped together: the largest difference of their
// states (q, p, z) over N steps, the largest size of the second's, the Newton updates of each, and the bound both
// tests below hold it to. Each accepts a step within kappa eps of each row's round-off scale, so they may differ by
// that much a step, carried along by a flow that does not amplify it (damped): over N steps no more than
// N kappa eps (1 + the largest |q|, |p|, |z|).
struct SideBySide {
  double worst = 0, size = 0;
  long updates_a = 0, updates_b = 0;
  double bound(long N) const { return double(N) * 16 * std::numeric_limits<double>::epsilon() * (1 + size); }
};
template <class Sys, class A, class B>
SideBySide side_by_side(const Sys& sys, A& a, B& b, long N) {
  const auto q0 = sys.template initial_position<double>();
  const auto v0 = sys.template initial_velocity<double>();
  a.start(q0, v0);
  b.start(q0, v0);
  SideBySide r;
  for (long j = 0; j < N; ++j) {
    a.step();
    b.step();
    r.updates_a += a.last_updates();
    r.updates_b += b.last_updates();
    const auto &x = a.state(), &y = b.state();
    r.worst = std::max({r.worst, (x.q - y.q).template lpNorm<Eigen::Infinity>(), (x.p - y.p).template lpNorm<Eigen::Infinity>(),
                        std::abs(x.z - y.z)});
    r.size = std::max({r.size, y.q.template lpNorm<Eigen::Infinity>(), y.p.template lpNorm<Eigen::Infinity>(), std::abs(y.z)});
  }
  return r;
}

// ---- a kept Jacobian across steps
//
// On a system whose L is quadratic, `la` and `contact` (Psi at the start of the step) have rows affine in the
// unknowns once q_j is fixed, with the constraint block (dPhi_d/dq_{j+1} and -A(t_j, q_j)^T) the only part of J that
// moves from step to step. A kept Jacobian with that block brought up to date (Stepper::refresh_constraint_block)
// is then exact: one update a step from the predictor, and the one Jacobian of the start. Measured over N steps:
// N updates and 1 Jacobian (Foucault `contact` over the hour: N + 3 and 6); without the refresh the knife edge took
// 1.08 N and N, the Foucault pendulum 2 N and 1.4 N. The bound leaves 5 updates and 9 Jacobians of slack.
//
// Such a system declares linear dynamics, and the stepper then takes that one update without evaluating the rows
// again (the single-update path, checked every 256th step); against every step through Newton (shortcuts off) to
// the bound of side_by_side.
template <class Sys>
void check_kept_jacobian(const Sys& sys, double h, long N) {
  static_assert(generic::has_linear_dynamics<Sys>() && !generic::is_linear<Sys>(), "the shortcut of linear dynamics");
  std::apply([&](auto... g) {
    (([&] {
       using G = decltype(g);
       generic::Stepper<Sys, G> st(sys, h), full(sys, h);
       full.allow_shortcuts(false);
       const SideBySide d = side_by_side(sys, st, full, N);
       const double worst = d.worst, bound = d.bound(N);
       INFO(Sys::name << " " << generic::scheme_name<G>() << ", h = " << h << ", " << N << " steps: "
                      << full.total_updates() << " Newton updates, " << full.jacobians() << " Jacobians; "
                      << "with the single-update path " << st.total_updates() << " and " << st.jacobians()
                      << ", largest difference " << worst << " (bound " << bound << ")");
       CHECK(full.total_updates() <= N + 5);
       CHECK(full.jacobians() <= 10);
       CHECK(!full.on_single_update_path());
       CHECK(st.on_single_update_path());
       CHECK(st.total_updates() <= N + 5);
       CHECK(st.jacobians() <= 10);
       CHECK(worst <= bound);
     }()),
     ...);
  }, std::tuple<generic::LaLeft, generic::ContactLeft>{});
}

// ---- z_{j+1} solved inside the rows
// The stepper solves contact-trapezoid's action row for z_{j+1} inside the rows, so that Newton's unknowns are
// (q_{j+1}, lambda); the scheme states the step with z_{j+1} among the unknowns (Stepper<..., false>). Both accept a
// step when every row is within kappa eps of its round-off scale, so they may differ by that much a step, carried
// along by a flow that does not amplify it (damped): over N steps no more than N kappa eps (1 + the largest |q|, |p|,
// |z|). Measured: 3e-16 (pendulum), 1.4e-15 (knife edge), 3.5e-13 (oscillator, z included) over 2000 steps.
template <class Sys>
void check_z_elimination(const Sys& sys, double h, long steps) {
  using G = generic::ContactTrapezoid;
  using Solved = generic::Stepper<Sys, G>;
  using Full = generic::Stepper<Sys, G, double, false>;
  static_assert(Solved::eliminate_z && Full::K == Solved::K + 1, "z_{j+1} is an unknown of the full step only");
  Solved a(sys, h);
  Full b(sys, h);
  const SideBySide d = side_by_side(sys, a, b, steps);
  const double bound = d.bound(steps);
  INFO(Sys::name << ", contact-trapezoid, h = " << h << ", " << steps << " steps: max difference " << d.worst << " (bound "
                 << bound << "); Newton updates a step " << double(d.updates_a) / steps << " with z_{j+1} solved, "
                 << double(d.updates_b) / steps << " with z_{j+1} an unknown");
  CHECK(d.worst <= bound);
}

}  // namespace geomint::testing
