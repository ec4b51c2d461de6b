// Benchmark (make bench): nanoseconds per step of every geomint oscillator scheme against a bare
// hand-written loop of the same formulas and against Boost.Odeint and GSL baselines on the same problem;
// subnormal slow-down and its remedy; on Kepler, the logH leapfrog's step against the leapfrog's closed form. (Ensembles: bench_ensembles.) Timed with Google Benchmark: medians over
// repetitions; every ratio is between medians measured in this run.
//   bench_steps [--steps 2000000] [--reps 9] [--out out] [--benchmark_filter=...]
// Writes out/bench_steps.tsv and out/bench_ratios.tsv (timings: not reproducible bit for bit, by nature).
#include <array>
#include <cmath>
#include <cstdio>
#include <map>

#include <Eigen/LU>
#include <boost/numeric/odeint.hpp>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include "bench_table.hpp"
#include "geomint/cli.hpp"
#include "geomint/error.hpp"
#include "geomint/systems/foucault.hpp"
#include "geomint/gsl_evolve.hpp"
#include "geomint/fp_env.hpp"
#include "geomint/generic/logh.hpp"
#include "geomint/io.hpp"
#include "geomint/systems/kepler.hpp"
#include "geomint/systems/oscillator.hpp"
#include "geomint/timing.hpp"
#include "paper_restatements.hpp"

using namespace geomint;
namespace odeint = boost::numeric::odeint;
using State2 = std::array<double, 2>;

namespace {

// N steps of an oscillator closed form through its system's run loop (what the registry's fast path runs).
template <class S>
double run_library(long N, double h, double alpha) {
  double q = 0;
  systems::Oscillator{alpha, -0.25, 0.75}.run_fast<S>(h, N, [&](const auto& v) { q = v.q(0); });
  do_not_optimize(q);
  return q;
}

int gsl_rhs(double, const double y[], double f[], void* params) {
  const double alpha = *static_cast<double*>(params);
  f[0] = y[1];
  f[1] = -y[0] - alpha * y[1];
  return GSL_SUCCESS;
}

}  // namespace

int main(int argc, char** argv) {
  return guarded_main("bench_steps", [&] {
    auto args = bench::Table::split_args(argc, argv);
    long N = 2000000;
    int reps = 9;
    Cli cli("bench_steps", "ns per step of every scheme, baselines, subnormals");
    cli.options.add_options()("steps", po::value(&N)->default_value(N), "steps per timed run")(
        "reps", po::value(&reps)->default_value(reps), "timed repetitions (median reported)");
    if (!cli.parse(argc, args.data())) return 0;
    // the same limits as the other benchmarks: a timed call of 1e8 steps is seconds, 1000 repetitions of the
    // ~40 cases an hour; beyond that a median says nothing more
    require(N >= 1000 && N <= 100000000, "steps must be in [1000, 1e8]");
    require(reps >= 3 && reps <= 1000, "reps must be in [3, 1000]");
    const auto dir = prepare_output_dir(cli.out);
    const double h = 0.01, alpha = 0.1, tol = 1e-10;
    bench::Table table(reps, 0.05);
    auto add = [&](const std::string& g, const std::string& n, double units, auto fn) { table.add(g, n, units, fn); };

    add("oscillator", "geomint la", N, [&] { run_library<systems::Oscillator::La>(N, h, alpha); });
    add("oscillator", "bare la", N, [&] {
      double q = -0.25, p = 0.75;
      const double c = 1 / (1 + h * alpha);
      for (long j = 0; j < N; ++j) {
        p = (p - h * q) * c;
        q = q + h * p;
      }
      do_not_optimize(q);
    });
    add("oscillator", "geomint contact", N, [&] { run_library<systems::Oscillator::Contact>(N, h, alpha); });
    add("oscillator", "bare contact", N, [&] {
      double q = -0.25, p = 0.75, z = 0;
      const double inv_h = 1 / h;
      for (long j = 0; j < N; ++j) {
        const double qn = (1 - h * h / 2) * q + h * (1 - h * alpha) * p;
        const double v = (qn - q) * inv_h;
        z = z + h * (v * v / 2 - (q * q + qn * qn) / 4 - alpha * z);
        p = (1 - h * alpha) * p - h / 2 * (qn + q);
        q = qn;
      }
      do_not_optimize(q);
      do_not_optimize(z);
    });
    add("oscillator", "geomint la-printed", N, [&] { run_library<systems::Oscillator::LaPrinted>(N, h, alpha); });
    add("oscillator", "geomint la-midpoint", N, [&] { run_library<systems::Oscillator::LaMidpoint>(N, h, alpha); });
    add("oscillator", "geomint contact-sym", N, [&] { run_library<systems::Oscillator::ContactSymmetric>(N, h, alpha); });
    add("oscillator", "geomint leapfrog", N, [&] { run_library<systems::Oscillator::Leapfrog>(N, h, alpha); });

    auto sys = [alpha](const State2& x, State2& dx, double) {
      dx[0] = x[1];
      dx[1] = -x[0] - alpha * x[1];
    };
    add("oscillator", "odeint runge_kutta4", N, [&] {
      odeint::runge_kutta4<State2> st;
      State2 x{-0.25, 0.75};
      for (long j = 0; j < N; ++j) st.do_step(sys, x, static_cast<double>(j) * h, h);
      do_not_optimize(x[0]);
    });
    // Adaptive baselines: integrate to T and divide by the number of steps they took.
    const double Tad = 2000;
    size_t steps_dopri = 0, steps_bs = 0, steps_gsl = 0;
    {
      State2 x{-0.25, 0.75};
      steps_dopri = odeint::integrate_adaptive(odeint::make_controlled(tol, tol, odeint::runge_kutta_dopri5<State2>()),
                                               sys, x, 0.0, Tad, 0.01);
      State2 y{-0.25, 0.75};
      odeint::bulirsch_stoer<State2> bs(tol, tol);
      steps_bs = odeint::integrate_adaptive(bs, sys, y, 0.0, Tad, 0.01);
    }
    add("oscillator", "odeint dopri5 (tol 1e-10)", static_cast<double>(steps_dopri), [&] {
      State2 x{-0.25, 0.75};
      odeint::integrate_adaptive(odeint::make_controlled(tol, tol, odeint::runge_kutta_dopri5<State2>()), sys, x, 0.0,
                                 Tad, 0.01);
      do_not_optimize(x[0]);
    });
    add("oscillator", "odeint bulirsch_stoer (1e-10)", static_cast<double>(steps_bs), [&] {
      State2 x{-0.25, 0.75};
      odeint::bulirsch_stoer<State2> bs(tol, tol);
      odeint::integrate_adaptive(bs, sys, x, 0.0, Tad, 0.01);
      do_not_optimize(x[0]);
    });
    auto gsl_run = [&](size_t* count) {
      double a = alpha;
      gsl_odeiv2_system gs{gsl_rhs, nullptr, 2, &a};
      GslEvolve gsl(gsl_odeiv2_step_rk8pd, 2, tol, tol);
      double t = 0, dt = 0.01, y[2] = {-0.25, 0.75};
      size_t n = 0;
      while (t < Tad) {
        if (gsl.apply(gs, t, Tad, dt, y) != GSL_SUCCESS) break;
        ++n;
      }
      do_not_optimize(y[0]);
      if (count) *count = n;
    };
    gsl_run(&steps_gsl);
    add("oscillator", "GSL rk8pd (tol 1e-10)", static_cast<double>(steps_gsl), [&] { gsl_run(nullptr); });

    // Foucault pendulum (15): the library loop, a bare closed-form loop, and the literal 3x3 system
    // solved by Eigen's PartialPivLU (what a generic implementation would do).
    {
      systems::Foucault sc;
      sc.alpha = 1e-4;
      const FoucaultParams<double> fp(sc);
      const double hp = 0.1;
      const long Np = std::max(1000L, N / 10);
      const Vec2<double> q0(sc.x0, sc.y0), v0(sc.vx0, sc.vy0);
      add("pendulum", "geomint la-nh", Np, [&] {
        double acc = 0;
        systems::run_closed_form<systems::Foucault::La>(sc, fp, q0, v0, hp, Np, FoucaultStart::legendre,
                                                        [&](const FoucaultStep<double>& st) { acc += st.lambda1; });
        do_not_optimize(acc);
      });
      const Vec2<double> qm0 = systems::Foucault::La::previous_point(fp, q0, v0, hp, FoucaultStart::legendre);
      add("pendulum", "bare la-nh closed form", Np, [&] {
        const double c = 1 / hp + fp.alpha, ic = 1 / c, ih = 1 / hp, w2 = fp.w2, s = fp.s;
        double xm = qm0(0), ym = qm0(1), x = q0(0), y = q0(1), acc = 0;
        for (long j = 0; j < Np; ++j) {
          const double r2 = x * x + y * y;
          const double lm = c * s * hp + (xm * y - ym * x) / (hp * r2);
          const double xn = x + ((x - xm) * ih - hp * w2 * x + lm * y) * ic;
          const double yn = y + ((y - ym) * ih - hp * w2 * y - lm * x) * ic;
          acc += lm;
          xm = x; ym = y; x = xn; y = yn;
        }
        do_not_optimize(acc);
        do_not_optimize(x);
      });
      add("pendulum", "la-nh via PartialPivLU 3x3", Np, [&] {
        Vec2<double> qm = qm0, q = q0, qn;
        double acc = 0;
        for (long j = 0; j < Np; ++j) {
          const auto ls = testing::paper_system<systems::Foucault::La>(fp, qm, q, hp);
          const Eigen::Vector3d sol = Eigen::PartialPivLU<Eigen::Matrix3d>(ls.A).solve(ls.b);
          qn = sol.head<2>();
          acc += sol(2);
          qm = q;
          q = qn;
        }
        do_not_optimize(acc);
        do_not_optimize(q(0));
      });
    }

    // Kepler (e = 0.4, h = 2 pi/128): a step of the logH leapfrog (generic/logh.hpp, at h in sigma) against the
    // leapfrog's closed form (Störmer–Verlet, kick-drift-kick: the la-trapezoid's closed form on Kepler without
    // friction), without friction and with alpha = 1e-5 (the leapfrog then scales p by exp(-alpha h/2) on each
    // side, the factor hoisted out of the loop; the logH step cannot hoist it: its dt varies). One force
    // evaluation a step each.
    {
      const long Nk = std::max(1000L, N / 4);
      const double hk = 6.283185307179586 / 128;
      for (const double ak : {0.0, 1e-5}) {
        systems::Kepler kep;
        kep.a = 0;
        kep.alpha = ak;
        const std::string tag = ak == 0 ? "" : ", friction";
        const Vec<double, 2> q0 = kep.initial_position<double>(), v0 = kep.initial_velocity<double>();
        add("kepler", "kepler leapfrog closed form" + tag, Nk, [=] {
          const double damp = std::exp(-ak * hk / 2);
          double x = q0(0), y = q0(1), u = v0(0), v = v0(1);
          auto accel = [](double x_, double y_, double& ax, double& ay) {
            const double r2 = x_ * x_ + y_ * y_, ir3 = 1 / (r2 * std::sqrt(r2));
            ax = -x_ * ir3;
            ay = -y_ * ir3;
          };
          double ax, ay;
          accel(x, y, ax, ay);
          for (long j = 0; j < Nk; ++j) {
            u = (u * damp + hk / 2 * ax);
            v = (v * damp + hk / 2 * ay);
            x += hk * u;
            y += hk * v;
            accel(x, y, ax, ay);
            u = (u + hk / 2 * ax) * damp;
            v = (v + hk / 2 * ay) * damp;
          }
          do_not_optimize(x);
          do_not_optimize(u);
        });
        add("kepler", "kepler logh step" + tag, Nk, [=] {
          generic::Logh<systems::Kepler> lg(kep, hk);
          lg.start(q0, v0);
          for (long j = 0; j < Nk; ++j) lg.step();
          do_not_optimize(lg.state().q(0));
        });
      }
    }

    // Subnormals: alpha = 1 over t in [0, 1e5] decays below DBL_MIN at t ~ 1400 and stays subnormal.
    const double hs = 0.01;
    const long Ns = static_cast<long>(1e5 / hs);
    add("subnormal", "contact, plain", Ns, [&] { run_library<systems::Oscillator::Contact>(Ns, hs, 1.0); });
    add("subnormal", "contact, flush-to-zero", Ns, [&] {
      ScopedFlushToZero ftz;
      run_library<systems::Oscillator::Contact>(Ns, hs, 1.0);
    });
    add("subnormal", "la, plain", Ns, [&] { run_library<systems::Oscillator::La>(Ns, hs, 1.0); });
    add("subnormal", "la, flush-to-zero", Ns, [&] {
      ScopedFlushToZero ftz;
      run_library<systems::Oscillator::La>(Ns, hs, 1.0);
    });

    std::printf("oscillator alpha = %g, h = %g, %ld steps per run; pendulum h = 0.1, alpha = 1e-4; subnormals alpha = 1, "
                "h = %g, t in [0, 1e5] (%ld steps); median of %d\n", alpha, h, N, hs, Ns, reps);
    table.run();

    std::map<std::string, double> ns;
    for (const auto& r : table.rows()) ns[r.name] = r.ns();
    struct Ratio {
      std::string what;
      double value, target;
      bool less;  // value must be <= target (else >=)
    };
    const std::vector<Ratio> ratios = {
        {"geomint la / bare la", ns["geomint la"] / ns["bare la"], 1.2, true},
        {"geomint contact / bare contact", ns["geomint contact"] / ns["bare contact"], 1.2, true},
        {"geomint la-nh / bare closed form", ns["geomint la-nh"] / ns["bare la-nh closed form"], 1.5, true},
        {"PartialPivLU / geomint la-nh", ns["la-nh via PartialPivLU 3x3"] / ns["geomint la-nh"], 4, false},
        {"contact plain / flush-to-zero (alpha=1, 1e5)", ns["contact, plain"] / ns["contact, flush-to-zero"], 0, false},
        {"la plain / flush-to-zero (alpha=1, 1e5)", ns["la, plain"] / ns["la, flush-to-zero"], 0, false},
        {"kepler logh step / leapfrog closed form", ns["kepler logh step"] / ns["kepler leapfrog closed form"], 2, true},
        {"kepler logh step / leapfrog, friction 1e-5", ns["kepler logh step, friction"] / ns["kepler leapfrog closed form, friction"], 2, true},
        {"quoted NumPy loop 1.8 us / geomint contact", 1800.0 / ns["geomint contact"], 300, false},
        {"quoted scipy fsolve 30 us / geomint contact", 30000.0 / ns["geomint contact"], 2000, false},
    };
    std::printf("\nratios (medians of this run)\n");
    for (const auto& r : ratios) {
      const bool ok = r.target == 0 || (r.less ? r.value <= r.target : r.value >= r.target);
      std::printf("  %-46s %9.2f %s\n", r.what.c_str(), r.value,
                  r.target == 0 ? "" : (ok ? "(target met)" : "(TARGET MISSED)"));
    }

    const Params params{{"steps", std::to_string(N)}, {"reps", std::to_string(reps)}, {"h", format_number(h)},
                        {"alpha", format_number(alpha)}, {"adaptive tol", format_number(tol)},
                        {"note", "timings (Google Benchmark); medians over reps"}};
    table.write_tsv(dir / "bench_steps.tsv", "bench_steps", params);
    TsvWriter rt(dir / "bench_ratios.tsv", "bench_steps", params, {"ratio", "value", "target"});
    for (const auto& r : ratios) rt.row(r.what, r.value, r.target == 0 ? std::string("-") : (r.less ? "<= " : ">= ") + format_number(r.target));
    rt.commit();
    return 0;
  });
}
