// Long-horizon work–precision on a nonlinear problem: the Kepler problem with a weak constant friction,
//   q'' = -q/|q|^3 - (alpha + a sin(theta t)) q'   (the `kepler` system, a = 0 by default),
// over 10^2 - 10^4 orbits: what each structural error costs, in CPU time and in evaluations of the equations.
// Measures (max over the output grid, `--outputs` points an orbit, against the reference or an exact law):
//   phase_err       |q - q_ref|: the orbital phase (position error)
//   momentum_err    |M / (M(0) e^{-alpha t - (a/theta)(1 - cos theta t)}) - 1|, M = q x q' (the exact law, no reference)
//   energy_err      |E - E_ref| / |E_ref|, E = |q'|^2/2 - 1/|q| (the energy-decay law, E' = -f |q'|^2)
//   lrl_err         |A - A_ref|, A = q' x M - q/|q| the Laplace–Runge–Lenz vector: |A| is the eccentricity and its
//                   direction the pericentre's (|A - A_ref| ~ |de| + e |d omega|; the angle alone is ill-conditioned
//                   as the friction circularizes the orbit)
// The reference is Boost.Odeint's Runge–Kutta–Fehlberg 7(8) in long double at --reference-tol, stepped to every
// output time; a second one at 100 times that tolerance bounds its error (written in the files' header).
// Methods: the geometric schemes and compositions (--schemes; their evaluations of the residual counted: Newton
// evaluates it before each update and once where it accepts, each time the derivatives of L at the quadrature
// nodes; the Jacobian, kept across steps while it converges in one update, is not counted) over k steps an orbit
// (h = 2 pi/k); the logH leapfrog and its compositions (--schemes logh <family>:logh, generic/logh.hpp) at a
// fixed step 2 pi/k in the fictitious time sigma, each output time reached by a partial step of the method, its
// kicks counted as its evaluations; Odeint rk4 over
// k; Odeint dopri5 and Bulirsch–Stoer (dense output on the grid) and GSL rk8pd (stepped to each output time) over
// the tolerance, all on the system's hand-written right-hand side, whose calls are counted.
//   long_horizon --system kepler [--orbits 100 300] [--k 32 64 128 256] [--tol 1e-6 1e-8 1e-10 1e-12] [--alpha 1e-5]
//                       [--e 0.4] [--a 0] [--theta 6.283185307179586] [--schemes ...] [--outputs 8] [--reps 3]
// The study in docs/speed-accuracy.md (about 20 minutes on one core):
//   long_horizon --system kepler --orbits 100 1000 10000 --k 32 64 128 256 512 --tol 1e-6 1e-8 1e-10 1e-12 1e-13
// Writes out/kepler_long_horizon.tsv (errors and evaluation counts: the same bits for the same command),
// _timings.tsv, _summary.tsv (CPU time to each target, crossovers, slopes), _summary_evals.tsv (the same with
// evaluations as the cost) and the figure out/kepler_long_horizon.{png,pdf}.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>

#include <boost/numeric/odeint.hpp>
#include <gsl/gsl_errno.h>

#include "geomint/budget.hpp"
#include "geomint/constants.hpp"
#include "geomint/cli.hpp"
#include "geomint/error.hpp"
#include "geomint/generic/composition_families.hpp"
#include "geomint/generic/logh.hpp"
#include "geomint/io.hpp"
#include "geomint/plots/figure.hpp"
#include "geomint/reference.hpp"
#include "geomint/registry.hpp"
#include "geomint/run/baselines.hpp"
#include "geomint/systems/kepler.hpp"
#include "geomint/timing.hpp"
#include "long_horizon/table.hpp"
#include "long_horizon/studies.hpp"

using namespace geomint;
namespace odeint = boost::numeric::odeint;

namespace {

using State = std::array<double, 4>;  // (q1, q2, q1', q2')

// The structural quantities of a state: angular momentum, energy, direction of the Laplace–Runge–Lenz vector.
struct Invariants {
  double M, E, A1, A2;
};
template <class T>
Invariants invariants(const T& x) {
  const double q1 = double(x[0]), q2 = double(x[1]), v1 = double(x[2]), v2 = double(x[3]);
  const double r = std::hypot(q1, q2), M = q1 * v2 - q2 * v1;
  return {M, (v1 * v1 + v2 * v2) / 2 - 1 / r, v2 * M - q1 / r, -v1 * M - q2 / r};
}

// The steps of the base scheme one step of `name` takes: a composition's stages, else 1.
int stages_of(const std::string& name) {
  if (!generic::is_composition_name(name)) return 1;
  return generic::find_composition_family(generic::parse_composition_name(name).family).stages();
}

// The logH leapfrog (generic/logh.hpp) and its compositions "<family>:logh": explicit time-transformed schemes
// the study runs beside the registry's, on the same system struct (its separable form).
bool is_logh(const std::string& name) {
  return name == "logh" || (generic::is_composition_name(name) && generic::parse_composition_name(name).base == "logh");
}
const generic::CompositionFamily* logh_family(const std::string& name) {
  return name == "logh" ? nullptr : &generic::find_composition_family(generic::parse_composition_name(name).family);
}

// The reference: the Kepler equations of the system's header in long double, RKF 7(8) at `tol`, at every output time.
std::vector<std::array<long double, 4>> reference(const systems::Kepler& k, const std::vector<double>& times, long double tol) {
  using X = std::array<long double, 4>;
  const long double alpha = k.alpha, a = k.a, theta = k.theta;
  auto f = [&](const X& x, X& dx, long double t) {
    const long double r = std::hypot(x[0], x[1]), r3 = r * r * r, fr = alpha + a * std::sin(theta * t);
    dx = {x[2], x[3], -x[0] / r3 - fr * x[2], -x[1] / r3 - fr * x[3]};
  };
  const auto q0 = k.initial_position<double>();
  const auto v0 = k.initial_velocity<double>();
  X x{q0(0), q0(1), v0(0), v0(1)};
  std::vector<long double> ts(times.begin(), times.end());
  std::vector<X> out;
  out.reserve(times.size());
  auto st = odeint::make_controlled(tol, tol, odeint::runge_kutta_fehlberg78<X, long double>());
  try {
    odeint::integrate_times(st, f, x, ts.begin(), ts.end(), static_cast<long double>(1e-3),
                            [&](const X& y, long double) { out.push_back(y); },
                            odeint::max_step_checker(odeint_max_steps_between_outputs));
  } catch (const odeint::no_progress_error&) {
    throw_too_stiff("the long double reference (RKF 7(8))", out.empty() ? 0.0 : times[out.size() - 1], out.size());
  }
  for (const auto& y : out)
    for (long double c : y)
      if (!std::isfinite(static_cast<double>(c))) throw NumericalFailure(0, "reference", "the reference is not finite");
  return out;
}

// The structural errors of a trajectory sampled on the output grid (t_i, x_i), i = 0.., against the reference.
struct Errors {
  const systems::Kepler& k;
  const std::vector<std::array<long double, 4>>& ref;
  double M0;
  std::array<double, 4> worst{0, 0, 0, 0};
  void operator()(std::size_t i, double t, const State& x) {
    for (double c : x)
      if (!std::isfinite(c)) throw NumericalFailure(static_cast<long>(i), "state", "non-finite state at t = " + show(t));
    const auto& y = ref[i];
    const Invariants a = invariants(x), b = invariants(y);
    const double e[4] = {std::hypot(x[0] - double(y[0]), x[1] - double(y[1])),
                         std::abs(a.M / (M0 * k.angular_momentum_factor(t)) - 1), std::abs(a.E - b.E) / std::abs(b.E),
                         std::hypot(a.A1 - b.A1, a.A2 - b.A2)};
    for (int c = 0; c < 4; ++c) worst[static_cast<std::size_t>(c)] = std::max(worst[static_cast<std::size_t>(c)], e[c]);
  }
};

// A baseline through the one door (run/baselines.hpp), its errors taken at every output time by `err`.
BaselineCount baseline_run(const BaselineSetup& b, const OdeRhs& f, const State& x0, Errors* err) {
  const BaselineObserver observe = [&](std::size_t i, double t, const double* x) { (*err)(i, t, State{x[0], x[1], x[2], x[3]}); };
  return run_baseline(b, f, std::vector<double>(x0.begin(), x0.end()), err ? &observe : nullptr);
}

}  // namespace

int long_horizon_kepler(int argc, char** argv) {
  return [&] {
    gsl_set_error_handler_off();  // GSL's failures are statuses the baseline reports, never an abort
    std::vector<double> orbits{100, 300}, ks{32, 64, 128, 256}, tols{1e-6, 1e-8, 1e-10, 1e-12};
    std::vector<std::string> schemes{"la-trapezoid", "contact-trapezoid", "yoshida4:la-trapezoid", "yoshida6a:la-trapezoid",
                                     "kahanli8:la-trapezoid", "logh", "yoshida4:logh", "yoshida6a:logh", "kahanli8:logh"};
    double alpha = 1e-5, e = 0.4, a = 0, theta = two_pi, reference_tol = 1e-17;
    long outputs = 8;
    int reps = 3;
    Cli cli("long_horizon", "long-horizon structural error against CPU time and evaluations: Kepler with friction");
    add_study_system_option(cli, "kepler");
    cli.options.add_options()("orbits", po::value(&orbits)->multitoken(), "horizons in unperturbed orbits of 2 pi (default 100 300)")(
        "k", po::value(&ks)->multitoken(), "steps an orbit of the fixed-step methods, h = 2 pi/k (default 32 64 128 256)")(
        "tol", po::value(&tols)->multitoken(), "tolerances (abs = rel) of the adaptive methods (default 1e-6 .. 1e-12)")(
        "alpha", po::value(&alpha)->default_value(alpha, "1e-5"), "constant friction (the weak dissipation)")(
        "e", po::value(&e)->default_value(e, "0.4"), "eccentricity of the initial orbit, in [0.1, 0.9]")(
        "a", po::value(&a)->default_value(a), "amplitude of the periodic friction a sin(theta t)")(
        "theta", po::value(&theta)->default_value(theta, "2 pi"), "frequency of the periodic friction")(
        "schemes", po::value(&schemes)->multitoken(),
        "schemes and compositions <family>:<base> of kepler (default la-trapezoid, contact-trapezoid and the "
        "yoshida4, yoshida6a, kahanli8 compositions of la-trapezoid; the logH leapfrog logh and the same compositions "
        "of it), and any composition <family>:logh (logh: a fixed step 2 pi/k in sigma, dt = dsigma/U)")(
        "outputs", po::value(&outputs)->default_value(outputs), "output points an orbit where the errors are taken (divides every k)")(
        "reference-tol", po::value(&reference_tol)->default_value(reference_tol, "1e-17"),
        "tolerance of the long double reference, in [1e-18, 1e-12]")(
        "reps", po::value(&reps)->default_value(reps), "timed repetitions");
    if (!cli.parse(argc, argv)) return 0;
    require(!orbits.empty() && !ks.empty() && !tols.empty() && !schemes.empty(), "give at least one value per list");
    for (double P : orbits)
      require(std::isfinite(P) && P >= 1 && P <= 1e6 && P == std::round(P), "orbits must be whole numbers in [1, 1e6], got " + show(P));
    require(outputs >= 1 && outputs <= 64, "outputs must be in [1, 64]");
    for (double k : ks)
      require(std::isfinite(k) && k >= 8 && k <= 1e5 && k == std::round(k) && std::fmod(k, double(outputs)) == 0,
              "k must be a whole number in [8, 1e5] and a multiple of --outputs, got " + show(k));
    for (double t : tols) require(std::isfinite(t) && t >= 1e-14 && t <= 1e-2, "tol must be in [1e-14, 1e-2], got " + show(t));
    require(std::isfinite(reference_tol) && reference_tol >= 1e-18 && reference_tol <= 1e-12,
            "reference-tol must be in [1e-18, 1e-12], got " + show(reference_tol));
    require(std::isfinite(e) && e >= 0.1 && e <= 0.9,
            "e must be in [0.1, 0.9], got " + show(e));
    require(reps >= 1 && reps <= 1000, "reps must be in [1, 1000]");
    std::sort(orbits.begin(), orbits.end());
    orbits.erase(std::unique(orbits.begin(), orbits.end()), orbits.end());
    const SystemInfo& sys = find_system("kepler");
    for (const auto& s : schemes)  // InputError naming the known ones, before any work
      if (is_logh(s))
        logh_family(s);
      else
        sys.scheme(s);
    auto values_for = [&](double P) {
      return ParamValues{{"a", a}, {"theta", theta}, {"alpha", alpha}, {"e", e}, {"T", P * two_pi}};
    };
    for (double P : orbits) sys.validate(values_for(P));
    // Infeasible work refused before it starts: steps of the fixed-step methods (compositions count their stages)
    double planned = 0;
    for (double P : orbits)
      for (double k : ks) {
        check_steps(P * k, "orbits x k = " + show(P) + " x " + show(k));
        planned += P * k * (static_cast<double>(schemes.size()) * 8 + 1);
      }
    plan_steps(planned * (reps + 1), "the fixed-step runs (stages x orbits x k x (reps + 1))");
    const auto dir = prepare_output_dir(cli.out);

    systems::Kepler kep;
    kep.a = a;
    kep.theta = theta;
    kep.alpha = alpha;
    kep.e = e;
    const double h_out = two_pi / static_cast<double>(outputs);
    const long n_out = std::lround(orbits.back() * static_cast<double>(outputs));
    std::vector<double> times(static_cast<std::size_t>(n_out + 1));
    for (long i = 0; i <= n_out; ++i) times[static_cast<std::size_t>(i)] = static_cast<double>(i) * h_out;
    std::fprintf(stderr, "long_horizon: reference over %g orbits ...\n", orbits.back());
    const auto ref = reference(kep, times, reference_tol);
    const auto check = reference(kep, times, reference_tol * 100);
    double ref_diff = 0;
    for (std::size_t i = 0; i < ref.size(); ++i)
      ref_diff = std::max(ref_diff, static_cast<double>(std::hypot(ref[i][0] - check[i][0], ref[i][1] - check[i][1])));
    std::fprintf(stderr, "long_horizon: reference within %.3g of the one at 100x its tolerance\n", ref_diff);
    // The orbit the friction has left at each horizon (semi-major axis -1/2E, eccentricity |A|), for the header.
    std::string orbit_at;
    for (double P : orbits) {
      const Invariants o = invariants(ref[static_cast<std::size_t>(std::lround(P * double(outputs)))]);
      orbit_at += (orbit_at.empty() ? "" : "; ") + format_number(P) + " orbits: a = " + format_number(-1 / (2 * o.E)) +
                  ", e = " + format_number(std::hypot(o.A1, o.A2));
    }

    const ParamValues pv0 = values_for(orbits.back());
    const OdeRhs f = sys.ode_rhs(pv0);
    const auto x0v = sys.ode_initial_state(pv0, true);
    const State x0{x0v[0], x0v[1], x0v[2], x0v[3]};
    const double M0 = x0[0] * x0[3] - x0[1] * x0[2];

    std::vector<WorkPoint> pts;
    std::vector<double> evals;  // per point: evaluations of the equations (Newton updates or rhs calls) per run
    auto add = [&](WorkPoint p, double n_eval) {
      pts.push_back(std::move(p));
      evals.push_back(pts.back().failure.empty() ? n_eval : WorkPoint::nan);
    };
    for (double P : orbits) {
      std::fprintf(stderr, "long_horizon: %g orbits ...\n", P);
      const ParamValues pv = values_for(P);
      const double T = P * two_pi;
      const std::vector<double> grid(times.begin(), times.begin() + std::lround(P * double(outputs)) + 1);
      auto context = [&](const std::string& m, const char* knob, double v) {
        return m + ", " + show(P) + " orbits, " + knob + " = " + show(v);
      };
      for (double k : ks) {
        const double h = two_pi / k;
        const long N = step_count(h, T), stride = std::lround(k) / outputs;
        for (const auto& name : schemes) {
          double n_eval = 0;
          if (is_logh(name)) {
            // A fixed step h = 2 pi/k in sigma (dt = dsigma/U on the motion, so k steps an orbit on average for
            // a = 1); each output time reached by a partial step of the method (Logh::run_to), which the timed runs
            // include. Evaluations: the kicks (one force evaluation a stage), partial steps included.
            const std::vector<double> out_times(grid.begin() + 1, grid.end());
            long steps = 0;
            auto run_logh = [&](Errors* err) {
              generic::Logh<systems::Kepler> lg(kep, h, logh_family(name));
              lg.start(kep.initial_position<double>(), kep.initial_velocity<double>());
              double last = 0;
              lg.run_to(out_times, [&](std::size_t i, const generic::Logh<systems::Kepler>::State& x) {
                if (err) (*err)(i + 1, x.t, State{x.q(0), x.q(1), x.p(0), x.p(1)});
                last += x.q(0);
              });
              do_not_optimize(last);
              steps = lg.steps();
              return lg.kicks();
            };
            WorkPoint pt = measure_point_timed(
                    work_point(name, "geometric", "k", k, alpha, P), 4,
                    [&] {
                      Errors err{kep, ref, M0};
                      err(0, 0.0, x0);
                      n_eval = static_cast<double>(run_logh(&err));
                      return Measured{{err.worst.begin(), err.worst.end()}, steps};
                    },
                    [&] { return time_per_call([&] { run_logh(nullptr); }, reps); }, reps, context(name, "k", k));
            add(std::move(pt), n_eval);
            continue;
          }
          WorkPoint pt = measure_point_timed(
                  work_point(name, "geometric", "k", k, alpha, P), 4,
                  [&] {
                    const Run r = sys.run(pv, name, h, Path::fast, stride);
                    Errors err{kep, ref, M0};
                    for (std::size_t i = 0; i < r.t.size(); ++i)
                      err(i, r.t[i], State{r.q[2 * i], r.q[2 * i + 1], r.p[2 * i], r.p[2 * i + 1]});
                    // Newton evaluates the residual once before each update and once where it accepts
                    n_eval = (r.newton_mean + stages_of(name)) * static_cast<double>(r.steps);
                    return Measured{{err.worst.begin(), err.worst.end()}, r.steps};
                  },
                  [&] { return sys.time_run(pv, name, h, Path::fast, reps); }, reps, context(name, "k", k));
          add(std::move(pt), n_eval);  // after the run: it counts the updates
        }
        BaselineSetup b;
        b.name = "odeint-rk4";
        b.h = h;
        b.steps = N;
        b.every = stride;
        BaselineCount w;
        WorkPoint pt = measure_point_timed(
                work_point("odeint-rk4", "rk", "k", k, alpha, P), 4,
                [&] {
                  Errors err{kep, ref, M0};
                  w = baseline_run(b, f, x0, &err);
                  return Measured{{err.worst.begin(), err.worst.end()}, w.steps};
                },
                [&] { return time_per_call([&] { baseline_run(b, f, x0, nullptr); }, reps); }, reps,
                context("odeint-rk4", "k", k));
        add(std::move(pt), static_cast<double>(w.calls));
      }
      for (double tol : tols) {
        for (const char* name : {"odeint-dopri5", "odeint-bulirsch-stoer", "gsl-rk8pd"}) {
          // dense output on the grid (Odeint), stepped to each output time from a first step of 1e-3 (GSL)
          BaselineSetup b;
          b.name = name;
          b.abs_tol = b.rel_tol = tol;
          b.watch = BaselineWatch::outputs;
          b.times = grid;
          if (!has_dense_output(name)) b.first_step = 1e-3;
          b.label = "Odeint";
          BaselineCount w;
          WorkPoint pt = measure_point_timed(
                  work_point(name, "adaptive", "tol", tol, alpha, P), 4,
                  [&] {
                    Errors err{kep, ref, M0};
                    w = baseline_run(b, f, x0, &err);
                    return Measured{{err.worst.begin(), err.worst.end()}, w.steps};
                  },
                  [&] { return time_per_call([&] { baseline_run(b, f, x0, nullptr); }, reps); }, reps, context(name, "tol", tol));
          add(std::move(pt), static_cast<double>(w.calls));
        }
      }
    }

    const Params params{
        {"system", "kepler: q'' = -q/|q|^3 - (alpha + a sin(theta t)) q', q0 = (1 - e, 0), q0' = (0, sqrt((1 + e)/(1 - e)))"},
        {"alpha", format_number(alpha)}, {"a", format_number(a)}, {"theta", format_number(theta)}, {"e", format_number(e)},
        {"orbits", format_list(orbits) + " (T = 2 pi orbits)"}, {"k", format_list(ks) + " (steps an orbit, h = 2 pi/k)"},
        {"tol", format_list(tols) + " (abs = rel)"}, {"outputs", std::to_string(outputs) + " an orbit"},
        {"reps", std::to_string(reps)}, {"schemes", join_names(schemes)},
        {"reference", "Boost.Odeint runge_kutta_fehlberg78, long double, tol " + format_number(reference_tol) +
                          ", stepped to every output time; max |q - q'| against tol x 100: " + format_number(ref_diff)},
        {"orbit_at_T", orbit_at},
        {"logh", "logh and <family>:logh: the logarithmic-Hamiltonian leapfrog (Mikkola-Tanikawa 1999) and its "
                 "compositions at a fixed step h = 2 pi/k in sigma, dt = dsigma/U on the motion; each output time "
                 "reached by a partial step of the method itself from the last state before it (its length solved so "
                 "that t lands on t_i; local error of the method's order; the run keeps its fixed step), included in "
                 "the timings; friction over the drifts' dt (the angular-momentum law at round-off)"},
        {"evals", "evaluations of the equations a run: of the residual for the schemes (Newton updates + one per base "
                  "step, where it accepts; Jacobian assemblies not counted), of the right-hand side for the baselines; for logh the kicks (force evaluations, partial steps included)"},
        {"measures", "max over the output grid: phase_err = |q - q_ref|; momentum_err = |M/(M0 exp(-alpha t - (a/theta)(1 - cos "
                     "theta t))) - 1|, M = q x q'; energy_err = |E - E_ref|/|E_ref|; lrl_err = |A - A_ref|, A = q' x M - q/|q| "
                     "(|A| = eccentricity, its direction the pericentre's)"}};
    const std::vector<std::string> head{"method", "family", "alpha", "orbits", "knob", "value", "steps", "evals",
                                        "phase_err", "momentum_err", "energy_err", "lrl_err"};
    TsvWriter data(dir / "kepler_long_horizon.tsv", "long_horizon", params, head);
    TsvWriter tim(dir / "kepler_long_horizon_timings.tsv", "long_horizon", params,
                  {"method", "family", "alpha", "orbits", "knob", "value", "seconds_median", "seconds_min", "seconds_max", "reps"});
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const auto& p = pts[i];
      data.row(p.method, p.family, p.group, p.horizon, p.knob, p.value, p.steps, evals[i], p.errors[0], p.errors[1],
               p.errors[2], p.errors[3]);
      tim.row(p.method, p.family, p.group, p.horizon, p.knob, p.value, p.time.median, p.time.min, p.time.max, p.time.reps);
    }
    data.commit();
    tim.commit();

    const std::vector<long_horizon::Measure> measures{
        {"phase_err", "position (orbital phase) error", 1e-3},
        {"momentum_err", "angular-momentum law error", 1e-9},
        {"energy_err", "relative energy error", 1e-8},
        {"lrl_err", "Laplace-Runge-Lenz vector error (eccentricity, pericentre)", 1e-6}};
    long_horizon::summarise(pts, measures, "alpha", "orbits", dir / "kepler_long_horizon_summary.tsv", "long_horizon",
                            params);
    // The same summary with evaluations of the equations as the cost (a point's "time" is its count).
    std::vector<WorkPoint> by_evals = pts;
    for (std::size_t i = 0; i < by_evals.size(); ++i) by_evals[i].time = {evals[i], evals[i], evals[i], 1};
    Params evals_params = params;
    evals_params.push_back({"cost", "evaluations of the equations a run (the rows of kind seconds_to_target hold them)"});
    long_horizon::summarise(by_evals, measures, "alpha", "orbits", dir / "kepler_long_horizon_summary_evals.tsv",
                            "long_horizon", evals_params, "Evaluations of the equations (thousands) a run", 1e-3);
    long_horizon::draw_saved(dir, "kepler_long_horizon", "alpha", "orbits", measures, format_number(orbits.back()),
                             "Kepler with friction over " + format_number(orbits.back()) +
                                 " orbits: structural error against CPU time (median)");
    return 0;
  }();
}
