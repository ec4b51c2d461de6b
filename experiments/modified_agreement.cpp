// Step-by-step agreement of each discrete solution with the solution of its automatic modified equation of
// order K, for every order: max_j |q_j - q~_K(t_j)| must fall like h^(K+1) (like h^(K+2) for even K of a
// symmetric second-order scheme, whose odd F_k vanish; for a composition of order p, whose F_1 .. F_(p-1) vanish
// too, like h^p for K < p). K = 0 is the original equation. Compositions ("yoshida4:la-trapezoid") cost their stage
// problem at every evaluation: 9x (yoshida4) to 72x (kahanli8) a scheme's.
//   modified_agreement [--systems oscillator pendulum forced-oscillator] [--schemes la contact la-trapezoid]
//                      [--orders 0 1 2 3 4] [--h-max (0.1 for K <= 1, 0.2 for K >= 2)] [--halvings 2] [--tol 1e-13]
//                      [--start shooting] [--all-orders] [--threads <cores>]
//                      [any parameter of the systems, one value or several to sweep: --alpha 0.5 --T 2 ...] [--out out]
// Discrete solutions: the generic Newton step in long double from each system's initial data (its parameters: the
// ones given, else the presets alpha = 0.5 and T = 2, else its defaults). alpha = 0.5: contact's odd-order terms are
// proportional to alpha (F_1 = -alpha^2 q'/2 on the oscillator), and at alpha = 0.1 they stay below the next
// even-order term over this range of h, so the fitted slope there is K + 2 for even K (measured,
// docs/modified-equations.md). Modified solutions: Boost.Odeint dopri5 with dense output at tolerance tol, the
// right-hand side sum_{k<=K} h^k F_k evaluated by the series engine at every stage. Two starts (--start, one or
// both): shooting, q~(0) = q_0 and q~(h) = q_1 by shooting on q~'(0), consistent at every order; naive,
// q~'(0) = v_0 from the system's initial data, which is off by O(h^p) for a scheme of order p and caps the agreement
// there (at K = 0 it is the original equation from the exact initial data). Round-off: errors below 1e2 * tol (the
// modified solution's own accuracy over the horizon; the discrete solutions in long double stay far below) are not
// fitted. h halves `halvings` times from h-max, one value per order: 0.1 for K <= 1 (at h = 0.2 the next order still
// competes with the leading error there: local slopes 0.6-0.8 between 0.2 and 0.1 at K = 0), 0.2 for K >= 2 (so that
// the errors at slope 4-6 keep three points above the floor: ~1e-10 at h = 0.05, K = 4).
// --all-orders (linear systems without constraints): the modified equation to all orders, q'' = A_v q' + A_q q from
// G = log(M)/h of the one-step matrix, beside the series truncated at the largest K asked, and the largest deviation
// of the steps from the flow of G (round-off: the flow passes through every step). For one degree of freedom,
// q'' + a_h q' + b_h q = 0 with a_h = -A_v, b_h = -A_q.
// Bigger runs: --halvings 3 --T 4 (four points per fit; about 4x the time), under mpirun -n N to share the runs
// across ranks (same files). A run that fails (Newton, Odeint) is a NaN row.
// Writes out/modified_agreement.tsv (system, scheme, swept parameters, start, K, h, err_modified, err_z, v_shift,
// steps), out/modified_agreement_fits.tsv (system, scheme, swept parameters, start, K, fitted_slope, expected_slope,
// points), out/modified_agreement.{png,pdf} (one panel per system, sweep point and scheme, one line per K and start)
// and with --all-orders out/modified_agreement_all_orders.tsv (system, scheme, swept parameters, h, i, j, A_q, A_v,
// A_q_series, A_v_series, series_K, flow_deviation); for one system, <system>_modified_agreement*.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <stdexcept>
#include <tuple>

#include "geomint/budget.hpp"
#include "geomint/modified/plan.hpp"
#include "geomint/cli.hpp"
#include "geomint/error.hpp"
#include "geomint/io.hpp"
#include "geomint/modified/all_orders.hpp"
#include "geomint/modified/automatic_registry.hpp"
#include "geomint/parallel.hpp"
#include "geomint/plots/figure.hpp"
#include "geomint/record.hpp"
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
    std::vector<std::string> start_names{"shooting"};
    bool all_orders = false;
    Cli cli("modified_agreement", "discrete solutions against their order-K automatic modified equations, K = 0..4 "
                                      "(several values of a system parameter sweep it)");
    SystemsOptions sysopt(cli, argc, argv, systems, {{"alpha", 0.5}, {"T", 2}});
    cli.options.add_options()(
        "schemes", po::value(&schemes)->multitoken()->default_value(schemes, "la contact la-trapezoid"), "schemes")(
        "orders", po::value(&orders)->multitoken()->default_value(orders, "0 1 2 3 4"), "orders K")(
        "h-max", po::value(&h_max)->multitoken(), "largest step, per order (or one for all); default 0.1 for K <= 1, 0.2 for K >= 2")(
        "halvings", po::value(&halvings)->default_value(halvings), "number of halvings of h")(
        "threads", po::value(&threads)->default_value(threads), "worker threads (the files do not depend on them)")(
        "tol", po::value(&tol)->default_value(tol), "Odeint tolerance")(
        "start", po::value(&start_names)->multitoken()->default_value(start_names, "shooting"),
        "how the modified solution starts, one or both: shooting (q~(h) = q_1) or naive (q~'(0) = v_0)")(
        "all-orders", po::bool_switch(&all_orders),
        "also the modified equation to all orders, from log(M)/h (linear systems without constraints)");
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
    std::vector<AgreementStart> starts;
    for (const auto& n : start_names) starts.push_back(parse_agreement_start(n));
    for (const auto& s : systems) {
      const auto& info = find_system(s);
      require(info.constraints == 0, "system '" + s + "' is constrained: use nonholonomic_modified");
      require(!all_orders || info.linear,
              "system '" + s + "' is not linear: --all-orders needs a linear system (a step x -> M x)");
      for (const auto& x : schemes) modified_scheme(info, x);
    }
    // the sweep points of each system (one when nothing is swept), and the swept parameters' columns
    std::vector<std::vector<ParamValues>> combos;
    for (const auto& s : systems) combos.push_back(sysopt.combinations(s));
    const std::vector<std::string> swept = sysopt.swept();
    auto swept_cells = [&](std::size_t si, std::size_t ci) {
      std::vector<std::string> cells;
      for (const auto& name : swept) {
        double v = missing_value;
        for (const auto& [k, x] : combos[si][ci])
          if (k == name) v = x;
        cells.push_back(format_cell(v));
      }
      return cells;
    };
    auto swept_text = [&](std::size_t si, std::size_t ci) {
      std::string t;
      const auto cells = swept_cells(si, ci);
      for (std::size_t i = 0; i < swept.size(); ++i) t += " " + swept[i] + "=" + cells[i];
      return t;
    };
    for (std::size_t ki = 0; ki < orders.size(); ++ki)
      for (double h : steps_of(ki))
        for (std::size_t si = 0; si < systems.size(); ++si)
          for (const auto& pv : combos[si])
            for (const auto& x : schemes)
              plan_agreement(find_system(systems[si]), x, h, param_value(pv, find_system(systems[si]), "T"),
                             starts.size());
    const auto dir = prepare_output_dir(cli.out, OtherRanks::compute);
    // one system: its name leads the files' (as every single-system study's), so a preset beside the default run
    // keeps its own files
    const std::string stem = systems.size() == 1 ? systems.front() + "_modified_agreement" : "modified_agreement";
    const double floor = 1e2 * tol;
    std::vector<double> order_values(orders.begin(), orders.end());
    Params params = sysopt.header();
    params.insert(params.end(), {{"schemes", join_names(schemes)},
                        {"orders", format_list(order_values)}, {"h_max", format_list(h_max)},
                        {"halvings", std::to_string(halvings)}, {"start", join_names(start_names)},
                        {"tol", format_number(tol)}, {"fit_floor", format_number(floor)},
                        {"fit_ceiling", "the size of the solution, max|q_ref| (an error above it has blown up)"},
                        {"discrete", "generic Newton step, long double, the parameters above, else the system's defaults"},
                        {"modified", "automatic (series through the residual), Odeint dopri5 dense, shooting start"}});
    // Every (system, scheme, K, h) run is independent: under mpirun the runs are shared across ranks
    // and gathered on rank 0 in this order, so the files are the single-process ones byte for byte.
    struct Run {
      std::size_t si, ci;  // system, sweep point
      std::string scheme;
      AgreementStart start;
      int K;
      double h;
    };
    std::vector<Run> runs;  // in output order: system, sweep point, scheme, start, K, h
    struct Key {
      std::size_t ki, hi, sti, xi, sc;
    };
    std::vector<Key> keys;
    std::size_t sc = 0;  // (system, sweep point) counted together
    for (std::size_t si = 0; si < systems.size(); ++si)
      for (std::size_t ci = 0; ci < combos[si].size(); ++ci, ++sc)
        for (std::size_t xi = 0; xi < schemes.size(); ++xi)
          for (std::size_t sti = 0; sti < starts.size(); ++sti)
            for (std::size_t ki = 0; ki < orders.size(); ++ki) {
              const auto hs = steps_of(ki);
              for (std::size_t hi = 0; hi < hs.size(); ++hi) {
                runs.push_back({si, ci, schemes[xi], starts[sti], orders[ki], hs[hi]});
                keys.push_back({ki, hi, sti, xi, sc});
              }
            }
    // Sweep order: systems and sweep points innermost, so every contiguous share holds each in the same proportion
    // (their costs differ by ~4x: the forced oscillator's Odeint runs take more steps), and the cost model need only
    // know K and the scheme: measured, a run costs about K + 2 (one series evaluation per order in each right-hand
    // side) times the scheme's cost factor (a composition's stage problem) and hardly depends on h (the modified
    // solution's Odeint steps follow its tolerance, not h).
    std::vector<std::size_t> item(runs.size());  // item[i]: the run computed as the i-th item of the sweep
    for (std::size_t i = 0; i < item.size(); ++i) item[i] = i;
    std::stable_sort(item.begin(), item.end(), [&](std::size_t a, std::size_t b) {
      const Key &x = keys[a], &y = keys[b];
      return std::tie(x.ki, x.hi, x.sti, x.xi, x.sc) < std::tie(y.ki, y.hi, y.sti, y.xi, y.sc);
    });
    std::vector<double> cost_of;
    for (std::size_t i : item)
      cost_of.push_back((runs[i].K + 2.0) * modified_cost_factor(find_system(systems[runs[i].si]), runs[i].scheme));
    const Sweep& sweep = Sweep::world();
    const auto by_item = sweep.map<ModifiedAgreement>(
        runs.size(), cost_of,
        [&](std::size_t first, std::size_t last) {
          std::vector<ModifiedAgreement> out(last - first);
          parallel_for(last - first, threads, [&](std::size_t k) {
            const auto& r = runs[item[first + k]];
            const std::string& system = systems[r.si];
            const ParamValues& pv = combos[r.si][r.ci];
            const std::string where = system + swept_text(r.si, r.ci) + " " + r.scheme + " start=" +
                                      start_name(r.start) + " K=" + std::to_string(r.K) + " h=" + show(r.h);
            const ModifiedAgreement a = run_or_missing(
                where,
                [&] {
                  const auto a = find_modified_system(system).agreement(pv, r.scheme, r.K, r.h,
                                                                        param_value(pv, find_system(system), "T"), tol,
                                                                        r.start);
                  for (double x : {a.err_q, a.err_z, a.v_shift})
                    if (!std::isfinite(x) && !is_missing(x))
                      throw NumericalFailure::in_output("the agreement run",
                                                        "an error of the run is " + show(x) + " in double");
                  return a;
                },
                [] {
                  ModifiedAgreement none;
                  none.err_q = none.err_z = none.v_shift = missing_value;
                  return none;
                });
            out[k] = a;
          });
          return out;
        });
    if (!sweep.root()) return 0;
    std::vector<ModifiedAgreement> results(runs.size());
    for (std::size_t i = 0; i < item.size(); ++i) results[item[i]] = by_item[i];
    std::vector<std::string> cols{"system", "scheme"};
    cols.insert(cols.end(), swept.begin(), swept.end());
    TsvWriter tsv(dir / (stem + ".tsv"), "modified_agreement", params, [&] {
      auto c = cols;
      c.insert(c.end(), {"start", "K", "h", "err_modified", "err_z", "v_shift", "steps"});
      return c;
    }());
    int sw = 13;  // the scheme column fits the longest name (compositions: "<family>:<base>")
    for (const auto& x : schemes) sw = std::max(sw, static_cast<int>(x.size()));
    std::printf("%-18s %-*s %-8s %-2s %-9s %12s %12s %12s\n", "system", sw, "scheme", "start", "K", "h", "err_q", "err_z",
                "v_shift");
    for (std::size_t i = 0; i < runs.size(); ++i) {
      const auto& r = runs[i];
      const auto& a = results[i];
      std::vector<std::string> cells{systems[r.si], r.scheme};
      const auto sc = swept_cells(r.si, r.ci);
      cells.insert(cells.end(), sc.begin(), sc.end());
      cells.insert(cells.end(), {start_name(r.start), std::to_string(r.K), format_cell(r.h), format_cell(a.err_q),
                                 format_cell(a.err_z), format_cell(a.v_shift), std::to_string(a.steps)});
      tsv.write_row(cells);
      std::printf("%-18s %-*s %-8s %-2d %-9g %12.3e %12.3e %12.3e\n", (systems[r.si] + swept_text(r.si, r.ci)).c_str(), sw,
                  r.scheme.c_str(), start_name(r.start), r.K, r.h, a.err_q, a.err_z, a.v_shift);
    }
    tsv.commit();

    // Fits, read back from the saved table.
    const auto t = plots::read_tsv(dir / (stem + ".tsv"));
    TsvWriter fits(dir / (stem + "_fits.tsv"), "modified_agreement", params, [&] {
      auto c = cols;
      c.insert(c.end(), {"start", "K", "fitted_slope", "expected_slope", "points"});
      return c;
    }());
    std::printf("\nfitted slopes of max_j |q_j - q~_K(t_j)| against h (expected in brackets)\n%-18s %-*s %-8s", "system", sw,
                "scheme", "start");
    for (int K : orders) std::printf("   K=%d      ", K);
    std::printf("\n");
    std::size_t points = 0;
    for (const auto& c : combos) points += c.size();
    plots::Figure fig;
    fig.title = "max_j |q_j - q^{mod}_K(t_j)| against h: each scheme against its order-K automatic modified equation";
    fig.rows = static_cast<int>(points);
    fig.cols = static_cast<int>(schemes.size());
    fig.width_in = 4.2 * fig.cols;
    fig.height_in = 3.6 * fig.rows;
    const char* colors[] = {"#1b9e77", "#d95f02", "#7570b3", "#e7298a", "#66a61e", "#e6ab02", "#a6761d"};
    for (std::size_t si = 0; si < systems.size(); ++si) {
      const auto& s = systems[si];
      const auto& info = find_system(s);
      for (std::size_t ci = 0; ci < combos[si].size(); ++ci) {
        const auto sc = swept_cells(si, ci);
        // The fits' band: above the floor, below the size of the solution (a run whose error is as large as the
        // solution has blown up: its slope is no order). The size from the system's reference on the finest h.
        FitBand band{floor};
        {
          const ParamValues& pv = combos[si][ci];
          const double T = param_value(pv, info, "T");
          double h = h_max.front();
          for (std::size_t ki = 0; ki < orders.size(); ++ki) h = std::min(h, steps_of(ki).back());
          try {
            band = fit_band(false, tol, solution_size(info.reference(pv, h, step_count(h, T), ReferenceKind::automatic, tol),
                                                      ErrorNorm::max));
          } catch (const NumericalFailure& f) {
            report_missing(s + swept_text(si, ci) + " (the fits' ceiling: no reference)", f.what());
          }
        }
        for (const auto& x : schemes) {
          plots::Panel p;
          p.setup = "set logscale xy\nset format y '10^{%L}'\nset xlabel 'h'\nset ylabel 'max error in q'\n"
                    "set key bottom right font ',8'\nset title '" + s + swept_text(si, ci) + ", " + x + "'\n";
          for (std::size_t sti = 0; sti < starts.size(); ++sti) {
            const AgreementStart st = starts[sti];
            std::printf("%-18s %-*s %-8s", (s + swept_text(si, ci)).c_str(), sw, x.c_str(), start_name(st));
            for (std::size_t ki = 0; ki < orders.size(); ++ki) {
              const int K = orders[ki];
              auto keep = [&](std::size_t i) {
                if (t.text(i, "system") != s || t.text(i, "scheme") != x || t.text(i, "start") != start_name(st) ||
                    t.number(i, "K") != K)
                  return false;
                for (std::size_t w = 0; w < swept.size(); ++w)
                  if (t.text(i, swept[w]) != sc[w]) return false;
                return true;
              };
              const auto hh = t.numbers("h", keep);
              const auto ee = t.numbers("err_modified", keep);
              const auto f = fit_order(hh, ee, band);
              const int expect = expected_agreement_slope(info, x, K, st);
              std::vector<std::string> cells{s, x};
              cells.insert(cells.end(), sc.begin(), sc.end());
              cells.insert(cells.end(), {start_name(st), std::to_string(K), format_cell(f.slope), std::to_string(expect),
                                         std::to_string(f.points)});
              fits.write_row(cells);
              if (std::isfinite(f.slope))
                std::printf("  %5.2f [%d]  ", f.slope, expect);
              else  // fewer than three points in the band: no slope to show
                std::printf("  -%dpt [%d]  ", f.points, expect);
              // the naive start dashed, open points
              const bool naive = st == AgreementStart::naive;
              const std::string label =
                  "K = " + std::to_string(K) + (starts.size() > 1 ? std::string(", ") + start_name(st) : "");
              const std::string style = naive ? "linespoints lw 1 dt 2 pt 4 lc rgb '" : "linespoints lw 1.5 pt 7 lc rgb '";
              p.series.push_back({hh, ee, plots::slope_label(label, f.slope), style + colors[ki % 7] + "'"});
            }
            std::printf("\n");
          }
          fig.panels.push_back(std::move(p));
        }
      }
    }
    fits.commit();
    fig.draw(dir / stem);

    if (!all_orders) return 0;
    // The modified equation to all orders, beside the series truncated at the largest K asked: their gap falls like
    // h^(K+1) (the first term left out), and the steps sit on the flow of G to round-off.
    const int series_K = *std::max_element(orders.begin(), orders.end());
    std::vector<double> all_h;
    for (std::size_t ki = 0; ki < orders.size(); ++ki)
      for (double h : steps_of(ki)) all_h.push_back(h);
    std::sort(all_h.begin(), all_h.end(), std::greater<>());
    all_h.erase(std::unique(all_h.begin(), all_h.end()), all_h.end());
    TsvWriter ao(dir / (stem + "_all_orders.tsv"), "modified_agreement", params, [&] {
      auto c = cols;
      c.insert(c.end(), {"h", "i", "j", "A_q", "A_v", "A_q_series", "A_v_series", "series_K", "flow_deviation"});
      return c;
    }());
    std::printf("\nthe modified equation to all orders, q'' = A_v q' + A_q q (G = log(M)/h), against the series to K = %d\n"
                "%-18s %-*s %-9s %-3s %-3s %16s %16s %11s %11s %11s\n",
                series_K, "system", sw, "scheme", "h", "i", "j", "A_q", "A_v", "gap A_q", "gap A_v", "flow dev");
    for (std::size_t si = 0; si < systems.size(); ++si) {
      const SystemInfo& info = find_system(systems[si]);
      for (std::size_t ci = 0; ci < combos[si].size(); ++ci) {
        const ParamValues& pv = combos[si][ci];
        const auto sc = swept_cells(si, ci);
        for (const auto& x : schemes)
          for (double h : all_h) {
            const std::string where = systems[si] + swept_text(si, ci) + " " + x + " h=" + show(h) + " (all orders)";
            const int n = info.dof;
            LinearModified lm;
            lm.n = n;
            lm.A_q.assign(static_cast<std::size_t>(n * n), missing_value);
            lm.A_v = lm.A_q;
            double dev = missing_value;
            run_or_missing(
                where,
                [&] {
                  const LinearModified m = all_orders_linear(info, pv, x, h, Path::fast);
                  for (std::size_t e = 0; e < m.A_q.size(); ++e)
                    if (!std::isfinite(static_cast<double>(m.A_q[e])) || !std::isfinite(static_cast<double>(m.A_v[e])))
                      throw NumericalFailure::in_output("the modified equation to all orders",
                                                        "A_q or A_v is not finite in double");
                  lm = m;
                  const double d = linear_flow_deviation(lm, info.run(pv, x, h, Path::fast, 1));
                  if (!std::isfinite(d) && !is_missing(d))
                    throw NumericalFailure::in_output("the flow deviation",
                                                      "the deviation from the flow of G is " + show(d));
                  dev = d;
                  return 0;
                },
                [] { return 0; });
            const LinearSeries ls = run_or_missing(
                where + " (series)",
                [&] {
                  const LinearSeries ls = linear_series(info, pv, x, series_K, h);
                  for (std::size_t e = 0; e < ls.A_q.size(); ++e)
                    if (!std::isfinite(ls.A_q[e]) || !std::isfinite(ls.A_v[e]))
                      throw NumericalFailure::in_output("the truncated series",
                                                        "a coefficient of the series is not finite");
                  return ls;
                },
                [&] {
                  LinearSeries none;
                  none.A_q.assign(static_cast<std::size_t>(n * n), missing_value);
                  none.A_v = none.A_q;
                  return none;
                });
            for (int i = 0; i < n; ++i)
              for (int j = 0; j < n; ++j) {
                const auto e = static_cast<std::size_t>(i * n + j);
                const double aq = static_cast<double>(lm.A_q[e]), av = static_cast<double>(lm.A_v[e]);
                std::vector<std::string> cells{systems[si], x};
                cells.insert(cells.end(), sc.begin(), sc.end());
                cells.insert(cells.end(), {format_cell(h), std::to_string(i), std::to_string(j), format_cell(aq),
                                           format_cell(av), format_cell(ls.A_q[e]), format_cell(ls.A_v[e]),
                                           std::to_string(series_K), format_cell(dev)});
                ao.write_row(cells);
                std::printf("%-18s %-*s %-9g %-3d %-3d %16.12f %16.12f %11.3e %11.3e %11.3e\n",
                            (systems[si] + swept_text(si, ci)).c_str(), sw, x.c_str(), h, i, j, aq, av,
                            std::abs(aq - ls.A_q[e]), std::abs(av - ls.A_v[e]), dev);
              }
          }
      }
    }
    ao.commit();
    return 0;
  });
}
