#pragma once
// Work–precision and long-horizon studies as data (the model: DiffEqDevTools' WorkPrecisionSet): one point per
// (method, knob value) with the errors the study measures, the steps, and the CPU time; a failure is a missing
// point (NaN errors and times) with its message. And what a set of points is summarised by: the CPU time each
// method needs to reach a target error, the best geometric scheme against the best adaptive method, the horizon
// from which the geometric scheme is cheaper, and the slope of log(error) against log(CPU time).
// Timings are medians of repeats after a warm-up (timing.hpp): never bit-reproducible, never in a test.
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <boost/numeric/odeint/util/odeint_error.hpp>

#include "geomint/error.hpp"
#include "geomint/record.hpp"
#include "geomint/registry.hpp"
#include "geomint/timing.hpp"

namespace geomint {

struct WorkPoint {
  static constexpr double nan = missing_value;
  std::string method;   // a scheme (as asked) or a baseline ("odeint-dopri5", ...)
  std::string family;   // "geometric" (a scheme), "rk" (a fixed-step baseline), "adaptive" (a tolerance)
  std::string knob;     // "h" or "tol"
  double group = nan;   // the study's grouping parameter (e.g. alpha); NaN if none
  double horizon = nan; // the horizon (T or periods); NaN if one
  double value = nan;   // h or the tolerance
  long steps = 0;
  std::vector<double> errors;          // the study's measures, in its order
  TimingStats time{nan, nan, nan, 0};  // CPU seconds per run
  std::string failure;                 // why the point is missing ("" when it is not)
};

// A point before it is measured: the method, its family and knob, the knob's value, and the study's group and
// horizon (NaN where the study has none).
inline WorkPoint work_point(std::string method, std::string family, std::string knob, double value,
                            double group = WorkPoint::nan, double horizon = WorkPoint::nan) {
  WorkPoint p;
  p.method = std::move(method);
  p.family = std::move(family);
  p.knob = std::move(knob);
  p.value = value;
  p.group = group;
  p.horizon = horizon;
  return p;
}

// What a measured run returns: its errors (in the study's order) and its step count.
struct Measured {
  std::vector<double> errors;
  long steps = 0;
};

// Fills p's errors and steps from measure() and its time from time() (TimingStats). A NumericalFailure, an Odeint
// failure or a domain error makes the point missing (n_errors NaN errors, NaN times, `reps` repeats), reported on
// stderr with `context`.
template <class Measure, class Time>
WorkPoint measure_point_timed(WorkPoint p, std::size_t n_errors, Measure&& measure, Time&& time, int reps,
                              const std::string& context) {
  auto fail = [&](const std::string& what) {
    report_missing(context, what);
    p.failure = what;
    p.errors.assign(n_errors, WorkPoint::nan);
    p.time = {WorkPoint::nan, WorkPoint::nan, WorkPoint::nan, reps};
  };
  try {
    const Measured m = measure();
    p.errors = m.errors;
    p.steps = m.steps;
    p.time = time();
  } catch (const NumericalFailure& e) {
    fail(e.what());
  } catch (const boost::numeric::odeint::odeint_error& e) {
    fail(std::string("Odeint: ") + e.what());
  } catch (const std::domain_error& e) {
    fail(e.what());
  }
  return p;
}

// The same where one function does both: run(true) measures, run(false) repeats the same work with nothing
// measured (timed: warm-up, then the median of `reps`).
template <class Run>
WorkPoint measure_point(WorkPoint p, std::size_t n_errors, Run&& run, int reps, const std::string& context) {
  return measure_point_timed(
      std::move(p), n_errors, [&] { return run(true); },
      [&] { return time_per_call([&] { do_not_optimize(run(false).steps); }, reps); }, reps, context);
}

// A measure of a study, the error the summary asks each method to reach, and the floor below which an error is the
// reference's (fit_band, study.hpp): the slope against CPU time is fitted above it only.
struct WorkMeasure {
  std::string column, label;
  double target;
  double floor = 1e-15;
};

// One line of a summary: kind is "seconds_to_target" (method's cheapest time to reach the target; NaN: never),
// "geometric_over_adaptive" (the ratio of the best of each family), "crossover" (the shortest horizon from which
// on, at it and every longer one, the best geometric scheme is cheaper than the best adaptive method; NaN: none)
// or "slope_vs_cpu_time" (the fitted d log(error) / d log(time) over the method's points above the measure's floor;
// NaN with fewer than three there).
struct WorkSummaryRow {
  std::string kind, measure;
  double target, group, horizon;  // horizon NaN for a crossover
  std::string method;             // "-" for the family ratio and the crossover
  double value;
};

// The summary of a set of points, measure by measure (rows in the order: times to target and ratios per
// (measure, group, horizon), crossovers per (measure, group), slopes per (horizon, group, method, measure)).
// Groups in first-seen order, horizons ascending, methods in first-seen order.
std::vector<WorkSummaryRow> summarise_work(const std::vector<WorkPoint>& points, const std::vector<WorkMeasure>& measures);

// The distinct methods, groups and horizons of a set (first-seen order; horizons ascending).
std::vector<std::string> work_methods(const std::vector<WorkPoint>& points);
std::vector<double> work_groups(const std::vector<WorkPoint>& points);
std::vector<double> work_horizons(const std::vector<WorkPoint>& points);

// The cheapest time of `method` at (group, horizon) whose error `measure` is <= target; INFINITY when none.
double time_to_target(const std::vector<WorkPoint>& points, const std::string& method, double group, double horizon,
                      std::size_t measure, double target);

// ---------------------------------------------------------------------------------------------------------------
// The work–precision study of any system: max_j |q(t_j) - q_ref(t_j)| against CPU time.

// What a study runs. Fixed-step methods (the system's schemes, Odeint's rk4) are swept over h, adaptive ones over
// the tolerance (rel = abs = tol). The reference is the system's (closed form, else Odeint at reference_tol; or
// the kind asked) on the finest h.
struct WorkPrecisionOptions {
  std::vector<std::string> schemes;    // the system's schemes or compositions, by name
  std::vector<double> hs;              // the fixed-step methods' steps (each divides T, each a multiple of the finest)
  std::vector<std::string> baselines;  // of work_precision_baselines()
  std::vector<double> tols;            // the adaptive baselines' tolerances
  Path path = Path::fast;
  ErrorNorm norm = ErrorNorm::max;
  // The baselines integrate x = (q, q') with the system's hand-written acceleration (what a hand-coded baseline
  // costs) instead of the one derived from L, F and Phi by AD.
  bool hand_written = false;
  // An adaptive method's error at the steps it chose, against the closed form there (no output grid caps its
  // step size; needs a closed form), instead of at dense output on the grid of the largest h.
  bool at_steps = false;
  int reps = 5;
  ReferenceKind reference = ReferenceKind::automatic;  // on the finest h
  double reference_tol = 1e-13;
  // > 0: every point also gets a relative error, max_k |q(t_k) - q_ref(t_k)| / A_k on the grid t_k = k h-max, where
  // A_k is the largest |q_ref| over [t_k - relative_window, t_k]. On a system that damps out, the error in q is set
  // in its first periods whatever the horizon; this one measures how a method follows the solution at the size it
  // has by then (a decay rate off by d shows as d t). Where A_k is below relative_size_floor, t_k is not counted.
  // Needs the output grid (not at_steps).
  double relative_window = 0;
  // Quantities measured along every run besides q, each as max_k |Q(t_k, q_k, q'_k) - Q(t_k, q_ref(t_k), q'_ref(t_k))|
  // on the output grid t_k = t0 + k h-max (state_measures): "energy", "p<i>" (the momentum dL/dq'_i), or
  // "<name>=<formula>" in t, q1.., v1.. and the system's parameters. Each is a column <name>_err after the errors
  // in q. Needs the output grid (not at_steps).
  std::vector<std::string> measures;
};

// A quantity of WorkPrecisionOptions::measures: its column and what it is, for a table's header.
struct StateMeasure {
  std::string column, doc;
};
// The measures `specs` name on `sys` (a formula checked at the system's defaults): InputError for an unknown kind,
// a momentum the system has not, a formula that does not parse, a name given twice or one of the study's own.
std::vector<StateMeasure> state_measures(const SystemInfo& sys, const std::vector<std::string>& specs);

// Where the relative error stops being measurable: A_k < 1e-280 against a closed form (a double keeps no relative
// accuracy below), A_k < 1e8 reference_tol against Odeint (its tolerance is absolute too: near it the reference has
// no relative accuracy left; above the floor its error is at most about 1e-8 of the solution's size, measured: with
// a factor 1e6 every method's err_rel on the pendulum at T = 2000 stopped at the same 4.9e-6).
double relative_size_floor(const SystemInfo& sys, const WorkPrecisionOptions& opt);

// odeint-rk4 (over h), odeint-dopri5, odeint-bulirsch-stoer and gsl-rk8pd (over tol; GSL's has no dense output:
// on the output grid it is stepped to each output time, its last step there shortened).
const std::vector<std::string>& work_precision_baselines();

struct WorkPrecisionStudy {
  std::string reference;         // what the errors are measured against (Reference::kind)
  double floor = 1e-13;          // the errors it resolves: above round-off (a closed form), or 100 times its tolerance
  // errors = {the max error} (and the relative error with relative_window, then one per measure); group = the index of
  // the combination
  std::vector<WorkPoint> points;
};

// Refuses what the study cannot run (unknown baselines, no closed form for at_steps, ...) and plans its work
// (plan_steps, memory), before anything is written.
void check_work_precision(const SystemInfo& sys, const std::vector<ParamValues>& combos, const WorkPrecisionOptions& opt);
// Every point of every combination: schemes over h, then rk4 over h, then the adaptive baselines over tol. A run
// that fails is a missing point named on stderr.
WorkPrecisionStudy work_precision_study(const SystemInfo& sys, const std::vector<ParamValues>& combos,
                                        const WorkPrecisionOptions& opt);

}  // namespace geomint
