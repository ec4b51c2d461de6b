// What the modified equations cost as formulas: seconds to derive F_0..F_K (with z', the multiplier, the
// modified constraint, the modified Lagrangian and force, and their printed forms) and the size of what comes out
// (nodes of the expression trees), against K, for the pendulum, the knife edge and the Foucault pendulum, and
// systems defined in files (the Chaplygin sleigh), with `la` and `contact` — the engine with GiNaC coefficients
// (geomint/modified/symbolic.hpp), through the registry as modified_equation --formulas calls it. A constrained
// system is run in both forms: in the velocities q' as they are, and on the constraint (quasi-velocities,
// symbolic.hpp's constraint_chart), the form that keeps its formulas small.
//   bench_symbolic [--systems pendulum knife-edge foucault] [--system-files F...] [--schemes la contact]
//                  [--forms velocities constraint] [--max-order 4] [--repeat 3] [--budget 60] [--out out]
// Each run has the time budget, checked between orders (a run can overshoot it by one order); a run that
// exhausts it is recorded with the order it reached and stops the higher orders of that system, scheme and form.
// Median of --repeat runs (one run above 5 s), in wall seconds and in CPU seconds of this process (the machine is
// shared: the CPU time is what another load does not inflate). A timing program, run by `make bench`, never a
// test; the header records the load average.
// Writes out/bench_symbolic.tsv (columns system, scheme, form, K, reached, seconds, cpu_seconds, nodes, runs,
// stopped).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>
#include <vector>

#include "geomint/cli.hpp"
#include "geomint/error.hpp"
#include "geomint/formula/formula_registry.hpp"
#include "geomint/io.hpp"
#include "geomint/modified/automatic_registry.hpp"
#include "geomint/modified/formula_modified.hpp"
#include "geomint/registry.hpp"

using namespace geomint;
using namespace geomint::modified;

namespace {
double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}
}  // namespace

int main(int argc, char** argv) {
  return guarded_main("bench_symbolic", [&] {
    std::vector<std::string> systems{"pendulum", "knife-edge", "foucault"}, schemes{"la", "contact"}, files,
        forms{"velocities", "constraint"};
    int max_order = 4, repeat = 3;
    double budget = 60;
    Cli cli("bench_symbolic", "seconds to derive the modified equations as formulas, against the order K");
    cli.options.add_options()("systems", po::value(&systems)->multitoken()->default_value(systems, "pendulum knife-edge foucault"),
                              "systems (registry names)")(
        "system-files", po::value(&files)->multitoken(), "systems defined by formulas (.geomint files), after --systems")(
        "forms", po::value(&forms)->multitoken()->default_value(forms, "velocities constraint"),
        "velocities: the formulas in q' as it is; constraint: on a nonholonomic constraint, in quasi-velocities "
        "(a system without one runs in the first form only)")(
        "schemes", po::value(&schemes)->multitoken()->default_value(schemes, "la contact"), "schemes")(
        "max-order", po::value(&max_order)->default_value(max_order), "largest K (0..6)")(
        "repeat", po::value(&repeat)->default_value(repeat), "runs per cell (median)")(
        "budget", po::value(&budget)->default_value(budget), "time budget of one run, seconds");
    if (!cli.parse(argc, argv)) return 0;
    require(max_order >= 0 && max_order <= registry_max_order, "--max-order must be in [0, " + std::to_string(registry_max_order) + "]");
    require(repeat >= 1 && repeat <= 100, "--repeat must be in [1, 100]");
    require(std::isfinite(budget) && budget > 0, "--budget must be a positive number of seconds");
    for (const auto& f : forms) require(f == "velocities" || f == "constraint", "--forms: velocities or constraint, got '" + f + "'");
    require(!forms.empty(), "--forms: give at least one");
    // every system: its name, its modified equations (a file's alive to the end), its scheme table
    struct Entry {
      std::string name;
      std::shared_ptr<const ModifiedSystem> file;
      const ModifiedSystem* ms;
      const SystemInfo* info;
    };
    std::vector<Entry> entries;
    std::vector<std::shared_ptr<const SystemInfo>> file_infos;
    for (const auto& s : systems) entries.push_back({s, nullptr, &find_modified_system(s), &find_system(s)});
    for (const auto& path : files) {
      const auto model = formula::load_system_file(path);
      auto ms = formula_modified_system(model);
      file_infos.push_back(formula::formula_system_info(model));
      entries.push_back({ms->name, ms, ms.get(), file_infos.back().get()});
    }
    for (const auto& e : entries)
      for (const auto& g : schemes) e.info->scheme(g);

    struct Row {
      std::string system, scheme, form;
      int K, reached, runs;
      double seconds, cpu;
      std::size_t nodes;
      bool stopped;
    };
    std::vector<Row> rows;
    double load[3] = {0, 0, 0};
    getloadavg(load, 3);
    std::printf("%-18s %-8s %-10s %3s %8s %12s %12s %9s %5s\n", "system", "scheme", "form", "K", "reached", "seconds",
                "cpu seconds", "nodes", "runs");
    std::vector<std::string> charts;
    for (const auto& e : entries) {
      const auto& ms = *e.ms;
      const bool chartable = ms.constraints > 0 && !ms.holonomic;
      for (const auto& g : schemes)
       for (const auto& form : forms) {
        const bool on_constraint = form == "constraint";
        if (on_constraint && !chartable) continue;
        bool over = false;
        for (int K = 0; K <= max_order && !over; ++K) {
          std::vector<double> times, cpus;
          ModifiedFormulas f;
          for (int r = 0; r < repeat; ++r) {
            const auto t0 = std::chrono::steady_clock::now();
            const double c0 = cpu_seconds();
            f = ms.formulas({}, g, K, budget, on_constraint);
            cpus.push_back(cpu_seconds() - c0);
            times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
            if (f.stopped || times.back() > 5) break;
          }
          std::sort(times.begin(), times.end());
          std::sort(cpus.begin(), cpus.end());
          const double med = times[times.size() / 2], cpu = cpus[cpus.size() / 2];
          rows.push_back({e.name, g, form, K, f.K, static_cast<int>(times.size()), med, cpu, f.size, f.stopped});
          std::printf("%-18s %-8s %-10s %3d %8d %12.4f %12.4f %9zu %5zu%s\n", e.name.c_str(), g.c_str(), form.c_str(), K,
                      f.K, med, cpu, f.size, times.size(), f.stopped ? "  stopped by the budget" : "");
          if (!f.chart.empty() && std::find(charts.begin(), charts.end(), e.name + ": " + f.chart) == charts.end())
            charts.push_back(e.name + ": " + f.chart);
          std::fflush(stdout);
          over = f.stopped;
        }
      }
    }

    const auto dir = prepare_output_dir(cli.out);
    char ld[64];
    std::snprintf(ld, sizeof ld, "%.2f %.2f %.2f", load[0], load[1], load[2]);
    TsvWriter tsv(dir / "bench_symbolic.tsv", "bench_symbolic",
                  {{"systems", join_names(systems)},
                   {"system_files", join_names(files)},
                   {"forms", join_names(forms)},
                   {"charts", [&] {
                      std::string c;
                      for (const auto& x : charts) c += (c.empty() ? "" : "; ") + x;
                      return c;
                    }()},
                   {"schemes", join_names(schemes)},
                   {"max_order", std::to_string(max_order)},
                   {"repeat", std::to_string(repeat)},
                   {"budget_s", format_number(budget)},
                   {"load_average_at_start", ld},
                   {"what", "wall and CPU seconds to derive F_0..F_K and the other quantities as printed formulas (medians), "
                            "and the nodes of their expression trees in all"}},
                  {"system", "scheme", "form", "K", "reached", "seconds", "cpu_seconds", "nodes", "runs", "stopped"});
    for (const auto& r : rows)
      tsv.row(r.system, r.scheme, r.form, r.K, r.reached, r.seconds, r.cpu, static_cast<long>(r.nodes), r.runs, r.stopped ? "yes" : "no");
    tsv.commit();
    return 0;
  });
}
