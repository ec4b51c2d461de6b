// The geomint Python module (_geomint; python/geomint/__init__.py re-exports it): the registry's systems and the
// studies a notebook needs, on the registry's type-erased entry points only (registry.hpp, formula_registry.hpp,
// automatic_registry.hpp, study.hpp), so this one translation unit instantiates no scheme and follows the registry
// wherever it goes. Every loop runs in C++ (with the GIL released); results come back as numpy arrays; an
// InputError is geomint.InputError (a ValueError), a NumericalFailure geomint.NumericalFailure (an ArithmeticError
// with .step and .quantity), each with the C++ message. Nothing a user passes is executed: formulas go to
// geomint's own parser.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "geomint/error.hpp"
#include "geomint/text.hpp"
#include "geomint/budget.hpp"
#include "geomint/formula/description.hpp"
#include "geomint/generic_ensemble.hpp"
#include "geomint/parallel.hpp"
#include "geomint/formula/formula_registry.hpp"
#include "geomint/formula/model.hpp"
#include "geomint/interrupt.hpp"
#include "geomint/io.hpp"
#include "geomint/modified/all_orders.hpp"
#include "geomint/modified/automatic_registry.hpp"
#include "geomint/modified/bounded_formulas.hpp"
#include "geomint/modified/formula_modified.hpp"
#include "geomint/modified/plan.hpp"
#include "geomint/modified/surrogate.hpp"
#include "geomint/registry.hpp"
#include "geomint/run_checks.hpp"
#include "geomint/step_cost.hpp"
#include "geomint/study.hpp"
#include "geomint/sweep.hpp"
#include "geomint/work_precision.hpp"
#include "geomint/timing.hpp"

namespace py = pybind11;
using namespace geomint;

namespace {

using Array = py::array_t<double>;

// A copy of v as a numpy array of the given shape (rows x cols, or a vector when cols < 0).
Array to_array(const std::vector<double>& v, long rows, long cols = -1) {
  if (cols < 0) {
    Array a(static_cast<py::ssize_t>(v.size()));
    std::copy(v.begin(), v.end(), a.mutable_data());
    return a;
  }
  require(static_cast<long>(v.size()) == rows * cols, "internal: array of " + std::to_string(v.size()) + " values is not " +
                                                          std::to_string(rows) + " x " + std::to_string(cols));
  Array a({static_cast<py::ssize_t>(rows), static_cast<py::ssize_t>(cols)});
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

template <class T>
py::array_t<T> to_int_array(const std::vector<T>& v) {
  py::array_t<T> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

// Parameters from a dict {name: number}; the system refuses unknown names itself (InputError naming the known).
ParamValues param_values(const py::dict& params) {
  ParamValues pv;
  for (const auto& [k, v] : params) {
    const std::string name = py::cast<std::string>(k);
    double x = 0;
    try {
      x = py::cast<double>(v);
    } catch (const py::cast_error&) {
      throw InputError("parameter " + name + ": not a number");
    }
    pv.emplace_back(name, x);
  }
  return pv;
}

// f() with the GIL released, under a Watch (interrupt.hpp): its loops poll Python's pending signals every 0.1 s
// (PyErr_CheckSignals on this, the main, thread), so Ctrl-C stops the call within a fraction of a second and raises
// KeyboardInterrupt from Python's own handler; the call's outermost task is handed to `progress` (a callable
// (fraction, message), or None). An exception the callback raises stops the call and is raised in its place.
template <class F>
auto watched(const py::object& progress, F&& f) -> decltype(f()) {
  if (!progress.is_none()) require(PyCallable_Check(progress.ptr()) != 0, "progress must be a callable (fraction, message) or None");
  std::function<void(double, const std::string&)> report;
  if (!progress.is_none())
    report = [&progress](double fraction, const std::string& line) {
      py::gil_scoped_acquire gil;
      progress(fraction, line);
    };
  Watch watch(
      [] {
        py::gil_scoped_acquire gil;
        if (PyErr_CheckSignals() != 0) throw py::error_already_set();
        return false;
      },
      report);
  try {
    if constexpr (std::is_void_v<decltype(f())>) {
      {
        py::gil_scoped_release release;
        f();
      }
      watch.rethrow_if_stopped();  // the callback's exception at the call's last report
    } else {
      auto result = [&] {
        py::gil_scoped_release release;
        return f();
      }();
      watch.rethrow_if_stopped();
      return result;
    }
  } catch (const Interrupted&) {
    watch.rethrow_if_stopped();
    throw;
  }
}

// A system of the registry or defined by formulas, with its modified equations where the build has them.
class System {
 public:
  // A header system (the registry's entries live as long as the process).
  explicit System(const SystemInfo& info) : info_(std::shared_ptr<const SystemInfo>(), &info) {}
  // Watched: a shape the build did not compile is compiled here at its first use (formula/jit.hpp), for a minute or
  // so, and Ctrl-C stops it.
  explicit System(std::shared_ptr<const formula::FormulaModel> model)
      : model_(std::move(model)), info_(watched(py::none(), [&] { return formula::formula_system_info(model_); })) {}

  const SystemInfo& info() const { return *info_; }
  bool is_formula() const { return model_ != nullptr; }

  const modified::ModifiedSystem& modified() const {
    if (!modified_) modified_ = watched(py::none(), [&] { return modified::modified_system(*info_); });
    return *modified_;
  }

  std::vector<std::string> warnings(const ParamValues& pv) const {
    if (!model_) return {};
    return formula::formula_warnings(model_, pv);
  }

  const std::shared_ptr<const formula::FormulaModel>& model() const { return model_; }
  // A surrogate (modified/surrogate.hpp): its step parameter, which a run sets to its step, and how it was built.
  std::string step_parameter;
  std::shared_ptr<const modified::SurrogateSystem> surrogate;

 private:
  std::shared_ptr<const formula::FormulaModel> model_;
  std::shared_ptr<const SystemInfo> info_;
  mutable std::shared_ptr<const modified::ModifiedSystem> modified_;
};

// geomint.GeomintWarning (a UserWarning), made when the module is imported.
PyObject* geomint_warning = nullptr;

// A Herglotz form inconsistent with the force, through Python's warnings before the first contact-family run of
// the system (formula::contact_warnings: once per system), so that `integrate("contact")` cannot silently run a
// different system. A filter that turns warnings into errors raises here, before the run.
void warn_contact(const System& s, const std::vector<ParamValues>& values, const std::vector<std::string>& schemes) {
  if (!s.is_formula()) return;
  for (const auto& why : formula::contact_warnings(s.model(), s.info(), values, schemes))
    if (PyErr_WarnEx(geomint_warning, one_line(why).c_str(), 1) != 0) throw py::error_already_set();
}

py::dict run_dict(const Run& run) {
  const long rows = static_cast<long>(run.t.size());
  py::dict d;
  d["j"] = to_int_array(run.j);
  d["t"] = to_array(run.t, rows);
  d["q"] = to_array(run.q, rows, run.n);
  d["p"] = to_array(run.p, rows, run.n);
  d["v"] = to_array(run.v, rows, run.n);
  d["z"] = to_array(run.z, rows);
  d["lambda"] = to_array(run.lambda, rows, run.m);
  d["energy"] = to_array(run.energy, rows);
  d["phi_d"] = to_array(run.phi_d, rows);
  d["phi"] = to_array(run.phi, rows);
  d["newton"] = to_int_array(run.newton);
  d["steps"] = run.steps;
  d["newton_mean"] = run.newton_mean;
  d["max_phi_d"] = run.max_phi_d;
  return d;
}

// Many runs from perturbed parameters (generic_ensemble.hpp): run k's perturbed values, its state at T (NaN where
// it failed) and its failure message ("" where it reached T). Run k has the bits of integrate() from those values.
py::dict ensemble(const System& s, const std::string& scheme, const py::dict& perturb, long runs, double h,
                  const py::dict& params, const std::string& path, unsigned long long seed, unsigned threads,
                  bool budget, const py::object& progress) {
  const BudgetScope scope(budget);
  const SystemInfo& sys = s.info();
  EnsembleSpec spec;
  spec.base = param_values(params);
  for (const auto& [name, spread] : param_values(perturb)) spec.perturb.push_back({name, spread});
  spec.scheme = sys.scheme(scheme).name;
  spec.h = h;
  spec.path = parse_path(path);
  spec.runs = runs;
  spec.seed = seed;
  require(threads <= 256, "threads must be in [0, 256] (0: every core)");
  plan_ensemble(sys, spec, "runs");
  validate_ensemble(sys, spec);
  warn_contact(s, {spec.base}, {spec.scheme});
  const std::vector<EnsembleRun> out =
      watched(progress, [&] { return run_ensemble(sys, spec, 0, runs, threads == 0 ? default_threads() : threads); });
  const long n = sys.dof, P = static_cast<long>(spec.perturb.size());
  const double nan = missing_value;  // a failed run has no final state (numpy shows nan)
  std::vector<double> values, q, v, z, e0, e, phi_d, newton;
  std::vector<std::string> failure, names;
  for (const auto& p : spec.perturb) names.push_back(p.name);
  for (const auto& r : out) {
    values.insert(values.end(), r.values.begin(), r.values.end());
    for (long i = 0; i < n; ++i) {
      q.push_back(r.ok() ? r.q[static_cast<std::size_t>(i)] : nan);
      v.push_back(r.ok() ? r.v[static_cast<std::size_t>(i)] : nan);
    }
    z.push_back(r.ok() ? r.z : nan);
    e0.push_back(r.ok() ? r.energy0 : nan);
    e.push_back(r.ok() ? r.energy : nan);
    phi_d.push_back(r.ok() ? r.max_phi_d : nan);
    newton.push_back(r.ok() ? r.newton_mean : nan);
    failure.push_back(r.failure);
  }
  py::dict d;
  d["perturbed"] = names;
  d["values"] = to_array(values, runs, P);
  d["q"] = to_array(q, runs, n);
  d["v"] = to_array(v, runs, n);
  d["z"] = to_array(z, runs);
  d["energy0"] = to_array(e0, runs);
  d["energy"] = to_array(e, runs);
  d["max_phi_d"] = to_array(phi_d, runs);
  d["newton_mean"] = to_array(newton, runs);
  d["failure"] = failure;
  d["T"] = sys.horizon(spec.base);
  return d;
}

// A surrogate's step parameter set to the step h of the run, unless the caller set it.
ParamValues with_step(const System& s, ParamValues pv, double h) {
  if (s.step_parameter.empty()) return pv;
  for (const auto& [name, x] : pv)
    if (name == s.step_parameter) return pv;
  pv.emplace_back(s.step_parameter, h);
  return pv;
}

py::dict integrate(const System& s, const std::string& scheme, double h, const py::dict& params, const std::string& path,
                   long every, bool budget, const py::object& progress) {
  const BudgetScope scope(budget);
  const SystemInfo& sys = s.info();
  const ParamValues pv = with_step(s, param_values(params), h);
  const SchemeInfo& sc = sys.scheme(scheme);
  require_positive(h, "h");
  require(every >= 1, "every must be a positive integer, got " + std::to_string(every));
  const Path p = parse_path(path);
  // the run and its numpy copy are held together while the arrays are made
  plan_run(sys, sc.name, p, h, sys.horizon(pv), every, 2, "every");
  warn_contact(s, {pv}, {sc.name});
  const Run run = watched(progress, [&] { return sys.run(pv, scheme, h, p, every); });
  require_finite_run(run, "system " + sys.name + ", scheme " + sc.name + " (" + to_string(p) + "), h = " + show(h));
  return run_dict(run);
}

py::dict reference(const System& s, double h, long N, const std::string& kind, double tol, const py::dict& params,
                   const py::object& progress) {
  const SystemInfo& sys = s.info();
  const ParamValues pv = param_values(params);
  require_positive(h, "h");
  const ReferenceKind k = parse_reference(kind);
  check_reference(sys, k, tol);
  if (N <= 0) N = step_count(h, sys.horizon(pv));
  const Reference ref = watched(progress, [&] { return sys.reference(pv, h, N, k, tol); });
  std::vector<double> t(static_cast<std::size_t>(ref.N + 1));
  for (long j = 0; j <= ref.N; ++j) t[static_cast<std::size_t>(j)] = static_cast<double>(j) * ref.h;
  py::dict d;
  d["t"] = to_array(t, ref.N + 1);
  d["q"] = to_array(ref.q, ref.N + 1, ref.n);
  d["kind"] = ref.kind;
  return d;
}

std::vector<std::string> scheme_list(const SystemInfo& sys, const std::vector<std::string>& asked) {
  if (asked.empty()) return sys.scheme_names();
  for (const auto& n : asked) sys.scheme(n);
  return asked;
}

// Errors against h (halving from h_max to <= h_min) for each scheme, observed and fitted orders, and the measures the
// system declares: the convergence program's study (convergence_study), as arrays.
py::dict convergence(const System& s, const std::vector<std::string>& schemes_asked, double h_max, double h_min,
                     const py::dict& params, const std::string& path, const std::string& ref_name, double tol,
                     const std::string& norm, bool budget, const py::object& progress) {
  const BudgetScope scope(budget);
  const SystemInfo& sys = s.info();
  const ParamValues pv = param_values(params);
  const auto schemes = scheme_list(sys, schemes_asked);
  const Path p = parse_path(path);
  const ReferenceKind k = parse_reference(ref_name);
  const ErrorNorm en = parse_norm(norm);
  check_reference(sys, k, tol);
  require_positive(h_max, "h_max");
  require_positive(h_min, "h_min");
  const auto hs = halving_sequence(h_max, h_min);
  plan_convergence(sys, {pv}, schemes, hs, p);
  warn_contact(s, {pv}, schemes);
  const ConvergenceStudy study =
      watched(progress, [&] { return convergence_study(sys, {pv}, schemes, hs, p, k, tol, Sweep::world(), en); });
  const auto H = static_cast<long>(hs.size());
  py::dict err, observed, fitted, asymptotic, expected, points, failed, measures;
  for (const auto& m : study.measures) measures[py::str(m.name)] = py::dict();
  for (const auto& se : study.series) {
    const py::str name(se.scheme);
    err[name] = to_array(se.err, H);
    observed[name] = to_array(se.local_order, H);
    fitted[name] = se.fit.slope;
    asymptotic[name] = se.asymptotic.describe();
    points[name] = se.fit.points;
    expected[name] = se.expected_order;
    for (const auto& f : se.failure)
      if (!f.empty()) {  // the first failure, as the program reports it
        failed[name] = f;
        break;
      }
    for (std::size_t i = 0; i < study.measures.size(); ++i) {
      std::vector<double> values;
      for (const auto& at_h : se.measures) values.push_back(at_h[i]);
      measures[py::str(study.measures[i].name)][name] = to_array(values, H);
    }
  }
  std::vector<long> steps;
  for (double h : hs) steps.push_back(step_count(h, sys.horizon(pv)));
  py::dict d;
  d["h"] = to_array(hs, H);
  d["steps"] = to_int_array(steps);
  d["error"] = err;
  d["observed_order"] = observed;
  d["fitted_order"] = fitted;
  d["asymptotic"] = asymptotic;
  d["points"] = points;
  d["expected_order"] = expected;
  d["failures"] = failed;
  d["measures"] = measures;
  d["norm"] = to_string(en);
  d["reference"] = study.reference;
  return d;
}

// Error and median CPU seconds of one run of each scheme against h, and of each baseline against h (rk4) or its
// tolerance: the work_precision program's study (work_precision_study), as arrays; with relative_window > 0 also
// the error relative to the solution's size over that window (long_horizon's err_rel).
py::dict work_precision(const System& s, const std::vector<std::string>& schemes_asked, const std::vector<double>& hs,
                        const py::dict& params, const std::string& path, int reps, const std::string& ref_name, double tol,
                        const std::vector<std::string>& baselines, const std::vector<double>& tols,
                        const std::string& equations, const std::string& adaptive_error, double relative_window,
                        const std::vector<std::string>& measures, bool budget, const py::object& progress) {
  const BudgetScope scope(budget);  // check_work_precision plans the work
  const SystemInfo& sys = s.info();
  const ParamValues pv = param_values(params);
  WorkPrecisionOptions opt;
  opt.schemes = scheme_list(sys, schemes_asked);
  opt.hs = hs;
  opt.baselines = baselines;
  opt.tols = tols;
  opt.path = parse_path(path);
  opt.reps = reps;
  opt.reference = parse_reference(ref_name);
  opt.reference_tol = tol;
  require(equations == "ad" || equations == "rhs", "unknown equations '" + equations + "' (known: ad rhs)");
  require(adaptive_error == "output" || adaptive_error == "steps",
          "unknown adaptive error '" + adaptive_error + "' (known: output steps)");
  opt.hand_written = equations == "rhs";
  opt.at_steps = adaptive_error == "steps";
  opt.relative_window = relative_window;
  opt.measures = measures;
  check_work_precision(sys, {pv}, opt);
  const std::vector<StateMeasure> measured = state_measures(sys, measures);
  warn_contact(s, {pv}, opt.schemes);
  // the study checks (and plans) again: from zero, or the plan would count twice
  const BudgetScope again(budget);
  const WorkPrecisionStudy study = watched(progress, [&] { return work_precision_study(sys, {pv}, opt); });
  // per method, its points in the study's order (over h, or over tol)
  std::vector<std::string> methods;
  std::vector<std::vector<double>> value, error, seconds, relative;
  std::vector<std::vector<std::vector<double>>> measure(measured.size());  // [measure][method][point]
  std::vector<std::string> knob;
  for (const auto& pt : study.points) {
    auto it = std::find(methods.begin(), methods.end(), pt.method);
    if (it == methods.end()) {
      methods.push_back(pt.method);
      knob.push_back(pt.knob);
      value.emplace_back();
      error.emplace_back();
      seconds.emplace_back();
      relative.emplace_back();
      for (auto& m : measure) m.emplace_back();
      it = methods.end() - 1;
    }
    const auto i = static_cast<std::size_t>(it - methods.begin());
    value[i].push_back(pt.value);
    error[i].push_back(pt.errors[0]);
    const std::size_t first = relative_window > 0 ? 2 : 1;  // the measures' errors follow q's
    if (relative_window > 0) relative[i].push_back(pt.errors[1]);
    for (std::size_t m = 0; m < measured.size(); ++m) measure[m][i].push_back(pt.errors[first + m]);
    seconds[i].push_back(pt.time.median);
  }
  py::dict err, sec, val, kn, rel;
  for (std::size_t i = 0; i < methods.size(); ++i) {
    const py::str name(methods[i]);
    const auto n = static_cast<long>(value[i].size());
    err[name] = to_array(error[i], n);
    if (relative_window > 0) rel[name] = to_array(relative[i], n);
    sec[name] = to_array(seconds[i], n);
    val[name] = to_array(value[i], n);
    kn[name] = knob[i];
  }
  py::dict mea;
  for (std::size_t m = 0; m < measured.size(); ++m) {
    py::dict per;
    for (std::size_t i = 0; i < methods.size(); ++i)
      per[py::str(methods[i])] = to_array(measure[m][i], static_cast<long>(measure[m][i].size()));
    mea[py::str(measured[m].column.substr(0, measured[m].column.size() - 4))] = per;
  }
  py::dict d;
  d["h"] = to_array(hs, static_cast<long>(hs.size()));
  d["error"] = err;
  if (relative_window > 0) d["relative_error"] = rel;
  d["measures"] = mea;
  d["seconds"] = sec;
  d["value"] = val;
  d["knob"] = kn;
  d["reference"] = study.reference;
  return d;
}

std::vector<double> point_or_initial(const System& s, const ParamValues& pv, const std::vector<double>& given, bool velocity) {
  if (!given.empty()) return given;
  // the initial data, from the continuous equations' consistent initial state (q, q')
  const auto x = s.info().ode_initial_state(pv, false);
  const auto n = static_cast<std::size_t>(s.info().dof);
  return velocity ? std::vector<double>(x.begin() + static_cast<long>(n), x.end()) : std::vector<double>(x.begin(), x.begin() + static_cast<long>(n));
}

py::dict modified_equation(const System& s, const std::string& scheme, int K, double t, const std::vector<double>& q_in,
                           const std::vector<double>& v_in, double z, const py::dict& params,
                           const py::object& progress) {
  const ParamValues pv = param_values(params);
  s.info().validate(pv);
  modified::modified_scheme(s.info(), scheme);
  const auto q = point_or_initial(s, pv, q_in, false), v = point_or_initial(s, pv, v_in, true);
  modified::require_finite_point(t, q, v, z);
  warn_contact(s, {pv}, {scheme});
  const auto& ms = s.modified();
  const modified::ModifiedPoint r = watched(progress, [&] { return ms.at(pv, scheme, K, t, q, v, z, true); });
  py::dict d;
  d["K"] = r.K;
  d["F"] = to_array(r.F, r.K + 1, r.n);
  d["Z"] = to_array(r.Z, static_cast<long>(r.Z.size()));
  d["mu"] = to_array(r.mu, r.m > 0 ? static_cast<long>(r.mu.size()) / r.m : 0, r.m);
  d["phi"] = to_array(r.phi, r.m > 0 ? static_cast<long>(r.phi.size()) / r.m : 0, r.m);
  d["phi_dot"] = to_array(r.phi_dot, r.m > 0 ? static_cast<long>(r.phi_dot.size()) / r.m : 0, r.m);
  d["lagrangian"] = to_array(r.lagrangian, static_cast<long>(r.lagrangian.size()));
  d["residual"] = r.residual;
  d["t"] = t;
  d["q"] = to_array(q, static_cast<long>(q.size()));
  d["v"] = to_array(v, static_cast<long>(v.size()));
  d["z"] = z;
  return d;
}

// Formulas as dicts {quantity, k, text, mathematica, latex}: a modified equation's rows, a surrogate's corrections.
template <class Row>
py::list formula_rows(const std::vector<Row>& rows) {
  py::list out;
  for (const auto& r : rows) {
    py::dict row;
    row["quantity"] = r.quantity;
    row["k"] = r.k;
    row["text"] = r.text;
    row["mathematica"] = r.mathematica;
    row["latex"] = r.latex;
    out.append(row);
  }
  return out;
}

py::dict modified_formulas(const System& s, const std::string& scheme, int K, double budget, const py::dict& params,
                           bool on_constraint, const py::object& progress) {
  const ParamValues pv = param_values(params);
  modified::formula_scheme(s.info(), scheme);
  require(std::isfinite(budget) && budget > 0, "budget must be a positive number of seconds");
  require(!on_constraint || (s.info().constraints > 0 && !s.modified().holonomic),
          "modified_formulas(on_constraint=True): system '" + s.info().name + "' has no nonholonomic constraint to chart");
  warn_contact(s, {pv}, {scheme});
  const auto& ms = s.modified();
  // in a child process, so that the budget holds inside an order (bounded_formulas.hpp)
  const modified::ModifiedFormulas f =
      watched(progress, [&] { return modified::bounded_formulas(ms, pv, scheme, K, budget, on_constraint); });
  if (f.stopped) {
    const std::string why =
        "modified_formulas(" + scheme + ", order=" + std::to_string(K) + "): the budget of " + show(budget) +
        " s ran out in order " + std::to_string(f.K + 1) +
        (f.K >= 0 ? ": the formulas hold orders 0.." + std::to_string(f.K) : ": no order was finished (no rows)") +
        " (raise budget= for more)";
    if (PyErr_WarnEx(geomint_warning, why.c_str(), 1) != 0) throw py::error_already_set();
  }
  const py::list rows = formula_rows(f.rows);
  py::dict d;
  d["K"] = f.K;
  d["K_asked"] = f.K_asked;
  d["stopped"] = f.stopped;
  d["seconds"] = f.seconds;
  d["symbols"] = f.symbols;
  d["values"] = f.values;
  d["rows"] = rows;
  d["size"] = f.size;
  d["chart"] = f.chart;
  return d;
}

// The modified equation to all orders of a linear system (modified::all_orders_linear): x' = G x on (q, p), and
// q'' = A_v q' + A_q q, in double.
py::dict all_orders(const System& s, const std::string& scheme, double h, const py::dict& params, const std::string& path) {
  const auto r = modified::all_orders_linear(s.info(), param_values(params), scheme, h, parse_path(path));
  auto as_double = [](const std::vector<long double>& v) { return std::vector<double>(v.begin(), v.end()); };
  py::dict d;
  d["G"] = to_array(as_double(r.G), 2 * r.n, 2 * r.n);
  d["A_q"] = to_array(as_double(r.A_q), r.n, r.n);
  d["A_v"] = to_array(as_double(r.A_v), r.n, r.n);
  return d;
}

py::dict modified_agreement(const System& s, const std::string& scheme, int K, double h, double T, double tol,
                            const py::dict& params, const std::string& start, bool budget,
                            const py::object& progress) {
  const BudgetScope scope(budget);
  const ParamValues pv = param_values(params);
  const auto st = modified::parse_agreement_start(start);
  modified::modified_scheme(s.info(), scheme);
  if (!(T > 0)) T = s.info().horizon(pv);
  modified::plan_agreement(s.info(), scheme, h, T);
  warn_contact(s, {pv}, {scheme});
  const auto& ms = s.modified();
  const modified::ModifiedAgreement a = watched(progress, [&] { return ms.agreement(pv, scheme, K, h, T, tol, st); });
  py::dict d;
  d["steps"] = a.steps;
  d["err_q"] = a.err_q;
  d["err_z"] = a.err_z;
  d["v_shift"] = a.v_shift;
  d["shoot_miss"] = a.shoot_miss;
  d["phi_d"] = a.phi_d;
  d["phi_h0"] = a.phi_h0;
  d["phi_h_drift"] = a.phi_h_drift;
  d["err_mu"] = a.err_mu;
  return d;
}

// The consistent start of the order-K modified solution: v~(0) with q~(0) = q_0 such that the modified flow passes
// through the scheme's first step q_1 at t = h (what modified_agreement's shooting start uses; its v_shift is
// |v~(0) - v_0|).
py::dict modified_start(const System& s, const std::string& scheme, int K, double h, double tol, const py::dict& params) {
  const ParamValues pv = param_values(params);
  s.info().validate(pv);
  modified::modified_scheme(s.info(), scheme);
  require(std::isfinite(h) && h > 0, "h must be a positive finite number, got " + show(h));
  require(std::isfinite(tol) && tol > 0, "tol must be a positive finite number, got " + show(tol));
  require(K >= 0 && K <= modified::registry_max_order,
          "order must be an integer in [0, " + std::to_string(modified::registry_max_order) + "]");
  warn_contact(s, {pv}, {scheme});
  const auto& ms = s.modified();
  const auto q0 = point_or_initial(s, pv, {}, false), v0 = point_or_initial(s, pv, {}, true);
  std::vector<double> v;
  {
    py::gil_scoped_release release;
    v = ms.shoot(pv, scheme, K, h, tol);
  }
  double shift = 0;
  for (std::size_t i = 0; i < v.size(); ++i) shift = std::max(shift, std::abs(v[i] - v0[i]));
  py::dict d;
  d["q"] = to_array(q0, static_cast<long>(q0.size()));
  d["v"] = to_array(v, static_cast<long>(v.size()));
  d["v0"] = to_array(v0, static_cast<long>(v0.size()));
  d["shift"] = shift;
  return d;
}

// A formula given from Python: a string (written as a user would), or a number (its shortest exact decimal).
formula::FormulaText formula_of(const py::handle& x, const std::string& field) {
  if (py::isinstance<py::str>(x)) return formula::formula_text(py::cast<std::string>(x), field);
  if (py::isinstance<py::float_>(x) || py::isinstance<py::int_>(x))
    return formula::formula_text(py::cast<std::string>(py::repr(py::float_(py::reinterpret_borrow<py::object>(x)))), field);
  throw InputError(field + ": a formula is a string or a number");
}

std::vector<formula::FormulaText> formula_list(const py::object& xs, const std::string& base) {
  std::vector<formula::FormulaText> out;
  if (xs.is_none()) return out;
  if (py::isinstance<py::str>(xs)) throw InputError(base + ": a list of formulas, one per component");
  int i = 1;
  for (const auto& x : xs) out.push_back(formula_of(x, base + std::to_string(i++)));
  return out;
}

System surrogate(const System& s, const std::string& scheme, int order, double budget, double step) {
  require(s.is_formula(), "system '" + s.info().name +
                              "' is a C++ header: a surrogate is built from a system's formulas (load its file, "
                              "geomint.load_system('docs/systems/" + s.info().name + ".geomint'))");
  modified::SurrogateSystem built;
  {
    py::gil_scoped_release release;
    built = modified::build_surrogate(s.model(), scheme, order, budget, step);
  }
  System out(formula::compile_model(built.description));
  out.step_parameter = built.step_parameter;
  out.surrogate = std::make_shared<const modified::SurrogateSystem>(std::move(built));
  return out;
}

py::dict surrogate_info(const System& s) {
  require(s.surrogate != nullptr, "system '" + s.info().name + "' is not a surrogate (System.surrogate builds one)");
  const auto& b = *s.surrogate;
  py::dict d;
  d["base"] = b.base;
  d["scheme"] = b.scheme;
  d["K"] = b.K;
  d["K_asked"] = b.K_asked;
  d["stopped"] = b.stopped;
  d["why_short"] = b.why_short;
  d["seconds"] = b.seconds;
  d["step_parameter"] = b.step_parameter;
  d["force_free"] = b.force_free;
  d["constraint_linear"] = b.constraint_linear;
  d["terms"] = formula_rows(b.terms);
  py::list checks;
  for (const auto& c : b.checks) {
    py::dict row;
    row["k"] = c.k;
    row["symbolic_zero"] = c.symbolic_zero;
    row["leading"] = c.leading;
    checks.append(row);
  }
  d["checks"] = checks;
  d["defect_h"] = b.defect_h;
  d["defect"] = b.defect;
  d["defect_slope"] = b.defect_slope;
  d["file"] = b.file_text;
  return d;
}

// A strict system is checked at its definition, at its default parameters: an inconsistent Herglotz form is an
// InputError here, not at its first contact run (validate checks it again at each run's own values). So is a system
// with an exact solution, always: a solution that does not solve the equations is refused where it is written.
System defined(System s, bool strict_herglotz) {
  if (strict_herglotz || s.info().has_exact) s.info().validate({});
  return s;
}

System define_system(const std::string& name, int coordinates, const py::object& L, const py::object& herglotz,
                     const py::object& force, const py::object& energy, const py::object& constraints, bool holonomic,
                     const py::dict& parameters, const py::dict& definitions, const py::object& initial_q,
                     const py::object& initial_v, const std::string& description, bool strict_herglotz,
                     const py::object& time_transform, const py::object& t0, const py::object& z0,
                     const py::object& exact_q, const py::object& exact_v) {
  formula::SystemDescription d;
  d.name = name;
  d.description = description;
  d.coordinates = coordinates;
  d.origin.source = "define_system(" + name + ")";
  for (const auto& [k, v] : parameters) {
    formula::ParameterText p;
    p.name = py::cast<std::string>(k);
    if (py::isinstance<py::tuple>(v) || py::isinstance<py::list>(v)) {  // (value, doc)
      const auto seq = py::reinterpret_borrow<py::sequence>(v);
      require(seq.size() == 2, "parameter " + p.name + ": a value, or (value, doc)");
      p.value = formula_of(seq[0], "parameter " + p.name);
      p.doc = py::cast<std::string>(seq[1]);
    } else {
      p.value = formula_of(v, "parameter " + p.name);
    }
    d.parameters.push_back(std::move(p));
  }
  for (const auto& [k, v] : definitions) {
    const std::string n = py::cast<std::string>(k);
    d.definitions.push_back({n, formula_of(v, n)});
  }
  d.lagrangian = formula_of(L, "L");
  if (!herglotz.is_none()) d.herglotz = formula_of(herglotz, "herglotz");
  if (!energy.is_none()) d.energy = formula_of(energy, "E");
  d.force = formula_list(force, "F");
  d.constraint_kind = holonomic ? formula::ConstraintKind::holonomic : formula::ConstraintKind::velocity;
  d.constraints = formula_list(constraints, holonomic ? "g" : "phi");
  d.initial_q = formula_list(initial_q, "q");
  d.initial_v = formula_list(initial_v, "v");
  if (!time_transform.is_none()) d.time_transform = formula_of(time_transform, "time_transform");
  if (!t0.is_none()) d.initial_t = formula_of(t0, "t0");
  if (!z0.is_none()) d.initial_z = formula_of(z0, "z0");
  d.exact_q = formula_list(exact_q, "exact q");
  d.exact_v = formula_list(exact_v, "exact v");
  require(d.exact_q.empty() || static_cast<int>(d.exact_q.size()) == coordinates,
          "define_system(" + name + "): exact_q needs " + std::to_string(coordinates) + " formulas, got " +
              std::to_string(d.exact_q.size()));
  require(d.exact_v.empty() || d.exact_v.size() == d.exact_q.size(),
          "define_system(" + name + "): exact_v needs one formula per exact_q (or none: the derivatives of exact_q)");
  formula::CompileOptions options;
  options.strict_herglotz = strict_herglotz;
  return defined(System(formula::compile_model(d, options)), strict_herglotz);
}

System load_system(const std::string& path, bool strict_herglotz, const py::object& time_transform) {
  formula::CompileOptions options;
  options.strict_herglotz = strict_herglotz;
  formula::SystemDescription d = formula::read_system_file(path);
  if (!time_transform.is_none()) d.time_transform = formula_of(time_transform, "time_transform");
  return defined(System(formula::compile_model(d, options)), strict_herglotz);
}

// C++ timing of the same registry call as integrate (nothing converted to numpy): the bench's floor.
double seconds_of_run(const System& s, const std::string& scheme, double h, const py::dict& params, const std::string& path,
                      long every, int reps) {
  const ParamValues pv = param_values(params);
  const Path p = parse_path(path);
  py::gil_scoped_release release;
  const auto st = time_median([&] { do_not_optimize(s.info().run(pv, scheme, h, p, every).steps); }, reps);
  return st.median;
}

}  // namespace

PYBIND11_MODULE(_geomint, m) {
  m.doc() = "geomint: geometric integrators of dissipative and nonholonomic systems, with backward-error analysis";

  static py::exception<InputError> input_error(m, "InputError", PyExc_ValueError);
  static py::exception<NumericalFailure> numerical_failure(m, "NumericalFailure", PyExc_ArithmeticError);
  geomint_warning = PyErr_NewExceptionWithDoc("geomint.GeomintWarning",
                                              "a result the module computed but doubts (a UserWarning): a Herglotz "
                                              "form inconsistent with the force, a budget that cut an order short",
                                              PyExc_UserWarning, nullptr);
  if (geomint_warning == nullptr) throw py::error_already_set();
  m.add_object("GeomintWarning", py::handle(geomint_warning));
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const NumericalFailure& e) {
      // Escaped as the programs print them: a control byte quoted from a file never reaches the user raw, and
      // bytes that are not UTF-8 cannot make the message undecodable (it would arrive empty).
      py::object err = py::reinterpret_borrow<py::object>(numerical_failure.ptr())(one_line(e.what()));  // an instance
      err.attr("step") = e.step;
      err.attr("quantity") = one_line(e.quantity);
      PyErr_SetObject(numerical_failure.ptr(), err.ptr());
    } catch (const InputError& e) {
      input_error(one_line(e.what()).c_str());
    } catch (const Interrupted&) {  // a watch's stop without a Python error of its own (watched() raises that one)
      PyErr_SetNone(PyExc_KeyboardInterrupt);
    }
  });

  m.def("systems", &system_names, "names of the systems of the registry (their C++ headers)");
  m.def("git_revision", [] { return std::string(git_revision()); }, "the git revision the module was built from");
  m.def("compiled_formula_shapes", &formula::compiled_formula_shapes,
        "the shapes (n, m) of systems defined by formulas this build compiled (core/src/formula/shapes.def); any "
        "other shape up to n = 12, m = 6 is compiled at its first use (a minute or so, once; docs/systems/README.md)");

  py::class_<System>(m, "System", "a system: its parameters, schemes and studies")
      .def_property_readonly("name", [](const System& s) { return s.info().name; })
      .def_property_readonly("description", [](const System& s) { return s.info().description; })
      .def_property_readonly("dof", [](const System& s) { return s.info().dof; })
      .def_property_readonly("constraints", [](const System& s) { return s.info().constraints; })
      .def_property_readonly("has_herglotz", [](const System& s) { return s.info().has_herglotz; })
      .def_property_readonly("has_exact", [](const System& s) { return s.info().has_exact; })
      .def_property_readonly("from_formulas", &System::is_formula)
      .def_property_readonly(
          "parameters",
          [](const System& s) {
            py::dict d;
            for (const auto& p : s.info().params) d[py::str(p.name)] = py::make_tuple(p.value, p.doc);
            return d;
          },
          "{name: (default, doc)}")
      .def_property_readonly(
          "schemes",
          [](const System& s) {
            py::dict d;
            for (const auto& sc : s.info().schemes) {
              py::dict e;
              e["principle"] = sc.principle;
              e["quadrature"] = sc.quadrature;
              e["order"] = sc.order;
              e["fast_path"] = sc.fast_path;
              e["aliases"] = sc.aliases;
              e["generic"] = sc.generic;
              d[py::str(sc.name)] = e;
            }
            return d;
          },
          "{name: {principle, quadrature, order, fast_path, aliases, generic}}: what runs when no scheme is named "
          "(fast_path: the closed form that runs it, '' if none; generic: it has a residual, so the Newton step runs it)")
      .def_property_readonly(
          "measures",
          [](const System& s) {
            py::dict d;
            for (const auto& m : s.info().measures) d[py::str(m.name)] = m.doc;
            return d;
          },
          "{name: doc}: what a convergence study measures on a run beyond the error in q (declared with the system)")
      .def_property_readonly(
          "expectations",
          [](const System& s) {
            const Expectations& x = s.info().expectations;
            py::dict d, orders;
            for (const auto& [scheme, k] : x.orders) orders[py::str(scheme)] = k;
            py::dict params;
            for (const auto& [k, v] : x.params) params[py::str(k)] = v;
            d["params"] = params;
            d["h_max"] = x.h_max;
            d["halvings"] = x.halvings;
            d["orders"] = orders;
            d["order_tolerance"] = x.order_tolerance;
            d["why"] = x.why;
            return d;
          },
          "what the system's tests expect of it: {params, h_max, halvings, orders, order_tolerance, why}")
      .def_property_readonly(
          "compositions",
          [](const System& s) {
            py::dict d;
            for (const auto& c : s.info().compositions) {
              py::dict e;
              e["principle"] = c.principle;
              e["base"] = c.base;
              e["order"] = c.order;
              d[py::str(c.name)] = e;
            }
            return d;
          },
          "{'<family>:<base>': {principle, base, order}}: compositions of the symmetric schemes, run when named")
      .def(
          "validate", [](const System& s, const py::dict& params) { s.info().validate(param_values(params)); },
          py::arg("params") = py::dict(), "InputError naming the first bad value")
      .def(
          "horizon", [](const System& s, const py::dict& params) { return s.info().horizon(param_values(params)); },
          py::arg("params") = py::dict())
      .def(
          "warnings", [](const System& s, const py::dict& params) { return s.warnings(param_values(params)); },
          py::arg("params") = py::dict(), "a formula system's Herglotz form against its force (empty when they agree)")
      .def("integrate", &integrate, py::arg("scheme"), py::arg("h"), py::arg("params") = py::dict(), py::arg("path") = "fast",
           py::arg("every") = 1, py::arg("budget") = true, py::arg("progress") = py::none(),
           "N = T/h steps of `scheme`, every `every`-th kept: {j, t, q, p, v, z, lambda, energy, phi_d, phi, newton} "
           "as arrays (q, p, v: rows x n; lambda: rows x m), and steps, newton_mean, max_phi_d; NumericalFailure "
           "(naming the step and t) where a kept state, energy or residual is not finite; budget=True refuses at "
           "once a run whose planned work exceeds the time budget (about an hour of steps; budget=False runs it "
           "anyway) or whose kept rows exceed the memory available (raise every)")
      .def("ensemble", &ensemble, py::arg("scheme"), py::arg("perturb"), py::arg("runs") = 1000, py::arg("h") = 0.1,
           py::arg("params") = py::dict(), py::arg("path") = "fast", py::arg("seed") = 1, py::arg("threads") = 0,
           py::arg("budget") = true, py::arg("progress") = py::none(),
           "budget=True (budget=False: run anyway) refuses at once runs x T/h steps beyond the time budget; "
           "runs from perturbed parameters, perturb = {name: spread} (run k: p + spread u, u uniform in [-1, 1) from "
           "(seed, k)), on `threads` threads (0: every core): {perturbed, values (runs x P), q, v (runs x n), z, "
           "energy0, energy, max_phi_d, newton_mean (NaN where a run failed), failure (messages, '' where it reached "
           "T), T}; run k has the bits of integrate() from its values")
      .def("reference", &reference, py::arg("h"), py::arg("N") = 0, py::arg("kind") = "auto", py::arg("tol") = 1e-13,
           py::arg("params") = py::dict(), py::arg("progress") = py::none(),
           "the reference solution on t_j = t0 + j h (closed form, or Boost.Odeint)")
      .def("convergence", &convergence, py::arg("schemes") = std::vector<std::string>{}, py::arg("h_max") = 0.1,
           py::arg("h_min") = 0.003, py::arg("params") = py::dict(), py::arg("path") = "fast", py::arg("reference") = "auto",
           py::arg("tol") = 1e-13, py::arg("norm") = "max", py::arg("budget") = true, py::arg("progress") = py::none(),
           "max_j |q_j - q_ref(t_j)| against h (norm 'max' or '2'), observed, least-squares and asymptotic orders, and "
           "the system's measures {name: {scheme: array}}; budget=True (budget=False: run anyway) refuses at once a "
           "sweep beyond the time budget. Under mpiexec the runs are shared by the ranks and rank 0 alone gets the "
           "results: the other ranks' dicts have empty error, orders and measures")
      .def("work_precision", &work_precision, py::arg("schemes") = std::vector<std::string>{}, py::arg("h"),
           py::arg("params") = py::dict(), py::arg("path") = "fast", py::arg("reps") = 3, py::arg("reference") = "auto",
           py::arg("tol") = 1e-13, py::arg("baselines") = std::vector<std::string>{},
           py::arg("tols") = std::vector<double>{}, py::arg("equations") = "ad", py::arg("adaptive_error") = "output",
           py::arg("relative_window") = 0.0, py::arg("measures") = std::vector<std::string>{}, py::arg("budget") = true,
           py::arg("progress") = py::none(),
           "budget=True (budget=False: run anyway) refuses at once a sweep beyond the time budget; error and median CPU seconds of one run, per method: the schemes against h, the baselines (odeint-rk4 over h; "
           "odeint-dopri5, odeint-bulirsch-stoer, gsl-rk8pd over tols) as the work_precision program runs them; with "
           "relative_window > 0 also relative_error, the error relative to the solution's size over that window as "
           "long_horizon measures it; with measures (energy, p<i>, '<name>=<formula>') also measures {name: {method: "
           "array}}, max_k |Q(run) - Q(reference)| at t_k = t0 + k max(h)")
      .def("modified_equation", &modified_equation, py::arg("scheme"), py::arg("order") = 4, py::arg("t") = 0.0,
           py::arg("q") = std::vector<double>{}, py::arg("v") = std::vector<double>{}, py::arg("z") = 0.0,
           py::arg("params") = py::dict(), py::arg("progress") = py::none(),
           "q'' = sum_k h^k F_k at (t, q, q', z) (default: the initial data); also Z, mu, phi, the modified Lagrangian")
      .def("modified_formulas", &modified_formulas, py::arg("scheme"), py::arg("order") = 4, py::arg("budget") = 60.0,
           py::arg("params") = py::dict(), py::arg("on_constraint") = false, py::arg("progress") = py::none(),
           "the modified equation as formulas (text, Mathematica, LaTeX), every parameter a symbol, derived in a "
           "child process so that the budget (seconds) holds inside an order: when it runs out the call returns the "
           "orders finished (K < K_asked, stopped) with a GeomintWarning naming the order reached")
      .def("modified_agreement", &modified_agreement, py::arg("scheme"), py::arg("order"), py::arg("h"), py::arg("T") = 0.0,
           py::arg("tol") = 1e-13, py::arg("params") = py::dict(), py::arg("start") = "shooting",
           py::arg("budget") = true, py::arg("progress") = py::none(),
           "budget=True (budget=False: run anyway) refuses at once T/h steps of the modified solution beyond the time "
           "budget; step-by-step agreement of the discrete solution with the order-K modified solution, started by shooting "
           "(q~(h) = q_1) or naive (v~(0) = v_0)")
      .def("modified_start", &modified_start, py::arg("scheme"), py::arg("order"), py::arg("h"), py::arg("tol") = 1e-13,
           py::arg("params") = py::dict(),
           "the consistent start of the order-K modified solution of `scheme` at step h: {q (= q_0), v (v~(0): the "
           "modified flow from (q_0, v~(0)) passes through the scheme's first step q_1 at t = h), v0 (the system's "
           "initial velocity), shift (max |v - v0|, modified_agreement's v_shift)}; found by shooting (Odeint at tol)")
      .def("all_orders", &all_orders, py::arg("scheme"), py::arg("h"), py::arg("params") = py::dict(),
           py::arg("path") = "fast",
           "a linear system's modified equation to all orders: G = log(M)/h, the generator of the flow through every "
           "step on (q, p), and q'' = A_v q' + A_q q with p eliminated")
      .def("surrogate", &surrogate, py::arg("scheme"), py::arg("order") = 2, py::arg("budget") = 120.0,
           py::arg("step") = 0.1,
           "the surrogate of a formula system for `scheme` to `order` K: a System on which the scheme follows this "
           "system's equations to O(h^(K+1)); its parameter h is the step (integrate sets it to its h)")
      .def_property_readonly("surrogate_info", &surrogate_info,
                             "how a surrogate was built: its corrections (terms), certification (checks, defect) and file")
      .def("__repr__", [](const System& s) {
        return "<geomint.System " + s.info().name + ": n = " + std::to_string(s.info().dof) + ", m = " +
               std::to_string(s.info().constraints) + (s.is_formula() ? ", from formulas>" : ">");
      });

  m.def("system", [](const std::string& name) { return System(find_system(name)); }, py::arg("name"),
        "a system of the registry by name");
  m.def("load_system", &load_system, py::arg("path"), py::arg("strict_herglotz") = false, py::arg("time_transform") = py::none(),
        "a system from a .geomint file (docs/systems/README.md); time_transform: a monitor g (formula in t, q1.., v1..) "
        "in place of the file's, dt = g dsigma (docs/time-transformation.md). A shape (n, m) the build did not compile "
        "is compiled here at its first use (compiled_formula_shapes; Ctrl-C stops it)");
  m.def("define_system", &define_system, py::arg("name"), py::arg("coordinates"), py::arg("L"), py::arg("herglotz") = py::none(),
        py::arg("force") = py::none(), py::arg("energy") = py::none(), py::arg("constraints") = py::none(),
        py::arg("holonomic") = false, py::arg("parameters") = py::dict(), py::arg("definitions") = py::dict(),
        py::arg("initial_q") = py::none(), py::arg("initial_v") = py::none(), py::arg("description") = "",
        py::arg("strict_herglotz") = false, py::arg("time_transform") = py::none(), py::arg("t0") = py::none(),
        py::arg("z0") = py::none(), py::arg("exact_q") = py::none(), py::arg("exact_v") = py::none(),
        "a system from its formulas (strings; numbers for constants): the Lagrangian L, the Herglotz Lagrangian, the "
        "force (n formulas), the constraint rows (phi: linear in v1..vn; or holonomic g), parameters {name: value or "
        "(value, doc)} with T the horizon, definitions, the initial q and v, and a time transformation dt = g dsigma "
        "(time_transform = g, a formula in t, q1.., v1..: the system steps in sigma with the time t as coordinate n + 1), "
        "the start t0 and initial action z0 (constants; 0 by default), and an exact solution exact_q (n formulas in t, "
        "checked against the equations here; exact_v: its velocities, else their derivatives) for reference='exact'");
  m.def("_seconds_of_run", &seconds_of_run, py::arg("system"), py::arg("scheme"), py::arg("h"), py::arg("params") = py::dict(),
        py::arg("path") = "fast", py::arg("every") = 1, py::arg("reps") = 5,
        "median seconds of the registry's run timed in C++ (the bench's reference for integrate called from Python)");
}
