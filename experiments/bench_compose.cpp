// Benchmark (make bench): what a composition step costs against the steps of its stages taken alone. For each
// system, symmetric base scheme and family: ns per composition step of size h, and ns per step of the base scheme
// alone at each stage's step |w_i| h (forward from the same initial data, so in the same regime; the sign of a
// stage's step does not change its equations' cost), summed over the stages. The ratio is the composition's
// overhead: its stage bookkeeping and its predictor against the lone stepper's (target <= 1.1). Newton updates per
// stage step (composition) and per step (alone) say where a difference comes from. Timed with Google Benchmark
// (medians over interleaved repetitions); every ratio is between medians of this run.
//   bench_compose [--steps 1000] [--reps 9] [--out out] [--benchmark_filter=...]
// Writes out/bench_compose.tsv (every case) and out/bench_compose_ratios.tsv (composition / sum of its stages).
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "bench_table.hpp"
#include "geomint/cli.hpp"
#include "geomint/error.hpp"
#include "geomint/generic/composition_families.hpp"
#include "geomint/io.hpp"
#include "geomint/registry.hpp"

using namespace geomint;

namespace {

struct Case {
  std::string system, base;
  double h;
};

std::string lone_name(const Case& c, double step) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "alone %s %s h=%.6g", c.system.c_str(), c.base.c_str(), step);
  return buf;
}

}  // namespace

int main(int argc, char** argv) {
  return guarded_main("bench_compose", [&] {
    auto args = bench::Table::split_args(argc, argv);
    long N = 1000;
    int reps = 9;
    Cli cli("bench_compose", "ns per composition step against the sum of its stages' steps alone");
    cli.options.add_options()("steps", po::value(&N)->default_value(N), "steps per timed call")(
        "reps", po::value(&reps)->default_value(reps), "timed repetitions (median reported)");
    if (!cli.parse(argc, args.data())) return 0;
    require(N >= 100 && N <= 10000000, "steps must be in [100, 1e7]");
    require(reps >= 3 && reps <= 1000, "reps must be in [3, 1000]");
    const auto dir = prepare_output_dir(cli.out);
    bench::Table table(reps, 0.05);

    // nonlinear unconstrained (LA and contact), the perturbed Kepler problem, a nonholonomic system
    const std::vector<Case> cases{{"pendulum", "la-trapezoid", 0.1},   {"pendulum", "contact-trapezoid", 0.1},
                                  {"kepler", "contact-trapezoid", 0.05}, {"kepler", "la-midpoint", 0.05},
                                  {"knife-edge", "la-trapezoid", 0.05},  {"knife-edge", "contact-trapezoid", 0.05}};
    const auto& families = generic::composition_families();
    std::map<std::string, double> updates;  // Newton updates per call, by case name
    for (const auto& c : cases) {
      const SystemInfo* sys = &find_system(c.system);
      std::map<double, bool> lone_done;
      for (const auto& fam : families) {
        const std::string name = generic::composition_name(fam.name, c.base);
        const std::string cname = "compose " + c.system + " " + name + " h=" + show(c.h);
        table.add(c.system, cname, double(N), [sys, name, c, N] { sys->composition_steps({}, name, c.h, N); });
        updates[cname] = double(sys->composition_steps({}, name, c.h, N));
        for (const long double w : fam.weights) {
          const double step = std::abs(static_cast<double>(w * static_cast<long double>(c.h)));
          if (lone_done[step]) continue;
          lone_done[step] = true;
          const std::string lname = lone_name(c, step);
          table.add(c.system, lname, double(N), [sys, c, step, N] { sys->base_steps({}, c.base, step, N); });
          updates[lname] = double(sys->base_steps({}, c.base, step, N));
        }
      }
    }

    std::printf("Google Benchmark, medians of %d interleaved repetitions (ns per step):\n", reps);
    table.run();
    const Params params{{"steps", std::to_string(N)},
                        {"reps", std::to_string(reps)},
                        {"stages alone", "the base scheme's stepper at |w_i| h, N steps forward from the initial data"}};
    table.write_tsv(dir / "bench_compose.tsv", "bench_compose", params);
    TsvWriter ratios(dir / "bench_compose_ratios.tsv", "bench_compose", params,
                     {"system", "base", "family", "stages", "h", "ns_composition", "ns_stages_alone", "ratio",
                      "newton_per_stage_composition", "newton_per_step_alone"});
    std::printf("\n%-11s %-18s %-10s %6s %12s %12s %7s %10s %10s\n", "system", "base", "family", "stages", "composition",
                "stages alone", "ratio", "Newton/st", "alone");
    for (const auto& c : cases)
      for (const auto& fam : families) {
        const std::string cname = "compose " + c.system + " " + generic::composition_name(fam.name, c.base) + " h=" + show(c.h);
        double sum = 0, lone_updates = 0;
        for (const long double w : fam.weights) {
          const std::string lname = lone_name(c, std::abs(static_cast<double>(w * static_cast<long double>(c.h))));
          sum += table.ns(lname);
          lone_updates += updates[lname] / double(N);
        }
        const double comp_ns = table.ns(cname), s = double(fam.stages());
        const double per_stage = updates[cname] / double(N) / s;
        ratios.row(c.system, c.base, fam.name, fam.stages(), c.h, comp_ns, sum, comp_ns / sum, per_stage, lone_updates / s);
        std::printf("%-11s %-18s %-10s %6d %12.1f %12.1f %7.3f %10.3f %10.3f\n", c.system.c_str(), c.base.c_str(),
                    fam.name.c_str(), fam.stages(), comp_ns, sum, comp_ns / sum, per_stage, lone_updates / s);
      }
    ratios.commit();
    return 0;
  });
}
