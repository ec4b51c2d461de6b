// Long-horizon work–precision for the forced damped oscillator q'' + alpha q' + q = beta sin(omega t) of the
// generic core (core/include/geomint/systems/forced_oscillator.hpp), started on its steady state
// q_ss = C sin(omega t - delta): steady-state amplitude and phase error against the closed form, against CPU time.
// Over the second half of the horizon (where a method's own transient, started from the exact steady state, has
// decayed by e^{-alpha T/4}) q is fitted by least squares (GSL) to A sin(omega t) + B cos(omega t) + c:
//   amp_err    |sqrt(A^2 + B^2) - C| / C
//   phase_err  |atan2(-B, A) - delta| (rad)
// Methods: every scheme the registry builds for the system (fast paths) and compositions of order 4, 6 and 8 of
// la-trapezoid (generic steps; --schemes names others), and Odeint rk4, over steps per forcing period; Odeint
// dopri5, Bulirsch–Stoer and GSL rk8pd over tolerance (abs = rel) on the equation written by hand.
//   long_horizon --system forced-oscillator [--periods 100 300] [--m 8 16 32 64 128] [--tol 1e-5 1e-7 1e-9 1e-11] [--reps 3]
//                       [--schemes ...] [--alpha 0.1] [--beta 0.3] [--omega 1.0471975511965976] [--out out]
// The study in docs/speed-accuracy.md:
//   long_horizon --system forced-oscillator --periods 100 1000 10000 --m 8 16 32 64 128 256 512 --tol 1e-5 1e-7 1e-9 1e-11
// With the default omega = pi/3 the forcing period is 6, T = 6 periods and h = 6/m divide exactly; another
// omega needs 2 pi/omega times m to give an h that divides T.
// Writes out/forced-oscillator_long_horizon.tsv (errors: same bits for the same command), _timings.tsv, _summary.tsv and
// the figure out/forced-oscillator_long_horizon.{png,pdf}.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_multifit.h>

#include "geomint/cli.hpp"
#include "geomint/constants.hpp"
#include "geomint/error.hpp"
#include "geomint/io.hpp"
#include "geomint/plots/figure.hpp"
#include "geomint/registry.hpp"
#include "geomint/run/baselines.hpp"
#include "geomint/timing.hpp"
#include "long_horizon/table.hpp"
#include "long_horizon/studies.hpp"

using namespace geomint;
using State2 = std::array<double, 2>;

namespace {


struct Fit {
  double amp = missing_value, phase = missing_value;
  long steps = 0;
};

// Least-squares A sin(w t) + B cos(w t) + c over the samples with t >= t0 (GSL multifit).
class SteadyFit {
 public:
  SteadyFit(double omega, double t0) : w_(omega), t0_(t0) {}
  void point(double t, double q) {
    if (t < t0_) return;
    t_.push_back(t);
    q_.push_back(q);
  }
  Fit result(long steps) const {
    Fit f;
    f.steps = steps;
    const std::size_t n = t_.size();
    if (n < 6) return f;
    gsl_matrix* X = gsl_matrix_alloc(n, 3);
    gsl_vector* y = gsl_vector_alloc(n);
    gsl_vector* c = gsl_vector_alloc(3);
    gsl_matrix* cov = gsl_matrix_alloc(3, 3);
    gsl_multifit_linear_workspace* ws = gsl_multifit_linear_alloc(n, 3);
    for (std::size_t i = 0; i < n; ++i) {
      gsl_matrix_set(X, i, 0, std::sin(w_ * t_[i]));
      gsl_matrix_set(X, i, 1, std::cos(w_ * t_[i]));
      gsl_matrix_set(X, i, 2, 1.0);
      gsl_vector_set(y, i, q_[i]);
    }
    double chisq = 0;
    gsl_multifit_linear(X, y, c, cov, &chisq, ws);
    const double A = gsl_vector_get(c, 0), B = gsl_vector_get(c, 1);
    f.amp = std::hypot(A, B);
    f.phase = std::atan2(-B, A);
    gsl_multifit_linear_free(ws);
    gsl_matrix_free(cov);
    gsl_vector_free(c);
    gsl_vector_free(y);
    gsl_matrix_free(X);
    // a run that grows without bound (contact at alpha h >> 1) can stay finite while its least squares overflow
    if (!std::isfinite(f.amp) || !std::isfinite(f.phase))
      throw NumericalFailure(steps, "steady-state fit",
                             "the least-squares amplitude over t >= " + show(t0_) + " is not finite (|q| up to " +
                                 show(max_abs()) + ")");
    return f;
  }

 private:
  double max_abs() const {
    double m = 0;
    for (double q : q_) m = std::max(m, std::abs(q));
    return m;
  }
  double w_, t0_;
  std::vector<double> t_, q_;
};

// A baseline through the one door (run/baselines.hpp): the steady state fitted from every step it takes (an adaptive
// one's last step lands on T).
Fit baseline_run(BaselineSetup b, const OdeRhs& f, const State2& x0, double T, double omega, bool measure) {
  SteadyFit fit(omega, T / 2);
  b.T = T;
  b.end = BaselineEnd::land;
  const BaselineObserver observe = [&](std::size_t, double t, const double* x) { fit.point(t, x[0]); };
  const BaselineCount n = run_baseline(b, f, {x0[0], x0[1]}, measure ? &observe : nullptr);
  return measure ? fit.result(n.steps) : Fit{};
}

// One point of the study: the steady-state amplitude and phase errors against (C, delta), and the CPU time.
struct Study {
  double C, delta;
  int reps;
  WorkPoint point(const std::string& method, const std::string& family, const std::string& knob, double periods,
                  double value, const std::function<Fit(bool)>& run, const std::function<TimingStats()>& timing) const {
    return measure_point_timed(
        work_point(method, family, knob, value, WorkPoint::nan, periods), 2,
        [&] {
          const Fit f = run(true);
          return Measured{{std::abs(f.amp - C) / C, std::abs(f.phase - delta)}, f.steps};
        },
        timing, reps, method + ", " + show(periods) + " periods, " + knob + " = " + show(value));
  }
};

}  // namespace

int long_horizon_forced(int argc, char** argv) {
  return [&] {
    std::vector<double> periods{100, 300}, ms{8, 16, 32, 64, 128}, tols{1e-5, 1e-7, 1e-9, 1e-11};
    double alpha = 0.1, beta = 0.3, omega = pi / 3;
    int reps = 3;
    std::vector<std::string> schemes;
    Cli cli("long_horizon", "long-horizon steady-state amplitude and phase error against CPU time: forced oscillator");
    add_study_system_option(cli, "forced-oscillator");
    cli.options.add_options()("periods", po::value(&periods)->multitoken(), "horizons in forcing periods (default 100 300)")(
        "m", po::value(&ms)->multitoken(), "steps per forcing period of the fixed-step methods (default 8 .. 128)")(
        "tol", po::value(&tols)->multitoken(), "tolerances (abs = rel) of the adaptive methods (default 1e-5 .. 1e-11)")(
        "alpha", po::value(&alpha)->default_value(alpha), "damping")("beta", po::value(&beta)->default_value(beta), "forcing amplitude")(
        "omega", po::value(&omega)->default_value(omega, "pi/3"), "forcing frequency")(
        "reps", po::value(&reps)->default_value(reps), "timed repetitions")(
        "schemes", po::value(&schemes)->multitoken(),
        "the geometric methods: schemes and compositions <family>:<base> of the system (default: every scheme, and "
        "yoshida4, yoshida6a and kahanli8 of la-trapezoid)");
    if (!cli.parse(argc, argv)) return 0;
    require(!periods.empty() && !ms.empty() && !tols.empty(), "give at least one value per list");
    require(std::isfinite(alpha) && alpha > 0, "alpha must be positive (a steady state needs damping), got " + show(alpha));
    require(std::isfinite(beta) && beta != 0, "beta must be finite and nonzero, got " + show(beta));
    require(std::isfinite(omega) && omega > 0, "omega must be positive, got " + show(omega));
    for (double P : periods) require(std::isfinite(P) && P >= 4 && P <= 1e7, "periods must be in [4, 1e7], got " + show(P));
    for (double m : ms) require(std::isfinite(m) && m >= 2 && m <= 1e5, "m must be in [2, 1e5], got " + show(m));
    for (double t : tols) require(std::isfinite(t) && t >= 1e-14 && t <= 1e-2, "tol must be in [1e-14, 1e-2], got " + show(t));
    require(reps >= 1 && reps <= 1000, "reps must be in [1, 1000]");
    std::sort(periods.begin(), periods.end());
    const SystemInfo& sys = find_system("forced-oscillator");
    if (schemes.empty()) {
      schemes = sys.scheme_names();
      for (const char* c : {"yoshida4:la-trapezoid", "yoshida6a:la-trapezoid", "kahanli8:la-trapezoid"}) schemes.push_back(c);
    }
    for (const auto& s : schemes) sys.scheme(s);  // InputError naming the known ones, before any work
    const double Tf = 2 * pi / omega;
    auto values_for = [&](double P) {
      return ParamValues{{"alpha", alpha}, {"beta", beta}, {"omega", omega}, {"dq0", 0}, {"dv0", 0}, {"T", P * Tf}};
    };
    for (double P : periods) {
      sys.validate(values_for(P));
      for (double m : ms) step_count(Tf / m, P * Tf);
    }
    // the closed form every error is measured against: refused before any output when it is not a number a
    // relative error can divide by (beta = 1e308 overflows it, alpha omega = 1e300 squares to inf)
    const double k = 1 - omega * omega, C = beta / std::sqrt(k * k + alpha * alpha * omega * omega),
                 delta = std::atan2(alpha * omega, k);
    require(std::isfinite(C) && C != 0,
            "the steady-state amplitude beta / sqrt((1 - omega^2)^2 + alpha^2 omega^2) is " + show(C) +
                " at these parameters; the errors are relative to it, so it must be finite and nonzero");
    const auto dir = prepare_output_dir(cli.out);

    std::vector<WorkPoint> pts;
    const Study study{C, delta, reps};
    for (double P : periods) {
      std::fprintf(stderr, "long_horizon: %g periods ...\n", P);
      const ParamValues pv = values_for(P);
      const double T = P * Tf;
      // The equation of the system's header, by hand (the AD-derived sys.ode(pv) costs ~10x more per evaluation and
      // would charge the ODE methods for the derivation, not for the integration; the schemes run their closed forms).
      const OdeRhs f = [alpha, beta, omega](double t, const double* x, double* dx) {
        dx[0] = x[1];
        dx[1] = -x[0] - alpha * x[1] + beta * std::sin(omega * t);
      };
      const auto x0v = sys.ode_initial_state(pv, false);
      const State2 x0{x0v[0], x0v[1]};
      for (double m : ms) {
        const double h = Tf / m;
        const long N = step_count(h, T);
        const long every = std::max(1L, static_cast<long>(m / 16));
        for (const auto& name : schemes) {
          auto run = [&, name, h, every](bool) {
            const Run r = sys.run(pv, name, h, Path::fast, every);
            SteadyFit fit(omega, T / 2);
            for (std::size_t i = 0; i < r.t.size(); ++i) fit.point(r.t[i], r.q[i]);
            return fit.result(r.steps);
          };
          auto timing = [&, name, h] { return sys.time_run(pv, name, h, Path::fast, reps); };
          pts.push_back(study.point(name, "geometric", "m", P, m, run, timing));
        }
        auto rk4 = [&, h, N](bool measure) {
          BaselineSetup b;
          b.name = "odeint-rk4";
          b.h = h;
          b.steps = N;
          return baseline_run(b, f, x0, T, omega, measure);
        };
        pts.push_back(study.point("odeint-rk4", "rk", "m", P, m, rk4,
                                    [&] { return time_per_call([&] { do_not_optimize(rk4(false).steps); }, reps); }));
      }
      for (double tol : tols) {
        BaselineSetup b;
        b.abs_tol = b.rel_tol = tol;
        auto adaptive = [&, b, T](const char* name) {
          return [&, b, T, name](bool m) {
            BaselineSetup named = b;
            named.name = name;
            return baseline_run(named, f, x0, T, omega, m);
          };
        };
        const auto dopri = adaptive("odeint-dopri5"), bs = adaptive("odeint-bulirsch-stoer"), r8 = adaptive("gsl-rk8pd");
        pts.push_back(study.point("odeint-dopri5", "adaptive", "tol", P, tol, dopri,
                                    [&] { return time_per_call([&] { do_not_optimize(dopri(false).steps); }, reps); }));
        pts.push_back(study.point("odeint-bulirsch-stoer", "adaptive", "tol", P, tol, bs,
                                    [&] { return time_per_call([&] { do_not_optimize(bs(false).steps); }, reps); }));
        pts.push_back(study.point("gsl-rk8pd", "adaptive", "tol", P, tol, r8,
                                    [&] { return time_per_call([&] { do_not_optimize(r8(false).steps); }, reps); }));
      }
    }

    const Params params{{"system", "forced-oscillator: q'' + alpha q' + q = beta sin(omega t), started on the steady state"},
                        {"alpha", format_number(alpha)}, {"beta", format_number(beta)}, {"omega", format_number(omega)},
                        {"periods", format_list(periods) + " (forcing periods 2 pi/omega)"}, {"m", format_list(ms) + " (steps per forcing period)"},
                        {"tol", format_list(tols) + " (abs = rel)"}, {"reps", std::to_string(reps)},
                        {"schemes", join_names(schemes) + " (compositions run the generic step of their base)"},
                        {"steady state", "C = " + format_number(C) + ", delta = " + format_number(delta)},
                        {"measures", "least squares q = A sin(omega t) + B cos(omega t) + c over t >= T/2; amp_err = |hypot(A,B) - C|/C; "
                                     "phase_err = |atan2(-B, A) - delta| rad"}};
    TsvWriter data(dir / "forced-oscillator_long_horizon.tsv", "long_horizon", params,
                   {"method", "family", "alpha", "periods", "knob", "value", "steps", "amp_err", "phase_err"});
    TsvWriter tim(dir / "forced-oscillator_long_horizon_timings.tsv", "long_horizon", params,
                  {"method", "family", "alpha", "periods", "knob", "value", "seconds_median", "reps"});
    for (auto& p : pts) {
      p.group = alpha;  // one damping: the summary's group
      data.row(p.method, p.family, alpha, p.horizon, p.knob, p.value, p.steps, p.errors[0], p.errors[1]);
      tim.row(p.method, p.family, alpha, p.horizon, p.knob, p.value, p.time.median, p.time.reps);
    }
    data.commit();
    tim.commit();

    const std::vector<long_horizon::Measure> measures{{"amp_err", "steady-state amplitude error |C_fit - C|/C", 1e-3},
                                                      {"phase_err", "steady-state phase error (rad)", 1e-3}};
    long_horizon::summarise(pts, measures, "alpha", "periods", dir / "forced-oscillator_long_horizon_summary.tsv",
                            "long_horizon", params);
    long_horizon::draw_saved(dir, "forced-oscillator_long_horizon", "alpha", "periods", measures, format_number(periods.back()),
                             "Forced oscillator over " + format_number(periods.back()) +
                                 " forcing periods: steady-state error against CPU time (median)");
    return 0;
  }();
}
