#pragma once
// make_system_info<Sys>(prototype): everything the run-time registry needs about one system, instantiated once per
// system in its own generated translation unit (see core/CMakeLists.txt and core/src/systems.def). Heavy:
// include it only there and in tests that need the typed pieces.
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <string>
#include <tuple>
#include <type_traits>

#include "geomint/error.hpp"
#include "geomint/generic/composition.hpp"
#include "geomint/generic/composition_families.hpp"
#include "geomint/generic/system_schemes.hpp"
#include "geomint/generic/stepper.hpp"
#include "geomint/interrupt.hpp"
#include "geomint/io.hpp"
#include "geomint/reference.hpp"
#include "geomint/registry.hpp"
#include "geomint/timing.hpp"

namespace geomint::generic {

// ---------------------------------------------------------------------------------------------------
// Parameters by name

// `prototype` with `values` set by name (a system defined by formulas: a prototype holding its model).
template <class Sys>
Sys make_system(Sys sys, const ParamValues& values) {
  for (const auto& [name, value] : values) {
    bool found = false;
    sys.visit([&, &name = name, value = value](const char* field, double& x, const char*) {
      if (name == field) {
        x = value;
        found = true;
      }
    });
    if (!found) {
      std::string known;
      sys.visit([&](const char* field, double&, const char*) { known += (known.empty() ? "" : ", ") + std::string(field); });
      throw InputError("system '" + system_name(sys) + "' has no parameter '" + name + "' (known: " + known + ")");
    }
  }
  return sys;
}
template <class Sys>
Sys make_system(const ParamValues& values) {
  return make_system(Sys{}, values);
}

template <class Sys>
double horizon_of(const Sys& sys) {
  double T = missing_value;
  Sys copy = sys;
  copy.visit([&](const char* field, double& x, const char*) {
    if (std::string(field) == "T") T = x;
  });
  return T;
}

// ---------------------------------------------------------------------------------------------------
// Driving a run: the closed form where asked and available, else the generic stepper. The observer gets
// the StepView of every q_j, j = 0..N, and the Newton iterations of the step into it (-1: closed form).
// X is a generic scheme or a scheme the system declares (which runs its closed form whatever the path).

// The path that actually runs X on Sys when `path` is asked for.
template <class Sys, class X>
Path effective_path(Path path) {
  if constexpr (is_extra_scheme_v<X>) {
    (void)path;
    return Path::fast;
  } else {
    return std::is_void_v<closed_form_for_t<Sys, X>> ? Path::generic : path;
  }
}

template <class Sys, class X>
void require_path(Path path) {
  if constexpr (is_extra_scheme_v<X>) {
    if (path == Path::generic)
      throw InputError(std::string("scheme '") + X::name + "' is declared" + of_system<Sys>("by") +
                       " as a closed form only: it has no generic step (use --path fast)");
  } else {
    (void)path;
  }
}

// positions_only: the observer reads only j, t and q, so a closed form that has run_positions runs it (the
// view's p, z and lambda are then missing values).
template <class Sys, class X, bool positions_only = false, class Observer>
void drive(const Sys& sys, double h, long N, Path path, Observer&& observe_step) {
  constexpr int n = Sys::dof, m = Sys::constraints;
  require_path<Sys, X>(path);
  // every step an interruption point, and the run's progress when it is the watched call's outermost task
  Task task("run", "steps", static_cast<double>(N));
  auto observe = [&](const StepView<double, n, m>& view, int updates) {
    interruption_point();
    task.set(static_cast<double>(view.j));
    observe_step(view, updates);
  };
  using C = runner_of_t<Sys, X>;
  if constexpr (!std::is_void_v<C>) {
    if (effective_path<Sys, X>(path) == Path::fast) {
      if constexpr (positions_only && has_run_positions<Sys, C>::value) {
        const Vec<double, n> p = Vec<double, n>::Constant(missing_value);
        const Vec<double, m> lambda = Vec<double, m>::Constant(missing_value);
        sys.template run_positions<C>(h, N, [&](long j, double t, const Vec<double, n>& q) {
          if (!q.allFinite()) throw NumericalFailure(j, "state", "the closed form's q is not finite");
          observe(StepView<double, n, m>{j, t, q, p, missing_value, lambda}, -1);
        });
        return;
      }
      // A closed form has no Newton to fail: an overflow (a damping of 1e308) is caught here, where it happens,
      // instead of reaching a table as nan.
      sys.template run_fast<C>(h, N, [&](const auto& view) {
        if (!view.q.allFinite() || !view.p.allFinite() || !std::isfinite(view.z))
          throw NumericalFailure(view.j, "state", "the closed form's q, p or z is not finite");
        observe(view, -1);
      });
      return;
    }
  }
  if constexpr (!is_extra_scheme_v<X>) {
    Stepper<Sys, X> st(sys, h);
    st.start(sys.template initial_position<double>(), sys.template initial_velocity<double>());
    auto emit = [&](int updates) {
      const auto& s = st.state();
      observe(StepView<double, n, m>{s.j, s.t, s.q, s.p, s.z, s.lambda}, updates);
    };
    emit(0);
    for (long j = 0; j < N; ++j) {
      st.step();
      emit(st.last_updates());
    }
  }
}

template <class Sys, class X>
std::string context(const Sys& sys, double h, Path path) {
  return "system " + system_name(sys) + ", scheme " + scheme_name_of<X>() + " (" +
         to_string(effective_path<Sys, X>(path)) + "), h = " + show(h);
}

// The velocity whose continuous momentum is p (Newton on dL/dq' = p, the Hessian by AD; one update for a
// quadratic kinetic energy).
template <class Sys>
Vec<double, Sys::dof> velocity_from_momentum(const Sys& sys, bool contact, double t, const Vec<double, Sys::dof>& q,
                                             const Vec<double, Sys::dof>& p, double z) {
  constexpr int n = Sys::dof;
  using D = Dual<double, n>;
  Vec<double, n> v = p;
  for (int it = 0; it < 8; ++it) {
    Vec<D, n> V;
    for (int i = 0; i < n; ++i) V(i) = D::variable(v(i), i);
    Vec<D, n> P;
    if constexpr (has_herglotz_v<Sys>) {
      if (contact)
        P = herglotz_momentum<Sys, D>(sys, D(t), Vec<D, n>(q.template cast<D>()), V, D(z));
      else
        P = momentum<Sys, D>(sys, D(t), Vec<D, n>(q.template cast<D>()), V);
    } else {
      (void)contact;
      (void)z;
      P = momentum<Sys, D>(sys, D(t), Vec<D, n>(q.template cast<D>()), V);
    }
    Mat<double, n, n> M;
    Vec<double, n> r;
    for (int i = 0; i < n; ++i) {
      r(i) = P(i).v - p(i);
      for (int k = 0; k < n; ++k) M(i, k) = P(i).d[static_cast<std::size_t>(k)];
    }
    const Vec<double, n> dv = Eigen::PartialPivLU<Mat<double, n, n>>(M).solve(r);
    v -= dv;
    if (dv.template lpNorm<Eigen::Infinity>() <= 4e-16 * (v.template lpNorm<Eigen::Infinity>() + 1e-300)) break;
  }
  return v;
}

// A run of N steps with nothing kept yet.
template <class Sys>
Run empty_run(bool contact, long N) {
  Run run;
  run.n = Sys::dof;
  run.m = Sys::constraints;
  run.contact = contact;
  run.steps = N;
  return run;
}

// Appends the kept step s to run: its state, the velocity from p_j, the energy, both constraint residuals (phid:
// what the scheme imposed on the step into q_j) and the Newton updates of that step.
template <class Sys>
void append_step(Run& run, const Sys& sys, bool contact, const StepView<double, Sys::dof, Sys::constraints>& s,
                 double phid, int updates) {
  constexpr int n = Sys::dof, m = Sys::constraints;
  const Vec<double, n> v = velocity_from_momentum(sys, contact, s.t, s.q, s.p, s.z);
  run.j.push_back(s.j);
  run.t.push_back(s.t);
  for (int i = 0; i < n; ++i) {
    run.q.push_back(s.q(i));
    run.p.push_back(s.p(i));
    run.v.push_back(v(i));
  }
  run.z.push_back(s.z);
  for (int c = 0; c < m; ++c) run.lambda.push_back(s.lambda(c));
  run.energy.push_back(energy(sys, s.t, s.q, v));
  double phi = 0;
  if constexpr (m > 0) phi = constraint<Sys, double>(sys, s.t, s.q, v).template lpNorm<Eigen::Infinity>();
  run.phi_d.push_back(phid);
  run.phi.push_back(phi);
  run.newton.push_back(updates);
}

template <class Sys, class G>
Run run_scheme(const Sys& sys, double h, Path path, long every) {
  constexpr int n = Sys::dof, m = Sys::constraints;
  require(every >= 1, "every must be a positive integer");
  const long N = step_count(h, horizon_of(sys));
  Run run = empty_run<Sys>(G::contact, N);
  Vec<double, n> qprev = Vec<double, n>::Zero();
  long newton_sum = 0;
  bool closed = false;
  try {
    drive<Sys, G>(sys, h, N, path, [&](const StepView<double, n, m>& s, int updates) {
      double phid = 0;
      if constexpr (m > 0 && !is_extra_scheme_v<G>) {
        if (s.j > 0)
          phid = discrete_constraint<Sys, typename G::quadrature, double>(sys, s.t - h, h, qprev, s.q)
                     .template lpNorm<Eigen::Infinity>();
      }
      run.max_phi_d = std::max(run.max_phi_d, phid);
      if (updates < 0) closed = true;
      if (s.j > 0) newton_sum += updates;
      qprev = s.q;
      if (s.j % every != 0 && s.j != N) return;
      append_step(run, sys, G::contact, s, phid, updates);
    });
  } catch (const NumericalFailure& e) {
    throw e.within(context<Sys, G>(sys, h, path));
  }
  run.newton_mean = closed ? -1 : (N > 0 ? double(newton_sum) / double(N) : 0);
  return run;
}

// ---------------------------------------------------------------------------------------------------
// Compositions (composition.hpp) run as schemes: "<family>:<base>", by the generic step of the base.

// The schemes a composition can be built on: the system's symmetric (second-order) ones.
template <class Sys, class G>
constexpr bool composable() {
  return applicable<Sys, G>() && G::order == 2;
}

template <class Sys>
std::vector<std::string> composable_schemes() {
  std::vector<std::string> names;
  std::apply([&](auto... g) { ((composable<Sys, decltype(g)>() ? names.push_back(scheme_name<decltype(g)>()) : void()), ...); },
             AllSchemesTuple{});
  return names;
}

// Calls f(G{}) for the composable scheme named `base`; InputError naming the composable ones otherwise.
template <class Sys, std::size_t I = 0, class F>
decltype(auto) visit_composable(const std::string& base, F&& f) {
  if constexpr (I == std::tuple_size_v<AllSchemesTuple>) {
    std::string known;
    for (const auto& s : composable_schemes<Sys>()) known += (known.empty() ? "" : ", ") + s;
    throw InputError("scheme '" + base + "'" + of_system<Sys>() + " cannot be composed (symmetric schemes: " +
                     known + ")");
    return f(LaTrapezoid{});  // not reached; gives the return type
  } else {
    using G = std::tuple_element_t<I, AllSchemesTuple>;
    if constexpr (composable<Sys, G>()) {
      if (base == scheme_name<G>()) return f(G{});
    }
    return visit_composable<Sys, I + 1>(base, f);
  }
}

// Calls f(G{}, family) for the composition named "<family>:<base>".
template <class Sys, class F>
decltype(auto) visit_composition(const std::string& name, F&& f) {
  const CompositionName parsed = parse_composition_name(name);
  const CompositionFamily& family = find_composition_family(parsed.family);
  return visit_composable<Sys>(parsed.base, [&](auto g) { return f(g, family); });
}

// N steps of the composition from the system's initial data; observe(StepView, newton updates, max |Phi_d| over
// the stages) at every q_j, j = 0..N.
template <class Sys, class G, class Observer>
void drive_composition(const Sys& sys, const CompositionFamily& family, double h, long N, Observer&& observe_step) {
  constexpr int n = Sys::dof, m = Sys::constraints;
  Task task("run", "steps", static_cast<double>(N));  // as drive
  auto observe = [&](const StepView<double, n, m>& view, int updates, double phid) {
    interruption_point();
    task.set(static_cast<double>(view.j));
    observe_step(view, updates, phid);
  };
  using C = Composition<Sys, G>;
  C c(sys, family, h);
  c.start(sys.template initial_position<double>(), sys.template initial_velocity<double>());
  double phid = 0;
  auto emit = [&](int updates) {
    const auto& s = c.state();
    observe(StepView<double, n, m>{s.j, s.t, s.q, s.p, s.z, s.lambda}, updates, phid);
  };
  emit(0);
  for (long j = 0; j < N; ++j) {
    phid = 0;
    c.step([&](std::size_t i, const typename C::State& in, const typename C::State& out) {
      (void)i;
      (void)in;
      (void)out;
      if constexpr (m > 0)
        phid = std::max(phid, discrete_constraint<Sys, typename G::quadrature, double>(sys, in.t, c.stage_h(i), in.q, out.q)
                                  .template lpNorm<Eigen::Infinity>());
    });
    emit(c.last_updates());
  }
}

template <class Sys>
std::string composition_context(const Sys& sys, const std::string& name, double h) {
  return "system " + system_name(sys) + ", composition " + name + ", h = " + show(h);
}

template <class Sys, class G>
Run run_composition(const Sys& sys, const CompositionFamily& family, const std::string& name, double h, long every) {
  constexpr int n = Sys::dof, m = Sys::constraints;
  require(every >= 1, "every must be a positive integer");
  const long N = step_count(h, horizon_of(sys));
  Run run = empty_run<Sys>(G::contact, N);
  long newton_sum = 0;
  try {
    drive_composition<Sys, G>(sys, family, h, N, [&](const StepView<double, n, m>& s, int updates, double phid) {
      run.max_phi_d = std::max(run.max_phi_d, phid);
      newton_sum += updates;
      if (s.j % every != 0 && s.j != N) return;
      append_step(run, sys, G::contact, s, phid, updates);
    });
  } catch (const NumericalFailure& e) {
    throw e.within(composition_context(sys, name, h));
  }
  run.newton_mean = N > 0 ? double(newton_sum) / double(N) : 0;
  return run;
}


// Calls observe(StepView) at every q_j, j = 0..N, of the scheme or composition `name`; the observer reads only
// j, t and q (a closed form may leave p, z and lambda missing). The observer is a
// std::function, so every error and measure of a run shares one instantiation of each scheme's loop (an indirect
// call a step costs nothing beside a step; build time is a budget).
template <class Sys>
using StepObserver = std::function<void(const StepView<double, Sys::dof, Sys::constraints>&)>;
template <class Sys>
void for_each_step_named(const Sys& sys, const std::string& name, double h, Path path, const StepObserver<Sys>& observe) {
  constexpr int n = Sys::dof, m = Sys::constraints;
  const long N = step_count(h, horizon_of(sys));
  if (is_composition_name(name)) {
    visit_composition<Sys>(name, [&](auto g, const CompositionFamily& f) {
      try {
        drive_composition<Sys, decltype(g)>(sys, f, h, N,
                                            [&](const StepView<double, n, m>& s, int, double) { observe(s); });
      } catch (const NumericalFailure& e) {
        throw e.within(composition_context(sys, name, h));
      }
    });
    return;
  }
  visit_scheme<Sys>(name, [&](auto g) {
    using G = decltype(g);
    try {
      drive<Sys, G, true>(sys, h, N, path, [&](const StepView<double, n, m>& s, int) { observe(s); });
    } catch (const NumericalFailure& e) {
      throw e.within(context<Sys, G>(sys, h, path));
    }
  });
}

// What a system measures on a run beyond the error in q: its `Measures`, an observer of every q_j with the
// reference (FoucaultPendulum::Measures is one):
//   static std::vector<MeasureInfo> info();
//   Measures(const Sys&, double h, long N, const Reference& ref);   // ref on a grid of h/2, with velocities
//   void operator()(long j, double t, const Vec<double, n>& q);      // every q_j, j = 0..N, in order
//   std::vector<double> values() const;                              // one per info() entry, after q_N
template <class Sys, class = void>
struct has_measures : std::false_type {};
template <class Sys>
struct has_measures<Sys, std::void_t<typename Sys::Measures>> : std::true_type {};

// SystemInfo::measure_run: the error in `norm` and the system's measures, in one pass.
template <class Sys>
std::vector<double> measure_run_of(const Sys& sys, const std::string& name, double h, Path path, const Reference& ref,
                                   ErrorNorm norm) {
  constexpr int n = Sys::dof;
  require(ref.n == n, "reference has the wrong dimension");
  double err = 0;
  auto error = [&](long j, const Vec<double, n>& q) {
    const std::size_t r = static_cast<std::size_t>(ref.index(j, h) * n);
    if (norm == ErrorNorm::max) {
      for (int i = 0; i < n; ++i) err = std::max(err, std::abs(q(i) - ref.q[r + static_cast<std::size_t>(i)]));
    } else {  // hypot, one component at a time: the length without overflow, exactly std::hypot for n = 2
      double d = 0;
      for (int i = 0; i < n; ++i) d = std::hypot(d, q(i) - ref.q[r + static_cast<std::size_t>(i)]);
      err = std::max(err, d);
    }
  };
  using View = StepView<double, n, Sys::constraints>;
  if constexpr (has_measures<Sys>::value) {
    typename Sys::Measures measures(sys, h, step_count(h, horizon_of(sys)), ref);
    for_each_step_named<Sys>(sys, name, h, path, [&](const View& s) {
      error(s.j, s.q);
      measures(s.j, s.t, s.q);
    });
    std::vector<double> out{err};
    for (double x : measures.values()) out.push_back(x);
    return out;
  } else {
    for_each_step_named<Sys>(sys, name, h, path, [&](const View& s) { error(s.j, s.q); });
    return {err};
  }
}

// max_j max_i metric(i, q_i(t_j), q_ref,i(t_j)) over the run of the scheme or composition `name`.
template <class Sys, class Metric>
double max_over_named(const Sys& sys, const std::string& name, double h, Path path, const Reference& ref, Metric&& metric) {
  constexpr int n = Sys::dof;
  require(ref.n == n, "reference has the wrong dimension");
  double err = 0;
  for_each_step_named<Sys>(sys, name, h, path, [&](const StepView<double, n, Sys::constraints>& s) {
    const std::size_t r = static_cast<std::size_t>(ref.index(s.j, h) * n);
    for (int i = 0; i < n; ++i) err = std::max(err, metric(i, s.q(i), ref.q[r + static_cast<std::size_t>(i)]));
  });
  return err;
}

// ---------------------------------------------------------------------------------------------------
// References

template <class Sys>
Reference reference_of(const Sys& sys, double h, long N, ReferenceKind kind, double tol) {
  constexpr int n = Sys::dof;
  require(N >= 1, "reference needs at least one step");
  const bool exact = exact_available(sys);
  if (kind == ReferenceKind::automatic) kind = exact ? ReferenceKind::exact : ReferenceKind::odeint;
  const double t0 = initial_time(sys);  // t_j = t0 + j h
  check_reference_memory(n, kind == ReferenceKind::exact, N);
  Reference ref;
  ref.h = h;
  ref.N = N;
  ref.n = n;
  ref.q.resize(static_cast<std::size_t>((N + 1) * n));
  ref.v.resize(ref.q.size());
  if (kind == ReferenceKind::exact) {
    if constexpr (has_exact_v<Sys>) {
      if (!exact)
        throw InputError("system '" + system_name(sys) + "' has no closed-form solution (use --reference odeint)");
      ref.kind = "closed form";
      for (long j = 0; j <= N; ++j) {
        const auto x = sys.template exact<double>(t0 + static_cast<double>(j) * h);
        // where a closed form overflows (extreme parameters), not as a nan in some table downstream
        if (!x.q.allFinite() || !x.v.allFinite())
          throw NumericalFailure(j, "reference", "the closed-form solution of " + system_name(sys) +
                                                     " is not finite at t = " + show(t0 + static_cast<double>(j) * h));
        for (int i = 0; i < n; ++i) {
          ref.q[static_cast<std::size_t>(j * n + i)] = x.q(i);
          ref.v[static_cast<std::size_t>(j * n + i)] = x.v(i);
        }
      }
      return ref;
    } else {
      throw InputError("system '" + system_name(sys) + "' has no closed-form solution (use --reference odeint)");
    }
  }
  if (kind == ReferenceKind::odeint_rhs && !has_rhs_v<Sys>)
    throw InputError("system '" + system_name(sys) + "' has no hand-written rhs (use --reference odeint)");
  require(std::isfinite(tol) && tol >= 1e-15 && tol < 1, "tol must be in [1e-15, 1), got " + show(tol));
  std::vector<double> times(static_cast<std::size_t>(N + 1));
  for (long j = 0; j <= N; ++j) times[static_cast<std::size_t>(j)] = t0 + static_cast<double>(j) * h;
  using State = std::array<double, 2 * n>;
  const Vec<double, n> q0 = sys.template initial_position<double>();
  const bool hand = kind == ReferenceKind::odeint_rhs;
  const Vec<double, n> v0 = hand ? hand_written_velocity(sys, t0, q0, sys.template initial_velocity<double>())
                                 : consistent_velocity(sys, t0, q0, sys.template initial_velocity<double>());
  State x0;
  for (int i = 0; i < n; ++i) {
    x0[static_cast<std::size_t>(i)] = q0(i);
    x0[static_cast<std::size_t>(n + i)] = v0(i);
  }
  auto rhs = [&](const State& x, State& dx, double t) {
    interruption_point();  // a tight tolerance over a long horizon is a long reference
    Vec<double, n> q, v, a;
    for (int i = 0; i < n; ++i) {
      q(i) = x[static_cast<std::size_t>(i)];
      v(i) = x[static_cast<std::size_t>(n + i)];
    }
    if constexpr (has_rhs_v<Sys>) {
      if (hand)
        sys.rhs(t, q, v, a);
      else
        a = acceleration(sys, t, q, v).a;
    } else {
      a = acceleration(sys, t, q, v).a;
    }
    for (int i = 0; i < n; ++i) {
      dx[static_cast<std::size_t>(i)] = v(i);
      dx[static_cast<std::size_t>(n + i)] = a(i);
    }
  };
  const auto xs = odeint_dense<2 * n>(rhs, x0, times, tol);
  require(xs.size() == times.size(), "reference: Odeint returned " + std::to_string(xs.size()) + " of " +
                                         std::to_string(times.size()) + " states");
  for (long j = 0; j <= N; ++j)
    for (int i = 0; i < n; ++i) {
      const double qi = xs[static_cast<std::size_t>(j)][static_cast<std::size_t>(i)];
      const double vi = xs[static_cast<std::size_t>(j)][static_cast<std::size_t>(n + i)];
      if (!std::isfinite(qi) || !std::isfinite(vi))
        throw NumericalFailure(j, "reference", "Odeint reference of " + system_name(sys) + " is not finite");
      ref.q[static_cast<std::size_t>(j * n + i)] = qi;
      ref.v[static_cast<std::size_t>(j * n + i)] = vi;
    }
  ref.kind = std::string("Boost.Odeint dopri5, dense output, tol ") + show(tol) +
             (hand ? ", hand-written equations" : ", equations derived from L, F, Phi by AD");
  return ref;
}

// ---------------------------------------------------------------------------------------------------
// Linear maps (stability)

template <class Sys>
void require_linear_unconstrained(const Sys& sys, const char* what) {
  if (!is_linear<Sys>() || Sys::constraints > 0)
    throw InputError(std::string(what) + " needs a linear system without constraints; '" + system_name(sys) + "' is not");
}

template <class Sys, class C, class = void>
struct has_closed_form_matrix : std::false_type {};
template <class Sys, class C>
struct has_closed_form_matrix<Sys, C, std::void_t<decltype(std::declval<const Sys&>().template closed_form_matrix<C>(0.0L))>>
    : std::true_type {};

// The matrix of an affine one-step map on (q, p) (2n x 2n, row-major): columns are the images of the unit
// vectors, minus the image of 0 (which carries any forcing). step(q, p) returns the state after one step.
template <int n, class Step>
std::vector<long double> affine_map_matrix(Step&& step) {
  constexpr int N = 2 * n;
  auto image = [&](const Vec<double, N>& x) {
    const auto s = step(Vec<double, n>(x.template head<n>()), Vec<double, n>(x.template tail<n>()));
    Vec<double, N> y;
    y << s.q, s.p;
    return y;
  };
  const Vec<double, N> zero = image(Vec<double, N>::Zero());
  std::vector<long double> M(static_cast<std::size_t>(N * N));
  for (int c = 0; c < N; ++c) {
    const Vec<double, N> col = image(Vec<double, N>::Unit(c)) - zero;
    for (int r = 0; r < N; ++r) M[static_cast<std::size_t>(r * N + c)] = col(r);
  }
  return M;
}

// The generic step's matrix: columns are the images of the unit vectors of (q, p), minus the image of 0 (which
// carries any forcing). A closed form with a closed_form_matrix gives its own on the fast path.
template <class Sys, class X>
std::vector<long double> one_step_matrix_of(const Sys& sys, double h, Path path) {
  constexpr int n = Sys::dof;
  require_path<Sys, X>(path);
  using C = runner_of_t<Sys, X>;
  if constexpr (!std::is_void_v<C>) {
    if constexpr (has_closed_form_matrix<Sys, C>::value) {
      if (effective_path<Sys, X>(path) == Path::fast) return sys.template closed_form_matrix<C>(h);
    }
  }
  if constexpr (is_extra_scheme_v<X>) {
    throw InputError(std::string("scheme '") + X::name + "' of system '" + system_name(sys) + "' gives no one-step matrix");
  } else {
    return affine_map_matrix<n>([&](const Vec<double, n>& q, const Vec<double, n>& p) {
      Stepper<Sys, X> st(sys, h);
      st.restart(0, q, p, 0.0);
      st.step();
      return st.state();
    });
  }
}

template <class Sys, class G>
std::vector<long double> composition_matrix_of(const Sys& sys, const CompositionFamily& family, double h) {
  return affine_map_matrix<Sys::dof>([&](const Vec<double, Sys::dof>& q, const Vec<double, Sys::dof>& p) {
    Composition<Sys, G> c(sys, family, h);
    c.restart(0, q, p, 0.0);
    c.step();
    return c.state();
  });
}

template <class Sys>
std::vector<double> continuous_matrix_of(const Sys& sys) {
  constexpr int n = Sys::dof, N = 2 * n;
  auto field = [&](const Vec<double, N>& x) {
    const Vec<double, n> q = x.template head<n>(), v = x.template tail<n>();
    const Vec<double, n> a = acceleration(sys, 0.0, q, v).a;
    Vec<double, N> y;  // element by element: Eigen's packet copy of a 1-vector into a block trips -Warray-bounds
    for (int i = 0; i < n; ++i) {
      y(i) = v(i);
      y(n + i) = a(i);
    }
    return y;
  };
  const Vec<double, N> zero = field(Vec<double, N>::Zero());
  std::vector<double> C(static_cast<std::size_t>(N * N));
  for (int c = 0; c < N; ++c) {
    const Vec<double, N> col = field(Vec<double, N>::Unit(c)) - zero;
    for (int r = 0; r < N; ++r) C[static_cast<std::size_t>(r * N + c)] = col(r);
  }
  return C;
}

// ---------------------------------------------------------------------------------------------------
// The registry entry

template <class Sys, class = void>
struct has_expectations : std::false_type {};
template <class Sys>
struct has_expectations<Sys, std::void_t<decltype(Sys::expectations())>> : std::true_type {};

// The system's declared expectations, or the defaults (the horizon cut to 20).
template <class Sys>
Expectations expectations_of(const Sys& sys) {
  if constexpr (has_expectations<Sys>::value) {
    (void)sys;
    return Sys::expectations();
  } else {
    Expectations e;
    const double T = horizon_of(sys);
    if (T > 20) e.params = {{"T", 20}};
    return e;
  }
}

// The entry of Sys. Every operation starts from `prototype` with the values it is given set by name: a header system's
// defaults, or a formula system holding its model (one compiled type for every model of a shape).
template <class Sys>
SystemInfo make_system_info(const Sys& prototype = Sys{}) {
  SystemInfo info;
  info.name = system_name(prototype);
  info.description = system_description(prototype);
  info.dof = Sys::dof;
  info.constraints = Sys::constraints;
  info.has_exact = has_exact_v<Sys>;
  info.has_herglotz = has_herglotz_v<Sys>;
  info.has_rhs = has_rhs_v<Sys>;
  info.linear = is_linear<Sys>();
  Sys defaults = prototype;
  defaults.visit([&](const char* name, double& x, const char* doc) { info.params.push_back({name, x, doc}); });
  for_each_scheme<Sys>([&](auto x) {
    using X = decltype(x);
    SchemeInfo si;
    si.name = scheme_name_of<X>();
    si.order = X::order;
    if constexpr (is_extra_scheme_v<X>) {
      si.principle = std::string("declared by the system: ") + X::description;
      si.fast_path = X::name;
      si.generic = false;
    } else {
      si.principle = X::contact ? "discrete Herglotz (3), (4)" : "Lagrange-d'Alembert (1)";
      si.quadrature = X::quadrature::name;
      using C = closed_form_for_t<Sys, X>;
      if constexpr (!std::is_void_v<C>) {
        si.fast_path = C::name;
        if (!std::string(alias_of<C>()).empty()) si.aliases.push_back(alias_of<C>());
      }
    }
    info.schemes.push_back(si);
  });
  for (const auto& family : composition_families())
    for (const auto& base : composable_schemes<Sys>()) {
      const SchemeInfo& b = info.scheme(base);
      SchemeInfo si;
      si.name = composition_name(family.name, base);
      si.order = family.order;
      si.principle = family.name + " composition (" + std::to_string(family.stages()) + " stages) of " + base + ": " +
                     b.principle;
      si.quadrature = b.quadrature;
      si.base = base;
      info.compositions.push_back(si);
    }

  info.expectations = expectations_of(prototype);
  if constexpr (has_measures<Sys>::value) info.measures = Sys::Measures::info();
  info.validate = [prototype](const ParamValues& pv) { make_system(prototype, pv).validate(); };
  info.horizon = [prototype](const ParamValues& pv) { return horizon_of(make_system(prototype, pv)); };
  info.initial_time = [prototype](const ParamValues& pv) { return initial_time(make_system(prototype, pv)); };
  info.run = [prototype](const ParamValues& pv, const std::string& scheme, double h, Path path, long every) {
    const Sys sys = make_system(prototype, pv);
    sys.validate();
    if (is_composition_name(scheme))
      return visit_composition<Sys>(scheme, [&](auto g, const CompositionFamily& f) {
        return run_composition<Sys, decltype(g)>(sys, f, scheme, h, every);
      });
    return visit_scheme<Sys>(scheme, [&](auto g) { return run_scheme<Sys, decltype(g)>(sys, h, path, every); });
  };
  info.max_error = [prototype](const ParamValues& pv, const std::string& scheme, double h, Path path, const Reference& ref) {
    const Sys sys = make_system(prototype, pv);
    sys.validate();
    return max_over_named(sys, scheme, h, path, ref, [](int, double q, double r) { return std::abs(q - r); });
  };
  info.measure_run = [prototype](const ParamValues& pv, const std::string& scheme, double h, Path path, const Reference& ref,
                        ErrorNorm norm) {
    const Sys sys = make_system(prototype, pv);
    sys.validate();
    return measure_run_of(sys, scheme, h, path, ref, norm);
  };
  info.max_relative_error = [prototype](const ParamValues& pv, const std::string& scheme, double h, Path path,
                               const Reference& ref, double shift) {
    const Sys sys = make_system(prototype, pv);
    sys.validate();
    return max_over_named(sys, scheme, h, path, ref, [shift](int i, double q, double r) {
      return i == 0 ? std::abs((shift + q) / (shift + r) - 1) : 0.0;
    });
  };
  info.reference = [prototype](const ParamValues& pv, double h, long N, ReferenceKind kind, double tol) {
    const Sys sys = make_system(prototype, pv);
    sys.validate();
    return reference_of(sys, h, N, kind, tol);
  };
  info.time_run = [prototype](const ParamValues& pv, const std::string& scheme, double h, Path path, int reps) {
    const Sys sys = make_system(prototype, pv);
    sys.validate();
    const long N = step_count(h, horizon_of(sys));
    if (is_composition_name(scheme))
      return visit_composition<Sys>(scheme, [&](auto g, const CompositionFamily& f) {
        double last = 0;
        return time_per_call(
            [&] {
              drive_composition<Sys, decltype(g)>(sys, f, h, N, [&](const StepView<double, Sys::dof, Sys::constraints>& v,
                                                                     int, double) { last = v.q(0); });
              do_not_optimize(last);
            },
            reps);
      });
    return visit_scheme<Sys>(scheme, [&](auto g) {
      using G = decltype(g);
      double last = 0;
      const auto st = time_per_call(
          [&] {
            drive<Sys, G, true>(sys, h, N, path,
                                [&](const StepView<double, Sys::dof, Sys::constraints>& v, int) { last = v.q(0); });
            do_not_optimize(last);
          },
          reps);
      return st;
    });
  };
  info.ode = [prototype](const ParamValues& pv) -> std::function<void(double, const double*, double*)> {
    const Sys sys = make_system(prototype, pv);
    sys.validate();
    return [sys](double t, const double* x, double* dx) {
      constexpr int n = Sys::dof;
      const Eigen::Map<const Vec<double, n>> q(x), v(x + n);
      const Vec<double, n> a = acceleration(sys, t, Vec<double, n>(q), Vec<double, n>(v)).a;
      for (int i = 0; i < n; ++i) {
        dx[i] = v(i);
        dx[n + i] = a(i);
      }
    };
  };
  info.observables = [prototype](const ParamValues& pv) -> SystemInfo::Observables {
    const Sys sys = make_system(prototype, pv);
    sys.validate();
    return [sys](double t, const double* q, const double* v, double* out) {
      constexpr int n = Sys::dof;
      const Vec<double, n> Q = Eigen::Map<const Vec<double, n>>(q), V = Eigen::Map<const Vec<double, n>>(v);
      out[0] = energy(sys, t, Q, V);
      const Vec<double, n> p = momentum(sys, t, Q, V);
      for (int i = 0; i < n; ++i) out[1 + i] = p(i);
    };
  };
  info.ode_rhs = [prototype](const ParamValues& pv) -> std::function<void(double, const double*, double*)> {
    if constexpr (has_rhs_v<Sys>) {
      const Sys sys = make_system(prototype, pv);
      sys.validate();
      return [sys](double t, const double* x, double* dx) {
        constexpr int n = Sys::dof;
        Vec<double, n> q, v, a;
        for (int i = 0; i < n; ++i) {
          q(i) = x[i];
          v(i) = x[n + i];
        }
        sys.rhs(t, q, v, a);
        for (int i = 0; i < n; ++i) {
          dx[i] = v(i);
          dx[n + i] = a(i);
        }
      };
    } else {
      (void)pv;
      throw InputError("system '" + system_name(prototype) + "' has no hand-written rhs (use the equations derived by AD)");
    }
  };
  info.exact_positions = [prototype](const ParamValues& pv, const std::vector<double>& times) {
    if constexpr (has_exact_v<Sys>) {
      const Sys sys = make_system(prototype, pv);
      sys.validate();
      if (!exact_available(sys)) throw InputError("system '" + system_name(sys) + "' has no closed-form solution");
      std::vector<double> q;
      q.reserve(times.size() * Sys::dof);
      for (double t : times) {
        const auto x = sys.template exact<double>(t);
        if (!x.q.allFinite())
          throw NumericalFailure(0, "reference", "the closed-form solution of " + system_name(sys) +
                                                     " is not finite at t = " + show(t));
        for (int i = 0; i < Sys::dof; ++i) q.push_back(x.q(i));
      }
      return q;
    } else {
      (void)pv;
      (void)times;
      throw InputError("system '" + system_name(prototype) + "' has no closed-form solution");
      return std::vector<double>{};
    }
  };
  info.one_step_matrix = [prototype](const ParamValues& pv, const std::string& scheme, double h, Path path) {
    const Sys sys = make_system(prototype, pv);
    require_linear_unconstrained(sys, "a one-step matrix");
    sys.validate();
    require_positive(h, "h");
    if constexpr (is_linear<Sys>() && Sys::constraints == 0) {
      if (is_composition_name(scheme))
        return visit_composition<Sys>(scheme, [&](auto g, const CompositionFamily& f) {
          return composition_matrix_of<Sys, decltype(g)>(sys, f, h);
        });
      return visit_scheme<Sys>(scheme, [&](auto g) { return one_step_matrix_of<Sys, decltype(g)>(sys, h, path); });
    } else {
      return std::vector<long double>{};
    }
  };
  info.continuous_matrix = [prototype](const ParamValues& pv) {
    const Sys sys = make_system(prototype, pv);
    require_linear_unconstrained(sys, "a continuous matrix");
    sys.validate();
    return continuous_matrix_of(sys);
  };
  info.ode_initial_state = [prototype](const ParamValues& pv, bool hand_written) {
    const Sys sys = make_system(prototype, pv);
    sys.validate();
    const Vec<double, Sys::dof> q0 = sys.template initial_position<double>();
    const Vec<double, Sys::dof> v = sys.template initial_velocity<double>();
    const double t0 = initial_time(sys);
    const Vec<double, Sys::dof> v0 = hand_written ? hand_written_velocity(sys, t0, q0, v) : consistent_velocity(sys, t0, q0, v);
    std::vector<double> x(q0.data(), q0.data() + Sys::dof);
    x.insert(x.end(), v0.data(), v0.data() + Sys::dof);
    return x;
  };
  return info;
}

}  // namespace geomint::generic
