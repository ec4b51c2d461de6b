// The work–precision study (work_precision.hpp): every scheme of a system over h and Boost.Odeint / GSL
// baselines over h or tolerance, each point's error against one reference and its CPU time.
#include <algorithm>
#include <deque>
#include <optional>
#include <cmath>
#include <cstdio>
#include <functional>

#include <boost/numeric/odeint.hpp>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include "geomint/budget.hpp"
#include "geomint/error.hpp"
#include "geomint/gsl_evolve.hpp"
#include "geomint/io.hpp"
#include "geomint/reference.hpp"
#include "geomint/step_cost.hpp"
#include "geomint/study.hpp"
#include "geomint/work_precision.hpp"

namespace geomint {

namespace odeint = boost::numeric::odeint;

const std::vector<std::string>& work_precision_baselines() {
  static const std::vector<std::string> names{"odeint-rk4", "odeint-dopri5", "odeint-bulirsch-stoer", "gsl-rk8pd"};
  return names;
}

namespace {

using State = std::vector<double>;
using Rhs = std::function<void(double, const double*, double*)>;

bool adaptive(const std::string& baseline) { return baseline != "odeint-rk4"; }

// The error of a state's positions against reference positions r (n of them) in `norm`.
double distance(const double* x, const double* r, int n, ErrorNorm norm) {
  double e = 0;
  for (int i = 0; i < n; ++i)
    e = norm == ErrorNorm::max ? std::max(e, std::abs(x[i] - r[i])) : std::hypot(e, x[i] - r[i]);
  return e;
}

// fine divides coarse a whole number of times (h-max by an h of the study); InputError otherwise.
long ratio_of(double coarse, double fine) {
  const double ratio = coarse / fine;
  const long k = std::lround(ratio);
  require(k >= 1 && std::abs(ratio - static_cast<double>(k)) <= 1e-9 * ratio,
          "h = " + show(fine) + " does not divide h-max = " + show(coarse) + " (the relative error's output grid)");
  return k;
}

}  // namespace

double relative_size_floor(const SystemInfo& sys, const WorkPrecisionOptions& opt) {
  const bool exact = opt.reference == ReferenceKind::exact || (opt.reference == ReferenceKind::automatic && sys.has_exact);
  return exact ? 1e-280 : 1e8 * opt.reference_tol;
}

namespace {

int gsl_rhs(double t, const double y[], double f[], void* params) {
  (*static_cast<const Rhs*>(params))(t, y, f);
  return GSL_SUCCESS;
}

// One combination of parameters: its equations, reference and every point.
struct Combination {
  const SystemInfo& sys;
  const ParamValues& pv;
  const WorkPrecisionOptions& opt;
  double group;
  double T;
  int n;
  Rhs f;
  State x0;
  Reference ref;
  // The reference's failure (e.g. a closed form that overflows at these parameters): every point that reads the
  // reference is missing and says why; the others run.
  std::optional<NumericalFailure> ref_failure;
  void need_reference() const {
    if (ref_failure) throw *ref_failure;
  }

  // The relative error (WorkPrecisionOptions::relative_window): A_k, the largest |q_ref| over the window that ends
  // at t_k = k h_out, on the output grid; empty without the option.
  double h_out;               // the largest h
  std::vector<double> size;  // filled by size_reference
  double size_floor = 0;     // below it t_k is not counted
  bool relative() const { return opt.relative_window > 0; }
  std::size_t n_errors() const { return relative() ? 2 : 1; }
  void size_reference() {
    if (!relative() || ref_failure) return;
    size_floor = relative_size_floor(sys, opt);
    const long N_out = step_count(h_out, T), stride = ref.index(1, h_out);
    const long w = static_cast<long>(std::floor(opt.relative_window / ref.h + 1e-9));
    const std::vector<double> zero(static_cast<std::size_t>(n), 0.0);
    std::vector<double> r(static_cast<std::size_t>(ref.N + 1));
    for (std::size_t i = 0; i < r.size(); ++i) r[i] = distance(&ref.q[i * static_cast<std::size_t>(n)], zero.data(), n, opt.norm);
    size.assign(static_cast<std::size_t>(N_out + 1), 0);
    std::deque<long> window;  // indices of the window's decreasing maxima: a sliding maximum in O(N)
    for (long i = 0, k = 0; k <= N_out; ++i) {
      while (!window.empty() && r[static_cast<std::size_t>(window.back())] <= r[static_cast<std::size_t>(i)]) window.pop_back();
      window.push_back(i);
      if (i != k * stride) continue;
      while (window.front() < i - w) window.pop_front();
      size[static_cast<std::size_t>(k++)] = r[static_cast<std::size_t>(window.front())];
    }
  }
  // The relative error along one run, fed the positions at output k.
  struct Relative {
    const Combination& c;
    double worst = 0;
    long counted = 0;
    void add(long k, const double* q) {
      const double a = c.size[static_cast<std::size_t>(k)];
      if (!(a >= c.size_floor)) return;
      const long i = c.ref.index(k, c.h_out);
      const double d = distance(q, &c.ref.q[static_cast<std::size_t>(i * c.n)], c.n, c.opt.norm) / a;
      if (!std::isfinite(d))
        throw NumericalFailure(k, "relative error", "q is not finite at t = " + show(static_cast<double>(k) * c.h_out));
      worst = std::max(worst, d);
      ++counted;
    }
    double value() const { return counted ? worst : missing_value; }
  };
  // {the max error} or {the max error, the relative error}
  std::vector<double> errors(double err, const Relative* rel) const {
    if (!relative()) return {err};
    return {err, rel->value()};
  }

  std::string where(const std::string& method, const char* knob, double value) const {
    std::string s = sys.name + " " + method;
    for (const auto& [k, v] : pv) s += " " + k + "=" + show(v);
    return s + " " + knob + "=" + show(value);
  }

  WorkPoint scheme(const std::string& name, double h) const {
    const long N = step_count(h, T);
    WorkPoint p = work_point(name, "geometric", "h", h, group);
    p.steps = N;  // known before the run: it stays in the table where the run fails
    return measure_point_timed(
        p, n_errors(),
        [&] {
          need_reference();
          const double err = sys.measure_run(pv, name, h, opt.path, ref, opt.norm).front();
          if (!relative()) return Measured{{err}, N};
          const long every = ratio_of(h_out, h);
          const Run r = sys.run(pv, name, h, opt.path, every);  // q at t_k = k h_out (j = k every)
          Relative rel{*this};
          for (std::size_t k = 0; k < r.j.size(); ++k) rel.add(r.j[k] / every, &r.q[k * static_cast<std::size_t>(n)]);
          return Measured{errors(err, &rel), N};
        },
        [&] { return sys.time_run(pv, name, h, opt.path, opt.reps); }, opt.reps, where(name, "h", h));
  }

  WorkPoint rk4(double h) const {
    const long N = step_count(h, T);
    const long stride = ref_failure ? 1 : ref.index(1, h);
    auto rhs = [&](const State& x, State& dx, double t) { f(t, x.data(), dx.data()); };
    const long every = relative() ? ratio_of(h_out, h) : 1;
    auto run = [&](double* err, Relative* rel) {
      odeint::runge_kutta4<State> st;
      State x = x0;
      if (rel) rel->add(0, x.data());
      for (long j = 0; j < N; ++j) {
        st.do_step(rhs, x, static_cast<double>(j) * h, h);
        if (err)
          *err = std::max(*err, distance(x.data(), &ref.q[static_cast<std::size_t>((j + 1) * stride * n)], n, opt.norm));
        if (rel && (j + 1) % every == 0) rel->add((j + 1) / every, x.data());
      }
      do_not_optimize(x[0]);
    };
    WorkPoint p = work_point("odeint-rk4", "rk", "h", h, group);
    p.steps = N;
    return measure_point_timed(
        p, n_errors(),
        [&] {
          need_reference();
          double err = 0;
          Relative rel{*this};
          run(&err, relative() ? &rel : nullptr);
          return Measured{errors(err, &rel), N};
        },
        [&] { return time_per_call([&] { run(nullptr, nullptr); }, opt.reps); }, opt.reps, where("odeint-rk4", "h", h));
  }

  // An adaptive method's error at the steps it chose, against the closed form there: no output grid caps its
  // step size. observe(t, x) is called at t = 0 and after every accepted step.
  template <class Integrate>
  WorkPoint at_steps(const std::string& name, double tol, Integrate&& integrate) const {
    auto measure = [&] {
      std::vector<double> ts, qs;
      const long steps = integrate([&](double t, const double* x) {
        ts.push_back(t);
        qs.insert(qs.end(), x, x + n);
      });
      const std::vector<double> exact = sys.exact_positions(pv, ts);
      double err = 0;
      for (std::size_t k = 0; k < ts.size(); ++k)
        err = std::max(err, distance(&qs[k * static_cast<std::size_t>(n)], &exact[k * static_cast<std::size_t>(n)], n, opt.norm));
      return Measured{{err}, steps};
    };
    return measure_point_timed(
        work_point(name, "adaptive", "tol", tol, group), 1, measure,
        [&] { return time_per_call([&] { do_not_optimize(integrate([](double, const double*) {})); }, opt.reps); },
        opt.reps, where(name, "tol", tol));
  }

  // An adaptive method's error by dense output on the grid of the largest h, against the reference there.
  template <class MakeStepper>
  WorkPoint at_output(const std::string& name, double tol, MakeStepper&& make) const {
    const long N_out = step_count(h_out, T), stride = ref_failure ? 1 : ref.index(1, h_out);
    std::vector<double> times(static_cast<std::size_t>(N_out + 1));
    for (long j = 0; j <= N_out; ++j) times[static_cast<std::size_t>(j)] = static_cast<double>(j) * h_out;
    auto rhs = [&](const State& x, State& dx, double t) { f(t, x.data(), dx.data()); };
    auto dense = [&](double* err, Relative* rel, bool measured) {
      State x = x0;
      std::size_t k = 0, kept = 0;
      try {
        k = odeint::integrate_times(make(tol), rhs, x, times.begin(), times.end(), h_out / 10,
                                    [&](const State& y, double) {
                                      if (err)
                                        *err = std::max(*err, distance(y.data(), &ref.q[kept * static_cast<std::size_t>(stride * n)], n, opt.norm));
                                      if (rel) rel->add(static_cast<long>(kept), y.data());
                                      ++kept;
                                    },
                                    odeint::max_step_checker(odeint_max_steps_between_outputs));
      } catch (const odeint::no_progress_error&) {
        throw_too_stiff("Boost.Odeint (" + std::string(measured ? "measured" : "timed") + " run)",
                        kept ? times[kept - 1] : times.front(), kept);
      }
      do_not_optimize(x[0]);
      if (err && kept != times.size()) *err = missing_value;
      return static_cast<long>(k);
    };
    return measure_point_timed(
        work_point(name, "adaptive", "tol", tol, group), n_errors(),
        [&] {
          need_reference();
          double err = 0;
          Relative rel{*this};
          const long steps = dense(&err, relative() ? &rel : nullptr, true);
          if (std::isnan(err)) rel.counted = 0;  // a run that stopped early is missing in both
          return Measured{errors(err, &rel), steps};
        },
        [&] { return time_per_call([&] { dense(nullptr, nullptr, false); }, opt.reps); }, opt.reps, where(name, "tol", tol));
  }

  WorkPoint baseline(const std::string& name, double tol) const {
    auto rhs = [&](const State& x, State& dx, double t) { f(t, x.data(), dx.data()); };
    if (!opt.at_steps) {
      if (name == "odeint-dopri5")
        return at_output(name, tol, [](double t) { return odeint::make_dense_output(t, t, odeint::runge_kutta_dopri5<State>()); });
      if (name == "odeint-bulirsch-stoer")
        return at_output(name, tol, [](double t) { return odeint::bulirsch_stoer_dense_out<State>(t, t); });
      throw InputError("baseline '" + name + "' has no dense output: it needs --adaptive-error steps");
    }
    // controlled steppers from t = 0 to T, a first step of 0.01, every accepted step observed
    auto odeint_run = [&](auto stepper) {
      return [&, stepper](auto&& observe) mutable {
        State x = x0;
        long accepted = 0;
        const std::size_t k = odeint::integrate_adaptive(stepper, rhs, x, 0.0, T, 0.01, [&](const State& y, double t) {
          if (t > 0) check_adaptive_steps(++accepted, t, T);
          observe(t, y.data());
        });
        do_not_optimize(x[0]);
        return static_cast<long>(k);
      };
    };
    if (name == "odeint-dopri5")
      return at_steps(name, tol, odeint_run(odeint::make_controlled(tol, tol, odeint::runge_kutta_dopri5<State>())));
    if (name == "odeint-bulirsch-stoer") return at_steps(name, tol, odeint_run(odeint::bulirsch_stoer<State>(tol, tol)));
    if (name == "gsl-rk8pd")
      return at_steps(name, tol, [&](auto&& observe) {
        gsl_odeiv2_system gs{gsl_rhs, nullptr, static_cast<std::size_t>(2 * n), const_cast<Rhs*>(&f)};
        GslEvolve gsl(gsl_odeiv2_step_rk8pd, static_cast<std::size_t>(2 * n), tol, tol);
        State y = x0;
        double t = 0, dt = 0.01;
        long steps = 0;
        observe(t, y.data());
        while (t < T) {
          if (gsl.apply(gs, t, T, dt, y.data()) != GSL_SUCCESS)
            throw NumericalFailure(steps, "step size", "GSL rk8pd could not take a step at t = " + show(t));
          check_adaptive_steps(++steps, t, T);
          observe(t, y.data());
        }
        do_not_optimize(y[0]);
        return steps;
      });
    throw InputError("unknown baseline '" + name + "'");
  }
};

}  // namespace

void check_work_precision(const SystemInfo& sys, const std::vector<ParamValues>& combos, const WorkPrecisionOptions& opt) {
  require(!opt.hs.empty() && !combos.empty(), "a work-precision study needs h and parameters");
  for (double h : opt.hs) require_positive(h, "h");
  check_reference(sys, opt.reference, opt.reference_tol);
  require(opt.reps >= 1 && opt.reps <= 1000, "reps must be in [1, 1000]");
  bool over_tol = false;
  for (const auto& b : opt.baselines) {
    const auto& known = work_precision_baselines();
    require(std::find(known.begin(), known.end(), b) != known.end(),
            "unknown baseline '" + b + "' (known: " + join_names(known, " ") + ")");
    if (!opt.at_steps) require(b != "gsl-rk8pd", "baseline 'gsl-rk8pd' has no dense output: it needs --adaptive-error steps");
    over_tol = over_tol || adaptive(b);
  }
  if (over_tol) require(!opt.tols.empty(), "the adaptive baselines need tolerances (--tol)");
  require(std::isfinite(opt.relative_window) && opt.relative_window >= 0, "the relative error's window must be >= 0");
  require(opt.relative_window == 0 || !opt.at_steps,
          "the relative error is taken on the output grid: it cannot be asked with the error at the adaptive steps");
  if (opt.relative_window > 0) {  // the output grid t_k = k h-max: every h divides h-max, h-max divides every T
    const double h_out = *std::max_element(opt.hs.begin(), opt.hs.end());
    for (double h : opt.hs) ratio_of(h_out, h);
    for (const auto& pv : combos) step_count(h_out, sys.horizon(pv));
  }
  for (double tol : opt.tols) check_tolerance(tol, "tol");
  if (opt.at_steps && over_tol)
    require(sys.has_exact, "--adaptive-error steps needs a closed-form solution, which system '" + sys.name +
                               "' has not (use --adaptive-error output)");
  require(!opt.hand_written || sys.has_rhs, "system '" + sys.name + "' has no hand-written rhs (use --equations ad)");
  double cost = 0;  // of one step of every scheme, in cheap steps
  for (const auto& s : opt.schemes) cost += step_cost(sys, s, opt.path);
  for (const auto& b : opt.baselines)
    if (!adaptive(b)) cost += 4;  // four evaluations of the equations
  // every point: one run measured, reps + 1 timed (the adaptive baselines' steps are bounded as they run)
  for (const auto& pv : combos) {
    const double T = sys.horizon(pv);
    for (double h : opt.hs)
      plan_steps((opt.reps + 2) * static_cast<double>(step_count(h, T)), "the sweep (methods x (reps + 2) x T/h)", cost);
    check_reference_memory(sys, opt.reference, step_count(reference_step(sys, opt.hs), T));
  }
}

WorkPrecisionStudy work_precision_study(const SystemInfo& sys, const std::vector<ParamValues>& combos,
                                        const WorkPrecisionOptions& opt) {
  check_work_precision(sys, combos, opt);
  WorkPrecisionStudy study;
  for (std::size_t c = 0; c < combos.size(); ++c) {
    const ParamValues& pv = combos[c];
    const double T = sys.horizon(pv);
    // every scheme and fixed-step baseline is measured on its own grid, a sub-grid of the reference's
    const double h_ref = reference_step(sys, opt.hs);
    Combination k{sys, pv, opt, static_cast<double>(c), T, sys.dof,
                  opt.hand_written ? sys.ode_rhs(pv) : sys.ode(pv), sys.ode_initial_state(pv, opt.hand_written),
                  {}, {}, *std::max_element(opt.hs.begin(), opt.hs.end()), {}};
    try {
      k.ref = sys.reference(pv, h_ref, step_count(h_ref, T), opt.reference, opt.reference_tol);
      study.reference = k.ref.kind;
    } catch (const NumericalFailure& f) {
      if (combos.size() == 1) throw;  // a study of one combination has nothing left to show
      k.ref_failure = f;
    }
    k.size_reference();
    for (const auto& name : opt.schemes)
      for (double h : opt.hs) study.points.push_back(k.scheme(name, h));
    for (const auto& b : opt.baselines)
      if (!adaptive(b))
        for (double h : opt.hs) study.points.push_back(k.rk4(h));
    for (double tol : opt.tols)
      for (const auto& b : opt.baselines)
        if (adaptive(b)) study.points.push_back(k.baseline(b, tol));
  }
  return study;
}

}  // namespace geomint
