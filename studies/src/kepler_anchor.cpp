#include "geomint/kepler_anchor.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <boost/numeric/odeint.hpp>

#include "geomint/budget.hpp"
#include "geomint/constants.hpp"
#include "geomint/error.hpp"
#include "geomint/reference.hpp"
#include "geomint/registry.hpp"
#include "geomint/run/baselines.hpp"
#include "geomint/systems/kepler.hpp"
#include "geomint/timing.hpp"

namespace geomint {

namespace {

constexpr double nan = missing_value;
using State = std::array<double, 4>;  // (q1, q2, q1', q2')

ParamValues params_of(const KeplerSetting& s) { return {{"a", s.a}, {"theta", s.theta}, {"e", s.e}, {"T", s.T}}; }

// A trajectory at every step t_j = j tau: positions and velocities.
struct Trajectory {
  std::vector<double> t;
  std::vector<State> x;
  double work_per_step = nan;
  std::string work_unit;
};

// x' = f(t, x) with the acceleration the core derives from L (the kepler system's AD path), at t_j = j tau:
// Bulirsch–Stoer with dense output (bulirsch = true) or Dormand–Prince (reference.hpp's odeint_dense).
std::vector<State> odeint_reference(const KeplerSetting& s, long N, double tol, bool bulirsch) {
  namespace odeint = boost::numeric::odeint;
  const SystemInfo& sys = find_system("kepler");
  const auto ode = sys.ode(params_of(s));
  const auto x0 = sys.ode_initial_state(params_of(s), false);
  std::vector<double> times(static_cast<std::size_t>(N + 1));
  for (long j = 0; j <= N; ++j) times[static_cast<std::size_t>(j)] = static_cast<double>(j) * s.tau;
  auto f = [&](const State& x, State& dx, double t) { ode(t, x.data(), dx.data()); };
  State x{x0[0], x0[1], x0[2], x0[3]};
  std::vector<State> xs;
  if (bulirsch) {
    odeint::bulirsch_stoer_dense_out<State> bs(tol, tol);
    odeint::integrate_times(bs, f, x, times.begin(), times.end(), s.tau / 10, [&](const State& y, double) { xs.push_back(y); });
  } else {
    xs = odeint_dense<4>(f, x, times, tol);
  }
  require(static_cast<long>(xs.size()) == N + 1, "kepler reference: Odeint returned too few states");
  for (const auto& y : xs)
    for (double c : y)
      if (!std::isfinite(c)) throw NumericalFailure(N, "reference", "the Odeint reference of kepler is not finite");
  return xs;
}

// The anchor's fixed-step RK4, here Odeint's through the one door (run/baselines.hpp), on the same derived
// equations; observe(j, t_j, x_j) at every step (null: a timed run).
void run_rk4(const KeplerSetting& s, long N, const BaselineObserver* observe) {
  const SystemInfo& sys = find_system("kepler");
  BaselineSetup b;
  b.name = "odeint-rk4";
  b.h = s.tau;
  b.steps = N;
  run_baseline(b, sys.ode(params_of(s)), sys.ode_initial_state(params_of(s), false), observe);
}

Trajectory run_method(const KeplerSetting& s, const std::string& method, long N) {
  Trajectory tr;
  if (method == "odeint-rk4") {
    const BaselineObserver keep = [&](std::size_t j, double t, const double* x) {
      for (int i = 0; i < 4; ++i)
        if (!std::isfinite(x[i])) throw NumericalFailure(static_cast<long>(j), "state", "odeint-rk4 left the finite numbers");
      tr.t.push_back(t);
      tr.x.push_back({x[0], x[1], x[2], x[3]});
    };
    run_rk4(s, N, &keep);
    tr.work_per_step = 4;
    tr.work_unit = "rhs";
    return tr;
  }
  const Run run = find_system("kepler").run(params_of(s), method, s.tau, Path::generic, 1);
  for (std::size_t j = 0; j < run.t.size(); ++j) {
    tr.t.push_back(run.t[j]);
    tr.x.push_back({run.q[2 * j], run.q[2 * j + 1], run.v[2 * j], run.v[2 * j + 1]});
  }
  tr.work_per_step = run.newton_mean;
  tr.work_unit = "newton";
  return tr;
}

int order_of(const std::string& method) {
  if (method == "odeint-rk4") return 4;
  return find_system("kepler").scheme(method).order;
}

double energy(const State& x) { return (x[2] * x[2] + x[3] * x[3]) / 2 - 1 / std::hypot(x[0], x[1]); }
double momentum(const State& x) { return x[0] * x[3] - x[1] * x[2]; }

}  // namespace

std::vector<KeplerSetting> kepler_anchor_settings() {
  return {{"anchor-1", -0.07, two_pi, 0.4, 40, 0.5, 1},
          {"anchor-2", -0.01, pi, 0.4, 55, 0.5, 1},
          {"error-e0", 0.01, two_pi, 0.0, 200, 0.05, 10},
          {"error-e0.2", 0.01, two_pi, 0.2, 200, 0.05, 10},
          {"error-e0.5", 0.01, two_pi, 0.5, 200, 0.05, 10}};
}

std::vector<std::string> kepler_anchor_methods() {
  return {"contact-trapezoid", "yoshida6a:contact-trapezoid", "odeint-rk4", "la-trapezoid", "yoshida6a:la-trapezoid"};
}

KeplerAnchor kepler_anchor(const std::vector<KeplerSetting>& settings, const std::vector<std::string>& methods,
                           double tol) {
  check_tolerance(tol, "tol");
  require(tol < 1e-3, "tol must be below 1e-3, got " + show(tol));
  for (const auto& m : methods) order_of(m);  // unknown names refused before any work
  KeplerAnchor out;
  out.reference = "Boost.Odeint Bulirsch-Stoer, dense output, tol " + show(tol) +
                  ", on the equations derived from L by AD; checked against Odeint dopri5 at the same tolerance";
  for (const auto& s : settings) {
    find_system("kepler").validate(params_of(s));
    require_positive(s.tau, "tau");
    require(s.every >= 1, "every must be a positive integer");
    const long N = step_count(s.tau, s.T);
    const auto ref = odeint_reference(s, N, tol, true);
    const auto check = odeint_reference(s, N, tol, false);
    double ref_err = 0;
    for (long j = 0; j <= N; ++j) {
      const auto& a = ref[static_cast<std::size_t>(j)];
      const auto& b = check[static_cast<std::size_t>(j)];
      ref_err = std::max(ref_err, std::hypot(a[0] - b[0], a[1] - b[1]));
    }
    const double M0 = momentum(ref.front());
    systems::Kepler law;  // the exact angular momentum law of these parameters
    law.a = s.a;
    law.theta = s.theta;
    law.e = s.e;
    std::vector<Trajectory> runs(methods.size());
    std::vector<std::string> failures(methods.size());
    for (std::size_t k = 0; k < methods.size(); ++k) {
      try {
        runs[k] = run_method(s, methods[k], N);
      } catch (const NumericalFailure& f) {
        failures[k] = f.what();
      }
    }
    const auto sixth = std::find(methods.begin(), methods.end(), "yoshida6a:contact-trapezoid");
    const Trajectory* six = sixth != methods.end() && failures[static_cast<std::size_t>(sixth - methods.begin())].empty()
                                ? &runs[static_cast<std::size_t>(sixth - methods.begin())]
                                : nullptr;
    for (std::size_t k = 0; k < methods.size(); ++k) {
      KeplerScore sc{s.name, methods[k], order_of(methods[k]), nan, nan, nan, nan, nan, nan, "", ref_err, failures[k]};
      if (!failures[k].empty()) {
        out.scores.push_back(sc);
        continue;
      }
      const Trajectory& tr = runs[k];
      KeplerTrace trace{s.name, methods[k], {}, {}, {}, {}, {}, {}, {}, {}};
      double e_max = 0, q_max = 0, m_max = 0, d6 = 0;
      for (long j = 0; j <= N; ++j) {
        const auto J = static_cast<std::size_t>(j);
        const State& x = tr.x[J];
        const State& r = ref[J];
        const double de = std::abs(energy(x) - energy(r));
        const double dq = std::hypot(x[0] - r[0], x[1] - r[1]);
        const double dm = std::abs(momentum(x) / (M0 * law.angular_momentum_factor(tr.t[J])) - 1);
        e_max = std::max(e_max, de);
        q_max = std::max(q_max, dq);
        m_max = std::max(m_max, dm);
        if (six) d6 = std::max(d6, std::hypot(x[0] - six->x[J][0], x[1] - six->x[J][1]));
        if (j % s.every == 0 || j == N) {
          trace.t.push_back(tr.t[J]);
          trace.q1.push_back(x[0]);
          trace.q2.push_back(x[1]);
          trace.q1_ref.push_back(r[0]);
          trace.q2_ref.push_back(r[1]);
          trace.energy_err.push_back(de);
          trace.position_err.push_back(dq);
          trace.momentum_err.push_back(dm);
        }
        if (j == N) sc.final_position_err = dq;
      }
      sc.max_energy_err = e_max;
      sc.max_position_err = q_max;
      sc.max_momentum_err = m_max;
      sc.diff_to_sixth = six ? d6 : nan;
      sc.work_per_step = tr.work_per_step;
      sc.work_unit = tr.work_unit;
      out.scores.push_back(sc);
      out.traces.push_back(std::move(trace));
    }
  }
  return out;
}

double kepler_anchor_seconds(const KeplerSetting& s, const std::string& method, int reps) {
  require(reps >= 1, "reps must be at least 1");
  const long N = step_count(s.tau, s.T);
  if (method == "odeint-rk4") {
    return time_per_call([&] { run_rk4(s, N, nullptr); }, reps).median;
  }
  return find_system("kepler").time_run(params_of(s), method, s.tau, Path::generic, reps).median;
}

}  // namespace geomint
