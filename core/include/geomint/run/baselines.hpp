#pragma once
// The baselines as methods: Odeint's classical rk4 (a fixed step h), Odeint's dopri5 and Bulirsch–Stoer and GSL's
// rk8pd (Prince–Dormand 8(9)) (adaptive, over a tolerance), each run by one call, run_baseline, on any equations
// x' = f(t, x) with one observer and the right-hand side's calls counted. A study names a baseline and watches it
// (the model: DiffEqDevTools' WorkPrecisionSet, where an adaptive method is one more entry solved by the same
// solve); it never drives an integrator itself.
//
// Each driver exists once, here. Two ways of ending an adaptive run watched at its steps are kept because the
// studies' tables depend on them to the bit: Odeint's integrate_adaptive, whose last step ends at t + (T - t), and
// try_step with the last step shortened to land on T exactly (a study that reads the state at t = T, or at the end
// of each of its windows).
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

namespace geomint {

// x' = f(t, x): writes dx (as many numbers as x).
using OdeRhs = std::function<void(double t, const double* x, double* dx)>;

// odeint-rk4, odeint-dopri5, odeint-bulirsch-stoer, gsl-rk8pd.
const std::vector<std::string>& baseline_names();
bool is_baseline(const std::string& name);
bool is_adaptive_baseline(const std::string& name);  // every one but odeint-rk4: swept over a tolerance
bool has_dense_output(const std::string& name);      // odeint-dopri5, odeint-bulirsch-stoer
// InputError naming the known ones.
void check_baseline(const std::string& name);

// Where a run is watched.
enum class BaselineWatch {
  steps,    // t = 0 and after every accepted step up to T (odeint-rk4: after every `every`-th step)
  outputs,  // at each of `times` (times[0] the start): dense output (dopri5, Bulirsch–Stoer), or stepped to each
            // time with the last step shortened (rk8pd); odeint-rk4 as for steps (its times are multiples of h)
};
// How an adaptive run watched at its steps ends (see above).
enum class BaselineEnd { integrate_adaptive, land };

struct BaselineSetup {
  std::string name;
  // odeint-rk4: `steps` steps of h from t = 0, watched at t = k every h
  double h = 0;
  long steps = 0;
  long every = 1;
  // the adaptive ones: Odeint's controlled steppers and GSL's control_y at (abs_tol, rel_tol)
  double abs_tol = 0, rel_tol = 0;
  BaselineWatch watch = BaselineWatch::steps;
  BaselineEnd end = BaselineEnd::integrate_adaptive;
  double T = 0;               // the end (watched at steps)
  std::vector<double> times;  // the output times (watched at outputs)
  double first_step = 0;      // the first trial step; 0: times[1] / 10 for dense output, 0.01 otherwise
  // Windows, for a study that acts on the state as it goes (renormalises a decaying linear state, restarts an
  // integral): the run stops at the end of window k = 1..windows (odeint-rk4: after steps k / windows steps; the
  // adaptive ones watched at steps with BaselineEnd::land: landing on T k / windows, the step size suggested before
  // the landing kept) and calls window_end(k, t, x) there, in timed runs too. It may change x and returns true when a
  // stepper's stored derivative (dopri5's first-same-as-last, GSL's history) no longer holds: the stepper restarts.
  long windows = 1;
  std::function<bool(long k, double t, double* x)> window_end;
  // Who a failure names ("Boost.Odeint" by default; a study may name its run).
  std::string label;
};

// What a run cost: accepted steps and evaluations of f.
struct BaselineCount {
  long steps = 0;
  long calls = 0;
};

// observe(k, t, x): k counts the observations from 0 (at an output time, its index).
using BaselineObserver = std::function<void(std::size_t k, double t, const double* x)>;

// Runs the baseline from x0 at t = 0. A state that stops being finite, a step GSL cannot take, a step size Odeint
// cannot find, or more steps than check_adaptive_steps allows is a NumericalFailure naming the step and t.
// observe may be null (a timed run: nothing watched).
BaselineCount run_baseline(const BaselineSetup& setup, const OdeRhs& f, std::vector<double> x0,
                           const BaselineObserver* observe);

}  // namespace geomint
