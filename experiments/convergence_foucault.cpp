// Convergence of the nonholonomic integrators (15) and (18) on the damped Foucault pendulum against the
// continuous reference: the Lagrange–d'Alembert equations with a multiplier, integrated by Boost.Odeint
// (dense-output dopri5, tol 1e-12) from the consistent initial state.
//   convergence_foucault [--h-max 0.1] [--h-min 0.0015625] [--alpha 1e-3 1e-4 0.1] [--T 4 32] [--out out]
// Writes out/convergence_foucault.tsv (one row per scheme, alpha, horizon, h), out/convergence_foucault_fits.tsv
// (fitted order per scheme, alpha, horizon) and out/convergence_foucault.{png,pdf} (one log-log panel per horizon).
//
// Horizons. The bob passes through the origin every half period (first at t = pi/(2 w) = 4.105 s, w^2 = w2 - s^2).
// A step that lands at distance u << h|q'| from the origin turns the discrete plane of oscillation by about
// s h (h|q'|/u) (the discrete constraint makes q_{j+1} - q_j nearly parallel to q_j), a heavy-tailed O(h)
// error that depends on where the grid happens to fall. So:
//   T = 4 s  (the first quarter swing, no step near the origin): the smooth error, clean fitted orders;
//   T = 32 s (two periods, four passes through the origin): what those passes add, shown, not hidden.
// Columns: err_max = max_j |q_j - q_ref(t_j)|; energy_err = max_j |E_{j+1/2} - E_ref(t_{j+1/2})| / E0 (chord
// energy, see foucault.hpp); plane_err = max |angle of q_j - angle of q_ref(t_j)| (mod pi, rad) over the steps
// where the reference is in the outer half of its swing (|q_ref| >= |q0| e^{-alpha t/2}/2), where the polar
// angle is the plane's; rate_rel_err = |fitted precession rate / (-Omega sin beta) - 1| (turning points, >= 3).
#include <cmath>
#include <cstdio>

#include "geomint/budget.hpp"
#include "geomint/cli.hpp"
#include "geomint/error.hpp"
#include "geomint/foucault_diagnostics.hpp"
#include "geomint/observers.hpp"
#include "geomint/io.hpp"
#include "geomint/registry.hpp"
#include "geomint/plots/figure.hpp"
#include "geomint/study.hpp"

using namespace geomint;

namespace {

struct RunErrors {
  double err_max = 0, energy_err = 0, plane_err = 0, rate_rel_err = missing_value, min_r = 0;
  std::string status = "ok";
};

}  // namespace

int main(int argc, char** argv) {
  return guarded_main("convergence_foucault", [&] {
    systems::Foucault base;  // the paper's constraint (13) as printed
    double h_max = 0.1, h_min = 0.0015625, tol = 1e-12;
    std::vector<double> alphas{1e-3, 1e-4, 0.1}, horizons{4, 32};
    std::vector<std::string> names{"la-nh", "contact-nh"};
    std::string start_name = "legendre";
    Cli cli("convergence_foucault", "error against h of the nonholonomic integrators vs the continuous reference");
    cli.options.add_options()("h-max", po::value(&h_max)->default_value(h_max), "largest step")(
        "h-min", po::value(&h_min)->default_value(h_min), "halve until h <= h-min")(
        "alpha", po::value(&alphas)->multitoken()->default_value(alphas, "1e-3 1e-4 0.1"), "damping values")(
        "T", po::value(&horizons)->multitoken()->default_value(horizons, "4 32"), "horizons, s")(
        "start", po::value(&start_name)->default_value(start_name), "starting procedure: legendre or taylor")(
        "schemes", po::value(&names)->multitoken()->default_value(names, "la-nh contact-nh"), "schemes")(
        "tol", po::value(&tol)->default_value(tol), "Odeint tolerance of the reference");
    if (!cli.parse(argc, argv)) return 0;

    // Validate everything before writing anything.
    const auto hs = halving_sequence(h_max, h_min);
    require(!horizons.empty() && !alphas.empty(), "give at least one horizon and one alpha");
    // the reference on the grid h_min / 2 (below): its times and its states (q, q'), and Odeint's copy of them
    for (double T : horizons)
      check_memory(double(step_count(hs.back() / 2, T) + 1) * sizeof(double) * (1 + 2 * 4),
                   "the reference on h_min / 2 over T = " + show(T) + " (lower --T or raise --h-min)");
    for (double T : horizons)
      for (double h : hs)
        plan_steps(static_cast<double>(names.size() * alphas.size()) * static_cast<double>(step_count(h, T)),
                   "the sweep (schemes x alpha x T/h)");
    for (double a : alphas) {
      systems::Foucault sc = base;
      sc.alpha = a;
      sc.validate();
    }
    const FoucaultStart start = parse_foucault_start(start_name);
    for (const auto& n : names) generic::visit_closed_form<systems::Foucault>(n, [](auto) {});  // (15), (18)
    require(std::isfinite(tol) && tol > 0 && tol <= 1e-6, "tol must be in (0, 1e-6]");
    check_tolerance(tol, "tol");
    const auto dir = prepare_output_dir(cli.out);

    const double s = base.s();
    const Params params{{"h", format_list(hs)},
                        {"T", format_list(horizons)},
                        {"alpha", format_list(alphas)},
                        {"start", start_name},
                        {"reference", "Lagrange-d'Alembert ODE with multiplier, Boost.Odeint dopri5 dense output, tol " +
                                          format_number(tol) + ", consistent initial velocity"},
                        {"err_max", "max_j |q_j - q_ref(t_j)|"},
                        {"energy_err", "max_j |E_{j+1/2} - E_ref(t_{j+1/2})| / E0, chord energy"},
                        {"plane_err", "max |angle(q_j) - angle(q_ref(t_j))| mod pi over |q_ref| >= |q0| e^{-alpha t/2}/2"}};
    TsvWriter tsv(dir / "convergence_foucault.tsv", "convergence_foucault", params,
                  {"scheme", "alpha", "T", "h", "steps", "err_max", "order", "energy_err", "plane_err",
                   "rate_rel_err", "min_r", "status"});
    TsvWriter fits(dir / "convergence_foucault_fits.tsv", "convergence_foucault", params,
                   {"scheme", "alpha", "T", "fitted_order", "points", "expected_order"});
    std::printf("%-10s %-7s %-4s %-10s %11s %6s %11s %11s %10s %10s\n", "scheme", "alpha", "T", "h", "err_max", "order",
                "energy_err", "plane_err", "rate_err", "min_r");
    for (double a : alphas) {
      systems::Foucault sc = base;
      sc.alpha = a;
      const FoucaultParams<double> p(sc);
      const Vec2<double> q0(sc.x0, sc.y0), v0(sc.vx0, sc.vy0);
      const Vec2<double> v0c = consistent_velocity(p, q0, v0);
      const double E0 = foucault_energy(p, q0, v0c);
      for (double T : horizons) {
        sc.T = T;
        // Reference on the grid h_min/2: it holds every t_j and every t_{j+1/2} of every h in the sequence
        // exactly (the h are h_max / 2^k, so j h and (j + 1/2) h are integer multiples of h_min/2).
        const double hr = hs.back() / 2;
        const long Nr = step_count(hr, T);
        std::vector<double> times(static_cast<size_t>(Nr) + 1);
        for (long i = 0; i <= Nr; ++i) times[static_cast<size_t>(i)] = static_cast<double>(i) * hr;
        const auto ref = foucault_reference(sc, times, tol);
        double ref_dev = 0;  // the reference against the closed form, for the record
        for (long i = 0; i <= Nr; ++i) {
          const auto ex = foucault_exact(p, q0, v0c, times[static_cast<size_t>(i)]);
          const auto& u = ref[static_cast<size_t>(i)];
          ref_dev = std::max(ref_dev, std::hypot(u[0] - ex.q(0), u[1] - ex.q(1)));
        }
        std::printf("# alpha %g, T %g: reference vs closed form max |dq| = %.2e m\n", a, T, ref_dev);
        for (const auto& n : names) {
          std::vector<double> errs;
          for (double h : hs) {
            const long N = step_count(h, T);
            const long stride = std::lround(h / hr);
            RunErrors e;
            try {
              generic::visit_closed_form<systems::Foucault>(n, [&](auto scheme) {
                using Scheme = decltype(scheme);
                FoucaultDiagnostics<systems::Foucault, double> diag(p, h, N, N, q0, v0);
                systems::run_closed_form<Scheme>(sc, p, q0, v0, h, N, start, [&](const FoucaultStep<double>& st) {
                  diag(st);
                  const auto& rn = ref[static_cast<size_t>((st.j + 1) * stride)];
                  e.err_max = std::max(e.err_max, std::hypot(st.qn(0) - rn[0], st.qn(1) - rn[1]));
                  const auto& rh = ref[static_cast<size_t>(st.j * stride + stride / 2)];
                  const double Eref = foucault_energy<double>(p, Vec2<double>(rh[0], rh[1]), Vec2<double>(rh[2], rh[3]));
                  e.energy_err = std::max(e.energy_err, std::abs(chord_energy(p, st.q, st.qn, h) - Eref) / E0);
                  const auto& rj = ref[static_cast<size_t>(st.j * stride)];
                  const double rr = std::hypot(rj[0], rj[1]);
                  if (rr >= q0.norm() * std::exp(-a * st.t / 2) / 2)
                    e.plane_err = std::max(e.plane_err, std::abs(nearest_branch(std::atan2(st.q(1), st.q(0)) -
                                                                                    std::atan2(rj[1], rj[0]),
                                                                                0.0, foucault_pi)));
                });
                const auto S = diag.summary();
                e.min_r = S.min_r;
                if (std::isfinite(S.rate)) e.rate_rel_err = std::abs(S.rate / -s - 1);
              });
            } catch (const NumericalFailure& f) {
              e = RunErrors{};  // a failed run is a missing value, not a crash
              e.err_max = e.energy_err = e.plane_err = e.min_r = missing_value;
              e.status = f.what();
            }
            errs.push_back(e.err_max);
            const double order = errs.size() > 1 ? std::log(errs[errs.size() - 2] / errs.back()) /
                                                       std::log(hs[errs.size() - 2] / hs[errs.size() - 1])
                                                 : missing_value;
            tsv.row(n, a, T, h, N, e.err_max, order, e.energy_err, e.plane_err, e.rate_rel_err, e.min_r, e.status);
            std::printf("%-10s %-7g %-4g %-10g %11.4e %6.2f %11.4e %11.4e %10.3e %10.3e\n", n.c_str(), a, T, h,
                        e.err_max, order, e.energy_err, e.plane_err, e.rate_rel_err, e.min_r);
          }
          const auto fit = fit_order(hs, errs);
          fits.row(n, a, T, fit.slope, fit.points, find_system(systems::Foucault::name).scheme(n).order);
        }
      }
    }
    tsv.commit();
    fits.commit();

    std::printf("\nfitted orders (least squares of log err_max on log h, all h):\n");
    const auto ft = plots::read_tsv(dir / "convergence_foucault_fits.tsv");
    for (size_t r = 0; r < ft.rows.size(); ++r)
      std::printf("%-10s alpha %-7g T %-4g order %6.3f (%d points)\n", ft.text(r, "scheme").c_str(),
                  ft.number(r, "alpha"), ft.number(r, "T"), ft.number(r, "fitted_order"),
                  static_cast<int>(ft.number(r, "points")));

    const auto t = plots::read_tsv(dir / "convergence_foucault.tsv");
    plots::Figure fig;
    fig.title = "Foucault pendulum: max_j |q_j - q_{ref}(t_j)| against h";
    fig.cols = static_cast<int>(horizons.size());
    fig.width_in = 5 * fig.cols;
    fig.height_in = 4.6;
    const char* points[] = {"pt 7", "pt 5", "pt 9", "pt 11", "pt 13"};
    for (double T : horizons) {
      plots::Panel p;
      p.setup = "set logscale xy\nset format y '10^{%L}'\nset xlabel 'h (s)'\nset ylabel 'max error in q (m)'\n"
                "set key bottom right\nset title 'T = " + format_number(T) + " s'\n";
      for (const auto& n : names)
        for (size_t ia = 0; ia < alphas.size(); ++ia) {
          const double a = alphas[ia];
          auto keep = [&](size_t i) {
            return t.text(i, "scheme") == n && t.number(i, "alpha") == a && t.number(i, "T") == T;
          };
          const auto x = t.numbers("h", keep), y = t.numbers("err_max", keep);
          p.series.push_back({x, y, plots::slope_label(n + ", alpha " + format_number(a), fit_order(x, y).slope),
                              plots::style_for(n, std::string("linespoints ") + points[ia % 5])});
        }
      fig.panels.push_back(std::move(p));
    }
    fig.draw(dir / "convergence_foucault");
    return 0;
  });
}
