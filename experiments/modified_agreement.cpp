// Step-by-step agreement of each discrete solution with the solution of its automatic modified equation of
// order K, for every order: max_j |q_j - q~_K(t_j)| must fall like h^(K+1) (like h^(K+2) for even K of a
// symmetric second-order scheme, whose odd F_k vanish). K = 0 is the original equation.
//   modified_agreement [--systems oscillator pendulum forced-oscillator] [--schemes la contact la-trapezoid]
//                      [--orders 0 1 2 3 4] [--alpha 0.5] [--h-max 0.1 0.1 0.2 0.2 0.2] [--halvings 2] [--T 2]
//                      [--tol 1e-13] [--out out]
// Discrete solutions: the generic Newton step in long double from each system's initial data (its default
// parameters, with damping alpha). alpha = 0.5 by default: contact's odd-order terms are proportional to alpha
// (F_1 = -alpha^2 q'/2 on the oscillator), and at alpha = 0.1 they stay below the next even-order term over
// this range of h, so the fitted slope there is K + 2 for even K (measured, README). Modified solutions: Boost.Odeint dopri5 with dense output at tolerance tol, the right-hand side
// sum_{k<=K} h^k F_k evaluated by the series engine at every stage, started consistently: q~(0) = q_0 and
// q~(h) = q_1 by shooting on q~'(0). Round-off: errors below 1e2 * tol (the modified solution's own accuracy
// over the horizon; the discrete solutions in long double stay far below) are not fitted. h halves `halvings`
// times from h-max, one value per order: 0.1 for K <= 1 (at h = 0.2 the next order still competes with the
// leading error there: local slopes 0.6-0.8 between 0.2 and 0.1 at K = 0), 0.2 for K >= 2 (so that the
// errors at slope 4-6 keep three points above the floor: ~1e-10 at h = 0.05, K = 4).
// Bigger runs: --halvings 3 --T 4 (four points per fit; about 4x the time). A run that fails (Newton, Odeint) is a NaN row.
// Writes out/modified_agreement.tsv (system, scheme, K, h, err_modified, err_z, v_shift, steps),
// out/modified_agreement_fits.tsv (system, scheme, K, fitted_slope, expected_slope, points) and
// out/modified_agreement.{png,pdf} (one panel per system and scheme, one line per K).
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "geomint/cli.hpp"
#include "geomint/error.hpp"
#include "geomint/io.hpp"
#include "geomint/modified/automatic_registry.hpp"
#include "geomint/plots/figure.hpp"
#include "geomint/registry.hpp"
#include "geomint/study.hpp"

using namespace geomint;
using namespace geomint::modified;

namespace {

// The order the agreement must show: the first h^k beyond K whose F_k may be nonzero.
int expected_slope(const SystemInfo& info, const std::string& scheme, int K) {
  const bool symmetric = info.scheme(scheme).order == 2;  // midpoint / trapezoid: odd F_k vanish
  return K + 1 + (symmetric && K % 2 == 0 ? 1 : 0);
}

}  // namespace

int main(int argc, char** argv) {
  return guarded_main("modified_agreement", [&] {
    std::vector<std::string> systems{"oscillator", "pendulum", "forced-oscillator"}, schemes{"la", "contact", "la-trapezoid"};
    std::vector<int> orders{0, 1, 2, 3, 4};
    double T = 2, tol = 1e-13, alpha = 0.5;
    std::vector<double> h_max{0.1, 0.1, 0.2, 0.2, 0.2};
    int halvings = 2;
    Cli cli("modified_agreement", "discrete solutions against their order-K automatic modified equations, K = 0..4");
    cli.options.add_options()("systems", po::value(&systems)->multitoken()->default_value(systems, "oscillator pendulum forced-oscillator"), "systems")(
        "schemes", po::value(&schemes)->multitoken()->default_value(schemes, "la contact la-trapezoid"), "schemes")(
        "orders", po::value(&orders)->multitoken()->default_value(orders, "0 1 2 3 4"), "orders K")(
        "alpha", po::value(&alpha)->default_value(alpha), "damping alpha of every system")(
        "h-max", po::value(&h_max)->multitoken()->default_value(h_max, "0.1 0.1 0.2 0.2 0.2"), "largest step, per order (or one for all)")(
        "halvings", po::value(&halvings)->default_value(halvings), "number of halvings of h")(
        "T", po::value(&T)->default_value(T), "horizon")("tol", po::value(&tol)->default_value(tol), "Odeint tolerance");
    if (!cli.parse(argc, argv)) return 0;
    require(h_max.size() == 1 || h_max.size() == orders.size(), "give one --h-max, or one per order");
    for (double h : h_max) require_positive(h, "h-max");
    require(halvings >= 2 && halvings <= 8, "halvings must be in [2, 8]");
    require_positive(T, "T");
    require(std::isfinite(tol) && tol >= 1e-15 && tol <= 1e-6, "tol must be in [1e-15, 1e-6]");
    auto steps_of = [&](std::size_t ki) {
      std::vector<double> hs;
      const double h0 = h_max[h_max.size() == 1 ? 0 : ki];
      for (int i = 0; i <= halvings; ++i) hs.push_back(h0 / std::pow(2.0, i));
      return hs;
    };
    for (std::size_t ki = 0; ki < orders.size(); ++ki)
      for (double h : steps_of(ki)) step_count(h, T);
    for (int K : orders) require(K >= 0 && K <= registry_max_order, "orders must be in [0, " + std::to_string(registry_max_order) + "]");
    for (const auto& s : systems) {
      const auto& info = find_system(s);
      require(info.constraints == 0, "system '" + s + "' is constrained: use nonholonomic_modified");
      for (const auto& x : schemes) info.scheme(x);
    }
    const ParamValues pv{{"alpha", alpha}};
    for (const auto& s : systems) find_system(s).validate(pv);
    const auto dir = prepare_output_dir(cli.out);
    const double floor = 1e2 * tol;
    std::vector<double> order_values(orders.begin(), orders.end());
    const Params params{{"systems", join_names(systems)}, {"schemes", join_names(schemes)},
                        {"orders", format_list(order_values)}, {"alpha", format_number(alpha)}, {"h_max", format_list(h_max)},
                        {"halvings", std::to_string(halvings)},
                        {"T", format_number(T)}, {"tol", format_number(tol)}, {"fit_floor", format_number(floor)},
                        {"discrete", "generic Newton step, long double, system defaults but alpha"},
                        {"modified", "automatic (series through the residual), Odeint dopri5 dense, shooting start"}};
    TsvWriter tsv(dir / "modified_agreement.tsv", "modified_agreement", params,
                  {"system", "scheme", "K", "h", "err_modified", "err_z", "v_shift", "steps"});
    std::printf("%-18s %-13s %-2s %-9s %12s %12s %12s\n", "system", "scheme", "K", "h", "err_q", "err_z", "v_shift");
    for (const auto& s : systems) {
      const auto& ms = find_modified_system(s);
      for (const auto& x : schemes)
        for (std::size_t ki = 0; ki < orders.size(); ++ki)
          for (double h : steps_of(ki)) {
            const int K = orders[ki];
            ModifiedAgreement a;
            try {
              a = ms.agreement(pv, x, K, h, T, tol);
            } catch (const NumericalFailure& e) {
              std::fprintf(stderr, "%s %s K=%d h=%g: %s (NaN row)\n", s.c_str(), x.c_str(), K, h, e.what());
              a.err_q = a.err_z = a.v_shift = std::nan("");
            } catch (const std::domain_error& e) {
              std::fprintf(stderr, "%s %s K=%d h=%g: %s (NaN row)\n", s.c_str(), x.c_str(), K, h, e.what());
              a.err_q = a.err_z = a.v_shift = std::nan("");
            }
            tsv.row(s, x, K, h, a.err_q, a.err_z, a.v_shift, a.steps);
            std::printf("%-18s %-13s %-2d %-9g %12.3e %12.3e %12.3e\n", s.c_str(), x.c_str(), K, h, a.err_q, a.err_z, a.v_shift);
          }
    }
    tsv.commit();

    // Fits, read back from the saved table.
    const auto t = plots::read_tsv(dir / "modified_agreement.tsv");
    TsvWriter fits(dir / "modified_agreement_fits.tsv", "modified_agreement", params,
                   {"system", "scheme", "K", "fitted_slope", "expected_slope", "points"});
    std::printf("\nfitted slopes of max_j |q_j - q~_K(t_j)| against h (expected in brackets)\n%-18s %-13s", "system", "scheme");
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
        std::printf("%-18s %-13s", s.c_str(), x.c_str());
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
          const int expect = expected_slope(info, x, K);
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
