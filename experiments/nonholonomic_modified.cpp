// Backward error analysis of the nonholonomic integrators (the paper's future work), automatically: the
// modified equation of the constrained LA and contact schemes with the modified multiplier and the modified
// constraint Phi_h = Phi_d(q~(t), q~(t+h)) on which the discrete solution lies.
//   nonholonomic_modified [--systems knife-edge foucault-rotation] [--schemes la contact] [--orders 0 1 2 3]
//                         [--h-max 0.2] [--halvings 2] [--tol 1e-13] [--radii 6] [--threads <cores>]
//                         [any parameter of the systems: --alpha 0.1 --T 2 --x0 ...] [--out out]
// Presets alpha = 0.1 (the systems' damping; the Foucault scene's default 1e-3 makes LA's odd-order terms,
// proportional to alpha, too small to show over this range of h) and T = 2; every other parameter is the system's
// default unless given. Bigger runs: --orders 0 1 2 3 --halvings 3 --T 4.
// Part 1, agreement: each discrete solution (generic Newton step, long double) against the solution of its
// order-K modified equation (Odeint dopri5, tol), started by shooting (q~(0) = q_0, q~(h) = q_1, which puts
// the start on the modified constraint). Columns: err_modified = max_j |q_j - q~(t_j)|; err_mu =
// max_j |lambda_j/h - mu~(t_j)| (the discrete impulse against the modified multiplier); phi_d =
// max_j |Phi_d(q~(t_j), q~(t_{j+1}))| (the discrete constraint along the modified solution); phi_h0 =
// |Phi_h^[K](x~(0))| and phi_h_drift = max_j |Phi_h^[K](x~(t_j)) - Phi_h^[K](x~(0))| (the truncated modified
// constraint at the start and how far the modified flow moves it).
// Part 2, when a Foucault pendulum is named (foucault or foucault-rotation), with its parameters: the paper's
// constraint (13) near the origin, where its covector (-y, x) vanishes: the norms of
// F_k and mu_k at q = (r, 0) with the consistent velocity (V, -Omega sin(beta) r), V the bob's speed through
// the origin, for r = 0.1 down to 0.1^radii; and the power of r of each, fitted over the three smallest r.
// Writes out/nonholonomic_modified.tsv, out/nonholonomic_modified_fits.tsv, out/nonholonomic_modified_origin.tsv,
// out/nonholonomic_modified_origin_fits.tsv and out/nonholonomic_modified.{png,pdf}.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "geomint/budget.hpp"
#include "geomint/cli.hpp"
#include "geomint/constants.hpp"
#include "geomint/error.hpp"
#include "geomint/io.hpp"
#include "geomint/modified/automatic_registry.hpp"
#include "geomint/parallel.hpp"
#include "geomint/plots/figure.hpp"
#include "geomint/registry.hpp"
#include "geomint/study.hpp"
#include "geomint/system_cli.hpp"

using namespace geomint;
using namespace geomint::modified;

int main(int argc, char** argv) {
  return guarded_main("nonholonomic_modified", [&] {
    std::vector<std::string> systems{"knife-edge", "foucault-rotation"}, schemes{"la", "contact"};
    std::vector<int> orders{1, 2, 3};
    double h_max = 0.2, tol = 1e-13;
    int halvings = 2, radii = 6;
    unsigned threads = default_threads();
    Cli cli("nonholonomic_modified", "modified equations, multipliers and constraints of the nonholonomic integrators");
    SystemsOptions sysopt(cli, argc, argv, systems, {{"alpha", 0.1}, {"T", 2}}, "constrained systems");
    cli.options.add_options()(
        "schemes", po::value(&schemes)->multitoken()->default_value(schemes, "la contact"), "schemes")(
        "orders", po::value(&orders)->multitoken()->default_value(orders, "1 2 3"), "orders K")(
        "h-max", po::value(&h_max)->default_value(h_max, format_number(h_max)), "largest step")(
        "halvings", po::value(&halvings)->default_value(halvings), "number of halvings of h")(
        "tol", po::value(&tol)->default_value(tol), "Odeint tolerance")(
        "radii", po::value(&radii)->default_value(radii), "part 2: r = 0.1 ... 0.1^radii")(
        "threads", po::value(&threads)->default_value(threads), "worker threads (the files do not depend on them)");
    if (!cli.parse(argc, argv)) return 0;
    systems = sysopt.names();
    require_positive(h_max, "h-max");
    require(halvings >= 2 && halvings <= 8, "halvings must be in [2, 8]");
    require(std::isfinite(tol) && tol >= 1e-15 && tol <= 1e-6, "tol must be in [1e-15, 1e-6]");
    require(radii >= 3 && radii <= 12, "radii must be in [3, 12]");
    require(threads >= 1 && threads <= 256, "threads must be in [1, 256]");
    std::vector<double> hs;
    for (int i = 0; i <= halvings; ++i) hs.push_back(h_max / std::pow(2.0, i));
    for (int K : orders) require(K >= 0 && K <= 4, "orders must be in [0, 4]");
    for (const auto& s : systems) {
      const auto& info = find_system(s);
      require(info.constraints > 0, "system '" + s + "' has no constraint");
      for (const auto& x : schemes) modified_scheme(info, x);
    }
    // every (system, scheme, order, h) is a run of T/h discrete steps (long double) and an Odeint solution of its
    // modified equation with multiplier rows over the same grid: ~3 ms a planned step (measured: 2.5 s of CPU per
    // 840 planned steps, T = 2 -> 4 at the defaults), 5e4 cheap steps
    for (double h : hs)
      for (const auto& s : systems) {
        double cost = 0;  // of a planned step of this system, over the schemes (a composition's cost factor)
        for (const auto& x : schemes) cost += modified_cost_factor(find_system(s), x);
        plan_steps(cost * static_cast<double>(orders.size()) * static_cast<double>(step_count(h, sysopt.value(s, "T"))),
                   "the sweep (systems x schemes x orders x T/h)", 5e4);
      }
    const auto dir = prepare_output_dir(cli.out);
    const double floor = 1e2 * tol;
    std::vector<double> order_values(orders.begin(), orders.end());
    Params params = sysopt.header();
    params.insert(params.end(), {{"schemes", join_names(schemes)},
                        {"orders", format_list(order_values)}, {"h", format_list(hs)},
                        {"tol", format_number(tol)}, {"fit_floor", format_number(floor)}, {"radii", std::to_string(radii)},
                        {"discrete", "generic Newton step, long double, the parameters above, else the system's defaults"},
                        {"modified", "automatic (series through the residual, with multiplier and constraint rows), Odeint dopri5 dense, shooting start"}});

    // Part 1
    TsvWriter tsv(dir / "nonholonomic_modified.tsv", "nonholonomic_modified", params,
                  {"system", "scheme", "K", "h", "err_modified", "err_mu", "phi_d", "phi_h0", "phi_h_drift"});
    int sw = 8;  // the scheme column fits the longest name (compositions: "<family>:<base>")
    for (const auto& x : schemes) sw = std::max(sw, static_cast<int>(x.size()));
    std::printf("%-18s %-*s %-2s %-7s %11s %11s %11s %11s %11s\n", "system", sw, "scheme", "K", "h", "err_q", "err_mu", "phi_d",
                "phi_h(0)", "phi_h drift");
    struct Run {
      std::string system, scheme;
      int K;
      double h;
    };
    std::vector<Run> runs;
    for (const auto& s : systems)
      for (const auto& x : schemes)
        for (int K : orders)
          for (double h : hs) runs.push_back({s, x, K, h});
    std::vector<ModifiedAgreement> results(runs.size());
    parallel_for(runs.size(), threads, [&](std::size_t i) {
      const auto& r = runs[i];
      ModifiedAgreement a;
      try {
        a = find_modified_system(r.system).agreement(sysopt.values(r.system), r.scheme, r.K, r.h, sysopt.value(r.system, "T"), tol,
                                                           AgreementStart::shooting);
      } catch (const NumericalFailure& e) {
        std::fprintf(stderr, "%s %s K=%d h=%g: %s (NaN row)\n", r.system.c_str(), r.scheme.c_str(), r.K, r.h, e.what());
        a.err_q = a.err_mu = a.phi_d = a.phi_h0 = a.phi_h_drift = missing_value;
      }
      results[i] = a;
    });
    for (std::size_t i = 0; i < runs.size(); ++i) {
      const auto& r = runs[i];
      const auto& a = results[i];
      tsv.row(r.system, r.scheme, r.K, r.h, a.err_q, a.err_mu, a.phi_d, a.phi_h0, a.phi_h_drift);
      std::printf("%-18s %-*s %-2d %-7g %11.3e %11.3e %11.3e %11.3e %11.3e\n", r.system.c_str(), sw, r.scheme.c_str(), r.K, r.h,
                  a.err_q, a.err_mu, a.phi_d, a.phi_h0, a.phi_h_drift);
    }
    tsv.commit();
    const auto t = plots::read_tsv(dir / "nonholonomic_modified.tsv");
    TsvWriter fits(dir / "nonholonomic_modified_fits.tsv", "nonholonomic_modified", params,
                   {"system", "scheme", "K", "quantity", "fitted_slope", "points"});
    std::printf("\nfitted slopes against h\n%-18s %-*s %-2s %9s %9s %9s %9s %9s\n", "system", sw, "scheme", "K", "err_q", "err_mu",
                "phi_d", "phi_h(0)", "drift");
    plots::Figure fig;
    fig.title = "constrained schemes against their automatic modified equations: max_j |q_j - q^{mod}_K(t_j)|, and the discrete constraint along q^{mod}_K";
    fig.rows = static_cast<int>(systems.size());
    fig.cols = static_cast<int>(schemes.size()) + 1;
    fig.width_in = 4.2 * fig.cols;
    fig.height_in = 3.6 * fig.rows;
    const char* colors[] = {"#1b9e77", "#d95f02", "#7570b3", "#e7298a", "#66a61e"};
    for (const auto& s : systems) {
      plots::Panel drift;
      drift.setup = "set logscale xy\nset format y '10^{%L}'\nset xlabel 'h'\nset ylabel 'max_j |Phi_d(q^{mod}(t_j), q^{mod}(t_{j+1}))|'\n"
                    "set key bottom right font ',8'\nset title '" + s + ": discrete constraint'\n";
      for (const auto& x : schemes) {
        plots::Panel p;
        p.setup = "set logscale xy\nset format y '10^{%L}'\nset xlabel 'h'\nset ylabel 'max error in q'\n"
                  "set key bottom right font ',8'\nset title '" + s + ", " + x + "'\n";
        for (std::size_t ki = 0; ki < orders.size(); ++ki) {
          const int K = orders[ki];
          auto keep = [&](std::size_t i) { return t.text(i, "system") == s && t.text(i, "scheme") == x && t.number(i, "K") == K; };
          const auto hh = t.numbers("h", keep);
          std::printf("%-18s %-*s %-2d", s.c_str(), sw, x.c_str(), K);
          for (const char* qty : {"err_modified", "err_mu", "phi_d", "phi_h0", "phi_h_drift"}) {
            const auto f = fit_order(hh, t.numbers(qty, keep), std::string(qty) == "err_modified" ? floor : 1e-14);
            fits.row(s, x, K, qty, f.slope, f.points);
            std::printf(" %9.2f", f.slope);
          }
          std::printf("\n");
          const auto ee = t.numbers("err_modified", keep);
          p.series.push_back({hh, ee, plots::slope_label("K = " + std::to_string(K), fit_order(hh, ee, floor).slope),
                              std::string("linespoints lw 1.5 pt 7 lc rgb '") + colors[ki % 5] + "'"});
          const auto pd = t.numbers("phi_d", keep);
          drift.series.push_back({hh, pd, plots::slope_label(x + " K = " + std::to_string(K), fit_order(hh, pd, 1e-14).slope),
                                  std::string(x == "la" ? "linespoints lw 1.2 pt 7" : "linespoints lw 1.2 pt 4 dt 2") +
                                      " lc rgb '" + colors[ki % 5] + "'"});
        }
        fig.panels.push_back(std::move(p));
      }
      fig.panels.push_back(std::move(drift));
    }
    fits.commit();
    fig.draw(dir / "nonholonomic_modified");

    // Part 2: the paper's constraint near the origin, in the scene of the Foucault pendulum named
    std::string scene;
    for (const auto& s : systems)
      if (s == "foucault" || s == "foucault-rotation") {
        scene = s;
        break;
      }
    if (scene.empty()) return 0;
    const auto& fm = find_modified_system("foucault");
    const ParamValues fpv = sysopt.values(scene);  // the same parameters: the two systems share their scene
    const double pg = sysopt.value(scene, "g"), pl = sysopt.value(scene, "l"), px0 = sysopt.value(scene, "x0"),
                 Omega = sysopt.value(scene, "Omega"), beta = sysopt.value(scene, "beta");
    const double s_ = Omega * std::sin(beta * geomint::pi / 180);
    const double V = px0 * std::sqrt(pg / pl);  // the bob's speed through the origin (undamped, to leading order)
    const int Ko = 4;
    TsvWriter org(dir / "nonholonomic_modified_origin.tsv", "nonholonomic_modified", params,
                  {"system", "scheme", "r", "k", "norm_F", "norm_mu"});
    std::vector<double> rs;
    for (int i = 1; i <= radii; ++i) rs.push_back(std::pow(0.1, i));
    struct Row {
      std::string scheme;
      int k;
      std::vector<double> F, mu;
    };
    std::vector<Row> rows;
    for (const auto& x : schemes) {
      for (int k = 0; k <= Ko; ++k) rows.push_back({x, k, {}, {}});
      for (double r : rs) {
        const auto P = fm.at(fpv, x, Ko, 0.0, {r, 0.0}, {V, -s_ * r}, 0.0, false);
        for (int k = 0; k <= Ko; ++k) {
          const double nf = std::hypot(P.F_at(k, 0), P.F_at(k, 1)), nm = std::abs(P.mu[static_cast<std::size_t>(k)]);
          org.row("foucault", x, r, k, nf, nm);
          rows[rows.size() - static_cast<std::size_t>(Ko + 1 - k)].F.push_back(nf);
          rows[rows.size() - static_cast<std::size_t>(Ko + 1 - k)].mu.push_back(nm);
        }
      }
    }
    org.commit();
    // crossover: the distance from the origin, in step lengths h V, below which h^3 |F_3| exceeds h |F_1| (the
    // terms of the modified equation stop decreasing): sqrt(|F_3| / |F_1|) r / V at the smallest r, where
    // |F_3| / |F_1| ~ C / r^2 (reported on the k = 3 rows)
    TsvWriter ofit(dir / "nonholonomic_modified_origin_fits.tsv", "nonholonomic_modified", params,
                   {"system", "scheme", "k", "power_F", "power_mu", "crossover_steps"});
    std::printf("\npaper's constraint (13) at q = (r, 0), q' = (%.4g, -Omega sin(beta) r): |F_k| ~ r^power (three smallest r)\n"
                "%-8s %-2s %9s %9s %22s\n", V, "scheme", "k", "power F", "power mu", "crossover (steps)");
    for (const auto& R : rows) {
      // the asymptotic power of r: slope of log|F_k| against log r over the three smallest radii
      const std::vector<double> r3(rs.end() - 3, rs.end()), f3(R.F.end() - 3, R.F.end()), m3(R.mu.end() - 3, R.mu.end());
      const auto pf = fit_order(r3, f3, 0), pm = fit_order(r3, m3, 0);
      double cross = missing_value;
      if (R.k == 3) {
        const auto& F1 = rows[static_cast<std::size_t>(&R - rows.data() - 2)].F;
        cross = std::sqrt(R.F.back() / F1.back()) * rs.back() / V;
      }
      ofit.row("foucault", R.scheme, R.k, pf.slope, pm.slope, cross);
      std::printf("%-8s %-2d %9.3f %9.3f %22.3g\n", R.scheme.c_str(), R.k, pf.slope, pm.slope, cross);
    }
    ofit.commit();
    return 0;
  });
}
