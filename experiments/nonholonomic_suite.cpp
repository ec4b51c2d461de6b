// The nonholonomic benchmark suite (docs/nonholonomic-suite.md): every problem with an exact solution or exact
// invariants (the rolling disk and the Chaplygin sleigh, free and damped, the Suslov problem, the contact oscillator
// and its non-reversible form) x every scheme x three step sizes, over a long horizon: the error against the exact
// observables, and each invariant's secular drift measured on the run against the drift the modified equation
// predicts (la and contact), with the power of h each follows.
//   nonholonomic_suite [--problems ...] [--schemes ...] [--predict la contact] [--h 0.04 0.02 0.01] [--T 200]
//                      [--kept 4000] [--K 3] [--orbit-T 200] [--orbit-dt 0.05] [--stride 8] [--systems-dir DIR]
//                      [--baselines gsl-rk8pd] [--tols 1e-3 ... 1e-13] [--reps 3] [--name nonholonomic_suite]
//                      [--out out]
// Writes out/<name>.tsv (one row per problem, scheme, invariant and h, and per baseline and tolerance, with what each
// baseline reaches in a scheme's time), out/<name>_fits.tsv (the powers of h and the worst predicted/measured
// ratio), out/<name>_traces.tsv (each invariant against t at the middle h) and out/<name>_invariants.{png,pdf}
// drawn from the traces.
#include <cmath>
#include <cstdio>

#include "geomint/budget.hpp"
#include "geomint/cli.hpp"
#include "geomint/error.hpp"
#include "geomint/io.hpp"
#include "geomint/modified/nonholonomic_suite_study.hpp"
#include "geomint/plots/figure.hpp"

using namespace geomint;
using namespace geomint::modified;

int main(int argc, char** argv) {
  return guarded_main("nonholonomic_suite", [&] {
    SuiteStudyOptions opt;
    opt.systems_dir = GEOMINT_SYSTEMS_DIR;
    std::string name = "nonholonomic_suite";
    std::string problems_doc;
    for (const auto& p : suite_problems()) problems_doc += (problems_doc.empty() ? "" : " ") + p.name;
    Cli cli("nonholonomic_suite",
            "the nonholonomic benchmark suite: error against the exact solution and the drift of each invariant,\n"
            "measured on long runs and predicted from the modified equation, for every problem x scheme x h");
    cli.options.add_options()(
        "problems", po::value(&opt.problems)->multitoken(), ("problems (default: all of " + problems_doc + ")").c_str())(
        "schemes", po::value(&opt.schemes)->multitoken()->default_value(opt.schemes, "la contact la-midpoint la-trapezoid contact-trapezoid yoshida4:la-trapezoid"),
        "schemes and compositions")(
        "predict", po::value(&opt.predict)->multitoken()->default_value(opt.predict, "la contact"),
        "schemes whose drift the modified equation predicts")(
        "h", po::value(&opt.hs)->multitoken()->default_value(opt.hs, "0.04 0.02 0.01"), "step sizes (each divides T)")(
        "T", po::value(&opt.T)->default_value(opt.T), "horizon of every run")(
        "kept", po::value(&opt.kept)->default_value(opt.kept), "rows kept of each run for the fits")(
        "K", po::value(&opt.K)->default_value(opt.K), "order of the modified equation")(
        "orbit-T", po::value(&opt.orbit_T)->default_value(opt.orbit_T), "length of the exact orbit the prediction averages over")(
        "orbit-dt", po::value(&opt.orbit_dt)->default_value(opt.orbit_dt), "grid of that orbit")(
        "stride", po::value(&opt.stride)->default_value(opt.stride), "every stride-th orbit point is averaged")(
        "baselines", po::value(&opt.baselines)->multitoken()->zero_tokens()->default_value(opt.baselines, "gsl-rk8pd"),
        "adaptive baselines run over the tolerances on the system's equations (none: --baselines with no value)")(
        "tols", po::value(&opt.tols)->multitoken()->default_value(opt.tols, "1e-3 1e-5 1e-7 1e-9 1e-11 1e-13"),
        "the baselines' tolerances (relative; absolute the same)")(
        "reps", po::value(&opt.reps)->default_value(opt.reps), "each run's time: the median of reps runs")(
        "name", po::value(&name)->default_value(name), "the stem of the files written")(
        "systems-dir", po::value(&opt.systems_dir)->default_value(opt.systems_dir, "the source tree's docs/systems"),
        "folder of the system files");
    if (!cli.parse(argc, argv)) return 0;
    check_suite_options(opt);
    require(!name.empty() && name.find_first_of("/\\") == std::string::npos && name[0] != '.',
            "--name must be a file stem (no folder, not starting with '.')");
    // every run (problems x schemes x T/h, a composition at its stages' cost) and every prediction (orbit points x
    // (n + 5) modified-equation evaluations, each ~1e4 cheap steps)
    const std::size_t P = opt.problems.empty() ? suite_problems().size() : opt.problems.size();
    for (double h : opt.hs)
      plan_steps(double(P * opt.schemes.size()) * double(step_count(h, opt.T)) * (opt.reps + 2),
                 "the runs (problems x schemes x T/h, each run once watched and reps + 1 times timed)", 20 * 3);
    plan_steps(double(P * opt.predict.size() * opt.hs.size()) * double(step_count(opt.orbit_dt, opt.orbit_T) / opt.stride) * 9,
               "the predictions (problems x schemes x h x orbit points x evaluations)", 1e4);
    const auto dir = prepare_output_dir(cli.out);
    const SuiteStudy study = nonholonomic_suite_study(opt);

    const Params params{{"h", format_list(opt.hs)}, {"T", format_number(opt.T)}, {"kept", std::to_string(opt.kept)},
                        {"K", std::to_string(opt.K)}, {"orbit_T", format_number(opt.orbit_T)},
                        {"orbit_dt", format_number(opt.orbit_dt)}, {"stride", std::to_string(opt.stride)},
                        {"error", "max over the kept rows of |observable - exact| (the problem's observables)"},
                        {"drift", "least-squares slope of I(t_j, q_j, v_j) over [0, T]; spread: |slope of first half - of second|"},
                        {"predicted", "orbit average of dI/dt along the order-K modified flow on Phi_h = 0"},
                        {"baselines", join_names(opt.baselines)}, {"tols", format_list(opt.tols)},
                        {"reps", std::to_string(opt.reps)},
                        {"seconds", "median of reps runs with nothing watched, after a warm-up (wall clock, one thread)"},
                        {"same_time", "a baseline's error and invariant deviation at the scheme's seconds, log-log between its "
                                      "tolerances; missing below its fastest run; beyond its slowest run, what that run reached in less time"}};
    std::vector<std::string> columns{"problem", "scheme", "invariant", "h", "tol", "steps", "error", "offset",
                                     "max_deviation", "measured_rate", "measured_spread", "predicted_rate",
                                     "predicted_spread", "seconds"};
    for (const auto& b : opt.baselines) {
      columns.push_back(b + "_error_same_time");
      columns.push_back(b + "_deviation_same_time");
    }
    TsvWriter tsv(dir / (name + ".tsv"), "nonholonomic_suite", params, columns);
    for (const auto& r : study.rows) {
      std::vector<std::string> cells{r.problem, r.scheme, r.invariant, format_cell(r.h), format_cell(r.tol),
                                     std::to_string(r.steps), format_cell(r.error), format_cell(r.offset),
                                     format_cell(r.max_deviation), format_cell(r.measured.rate),
                                     format_cell(r.measured.spread), format_cell(r.predicted.rate),
                                     format_cell(r.predicted.spread), format_cell(r.seconds)};
      for (std::size_t b = 0; b < opt.baselines.size(); ++b) {
        cells.push_back(format_cell(b < r.baseline_error.size() ? r.baseline_error[b] : missing_value));
        cells.push_back(format_cell(b < r.baseline_deviation.size() ? r.baseline_deviation[b] : missing_value));
      }
      tsv.write_row(cells);
    }
    tsv.commit();
    TsvWriter fits(dir / (name + "_fits.tsv"), "nonholonomic_suite", params,
                   {"problem", "scheme", "invariant", "power_measured", "power_predicted", "worst_ratio"});
    std::printf("%-26s %-22s %-9s %9s %9s %9s\n", "problem", "scheme", "invariant", "p_meas", "p_pred", "worst");
    for (const auto& f : study.fits) {
      fits.row(f.problem, f.scheme, f.invariant, f.power_measured, f.power_predicted, f.worst_ratio);
      std::printf("%-26s %-22s %-9s %9.3f %9.3f %9.3f\n", f.problem.c_str(), f.scheme.c_str(), f.invariant.c_str(),
                  f.power_measured, f.power_predicted, f.worst_ratio);
    }
    fits.commit();
    // Each scheme against each baseline in the same time (the first invariant's rows carry the run's error).
    for (std::size_t b = 0; b < opt.baselines.size(); ++b) {
      std::printf("\n%-26s %-22s %8s %10s %10s %12s\n", "problem", "scheme", "h", "seconds", "error",
                  (opt.baselines[b] + " same s").c_str());
      for (const auto& r : study.rows)
        if (!is_missing(r.h) && b < r.baseline_error.size() &&
            r.invariant == find_suite_problem(r.problem).invariants.front())
          std::printf("%-26s %-22s %8g %10.3g %10.3g %12.3g\n", r.problem.c_str(), r.scheme.c_str(), r.h, r.seconds,
                      r.error, r.baseline_error[b]);
    }
    TsvWriter traces(dir / (name + "_traces.tsv"), "nonholonomic_suite", params,
                     {"problem", "scheme", "invariant", "h", "t", "deviation"});
    for (const auto& tr : study.traces)
      for (std::size_t j = 0; j < tr.t.size(); ++j) traces.row(tr.problem, tr.scheme, tr.invariant, tr.h, tr.t[j], tr.deviation[j]);
    traces.commit();

    // One panel per (problem, invariant): |I(t) - I(exact start)| against t, every scheme, from the saved traces.
    const auto t = plots::read_tsv(dir / (name + "_traces.tsv"));
    plots::Figure fig;
    std::vector<std::pair<std::string, std::string>> panels;
    for (const auto& tr : study.traces)
      if (std::find(panels.begin(), panels.end(), std::make_pair(tr.problem, tr.invariant)) == panels.end())
        panels.emplace_back(tr.problem, tr.invariant);
    fig.title = "invariants against time at h = " + format_number(opt.hs[opt.hs.size() / 2]);
    fig.cols = 4;
    fig.rows = int((panels.size() + 3) / 4);
    fig.width_in = 18;
    fig.height_in = 3.8 * fig.rows;
    for (const auto& [problem, inv] : panels) {
      plots::Panel p;
      p.setup = "set logscale y\nset format y '10^{%L}'\nset xlabel 't'\nset ylabel '|I - I_0|'\nset key bottom right font ',7'\n"
                "set title '" + problem + ": " + inv + "' noenhanced\n";
      for (const auto& scheme : opt.schemes) {
        auto keep = [&](std::size_t r) { return t.text(r, "problem") == problem && t.text(r, "invariant") == inv && t.text(r, "scheme") == scheme; };
        std::vector<double> x = t.numbers("t", keep), y = t.numbers("deviation", keep);
        for (double& v : y) v = std::abs(v);
        p.series.push_back({x, y, scheme, plots::style_for(scheme)});
      }
      fig.panels.push_back(std::move(p));
    }
    fig.draw(dir / (name + "_invariants"));
    return 0;
  });
}
