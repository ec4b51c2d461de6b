// The nonholonomic benchmark suite (core/include/geomint/nonholonomic_suite.hpp): its closed forms and invariants
// against Boost.Odeint on each system file's own equations, every scheme's fitted order against the closed forms,
// the drift of an invariant predicted by the modified equation against the drift measured on a run, and GSL's rk8pd
// run through the one door against the same closed forms.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

#include "geomint/modified/formula_modified.hpp"
#include "geomint/modified/invariant_drift.hpp"
#include "geomint/modified/nonholonomic_suite_study.hpp"
#include "geomint/nonholonomic_suite.hpp"
#include "geomint/study.hpp"

using namespace geomint;

namespace {

const std::string systems_dir = std::string(GEOMINT_SOURCE_DIR) + "/docs/systems";

ParamValues with(ParamValues pv, const std::string& name, double value) {
  for (auto& [k, v] : pv)
    if (k == name) {
      v = value;
      return pv;
    }
  pv.emplace_back(name, value);
  return pv;
}

// max_j max_i |observable_i(t_j, q_j, v_j) - exact_i(t_j)| over rows of q and v on t_j = j h.
double observable_error(const SuiteSystem& s, const std::vector<double>& t, const std::vector<double>& q,
                        const std::vector<double>& v) {
  const int n = s.model->n;
  double e = 0;
  for (std::size_t j = 0; j < t.size(); ++j) {
    const auto obs = suite_observe(s, suite_state(t[j], &q[j * std::size_t(n)], &v[j * std::size_t(n)], n));
    const auto ex = suite_exact(s, t[j]);
    for (std::size_t i = 0; i < ex.size(); ++i) e = std::max(e, std::abs(obs[i] - ex[i]));
  }
  return e;
}

}  // namespace

TEST_CASE("suite: every closed form and invariant holds along Odeint on the system file's own equations",
          "[suite][exact]") {
  for (const auto& problem : suite_problems()) {
    const SuiteSystem s = load_suite_system(problem, systems_dir);
    const double T = 20, h = 0.01;
    const ParamValues pv = with(problem.params, "T", T);
    const Reference ref = s.info->reference(pv, h, step_count(h, T), ReferenceKind::odeint, 1e-12);
    std::vector<double> t;
    for (long j = 0; j <= ref.N; ++j) t.push_back(double(j) * h);
    const double err = observable_error(s, t, ref.q, ref.v);
    INFO(problem.name << ": closed form against Odeint (tol 1e-12) " << err);
    CHECK(err < 1e-8);
    const int n = s.model->n;
    for (std::size_t k = 0; k < problem.invariants.size(); ++k) {
      const double I0 = suite_invariant(s, k, suite_state(0, &ref.q[0], &ref.v[0], n));
      double drift = 0;
      for (long j = 0; j <= ref.N; ++j)
        drift = std::max(drift, std::abs(suite_invariant(s, k, suite_state(t[std::size_t(j)], &ref.q[std::size_t(j * n)],
                                                                               &ref.v[std::size_t(j * n)], n)) - I0));
      INFO(problem.name << ": invariant " << problem.invariants[k] << " = " << I0 << " changes by " << drift);
      CHECK(drift < 1e-8 * (1 + std::abs(I0)));
    }
    if (problem.file == "suslov") {  // the Euler-angle chart stays away from its singularity sin(theta) = 0
      double smin = 1;
      for (long j = 0; j <= ref.N; ++j) smin = std::min(smin, std::abs(std::sin(ref.q[std::size_t(j * n + 1)])));
      INFO("min |sin theta| " << smin);
      CHECK(smin > 0.9);
    }
  }
}

TEST_CASE("suite: the invariants' gradients are their derivatives", "[suite][exact]") {
  for (const auto& problem : suite_problems()) {
    const SuiteSystem s = load_suite_system(problem, systems_dir);
    SuiteState x{0.7, 0.3, -0.4, 0.9, 0.2, 0.5, -0.6, 0.8, 0.1};
    for (std::size_t k = 0; k < problem.invariants.size(); ++k) {
      SuiteState g{};
      suite_invariant(s, k, x, &g);
      for (std::size_t i = 0; i < x.size(); ++i) {
        const double d = 1e-6;
        SuiteState a = x, b = x;
        a[i] += d, b[i] -= d;
        const double fd = (suite_invariant(s, k, a) - suite_invariant(s, k, b)) / (2 * d);
        CHECK(std::abs(g[i] - fd) < 1e-8 * (1 + std::abs(fd)));
      }
    }
  }
}

// The error a convergence test fits: the position observables on the grid (suite_error); without any (Suslov),
// every observable at the midpoints t_{j+1/2} from the chord, q = (q_j + q_{j+1})/2, q' = (q_{j+1} - q_j)/h: second
// order at best, so it shows min(p, 2). (A scheme's own velocity, from p_j, is first order on these constrained
// systems whatever the scheme: suite_error says why.)
double convergence_error(const SuiteSystem& s, const Run& r, double h) {
  if (s.problem->positions > 0) return suite_error(s, r.t, r.q, r.v);
  const int n = s.model->n;
  double e = 0;
  for (std::size_t j = 0; j + 1 < r.t.size(); ++j) {
    double q[suite_max_dof], v[suite_max_dof];
    for (int i = 0; i < n; ++i) {
      q[i] = (r.q[j * std::size_t(n) + std::size_t(i)] + r.q[(j + 1) * std::size_t(n) + std::size_t(i)]) / 2;
      v[i] = (r.q[(j + 1) * std::size_t(n) + std::size_t(i)] - r.q[j * std::size_t(n) + std::size_t(i)]) / h;
    }
    const double t = (r.t[j] + r.t[j + 1]) / 2;
    const auto obs = suite_observe(s, suite_state(t, q, v, n));
    const auto ex = suite_exact(s, t);
    for (std::size_t i = 0; i < ex.size(); ++i) e = std::max(e, std::abs(obs[i] - ex[i]));
  }
  return e;
}

TEST_CASE("suite: every scheme and a composition converge at their order against the exact observables",
          "[suite][orders]") {
  for (const auto& problem : suite_problems()) {
    const SuiteSystem s = load_suite_system(problem, systems_dir);
    const double T = 4;
    const ParamValues pv = with(problem.params, "T", T);
    std::vector<std::string> schemes = s.info->scheme_names();
    schemes.push_back("yoshida4:la-trapezoid");
    for (const auto& scheme : schemes) {
      const int own = s.info->scheme(scheme).order,
                order = problem.positions > 0 ? std::max(own, problem.least_order) : std::min(own, 2);
      // the order-4 composition reaches round-off sooner: coarser steps
      const double h0 = own >= 4 ? 0.2 : 0.05;
      std::vector<double> hs, errs;
      for (int i = 0; i < 4; ++i) {
        const double h = h0 / double(1 << i);
        hs.push_back(h);
        errs.push_back(convergence_error(s, s.info->run(pv, scheme, h, Path::generic, 1), h));
      }
      const AsymptoticOrder fit = asymptotic_order(hs, errs, 0.15, 1e-12);
      INFO(problem.name << " " << scheme << ": errors " << errs[0] << " ... " << errs[3] << ", " << fit.describe());
      REQUIRE(fit.asymptotic());
      CHECK(std::abs(fit.slope - order) < 0.2);
    }
  }
}

TEST_CASE("suite: the drift of the energy on the non-reversible oscillator is the modified equation's, in rate and power",
          "[suite][drift]") {
  const SuiteSystem s = load_suite_system(find_suite_problem("nonreversible-oscillator"), systems_dir);
  const auto me = modified::formula_modified_system(s.model);
  const double T_orbit = 200, dt = 0.05;
  const Reference orbit = s.info->reference(with({}, "T", T_orbit), dt, step_count(dt, T_orbit), ReferenceKind::odeint, 1e-12);
  const auto H = modified::suite_invariant_function(s, 0);
  const double H0 = suite_invariant(s, 0, suite_state(0, &orbit.q[0], &orbit.v[0], 3));
  for (const char* scheme : {"la", "contact"}) {
    std::vector<double> hs;
    std::vector<modified::DriftRate> predicted, measured;
    for (double h : {0.05, 0.025}) {
      hs.push_back(h);
      predicted.push_back(modified::predicted_drift(*me, {}, scheme, 3, h, orbit, 8, {H}).front());
      measured.push_back(modified::measured_drift(*s.info, {}, scheme, h, T_orbit, 10, H, H0).slope);
      INFO(scheme << " h = " << h << ": predicted " << predicted.back().rate << " (spread " << predicted.back().spread
                  << "), measured " << measured.back().rate << " (spread " << measured.back().spread << ")");
      CHECK(std::abs(predicted.back().rate - measured.back().rate) < 0.1 * std::abs(measured.back().rate));
    }
    const double pp = modified::drift_power(hs, predicted), pm = modified::drift_power(hs, measured);
    INFO(scheme << ": power of h predicted " << pp << ", measured " << pm);
    CHECK(std::abs(pp - pm) < 0.2);
  }
}

TEST_CASE("suite: rk8pd through the door on the sleigh's exact solution, and set against a scheme at the same time",
          "[suite][baselines]") {
  modified::SuiteStudyOptions opt;
  opt.problems = {"sleigh"};
  opt.schemes = {"la-midpoint"};
  opt.predict = {};
  opt.hs = {0.04, 0.02};
  opt.T = 20;
  opt.kept = 200;
  opt.orbit_T = 1;
  opt.orbit_dt = 0.1;
  opt.tols = {1e-4, 1e-7, 1e-10};
  opt.reps = 1;
  opt.systems_dir = systems_dir;
  const auto study = modified::nonholonomic_suite_study(opt);
  std::vector<std::pair<double, double>> curve;  // (log seconds, log error) of rk8pd
  std::map<double, double> error_at_tol, deviation_at_tol;
  for (const auto& r : study.rows)
    if (r.scheme == "gsl-rk8pd") {
      REQUIRE(std::isfinite(r.seconds));
      curve.emplace_back(std::log(r.seconds), std::log(r.error));
      error_at_tol[r.tol] = r.error;
      deviation_at_tol[r.tol] = r.max_deviation;
    }
  REQUIRE(error_at_tol.size() == 3);
  // rk8pd's heading against the sleigh's closed form: the error control (relative and absolute tol per step) keeps
  // the global error within a small multiple of tol over T = 20 (measured: see INFO), and tightening the tolerance
  // by 1e6 gains at least 1e4 (the closed form is not rk8pd's own restatement: this fails if the door fed rk8pd other
  // equations or another start).
  INFO("rk8pd error at tol 1e-4, 1e-7, 1e-10: " << error_at_tol[1e-4] << ", " << error_at_tol[1e-7] << ", "
                                                 << error_at_tol[1e-10] << "; energy deviation at 1e-10: "
                                                 << deviation_at_tol[1e-10]);
  CHECK(error_at_tol[1e-10] < 1e-8);
  CHECK(error_at_tol[1e-4] > 1e4 * error_at_tol[1e-10]);
  CHECK(deviation_at_tol[1e-10] < 1e-8);
  // The scheme's rows carry rk8pd's error at the scheme's own time: log-log between rk8pd's points, missing below
  // the fastest, the slowest point's error beyond it.
  std::sort(curve.begin(), curve.end());
  int compared = 0;
  for (const auto& r : study.rows) {
    if (r.scheme != "la-midpoint") continue;
    REQUIRE(r.baseline_error.size() == 1);
    const double x = std::log(r.seconds);
    if (x < curve.front().first) {  // rk8pd never ran this fast
      CHECK(is_missing(r.baseline_error[0]));
      continue;
    }
    if (x >= curve.back().first) {  // what rk8pd's slowest run reached, in less time
      CHECK(std::abs(r.baseline_error[0] / std::exp(curve.back().second) - 1) < 1e-12);
      ++compared;
      continue;
    }
    std::size_t i = 1;
    while (curve[i].first < x) ++i;
    const double w = (x - curve[i - 1].first) / (curve[i].first - curve[i - 1].first);
    const double expected = std::exp(curve[i - 1].second + w * (curve[i].second - curve[i - 1].second));
    CHECK(std::abs(r.baseline_error[0] / expected - 1) < 1e-12);
    ++compared;
  }
  CHECK(compared >= 1);
}
