#pragma once
// make_modified_system<Sys>(prototype): the registry entry of one system's automatic modified equations — the engine
// (automatic.hpp) for every applicable scheme, the modified flow as an Odeint right-hand side, the shooting
// start and the agreement run. Heavy: included only by the generated per-system translation units
// (modified_equations/src/automatic_instance.cpp.in). A composition "<family>:<base>" uses the engine of its
// base with the family as run-time data (automatic.hpp): no instantiation per family.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "geomint/error.hpp"
#include "geomint/generic/composition.hpp"
#include "geomint/generic/stepper.hpp"
#include "geomint/generic/system_info.hpp"
#include "geomint/interrupt.hpp"
#include "geomint/modified/automatic.hpp"
#include "geomint/modified/automatic_registry.hpp"
#include "geomint/reference.hpp"

namespace geomint::modified::detail {

template <class Sys, class G>
using Engine = ModifiedEquation<Sys, G, registry_max_order>;
using Family = generic::CompositionFamily;

// The engine of scheme G, or of its composition with `family` (not null).
template <class Sys, class G>
Engine<Sys, G> engine(const Sys& sys, const Family* family) {
  if constexpr (Engine<Sys, G>::composable) {
    if (family) return Engine<Sys, G>(sys, *family);
  } else {
    if (family) throw std::logic_error("a composition of a scheme that is not symmetric");
  }
  return Engine<Sys, G>(sys);
}

// Calls f(G{}, family) for the scheme `name` of Sys: a generic scheme (family null) or a composition
// "<family>:<base>" (G its base). InputError for an unknown name.
template <class Sys, class F>
decltype(auto) visit_modified_scheme(const std::string& name, F&& f) {
  if (generic::is_composition_name(name))
    return generic::visit_composition<Sys>(name, [&](auto g, const Family& family) { return f(g, &family); });
  return generic::visit_generic_scheme<Sys>(name, [&](auto g) { return f(g, static_cast<const Family*>(nullptr)); });
}

inline constexpr double nan = missing_value;

template <int n>
Vec<double, n> to_vec(const std::vector<double>& x, const char* what) {
  require(static_cast<int>(x.size()) == n, std::string(what) + " needs " + std::to_string(n) + " components, got " +
                                               std::to_string(x.size()));
  Vec<double, n> v;
  for (int i = 0; i < n; ++i) v(i) = x[static_cast<std::size_t>(i)];
  return v;
}

template <class Sys, class G>
ModifiedPoint point(const Sys& sys, const Family* family, int K, double t, const Vec<double, Sys::dof>& q,
                    const Vec<double, Sys::dof>& v, double z, bool check) {
  constexpr int n = Sys::dof, m = Sys::constraints;
  const Engine<Sys, G> me = engine<Sys, G>(sys, family);
  typename Engine<Sys, G>::Result r;
  me.evaluate(t, q, v, z, K, r, check);
  ModifiedPoint out;
  out.n = n;
  out.m = m;
  out.K = K;
  out.contact = G::contact;
  out.holonomic = Engine<Sys, G>::holonomic;
  out.residual = check ? r.residual : 0.0;
  const auto lag = me.mesh_lagrangian(t, r);
  for (int k = 0; k <= K; ++k) {
    out.lagrangian.push_back(m == 0 ? lag[static_cast<std::size_t>(k)] : nan);
    for (int i = 0; i < n; ++i) out.F.push_back(r.F[k](i));
    out.Z.push_back(r.Z[k]);
    for (int c = 0; c < m; ++c) out.mu.push_back(r.mu[k](c));
  }
  if constexpr (m > 0) {
    constexpr int o = Engine<Sys, G>::o;
    for (int k = 0; k <= K + o; ++k)
      for (int c = 0; c < m; ++c) out.phi.push_back(r.phi[k](c));
    if (o == 2)
      for (int k = 0; k <= K + 1; ++k)
        for (int c = 0; c < m; ++c) out.phi_dot.push_back(r.phi_dot[k](c));
  }
  return out;
}

// The order-K modified flow as a first-order system in x = (q, v, z).
template <class Sys, class G>
struct Flow {
  static constexpr int n = Sys::dof, N = 2 * n + 1;
  using State = std::array<double, N>;
  const Engine<Sys, G>* me;
  int K;
  double h;
  void operator()(const State& x, State& dx, double t) const {
    interruption_point();  // each evaluation is a modified equation to order K: a watched call stops here
    Vec<double, n> q, v;
    for (int i = 0; i < n; ++i) {
      q(i) = x[static_cast<std::size_t>(i)];
      v(i) = x[static_cast<std::size_t>(n + i)];
    }
    const auto f = me->field(t, q, v, x[N - 1], K, h);
    for (int i = 0; i < n; ++i) {
      dx[static_cast<std::size_t>(i)] = v(i);
      dx[static_cast<std::size_t>(n + i)] = f.a(i);
    }
    dx[N - 1] = f.zdot;
  }
};

template <class Sys, class G>
typename Flow<Sys, G>::State state_of(const Vec<double, Sys::dof>& q, const Vec<double, Sys::dof>& v, double z) {
  constexpr int n = Sys::dof;
  typename Flow<Sys, G>::State x{};
  for (int i = 0; i < n; ++i) {
    x[static_cast<std::size_t>(i)] = q(i);
    x[static_cast<std::size_t>(n + i)] = v(i);
  }
  x[2 * n] = z;
  return x;
}

// Odeint with dense output: Bulirsch–Stoer (extrapolation, high order) rather than dopri5, because every
// right-hand side evaluation here costs a series evaluation of the residual: at tolerance 1e-13 it needs far
// fewer of them (with the chord-Newton shooting below, the modified_agreement study went from 48 s to 23 s).
template <std::size_t N, class System>
std::vector<std::array<double, N>> flow_dense(System sys, std::array<double, N> x0, const std::vector<double>& times,
                                              double tol) {
  namespace odeint = boost::numeric::odeint;
  using State = std::array<double, N>;
  std::vector<State> out;
  out.reserve(times.size());
  odeint::bulirsch_stoer_dense_out<State> stepper(tol, tol);
  const double dt0 = times.size() > 1 ? (times[1] - times[0]) : 1e-3;
  try {
    odeint::integrate_times(stepper, sys, x0, times.begin(), times.end(), dt0,
                            [&](const State& x, double) { out.push_back(x); },
                            odeint::max_step_checker(odeint_max_steps_between_outputs));
  } catch (const odeint::no_progress_error&) {
    throw_too_stiff("Boost.Odeint Bulirsch-Stoer (the modified equation)", out.empty() ? times.front() : times[out.size() - 1],
                    out.size());
  }
  return out;
}

// v~(0) such that the modified flow from (q0, v~(0), z0) passes through q1 at t = h: chord Newton (the
// Jacobian dq~(h)/dv ~ h I by forward differences once), each residual one Odeint solve over [0, h].
template <class Sys, class G>
Vec<double, Sys::dof> shoot_velocity(const Engine<Sys, G>& me, int K, double h, const Vec<double, Sys::dof>& q0,
                                     Vec<double, Sys::dof> v, double z0, const Vec<double, Sys::dof>& q1, double tol,
                                     double* miss) {
  constexpr int n = Sys::dof;
  const Flow<Sys, G> flow{&me, K, h};
  const std::vector<double> times{0.0, h};
  auto end = [&](const Vec<double, n>& vv) {
    const auto xs = flow_dense<Flow<Sys, G>::N>(flow, state_of<Sys, G>(q0, vv, z0), times, tol);
    Vec<double, n> q;
    for (int i = 0; i < n; ++i) q(i) = xs.back()[static_cast<std::size_t>(i)];
    return q;
  };
  Vec<double, n> r = end(v) - q1;
  Mat<double, n, n> J;
  for (int i = 0; i < n; ++i) {
    Vec<double, n> w = v;
    const double d = 1e-6 * (1 + std::abs(v(i)));
    w(i) += d;
    J.col(i) = (end(w) - q1 - r) / d;
  }
  const Eigen::PartialPivLU<Mat<double, n, n>> lu(J);
  for (int it = 0; it < 20; ++it) {
    const Vec<double, n> dv = lu.solve(r);
    v -= dv;
    r = end(v) - q1;
    if (dv.template lpNorm<Eigen::Infinity>() <= 1e-15 * (1 + v.template lpNorm<Eigen::Infinity>())) break;
  }
  if (miss) *miss = r.template lpNorm<Eigen::Infinity>();
  return v;
}

// The discrete solution by the generic Newton step in long double (its round-off stays far below the
// agreement errors being fitted), from the system's initial data; for a composition, its stages' steps
// (Composition), the impulse of a step the sum of its stages'.
template <class Sys, class G>
struct Discrete {
  std::vector<Vec<double, Sys::dof>> q;
  std::vector<double> z;
  std::vector<Vec<double, Sys::constraints>> lambda;  // impulse of the step j -> j+1
  Vec<double, Sys::dof> v0;
};
template <class Sys, class G, class Stepper>
Discrete<Sys, G> discrete_steps(const Sys& sys, Stepper& st, long N) {
  constexpr int n = Sys::dof;
  using LD = long double;
  const Vec<LD, n> q0 = sys.template initial_position<LD>();
  st.start(q0, sys.template initial_velocity<LD>());
  Discrete<Sys, G> d;
  d.v0 = generic::consistent_velocity(sys, 0.0, Vec<double, n>(q0.template cast<double>()),
                                      sys.template initial_velocity<double>());
  auto keep = [&] {
    d.q.push_back(st.state().q.template cast<double>());
    d.z.push_back(static_cast<double>(st.state().z));
  };
  keep();
  for (long j = 0; j < N; ++j) {
    interruption_point();
    st.step();
    keep();
    d.lambda.push_back(st.state().lambda.template cast<double>());
  }
  return d;
}
template <class Sys, class G>
Discrete<Sys, G> discrete_run(const Sys& sys, const Family* family, double h, long N) {
  using LD = long double;
  if constexpr (Engine<Sys, G>::composable) {
    if (family) {
      generic::Composition<Sys, G, LD> c(sys, *family, LD(h));
      return discrete_steps<Sys, G>(sys, c, N);
    }
  }
  generic::Stepper<Sys, G, LD> st(sys, LD(h));
  return discrete_steps<Sys, G>(sys, st, N);
}

template <class Sys, class G>
ModifiedAgreement agreement_run(const Sys& sys, const Family* family, int K, double h, double T, double tol,
                                AgreementStart start) {
  constexpr int n = Sys::dof, m = Sys::constraints;
  using Q = typename G::quadrature;
  const long N = step_count(h, T);
  ModifiedAgreement a;
  a.steps = N;
  const Engine<Sys, G> me = engine<Sys, G>(sys, family);
  const auto d = discrete_run<Sys, G>(sys, family, h, N);
  a.shoot_miss = nan;
  const Vec<double, n> v0 =
      start == AgreementStart::naive ? d.v0 : shoot_velocity(me, K, h, d.q[0], d.v0, d.z[0], d.q[1], tol, &a.shoot_miss);
  a.v_shift = (v0 - d.v0).template lpNorm<Eigen::Infinity>();
  std::vector<double> times(static_cast<std::size_t>(N + 1));
  for (long j = 0; j <= N; ++j) times[static_cast<std::size_t>(j)] = static_cast<double>(j) * h;
  const Flow<Sys, G> flow{&me, K, h};
  const auto xs = flow_dense<Flow<Sys, G>::N>(flow, state_of<Sys, G>(d.q[0], v0, d.z[0]), times, tol);
  require(xs.size() == times.size(), "modified solution: Odeint returned too few states");
  a.err_z = G::contact ? 0.0 : nan;
  std::vector<Vec<double, n>> qm(xs.size());
  for (std::size_t j = 0; j < xs.size(); ++j) {
    for (int i = 0; i < n; ++i) qm[j](i) = xs[j][static_cast<std::size_t>(i)];
    a.err_q = std::max(a.err_q, (qm[j] - d.q[j]).template lpNorm<Eigen::Infinity>());
    if (G::contact) a.err_z = std::max(a.err_z, std::abs(xs[j][2 * n] - d.z[j]));
  }
  if constexpr (m > 0) {
    typename Engine<Sys, G>::Result r;
    constexpr int o = Engine<Sys, G>::o;
    Vec<double, m> phi0 = Vec<double, m>::Zero();
    for (std::size_t j = 0; j < xs.size(); ++j) {
      interruption_point();
      const double t = times[j];
      Vec<double, n> v;
      for (int i = 0; i < n; ++i) v(i) = xs[j][static_cast<std::size_t>(n + i)];
      if (j + 1 < xs.size()) {
        // the scheme's discrete constraint (a composition's: its stages', see composed_residual.hpp)
        Vec<double, m> phi_d;
        if constexpr (Engine<Sys, G>::composable) {
          if (me.composition())
            phi_d = me.composition()->step(sys, t, h, qm[j], qm[j + 1], xs[j][2 * n], xs[j + 1][2 * n]).phi;
          else
            phi_d = generic::discrete_constraint<Sys, Q, double>(sys, t, h, qm[j], qm[j + 1]);
        } else {
          phi_d = generic::discrete_constraint<Sys, Q, double>(sys, t, h, qm[j], qm[j + 1]);
        }
        a.phi_d = std::max(a.phi_d, phi_d.template lpNorm<Eigen::Infinity>());
      }
      me.evaluate(t, qm[j], v, xs[j][2 * n], K, r);
      Vec<double, m> phi = Vec<double, m>::Zero(), mu = Vec<double, m>::Zero();
      for (int k = K + o; k >= 0; --k) phi = phi * h + r.phi[static_cast<std::size_t>(k)];
      for (int k = K; k >= 0; --k) mu = mu * h + r.mu[static_cast<std::size_t>(k)];
      if (j == 0) {
        phi0 = phi;
        a.phi_h0 = phi.template lpNorm<Eigen::Infinity>();
      }
      a.phi_h_drift = std::max(a.phi_h_drift, (phi - phi0).template lpNorm<Eigen::Infinity>());
      // from j = 1: the first impulse also absorbs, along A^T, the start's momentum p_0 (the continuous one),
      // which is not the scheme's discrete momentum of the modified solution
      if (j >= 1 && j < d.lambda.size()) a.err_mu = std::max(a.err_mu, (d.lambda[j] / h - mu).template lpNorm<Eigen::Infinity>());
    }
  } else {
    a.phi_d = a.phi_h0 = a.phi_h_drift = a.err_mu = nan;
  }
  return a;
}

}  // namespace geomint::modified::detail

namespace geomint::modified {

// The entry of Sys; every operation starts from `prototype` (generic::make_system_info says why).
template <class Sys>
ModifiedSystem make_modified_system(const Sys& prototype = Sys{}) {
  ModifiedSystem s;
  s.name = generic::system_name(prototype);
  s.dof = Sys::dof;
  s.constraints = Sys::constraints;
  s.holonomic = generic::has_holonomic_v<Sys>;
  s.has_herglotz = generic::has_herglotz_v<Sys>;
  s.schemes = generic::generic_scheme_names<Sys>();
  s.at = [prototype](const ParamValues& pv, const std::string& scheme, int K, double t, const std::vector<double>& q,
                     const std::vector<double>& v, double z, bool check) {
    const Sys sys = generic::make_system(prototype, pv);
    sys.validate();
    require(K >= 0 && K <= registry_max_order, "order must be an integer in [0, " + std::to_string(registry_max_order) + "]");
    const auto Q = detail::to_vec<Sys::dof>(q, "q");
    const auto V = detail::to_vec<Sys::dof>(v, "v");
    return detail::visit_modified_scheme<Sys>(
        scheme, [&](auto g, const detail::Family* f) { return detail::point<Sys, decltype(g)>(sys, f, K, t, Q, V, z, check); });
  };
  s.agreement = [prototype](const ParamValues& pv, const std::string& scheme, int K, double h, double T, double tol,
                            AgreementStart start) {
    const Sys sys = generic::make_system(prototype, pv);
    sys.validate();
    require(K >= 0 && K <= registry_max_order, "order must be an integer in [0, " + std::to_string(registry_max_order) + "]");
    return detail::visit_modified_scheme<Sys>(
        scheme, [&](auto g, const detail::Family* f) { return detail::agreement_run<Sys, decltype(g)>(sys, f, K, h, T, tol, start); });
  };
  s.shoot = [prototype](const ParamValues& pv, const std::string& scheme, int K, double h, double tol) {
    const Sys sys = generic::make_system(prototype, pv);
    sys.validate();
    return detail::visit_modified_scheme<Sys>(scheme, [&](auto g, const detail::Family* f) {
      using G = decltype(g);
      const detail::Engine<Sys, G> me = detail::engine<Sys, G>(sys, f);
      const auto d = detail::discrete_run<Sys, G>(sys, f, h, 1);
      const auto v = detail::shoot_velocity(me, K, h, d.q[0], d.v0, d.z[0], d.q[1], tol, nullptr);
      return std::vector<double>(v.data(), v.data() + Sys::dof);
    });
  };
  return s;
}

}  // namespace geomint::modified
