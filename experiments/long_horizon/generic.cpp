// The long-horizon study of a system that declares no structure of its own (long_horizon/studies.hpp): the
// work–precision study of work_precision.hpp run over horizons a multiple of the system's T, two errors against
// CPU time:
//   err_max  max_j |q(t_j) - q_ref(t_j)|: on a system that damps out, set in its first periods whatever the horizon;
//   err_rel  max_k |q(t_k) - q_ref(t_k)| / A_k on the grid t_k = k h-max, A_k the largest |q_ref| over the last T
//            before t_k: how well a method follows the solution at the size it has by then (a decay rate off by d
//            shows as d t), the long-horizon question on a dissipative system; counted where A_k is above what the
//            reference resolves (relative_size_floor: 1e8 times an Odeint reference's tolerance);
// summarised as the structure studies are (the CPU time each method needs to reach a target, the best geometric
// scheme against the best adaptive method, the horizon from which a geometric scheme is cheaper, the slope of log
// error against log time). What it measures is what the horizon accumulates, not a law: a system whose structure
// has an exact law a run can be held to deserves a study of its own.
//   long_horizon --system pendulum [--horizons 10 100] [--h-max 0.1] [--h-min 0.0125] [--tol 1e-4 ... 1e-10]
//                [--target 1e-6] [--rel-target 1e-4] [--schemes ...] [--baselines ...]
//                [parameters of the system; one swept besides T]
// Writes out/<system>_long_horizon.tsv (errors: the same bits for the same command), _timings.tsv, _summary.tsv and
// the figure out/<system>_long_horizon.{png,pdf} (at the longest horizon).
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "geomint/error.hpp"
#include "geomint/io.hpp"
#include "geomint/study.hpp"
#include "geomint/system_cli.hpp"
#include "geomint/work_precision.hpp"
#include "long_horizon/studies.hpp"
#include "long_horizon/table.hpp"

using namespace geomint;

int long_horizon_generic(int argc, char** argv) {
  Cli cli("long_horizon", "long-horizon error in q against CPU time, over multiples of a system's horizon");
  SystemOptions sysopt(cli, argc, argv, find_system_arg(argc, argv, "pendulum"), true);
  WorkPrecisionOptions opt;
  double h_max = 0.1, h_min = 0.0125, target = 1e-6, rel_target = 1e-4;
  std::vector<double> factors{10, 100};
  std::vector<std::string> names;
  opt.baselines = {"odeint-rk4", "odeint-dopri5", "odeint-bulirsch-stoer"};
  opt.tols = {1e-4, 1e-6, 1e-8, 1e-10};
  opt.reps = 3;
  std::string path_name = "fast", norm_name = "max", equations = "ad";
  std::string studies;
  for (const auto& s : long_horizon_studies()) studies += std::string(studies.empty() ? "" : ", ") + s.system;
  cli.options.add_options()(
      "horizons", po::value(&factors)->multitoken()->default_value(factors, "10 100"),
      ("the horizons, as multiples of the system's T (a preset of this study: T itself is a convergence study's "
       "horizon; " + studies + " have studies of their own)").c_str())(
      "schemes", po::value(&names)->multitoken(),
      "schemes and compositions <family>:<base> (default: every scheme of the system, and yoshida4, yoshida6a and "
      "kahanli8 of its la-trapezoid)")(
      "h-max", po::value(&h_max)->default_value(h_max, "0.1"), "largest step")(
      "h-min", po::value(&h_min)->default_value(h_min, "0.0125"), "halve until h <= h-min")(
      "baselines", po::value(&opt.baselines)->multitoken()->default_value(opt.baselines, join_names(opt.baselines, " ")),
      "odeint-rk4 (over h), odeint-dopri5, odeint-bulirsch-stoer, gsl-rk8pd (over tol)")(
      "tol", po::value(&opt.tols)->multitoken()->default_value(opt.tols, "1e-4 1e-6 1e-8 1e-10"),
      "tolerances of the adaptive baselines (rel = abs)")(
      "target", po::value(&target)->default_value(target, "1e-6"), "the err_max the summary asks each method to reach")(
      "rel-target", po::value(&rel_target)->default_value(rel_target, "1e-4"),
      "the err_rel (relative to the solution's size over the last T) the summary asks each method to reach");
  add_baseline_study_options(cli, equations, path_name, norm_name, opt.reps);
  if (!cli.parse(argc, argv)) return 0;
  const SystemInfo& sys = sysopt.system();
  const auto combos = sysopt.combinations();
  const auto swept = sysopt.swept();
  require(std::find(swept.begin(), swept.end(), "T") == swept.end(),
          "give one --T: the horizons are --horizons times it");
  require(swept.size() <= 1, "long_horizon sweeps one parameter besides the horizon, got " + join_names(swept, " "));
  require(!factors.empty(), "give at least one --horizons");
  for (double k : factors)
    require(std::isfinite(k) && k >= 1 && k <= 1e6, "horizons must be multiples of T in [1, 1e6], got " + show(k));
  require(std::isfinite(target) && target > 0, "target must be a positive error, got " + show(target));
  require(std::isfinite(rel_target) && rel_target > 0, "rel-target must be a positive error, got " + show(rel_target));
  opt.schemes = sysopt.schemes(names);
  if (names.empty()) {  // and the compositions of orders 4, 6, 8 of its leapfrog (or its first symmetric scheme)
    const auto bases = sys.composition_bases();
    const std::string base = std::find(bases.begin(), bases.end(), "la-trapezoid") != bases.end() ? "la-trapezoid"
                             : bases.empty()                                                      ? ""
                                                                                                  : bases.front();
    const auto all = sys.composition_names();
    for (const char* family : {"yoshida4", "yoshida6a", "kahanli8"})
      if (std::find(all.begin(), all.end(), family + (":" + base)) != all.end()) opt.schemes.push_back(family + (":" + base));
  }
  opt.hs = halving_sequence(h_max, h_min);
  opt.path = parse_path(path_name);
  opt.norm = parse_norm(norm_name);
  require(equations == "ad" || equations == "rhs", "unknown equations '" + equations + "' (known: ad rhs)");
  opt.hand_written = equations == "rhs";
  // The study's group (its value names a row of the summary): the swept parameter, else the damping alpha where the
  // system has one (what the structure studies group by), else its first parameter.
  std::string group = swept.empty() ? "" : swept.front();
  for (const auto& p : sys.params)
    if (group.empty() && p.name == "alpha") group = p.name;
  for (const auto& p : sys.params)
    if (group.empty() && p.name != "T") group = p.name;
  require(!group.empty(), "system '" + sys.name + "' has no parameter besides T to name the study's rows");
  bool has_T = false;
  for (const auto& p : sys.params) has_T = has_T || p.name == "T";
  require(has_T, "system '" + sys.name + "' has no parameter T, the horizon the study multiplies");
  std::vector<ParamValues> runs;  // every combination at every horizon, horizons innermost
  for (const auto& pv : combos)
    for (double k : factors) {
      ParamValues r;
      for (const auto& [name, v] : pv)
        if (name != "T") r.emplace_back(name, v);
      r.emplace_back("T", k * sys.horizon(pv));
      sys.validate(r);
      runs.push_back(std::move(r));
    }
  opt.relative_window = sys.horizon(combos.front());  // the system's T (not swept)
  check_work_precision(sys, runs, opt);
  const auto dir = prepare_output_dir(cli.out);

  std::fprintf(stderr, "long_horizon: %s over %s times T ...\n", sys.name.c_str(), format_list(factors).c_str());
  WorkPrecisionStudy study = work_precision_study(sys, runs, opt);
  auto& pts = study.points;
  for (auto& p : pts) {  // group: the index of the run, until here
    const auto& r = runs[static_cast<std::size_t>(p.group)];
    p.horizon = sys.horizon(r);
    p.group = param_value(r, sys, group);
  }
  Params params = sysopt.header();
  params.insert(params.end(), {{"horizons", format_list(factors) + " times T"}, {"h", format_list(opt.hs)},
                               {"tol", format_list(opt.tols)}, {"baselines", join_names(opt.baselines, " ")},
                               {"path", to_string(opt.path)}, {"equations", equations},
                               {"reps", std::to_string(opt.reps)}, {"reference", study.reference},
                               {"targets", "err_max " + format_number(target) + ", err_rel " + format_number(rel_target)},
                               {"err_max", "max_j |q(t_j) - q_ref(t_j)| (" + std::string(to_string(opt.norm)) +
                                               " norm) over the horizon; adaptive methods: at t = k h-max (dense output; gsl-rk8pd stepped to each)"},
                               {"err_rel", "max_k |q(t_k) - q_ref(t_k)| / A_k at t_k = k h-max, A_k = max |q_ref| over [t_k - " +
                                               format_number(opt.relative_window) + ", t_k] (t_k where A_k < " + format_number(relative_size_floor(sys, opt)) +
                                               " not counted: the reference's floor)"}});
  const std::string stem = sys.name + "_long_horizon";
  TsvWriter data(dir / (stem + ".tsv"), "long_horizon", params,
                 {"system", "method", "family", group, "T", "knob", "value", "steps", "err_max", "err_rel"});
  TsvWriter tim(dir / (stem + "_timings.tsv"), "long_horizon", params,
                {"system", "method", "family", group, "T", "knob", "value", "seconds_median", "seconds_min",
                 "seconds_max", "reps"});
  for (const auto& p : pts) {
    data.row(sys.name, p.method, p.family, format_number(p.group), format_number(p.horizon), p.knob, p.value, p.steps,
             p.errors[0], p.errors[1]);
    tim.row(sys.name, p.method, p.family, format_number(p.group), format_number(p.horizon), p.knob, p.value,
            p.time.median, p.time.min, p.time.max, p.time.reps);
  }
  data.commit();
  tim.commit();
  const std::vector<long_horizon::Measure> measures{{"err_max", "max error in q", target},
                                                    {"err_rel", "error relative to the size of the solution", rel_target}};
  long_horizon::summarise(pts, measures, group, "T", dir / (stem + "_summary.tsv"), "long_horizon", params);
  double longest = 0;
  for (const auto& r : runs) longest = std::max(longest, sys.horizon(r));
  long_horizon::draw_saved(dir, stem, group, "T", measures, format_number(longest),
                           sys.name + " over T = " + format_number(longest) + ": error in q against CPU time (median)");
  return 0;
}
