// The error measure of the paper's Figure 1 and of the contact-integrator literature, for any system with a
// closed-form solution: max_j |(shift + q_j) / (shift + q(t_j)) - 1| (first component), at one h, over a sweep
// of parameters. With the defaults of `make figures` it is the forced oscillator in the literature's setting
// (h = 0.1, T = 50, alpha in {0.01, 0.1, 1, 2}, shift 10).
//   regularized_error --system forced-oscillator --alpha 0.01 0.1 1 2 [--h 0.1] [--shift 10] [--schemes ...]
// Writes out/<system>_regularized_error.tsv (columns system, scheme, <swept parameters>, h, max_rel_err) and a figure.
#include <cmath>
#include <cstdio>

#include "geomint/budget.hpp"
#include "geomint/cli.hpp"
#include "geomint/error.hpp"
#include "geomint/io.hpp"
#include "geomint/plots/figure.hpp"
#include "geomint/system_cli.hpp"
#include "geomint/step_cost.hpp"

using namespace geomint;

int main(int argc, char** argv) {
  return guarded_main("regularized_error", [&] {
    Cli cli("regularized_error", "max regularized relative error against the closed form, over a parameter sweep");
    SystemOptions sysopt(cli, argc, argv, "forced-oscillator", true);
    double h = 0.1, shift = 10;
    std::vector<std::string> names;
    std::string path_name = "fast";
    cli.options.add_options()("h", po::value(&h)->default_value(h, "0.1"), "step size")(
        "shift", po::value(&shift)->default_value(shift, "10"), "the shift s in |(s + q)/(s + q_ref) - 1|")(
        "schemes", po::value(&names)->multitoken(), "schemes (default: every scheme of the system)")(
        "path", po::value(&path_name)->default_value(path_name), "fast (closed forms where they exist) or generic");
    if (!cli.parse(argc, argv)) return 0;
    const SystemInfo& sys = sysopt.system();
    require(sys.has_exact, "system '" + sys.name + "' has no closed-form solution to measure against");
    require_positive(h, "h");
    require(std::isfinite(shift), "shift must be finite, got " + show(shift));
    const auto combos = sysopt.combinations();
    const auto swept = sysopt.swept();
    const auto schemes = sysopt.schemes(names);
    const Path path = parse_path(path_name);
    for (const auto& pv : combos) check_reference_memory(sys, ReferenceKind::exact, step_count(h, sys.horizon(pv)));
    double cost = 1;  // of one step of the closed-form reference and of every scheme, in cheap steps
    for (const auto& s : schemes) cost += step_cost(sys, s, path);
    for (const auto& pv : combos)
      plan_steps(static_cast<double>(step_count(h, sys.horizon(pv))),
                 "the sweep (schemes and the reference x T/h per parameter set)", cost);
    const auto dir = prepare_output_dir(cli.out);
    const std::string stem = sys.name + "_regularized_error";

    Params params = sysopt.header();
    params.insert(params.end(), {{"h", format_number(h)}, {"shift", format_number(shift)}, {"path", to_string(path)},
                                 {"error", "max_j |(shift + q_j)/(shift + q_exact(t_j)) - 1|, first component"}});
    std::vector<std::string> cols{"system", "scheme"};
    cols.insert(cols.end(), swept.begin(), swept.end());
    cols.insert(cols.end(), {"h", "max_rel_err"});
    TsvWriter tsv(dir / (stem + ".tsv"), "regularized_error", params, cols);
    std::printf("%-20s", "scheme");
    for (const auto& pv : combos) {
      std::string label;
      for (const auto& s : swept) label += (label.empty() ? "" : ",") + s + "=" + format_number(param_value(pv, sys, s));
      std::printf(" %14s", label.c_str());
    }
    std::printf("\n");
    // One reference at a time: a closed form stored on T/h + 1 times is the largest thing this program holds, and
  // the memory check above is per parameter set.
  std::vector<std::vector<double>> err(schemes.size(), std::vector<double>(combos.size()));
  for (std::size_t c = 0; c < combos.size(); ++c) {
    const Reference ref = sys.reference(combos[c], h, step_count(h, sys.horizon(combos[c])), ReferenceKind::exact, 1e-13);
    for (std::size_t s = 0; s < schemes.size(); ++s) {
      try {
        err[s][c] = sys.max_relative_error(combos[c], schemes[s], h, path, ref, shift);
      } catch (const NumericalFailure& f) {
        std::fprintf(stderr, "regularized_error: %s (recorded as a missing value)\n", f.what());
        err[s][c] = missing_value;
      }
    }
  }
  for (std::size_t s = 0; s < schemes.size(); ++s) {
    std::printf("%-20s", schemes[s].c_str());
    for (std::size_t c = 0; c < combos.size(); ++c) {
      std::vector<std::string> row{sys.name, schemes[s]};
      for (const auto& x : swept) row.push_back(format_number(param_value(combos[c], sys, x)));
      row.insert(row.end(), {format_number(h), format_cell(err[s][c])});
      tsv.write_row(row);
      std::printf(" %14.3e", err[s][c]);
    }
    std::printf("\n");
  }
    tsv.commit();

    if (swept.size() == 1) {  // error against the swept parameter, a line per scheme
      const auto t = plots::read_tsv(dir / (stem + ".tsv"));
      const std::string x = swept.front();
      bool positive = true;
      for (const auto& pv : combos) positive = positive && param_value(pv, sys, x) > 0;
      plots::Figure fig;
      fig.title = sys.name + ": max regularized relative error (shift " + format_number(shift) + "), h = " + format_number(h);
      fig.width_in = 6.5;
      fig.height_in = 4.5;
      plots::Panel p;
      p.setup = std::string(positive ? "set logscale xy\n" : "set logscale y\n") + "set format y '10^{%L}'\nset xlabel '" +
                x + "'\nset ylabel 'max relative error'\nset key outside right font ',8'\n";
      for (const auto& name : schemes) {
        auto keep = [&](std::size_t r) { return t.text(r, "scheme") == name; };
        p.series.push_back({t.numbers(x, keep), t.numbers("max_rel_err", keep), name, plots::style_for(name, "linespoints")});
      }
      fig.panels.push_back(std::move(p));
      fig.draw(dir / stem);
    }
    return 0;
  });
}
