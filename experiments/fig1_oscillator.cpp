// Figure 1 of the paper: the damped oscillator solved by the LA and contact integrators, and their
// regularized relative error |(s + q)/(s + q_ref) - 1| (s = 10, as in the authors' earlier code)
// against the implicit leapfrog reference at step h/10.
//   fig1_oscillator [--h 0.1] [--T 50] [--alpha 0.01 0.1] [--out out]
// Writes out/fig1_oscillator.tsv (one row per scheme, alpha and t), out/fig1_oscillator_summary.tsv
// and out/fig1_oscillator.{png,pdf} drawn from the first file.
#include <algorithm>
#include <cmath>
#include <optional>
#include <cstdio>
#include <map>

#include "geomint/budget.hpp"
#include "geomint/cli.hpp"
#include "geomint/error.hpp"
#include "geomint/io.hpp"
#include "geomint/record.hpp"
#include "geomint/registry.hpp"
#include "geomint/plots/figure.hpp"

using namespace geomint;

int main(int argc, char** argv) {
  return guarded_main("fig1_oscillator", [&] {
    double h = 0.1, T = 50, q0 = -0.25, p0 = 0.75, shift = 10;
    int ref_factor = 10;
    std::vector<double> alphas{0.01, 0.1};
    std::vector<std::string> names{"la", "la-printed", "contact"};  // the paper's Figure 1 (and (7) as printed)
    Cli cli("fig1_oscillator", "Figure 1: damped oscillator, LA vs contact, relative error against leapfrog at h/10");
    cli.options.add_options()("h", po::value(&h)->default_value(h), "step size")(
        "T", po::value(&T)->default_value(T), "horizon")("q0", po::value(&q0)->default_value(q0), "initial position")(
        "p0", po::value(&p0)->default_value(p0), "initial momentum")(
        "alpha", po::value(&alphas)->multitoken()->default_value(alphas, "0.01 0.1"), "damping values")(
        "schemes", po::value(&names)->multitoken()->default_value(names, "la la-printed contact"), "schemes to compare")(
        "ref-factor", po::value(&ref_factor)->default_value(ref_factor), "reference leapfrog runs at h/ref-factor")(
        "shift", po::value(&shift)->default_value(shift), "shift s of the regularized relative error");
    if (!cli.parse(argc, argv)) return 0;

    // Validate everything before writing anything.
    const long N = step_count(h, T);
    require(ref_factor >= 1, "ref-factor must be a positive integer");
    // The reference run at h/ref-factor is stored (every column of a Run) before the table is written.
    check_steps(static_cast<double>(N) * ref_factor, "the reference run (T/h times ref-factor)");
    check_memory(static_cast<double>(N) * ref_factor * Run::bytes_per_step(1, 0), "the reference trajectory");
    require_finite(shift, "shift");
    const SystemInfo& osc = find_system("oscillator");
    auto scene = [&](double a) { return ParamValues{{"alpha", a}, {"q0", q0}, {"p0", p0}, {"T", T}}; };
    for (double a : alphas) osc.validate(scene(a));
    for (const auto& n : names) osc.scheme(n);  // unknown names fail here
    const auto dir = prepare_output_dir(cli.out);

    const Params params{{"h", format_number(h)},       {"T", format_number(T)},
                        {"q0", format_number(q0)},     {"p0", format_number(p0)},
                        {"alpha", format_list(alphas)}, {"reference", "leapfrog at h/" + std::to_string(ref_factor)},
                        {"shift", format_number(shift)}};
    TsvWriter tsv(dir / "fig1_oscillator.tsv", "fig1_oscillator", params,
                  {"alpha", "scheme", "t", "q", "p", "q_ref", "rel_err", "abs_err_exact"});
    TsvWriter summary(dir / "fig1_oscillator_summary.tsv", "fig1_oscillator", params,
                      {"alpha", "scheme", "max_rel_err", "max_abs_err_ref", "max_abs_err_exact"});
    std::printf("%-8s %-12s %14s %14s %14s\n", "alpha", "scheme", "max_rel_err", "max|q-q_ref|", "max|q-q_exact|");
    for (double a : alphas) {
      const ParamValues pv = scene(a);
      // the reference: the implicit leapfrog (the paper's; la-trapezoid's closed form) at h/ref-factor
      const Run r = osc.run(pv, "leapfrog", h / ref_factor, Path::fast, 1);
      // the exact solution, where double precision holds it (at a damping of 1e200 it is 0 * inf): else missing
      const std::vector<double> exact = run_or_missing(
          "alpha=" + show(a) + " (the exact solution)",
          [&] {
            const Reference e = osc.reference(pv, h, N, ReferenceKind::exact, 0);
            for (std::size_t j = 0; j < e.q.size(); ++j)
              if (!std::isfinite(e.q[j]))
                throw NumericalFailure(static_cast<long>(j), "reference",
                                       "the exact solution is not finite at t = " + show(static_cast<double>(j) * h));
            return e.q;
          },
          [&] { return std::vector<double>(static_cast<std::size_t>(N + 1), missing_value); });
      auto q_ref = [&](long j) { return r.q[static_cast<size_t>(j * ref_factor)]; };
      auto q_exact = [&](long j) { return exact[static_cast<size_t>(j)]; };
      for (long j = 0; j <= N; ++j)
        tsv.row(a, "leapfrog-ref", r.t[static_cast<size_t>(j * ref_factor)], q_ref(j),
                r.p[static_cast<size_t>(j * ref_factor)], q_ref(j), 0.0, std::abs(q_ref(j) - q_exact(j)));
      for (const auto& name : names) {
        // A run that fails is missing (no trajectory rows, nan in the summary); the sweep goes on.
        const auto run = run_or_missing(
            name + " alpha=" + show(a) + " h=" + show(h), [&] { return std::optional<Run>(osc.run(pv, name, h, Path::fast, 1)); },
            [] { return std::optional<Run>(); });
        if (!run) {
          const double nan = missing_value;
          summary.row(a, name, nan, nan, nan);
          continue;
        }
        const auto& tr = *run;
        double max_rel = 0, max_abs = 0, max_exact = 0;
        for (long j = 0; j <= N; ++j) {
          const auto k = static_cast<size_t>(j);
          const double rel = std::abs((shift + tr.q[k]) / (shift + q_ref(j)) - 1);
          const double ex = std::abs(tr.q[k] - q_exact(j));
          max_rel = std::max(max_rel, rel);
          max_abs = std::max(max_abs, std::abs(tr.q[k] - q_ref(j)));
          max_exact = std::max(max_exact, ex);
          tsv.row(a, name, tr.t[k], tr.q[k], tr.p[k], q_ref(j), rel, ex);
        }
        summary.row(a, name, max_rel, max_abs, max_exact);
        std::printf("%-8g %-12s %14.4e %14.4e %14.4e\n", a, name.c_str(), max_rel, max_abs, max_exact);
      }
    }
    tsv.commit();
    summary.commit();

    // Figure, from the saved file.
    const auto t = plots::read_tsv(dir / "fig1_oscillator.tsv");
    plots::Figure fig;
    fig.title = "Damped oscillator, h = " + format_number(h) + ", (p0, q0) = (" + format_number(p0) + ", " +
                format_number(q0) + ")";
    fig.rows = 2;
    fig.cols = static_cast<int>(alphas.size());
    fig.width_in = 4.5 * fig.cols;
    fig.height_in = 7;
    std::vector<std::string> all_names = {"leapfrog-ref"};
    for (const auto& n : names) all_names.push_back(n);
    for (int row = 0; row < 2; ++row)
      for (double a : alphas) {
        plots::Panel p;
        p.setup = "set xlabel 't'\nset title 'alpha = " + format_number(a) + "'\n" +
                  (row == 0 ? "set ylabel 'q'\nset key bottom right\n"
                            : "set ylabel '|(10+q)/(10+q_{ref}) - 1|'\nset logscale y\nset format y '10^{%L}'\n"
                              "set key bottom right\n");
        for (const auto& n : all_names) {
          if (row == 1 && n == "leapfrog-ref") continue;
          auto keep = [&](size_t i) { return t.text(i, "scheme") == n && t.number(i, "alpha") == a; };
          plots::Series s{t.numbers("t", keep), t.numbers(row == 0 ? "q" : "rel_err", keep),
                          n == "leapfrog-ref" ? "leapfrog, h/" + std::to_string(ref_factor) : n, plots::style_for(n)};
          if (row == 1)  // log axis: zero error (t = 0) is not a point
            for (auto& y : s.y)
              if (y <= 0) y = missing_value;
          p.series.push_back(std::move(s));
        }
        fig.panels.push_back(std::move(p));
      }
    fig.draw(dir / "fig1_oscillator");
    return 0;
  });
}
