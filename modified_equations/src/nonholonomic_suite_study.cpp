// The nonholonomic suite's verdict as data (nonholonomic_suite_study.hpp).
#include "geomint/modified/nonholonomic_suite_study.hpp"

#include <algorithm>
#include <cmath>

#include "geomint/error.hpp"
#include "geomint/modified/formula_modified.hpp"
#include "geomint/record.hpp"
#include "geomint/run/baselines.hpp"
#include "geomint/run/method.hpp"

namespace geomint::modified {

InvariantFunction suite_invariant_function(const SuiteSystem& sys, std::size_t k) {
  return [&sys, k](double t, const double* q, const double* v, double* grad) {
    const int n = sys.model->n;
    const SuiteState x = suite_state(t, q, v, n);
    if (!grad) return suite_invariant(sys, k, x);
    SuiteState g{};
    const double value = suite_invariant(sys, k, x, &g);
    grad[0] = g[0];
    for (int i = 0; i < n; ++i) {
      grad[1 + i] = g[std::size_t(1 + i)];
      grad[1 + n + i] = g[std::size_t(1 + n + i)];
    }
    return value;
  };
}

namespace {

std::vector<const SuiteProblem*> chosen(const SuiteStudyOptions& opt) {
  std::vector<const SuiteProblem*> out;
  if (opt.problems.empty())
    for (const auto& p : suite_problems()) out.push_back(&p);
  else
    for (const auto& name : opt.problems) out.push_back(&find_suite_problem(name));
  return out;
}

ParamValues with_T(ParamValues pv, double T) {
  for (auto& [k, v] : pv)
    if (k == "T") {
      v = T;
      return pv;
    }
  pv.emplace_back("T", T);
  return pv;
}

// y at x on the piecewise-linear curve through (log x_i, log y_i), the points sorted by x. Below the fastest point:
// NaN (the baseline never ran that fast). Beyond the slowest: the slowest point's y, what the baseline reached in
// less time than x (its tightest tolerance; more time would only lower it) — a bound, never an extrapolation.
double loglog_at(std::vector<std::pair<double, double>> pts, double x) {
  std::vector<std::pair<double, double>> ok;
  for (const auto& [a, b] : pts)
    if (std::isfinite(a) && std::isfinite(b) && a > 0) ok.emplace_back(std::log(a), std::log(std::max(b, 1e-300)));
  std::sort(ok.begin(), ok.end());
  if (ok.size() < 2 || !(x > 0)) return missing_value;
  const double lx = std::log(x);
  if (lx < ok.front().first) return missing_value;
  if (lx >= ok.back().first) return std::exp(ok.back().second);
  for (std::size_t i = 1; i < ok.size(); ++i)
    if (lx <= ok[i].first) {
      const double w = ok[i].first > ok[i - 1].first ? (lx - ok[i - 1].first) / (ok[i].first - ok[i - 1].first) : 1.0;
      return std::exp(ok[i - 1].second + w * (ok[i].second - ok[i - 1].second));
    }
  return missing_value;
}

// One baseline's runs over the tolerances: (seconds, error) and, per invariant, (seconds, max deviation).
// A row of a run before its measures: a scheme's at step h (tol NaN) or a baseline's at tol (h NaN).
SuiteRow run_row(const std::string& problem, const std::string& method, const std::string& invariant, double h,
                 double tol, long steps, double error, double seconds) {
  SuiteRow row;
  row.problem = problem;
  row.scheme = method;
  row.invariant = invariant;
  row.h = h;
  row.tol = tol;
  row.steps = steps;
  row.error = error;
  row.seconds = seconds;
  row.measured = row.predicted = {missing_value, missing_value, 0};
  row.offset = row.max_deviation = missing_value;
  return row;
}

struct BaselineCurve {
  std::vector<std::pair<double, double>> error;
  std::vector<std::vector<std::pair<double, double>>> deviation;
};

}  // namespace

void check_suite_options(const SuiteStudyOptions& opt) {
  require(!opt.schemes.empty(), "give at least one scheme");
  require(opt.hs.size() >= 2, "give at least two step sizes (the power of h is fitted over them)");
  require(std::isfinite(opt.T) && opt.T > 0, "T must be positive");
  require(opt.kept >= 16 && opt.kept <= 1000000, "kept must be in [16, 1e6]");
  require(opt.K >= 1 && opt.K <= registry_max_order, "K must be in [1, " + std::to_string(registry_max_order) + "]");
  require(std::isfinite(opt.orbit_T) && opt.orbit_T > 0, "orbit-T must be positive");
  require(std::isfinite(opt.orbit_dt) && opt.orbit_dt > 0 && opt.orbit_dt <= opt.orbit_T, "orbit-dt must be in (0, orbit-T]");
  require(opt.stride >= 1, "stride must be >= 1");
  require(opt.trace_points >= 2, "trace-points must be at least 2");
  require(opt.reps >= 1, "reps must be at least 1");
  for (const auto& b : opt.baselines) {
    check_baseline(b);
    require(is_adaptive_baseline(b), "baseline " + b + " has a fixed step: give an adaptive one (its tolerance is swept)");
  }
  require(opt.baselines.empty() || opt.tols.size() >= 2, "give at least two tolerances (a baseline is interpolated between them)");
  for (double tol : opt.tols) require(std::isfinite(tol) && tol > 0 && tol < 1, "every tolerance must be in (0, 1)");
  for (double h : opt.hs) {
    require(std::isfinite(h) && h > 0, "every h must be positive");
    const long N = step_count(h, opt.T);  // InputError when h does not divide T
    require(N >= opt.kept, "T/h must be at least kept (h = " + format_number(h) + ")");
  }
  step_count(opt.orbit_dt, opt.orbit_T);
  for (const auto* p : chosen(opt)) {
    const SuiteSystem s = load_suite_system(*p, opt.systems_dir);
    for (const auto& x : opt.schemes) s.info->scheme(x);  // InputError naming the known ones
    for (const auto& x : opt.predict) modified_scheme(*s.info, x);
  }
}

SuiteStudy nonholonomic_suite_study(const SuiteStudyOptions& opt) {
  check_suite_options(opt);
  SuiteStudy study;
  const std::size_t mid = opt.hs.size() / 2;
  for (const auto* problem : chosen(opt)) {
    const SuiteSystem s = load_suite_system(*problem, opt.systems_dir);
    const auto me = formula_modified_system(s.model);
    const int n = s.model->n;
    const ParamValues pv = problem->params;
    const Reference orbit = s.info->reference(with_T(pv, opt.orbit_T), opt.orbit_dt, step_count(opt.orbit_dt, opt.orbit_T),
                                              ReferenceKind::odeint, 1e-12);
    std::vector<InvariantFunction> invariants;
    std::vector<double> exact_start;
    for (std::size_t k = 0; k < problem->invariants.size(); ++k) {
      invariants.push_back(suite_invariant_function(s, k));
      exact_start.push_back(invariants.back()(0, &orbit.q[0], &orbit.v[0], nullptr));
    }
    const ParamValues pv_T = with_T(pv, opt.T);
    MethodOptions mo;
    mo.path = Path::generic;
    std::vector<BaselineCurve> curves;
    for (const auto& name : opt.baselines) {
      const Method m = find_method(*s.info, name);
      BaselineCurve curve;
      curve.deviation.resize(invariants.size());
      for (double tol : opt.tols) {
        Run run;
        run.n = n;
        double seconds = missing_value;
        const std::string context = problem->name + " " + name + " tol = " + format_number(tol);
        try {
          const MethodWork w = run_method(*s.info, pv_T, m, tol, mo, [&](double t, const double* q, const double* v) {
            run.t.push_back(t);
            run.q.insert(run.q.end(), q, q + n);
            run.v.insert(run.v.end(), v, v + n);
          });
          run.steps = w.steps;
          seconds = time_method(*s.info, pv_T, m, tol, mo, opt.reps).median;
        } catch (const NumericalFailure& e) {
          report_missing(context, e.what());
          run = Run{};
        }
        const double error = run.t.empty() ? missing_value : suite_error(s, run.t, run.q, run.v);
        curve.error.emplace_back(seconds, error);
        for (std::size_t k = 0; k < invariants.size(); ++k) {
          SuiteRow row = run_row(problem->name, name, problem->invariants[k], missing_value, tol, run.steps, error, seconds);
          if (run.t.size() >= 8) {
            const MeasuredDrift d = measured_drift(run, invariants[k], exact_start[k]);
            row.measured = d.slope;
            row.offset = d.offset;
            row.max_deviation = d.max_deviation;
          }
          curve.deviation[k].emplace_back(seconds, row.max_deviation);
          study.rows.push_back(row);
        }
      }
      curves.push_back(std::move(curve));
    }
    for (const auto& scheme : opt.schemes) {
      const bool predicted = std::find(opt.predict.begin(), opt.predict.end(), scheme) != opt.predict.end();
      std::vector<std::vector<DriftRate>> measured(invariants.size()), predictions(invariants.size());
      for (std::size_t hi = 0; hi < opt.hs.size(); ++hi) {
        const double h = opt.hs[hi];
        const long N = step_count(h, opt.T), every = std::max(1L, N / opt.kept);
        const std::string context = problem->name + " " + scheme + " h = " + format_number(h);
        Run run;
        double seconds = missing_value;
        try {
          run = s.info->run(pv_T, scheme, h, Path::generic, every);
          seconds = time_method(*s.info, pv_T, find_method(*s.info, scheme), h, mo, opt.reps).median;
        } catch (const NumericalFailure& e) {
          report_missing(context, e.what());
        }
        const double error = run.t.empty() ? missing_value : suite_error(s, run.t, run.q, run.v);
        std::vector<DriftRate> pred(invariants.size(), DriftRate{missing_value, missing_value, 0});
        if (predicted) try {
            pred = predicted_drift(*me, pv, scheme, opt.K, h, orbit, opt.stride, invariants);
          } catch (const NumericalFailure& e) {
            report_missing(context + " (prediction)", e.what());
          }
        for (std::size_t k = 0; k < invariants.size(); ++k) {
          SuiteRow row = run_row(problem->name, scheme, problem->invariants[k], h, missing_value, N, error, seconds);
          if (!run.t.empty()) {
            const MeasuredDrift d = measured_drift(run, invariants[k], exact_start[k]);
            row.measured = d.slope;
            row.offset = d.offset;
            row.max_deviation = d.max_deviation;
            if (hi == mid) {
              SuiteTrace tr{problem->name, scheme, problem->invariants[k], h, {}, {}};
              const std::size_t step = std::max<std::size_t>(1, run.t.size() / std::size_t(opt.trace_points));
              for (std::size_t j = 0; j < run.t.size(); j += step) {
                tr.t.push_back(run.t[j]);
                tr.deviation.push_back(invariants[k](run.t[j], &run.q[j * std::size_t(n)], &run.v[j * std::size_t(n)], nullptr) -
                                       exact_start[k]);
              }
              study.traces.push_back(std::move(tr));
            }
          }
          row.predicted = pred[k];
          for (const auto& c : curves) {
            row.baseline_error.push_back(loglog_at(c.error, seconds));
            row.baseline_deviation.push_back(loglog_at(c.deviation[k], seconds));
          }
          measured[k].push_back(row.measured);
          predictions[k].push_back(row.predicted);
          study.rows.push_back(row);
        }
      }
      for (std::size_t k = 0; k < invariants.size(); ++k) {
        SuiteFit f{problem->name, scheme, problem->invariants[k], drift_power(opt.hs, measured[k]), missing_value,
                   missing_value};
        if (predicted) {
          f.power_predicted = drift_power(opt.hs, predictions[k]);
          f.worst_ratio = 0;
          for (std::size_t i = 0; i < opt.hs.size(); ++i)
            f.worst_ratio = std::max(f.worst_ratio, std::abs(predictions[k][i].rate / measured[k][i].rate - 1));
        }
        study.fits.push_back(f);
      }
    }
  }
  return study;
}

}  // namespace geomint::modified
