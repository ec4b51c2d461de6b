// The one door for every method of a registry system (run/method.hpp).
#include "geomint/run/method.hpp"

#include <algorithm>
#include <cmath>

#include "geomint/error.hpp"
#include "geomint/generic/composition_families.hpp"
#include "geomint/io.hpp"
#include "geomint/run/baselines.hpp"

namespace geomint {

Method find_method(const SystemInfo& sys, const std::string& name) {
  if (is_baseline(name)) return {name, is_adaptive_baseline(name) ? "adaptive" : "rk"};
  try {
    sys.scheme(name);
  } catch (const InputError& e) {
    throw InputError(std::string(e.what()) + "; or a baseline: " + join_names(baseline_names(), ", "));
  }
  return {name, "geometric"};
}

namespace {

// The baseline's setup: odeint-rk4 in T/h steps, the others landing on T; every step watched.
BaselineSetup baseline_setup(const Method& m, double knob, double T, const MethodOptions& opt) {
  BaselineSetup b;
  b.name = m.name;
  b.T = T;
  b.end = BaselineEnd::land;
  if (m.adaptive()) {
    b.abs_tol = opt.abs_factor * knob;
    b.rel_tol = knob;
  } else {
    b.h = knob;
    b.steps = step_count(knob, T);
    b.every = opt.every;
  }
  return b;
}

// The baselines run on their own clock from 0: the equations are read at t0 + their t (a system that starts at t0).
OdeRhs equations(const SystemInfo& sys, const ParamValues& pv, const MethodOptions& opt) {
  OdeRhs f = opt.hand_written && sys.has_rhs ? sys.ode_rhs(pv) : sys.ode(pv);
  const double t0 = sys.initial_time ? sys.initial_time(pv) : 0.0;
  if (t0 == 0) return f;
  return [f = std::move(f), t0](double t, const double* x, double* dx) { f(t0 + t, x, dx); };
}

}  // namespace

MethodWork run_method(const SystemInfo& sys, const ParamValues& pv, const Method& m, double knob, const MethodOptions& opt,
                      const StateObserver& observe) {
  const double T = sys.horizon(pv);
  const int n = sys.dof;
  const std::size_t un = static_cast<std::size_t>(n);
  MethodWork w;
  if (m.family == "geometric") {
    const Run r = sys.run(pv, m.name, knob, opt.path, opt.every);
    for (std::size_t i = 0; i < r.t.size(); ++i) observe(r.t[i], &r.q[i * un], &r.v[i * un]);
    w.steps = r.steps;
    if (r.newton_mean >= 0) {  // Newton evaluates the residual once before each update and once where it accepts
      const auto& sc = sys.scheme(m.name);
      const double stages =
          sc.base.empty() ? 1.0 : generic::find_composition_family(m.name.substr(0, m.name.find(':'))).stages();
      w.evaluations = (r.newton_mean + stages) * static_cast<double>(r.steps);
    }
    return w;
  }
  const bool hand = opt.hand_written && sys.has_rhs;
  const double t0 = sys.initial_time ? sys.initial_time(pv) : 0.0;
  const BaselineObserver watch = [&](std::size_t, double t, const double* x) { observe(t0 + t, x, x + n); };
  const BaselineCount c = run_baseline(baseline_setup(m, knob, T, opt), equations(sys, pv, opt),
                                       sys.ode_initial_state(pv, hand), &watch);
  w.steps = c.steps;
  w.evaluations = static_cast<double>(c.calls);
  return w;
}

TimingStats time_method(const SystemInfo& sys, const ParamValues& pv, const Method& m, double knob,
                        const MethodOptions& opt, int reps) {
  if (m.family == "geometric") return sys.time_run(pv, m.name, knob, opt.path, reps);
  const BaselineSetup b = baseline_setup(m, knob, sys.horizon(pv), opt);
  const OdeRhs f = equations(sys, pv, opt);
  const auto x0 = sys.ode_initial_state(pv, opt.hand_written && sys.has_rhs);
  return time_per_call([&] { run_baseline(b, f, x0, nullptr); }, reps);
}

}  // namespace geomint
