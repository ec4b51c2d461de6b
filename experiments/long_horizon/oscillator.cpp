// Long-horizon work–precision for the damped oscillator q'' = -q - alpha q': what the structure costs.
// x-axis: CPU time per run (median of repeats after a warm-up); y-axis: a structural error over the whole horizon
// (studies/include/geomint/oscillator_structure.hpp defines and justifies the measures):
//   decay   |alpha_fit - alpha| / alpha, alpha_fit the least-squares exponent of Q = q^2 + alpha q p + p^2
//   freq    |omega_fit - omega| / omega, omega_fit the least-squares slope of the unwrapped phase
//   phase   |theta(T) - theta(0) - omega T| (rad): the phase error accumulated over the horizon
//   balance max over windows of |E_k - E_{k+1} - W_k| / E_k: energy lost against the work of the damping force
//           (windows of a fixed length, --window-periods, so that the balance means the same at every horizon)
// Methods: the geometric schemes (la, contact: first order; la-midpoint, contact-sym, leapfrog: second order),
// compositions of order 4, 6 and 8 of leapfrog (--compositions: any family of a symmetric scheme, stepped by the
// base's closed form at each stage step) and Odeint's rk4 over steps per period; Odeint dopri5 and Bulirsch–Stoer
// and GSL rk8pd over tolerance.
// A run that fails is a missing value (nan) with a message naming method, parameters and step.
//   long_horizon --system oscillator [--alpha 0.01 0.1] [--periods 100 1000] [--m 16 32 64 128 256] [--tol 1e-5 1e-7 1e-9 1e-11]
//                [--window-periods 5] [--reps 3] [--compositions yoshida4:la-trapezoid ...] [--out out]
// The study in docs/speed-accuracy.md (6 minutes on one idle core, compositions included):
//   long_horizon --system oscillator --periods 1000 10000 100000 --m 16 32 64 128 256 512 --tol 1e-4 1e-6 1e-8 1e-10 1e-12
// Writes out/oscillator_long_horizon.tsv (errors: the same bits for the same command),
// out/oscillator_long_horizon_timings.tsv, out/oscillator_long_horizon_summary.tsv (times to reach each target,
// crossovers and fitted slopes: derived from timings) and the figure out/oscillator_long_horizon.{png,pdf}.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>

#include "geomint/budget.hpp"
#include "geomint/cli.hpp"
#include "geomint/constants.hpp"
#include "geomint/error.hpp"
#include "geomint/generic/composition_families.hpp"
#include "geomint/registry.hpp"
#include "geomint/io.hpp"
#include "geomint/oscillator_structure.hpp"
#include "geomint/systems/oscillator.hpp"
#include "geomint/plots/figure.hpp"
#include "geomint/study.hpp"
#include "geomint/timing.hpp"
#include "long_horizon/table.hpp"
#include "long_horizon/studies.hpp"

using namespace geomint;

namespace {


struct Measure {
  const char* column;
  const char* label;
  double target;  // the structural error the summary asks each method to reach
};
const Measure kMeasures[] = {{"decay_err", "decay-rate error |alpha_fit - alpha|/alpha", 1e-5},
                             {"freq_err", "frequency error |omega_fit - omega|/omega", 1e-7},
                             {"phase_err", "phase error at T (rad)", 1e-2},
                             {"balance_err", "dissipation balance error (max over windows)", 1e-5}};

using Runner = std::function<OscillatorStructure(bool measure)>;

template <class S>
Runner fixed(double alpha, double q0, double p0, double h, long N, long windows) {
  return [=](bool m) {
    return m ? run_fixed_structure<S, true>(alpha, q0, p0, h, N, windows)
             : run_fixed_structure<S, false>(alpha, q0, p0, h, N, windows);
  };
}

// A geometric scheme of the oscillator by name (or alias): its closed form, renormalised between windows.
Runner geometric(const std::string& name, double alpha, double q0, double p0, double h, long N, long windows) {
  Runner run;
  generic::visit_closed_form<systems::Oscillator>(
      name, [&](auto c) { run = fixed<decltype(c)>(alpha, q0, p0, h, N, windows); });
  return run;
}

// A composition "<family>:<base>" of a symmetric scheme of the oscillator: the base's closed form at each stage step.
Runner composed(const std::string& name, double alpha, double q0, double p0, double h, long N, long windows) {
  const auto cn = generic::parse_composition_name(name);
  const std::vector<double> stage_h = composition_stage_steps(cn.family, h);
  Runner run;
  generic::visit_closed_form<systems::Oscillator>(cn.base, [&](auto c) {
    using S = decltype(c);
    run = [=](bool m) {
      return m ? run_composed_structure<S, true>(stage_h, alpha, q0, p0, h, N, windows)
               : run_composed_structure<S, false>(stage_h, alpha, q0, p0, h, N, windows);
    };
  });
  return run;
}

double rel(double a, double b) { return std::abs(a - b) / std::abs(b); }

// One point of the study: the four structural errors of kMeasures against the exact values (decay rate alpha,
// frequency sqrt(1 - alpha^2/4), phase 0, balance 0), and the CPU time.
WorkPoint measure(const std::string& method, const std::string& family, const std::string& knob, double alpha,
                  double periods, double value, const Runner& run, int reps) {
  const double w = std::sqrt(1 - alpha * alpha / 4);
  return measure_point(
      work_point(method, family, knob, value, alpha, periods), 4,
      [&](bool m) {
        const OscillatorStructure s = run(m);
        return Measured{{rel(s.decay_rate, alpha), rel(s.frequency, w), std::abs(s.phase_end), s.balance}, s.steps};
      },
      reps, method + ", alpha = " + show(alpha) + ", " + show(periods) + " periods, " + knob + " = " + show(value));
}

}  // namespace

int long_horizon_oscillator(int argc, char** argv) {
  return [&] {
    std::vector<double> alphas{0.01, 0.1}, periods{100, 1000}, ms{16, 32, 64, 128, 256}, tols{1e-5, 1e-7, 1e-9, 1e-11};
    double q0 = -0.25, p0 = 0.75;
    double window_periods = 5;
    int reps = 3;
    std::vector<std::string> compositions{"yoshida4:la-trapezoid", "yoshida6a:la-trapezoid", "kahanli8:la-trapezoid"};
    Cli cli("long_horizon", "long-horizon structural error against CPU time: damped oscillator");
    add_study_system_option(cli, "oscillator");
    cli.options.add_options()("alpha", po::value(&alphas)->multitoken(), "damping values (default 0.01 0.1)")(
        "periods", po::value(&periods)->multitoken(), "horizons T = 2 pi periods (default 100 1000)")(
        "m", po::value(&ms)->multitoken(), "steps per period of the fixed-step methods, h = 2 pi / m (default 16 .. 256)")(
        "tol", po::value(&tols)->multitoken(), "tolerances (abs = rel) of the adaptive methods (default 1e-5 .. 1e-11)")(
        "q0", po::value(&q0)->default_value(q0), "initial position")("p0", po::value(&p0)->default_value(p0), "initial momentum")(
        "window-periods", po::value(&window_periods)->default_value(window_periods),
        "length of the windows of the balance and of the renormalisation, in periods (must divide every horizon)")(
        "reps", po::value(&reps)->default_value(reps), "timed repetitions")(
        "compositions", po::value(&compositions)->multitoken(),
        "compositions <family>:<base> of the oscillator's symmetric schemes (default yoshida4, yoshida6a and kahanli8 "
        "of la-trapezoid, the leapfrog)");
    if (!cli.parse(argc, argv)) return 0;
    require(!alphas.empty() && !periods.empty() && !ms.empty() && !tols.empty(), "give at least one value per list");
    double stages = 0;  // base steps a step of every composition takes, for the plan below
    for (const auto& c : compositions) {
      require(generic::is_composition_name(c), "--compositions takes <family>:<base>, got '" + c + "'");
      find_system("oscillator").scheme(c);  // InputError naming the family or the base when either is not one
      stages += generic::find_composition_family(generic::parse_composition_name(c).family).stages();
    }
    for (double a : alphas) require(std::isfinite(a) && a > 0 && a < 2, "alpha must be in (0, 2) (under-damped), got " + show(a));
    for (double P : periods)
      require(std::isfinite(P) && P >= 1 && P <= 1e7 && P == std::round(P), "periods must be whole numbers in [1, 1e7], got " + show(P));
    for (double m : ms) require(m >= 4 && m <= 1e5 && m == std::round(m), "m must be a whole number in [4, 1e5], got " + show(m));
    for (double t : tols) require(std::isfinite(t) && t >= 1e-14 && t <= 1e-2, "tol must be in [1e-14, 1e-2], got " + show(t));
    require_finite(q0, "q0");
    require_finite(p0, "p0");
    require(q0 != 0 || p0 != 0, "q0 and p0 are both zero: nothing to measure");
    // Infeasible work refused before it starts: periods x m steps per fixed-step run, for every scheme and alpha.
    for (double P : periods)
      for (double m : ms) {
        check_steps(P * m, "periods x m = " + show(P) + " x " + show(m));
        plan_steps(P * m * static_cast<double>(alphas.size()) * (4 + stages), "the runs (schemes x alpha x periods x m)");
      }
    require(std::isfinite(window_periods) && window_periods >= 1 && window_periods == std::round(window_periods),
            "window-periods must be a whole number >= 1, got " + show(window_periods));
    for (double P : periods)
      require(std::fmod(P, window_periods) == 0 && P / window_periods >= 3,
              "every horizon must be at least 3 windows and a multiple of --window-periods");
    require(reps >= 1 && reps <= 1000, "reps must be in [1, 1000]");
    for (double a : alphas)
      require(a * two_pi * window_periods <= 20,
                "the energy must decay by at most e^-20 per window (alpha 2 pi window-periods <= 20), so that the adaptive "
                "methods' tolerance stays relative to the amplitude: lower --window-periods");
    std::sort(periods.begin(), periods.end());
    for (double P : periods)
      for (double m : ms) require(P * m <= 1e10, "more than 1e10 steps in one run (periods x m)");
    const auto dir = prepare_output_dir(cli.out);
    // first order (the paper's), then the second-order comparators under the paper's names
    const std::vector<std::string> geo{"la", "contact", "la-midpoint", "contact-sym", "leapfrog"};

    std::vector<WorkPoint> pts;
    for (double a : alphas)
      for (double P : periods) {
        std::fprintf(stderr, "long_horizon: alpha = %g, %g periods ...\n", a, P);
        const double T = two_pi * P;
        for (double m : ms) {
          const double h = two_pi / m;
          const long N = std::lround(P * m);
          const long W = std::lround(P / window_periods);
          for (const auto& name : geo)
            pts.push_back(measure(name, "geometric", "m", a, P, m, geometric(name, a, q0, p0, h, N, W), reps));
          for (const auto& name : compositions)
            pts.push_back(measure(name, "geometric", "m", a, P, m, composed(name, a, q0, p0, h, N, W), reps));
          BaselineSetup rk4;
          rk4.name = "odeint-rk4";
          rk4.h = h;
          rk4.steps = N;
          pts.push_back(measure("odeint-rk4", "rk", "m", a, P, m, [=](bool mm) {
            return run_baseline_structure(rk4, a, q0, p0, h * static_cast<double>(N), W, mm);
          }, reps));
        }
        const long windows = std::lround(P / window_periods);
        for (double tol : tols)
          for (const char* name : {"odeint-dopri5", "odeint-bulirsch-stoer", "gsl-rk8pd"}) {
            BaselineSetup b;
            b.name = name;
            b.abs_tol = b.rel_tol = tol;
            pts.push_back(measure(name, "adaptive", "tol", a, P, tol, [=](bool mm) {
              return run_baseline_structure(b, a, q0, p0, T, windows, mm);
            }, reps));
          }
      }

    const Params params{{"system", "oscillator"}, {"problem", "damped oscillator q'' = -q - alpha q'"}, {"alpha", format_list(alphas)},
                        {"periods", format_list(periods)}, {"q0", format_number(q0)}, {"p0", format_number(p0)},
                        {"m", format_list(ms) + " (steps per period, h = 2 pi/m)"}, {"tol", format_list(tols) + " (abs = rel)"},
                        {"window_periods", format_number(window_periods)}, {"reps", std::to_string(reps)},
                        {"compositions", join_names(compositions) + " (the base's closed form at each stage step w_i h)"},
                        {"measures", "decay_err = |alpha_fit - alpha|/alpha (log Q, Q = q^2 + alpha q p + p^2); freq_err = "
                                     "|omega_fit - omega|/omega; phase_err = |theta(T) - theta(0) - omega T| rad; balance_err = "
                                     "max_k |E_k - E_k+1 - W_k|/E_k (W: trapezoid on the steps for geometric schemes, "
                                     "W' = alpha p^2 integrated by the method for rk4/adaptive)"}};
    TsvWriter data(dir / "oscillator_long_horizon.tsv", "long_horizon", params,
                   {"method", "family", "alpha", "periods", "knob", "value", "steps", "decay_err", "freq_err", "phase_err", "balance_err"});
    TsvWriter tim(dir / "oscillator_long_horizon_timings.tsv", "long_horizon", params,
                  {"method", "family", "alpha", "periods", "knob", "value", "seconds_median", "seconds_min", "seconds_max", "reps"});
    for (const auto& p : pts) {
      data.row(p.method, p.family, p.group, p.horizon, p.knob, p.value, p.steps, p.errors[0], p.errors[1], p.errors[2],
               p.errors[3]);
      tim.row(p.method, p.family, p.group, p.horizon, p.knob, p.value, p.time.median, p.time.min, p.time.max, p.time.reps);
    }
    data.commit();
    tim.commit();

    std::vector<long_horizon::Measure> measures;
    for (const auto& M : kMeasures) measures.push_back({M.column, M.label, M.target});
    long_horizon::summarise(pts, measures, "alpha", "periods", dir / "oscillator_long_horizon_summary.tsv",
                            "long_horizon", params);
    // The figure is drawn from the files just written.
    long_horizon::draw_saved(dir, "oscillator_long_horizon", "alpha", "periods", measures, format_number(periods.back()),
                             "Damped oscillator over " + format_number(periods.back()) +
                                 " periods: structural error against CPU time (median)");
    return 0;
  }();
}
