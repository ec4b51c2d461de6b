// Work–precision diagram: max-norm error in q against CPU time. With the default --system oscillator it is the
// paper's damped oscillator (T = 50) against the closed-form solution, its schemes from the oscillator registry;
// with any other --system, every scheme built from that system against its reference (closed form or a tight
// Odeint solution), with Odeint baselines on the equations derived from its Lagrangian (rk4 over h; dopri5 and
// Bulirsch–Stoer with dense output over tolerances, their errors taken at the reference grid). Fixed-step methods are swept over h, adaptive ones (Odeint dopri5 and
// Bulirsch–Stoer, GSL rk8pd) over tolerance; adaptive errors are the max over the steps each method chose
// (no forced output grid, which would cap their step size). Each time is the median of repeated runs
// after a warm-up.
//   work_precision [--alpha 0.01 0.1 1] [--h-max 0.2] [--h-min 2e-4] [--reps 5] [--out out]
//   work_precision --system pendulum [--schemes ...] [--h-max 0.1] [--h-min 1e-3] [--reps 5] [parameters]
// Writes out/work_precision.tsv (errors: reproducible), out/work_precision_timings.tsv (timings) and
// out/work_precision.{png,pdf}; for another system, out/<system>_work_precision{,_timings}.tsv and a figure.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include <boost/numeric/odeint.hpp>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include "geomint/budget.hpp"
#include "geomint/cli.hpp"
#include "geomint/error.hpp"
#include "geomint/gsl_evolve.hpp"
#include "geomint/io.hpp"
#include "geomint/reference.hpp"
#include "geomint/record.hpp"
#include "geomint/registry.hpp"
#include "geomint/system_cli.hpp"
#include "geomint/systems/oscillator.hpp"
#include "geomint/plots/figure.hpp"
#include "geomint/study.hpp"
#include "geomint/timing.hpp"
#include "geomint/work_precision.hpp"
#include "geomint/step_cost.hpp"

using namespace geomint;
namespace odeint = boost::numeric::odeint;
using State2 = std::array<double, 2>;

namespace {

// A point of the study (work_precision.hpp): errors = {max_j |q_j - q(t_j)|}, group = alpha; its step count is
// known before the run (0 for the adaptive methods), and stays in the table where the run fails.
using Point = WorkPoint;
Point point(const std::string& method, const std::string& family, const std::string& knob, double alpha, double value,
            long steps) {
  Point p = work_point(method, family, knob, value, alpha);
  p.steps = steps;
  return p;
}
// How a missing point of the oscillator's study is named on stderr.
std::string context(const std::string& method, double alpha, const char* knob, double value) {
  return method + " alpha=" + show(alpha) + " " + knob + "=" + show(value);
}

// The oscillator's scene (the paper's; --q0, --p0, --T change it).
double T = 50, q0 = -0.25, p0 = 0.75;
ParamValues scene(double alpha) { return {{"alpha", alpha}, {"q0", q0}, {"p0", p0}, {"T", T}}; }
double exact_q(double alpha, double t) {
  return systems::Oscillator{alpha, q0, p0, T}.exact<double>(t).q(0);
}

// A scheme of the registry's oscillator (its closed form) against the closed-form solution.
Point fixed_step(const std::string& name, double alpha, double h, int reps) {
  const SystemInfo& osc = find_system("oscillator");
  const long N = step_count(h, T);
  return measure_point_timed(
      point(name, "geometric", "h", alpha, h, N), 1,
      [&] {
        return Measured{{osc.max_error(scene(alpha), name, h, Path::fast, osc.reference(scene(alpha), h, N, ReferenceKind::exact, 0))},
                        N};
      },
      [&] { return osc.time_run(scene(alpha), name, h, Path::fast, reps); }, reps, context(name, alpha, "h", h));
}

Point odeint_rk4(double alpha, double h, int reps) {
  const long N = step_count(h, T);
  auto sys = [alpha](const State2& x, State2& dx, double) { dx = {x[1], -x[0] - alpha * x[1]}; };
  auto run = [&](double* err) {
    odeint::runge_kutta4<State2> st;
    State2 x{q0, p0};
    for (long j = 0; j < N; ++j) {
      st.do_step(sys, x, static_cast<double>(j) * h, h);
      if (err) *err = std::max(*err, std::abs(x[0] - exact_q(alpha, static_cast<double>(j + 1) * h)));
    }
    do_not_optimize(x[0]);
  };
  return measure_point_timed(
      point("odeint-rk4", "rk", "h", alpha, h, N), 1,
      [&] {
        double err = 0;
        run(&err);
        return Measured{{err}, N};
      },
      [&] { return time_per_call([&] { run(nullptr); }, reps); }, reps, context("odeint-rk4", alpha, "h", h));
}

template <class Stepper>
Point odeint_adaptive(const std::string& name, Stepper make, double alpha, double tol, int reps) {
  auto sys = [alpha](const State2& x, State2& dx, double) { dx = {x[1], -x[0] - alpha * x[1]}; };
  double err = 0;
  long steps = 0;
  auto run = [&](bool measure) {
    State2 x{q0, p0};
    auto stepper = make(tol);
    long accepted = 0;
    size_t n = odeint::integrate_adaptive(stepper, sys, x, 0.0, T, 0.01, [&](const State2& y, double t) {
      check_adaptive_steps(++accepted, t, T);
      if (measure) err = std::max(err, std::abs(y[0] - exact_q(alpha, t)));
    });
    if (measure) steps = static_cast<long>(n);
    do_not_optimize(x[0]);
  };
  return measure_point_timed(
      point(name, "adaptive", "tol", alpha, tol, 0), 1,
      [&] {
        run(true);
        return Measured{{err}, steps};
      },
      [&] { return time_per_call([&] { run(false); }, reps); }, reps, context(name, alpha, "tol", tol));
}

int gsl_rhs(double, const double y[], double f[], void* params) {
  const double alpha = *static_cast<double*>(params);
  f[0] = y[1];
  f[1] = -y[0] - alpha * y[1];
  return GSL_SUCCESS;
}

Point gsl_rk8pd(double alpha, double tol, int reps) {
  double err = 0;
  long steps = 0;
  auto run = [&](bool measure) {
    double a = alpha;
    gsl_odeiv2_system sys{gsl_rhs, nullptr, 2, &a};
    GslEvolve gsl(gsl_odeiv2_step_rk8pd, 2, tol, tol);
    double t = 0, dt = 0.01, y[2] = {q0, p0};
    long n = 0;
    while (t < T) {
      if (gsl.apply(sys, t, T, dt, y) != GSL_SUCCESS) {
        err = missing_value;  // a failed run is a missing point
        break;
      }
      check_adaptive_steps(++n, t, T);
      if (measure) err = std::max(err, std::abs(y[0] - exact_q(alpha, t)));
    }
    if (measure) steps = n;
    do_not_optimize(y[0]);
  };
  return measure_point_timed(
      point("gsl-rk8pd", "adaptive", "tol", alpha, tol, 0), 1,
      [&] {
        run(true);
        return Measured{{err}, steps};
      },
      [&] { return time_per_call([&] { run(false); }, reps); }, reps, context("gsl-rk8pd", alpha, "tol", tol));
}

}  // namespace

int generic_work_precision(const Cli& cli, const SystemOptions& sysopt, const std::vector<std::string>& names,
                           const std::vector<double>& hs, int reps);

int main(int argc, char** argv) {
  return guarded_main("work_precision", [&] {
    int reps = 5;
    // the step sizes' defaults depend on the system (the paper's oscillator sweeps further), so a value given is
    // told apart from none: every value given is checked and used, whatever the system
    double h_max = 0, h_min = 0;
    bool h_max_given = false, h_min_given = false;
    std::vector<std::string> names;
    Cli cli("work_precision", "error against CPU time: geomint schemes and Odeint/GSL baselines");
    SystemOptions sysopt(cli, argc, argv, "oscillator", true);
    cli.options.add_options()("reps", po::value(&reps)->default_value(reps), "timed repetitions")(
        "schemes", po::value(&names)->multitoken(), "schemes (other systems; default: every scheme of the system)")(
        "h-max", po::value(&h_max)->notifier([&](double) { h_max_given = true; }),
        "largest step (default 0.2 on the oscillator, 0.1 on other systems)")(
        "h-min", po::value(&h_min)->notifier([&](double) { h_min_given = true; }),
        "halve until h <= h-min (default 2e-4 on the oscillator, 1e-3 on other systems)");
    if (!cli.parse(argc, argv)) return 0;
    require(reps >= 1 && reps <= 1000, "reps must be in [1, 1000]");
    const auto combos = sysopt.combinations();
    const bool oscillator = sysopt.system().name == "oscillator";
    if (!h_max_given) h_max = oscillator ? 0.2 : 0.1;
    if (!h_min_given) h_min = oscillator ? 2e-4 : 1e-3;
    const auto hs = halving_sequence(h_max, h_min);
    if (!oscillator) return generic_work_precision(cli, sysopt, names, hs, reps);
    // The paper's oscillator: alpha 0.01, 0.1, 1 unless given; its first-order schemes and the second-order
    // comparators under the paper's names.
    require(names.empty(), "work_precision on the oscillator compares the paper's schemes (drop --schemes)");
    const std::vector<std::string> osc_names{"la", "contact", "la-midpoint", "contact-sym", "leapfrog"};
    std::vector<double> alphas;
    for (const auto& pv : combos) alphas.push_back(param_value(pv, sysopt.system(), "alpha"));
    if (sysopt.swept().empty() && combos.front().end() == std::find_if(combos.front().begin(), combos.front().end(),
                                                                        [](const auto& kv) { return kv.first == "alpha"; }))
      alphas = {0.01, 0.1, 1};
    q0 = param_value(combos.front(), sysopt.system(), "q0");
    p0 = param_value(combos.front(), sysopt.system(), "p0");
    T = param_value(combos.front(), sysopt.system(), "T");
    require(sysopt.swept().empty() || sysopt.swept() == std::vector<std::string>{"alpha"},
            "work_precision on the oscillator sweeps alpha only");
    for (double a : alphas) sysopt.system().validate(scene(a));
    // every h: five schemes and RK4, each run once for its error (the closed form as reference) and reps + 1 times
    // timed; the adaptive baselines' steps are not known before they run (a few thousand per tolerance here)
    for (double h : hs) {
      const long N = step_count(h, T);
      plan_steps(6.0 * static_cast<double>(alphas.size()) * (reps + 2) * static_cast<double>(N),
                 "the sweep (alpha x methods x (reps + 2) x T/h)");
      check_reference_memory(sysopt.system(), ReferenceKind::exact, N);
    }
    const auto dir = prepare_output_dir(cli.out);

    const std::vector<double> tols{1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12};
    std::vector<Point> pts;
    for (double a : alphas) {
      std::fprintf(stderr, "work_precision: alpha = %g ...\n", a);
      // A run that fails is a missing point (nan error and times, measure_point_timed); the sweep goes on.
      for (double h : hs) {
        for (const auto& name : osc_names) pts.push_back(fixed_step(name, a, h, reps));
        pts.push_back(odeint_rk4(a, h, reps));
      }
      for (double tol : tols) {
        pts.push_back(odeint_adaptive(
            "odeint-dopri5", [](double t) { return odeint::make_controlled(t, t, odeint::runge_kutta_dopri5<State2>()); },
            a, tol, reps));
        pts.push_back(odeint_adaptive(
            "odeint-bulirsch-stoer", [](double t) { return odeint::bulirsch_stoer<State2>(t, t); }, a, tol, reps));
        pts.push_back(gsl_rk8pd(a, tol, reps));
      }
    }
    const Params params{{"alpha", format_list(alphas)}, {"T", format_number(T)}, {"q0", format_number(q0)}, {"p0", format_number(p0)},
                        {"h", format_list(hs)}, {"tol", format_list(tols)}, {"reps", std::to_string(reps)}};
    TsvWriter data(dir / "work_precision.tsv", "work_precision", params,
                   {"method", "alpha", "knob", "value", "steps", "err_max"});
    TsvWriter tim(dir / "work_precision_timings.tsv", "work_precision", params,
                  {"method", "alpha", "knob", "value", "seconds_median", "seconds_min", "seconds_max", "reps"});
    for (const auto& p : pts) {
      data.row(p.method, p.group, p.knob, p.value, p.steps, p.errors[0]);
      tim.row(p.method, p.group, p.knob, p.value, p.time.median, p.time.min, p.time.max, p.time.reps);
    }
    data.commit();
    tim.commit();

    // Cheapest time to reach a max error <= 1e-6, per method and alpha.
    std::printf("CPU time to reach max error <= 1e-6 (median, microseconds); '-' = not reached\n%-24s", "method");
    for (double a : alphas) std::printf(" alpha=%-8g", a);
    std::printf("\n");
    const auto d = plots::read_tsv(dir / "work_precision.tsv");
    const auto tt = plots::read_tsv(dir / "work_precision_timings.tsv");
    std::vector<std::string> methods;
    for (const auto& p : pts)
      if (std::find(methods.begin(), methods.end(), p.method) == methods.end()) methods.push_back(p.method);
    for (const auto& m : methods) {
      std::printf("%-24s", m.c_str());
      for (double a : alphas) {
        double best = INFINITY;
        for (size_t r = 0; r < d.rows.size(); ++r)
          if (d.text(r, "method") == m && d.number(r, "alpha") == a && d.number(r, "err_max") <= 1e-6)
            best = std::min(best, tt.number(r, "seconds_median"));
        if (std::isfinite(best))
          std::printf(" %14.1f", best * 1e6);
        else
          std::printf(" %14s", "-");
      }
      std::printf("\n");
    }

    plots::Figure fig;
    fig.title = "Damped oscillator, T = " + format_number(T) + ": max error in q against CPU time (median)";
    fig.cols = static_cast<int>(alphas.size());
    fig.width_in = 4.6 * fig.cols;
    fig.height_in = 4.6;
    for (double a : alphas) {
      plots::Panel p;
      p.setup = "set logscale xy\nset format x '10^{%L}'\nset format y '10^{%L}'\nset xlabel 'CPU time per run (s)'\n"
                "set ylabel 'max error in q'\nset key bottom left font ',8'\nset title 'alpha = " + format_number(a) + "'\n";
      for (const auto& m : methods) {
        auto keep = [&](size_t i) { return d.text(i, "method") == m && d.number(i, "alpha") == a; };
        p.series.push_back({tt.numbers("seconds_median", keep), d.numbers("err_max", keep), m,
                            plots::style_for(m, "linespoints")});
      }
      fig.panels.push_back(std::move(p));
    }
    fig.draw(dir / "work_precision");
    return 0;
  });
}

// Any other system: every scheme built from it over h, Odeint baselines on its AD-derived equations.
int generic_work_precision(const Cli& cli, const SystemOptions& sysopt, const std::vector<std::string>& names,
                           const std::vector<double>& hs, int reps) {
  const SystemInfo& sys = sysopt.system();
  const ParamValues pv = sysopt.values();
  const auto schemes = sysopt.schemes(names);
  const double Tsys = sys.horizon(pv);
  double cost = 0;  // of one step of every scheme, in cheap steps
  for (const auto& s : schemes) cost += step_cost(sys, s, Path::fast);
  for (double h : hs)
    plan_steps((reps + 2) * static_cast<double>(step_count(h, Tsys)), "the sweep (schemes x (reps + 2) x T/h)", cost);
  check_reference_memory(sys, ReferenceKind::automatic, step_count(hs.back(), Tsys));
  const std::vector<double> tols{1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12};
  const auto dir = prepare_output_dir(cli.out);
  const double h_ref = hs.back();
  const long N_ref = step_count(h_ref, Tsys);
  const Reference ref = sys.reference(pv, h_ref, N_ref, ReferenceKind::automatic, 1e-13);
  std::fprintf(stderr, "work_precision: %s, reference %s\n", sys.name.c_str(), ref.kind.c_str());
  const int n = sys.dof;
  std::vector<Point> pts;
  for (const auto& name : schemes)
    for (double h : hs) {
      pts.push_back(measure_point_timed(
          point(name, "geometric", "h", missing_value, h, step_count(h, Tsys)), 1,
          [&] { return Measured{{sys.max_error(pv, name, h, Path::fast, ref)}, step_count(h, Tsys)}; },
          [&] { return sys.time_run(pv, name, h, Path::fast, reps); }, reps, sys.name + " " + name + " h=" + show(h)));
    }
  // Odeint on x = (q, q'), the acceleration derived from L, F and Phi by AD
  using State = std::vector<double>;
  const auto f = sys.ode(pv);
  const State x0 = sys.ode_initial_state(pv);
  auto rhs = [&](const State& x, State& dx, double t) { f(t, x.data(), dx.data()); };
  // adaptive methods are compared on the coarsest grid (h-max): dense output there does not dominate their cost
  const double h_out = hs.front();
  const long N_out = step_count(h_out, Tsys), out_stride = ref.index(1, h_out);
  std::vector<double> times(static_cast<std::size_t>(N_out + 1));
  for (long j = 0; j <= N_out; ++j) times[static_cast<std::size_t>(j)] = static_cast<double>(j) * h_out;
  auto error_of = [&](const std::vector<State>& xs) {
    double e = 0;
    for (std::size_t j = 0; j < xs.size(); ++j)
      for (int i = 0; i < n; ++i)
        e = std::max(e, std::abs(xs[j][static_cast<std::size_t>(i)] - ref.q[j * static_cast<std::size_t>(out_stride * n) + static_cast<std::size_t>(i)]));
    return xs.size() == times.size() ? e : missing_value;
  };
  for (double h : hs) {
    const long N = step_count(h, Tsys);
    const long stride = ref.index(1, h);
    auto run = [&](std::vector<State>* out) {
      odeint::runge_kutta4<State> st;
      State x = x0;
      if (out) out->push_back(x);
      for (long j = 0; j < N; ++j) {
        st.do_step(rhs, x, static_cast<double>(j) * h, h);
        if (out) out->push_back(x);
      }
      do_not_optimize(x[0]);
    };
    pts.push_back(measure_point_timed(
        point("odeint-rk4", "rk", "h", missing_value, h, N), 1,
        [&] {
          std::vector<State> xs;
          run(&xs);
          double e = 0;
          for (long j = 0; j <= N; ++j)
            for (int i = 0; i < n; ++i)
              e = std::max(e, std::abs(xs[static_cast<std::size_t>(j)][static_cast<std::size_t>(i)] -
                                       ref.q[static_cast<std::size_t>(j * stride * n + i)]));
          return Measured{{e}, N};
        },
        [&] { return time_per_call([&] { run(nullptr); }, reps); }, reps, sys.name + " odeint-rk4 h=" + show(h)));
  }
  for (double tol : tols) {
    auto dense = [&](auto stepper, std::vector<State>* out) {
      State x = x0;
      std::size_t k = 0, kept = 0;
      try {
        k = odeint::integrate_times(stepper, rhs, x, times.begin(), times.end(), h_out / 10,
                                    [&](const State& y, double) {
                                      ++kept;
                                      if (out) out->push_back(y);
                                    },
                                    odeint::max_step_checker(odeint_max_steps_between_outputs));
      } catch (const odeint::no_progress_error&) {
        throw_too_stiff("Boost.Odeint (" + std::string(out ? "measured" : "timed") + " run)",
                        kept ? times[kept - 1] : times.front(), kept);
      }
      do_not_optimize(x[0]);
      return static_cast<long>(k);
    };
    // an adaptive run's error and steps (measured), or the same work with nothing kept (timed)
    auto adaptive = [&](const std::string& method, auto make) {
      return measure_point_timed(
          point(method, "adaptive", "tol", missing_value, tol, 0), 1,
          [&] {
            std::vector<State> xs;
            const long steps = dense(make(), &xs);
            return Measured{{error_of(xs)}, steps};
          },
          [&] { return time_per_call([&] { dense(make(), nullptr); }, reps); }, reps,
          sys.name + " " + method + " tol=" + show(tol));
    };
    pts.push_back(adaptive("odeint-dopri5", [&] { return odeint::make_dense_output(tol, tol, odeint::runge_kutta_dopri5<State>()); }));
    pts.push_back(adaptive("odeint-bulirsch-stoer", [&] { return odeint::bulirsch_stoer_dense_out<State>(tol, tol); }));
  }
  Params params = sysopt.header();
  params.insert(params.end(), {{"h", format_list(hs)}, {"tol", format_list(tols)}, {"reps", std::to_string(reps)},
                               {"reference", ref.kind},
                               {"error", "max_j max_i |q_i(t_j) - q_ref,i(t_j)|; adaptive methods: dense output at t = k h-max"}});
  const std::string stem = sys.name + "_work_precision";
  TsvWriter data(dir / (stem + ".tsv"), "work_precision", params, {"system", "method", "knob", "value", "steps", "err_max"});
  TsvWriter tim(dir / (stem + "_timings.tsv"), "work_precision", params,
                {"system", "method", "knob", "value", "seconds_median", "reps"});
  std::vector<std::string> methods;
  for (const auto& p : pts) {
    data.row(sys.name, p.method, p.knob, p.value, p.steps, p.errors[0]);
    tim.row(sys.name, p.method, p.knob, p.value, p.time.median, p.time.reps);
    if (std::find(methods.begin(), methods.end(), p.method) == methods.end()) methods.push_back(p.method);
  }
  data.commit();
  tim.commit();
  const auto d = plots::read_tsv(dir / (stem + ".tsv"));
  const auto tt = plots::read_tsv(dir / (stem + "_timings.tsv"));
  plots::Figure fig;
  fig.title = sys.name + ": max error in q against CPU time (median), T = " + format_number(Tsys);
  fig.width_in = 7;
  fig.height_in = 5;
  plots::Panel p;
  p.setup = "set logscale xy\nset format x '10^{%L}'\nset format y '10^{%L}'\nset xlabel 'CPU time per run (s)'\n"
            "set ylabel 'max error in q'\nset key bottom left font ',8'\n";
  for (const auto& m : methods) {
    auto keep = [&](std::size_t i) { return d.text(i, "method") == m; };
    p.series.push_back({tt.numbers("seconds_median", keep), d.numbers("err_max", keep), m, plots::style_for(m, "linespoints")});
  }
  fig.panels.push_back(std::move(p));
  fig.draw(dir / stem);
  std::printf("CPU time to reach max error <= 1e-6 (median, microseconds); '-' = not reached\n");
  for (const auto& m : methods) {
    double best = INFINITY;
    for (std::size_t r = 0; r < d.rows.size(); ++r)
      if (d.text(r, "method") == m && d.number(r, "err_max") <= 1e-6) best = std::min(best, tt.number(r, "seconds_median"));
    if (std::isfinite(best))
      std::printf("%-24s %14.1f\n", m.c_str(), best * 1e6);
    else
      std::printf("%-24s %14s\n", m.c_str(), "-");
  }
  return 0;
}
