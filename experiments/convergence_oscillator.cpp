// Convergence study of the oscillator schemes against the closed-form solution:
// err_max = max_j |q_j - q(t_j)| for h halving from h-max to <= h-min, several alpha.
//   convergence_oscillator [--h-max 0.2] [--h-min 0.003] [--alpha 0.01 0.1 1] [--T 50] [--out out]
// Writes out/convergence_oscillator.tsv (one row per scheme, alpha, h), out/convergence_oscillator_fits.tsv
// (fitted order per scheme and alpha) and out/convergence_oscillator.{png,pdf}.
#include <cmath>
#include <cstdio>

#include "geomint/budget.hpp"
#include "geomint/cli.hpp"
#include "geomint/error.hpp"
#include "geomint/io.hpp"
#include "geomint/record.hpp"
#include "geomint/registry.hpp"
#include "geomint/plots/figure.hpp"
#include "geomint/study.hpp"
#include "geomint/sweep.hpp"

using namespace geomint;

int main(int argc, char** argv) {
  return guarded_main("convergence_oscillator", [&] {
    double h_max = 0.2, h_min = 0.003, T = 50, q0 = -0.25, p0 = 0.75;
    std::vector<double> alphas{0.01, 0.1, 1};
    // the paper's schemes (under the paper's names: leapfrog is la-trapezoid's closed form, contact-sym
    // contact-trapezoid's), (7) as printed, and the second-order comparators
    std::vector<std::string> names{"la", "contact", "la-printed", "leapfrog", "la-midpoint", "contact-sym"};
    Cli cli("convergence_oscillator", "error against h of the oscillator schemes, with fitted orders");
    cli.options.add_options()("h-max", po::value(&h_max)->default_value(h_max), "largest step")(
        "h-min", po::value(&h_min)->default_value(h_min), "halve until h <= h-min")(
        "T", po::value(&T)->default_value(T), "horizon")("q0", po::value(&q0)->default_value(q0), "initial position")(
        "p0", po::value(&p0)->default_value(p0), "initial momentum")(
        "alpha", po::value(&alphas)->multitoken()->default_value(alphas, "0.01 0.1 1"), "damping values")(
        "schemes", po::value(&names)->multitoken()->default_value(names, "la contact la-printed leapfrog la-midpoint contact-sym"),
        "schemes");
    if (!cli.parse(argc, argv)) return 0;

    const auto hs = halving_sequence(h_max, h_min);
    for (double h : hs)
      plan_steps(static_cast<double>(names.size() * alphas.size()) * static_cast<double>(step_count(h, T)),
                 "the sweep (schemes x alpha x T/h)");
    const SystemInfo& osc = find_system("oscillator");
    auto scene = [&](double a) { return ParamValues{{"alpha", a}, {"q0", q0}, {"p0", p0}, {"T", T}}; };
    for (double a : alphas) osc.validate(scene(a));
    for (const auto& n : names) osc.scheme(n);  // unknown names fail here
    const auto dir = prepare_output_dir(cli.out);

    // The study (core/include/geomint/study.hpp): the closed forms against the closed-form solution, one parameter
    // combination per alpha.
    std::vector<ParamValues> combos;
    for (double a : alphas) combos.push_back(scene(a));
    const Sweep& sweep = Sweep::world();  // under mpirun the ranks share the runs; rank 0 writes
    const ConvergenceStudy study = convergence_study(osc, combos, names, hs, Path::fast, ReferenceKind::exact, 0, sweep);
    if (!sweep.root()) return 0;
    const Params params{{"h", format_list(hs)}, {"T", format_number(T)}, {"q0", format_number(q0)},
                        {"p0", format_number(p0)}, {"alpha", format_list(alphas)},
                        {"error", "max_j |q_j - q_exact(t_j)|, closed-form solution"}};
    TsvWriter tsv(dir / "convergence_oscillator.tsv", "convergence_oscillator", params,
                  {"scheme", "alpha", "h", "steps", "err_max", "order"});
    TsvWriter fits(dir / "convergence_oscillator_fits.tsv", "convergence_oscillator", params,
                   {"scheme", "alpha", "fitted_order", "points", "expected_order"});
    std::printf("%-11s %-6s %-10s %12s %7s\n", "scheme", "alpha", "h", "err_max", "order");
    for (std::size_t si = 0; si < names.size(); ++si)
      for (std::size_t c = 0; c < alphas.size(); ++c) {
        const ConvergenceSeries& se = study.series[c * names.size() + si];
        const double a = alphas[c];
        for (size_t i = 0; i < hs.size(); ++i) {
          tsv.row(se.scheme, a, hs[i], se.steps[i], se.err[i], se.local_order[i]);
          std::printf("%-11s %-6g %-10g %12.4e %7.3f\n", se.scheme.c_str(), a, hs[i], se.err[i], se.local_order[i]);
        }
        fits.row(se.scheme, a, se.fit.slope, se.fit.points, se.expected_order);
      }
    tsv.commit();
    fits.commit();

    std::printf("\nfitted orders (least squares over all h):\n%-11s", "scheme");
    for (double a : alphas) std::printf(" alpha=%-6g", a);
    std::printf("\n");
    const auto ft = plots::read_tsv(dir / "convergence_oscillator_fits.tsv");
    for (const auto& name : names) {
      std::printf("%-11s", name.c_str());
      for (double a : alphas)
        for (size_t r = 0; r < ft.rows.size(); ++r)
          if (ft.text(r, "scheme") == name && ft.number(r, "alpha") == a)
            std::printf(" %12.3f", ft.number(r, "fitted_order"));
      std::printf("\n");
    }

    const auto t = plots::read_tsv(dir / "convergence_oscillator.tsv");
    plots::Figure fig;
    fig.title = "Oscillator: max_j |q_j - q(t_j)| against h, T = " + format_number(T);
    fig.cols = static_cast<int>(alphas.size());
    fig.width_in = 4.2 * fig.cols;
    fig.height_in = 4.2;
    for (double a : alphas) {
      plots::Panel p;
      p.setup = "set logscale xy\nset format y '10^{%L}'\nset xlabel 'h'\nset ylabel 'max error in q'\n"
                "set key bottom right\nset title 'alpha = " + format_number(a) + "'\n";
      for (const auto& name : names) {
        auto keep = [&](size_t i) { return t.text(i, "scheme") == name && t.number(i, "alpha") == a; };
        const auto x = t.numbers("h", keep), y = t.numbers("err_max", keep);
        p.series.push_back({x, y, plots::slope_label(name, fit_order(x, y).slope), plots::style_for(name, "linespoints")});
      }
      fig.panels.push_back(std::move(p));
    }
    fig.draw(dir / "convergence_oscillator");
    return 0;
  });
}
