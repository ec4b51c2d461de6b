// Step-by-step agreement of each discrete solution with the solution of its automatic modified equation of
// order K, for every order: max_j |q_j - q~_K(t_j)| must fall like h^(K+1) (like h^(K+2) for even K of a
// symmetric second-order scheme, whose odd F_k vanish; for a composition of order p, whose F_1 .. F_(p-1) vanish
// too, like h^p for K < p). K = 0 is the original equation. Compositions ("yoshida4:la-trapezoid") cost their stage
// problem at every evaluation: 9x (yoshida4) to 72x (kahanli8) a scheme's.
//   modified_agreement [--systems oscillator pendulum forced-oscillator] [--schemes la contact la-trapezoid]
//                      [--orders 0 1 2 3 4] [--h-max (0.1 for K <= 1, 0.2 for K >= 2)] [--halvings 2] [--tol 1e-13]
//                      [--threads <cores>] [any parameter of the systems: --alpha 0.5 --T 2 --q0 ...] [--out out]
// Discrete solutions: the generic Newton step in long double from each system's initial data (its parameters: the
// ones given, else the presets alpha = 0.5 and T = 2, else its defaults). alpha = 0.5: contact's odd-order terms are proportional to alpha
// (F_1 = -alpha^2 q'/2 on the oscillator), and at alpha = 0.1 they stay below the next even-order term over
// this range of h, so the fitted slope there is K + 2 for even K (measured, docs/modified-equations.md). Modified solutions: Boost.Odeint dopri5 with dense output at tolerance tol, the right-hand side
// sum_{k<=K} h^k F_k evaluated by the series engine at every stage, started consistently: q~(0) = q_0 and
// q~(h) = q_1 by shooting on q~'(0). Round-off: errors below 1e2 * tol (the modified solution's own accuracy
// over the horizon; the discrete solutions in long double stay far below) are not fitted. h halves `halvings`
// times from h-max, one value per order: 0.1 for K <= 1 (at h = 0.2 the next order still competes with the
// leading error there: local slopes 0.6-0.8 between 0.2 and 0.1 at K = 0), 0.2 for K >= 2 (so that the
// errors at slope 4-6 keep three points above the floor: ~1e-10 at h = 0.05, K = 4).
// Bigger runs: --halvings 3 --T 4 (four points per fit; about 4x the time), under mpirun -n N to share the runs
// across ranks (same files). A run that fails (Newton, Odeint) is a NaN row.
// Writes out/modified_agreement.tsv (system, scheme, K, h, err_modified, err_z, v_shift, steps),
// out/modified_agreement_fits.tsv (system, scheme, K, fitted_slope, expected_slope, points) and
// out/modified_agreement.{png,pdf} (one panel per system and scheme, one line per K).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "geomint/budget.hpp"
#include "geomint/cli.hpp"
#include "geomint/error.hpp"
#include "geomint/io.hpp"
#include "geomint/modified/automatic_registry.hpp"
#include "geomint/parallel.hpp"
#include "geomint/plots/figure.hpp"
#include "geomint/registry.hpp"
#include "geomint/study.hpp"
#include "geomint/sweep.hpp"
#include "geomint/system_cli.hpp"

using namespace geomint;
using namespace geomint::modified;

int main(int argc, char** argv) {
  return guarded_main("modified_agreement", [&] {
    std::vector<std::string> systems{"oscillator", "pendulum", "forced-oscillator"}, schemes{"la", "contact", "la-trapezoid"};
    std::vector<int> orders{0, 1, 2, 3, 4};
    double tol = 1e-13;
    std::vector<double> h_max;  // empty: 0.1 for K <= 1, 0.2 for K >= 2
    int halvings = 2;
    unsigned threads = default_threads();
    Cli cli("modified_agreement", "discrete solutions against their order-K automatic modified equations, K = 0..4");
    SystemsOptions sysopt(cli, argc, argv, systems, {{"alpha", 0.5}, {"T", 2}});
    cli.options.add_options()(
        "schemes", po::value(&schemes)->multitoken()->default_value(schemes, "la contact la-trapezoid"), "schemes")(
        "orders", po::value(&orders)->multitoken()->default_value(orders, "0 1 2 3 4"), "orders K")(
        "h-max", po::value(&h_max)->multitoken(), "largest step, per order (or one for all); default 0.1 for K <= 1, 0.2 for K >= 2")(
        "halvings", po::value(&halvings)->default_value(halvings), "number of halvings of h")(
        "threads", po::value(&threads)->default_value(threads), "worker threads (the files do not depend on them)")(
        "tol", po::value(&tol)->default_value(tol), "Odeint tolerance");
    if (!cli.parse(argc, argv)) return 0;
    systems = sysopt.names();
    if (h_max.empty())
      for (int K : orders) h_max.push_back(K <= 1 ? 0.1 : 0.2);
    require(h_max.size() == 1 || h_max.size() == orders.size(), "give one --h-max, or one per order");
    for (double h : h_max) require_positive(h, "h-max");
    require(halvings >= 2 && halvings <= 8, "halvings must be in [2, 8]");
    require(threads >= 1 && threads <= 256, "threads must be in [1, 256]");
    require(std::isfinite(tol) && tol >= 1e-15 && tol <= 1e-6, "tol must be in [1e-15, 1e-6]");
    auto steps_of = [&](std::size_t ki) {
      std::vector<double> hs;
      const double h0 = h_max[h_max.size() == 1 ? 0 : ki];
      for (int i = 0; i <= halvings; ++i) hs.push_back(h0 / std::pow(2.0, i));
      return hs;
    };
    for (int K : orders) require(K >= 0 && K <= registry_max_order, "orders must be in [0, " + std::to_string(registry_max_order) + "]");
    for (const auto& s : systems) {
      const auto& info = find_system(s);
      require(info.constraints == 0, "system '" + s + "' is constrained: use nonholonomic_modified");
      for (const auto& x : schemes) modified_scheme(info, x);
    }
    for (std::size_t ki = 0; ki < orders.size(); ++ki)
      for (double h : steps_of(ki))
        // a planned step costs ~0.5 ms (the order-K modified equation solved by Odeint at tol 1e-13 along it;
        // measured: 2.35 s of CPU per 4410 planned steps, T = 2 -> 4 at the defaults): 1e4 cheap steps, times a
        // composition's cost factor
        for (const auto& s : systems) {
          double cost = 0;
          for (const auto& x : schemes) cost += modified_cost_factor(find_system(s), x);
          plan_steps(cost * static_cast<double>(step_count(h, sysopt.value(s, "T"))),
                     "the sweep (systems x schemes x T/h per order)", 1e4);
        }
    const auto dir = prepare_output_dir(cli.out, OtherRanks::compute);
    const double floor = 1e2 * tol;
    std::vector<double> order_values(orders.begin(), orders.end());
    Params params = sysopt.header();
    params.insert(params.end(), {{"schemes", join_names(schemes)},
                        {"orders", format_list(order_values)}, {"h_max", format_list(h_max)},
                        {"halvings", std::to_string(halvings)},
                        {"tol", format_number(tol)}, {"fit_floor", format_number(floor)},
                        {"discrete", "generic Newton step, long double, the parameters above, else the system's defaults"},
                        {"modified", "automatic (series through the residual), Odeint dopri5 dense, shooting start"}});
    // Every (system, scheme, K, h) run is independent: under mpirun the runs are shared across ranks
    // and gathered on rank 0 in this order, so the files are the single-process ones byte for byte.
    struct Run {
      std::string system, scheme;
      int K;
      double h;
    };
    std::vector<Run> runs;  // in output order: system, scheme, K, h
    for (const auto& s : systems)
      for (const auto& x : schemes)
        for (std::size_t ki = 0; ki < orders.size(); ++ki)
          for (double h : steps_of(ki)) runs.push_back({s, x, orders[ki], h});
    // Sweep order: systems innermost, so every contiguous share holds each system in the same proportion (their
    // costs differ by ~4x: the forced oscillator's Odeint runs take more steps), and the cost model need only
    // know K and the scheme: measured, a run costs about K + 2 (one series evaluation per order in each right-hand
    // side) times the scheme's cost factor (a composition's stage problem) and hardly depends on h (the modified
    // solution's Odeint steps follow its tolerance, not h).
    std::vector<std::size_t> item;  // item[i]: the run computed as the i-th item of the sweep
    const std::size_t X = schemes.size(), H = static_cast<std::size_t>(halvings) + 1;
    for (std::size_t ki = 0; ki < orders.size(); ++ki)
      for (std::size_t hi = 0; hi < H; ++hi)
        for (std::size_t xi = 0; xi < X; ++xi)
          for (std::size_t si = 0; si < systems.size(); ++si) item.push_back(((si * X + xi) * orders.size() + ki) * H + hi);
    std::vector<double> cost_of;
    for (std::size_t i : item)
      cost_of.push_back((runs[i].K + 2.0) * modified_cost_factor(find_system(runs[i].system), runs[i].scheme));
    const Sweep& sweep = Sweep::world();
    const auto by_item = sweep.map<ModifiedAgreement>(
        runs.size(), cost_of,
        [&](std::size_t first, std::size_t last) {
          std::vector<ModifiedAgreement> out(last - first);
          parallel_for(last - first, threads, [&](std::size_t k) {
            const auto& r = runs[item[first + k]];
            ModifiedAgreement a;
            try {
              a = find_modified_system(r.system).agreement(sysopt.values(r.system), r.scheme, r.K, r.h,
                                                           sysopt.value(r.system, "T"), tol);
            } catch (const NumericalFailure& e) {
              std::fprintf(stderr, "%s %s K=%d h=%g: %s (NaN row)\n", r.system.c_str(), r.scheme.c_str(), r.K, r.h, e.what());
              a.err_q = a.err_z = a.v_shift = missing_value;
            } catch (const std::domain_error& e) {
              std::fprintf(stderr, "%s %s K=%d h=%g: %s (NaN row)\n", r.system.c_str(), r.scheme.c_str(), r.K, r.h, e.what());
              a.err_q = a.err_z = a.v_shift = missing_value;
            }
            out[k] = a;
          });
          return out;
        });
    if (!sweep.root()) return 0;
    std::vector<ModifiedAgreement> results(runs.size());
    for (std::size_t i = 0; i < item.size(); ++i) results[item[i]] = by_item[i];
    TsvWriter tsv(dir / "modified_agreement.tsv", "modified_agreement", params,
                  {"system", "scheme", "K", "h", "err_modified", "err_z", "v_shift", "steps"});
    int sw = 13;  // the scheme column fits the longest name (compositions: "<family>:<base>")
    for (const auto& x : schemes) sw = std::max(sw, static_cast<int>(x.size()));
    std::printf("%-18s %-*s %-2s %-9s %12s %12s %12s\n", "system", sw, "scheme", "K", "h", "err_q", "err_z", "v_shift");
    for (std::size_t i = 0; i < runs.size(); ++i) {
      const auto& r = runs[i];
      const auto& a = results[i];
      tsv.row(r.system, r.scheme, r.K, r.h, a.err_q, a.err_z, a.v_shift, a.steps);
      std::printf("%-18s %-*s %-2d %-9g %12.3e %12.3e %12.3e\n", r.system.c_str(), sw, r.scheme.c_str(), r.K, r.h, a.err_q, a.err_z,
                  a.v_shift);
    }
    tsv.commit();

    // Fits, read back from the saved table.
    const auto t = plots::read_tsv(dir / "modified_agreement.tsv");
    TsvWriter fits(dir / "modified_agreement_fits.tsv", "modified_agreement", params,
                   {"system", "scheme", "K", "fitted_slope", "expected_slope", "points"});
    std::printf("\nfitted slopes of max_j |q_j - q~_K(t_j)| against h (expected in brackets)\n%-18s %-*s", "system", sw, "scheme");
    for (int K : orders) std::printf("   K=%d      ", K);
    std::printf("\n");
    plots::Figure fig;
    fig.title = "max_j |q_j - q^{mod}_K(t_j)| against h: each scheme against its order-K automatic modified equation";
    fig.rows = static_cast<int>(systems.size());
    fig.cols = static_cast<int>(schemes.size());
    fig.width_in = 4.2 * fig.cols;
    fig.height_in = 3.6 * fig.rows;
    const char* colors[] = {"#1b9e77", "#d95f02", "#7570b3", "#e7298a", "#66a61e", "#e6ab02", "#a6761d"};
    for (const auto& s : systems) {
      const auto& info = find_system(s);
      for (const auto& x : schemes) {
        std::printf("%-18s %-*s", s.c_str(), sw, x.c_str());
        plots::Panel p;
        p.setup = "set logscale xy\nset format y '10^{%L}'\nset xlabel 'h'\nset ylabel 'max error in q'\n"
                  "set key bottom right font ',8'\nset title '" + s + ", " + x + "'\n";
        for (std::size_t ki = 0; ki < orders.size(); ++ki) {
          const int K = orders[ki];
          auto keep = [&](std::size_t i) {
            return t.text(i, "system") == s && t.text(i, "scheme") == x && t.number(i, "K") == K;
          };
          const auto hh = t.numbers("h", keep);
          const auto ee = t.numbers("err_modified", keep);
          const auto f = fit_order(hh, ee, floor);
          const int expect = expected_agreement_slope(info, x, K);
          fits.row(s, x, K, f.slope, expect, f.points);
          std::printf("  %5.2f [%d]  ", f.slope, expect);
          p.series.push_back({hh, ee, plots::slope_label("K = " + std::to_string(K), f.slope),
                              std::string("linespoints lw 1.5 pt 7 lc rgb '") + colors[ki % 7] + "'"});
        }
        std::printf("\n");
        fig.panels.push_back(std::move(p));
      }
    }
    fits.commit();
    fig.draw(dir / "modified_agreement");
    return 0;
  });
}
