// Benchmark (make bench): the cost of a time transformation dt = g dsigma (docs/time-transformation.md). A step
// of the time-transformed system (n + 1 coordinates, the extended Lagrangian t' L(t, q, q'/t') plus the penalty,
// built from the same formulas) against a step of the untransformed system, same scheme, same system file, same
// step count, both through the registry's generic path. Target: transformed / untransformed <= 1.5.
//   bench_time_transform [--systems docs/systems] [--reps 7] [--out out]
// Writes out/bench_time_transform.tsv.
#include <cstdio>

#include "geomint/cli.hpp"
#include "geomint/error.hpp"
#include "geomint/formula/description.hpp"
#include "geomint/formula/formula_registry.hpp"
#include "geomint/formula/model.hpp"
#include "geomint/io.hpp"
#include "geomint/timing.hpp"

using namespace geomint;

int main(int argc, char** argv) {
  return guarded_main("bench_time_transform", [&] {
    int reps = 7;
    std::string dir = "docs/systems";
    Cli cli("bench_time_transform", "ns per generic step: a time-transformed system against the same system untransformed");
    cli.options.add_options()("reps", po::value(&reps)->default_value(reps), "timed repetitions (median reported)")(
        "systems", po::value(&dir)->default_value(dir), "folder of the formula files (pendulum, duffing, knife-edge)");
    if (!cli.parse(argc, argv)) return 0;
    require(reps >= 3 && reps <= 1000, "reps must be in [3, 1000]");
    struct Case {
      std::string file, monitor;
    };
    const std::vector<Case> cases{{"pendulum", "1/sqrt(1 + v1*v1)"},
                                  {"duffing", "1/(1 + q1*q1)"},
                                  {"knife-edge", "1/(1 + v1*v1 + v2*v2 + q1*q1)"}};
    const std::vector<std::string> schemes{"la", "la-midpoint", "contact"};
    const double h = 0.01, T = 100;
    const long N = 10000;
    const auto out = prepare_output_dir(cli.out);
    const Params params{{"reps", std::to_string(reps)}, {"h", format_number(h)}, {"steps", std::to_string(N)}, {"systems", dir}};
    TsvWriter tsv(out / "bench_time_transform.tsv", "bench_time_transform", params,
                  {"system", "monitor", "scheme", "ns_step", "ns_step_transformed", "ratio", "newton", "newton_transformed"});
    std::printf("median of %d runs of %ld steps (h = %g), ns per step:\n%-12s %-12s %10s %12s %7s %8s %8s\n", reps, N, h,
                "system", "scheme", "plain", "transformed", "ratio", "newton", "newton_t");
    for (const auto& c : cases) {
      formula::SystemDescription d = formula::read_system_file(dir + "/" + c.file + ".geomint");
      const auto plain = formula::formula_system_info(formula::compile_model(d));
      d.time_transform = formula::formula_text(c.monitor, "monitor");
      const auto tt = formula::formula_system_info(formula::compile_model(d));
      const ParamValues pv{{"T", T}};
      for (const auto& s : schemes) {
        const double a = plain->time_run(pv, s, h, Path::generic, reps).median * 1e9 / double(N);
        const double b = tt->time_run(pv, s, h, Path::generic, reps).median * 1e9 / double(N);
        const double na = plain->run(pv, s, h, Path::generic, N).newton_mean, nb = tt->run(pv, s, h, Path::generic, N).newton_mean;
        tsv.row(c.file, c.monitor, s, a, b, b / a, na, nb);
        std::printf("%-12s %-12s %10.1f %12.1f %7.2f %8.2f %8.2f\n", c.file.c_str(), s.c_str(), a, b, b / a, na, nb);
      }
    }
    tsv.commit();
    return 0;
  });
}
