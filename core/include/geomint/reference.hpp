#pragma once
// High-accuracy reference solutions with Boost.Odeint: dense output of an adaptive Dormand–Prince
// stepper, so every requested time t_j = j h is hit exactly (not by accumulating t += h).
#include <algorithm>
#include <array>
#include <string>
#include <vector>

#include <boost/numeric/odeint.hpp>

#include "geomint/error.hpp"

namespace geomint {

// An adaptive explicit reference takes a handful of steps between two output times on a nonstiff problem; a stiff
// one (a damping of 1e15) would take about alpha T steps, for hours. Past this many it stops with a numerical failure.
inline constexpr int odeint_max_steps_between_outputs = 1000000;

// An explicit integrator stopped by a step limit: "<what> by t = <t>: the equations are too stiff ...".
[[noreturn]] inline void throw_too_stiff(long where, const std::string& quantity, const std::string& what, double t) {
  throw NumericalFailure(where, quantity,
                         what + " by t = " + show(t) + ": the equations are too stiff for an explicit integrator at "
                                                       "these parameters");
}
[[noreturn]] inline void throw_too_stiff(const std::string& method, double t, std::size_t outputs) {
  throw_too_stiff(static_cast<long>(outputs), "reference",
                  method + " took more than " + std::to_string(odeint_max_steps_between_outputs) +
                      " steps between two output times",
                  t);
}

// An adaptive explicit method takes well under 1e3 steps per unit time on the problems here at any tolerance; a
// stiff one (a damping of 1e15) would take about alpha T steps, for hours. Past this many it stops with a numerical
// failure: 1e6 steps, plus 1e5 per unit time (100 times the most a tight nonstiff run takes).
inline long adaptive_step_limit(double T) { return 1000000 + static_cast<long>(std::min(1e5 * T, 1e15)); }
inline void check_adaptive_steps(long steps, double t, double T) {
  if (steps > adaptive_step_limit(T))
    throw_too_stiff(steps, "step size", "more than " + show(static_cast<double>(adaptive_step_limit(T))) + " adaptive steps", t);
}

// Integrates x' = sys(x, t) from times.front() and returns the state at every entry of `times`.
template <std::size_t N, class System>
std::vector<std::array<double, N>> odeint_dense(System sys, std::array<double, N> x0, const std::vector<double>& times,
                                                double tol = 1e-13) {
  namespace odeint = boost::numeric::odeint;
  using State = std::array<double, N>;
  require(!times.empty(), "odeint_dense: no output times");
  std::vector<State> out;
  out.reserve(times.size());
  auto stepper = odeint::make_dense_output(tol, tol, odeint::runge_kutta_dopri5<State>());
  const double dt0 = times.size() > 1 ? (times[1] - times[0]) / 10 : 1e-3;
  try {
    odeint::integrate_times(stepper, sys, x0, times.begin(), times.end(), dt0,
                            [&](const State& x, double) { out.push_back(x); },
                            odeint::max_step_checker(odeint_max_steps_between_outputs));
  } catch (const odeint::no_progress_error&) {
    throw_too_stiff("Boost.Odeint dopri5", out.empty() ? times.front() : times[out.size() - 1], out.size());
  }
  return out;
}

// The damped oscillator q'' = -q - alpha q' as a first-order system in (q, p).
inline std::vector<std::array<double, 2>> oscillator_odeint(double alpha, double q0, double p0,
                                                            const std::vector<double>& times, double tol = 1e-13) {
  return odeint_dense<2>(
      [alpha](const std::array<double, 2>& x, std::array<double, 2>& dx, double) {
        dx[0] = x[1];
        dx[1] = -x[0] - alpha * x[1];
      },
      {q0, p0}, times, tol);
}

}  // namespace geomint
