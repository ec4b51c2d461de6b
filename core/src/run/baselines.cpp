// The baselines' drivers (run/baselines.hpp), each once: Odeint's rk4 stepped by hand, its controlled and dense
// steppers, and GSL's rk8pd through evolve_apply, all on a vector state and a counted right-hand side.
#include "geomint/run/baselines.hpp"

#include <algorithm>
#include <cmath>
#include <type_traits>
#include <utility>

#include <boost/numeric/odeint.hpp>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include "geomint/error.hpp"
#include "geomint/gsl_evolve.hpp"
#include "geomint/interrupt.hpp"
#include "geomint/io.hpp"
#include "geomint/reference.hpp"
#include "geomint/timing.hpp"

namespace geomint {

namespace odeint = boost::numeric::odeint;

const std::vector<std::string>& baseline_names() {
  static const std::vector<std::string> names{"odeint-rk4", "odeint-dopri5", "odeint-bulirsch-stoer", "gsl-rk8pd"};
  return names;
}

bool is_baseline(const std::string& name) {
  const auto& b = baseline_names();
  return std::find(b.begin(), b.end(), name) != b.end();
}

bool is_adaptive_baseline(const std::string& name) { return is_baseline(name) && name != "odeint-rk4"; }

bool has_dense_output(const std::string& name) { return name == "odeint-dopri5" || name == "odeint-bulirsch-stoer"; }

void check_baseline(const std::string& name) {
  require(is_baseline(name), "unknown baseline '" + name + "' (known: " + join_names(baseline_names(), " ") + ")");
}

namespace {

using State = std::vector<double>;

// The right-hand side in Odeint's form with its calls counted (Odeint copies the functor: the count is shared).
struct Counted {
  const OdeRhs* f;
  long* calls;
  void operator()(const State& x, State& dx, double t) const {
    interruption_point();  // a watched call stops here (interrupt.hpp); GSL's steps check in step_to instead
    ++*calls;
    (*f)(t, x.data(), dx.data());
  }
};

int gsl_counted(double t, const double y[], double dydt[], void* params) {
  const Counted& c = *static_cast<const Counted*>(params);
  ++*c.calls;
  (*c.f)(t, y, dydt);
  return GSL_SUCCESS;
}

bool finite(const State& x) {
  for (const double c : x)
    if (!std::isfinite(c)) return false;
  return true;
}

double first_step(const BaselineSetup& s) { return s.first_step > 0 ? s.first_step : 0.01; }

std::string who(const BaselineSetup& s) { return (s.label.empty() ? std::string("Boost.Odeint") : s.label) + " " + s.name; }

// The end of window w at step j: the state must be finite there; the study's window_end may act on it.
bool window_end(const BaselineSetup& s, long w, long j, double t, State& x) {
  if (!finite(x))
    throw NumericalFailure(j, "state", s.name + ": non-finite state " +
                                           (s.windows == 1 ? std::string("at the end") : "by the end of window " + std::to_string(w)));
  return s.window_end && s.window_end(w, t, x.data());
}

void rk4(const BaselineSetup& s, const Counted& rhs, State& x, const BaselineObserver* observe, BaselineCount& n) {
  require(s.h > 0 && s.steps >= 0 && s.every >= 1, "odeint-rk4 needs h > 0, steps >= 0 and every >= 1");
  odeint::runge_kutta4<State> st;
  std::size_t k = 0;
  if (observe) (*observe)(k++, 0.0, x.data());
  long j = 0;
  for (long w = 1; w <= s.windows; ++w) {
    for (const long end = s.steps * w / s.windows; j < end; ++j) {
      st.do_step(rhs, x, static_cast<double>(j) * s.h, s.h);
      if (observe && (j + 1) % s.every == 0) (*observe)(k++, static_cast<double>(j + 1) * s.h, x.data());
    }
    window_end(s, w, j, static_cast<double>(j) * s.h, x);  // rk4 keeps nothing between steps
  }
  n.steps = s.steps;
}

// Steppers that keep a derivative between steps (first-same-as-last: dopri5) have reset(); the others keep nothing.
template <class S, class = void>
struct has_reset : std::false_type {};
template <class S>
struct has_reset<S, std::void_t<decltype(std::declval<S&>().reset())>> : std::true_type {};

// Odeint's controlled stepper st from 0 to T, every accepted step watched.
template <class Stepper>
void controlled(const BaselineSetup& s, Stepper st, const Counted& rhs, State& x, const BaselineObserver* observe,
                BaselineCount& n) {
  std::size_t k = 0;
  if (s.end == BaselineEnd::integrate_adaptive) {
    require(s.windows == 1, "an adaptive run in windows lands on their ends (BaselineEnd::land)");
    long accepted = 0;
    n.steps = static_cast<long>(odeint::integrate_adaptive(st, rhs, x, 0.0, s.T, first_step(s), [&](const State& y, double t) {
      if (t > 0) check_adaptive_steps(++accepted, t, s.T);
      if (observe) (*observe)(k++, t, y.data());
    }));
    if (!finite(x)) throw NumericalFailure(n.steps, "state", who(s) + ": non-finite state at t = " + show(s.T));
    return;
  }
  // try_step, the last step of each window shortened to land on its end exactly (the step size suggested before the
  // shortening kept for the next); a rejected step retries with the step size the stepper suggests
  double t = 0, dt = first_step(s);
  long fails = 0;
  if (observe) (*observe)(k++, t, x.data());
  for (long w = 1; w <= s.windows; ++w) {
    const double tb = w == s.windows ? s.T : s.T * static_cast<double>(w) / static_cast<double>(s.windows);
    while (t < tb) {
      const bool clamped = dt >= tb - t;
      const double dt_before = dt;
      double dt_try = clamped ? tb - t : dt;
      if (st.try_step(rhs, x, t, dt_try) == odeint::success) {
        check_adaptive_steps(++n.steps, t, s.T);
        fails = 0;
        if (clamped) {
          t = tb;
          dt = std::max(dt_try, dt_before);
        } else {
          dt = dt_try;
        }
        if (observe) (*observe)(k++, t, x.data());
      } else {
        dt = dt_try;
        if (++fails > 1000 || !(dt > 0))
          throw NumericalFailure(n.steps, "step size", who(s) + ": no acceptable step at t = " + show(t));
      }
      if (!finite(x)) throw NumericalFailure(n.steps, "state", who(s) + ": non-finite state at t = " + show(t));
    }
    if (window_end(s, w, n.steps, t, x)) {
      if constexpr (has_reset<Stepper>::value) st.reset();  // its stored derivative is stale now
    }
  }
}

// Odeint's dense-output stepper at every output time.
template <class Dense>
void dense(const BaselineSetup& s, Dense st, const Counted& rhs, State& x, const BaselineObserver* observe,
           BaselineCount& n) {
  const auto& ts = s.times;
  require(ts.size() >= 2, "a baseline watched at output times needs at least two of them");
  require(s.windows == 1, "a baseline watched at output times runs in one window");
  std::size_t k = 0;
  try {
    n.steps = static_cast<long>(odeint::integrate_times(
        st, rhs, x, ts.begin(), ts.end(), s.first_step > 0 ? s.first_step : ts[1] / 10,
        [&](const State& y, double t) {
          if (observe) (*observe)(k, t, y.data());
          ++k;
        },
        odeint::max_step_checker(odeint_max_steps_between_outputs)));
  } catch (const odeint::no_progress_error&) {
    throw_too_stiff(who(s), k ? ts[k - 1] : ts.front(), k);
  }
  if (!finite(x)) throw NumericalFailure(n.steps, "state", who(s) + ": non-finite state at the end");
}

// GSL's rk8pd: stepped to T watching every accepted step, or to each output time watching it there.
void rk8pd(const BaselineSetup& s, const Counted& rhs, State& x, const BaselineObserver* observe, BaselineCount& n) {
  gsl_odeiv2_system gs{gsl_counted, nullptr, x.size(), const_cast<Counted*>(&rhs)};
  GslEvolve gsl(gsl_odeiv2_step_rk8pd, x.size(), s.abs_tol, s.rel_tol);
  double t = 0, dt = first_step(s);
  std::size_t k = 0;
  if (observe) (*observe)(k++, t, x.data());
  auto step_to = [&](double t1, double T) {
    interruption_point();  // here, not in gsl_counted: no exception through GSL's C frames
    if (gsl.apply(gs, t, t1, dt, x.data()) != GSL_SUCCESS || !finite(x))
      throw NumericalFailure(n.steps, "state", "GSL rk8pd could not take a step at t = " + show(t));
    check_adaptive_steps(++n.steps, t, T);
  };
  if (s.watch == BaselineWatch::steps) {
    for (long w = 1; w <= s.windows; ++w) {
      const double tb = w == s.windows ? s.T : s.T * static_cast<double>(w) / static_cast<double>(s.windows);
      while (t < tb) {
        step_to(tb, s.T);
        if (observe) (*observe)(k++, t, x.data());
      }
      if (window_end(s, w, n.steps, t, x)) gsl.reset();  // its step history is stale now
    }
    return;
  }
  const auto& ts = s.times;
  require(ts.size() >= 2, "a baseline watched at output times needs at least two of them");
  require(s.windows == 1, "a baseline watched at output times runs in one window");
  for (std::size_t i = 1; i < ts.size(); ++i)
    while (t < ts[i]) {
      step_to(ts[i], ts.back());
      if (t >= ts[i] && observe) (*observe)(i, t, x.data());
    }
}

}  // namespace

BaselineCount run_baseline(const BaselineSetup& s, const OdeRhs& f, std::vector<double> x, const BaselineObserver* observe) {
  check_baseline(s.name);
  require(s.windows >= 1, "a baseline runs in at least one window");
  BaselineCount n;
  const Counted rhs{&f, &n.calls};
  if (s.name == "odeint-rk4") {
    rk4(s, rhs, x, observe, n);
  } else if (s.name == "gsl-rk8pd") {
    rk8pd(s, rhs, x, observe, n);
  } else if (s.watch == BaselineWatch::outputs) {
    if (s.name == "odeint-dopri5")
      dense(s, odeint::make_dense_output(s.abs_tol, s.rel_tol, odeint::runge_kutta_dopri5<State>()), rhs, x, observe, n);
    else
      dense(s, odeint::bulirsch_stoer_dense_out<State>(s.abs_tol, s.rel_tol), rhs, x, observe, n);
  } else {
    if (s.name == "odeint-dopri5")
      controlled(s, odeint::make_controlled(s.abs_tol, s.rel_tol, odeint::runge_kutta_dopri5<State>()), rhs, x, observe, n);
    else
      controlled(s, odeint::bulirsch_stoer<State>(s.abs_tol, s.rel_tol), rhs, x, observe, n);
  }
  do_not_optimize(x[0]);
  return n;
}

}  // namespace geomint
