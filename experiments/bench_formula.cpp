// Benchmark (make bench): a system written as formulas (docs/systems/*.geomint, evaluated by the tape
// interpreter of core/include/geomint/formula/) against the same system written as a header, ns per generic
// Newton step of the `la` and `contact` schemes, on the pendulum (n = 1) and the knife edge (n = 3, m = 1).
// Before timing anything it checks that both step to the same bits (the formula files are written as the
// headers associate). Timed with Google Benchmark (medians over interleaved repetitions); every ratio is
// between medians of this run. Target: formula / header <= 3.
//   bench_formula [--systems docs/systems] [--reps 9] [--out out] [--benchmark_filter=...]
// Then the knife-edge file through its registry entry, as the programs run it: the shape the build compiled against
// the same shape compiled at run time (formula/jit.hpp, the path of the shapes the build does not compile), ns per
// step of whole generic runs, after checking that both give the same bits. Target: run time / compiled <= 3.
// Writes out/bench_formula.tsv (every case), out/bench_formula_ratios.tsv (formula / header) and
// out/bench_formula_run_time.tsv (compiled at run time / compiled with the build).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <tuple>

#include "bench_table.hpp"
#include "geomint/cli.hpp"
#include "geomint/error.hpp"
#include "geomint/formula/formula_registry.hpp"
#include "geomint/formula/formula_system.hpp"
#include "geomint/generic/stepper.hpp"
#include "geomint/io.hpp"
#include "geomint/systems/knife_edge.hpp"
#include "geomint/systems/pendulum.hpp"
#include "geomint/timing.hpp"

using namespace geomint;

namespace {

// N generic steps from the system's initial data; the final state.
template <class Sys, class G>
typename generic::Stepper<Sys, G>::State run_steps(const Sys& sys, double h, long N) {
  generic::Stepper<Sys, G> st(sys, h);
  st.start(sys.template initial_position<double>(), sys.template initial_velocity<double>());
  for (long j = 0; j < N; ++j) st.step();
  do_not_optimize(st.state().q(0));
  return st.state();
}

struct Pair {
  std::string system, scheme, header_case, formula_case;
};

}  // namespace

int main(int argc, char** argv) {
  return guarded_main("bench_formula", [&] {
    auto args = bench::Table::split_args(argc, argv);
    int reps = 9;
    std::string dir = "docs/systems";
    Cli cli("bench_formula", "ns per generic step: systems written as formulas against the same systems as headers");
    cli.options.add_options()("reps", po::value(&reps)->default_value(reps), "timed repetitions (median reported)")(
        "systems", po::value(&dir)->default_value(dir), "folder of the formula files (pendulum.geomint, knife-edge.geomint)");
    if (!cli.parse(argc, args.data())) return 0;
    require(reps >= 3 && reps <= 1000, "reps must be in [3, 1000]");
    // the formula files before anything is written
    const formula::FormulaSystem<1, 0> pendulum(formula::load_system_file(dir + "/pendulum.geomint"));
    const formula::FormulaSystem<3, 1> knife_edge(formula::load_system_file(dir + "/knife-edge.geomint"));
    const auto out = prepare_output_dir(cli.out);
    bench::Table table(reps, 0.05);
    std::vector<Pair> pairs;
    const double h = 0.1;
    const long N = 20000;

    auto compare = [&](const auto& header, const auto& formula) {
      using H = std::decay_t<decltype(header)>;
      using F = std::decay_t<decltype(formula)>;
      using Schemes = std::tuple<generic::LaLeft, generic::ContactLeft>;
      std::apply([&](auto... g) {
        (([&] {
           using G = decltype(g);
           const std::string scheme = generic::scheme_name<G>(), name = H::name;
           // the same bits first: a formula file that drifted from its header is not timed
           const auto a = run_steps<H, G>(header, h, 2000), b = run_steps<F, G>(formula, h, 2000);
           require(a.q == b.q && a.p == b.p && a.z == b.z,
                   name + " " + scheme + ": the formula system does not step to the header's bits (" + dir + ")");
           Pair p{name, scheme, "header " + name + " " + scheme, "formula " + name + " " + scheme};
           table.add(name, p.header_case, double(N), [=] { run_steps<H, G>(header, h, N); });
           table.add(name, p.formula_case, double(N), [=] { run_steps<F, G>(formula, h, N); });
           pairs.push_back(p);
         }()),
         ...);
      }, Schemes{});
    };
    compare(systems::Pendulum{}, pendulum);
    compare(systems::KnifeEdge{}, knife_edge);

    // The registry entry's runs, compiled with the build and at run time (loaded, or compiled now on a first use).
    const auto model = knife_edge.model_ptr();
    const auto built = formula::formula_system_info(model);
    const auto load_start = std::chrono::steady_clock::now();
    const auto loaded = formula::formula_system_info(model, true);
    const double load_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - load_start).count();
    const double h_run = 0.01;
    const long run_steps_count = step_count(h_run, 20.0), keep = run_steps_count;  // the horizon T = 20 of the file
    std::vector<Pair> entry_pairs;
    for (const char* scheme : {"la", "contact", "la-midpoint"}) {
      const Run a = built->run({}, scheme, h_run, Path::generic, 1), b = loaded->run({}, scheme, h_run, Path::generic, 1);
      require(a.q == b.q && a.p == b.p && a.z == b.z && a.lambda == b.lambda,
              std::string("knife-edge ") + scheme + ": the shape compiled at run time does not step to the build's bits");
      Pair p{"knife-edge", scheme, std::string("entry compiled knife-edge ") + scheme,
             std::string("entry run-time knife-edge ") + scheme};
      table.add("knife-edge entry", p.header_case, double(run_steps_count),
                [=] { do_not_optimize(built->run({}, scheme, h_run, Path::generic, keep).steps); });
      table.add("knife-edge entry", p.formula_case, double(run_steps_count),
                [=] { do_not_optimize(loaded->run({}, scheme, h_run, Path::generic, keep).steps); });
      entry_pairs.push_back(p);
    }

    std::printf("Google Benchmark, medians of %d interleaved repetitions (ns per step):\n", reps);
    table.run();
    const Params params{{"reps", std::to_string(reps)}, {"h", format_number(h)}, {"steps", std::to_string(N)},
                        {"systems", dir}};
    table.write_tsv(out / "bench_formula.tsv", "bench_formula", params);
    TsvWriter ratios(out / "bench_formula_ratios.tsv", "bench_formula", params,
                     {"system", "scheme", "ns_header", "ns_formula", "ratio"});
    std::printf("\n%-12s %-10s %10s %10s %8s\n", "system", "scheme", "header", "formula", "ratio");
    for (const auto& p : pairs) {
      const double a = table.ns(p.header_case), b = table.ns(p.formula_case);
      ratios.row(p.system, p.scheme, a, b, b / a);
      std::printf("%-12s %-10s %10.1f %10.1f %8.2f\n", p.system.c_str(), p.scheme.c_str(), a, b, b / a);
    }
    ratios.commit();
    TsvWriter run_time(out / "bench_formula_run_time.tsv", "bench_formula",
                       {{"reps", std::to_string(reps)}, {"h", format_number(h_run)}, {"steps", std::to_string(run_steps_count)},
                        {"systems", dir}, {"load_seconds", format_number(load_seconds)}},
                       {"system", "scheme", "ns_compiled", "ns_run_time", "ratio"});
    std::printf("\nregistry entry, whole runs (h = %g, %ld steps): the shape compiled with the build and at run time "
                "(loaded in %.3g s)\n%-12s %-12s %10s %10s %8s\n",
                h_run, run_steps_count, load_seconds, "system", "scheme", "compiled", "run time", "ratio");
    for (const auto& p : entry_pairs) {
      const double a = table.ns(p.header_case), b = table.ns(p.formula_case);
      run_time.row(p.system, p.scheme, a, b, b / a);
      std::printf("%-12s %-12s %10.1f %10.1f %8.2f\n", p.system.c_str(), p.scheme.c_str(), a, b, b / a);
    }
    run_time.commit();
    return 0;
  });
}
