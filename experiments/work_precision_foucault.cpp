// Work–precision for the damped Foucault pendulum: max error in q against the closed-form solution versus
// CPU time. Two horizons without anomalies: T = 4 s with the paper's constraint discretization (before the
// first pass through the origin) and T = 100 s with the non-singular 'rotation' discretization (no jumps by
// construction). Fixed-step schemes are swept over h (max over every step); Boost.Odeint's dopri5 on the
// Lagrange–d'Alembert multiplier ODE is swept over tolerance (max over the output grid t = 0.1 j it hits).
//   work_precision_foucault [--alpha 1e-3] [--reps 5] [--out out]
// Writes out/work_precision_foucault.tsv (errors), out/work_precision_foucault_timings.tsv and the figure.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "geomint/cli.hpp"
#include "geomint/error.hpp"
#include "geomint/systems/foucault.hpp"
#include "geomint/io.hpp"
#include "geomint/record.hpp"
#include "geomint/plots/figure.hpp"
#include "geomint/study.hpp"
#include "geomint/timing.hpp"

using namespace geomint;

namespace {

struct Point {
  std::string method, constraint, knob;
  double T, value, err;
  long steps;
  TimingStats time;
};

template <class Sys, class Scheme>
Point scheme_point(const std::string& name, const Sys& sc, double T, double h, int reps) {
  const FoucaultParams<double> p(sc);
  const Vec2<double> q0(sc.x0, sc.y0), v0(sc.vx0, sc.vy0);
  const Vec2<double> v0c = consistent_velocity(p, q0, v0);
  const long N = step_count(h, T);
  double err = 0;
  systems::run_closed_form<Scheme>(sc, p, q0, v0, h, N, FoucaultStart::legendre, [&](const FoucaultStep<double>& st) {
    const double t = static_cast<double>(st.j + 1) * h;
    err = std::max(err, (st.qn - foucault_exact(p, q0, v0c, t).q).template lpNorm<Eigen::Infinity>());
  });
  const auto tm = time_per_call([&] {
    double acc = 0;
    systems::run_closed_form<Scheme>(sc, p, q0, v0, h, N, FoucaultStart::legendre,
                                     [&](const FoucaultStep<double>& st) { acc += st.qn(0); });
    do_not_optimize(acc);
  }, reps);
  return {name, Sys::discretization, "h", T, h, err, N, tm};
}

// The closed form of `name` on system Sys (its constraint row) against the closed-form solution.
template <class Sys>
Point scheme_point(const std::string& name, const Sys& sc, double T, double h, int reps) {
  Point pt;
  generic::visit_closed_form<Sys>(name, [&](auto c) { pt = scheme_point<Sys, decltype(c)>(name, sc, T, h, reps); });
  return pt;
}

Point odeint_point(const systems::FoucaultPendulum& sc, double T, double tol, int reps) {
  const FoucaultParams<double> p(sc);
  const Vec2<double> q0(sc.x0, sc.y0), v0(sc.vx0, sc.vy0);
  const Vec2<double> v0c = consistent_velocity(p, q0, v0);
  std::vector<double> times;
  for (long j = 0; j <= std::lround(T / 0.1); ++j) times.push_back(0.1 * static_cast<double>(j));
  const auto ref = foucault_reference(sc, times, tol);
  double err = 0;
  for (size_t j = 0; j < times.size(); ++j) {
    const auto ex = foucault_exact(p, q0, v0c, times[j]).q;
    err = std::max({err, std::abs(ref[j][0] - ex(0)), std::abs(ref[j][1] - ex(1))});
  }
  const auto tm = time_per_call([&] { do_not_optimize(foucault_reference(sc, times, tol).back()[0]); }, reps);
  return {"odeint-dopri5", "ode", "tol", T, tol, err, static_cast<long>(times.size()), tm};
}

}  // namespace

int main(int argc, char** argv) {
  return guarded_main("work_precision_foucault", [&] {
    double alpha = 1e-3;
    int reps = 5;
    Cli cli("work_precision_foucault", "error against CPU time for the Foucault pendulum over anomaly-free horizons");
    cli.options.add_options()("alpha", po::value(&alpha)->default_value(alpha), "damping")(
        "reps", po::value(&reps)->default_value(reps), "timed repetitions");
    if (!cli.parse(argc, argv)) return 0;
    systems::Foucault sc;  // the scene; on foucault-rotation below with the same parameters
    sc.alpha = alpha;
    sc.validate();
    systems::FoucaultRotation sc_rotation;
    static_cast<systems::FoucaultPendulum&>(sc_rotation) = sc;
    require(reps >= 1 && reps <= 1000, "reps must be in [1, 1000]");
    const auto dir = prepare_output_dir(cli.out);

    const auto hs = halving_sequence(0.1, 4e-4);
    const std::vector<double> tols{1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12};
    // the paper's constraint before the first pass through the origin, the remedy over 100 s
    struct Horizon {
      double T;
      std::string con;  // the system's discretization of (13)
    };
    const Horizon horizons[] = {{4, systems::Foucault::discretization}, {100, systems::FoucaultRotation::discretization}};
    std::vector<Point> pts;
    for (const auto& hz : horizons) {
      std::fprintf(stderr, "work_precision_foucault: T = %g s ...\n", hz.T);
      // A run that fails is a missing point (nan error and times); the sweep goes on.
      const double nan = missing_value;
      auto missing = [&](const std::string& method, const char* knob, double value, long steps) {
        return [&, method, knob, value, steps] {
          return Point{method, hz.con, knob, hz.T, value, nan, steps, {nan, nan, nan, reps}};
        };
      };
      auto where = [&](const std::string& method, const char* knob, double value) {
        return method + " constraint=" + hz.con + " T=" + show(hz.T) + " alpha=" + show(alpha) + " " + knob +
               "=" + show(value);
      };
      for (double h : hs) {
        const long N = step_count(h, hz.T);
        for (const std::string name : {"la-nh", "contact-nh"})  // (15), (18) under the paper's names
          pts.push_back(run_or_missing(where(name, "h", h),
                                       [&] {
                                         return hz.con == systems::Foucault::discretization
                                                    ? scheme_point(name, sc, hz.T, h, reps)
                                                    : scheme_point(name, sc_rotation, hz.T, h, reps);
                                       },
                                       missing(name, "h", h, N)));
      }
      for (double tol : tols)
        pts.push_back(run_or_missing(where("odeint-dopri5", "tol", tol), [&] { return odeint_point(sc, hz.T, tol, reps); },
                                     [&] {
                                       Point p = missing("odeint-dopri5", "tol", tol, 0)();
                                       p.constraint = "ode";
                                       return p;
                                     }));
    }
    const Params params{{"alpha", format_number(alpha)}, {"T", "4 (constraint paper), 100 (constraint rotation)"},
                        {"h", format_list(hs)}, {"tol", format_list(tols)}, {"start", "legendre"},
                        {"error", "max |q - q_exact| over every step (schemes) or over t = 0.1 j (odeint)"},
                        {"reps", std::to_string(reps)}};
    TsvWriter data(dir / "work_precision_foucault.tsv", "work_precision_foucault", params,
                   {"method", "constraint", "T", "knob", "value", "steps", "err_max"});
    TsvWriter tim(dir / "work_precision_foucault_timings.tsv", "work_precision_foucault", params,
                  {"method", "constraint", "T", "knob", "value", "seconds_median", "seconds_min", "seconds_max", "reps"});
    for (const auto& p : pts) {
      data.row(p.method, p.constraint, p.T, p.knob, p.value, p.steps, p.err);
      tim.row(p.method, p.constraint, p.T, p.knob, p.value, p.time.median, p.time.min, p.time.max, p.time.reps);
    }
    data.commit();
    tim.commit();

    const auto d = plots::read_tsv(dir / "work_precision_foucault.tsv");
    const auto tt = plots::read_tsv(dir / "work_precision_foucault_timings.tsv");
    std::printf("CPU time to reach max error <= 1e-6 m (median, microseconds)\n");
    plots::Figure fig;
    fig.title = "Foucault pendulum, alpha = " + format_number(alpha) + ": max error in q against CPU time (median)";
    fig.cols = 2;
    fig.width_in = 11;
    fig.height_in = 4.6;
    for (const auto& hz : horizons) {
      plots::Panel panel;
      panel.setup = "set logscale xy\nset format x '10^{%L}'\nset format y '10^{%L}'\nset xlabel 'CPU time per run (s)'\n"
                    "set ylabel 'max error in q (m)'\nset key bottom left\nset title 'T = " + format_number(hz.T) +
                    " s, constraint " + hz.con + "'\n";
      for (const std::string m : {"la-nh", "contact-nh", "odeint-dopri5"}) {
        auto keep = [&](size_t i) { return d.text(i, "method") == m && d.number(i, "T") == hz.T; };
        const auto x = tt.numbers("seconds_median", keep), y = d.numbers("err_max", keep);
        double best = INFINITY;
        for (size_t i = 0; i < x.size(); ++i)
          if (y[i] <= 1e-6) best = std::min(best, x[i]);
        std::printf("  T = %-4g %-14s %10s\n", hz.T, m.c_str(),
                    std::isfinite(best) ? format_number(std::round(best * 1e7) / 10).c_str() : "-");
        panel.series.push_back({x, y, m, plots::style_for(m == "odeint-dopri5" ? "reference" : m, "linespoints")});
      }
      fig.panels.push_back(std::move(panel));
    }
    fig.draw(dir / "work_precision_foucault");
    return 0;
  });
}
