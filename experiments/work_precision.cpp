// Work–precision diagram for the damped oscillator (T = 50): max-norm error in q against the closed-form
// solution, versus CPU time. Fixed-step methods are swept over h, adaptive ones (Odeint dopri5 and
// Bulirsch–Stoer, GSL rk8pd) over tolerance; adaptive errors are the max over the steps each method chose
// (no forced output grid, which would cap their step size). Each time is the median of repeated runs
// after a warm-up.
//   work_precision [--alpha 0.01 0.1 1] [--reps 5] [--out out]
// Writes out/work_precision.tsv (errors: reproducible), out/work_precision_timings.tsv (timings) and
// out/work_precision.{png,pdf}.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include <boost/numeric/odeint.hpp>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include "geomint/cli.hpp"
#include "geomint/error.hpp"
#include "geomint/integrate.hpp"
#include "geomint/io.hpp"
#include "geomint/oscillator_schemes.hpp"
#include "geomint/plots/figure.hpp"
#include "geomint/study.hpp"
#include "geomint/timing.hpp"

using namespace geomint;
namespace odeint = boost::numeric::odeint;
using State2 = std::array<double, 2>;

namespace {

struct Point {
  std::string method, knob;
  double alpha, param, err;
  long steps;
  TimingStats time;
};

const double T = 50, q0 = -0.25, p0 = 0.75;

template <class S>
Point fixed_step(const std::string& name, double alpha, double h, int reps) {
  const long N = step_count(h, T);
  double err = 0;
  {
    OscState<double> s{q0, p0, 0};
    integrate_const<S>(s, h, N, alpha, [&](long j, const OscState<double>& x) {
      err = std::max(err, std::abs(x.q - oscillator_exact(alpha, q0, p0, static_cast<double>(j) * h).q));
    });
  }
  const auto t = time_per_call(
      [&] {
        OscState<double> s{q0, p0, 0};
        integrate_const<S>(s, h, N, alpha, [](long, const OscState<double>&) {});
        do_not_optimize(s.q);
      },
      reps);
  return {name, "h", alpha, h, err, N, t};
}

Point odeint_rk4(double alpha, double h, int reps) {
  const long N = step_count(h, T);
  auto sys = [alpha](const State2& x, State2& dx, double) { dx = {x[1], -x[0] - alpha * x[1]}; };
  auto run = [&](double* err) {
    odeint::runge_kutta4<State2> st;
    State2 x{q0, p0};
    for (long j = 0; j < N; ++j) {
      st.do_step(sys, x, static_cast<double>(j) * h, h);
      if (err) *err = std::max(*err, std::abs(x[0] - oscillator_exact(alpha, q0, p0, static_cast<double>(j + 1) * h).q));
    }
    do_not_optimize(x[0]);
  };
  double err = 0;
  run(&err);
  return {"odeint-rk4", "h", alpha, h, err, N, time_per_call([&] { run(nullptr); }, reps)};
}

template <class Stepper>
Point odeint_adaptive(const std::string& name, Stepper make, double alpha, double tol, int reps) {
  auto sys = [alpha](const State2& x, State2& dx, double) { dx = {x[1], -x[0] - alpha * x[1]}; };
  double err = 0;
  long steps = 0;
  auto run = [&](bool measure) {
    State2 x{q0, p0};
    auto stepper = make(tol);
    size_t n = odeint::integrate_adaptive(stepper, sys, x, 0.0, T, 0.01, [&](const State2& y, double t) {
      if (measure) err = std::max(err, std::abs(y[0] - oscillator_exact(alpha, q0, p0, t).q));
    });
    if (measure) steps = static_cast<long>(n);
    do_not_optimize(x[0]);
  };
  run(true);
  return {name, "tol", alpha, tol, err, steps, time_per_call([&] { run(false); }, reps)};
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
    gsl_odeiv2_step* st = gsl_odeiv2_step_alloc(gsl_odeiv2_step_rk8pd, 2);
    gsl_odeiv2_control* c = gsl_odeiv2_control_y_new(tol, tol);
    gsl_odeiv2_evolve* ev = gsl_odeiv2_evolve_alloc(2);
    double t = 0, dt = 0.01, y[2] = {q0, p0};
    long n = 0;
    while (t < T) {
      if (gsl_odeiv2_evolve_apply(ev, c, st, &sys, &t, T, &dt, y) != GSL_SUCCESS) {
        err = std::nan("");  // a failed run is a missing point
        break;
      }
      ++n;
      if (measure) err = std::max(err, std::abs(y[0] - oscillator_exact(alpha, q0, p0, t).q));
    }
    if (measure) steps = n;
    gsl_odeiv2_evolve_free(ev);
    gsl_odeiv2_control_free(c);
    gsl_odeiv2_step_free(st);
    do_not_optimize(y[0]);
  };
  run(true);
  return {"gsl-rk8pd", "tol", alpha, tol, err, steps, time_per_call([&] { run(false); }, reps)};
}

}  // namespace

int main(int argc, char** argv) {
  return guarded_main("work_precision", [&] {
    std::vector<double> alphas{0.01, 0.1, 1};
    int reps = 5;
    Cli cli("work_precision", "error against CPU time for the oscillator: geomint schemes and Odeint/GSL baselines");
    cli.options.add_options()("alpha", po::value(&alphas)->multitoken()->default_value(alphas, "0.01 0.1 1"),
                              "damping values")("reps", po::value(&reps)->default_value(reps), "timed repetitions");
    if (!cli.parse(argc, argv)) return 0;
    for (double a : alphas) OscillatorScene{a, q0, p0, T}.validate();
    require(reps >= 1 && reps <= 1000, "reps must be in [1, 1000]");
    const auto dir = prepare_output_dir(cli.out);

    const auto hs = halving_sequence(0.2, 2e-4);
    const std::vector<double> tols{1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12};
    std::vector<Point> pts;
    for (double a : alphas) {
      std::fprintf(stderr, "work_precision: alpha = %g ...\n", a);
      for (double h : hs) {
        pts.push_back(fixed_step<schemes::La>("la", a, h, reps));
        pts.push_back(fixed_step<schemes::Contact>("contact", a, h, reps));
        pts.push_back(fixed_step<schemes::LaMidpoint>("la-midpoint", a, h, reps));
        pts.push_back(fixed_step<schemes::ContactSymmetric>("contact-sym", a, h, reps));
        pts.push_back(fixed_step<schemes::Leapfrog>("leapfrog", a, h, reps));
        pts.push_back(odeint_rk4(a, h, reps));
      }
      for (double tol : tols) {
        pts.push_back(odeint_adaptive(
            "odeint-dopri5",
            [](double t) { return odeint::make_controlled(t, t, odeint::runge_kutta_dopri5<State2>()); }, a, tol, reps));
        pts.push_back(odeint_adaptive(
            "odeint-bulirsch-stoer", [](double t) { return odeint::bulirsch_stoer<State2>(t, t); }, a, tol, reps));
        pts.push_back(gsl_rk8pd(a, tol, reps));
      }
    }
    const Params params{{"alpha", format_list(alphas)}, {"T", "50"}, {"q0", "-0.25"}, {"p0", "0.75"},
                        {"h", format_list(hs)}, {"tol", format_list(tols)}, {"reps", std::to_string(reps)}};
    TsvWriter data(dir / "work_precision.tsv", "work_precision", params,
                   {"method", "alpha", "knob", "value", "steps", "err_max"});
    TsvWriter tim(dir / "work_precision_timings.tsv", "work_precision", params,
                  {"method", "alpha", "knob", "value", "seconds_median", "seconds_min", "seconds_max", "reps"});
    for (const auto& p : pts) {
      data.row(p.method, p.alpha, p.knob, p.param, p.steps, p.err);
      tim.row(p.method, p.alpha, p.knob, p.param, p.time.median, p.time.min, p.time.max, p.time.reps);
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
    fig.title = "Damped oscillator, T = 50: max error in q against CPU time (median)";
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
