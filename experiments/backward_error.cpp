// Backward error analysis of the oscillator integrators: each discrete solution against the solution of
// its modified equation ((8) for LA, (11) for contact; derived by automatic differentiation, integrated with
// Odeint at tolerance 1e-12) and against the original equation, step by step, h halving.
// Also: the all-orders modified coefficients (a_h, b_h) from the characteristic roots of each recurrence,
// and a cross-check of the Odeint modified solution against GSL's rk8pd.
//   backward_error [--h-max 0.2] [--h-min 0.003] [--alpha 0.01 0.1 1] [--T 50] [--out out]
// Writes out/backward_error.tsv, out/backward_error_fits.tsv, out/all_orders.tsv,
// out/backward_error_crosscheck.tsv and out/backward_error_{la,contact}.{png,pdf}.
#include <array>
#include <cmath>
#include <cstdio>

#include "geomint/budget.hpp"
#include "geomint/cli.hpp"
#include "geomint/error.hpp"
#include "geomint/io.hpp"
#include "geomint/modified/agreement.hpp"
#include "geomint/modified/all_orders.hpp"
#include "geomint/registry.hpp"
#include "geomint/plots/figure.hpp"
#include "geomint/record.hpp"
#include "geomint/study.hpp"

using namespace geomint;
using namespace geomint::modified;

int main(int argc, char** argv) {
  return guarded_main("backward_error", [&] {
    double h_max = 0.2, h_min = 0.003, T = 50, q0 = -0.25, p0 = 0.75, tol = 1e-12;
    std::vector<double> alphas{0.01, 0.1, 1};
    Cli cli("backward_error", "discrete solutions against their modified equations (8), (11) and the original");
    cli.options.add_options()("h-max", po::value(&h_max)->default_value(h_max), "largest step")(
        "h-min", po::value(&h_min)->default_value(h_min), "halve until h <= h-min")(
        "T", po::value(&T)->default_value(T), "horizon")("q0", po::value(&q0)->default_value(q0), "initial position")(
        "p0", po::value(&p0)->default_value(p0), "initial momentum")(
        "alpha", po::value(&alphas)->multitoken()->default_value(alphas, "0.01 0.1 1"), "damping values")(
        "tol", po::value(&tol)->default_value(tol), "Odeint tolerance for the modified equations");
    if (!cli.parse(argc, argv)) return 0;
    const auto hs = halving_sequence(h_max, h_min);
    // the discrete runs, their modified solutions and the all-orders runs: about 5 runs per (scheme, alpha, h)
    // a planned step costs ~250 ns (the Odeint solutions of the modified equations; measured: 0.48 s of CPU per
    // 1.9e6 planned steps, T = 50 -> 100): 5 cheap steps
    for (double h : hs) plan_steps(5.0 * 2 * static_cast<double>(alphas.size()) * static_cast<double>(step_count(h, T)),
                                   "the sweep (schemes x alpha x starts x T/h)", 5);
    const SystemInfo& osc = find_system("oscillator");
    auto scene = [&](double a) { return ParamValues{{"alpha", a}, {"q0", q0}, {"p0", p0}, {"T", T}}; };
    for (double a : alphas) osc.validate(scene(a));
    require(std::isfinite(tol) && tol > 0 && tol <= 1e-6, "tol must be in (0, 1e-6]");
    check_tolerance(tol, "tol");
    const auto dir = prepare_output_dir(cli.out);
    const std::vector<std::string> names{"la", "contact"};
    const Params params{{"h", format_list(hs)},       {"T", format_number(T)},     {"q0", format_number(q0)},
                        {"p0", format_number(p0)},    {"alpha", format_list(alphas)}, {"tol", format_number(tol)},
                        {"modified", "la: (8), contact: (11); equations by Eigen AutoDiff; Odeint dopri5 dense"}};

    TsvWriter tsv(dir / "backward_error.tsv", "backward_error", params,
                  {"scheme", "alpha", "h", "start", "err_modified", "err_original", "err_p_modified", "err_p_original",
                   "err_z_modified", "err_z_original"});
    std::printf("%-8s %-5s %-10s %-10s %12s %12s %12s %12s %12s %12s\n", "scheme", "alpha", "h", "start", "q:modified",
                "q:original", "p:modified", "p:original", "z:modified", "z:original");
    for (const auto& s : names)
      for (double a : alphas)
        for (Start st : {Start::consistent, Start::naive})
          for (double h : hs) {
            const double nan = missing_value;
            const auto g = run_or_missing(
                s + " alpha=" + show(a) + " h=" + show(h) + " start=" + start_name(st),
                [&] { return agreement(s, a, h, T, q0, p0, st, 1, tol); },
                [&] { return Agreement{nan, nan, nan, nan, nan, nan}; });
            tsv.row(s, a, h, start_name(st), g.err_modified, g.err_original, g.err_p_modified, g.err_p_original,
                    g.err_z_modified, g.err_z_original);
            std::printf("%-8s %-5g %-10g %-10s %12.3e %12.3e %12.3e %12.3e %12.3e %12.3e\n", s.c_str(), a, h,
                        start_name(st), g.err_modified, g.err_original, g.err_p_modified, g.err_p_original,
                        g.err_z_modified, g.err_z_original);
          }
    tsv.commit();

    // Fitted slopes, read back from the saved table.
    const auto t = plots::read_tsv(dir / "backward_error.tsv");
    TsvWriter fits(dir / "backward_error_fits.tsv", "backward_error", params,
                   {"scheme", "alpha", "start", "quantity", "against", "fitted_order", "points"});
    std::printf("\nfitted slopes of max error vs h\n%-8s %-5s %-10s %-3s %9s %9s\n", "scheme", "alpha", "start", "var",
                "modified", "original");
    for (const auto& s : names)
      for (double a : alphas)
        for (const char* st : {"consistent", "naive"})
          for (const char* var : {"q", "p", "z"}) {
            if (s == "la" && std::string(var) == "z") continue;
            auto keep = [&](size_t i) {
              return t.text(i, "scheme") == s && t.number(i, "alpha") == a && t.text(i, "start") == st;
            };
            const std::string sfx = std::string(var) == "q" ? "" : std::string("_") + var;
            const auto x = t.numbers("h", keep);
            const auto fm = fit_order(x, t.numbers("err" + sfx + "_modified", keep));
            const auto fo = fit_order(x, t.numbers("err" + sfx + "_original", keep));
            fits.row(s, a, st, var, "modified", fm.slope, fm.points);
            fits.row(s, a, st, var, "original", fo.slope, fo.points);
            std::printf("%-8s %-5g %-10s %-3s %9.3f %9.3f\n", s.c_str(), a, st, var, fm.slope, fo.slope);
          }
    fits.commit();

    // All-orders modified coefficients.
    TsvWriter ao(dir / "all_orders.tsv", "backward_error", params,
                 {"scheme", "alpha", "h", "a_h", "b_h", "a1_measured", "a1_predicted", "b1_measured", "b1_predicted",
                  "max_dev_all_orders"});
    std::printf("\nall-orders modified equation q'' + a_h q' + b_h q = 0; first-order coefficients (a_h - alpha)/h, "
                "(b_h - 1)/h against (8)/(11)\n%-8s %-5s %-10s %14s %14s %11s %11s %11s %11s %11s\n",
                "scheme", "alpha", "h", "a_h", "b_h", "a1 meas", "a1 (8/11)", "b1 meas", "b1 (8/11)", "max|q-q^|");
    for (const auto& s : names)
      for (double a : alphas)
        for (double h : hs) {
          const std::string context = s + " alpha=" + show(a) + " h=" + show(h) + " (all orders)";
          // the coefficients, and the first-order ones predicted by the code of (8)/(11): (a_mod - alpha)/h,
          // (b_mod - 1)/h; beyond double precision (a damping of 1e200) they are missing values, named
          const auto co = run_or_missing(
              context,
              [&] {
                const auto m = all_orders_by_name(s, h, a);
                const auto c = modified_coefficients(s, a, h);
                const std::array<double, 6> v{m.a, m.b, (m.a - a) / h, (c.a - a) / h, (m.b - 1) / h, (c.b - 1) / h};
                for (double x : v)
                  if (!std::isfinite(x) && !is_missing(x))
                    throw NumericalFailure(0, "modified coefficients", "a coefficient is " + show(x));
                return std::make_pair(m, v);
              },
              [&] {
                AllOrders none;
                return std::make_pair(none, std::array<double, 6>{missing_value, missing_value, missing_value,
                                                                   missing_value, missing_value, missing_value});
              });
          const auto& [m, v] = co;
          const double dev = run_or_missing(
              context,
              [&] {
                const auto tr = osc.run(scene(a), s, h, Path::fast, 1);
                return all_orders_deviation(m, tr.t, tr.q);
              },
              [] { return missing_value; });
          ao.row(s, a, h, v[0], v[1], v[2], v[3], v[4], v[5], dev);
          std::printf("%-8s %-5g %-10g %14.10f %14.10f %11.6f %11.6f %11.6f %11.6f %11.2e\n", s.c_str(), a, h, v[0],
                      v[1], v[2], v[3], v[4], v[5], dev);
        }
    ao.commit();

    // Cross-check of the Odeint modified solution against GSL rk8pd on one case.
    {
      const double a = 0.1, h = 0.05;
      TsvWriter cc(dir / "backward_error_crosscheck.tsv", "backward_error", params,
                   {"scheme", "alpha", "h", "max_diff_q", "max_diff_z"});
      for (const auto& s : names) {
        const auto [dq, dz] = run_or_missing(
            s + " alpha=" + show(a) + " h=" + show(h) + " (Odeint vs GSL)",
            [&] {
              const auto ode = modified_solution(s, a, h, h, T, q0, p0, Start::consistent, 1, tol);
              const auto gsl = modified_solution_gsl(s, a, h, ode.t, {ode.q[0], ode.v[0], 0.0}, tol);
              double mq = 0, mz = 0;
              for (size_t j = 0; j < ode.t.size(); ++j) {
                mq = std::max(mq, std::abs(ode.q[j] - gsl[j][0]));
                mz = std::max(mz, std::abs(ode.z[j] - gsl[j][2]));
              }
              return std::make_pair(mq, mz);
            },
            [] { return std::make_pair(missing_value, missing_value); });
        cc.row(s, a, h, dq, dz);
        std::printf("\nOdeint dopri5 vs GSL rk8pd, %s alpha=%g h=%g: max|dq| = %.2e, max|dz| = %.2e", s.c_str(), a, h,
                    dq, dz);
      }
      std::printf("\n");
      cc.commit();
    }

    // Figures: one per integrator, one panel per alpha.
    for (const auto& s : names) {
      plots::Figure fig;
      fig.title = s + " integrator: max_j |q_j - q(t_j)| against the modified and the original equation";
      fig.cols = static_cast<int>(alphas.size());
      fig.width_in = 4.2 * fig.cols;
      fig.height_in = 4.4;
      for (double a : alphas) {
        plots::Panel p;
        p.setup = "set logscale xy\nset format y '10^{%L}'\nset xlabel 'h'\nset ylabel 'max error in q'\n"
                  "set key bottom right\nset title 'alpha = " + format_number(a) + "'\n";
        auto sel = [&](const char* st) {
          return [&, st](size_t i) {
            return t.text(i, "scheme") == s && t.number(i, "alpha") == a && t.text(i, "start") == st;
          };
        };
        const auto x = t.numbers("h", sel("consistent"));
        const auto eo = t.numbers("err_original", sel("consistent"));
        const auto ec = t.numbers("err_modified", sel("consistent"));
        const auto en = t.numbers("err_modified", sel("naive"));
        p.series.push_back({x, eo, plots::slope_label("original", fit_order(x, eo).slope),
                            "linespoints lw 1.5 pt 7 lc rgb '#d95f02'"});
        p.series.push_back({x, ec, plots::slope_label("modified, consistent start", fit_order(x, ec).slope),
                            "linespoints lw 1.5 pt 5 lc rgb '#1b9e77'"});
        p.series.push_back({x, en, plots::slope_label("modified, naive start", fit_order(x, en).slope),
                            "linespoints lw 1 pt 4 dt 2 lc rgb '#7570b3'"});
        // reference slopes 1 and 2 through the first points
        std::vector<double> r1, r2;
        for (double h : x) {
          r1.push_back(eo.front() * 0.5 * (h / x.front()));
          r2.push_back(ec.front() * 0.5 * (h / x.front()) * (h / x.front()));
        }
        p.series.push_back({x, r1, "slope 1", "lines dt 3 lc rgb '#999999'"});
        p.series.push_back({x, r2, "slope 2", "lines dt 4 lc rgb '#555555'"});
        fig.panels.push_back(std::move(p));
      }
      fig.draw(dir / ("backward_error_" + s));
    }
    return 0;
  });
}
