// Cost of one evaluation of the automatic modified equation (all of F_0..F_K, z', the multiplier and the
// modified constraint at a point), against the order K and the dimension n: what one right-hand side
// evaluation costs when the modified equation is integrated with Odeint. Timings only (not part of
// `make figures`: they differ from run to run).
//   modified_cost [--systems pendulum knife-edge foucault-rotation] [--schemes la contact la-trapezoid]
//                 (compositions too: --schemes la-trapezoid yoshida4:la-trapezoid)
//                 [--orders 0 1 2 3 4 5 6] [--seconds 0.2] [--reps 5] [--out out]
// Each cell: the median over `reps` repeats of (time of a loop of evaluations lasting >= seconds) / count,
// after a warm-up. Points: each system's initial position and (consistent) velocity.
// Writes out/modified_cost_timings.tsv (system, n, m, scheme, K, us_per_evaluation).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "geomint/budget.hpp"
#include "geomint/cli.hpp"
#include "geomint/error.hpp"
#include "geomint/generic/composition_families.hpp"
#include "geomint/io.hpp"
#include "geomint/modified/automatic_registry.hpp"
#include "geomint/registry.hpp"
#include "geomint/system_cli.hpp"

using namespace geomint;
using namespace geomint::modified;

int main(int argc, char** argv) {
  return guarded_main("modified_cost", [&] {
    std::vector<std::string> systems{"pendulum", "knife-edge", "foucault-rotation"}, schemes{"la", "contact", "la-trapezoid"};
    std::vector<int> orders{0, 1, 2, 3, 4, 5, 6};
    double seconds = 0.2;
    int reps = 5;
    Cli cli("modified_cost", "microseconds per evaluation of the automatic modified equation, against K and n");
    SystemsOptions sysopt(cli, argc, argv, systems, {});
    cli.options.add_options()(
        "schemes", po::value(&schemes)->multitoken()->default_value(schemes, "la contact la-trapezoid"), "schemes (skipped where not applicable)")(
        "orders", po::value(&orders)->multitoken()->default_value(orders, "0 1 2 3 4 5 6"), "orders K")(
        "seconds", po::value(&seconds)->default_value(seconds), "length of one timed loop")(
        "reps", po::value(&reps)->default_value(reps), "timed loops per cell (median)");
    if (!cli.parse(argc, argv)) return 0;
    systems = sysopt.names();
    require(std::isfinite(seconds) && seconds > 0 && seconds <= 10, "seconds must be in (0, 10]");
    require(reps >= 1 && reps <= 100, "reps must be in [1, 100]");
    for (int K : orders) require(K >= 0 && K <= registry_max_order, "orders must be in [0, " + std::to_string(registry_max_order) + "]");
    for (const auto& s : systems) sysopt.values(s);
    // A scheme is skipped on a system it does not apply to, but a name no listed system knows is a typo.
    // Compositions "<family>:<base>" (every system has them) cost their stage problem at every order.
    auto applies = [](const std::string& system, const std::string& x) {
      const auto& names = find_modified_system(system).schemes;
      if (std::find(names.begin(), names.end(), x) != names.end()) return true;
      if (!generic::is_composition_name(x)) return false;
      modified_scheme(find_system(system), x);  // InputError naming the families and bases
      return true;
    };
    std::vector<std::string> known;
    for (const auto& s : systems)
      for (const auto& name : find_modified_system(s).schemes)
        if (std::find(known.begin(), known.end(), name) == known.end()) known.push_back(name);
    for (const auto& x : schemes) {
      bool any = false;
      for (const auto& s : systems) any = applies(s, x) || any;
      require(any, "unknown scheme '" + x + "' for the systems named (their schemes: " + join_names(known, ", ") +
                       ", and compositions <family>:<base>)");
    }
    // every cell is `reps` timed loops of at least `seconds` (and one untimed loop first)
    plan_seconds(static_cast<double>(systems.size() * schemes.size() * orders.size()) * (reps + 1) * seconds,
                 "the timed loops (systems x schemes x orders x (reps + 1) x --seconds)");
    const auto dir = prepare_output_dir(cli.out);
    TsvWriter tsv(dir / "modified_cost_timings.tsv", "modified_cost",
                  [&] {
                    Params params = sysopt.header();
                    params.insert(params.end(), {{"seconds", format_number(seconds)}, {"reps", std::to_string(reps)}});
                    return params;
                  }(),
                  {"system", "n", "m", "scheme", "K", "us_per_evaluation"});
    std::printf("%-18s %-2s %-2s %-13s %-2s %12s\n", "system", "n", "m", "scheme", "K", "us/eval");
    for (const auto& s : systems) {
      const auto& info = find_system(s);
      const auto& ms = find_modified_system(s);
      const ParamValues pv = sysopt.values(s);
      const auto run = info.run(pv, info.schemes.front().name, 0.1, Path::generic, 1);
      std::vector<double> q(run.q.begin(), run.q.begin() + info.dof), v(run.v.begin(), run.v.begin() + info.dof);
      for (const auto& x : schemes) {
        if (!applies(s, x)) continue;
        for (int K : orders) {
          double sink = 0;
          auto loop = [&] {
            long count = 0;
            const auto t0 = std::chrono::steady_clock::now();
            double el = 0;
            do {
              sink += ms.at(pv, x, K, 0.0, q, v, 0.0, false).F.back();
              ++count;
              el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            } while (el < seconds);
            return el / static_cast<double>(count) * 1e6;
          };
          loop();  // warm-up
          std::vector<double> t;
          for (int r = 0; r < reps; ++r) t.push_back(loop());
          std::nth_element(t.begin(), t.begin() + reps / 2, t.end());
          const double us = t[static_cast<std::size_t>(reps / 2)];
          tsv.row(s, info.dof, info.constraints, x, K, us);
          std::printf("%-18s %-2d %-2d %-13s %-2d %12.1f%s\n", s.c_str(), info.dof, info.constraints, x.c_str(), K, us,
                      std::isfinite(sink) ? "" : " (non-finite)");
        }
      }
    }
    tsv.commit();
    return 0;
  });
}
