#pragma once
// make_composition_info<Sys>(): the compositions of one system for the run-time lookup (composition_registry.hpp),
// instantiated once per system in its generated translation unit, next to make_system_info<Sys>(): a
// Composition<Sys, G> reuses the Stepper<Sys, G> instantiated there, so the compositions add one thin layer per
// symmetric base scheme and nothing per family. Heavy: include it only there and in tests of typed pieces.
#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>
#include <vector>

#include "geomint/composition_registry.hpp"
#include "geomint/error.hpp"
#include "geomint/generic/composition.hpp"
#include "geomint/generic/system_info.hpp"
#include "geomint/timing.hpp"

namespace geomint::generic {

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
    throw InputError("scheme '" + base + "' of system '" + Sys::name + "' cannot be composed (symmetric schemes: " +
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
void drive_composition(const Sys& sys, const CompositionFamily& family, double h, long N, Observer&& observe) {
  constexpr int n = Sys::dof, m = Sys::constraints;
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
std::string composition_context(const std::string& name, double h) {
  return std::string("system ") + Sys::name + ", composition " + name + ", h = " + show(h);
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
    throw e.within(composition_context<Sys>(name, h));
  }
  run.newton_mean = N > 0 ? double(newton_sum) / double(N) : 0;
  return run;
}

template <class Sys, class G>
SymmetryDefect symmetry_defect(const Sys& sys, double h, long steps) {
  constexpr int n = Sys::dof, m = Sys::constraints;
  require(steps >= 0, "steps must be non-negative");
  Stepper<Sys, G> forward(sys, h);
  forward.start(sys.template initial_position<double>(), sys.template initial_velocity<double>());
  for (long j = 0; j < steps; ++j) forward.step();
  const auto x0 = forward.state();
  forward.step();
  const auto x1 = forward.state();
  Stepper<Sys, G> back(sys, -h, x1.t);
  back.restart(0, x1.q, x1.p, x1.z);
  back.step();
  const auto& b = back.state();
  SymmetryDefect d;
  d.dq = (b.q - x0.q).template lpNorm<Eigen::Infinity>();
  d.dz = std::abs(b.z - x0.z);
  const Vec<double, n> dp = b.p - x0.p;
  d.dp = dp.template lpNorm<Eigen::Infinity>();
  d.dp_tangent = d.dp;
  if constexpr (m > 0) {
    // the part of dp orthogonal to the rows of A(t_j, q_j), where the forward step applied its impulse
    const Mat<double, m, n> A = sys.constraint_matrix(x0.t, x0.q);
    const Mat<double, m, m> AAt = A * A.transpose();
    const Vec<double, n> normal = A.transpose() * Eigen::PartialPivLU<Mat<double, m, m>>(AAt).solve(A * dp);
    d.dp_tangent = (dp - normal).template lpNorm<Eigen::Infinity>();
  }
  d.q = x0.q.template lpNorm<Eigen::Infinity>();
  d.p = x0.p.template lpNorm<Eigen::Infinity>();
  return d;
}

template <class Sys>
CompositionInfo make_composition_info() {
  CompositionInfo info;
  info.system = Sys::name;
  info.bases = composable_schemes<Sys>();
  info.run = [](const ParamValues& pv, const std::string& name, double h, long every) {
    const Sys sys = make_system<Sys>(pv);
    sys.validate();
    return visit_composition<Sys>(name, [&](auto g, const CompositionFamily& f) {
      return run_composition<Sys, decltype(g)>(sys, f, name, h, every);
    });
  };
  info.max_error = [](const ParamValues& pv, const std::string& name, double h, const Reference& ref) {
    constexpr int n = Sys::dof, m = Sys::constraints;
    const Sys sys = make_system<Sys>(pv);
    sys.validate();
    require(ref.n == n, "reference has the wrong dimension");
    const long N = step_count(h, horizon_of(sys));
    return visit_composition<Sys>(name, [&](auto g, const CompositionFamily& f) {
      double err = 0;
      try {
        drive_composition<Sys, decltype(g)>(sys, f, h, N, [&](const StepView<double, n, m>& s, int, double) {
          const long r = ref.index(s.j, h);
          for (int i = 0; i < n; ++i) err = std::max(err, std::abs(s.q(i) - ref.q[static_cast<std::size_t>(r * n + i)]));
        });
      } catch (const NumericalFailure& e) {
        throw e.within(composition_context<Sys>(name, h));
      }
      return err;
    });
  };
  info.seconds_per_run = [](const ParamValues& pv, const std::string& name, double h, int reps) {
    const Sys sys = make_system<Sys>(pv);
    sys.validate();
    const long N = step_count(h, horizon_of(sys));
    return visit_composition<Sys>(name, [&](auto g, const CompositionFamily& f) {
      double last = 0;
      const auto st = time_per_call(
          [&] {
            drive_composition<Sys, decltype(g)>(sys, f, h, N, [&](const StepView<double, Sys::dof, Sys::constraints>& v, int,
                                                                   double) { last = v.q(0); });
            do_not_optimize(last);
          },
          reps);
      return st.median;
    });
  };
  info.steps = [](const ParamValues& pv, const std::string& name, double h, long N) {
    const Sys sys = make_system<Sys>(pv);
    sys.validate();
    require(std::isfinite(h) && h != 0 && N >= 0, "steps needs a finite nonzero h and N >= 0");
    return visit_composition<Sys>(name, [&](auto g, const CompositionFamily& f) {
      Composition<Sys, decltype(g)> c(sys, f, h);
      c.start(sys.template initial_position<double>(), sys.template initial_velocity<double>());
      for (long j = 0; j < N; ++j) c.step();
      do_not_optimize(c.state().q(0));
      return c.total_updates();
    });
  };
  info.base_steps = [](const ParamValues& pv, const std::string& base, double h, long N) {
    const Sys sys = make_system<Sys>(pv);
    sys.validate();
    require(std::isfinite(h) && h != 0 && N >= 0, "base_steps needs a finite nonzero h and N >= 0");
    return visit_composable<Sys>(base, [&](auto g) {
      Stepper<Sys, decltype(g)> st(sys, h);
      st.start(sys.template initial_position<double>(), sys.template initial_velocity<double>());
      for (long j = 0; j < N; ++j) st.step();
      do_not_optimize(st.state().q(0));
      return st.total_updates();
    });
  };
  info.symmetry = [](const ParamValues& pv, const std::string& base, double h, long steps) {
    const Sys sys = make_system<Sys>(pv);
    sys.validate();
    return visit_composable<Sys>(base, [&](auto g) { return symmetry_defect<Sys, decltype(g)>(sys, h, steps); });
  };
  return info;
}

}  // namespace geomint::generic
