// Long-horizon work–precision for the damped Foucault pendulum (Section 3.2, the paper's scene): structural error
// against CPU time (median of repeats after a warm-up) over the paper's hour and longer.
//   precession_err  |rate_fit + Omega sin(beta)| / (Omega sin(beta)): the plane angle atan2(y, x) (mod pi) at the
//                   turning points (local maxima of |q| along the run) fitted against t (GSL); exactly -s t + c.
//   decay_err       |alpha_fit - alpha| / alpha from log Q_r at the turning points, Q_r = b r^2 + alpha r r' + r'^2,
//                   b = w2 - s^2, r r' = q.v, r'^2 = (q.v)^2/|q|^2: the signed radius obeys r'' = -b r - alpha r',
//                   so Q_r decays exactly as e^{-alpha t} (systems/foucault/exact.hpp, foucault_exact).
//   constraint_err  max over the run of |Phi(q, v)| / (|q| |v| + s |q|^2), (13) in the continuous variables. For the
//                   ODE methods v is their state (this is the drift of (13)); for the schemes v = (q_{j+1} - q_{j-1})/2h.
//   discrete_err    the schemes' own discrete constraint (paper: |Phi_d| / its round-off scale; rotation:
//                   |n(phi_{j+1}).q_{j+1}| / (|q_j| + |q_{j+1}|)), max over every step; nan for the ODE methods.
//   own_constraint_err  the constraint each method imposes: discrete_err for the schemes, constraint_err for the
//                   ODE methods (which impose (13) only through its derivative, so its value drifts).
// Methods: la-nh and contact-nh with the paper's constraint and with 'rotation', and Odeint rk4 over h; on the
// Lagrange–d'Alembert multiplier ODE (systems/foucault/exact.hpp) Odeint dopri5 and Bulirsch–Stoer and GSL rk8pd over tolerance
// (rel = tol, abs = 1e-8 tol in m and m/s, so the control stays relative while the amplitude decays by e^-18 in
// 10 h). A run that fails is a missing value with a message.
//   long_horizon --system foucault [--alpha 1e-3] [--T 3600] [--h 0.1 0.05 0.025] [--tol 1e-6 1e-8 1e-10] [--reps 3] [--out out]
//                         [any parameter of the scene: --m --l --g --beta --Omega --x0 --y0 --vx0 --vy0]
// The study in docs/speed-accuracy.md (the hour and 10 hours; a few minutes):
//   long_horizon --system foucault --T 3600 36000 --h 0.2 0.1 0.05 0.025 0.0125 --tol 1e-5 1e-6 1e-7 1e-8 1e-9 1e-10 1e-11
// Writes out/foucault_long_horizon.tsv (errors: same bits for the same command), _timings.tsv, _summary.tsv,
// out/foucault_long_horizon_drift.tsv (the constraint residual at the turning points of one run per method) and
// the figure out/foucault_long_horizon.{png,pdf}.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_fit.h>

#include "geomint/cli.hpp"
#include "geomint/scene_options.hpp"
#include "geomint/error.hpp"
#include "geomint/observers.hpp"
#include "geomint/systems/foucault.hpp"
#include "geomint/io.hpp"
#include "geomint/plots/figure.hpp"
#include "geomint/run/baselines.hpp"
#include "geomint/timing.hpp"
#include "geomint/work_precision.hpp"
#include "long_horizon/table.hpp"
#include "long_horizon/studies.hpp"

using namespace geomint;
using State4 = std::array<double, 4>;

namespace {

struct Structure {
  double precession = missing_value, decay = missing_value, constraint = missing_value, discrete = missing_value;
  long steps = 0, turns = 0;
  std::vector<std::array<double, 2>> drift;  // (t, constraint residual) at the turning points
};

// Turning points and the measures, fed with (t, q, v) at every step (or accepted step). The turning points and the
// plane at each are the pendulum's one record of them (PlaneTurns, systems/foucault/plane.hpp), as the system's own
// measures and the diagnostics keep them; this study adds the amplitude and the drift of (13) there.
class Probe {
 public:
  explicit Probe(const FoucaultParams<double>& p) : p_(p), b_(p.w2 - p.s * p.s) {}
  void point(double t, const Vec2<double>& q, const Vec2<double>& v) {
    const double r = q.norm();
    const double scale = r * v.norm() + p_.s * r * r;
    if (scale > 0) cmax_ = std::max(cmax_, std::abs(foucault_constraint(p_, q, v)) / scale);
    // the point before this one, j = have_ - 1 >= 1 (the first point is never a turning point here)
    if (have_ >= 2 && plane_.observe(have_ - 1, t_m_, r_mm_, q_m_(0), q_m_(1), r_m_, r, missing_value)) turn(q_m_, v_m_);
    r_mm_ = r_m_;
    r_m_ = r;
    t_m_ = t;
    q_m_ = q;
    v_m_ = v;
    ++have_;
  }
  Structure result(long steps) const {
    Structure s;
    s.steps = steps;
    s.turns = static_cast<long>(plane_.turns.size());
    s.constraint = cmax_;
    s.drift = drift_;
    if (plane_.turns.size() < 3) return s;
    s.precession = std::abs(plane_.rate() + p_.s) / p_.s;
    std::vector<double> ts;
    for (const auto& k : plane_.turns) ts.push_back(k.t);
    double c0, c1, c00, c01, c11, ss;
    gsl_fit_linear(ts.data(), 1, lq_.data(), 1, ts.size(), &c0, &c1, &c00, &c01, &c11, &ss);
    s.decay = std::abs(-c1 - p_.alpha) / p_.alpha;
    return s;
  }

 private:
  // the amplitude and the drift at the turning point just recorded
  void turn(const Vec2<double>& q, const Vec2<double>& v) {
    const double r2 = q.squaredNorm(), qv = q.dot(v);
    lq_.push_back(std::log(b_ * r2 + p_.alpha * qv + qv * qv / r2));
    const double scale = std::sqrt(r2) * v.norm() + p_.s * r2;
    drift_.push_back({plane_.turns.back().t, std::abs(foucault_constraint(p_, q, v)) / scale});
  }
  FoucaultParams<double> p_;
  double b_;
  double cmax_ = 0, r_m_ = 0, r_mm_ = 0, t_m_ = 0;
  long have_ = 0;
  Vec2<double> q_m_, v_m_;
  PlaneTurns plane_;
  std::vector<double> lq_;
  std::vector<std::array<double, 2>> drift_;
};

// A point of the study, and what its measured run saw besides the errors: the turning points' count and the
// drift of (13) at them.
struct Point {
  WorkPoint w;
  Structure s;
};

// The closed form Scheme on system Sys (its constraint row).
template <class Sys, class Scheme>
Structure scheme_run(const Sys& sc, double h, long N, bool measure) {
  const FoucaultParams<double> p(sc);
  const Vec2<double> q0(sc.x0, sc.y0), v0(sc.vx0, sc.vy0);
  if (!measure) {
    double acc = 0;
    systems::run_closed_form<Scheme>(sc, p, q0, v0, h, N, FoucaultStart::legendre,
                                     [&](const FoucaultStep<double>& st) { acc += st.qn(0); });
    do_not_optimize(acc);
    return {};
  }
  Probe probe(p);
  double disc = 0;
  systems::run_closed_form<Scheme>(sc, p, q0, v0, h, N, FoucaultStart::legendre, [&](const FoucaultStep<double>& st) {
    const double phid = Sys::imposed_constraint(p, st, h);
    const double scale = Sys::imposed_constraint_scale(st, h);
    disc = std::max(disc, scale > 0 ? std::abs(phid) / scale : std::abs(phid));
    probe.point(st.t, st.q, (st.qn - st.qm) / (2 * h));
  });
  Structure s = probe.result(N);
  s.discrete = disc;
  return s;
}

// A baseline through the one door (run/baselines.hpp) on the Lagrange–d'Alembert multiplier ODE from the consistent
// start, every step watched (an adaptive one's last step lands on T).
Structure baseline_run(const systems::FoucaultPendulum& sc, BaselineSetup b, double T, bool measure) {
  const FoucaultParams<double> p(sc);
  const FoucaultMultiplierOde ode(p);
  const OdeRhs f = [&ode](double t, const double* x, double* dx) {
    const State4 u{x[0], x[1], x[2], x[3]};
    State4 du;
    ode(u, du, t);
    std::copy(du.begin(), du.end(), dx);
  };
  const Vec2<double> q0(sc.x0, sc.y0), v0 = consistent_velocity(p, q0, Vec2<double>(sc.vx0, sc.vy0));
  Probe probe(p);
  b.T = T;
  b.end = BaselineEnd::land;
  const BaselineObserver observe = [&](std::size_t, double t, const double* x) {
    probe.point(t, Vec2<double>(x[0], x[1]), Vec2<double>(x[2], x[3]));
  };
  const BaselineCount n = run_baseline(b, f, {q0(0), q0(1), v0(0), v0(1)}, measure ? &observe : nullptr);
  return measure ? probe.result(n.steps) : Structure{};
}

// The measures, in the summary's order: precession_err, decay_err, constraint_err, discrete_err and
// own_constraint_err (the constraint each method imposes: discrete_err for the schemes, constraint_err for the ODE
// methods).
Point measure_point(const std::string& method, const std::string& family, const std::string& knob, double T, double value,
                    const std::function<Structure(bool)>& run, int reps) {
  Point pt;
  pt.w = geomint::measure_point(
      work_point(method, family, knob, value, WorkPoint::nan, T), 5,
      [&](bool m) {
        Structure s = run(m);
        const double own = family == "geometric" ? s.discrete : s.constraint;
        Measured r{{s.precession, s.decay, s.constraint, s.discrete, own}, s.steps};
        if (m) pt.s = std::move(s);
        return r;
      },
      reps, method + ", T = " + show(T) + " s, " + knob + " = " + show(value));
  return pt;
}

}  // namespace

int long_horizon_foucault(int argc, char** argv) {
  return [&] {
    systems::Foucault sc;  // the scene; the rotation runs use foucault-rotation with the same parameters
    std::vector<double> horizons{3600}, hs{0.1, 0.05, 0.025}, tols{1e-6, 1e-8, 1e-10};
    int reps = 3;
    Cli cli("long_horizon", "long-horizon structural error against CPU time: damped Foucault pendulum");
    add_study_system_option(cli, "foucault");
    cli.options.add_options()("T", po::value(&horizons)->multitoken(), "horizons in s (default 3600, the paper's hour)")(
        "h", po::value(&hs)->multitoken(), "steps of the fixed-step methods (each must divide every T; default 0.1 0.05 0.025)")(
        "tol", po::value(&tols)->multitoken(), "relative tolerances of the adaptive methods (default 1e-6 1e-8 1e-10)")(
        "reps", po::value(&reps)->default_value(reps), "timed repetitions");
    add_scene_options(cli, sc, {"T"});
    if (!cli.parse(argc, argv)) return 0;
    require(!horizons.empty() && !hs.empty() && !tols.empty(), "give at least one value per list");
    sc.validate();
    systems::FoucaultRotation sc_rotation;
    static_cast<systems::FoucaultPendulum&>(sc_rotation) = sc;
    require(sc.alpha > 0, "alpha must be positive (the decay rate is measured against it)");
    for (double T : horizons) require(std::isfinite(T) && T >= 100 && T <= 1e6, "T must be in [100, 1e6] s, got " + show(T));
    for (double T : horizons)
      for (double h : hs) {
        require_positive(h, "h");
        require(T / h <= 1e9, "more than 1e9 steps in one run");
        step_count(h, T);
      }
    for (double t : tols) require(std::isfinite(t) && t >= 1e-13 && t <= 1e-3, "tol must be in [1e-13, 1e-3], got " + show(t));
    require(reps >= 1 && reps <= 1000, "reps must be in [1, 1000]");
    std::sort(horizons.begin(), horizons.end());
    const auto dir = prepare_output_dir(cli.out);

    std::vector<Point> pts;
    for (double T : horizons) {
      std::fprintf(stderr, "long_horizon: T = %g s ...\n", T);
      for (double h : hs) {
        const long N = step_count(h, T);
        // (15) and (18) under the paper's names, the remedy's rows first, then the paper's
        auto geometric = [&](const auto& sys) {
          using Sys = std::decay_t<decltype(sys)>;
          const std::string tag = std::string("-") + Sys::discretization;
          pts.push_back(measure_point("la-nh" + tag, "geometric", "h", T, h, [&, h, N](bool m) {
            return scheme_run<Sys, systems::FoucaultPendulum::La>(sys, h, N, m);
          }, reps));
          pts.push_back(measure_point("contact-nh" + tag, "geometric", "h", T, h, [&, h, N](bool m) {
            return scheme_run<Sys, systems::FoucaultPendulum::Contact>(sys, h, N, m);
          }, reps));
        };
        geometric(sc_rotation);
        geometric(sc);
        BaselineSetup rk4;
        rk4.name = "odeint-rk4";
        rk4.h = h;
        rk4.steps = N;
        pts.push_back(measure_point("odeint-rk4", "rk", "h", T, h, [&, rk4, T](bool m) { return baseline_run(sc, rk4, T, m); }, reps));
      }
      for (double tol : tols) {
        for (const char* name : {"odeint-dopri5", "odeint-bulirsch-stoer", "gsl-rk8pd"}) {
          BaselineSetup b;  // relative control: abs = 1e-8 tol (the amplitude decays by e^-18 in 10 h)
          b.name = name;
          b.abs_tol = 1e-8 * tol;
          b.rel_tol = tol;
          pts.push_back(measure_point(name, "adaptive", "tol", T, tol, [&, b, T](bool m) { return baseline_run(sc, b, T, m); }, reps));
        }
      }
    }

    Params params = sc.header_params();
    params.insert(params.begin(), {"system", "foucault (methods *-paper) beside foucault-rotation (methods *-rotation), one scene"});
    params.insert(params.end(), {{"T", format_list(horizons)}, {"h", format_list(hs)}, {"tol", format_list(tols) + " (rel; abs = 1e-8 tol)"},
                                 {"start", "legendre"}, {"reps", std::to_string(reps)},
                                 {"measures", "precession_err = |rate + s|/s (turning points); decay_err = |alpha_fit - alpha|/alpha "
                                              "(log Q_r at turning points); constraint_err = max |Phi(q,v)|/(|q||v| + s|q|^2); "
                                              "discrete_err = the schemes' discrete constraint residual (round-off units); own_constraint_err = discrete_err (schemes) or constraint_err (ODE methods)"}});
    TsvWriter data(dir / "foucault_long_horizon.tsv", "long_horizon", params,
                   {"method", "family", "alpha", "T", "knob", "value", "steps", "turns", "precession_err", "decay_err",
                    "constraint_err", "discrete_err", "own_constraint_err"});
    TsvWriter tim(dir / "foucault_long_horizon_timings.tsv", "long_horizon", params,
                  {"method", "family", "alpha", "T", "knob", "value", "seconds_median", "seconds_min", "seconds_max", "reps"});
    // Drift of (13) over time: the finest run of each fixed-step method and the tightest of each adaptive one,
    // at the longest horizon.
    TsvWriter drift(dir / "foucault_long_horizon_drift.tsv", "long_horizon", params, {"method", "knob", "value", "t", "constraint_err"});
    std::vector<WorkPoint> work;
    for (auto& pt : pts) {
      const WorkPoint& p = pt.w;
      data.row(p.method, p.family, sc.alpha, p.horizon, p.knob, p.value, p.steps, pt.s.turns, p.errors[0], p.errors[1],
               p.errors[2], p.errors[3], p.errors[4]);
      tim.row(p.method, p.family, sc.alpha, p.horizon, p.knob, p.value, p.time.median, p.time.min, p.time.max, p.time.reps);
      const bool pick = p.horizon == horizons.back() && p.value == (p.knob == "h" ? hs.back() : tols.back());
      if (pick)
        for (const auto& [t, c] : pt.s.drift) drift.row(p.method, p.knob, p.value, t, c);
      work.push_back(p);
      work.back().group = sc.alpha;  // one damping: the summary's group
    }
    data.commit();
    tim.commit();
    drift.commit();

    // the summary's measures: the errors' columns 0, 1, 2 and 4 (discrete_err is nan for the ODE methods)
    const std::vector<long_horizon::Measure> measures{
        {"precession_err", "precession-rate error |rate + s|/s", 1e-6},
        {"decay_err", "energy-decay-rate error |alpha_fit - alpha|/alpha", 1e-4},
        {"constraint_err", "max |Phi(q,v)| / (|q||v| + s|q|^2), (13)", 1e-8},
        {"own_constraint_err", "residual of the constraint each method imposes", 1e-12}};
    for (auto& p : work) p.errors.erase(p.errors.begin() + 3);  // in the measures' order
    long_horizon::summarise(work, measures, "alpha", "T", dir / "foucault_long_horizon_summary.tsv", "long_horizon",
                            params);
    const auto d = plots::read_tsv(dir / "foucault_long_horizon.tsv");
    const auto tt = plots::read_tsv(dir / "foucault_long_horizon_timings.tsv");
    const long_horizon::Table table{d, tt, "alpha", "T"};

    // The figure: the three measures against CPU time at the longest horizon, and the drift of (13) over time.
    const auto dr = plots::read_tsv(dir / "foucault_long_horizon_drift.tsv");
    plots::Figure fig;
    fig.title = "Foucault pendulum, alpha = " + format_number(sc.alpha) + ", T = " + format_number(horizons.back()) +
                " s: structural error against CPU time (median); drift of (13) along the run";
    fig.rows = 2;
    fig.cols = 3;
    fig.width_in = 15;
    fig.height_in = 9;
    const auto methods = table.values("method");
    for (const auto& M : measures)
      fig.panels.push_back(long_horizon::cost_panel(d, tt, M, methods, M.label, [&](std::size_t i, const std::string& m) {
        return d.text(i, "method") == m && d.number(i, "T") == horizons.back();
      }));
    plots::Panel pd;
    pd.setup = "set logscale y\nset format y '10^{%L}'\nset xlabel 't (s)'\nset ylabel '|Phi| / (|q||v| + s|q|^2)'\n"
               "set key top left font ',7'\nset title '(13) at the turning points (finest h, last tol; schemes: central v)' font ',9' noenhanced\n";
    for (const auto& m : methods) {
      auto keep = [&](std::size_t i) { return dr.text(i, "method") == m && dr.number(i, "constraint_err") > 0; };
      const auto x = dr.numbers("t", keep), y = dr.numbers("constraint_err", keep);
      if (!x.empty()) pd.series.push_back({x, y, m, plots::style_for(m, "lines")});
    }
    fig.panels.push_back(std::move(pd));
    fig.draw(dir / "foucault_long_horizon");
    return 0;
  }();
}
