#pragma once
// The nonholonomic suite's verdict as data: for every problem (nonholonomic_suite.hpp) x scheme x h, a run over
// [0, T] with its error against the exact observables and, for every invariant, its secular drift measured on the
// run and predicted from the modified equation (invariant_drift.hpp), with the power of h each follows; and the
// invariants against time at one h, for the figures. The baselines (GSL's rk8pd by default) run through the same
// door as the schemes (run/method.hpp), over a tolerance, on the system's own equations: each scheme's run is set
// against what a baseline reaches at the same time, interpolated in log-log between its tolerances.
#include <string>
#include <vector>

#include "geomint/modified/invariant_drift.hpp"
#include "geomint/nonholonomic_suite.hpp"

namespace geomint::modified {

// Invariant k of a suite problem as an InvariantFunction (value and gradient in (t, q, q')).
InvariantFunction suite_invariant_function(const SuiteSystem& sys, std::size_t k);

struct SuiteStudyOptions {
  std::vector<std::string> problems;  // empty: every problem of the suite
  std::vector<std::string> schemes{"la", "contact", "la-midpoint", "la-trapezoid", "contact-trapezoid",
                                   "yoshida4:la-trapezoid"};
  std::vector<std::string> predict{"la", "contact"};  // the schemes whose drift the modified equation predicts
  std::vector<double> hs{0.04, 0.02, 0.01};
  double T = 200;      // horizon of every run (T/h steps)
  long kept = 4000;    // rows kept of each run (every T/(h kept)-th step)
  int K = 3;           // order of the modified equation
  double orbit_T = 200;  // the exact orbit the prediction averages over (Odeint, tol 1e-12, on a grid of orbit_dt)
  double orbit_dt = 0.05;
  long stride = 2;     // every stride-th orbit point
  long trace_points = 1000;  // rows of each trace (the middle h; at most the kept rows)
  std::string systems_dir = "docs/systems";
  std::vector<std::string> baselines{"gsl-rk8pd"};  // adaptive baselines of run/baselines.hpp
  std::vector<double> tols{1e-3, 1e-5, 1e-7, 1e-9, 1e-11, 1e-13};
  int reps = 3;        // the times: median of reps runs with nothing watched (after a warm-up), schemes and baselines
};

// A row is a scheme at step h, or a baseline at tolerance tol (then h is NaN and nothing is predicted).
struct SuiteRow {
  std::string problem, scheme, invariant;
  double h = 0;
  double tol = 0;            // NaN for a scheme
  long steps = 0;
  double error = 0;          // suite_error over the kept rows
  double offset = 0;         // I_0 - I(exact start)
  double max_deviation = 0;  // max_j |I_j - I_0|
  DriftRate measured, predicted;  // predicted: rate NaN where the scheme is not predicted
  double seconds = 0;        // time of the run (median of reps, nothing watched)
  // A scheme's row: what each baseline reaches in the same time (log-log between its tolerances; NaN below its
  // fastest run; beyond its slowest, what that run reached in less time), one entry per baseline in
  // SuiteStudyOptions::baselines order.
  std::vector<double> baseline_error, baseline_deviation;
};
struct SuiteFit {
  std::string problem, scheme, invariant;
  double power_measured = 0, power_predicted = 0;  // NaN where no rate stands above its spread
  double worst_ratio = 0;  // max over h of |predicted / measured - 1| (NaN where not predicted)
};
struct SuiteTrace {
  std::string problem, scheme, invariant;
  double h = 0;
  std::vector<double> t, deviation;  // I(t_j) - I(exact start)
};
struct SuiteStudy {
  std::vector<SuiteRow> rows;
  std::vector<SuiteFit> fits;
  std::vector<SuiteTrace> traces;
};

// Refuses bad options (unknown problems or schemes, h that does not divide T, kept rows out of range) before any
// work; a run that fails numerically becomes a row of missing values, said on stderr.
void check_suite_options(const SuiteStudyOptions& opt);
SuiteStudy nonholonomic_suite_study(const SuiteStudyOptions& opt);

}  // namespace geomint::modified
