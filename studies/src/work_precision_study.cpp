// The work–precision study (work_precision.hpp): every scheme of a system over h and Boost.Odeint / GSL
// baselines over h or tolerance, each point's error against one reference and its CPU time.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <deque>
#include <functional>
#include <limits>
#include <memory>
#include <optional>

#include "geomint/budget.hpp"
#include "geomint/error.hpp"
#include "geomint/formula/state_formula.hpp"
#include "geomint/interrupt.hpp"
#include "geomint/io.hpp"
#include "geomint/reference.hpp"
#include "geomint/run/baselines.hpp"
#include "geomint/step_cost.hpp"
#include "geomint/study.hpp"
#include "geomint/work_precision.hpp"

namespace geomint {

const std::vector<std::string>& work_precision_baselines() { return baseline_names(); }

namespace {

using State = std::vector<double>;
using Rhs = OdeRhs;

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

// A quantity of a state, Q(t, q, q').
using Quantity = std::function<double(double t, const double* q, const double* v)>;

// One measure asked: energy, a momentum component (index 1..n of SystemInfo::observables), or a named formula.
struct MeasureSpec {
  std::string name;
  int observable = -1;  // 0: energy, i: p_i; -1: the formula
  std::string formula;
};

bool identifier(const std::string& s) {
  if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
  return std::all_of(s.begin(), s.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
}

// The system's parameters at pv (its defaults where pv is silent), for a formula's symbols.
std::vector<std::pair<std::string, double>> parameters_at(const SystemInfo& sys, const ParamValues& pv) {
  std::vector<std::pair<std::string, double>> out;
  for (const auto& p : sys.params) {
    double x = p.value;
    for (const auto& [name, value] : pv)
      if (name == p.name) x = value;
    out.emplace_back(p.name, x);
  }
  return out;
}

MeasureSpec parse_measure(const SystemInfo& sys, const std::string& spec) {
  MeasureSpec m;
  const auto eq = spec.find('=');
  if (eq != std::string::npos) {
    m.name = spec.substr(0, eq);
    m.formula = spec.substr(eq + 1);
    require(identifier(m.name), "measure '" + spec + "': a formula's measure is <name>=<formula>, the name a letter followed by "
                                "letters, digits or _");
    require(m.name != "energy" && !(m.name.size() > 1 && m.name[0] == 'p' && std::isdigit(static_cast<unsigned char>(m.name[1]))),
            "measure '" + spec + "': '" + m.name + "' names a measure of its own (energy, p<i>): choose another name");
    formula::StateFormula(m.formula, sys.dof, parameters_at(sys, {}));  // refused here, before any work
    return m;
  }
  m.name = spec;
  if (spec == "energy") {
    m.observable = 0;
    return m;
  }
  if (spec.size() >= 2 && spec.size() <= 4 && spec[0] == 'p' && spec[1] != '0' &&
      std::all_of(spec.begin() + 1, spec.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)); })) {
    const int i = std::stoi(spec.substr(1));
    require(i <= sys.dof, "measure '" + spec + "': system '" + sys.name + "' has " + std::to_string(sys.dof) +
                              (sys.dof == 1 ? " coordinate" : " coordinates") + " (p1..p" + std::to_string(sys.dof) + ")");
    m.observable = i;
    return m;
  }
  throw InputError("unknown measure '" + spec + "' (known: energy, p1..p" + std::to_string(sys.dof) +
                   " (the momentum dL/dq'_i), <name>=<formula> in t, q1.., v1.. and the parameters)");
}

std::vector<MeasureSpec> parse_measures(const SystemInfo& sys, const std::vector<std::string>& specs) {
  std::vector<MeasureSpec> out;
  for (const auto& spec : specs) {
    MeasureSpec m = parse_measure(sys, spec);
    for (const auto& o : out) require(o.name != m.name, "measure '" + m.name + "' is asked twice");
    out.push_back(std::move(m));
  }
  return out;
}

Quantity quantity_at(const SystemInfo& sys, const ParamValues& pv, const MeasureSpec& m) {
  if (m.observable < 0) {
    auto f = std::make_shared<const formula::StateFormula>(m.formula, sys.dof, parameters_at(sys, pv));
    return [f](double t, const double* q, const double* v) { return (*f)(t, q, v); };
  }
  auto obs = std::make_shared<const SystemInfo::Observables>(sys.observables(pv));
  const int n = sys.dof, k = m.observable;
  return [obs, n, k](double t, const double* q, const double* v) {
    std::vector<double> out(static_cast<std::size_t>(n + 1));
    (*obs)(t, q, v, out.data());
    return out[static_cast<std::size_t>(k)];
  };
}

}  // namespace

std::vector<StateMeasure> state_measures(const SystemInfo& sys, const std::vector<std::string>& specs) {
  std::vector<StateMeasure> out;
  for (const auto& m : parse_measures(sys, specs)) {
    const std::string what = m.observable == 0   ? "E (the energy)"
                             : m.observable > 0 ? "p" + std::to_string(m.observable) + " = dL/dv" + std::to_string(m.observable)
                                                : m.formula;
    out.push_back({m.name + "_err", "max_k |Q(t_k, q_k, v_k) - Q(t_k, q_ref, v_ref)| at t_k = t0 + k h-max, Q = " + what});
  }
  return out;
}

namespace {

// One combination of parameters: its equations, reference and every point.
// A baseline runs on its own clock from 0: the equations of a system that starts at t0 are read at t0 + that clock.
Rhs on_own_clock(const SystemInfo& sys, const ParamValues& pv, Rhs f) {
  const double t0 = sys.initial_time ? sys.initial_time(pv) : 0.0;
  if (t0 == 0) return f;
  return [f = std::move(f), t0](double t, const double* x, double* dx) { f(t0 + t, x, dx); };
}

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
  std::vector<Quantity> quantities{};  // the measures' Q at these parameters (WorkPrecisionOptions::measures)
  // the max error, the relative error where asked, one error per measure
  std::size_t n_errors() const { return (relative() ? 2 : 1) + quantities.size(); }
  // whether the study reads a run on the output grid t_k = k h_out
  bool on_grid() const { return relative() || !quantities.empty(); }
  // The measures' Q along the reference at t_k = t0 + k h_out, [measure][k]: once for all the methods it is read by.
  std::vector<std::vector<double>> ref_quantities{};
  void quantity_reference() {
    if (quantities.empty() || ref_failure) return;
    const double t0 = sys.initial_time ? sys.initial_time(pv) : 0.0;
    const long N_out = step_count(h_out, T);
    ref_quantities.assign(quantities.size(), std::vector<double>(static_cast<std::size_t>(N_out + 1)));
    for (long k = 0; k <= N_out; ++k) {
      const long i = ref.index(k, h_out);
      const std::size_t at = static_cast<std::size_t>(i * n);
      for (std::size_t m = 0; m < quantities.size(); ++m)
        ref_quantities[m][static_cast<std::size_t>(k)] = quantities[m](t0 + static_cast<double>(i) * ref.h, &ref.q[at], &ref.v[at]);
    }
  }
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
  // The measures' errors along one run, fed the state at output k (time t) against the reference there.
  struct Measures {
    const Combination& c;
    std::vector<double> worst = std::vector<double>(c.quantities.size(), 0.0);
    void add(long k, double t, const double* q, const double* v) {
      for (std::size_t m = 0; m < c.quantities.size(); ++m) {
        const double d = std::abs(c.quantities[m](t, q, v) - c.ref_quantities[m][static_cast<std::size_t>(k)]);
        if (!std::isfinite(d))
          throw NumericalFailure(k, c.opt.measures[m], "the measure is not finite at t = " + show(t));
        worst[m] = std::max(worst[m], d);
      }
    }
  };
  // {the max error}, then the relative error where asked, then the measures' errors
  std::vector<double> errors(double err, const Relative* rel, const Measures* mea) const {
    std::vector<double> e{err};
    if (relative()) e.push_back(rel->value());
    if (mea) e.insert(e.end(), mea->worst.begin(), mea->worst.end());
    return e;
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
          if (!on_grid()) return Measured{{err}, N};
          const long every = ratio_of(h_out, h);
          const Run r = sys.run(pv, name, h, opt.path, every);  // q at t_k = k h_out (j = k every)
          Relative rel{*this};
          Measures mea{*this};
          for (std::size_t k = 0; k < r.j.size(); ++k) {
            const std::size_t at = k * static_cast<std::size_t>(n);
            if (relative()) rel.add(r.j[k] / every, &r.q[at]);
            mea.add(r.j[k] / every, r.t[k], &r.q[at], &r.v[at]);
          }
          return Measured{errors(err, &rel, &mea), N};
        },
        [&] { return sys.time_run(pv, name, h, opt.path, opt.reps); }, opt.reps, where(name, "h", h));
  }

  // A baseline through the one door (run/baselines.hpp): odeint-rk4 over h on the grid of the reference, the
  // adaptive ones over tol, watched on the grid of the largest h (dense output; GSL's rk8pd, which has none, stepped
  // to each output time), or at the steps they chose (at_steps, against the closed form there: no output grid caps
  // their step size).
  WorkPoint baseline(const std::string& name, double knob) const {
    BaselineSetup b;
    b.name = name;
    const bool rk4 = !is_adaptive_baseline(name);
    if (rk4) {
      b.h = knob;
      b.steps = step_count(knob, T);
    } else {
      b.abs_tol = b.rel_tol = knob;
    }
    if (!rk4 && !opt.at_steps) {
      const long N_out = step_count(h_out, T);
      for (long j = 0; j <= N_out; ++j) b.times.push_back(static_cast<double>(j) * h_out);
      b.watch = BaselineWatch::outputs;
    } else {
      b.T = T;
    }
    const bool at_steps = !rk4 && opt.at_steps;  // read against the closed form, not the reference
    const double start = sys.initial_time ? sys.initial_time(pv) : 0.0;  // the baselines' clock starts at 0
    const long stride = ref_failure || at_steps ? 1 : ref.index(1, rk4 ? knob : h_out);
    const long every = rk4 && on_grid() ? ratio_of(h_out, knob) : 1;
    auto label = [&](bool measured) {
      b.label = std::string("Boost.Odeint (") + (measured ? "measured" : "timed") + " run)";
    };
    auto measure = [&] {
      if (!at_steps) need_reference();
      label(true);
      double err = 0;
      Relative rel{*this};
      Measures mea{*this};
      std::vector<double> ts, qs;  // at_steps: the states where the closed form is read afterwards
      const BaselineObserver observe = [&](std::size_t k, double t, const double* x) {
        if (rk4) {
          if (k > 0) err = std::max(err, distance(x, &ref.q[k * static_cast<std::size_t>(stride * n)], n, opt.norm));
          if (static_cast<long>(k) % every == 0) {
            if (relative()) rel.add(static_cast<long>(k) / every, x);
            mea.add(static_cast<long>(k) / every, start + t, x, x + n);
          }
        } else if (at_steps) {
          ts.push_back(start + t);
          qs.insert(qs.end(), x, x + n);
        } else {
          err = std::max(err, distance(x, &ref.q[k * static_cast<std::size_t>(stride * n)], n, opt.norm));
          if (relative()) rel.add(static_cast<long>(k), x);
          mea.add(static_cast<long>(k), start + t, x, x + n);
        }
      };
      const BaselineCount c = run_baseline(b, f, x0, &observe);
      if (at_steps) {
        const std::vector<double> exact = sys.exact_positions(pv, ts);
        for (std::size_t k = 0; k < ts.size(); ++k)
          err = std::max(err, distance(&qs[k * static_cast<std::size_t>(n)], &exact[k * static_cast<std::size_t>(n)], n, opt.norm));
      }
      return Measured{errors(err, &rel, &mea), c.steps};
    };
    WorkPoint p = work_point(name, rk4 ? "rk" : "adaptive", rk4 ? "h" : "tol", knob, group);
    if (rk4) p.steps = b.steps;  // known before the run: it stays in the table where the run fails
    return measure_point_timed(
        p, at_steps ? 1 : n_errors(), measure,
        [&] {
          label(false);
          return time_per_call([&] { run_baseline(b, f, x0, nullptr); }, opt.reps);
        },
        opt.reps, where(name, rk4 ? "h" : "tol", knob));
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
    check_baseline(b);
    over_tol = over_tol || is_adaptive_baseline(b);
  }
  if (over_tol) require(!opt.tols.empty(), "the adaptive baselines need tolerances (--tol)");
  require(std::isfinite(opt.relative_window) && opt.relative_window >= 0, "the relative error's window must be >= 0");
  require(opt.relative_window == 0 || !opt.at_steps,
          "the relative error is taken on the output grid: it cannot be asked with the error at the adaptive steps");
  parse_measures(sys, opt.measures);
  require(opt.measures.empty() || !opt.at_steps,
          "the measures are taken on the output grid: they cannot be asked with the error at the adaptive steps");
  if (opt.relative_window > 0 || !opt.measures.empty()) {  // the output grid t_k = k h-max: every h divides h-max, h-max divides every T
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
    if (!is_adaptive_baseline(b)) cost += 4;  // four evaluations of the equations
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
  const bool exact = opt.reference == ReferenceKind::exact || (opt.reference == ReferenceKind::automatic && sys.has_exact);
  study.floor = fit_band(exact, opt.reference_tol, std::numeric_limits<double>::infinity()).floor;
  for (std::size_t c = 0; c < combos.size(); ++c) {
    const ParamValues& pv = combos[c];
    const double T = sys.horizon(pv);
    // every scheme and fixed-step baseline is measured on its own grid, a sub-grid of the reference's
    const double h_ref = reference_step(sys, opt.hs);
    Combination k{sys, pv, opt, static_cast<double>(c), T, sys.dof,
                  on_own_clock(sys, pv, opt.hand_written ? sys.ode_rhs(pv) : sys.ode(pv)), sys.ode_initial_state(pv, opt.hand_written),
                  {}, {}, *std::max_element(opt.hs.begin(), opt.hs.end()), {}};
    try {
      k.ref = sys.reference(pv, h_ref, step_count(h_ref, T), opt.reference, opt.reference_tol);
      study.reference = k.ref.kind;
    } catch (const NumericalFailure& f) {
      if (combos.size() == 1) throw;  // a study of one combination has nothing left to show
      k.ref_failure = f;
    }
    k.size_reference();
    for (const auto& m : parse_measures(sys, opt.measures)) k.quantities.push_back(quantity_at(sys, pv, m));
    k.quantity_reference();
    // a watched call's progress (interrupt.hpp): the points of this combination
    Task task("work_precision", "points",
              static_cast<double>(opt.hs.size() * (opt.schemes.size() + opt.baselines.size()) +
                                  opt.tols.size() * opt.baselines.size()));
    for (const auto& name : opt.schemes)
      for (double h : opt.hs) {
        study.points.push_back(k.scheme(name, h));
        task.add();
      }
    for (const auto& b : opt.baselines)
      if (!is_adaptive_baseline(b))
        for (double h : opt.hs) {
          study.points.push_back(k.baseline(b, h));
          task.add();
        }
    for (double tol : opt.tols)
      for (const auto& b : opt.baselines)
        if (is_adaptive_baseline(b)) {
          study.points.push_back(k.baseline(b, tol));
          task.add();
        }
  }
  return study;
}

}  // namespace geomint
