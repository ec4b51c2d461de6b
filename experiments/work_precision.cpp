// Work–precision diagram of any system: the max error in q against CPU time, its schemes over h beside Boost.Odeint
// and GSL baselines (rk4 over h; dopri5, Bulirsch–Stoer and rk8pd over the tolerance), every error against the
// system's reference (its closed form, else Odeint at 1e-13) and every time the median of repeated runs after a
// warm-up. The baselines integrate x = (q, q') with the acceleration derived from L, F and Phi by AD, or with the
// system's own (--equations rhs: what a hand-coded baseline costs). An adaptive method's error is taken at dense
// output on the grid of h-max, or at the steps it chose against the closed form (--adaptive-error steps: no output
// grid caps its step size). --measure adds quantities measured along every run against the reference on the grid of
// h-max: the energy, a momentum p<i> = dL/dq'_i, or a formula of the state ("<name>=<formula>").
//   work_precision [--system oscillator] [--schemes ...] [--h-max 0.1] [--h-min 1e-3] [--tol 1e-3 ... 1e-12] [--reps 5]
//                  [--baselines odeint-rk4 odeint-dopri5 odeint-bulirsch-stoer gsl-rk8pd] [--measure energy p1 r=...]
//                  [parameters: a sweep]
// The paper's damped oscillator (T = 50, alpha 0.01, 0.1, 1) and the Foucault pendulum over its anomaly-free
// horizons (T = 4 s with the paper's constraint, 100 s with the rotation) are lines of the Makefile's
// FIGURE_COMMANDS.
// Writes out/<system>_work_precision.tsv (errors: the same bits for the same command), ..._timings.tsv,
// ..._summary.tsv (per combination: each method's CPU time to reach --target, the best geometric scheme's over the
// best adaptive method's, the slopes; timings) and the figure out/<system>_work_precision.{png,pdf} (a panel per
// parameter combination).
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "geomint/budget.hpp"
#include "geomint/cli.hpp"
#include "geomint/error.hpp"
#include "geomint/io.hpp"
#include "geomint/plots/figure.hpp"
#include "geomint/study.hpp"
#include "geomint/system_cli.hpp"
#include "geomint/work_precision.hpp"
#include "text_columns.hpp"

using namespace geomint;

int main(int argc, char** argv) {
  return guarded_main("work_precision", [&] {
    Cli cli("work_precision", "error against CPU time: a system's schemes and Odeint/GSL baselines");
    SystemOptions sysopt(cli, argc, argv, "oscillator", true);
    WorkPrecisionOptions opt;
    double h_max = 0.1, h_min = 1e-3;
    std::vector<std::string> names;
    opt.baselines = {"odeint-rk4", "odeint-dopri5", "odeint-bulirsch-stoer"};
    opt.tols = {1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12};
    std::string path_name = "fast", norm_name = "max", equations = "ad", adaptive_error = "output";
    double target = 1e-6;
    cli.options.add_options()("schemes", po::value(&names)->multitoken(), "schemes (default: every scheme of the system)")(
        "h-max", po::value(&h_max)->default_value(h_max, "0.1"), "largest step")(
        "h-min", po::value(&h_min)->default_value(h_min, "1e-3"), "halve until h <= h-min")(
        "baselines", po::value(&opt.baselines)->multitoken()->default_value(opt.baselines, join_names(opt.baselines, " ")),
        "odeint-rk4 (over h), odeint-dopri5, odeint-bulirsch-stoer, gsl-rk8pd (over tol)")(
        "tol", po::value(&opt.tols)->multitoken()->default_value(opt.tols, "1e-3 ... 1e-12"),
        "tolerances of the adaptive baselines (rel = abs)")(
        "adaptive-error", po::value(&adaptive_error)->default_value(adaptive_error),
        "output (dense output on the grid of h-max, against the reference) or steps (at the steps each chose, "
        "against the closed form)")(
        "target", po::value(&target)->default_value(target, "1e-6"),
        "the max error in q the summary asks each method to reach (its cheapest CPU time to reach it, the best "
        "geometric scheme's over the best adaptive method's); and each measure's error")(
        "measure", po::value(&opt.measures)->multitoken(),
        "quantities measured along every run against the reference, max_k |Q(run) - Q(ref)| at t_k = t0 + k h-max: "
        "energy, p<i> (the momentum dL/dq'_i), <name>=<formula> (in t, q1.., v1.., pi and the parameters, e.g. "
        "'r=sqrt(q1^2+q2^2)'); each a column <name>_err, a line of the summary and a panel of the figure");
    add_baseline_study_options(cli, equations, path_name, norm_name, opt.reps);
    if (!cli.parse(argc, argv)) return 0;
    const SystemInfo& sys = sysopt.system();
    const auto combos = sysopt.combinations();
    const auto swept = sysopt.swept();
    opt.schemes = sysopt.schemes(names);
    sysopt.warn_contact(combos, opt.schemes);
    opt.hs = halving_sequence(h_max, h_min);
    opt.path = parse_path(path_name);
    opt.norm = parse_norm(norm_name);
    require(equations == "ad" || equations == "rhs", "unknown equations '" + equations + "' (known: ad rhs)");
    require(adaptive_error == "output" || adaptive_error == "steps",
            "unknown adaptive error '" + adaptive_error + "' (known: output steps)");
    require(std::isfinite(target) && target > 0, "target must be a positive number, got " + format_number(target));
    opt.hand_written = equations == "rhs";
    opt.at_steps = adaptive_error == "steps";
    check_work_precision(sys, combos, opt);
    const std::vector<StateMeasure> measures = state_measures(sys, opt.measures);
    const auto dir = prepare_output_dir(cli.out);

    std::fprintf(stderr, "work_precision: %s ...\n", sys.name.c_str());
    // the study checks (and plans) again: from zero, or a plan within the budget would count twice and be refused
    const WorkPrecisionStudy study = [&] {
      const BudgetScope again(budget_enabled(), "--no-budget");
      return work_precision_study(sys, combos, opt);
    }();
    const auto& pts = study.points;
    Params params = sysopt.header();
    params.insert(params.end(), {{"h", format_list(opt.hs)}, {"tol", format_list(opt.tols)},
                                 {"baselines", join_names(opt.baselines, " ")}, {"path", to_string(opt.path)},
                                 {"equations", equations}, {"adaptive_error", adaptive_error},
                                 {"reps", std::to_string(opt.reps)}, {"reference", study.reference}, {"norm", to_string(opt.norm)},
                                 {"target", format_number(target)},
                                 {"error", "max_j |q(t_j) - q_ref(t_j)| (" + std::string(to_string(opt.norm)) +
                                               " norm); adaptive methods: " +
                                               (opt.at_steps ? "at every step they chose" : "dense output at t = k h-max")}});
    for (std::size_t m = 0; m < measures.size(); ++m)
      params.emplace_back(measures[m].column, measures[m].doc + " (--measure " + opt.measures[m] + ")");
    // the swept values of a point's combination
    auto key = [&](const WorkPoint& p) {
      std::vector<std::string> k;
      for (const auto& s : swept) k.push_back(format_number(param_value(combos[static_cast<std::size_t>(p.group)], sys, s)));
      return k;
    };
    std::vector<std::string> cols{"system", "method"}, tcols{"system", "method"};
    cols.insert(cols.end(), swept.begin(), swept.end());
    tcols.insert(tcols.end(), swept.begin(), swept.end());
    cols.insert(cols.end(), {"knob", "value", "steps", "err_max"});
    for (const auto& m : measures) cols.push_back(m.column);
    tcols.insert(tcols.end(), {"knob", "value", "seconds_median", "seconds_min", "seconds_max", "reps"});
    const std::string stem = sys.name + "_work_precision";
    TsvWriter data(dir / (stem + ".tsv"), "work_precision", params, cols);
    TsvWriter tim(dir / (stem + "_timings.tsv"), "work_precision", params, tcols);
    std::vector<std::string> methods;
    for (const auto& p : pts) {
      std::vector<std::string> row{sys.name, p.method}, trow{sys.name, p.method};
      for (const auto& k : key(p)) {
        row.push_back(k);
        trow.push_back(k);
      }
      row.insert(row.end(), {p.knob, format_cell(p.value), std::to_string(p.steps), format_cell(p.errors[0])});
      for (std::size_t m = 0; m < measures.size(); ++m) row.push_back(format_cell(p.errors[1 + m]));
      trow.insert(trow.end(), {p.knob, format_cell(p.value), format_cell(p.time.median), format_cell(p.time.min),
                               format_cell(p.time.max), std::to_string(p.time.reps)});
      data.write_row(row);
      tim.write_row(trow);
      if (std::find(methods.begin(), methods.end(), p.method) == methods.end()) methods.push_back(p.method);
    }
    data.commit();
    tim.commit();

    // The summary (summarise_work, as the long-horizon studies'): per combination, each method's cheapest CPU time
    // to reach the target max error, the best geometric scheme's over the best adaptive method's, and each method's
    // fitted slope of log(error) against log(time) above the reference's floor (fewer than three points there: no
    // slope). Written with the timings' caveat: never the same bits twice.
    std::vector<WorkMeasure> summarised{{"err_max", "max error in q", target, study.floor}};
    for (const auto& m : measures) summarised.push_back({m.column, m.doc, target, study.floor});
    const std::vector<WorkSummaryRow> summary = summarise_work(pts, summarised);
    std::vector<std::string> scols{"kind", "measure", "target"};
    scols.insert(scols.end(), swept.begin(), swept.end());
    scols.insert(scols.end(), {"method", "value"});
    Params sparams = params;
    sparams.emplace_back("slope_floor", format_number(study.floor) + " (errors at or below it are the reference's: no slope is fitted through them)");
    TsvWriter sum(dir / (stem + "_summary.tsv"), "work_precision", sparams, scols);
    for (const auto& r : summary) {
      if (r.kind == "crossover") continue;  // one horizon: no crossover
      std::vector<std::string> row{r.kind, r.measure, format_cell(r.target)};
      WorkPoint g;
      g.group = r.group;
      for (const auto& k : key(g)) row.push_back(k);
      row.insert(row.end(), {r.method, format_cell(r.value)});
      sum.write_row(row);
    }
    sum.commit();
    const auto d = plots::read_tsv(dir / (stem + ".tsv"));
    const auto tt = plots::read_tsv(dir / (stem + "_timings.tsv"));
    auto in = [&](std::size_t r, const ParamValues& pv) {
      for (const auto& s : swept)
        if (d.number(r, s) != param_value(pv, sys, s)) return false;
      return true;
    };
    const int width = name_width(methods, 24);
    std::printf("CPU time to reach max error <= %s (median, microseconds); '-' = not reached\n%-*s",
                format_number(target).c_str(), width, "method");
    for (const auto& pv : combos) {
      std::string label;
      for (const auto& s : swept) label += (label.empty() ? "" : ",") + s + "=" + format_number(param_value(pv, sys, s));
      std::printf(" %14s", label.empty() ? sys.name.c_str() : label.c_str());
    }
    std::printf("\n");
    auto print_row = [&](const std::string& label, const std::string& kind, const std::string& method, double scale,
                         const char* format) {
      std::printf("%-*s", width, label.c_str());
      for (std::size_t g = 0; g < combos.size(); ++g)
        for (const auto& r : summary)
          if (r.kind == kind && r.measure == "err_max" && r.method == method && r.group == double(g)) {
            if (std::isfinite(r.value))
              std::printf(format, r.value * scale);
            else
              std::printf(" %14s", "-");
          }
      std::printf("\n");
    };
    for (const auto& m : methods) print_row(m, "seconds_to_target", m, 1e6, " %14.1f");
    print_row("geometric/adaptive", "geometric_over_adaptive", "-", 1.0, " %14.3g");

    plots::Figure fig;
    fig.title = sys.name + ": max error in q against CPU time (median)";
    // a panel per combination (three to a row), or with measures a row per combination: q, then each measure
    fig.cols = measures.empty() ? static_cast<int>(std::min<std::size_t>(combos.size(), 3)) : static_cast<int>(1 + measures.size());
    fig.rows = measures.empty() ? static_cast<int>((combos.size() + 2) / 3) : static_cast<int>(combos.size());
    fig.width_in = 4.6 * fig.cols;
    fig.height_in = 4.6 * fig.rows;
    for (const auto& pv : combos) {
      std::string title;
      for (const auto& s : swept) title += (title.empty() ? "" : ", ") + s + " = " + format_number(param_value(pv, sys, s));
      std::vector<std::pair<std::string, std::string>> panels{{"err_max", "max error in q"}};
      // a measure's label is its name (letters, digits, _: checked), never the formula a user wrote
      for (const auto& m : measures) panels.emplace_back(m.column, "max error in " + m.column.substr(0, m.column.size() - 4));
      for (const auto& [column, label] : panels) {
        plots::Panel p;
        p.setup = "set logscale xy\nset format x '10^{%L}'\nset format y '10^{%L}'\nset xlabel 'CPU time per run (s)'\n"
                  "set ylabel '" + label + "'\nset key bottom left font ',8'\nset title '" +
                  (title.empty() ? "T = " + format_number(sys.horizon(pv)) : title) + "'\n";
        for (const auto& m : methods) {
          auto keep = [&](std::size_t i) { return d.text(i, "method") == m && in(i, pv); };
          p.series.push_back({tt.numbers("seconds_median", keep), d.numbers(column, keep), m, plots::style_for(m, "linespoints")});
        }
        fig.panels.push_back(std::move(p));
      }
    }
    fig.draw(dir / stem);
    return 0;
  });
}
