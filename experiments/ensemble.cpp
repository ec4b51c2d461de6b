// Ensembles of any registered system: many runs of one scheme from perturbed parameters (initial data or
// constants), on every core and, under mpirun, on every rank; each run has the bits of that run alone.
//   ensemble --system knife-edge --scheme la [--perturb theta0=1e-3 u0=1e-3] [--runs 1000] [--h 0.1]
//            [--path fast|generic] [--seed 1] [--threads <cores>] [system parameters...] [--out out]
// Run k moves every perturbed parameter p to p + spread u, u uniform in [-1, 1) from (seed, k) alone
// (generic_ensemble.hpp); by default every initial datum moves by 1e-3. Writes
// out/ensemble_<system>_<scheme>_runs.tsv (one row per run: its perturbed values, its state at T, energy,
// max |Phi_d|, Newton updates, or where it failed), out/ensemble_<system>_<scheme>_summary.tsv
// (mean, standard deviation, min and max of every final quantity over the runs that reached T) and the figure
// ensemble_<system>_<scheme>.{png,pdf}. Prints runs per second (not written: the files are the same bits on
// every machine).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <tuple>

#include "geomint/budget.hpp"
#include "geomint/cli.hpp"
#include "geomint/error.hpp"
#include "geomint/generic_ensemble.hpp"
#include "geomint/io.hpp"
#include "geomint/parallel.hpp"
#include "geomint/plots/figure.hpp"
#include "geomint/progress.hpp"
#include "geomint/record.hpp"
#include "geomint/sweep.hpp"
#include "geomint/system_cli.hpp"
#include "geomint/step_cost.hpp"

using namespace geomint;

int main(int argc, char** argv) {
  return guarded_main("ensemble", [&] {
    Cli cli("ensemble", "many runs of one system and scheme from perturbed parameters, on every core and rank");
    SystemOptions sysopt(cli, argc, argv, "knife-edge", false);
    std::string scheme = "la", path_name = "fast";
    std::vector<std::string> perturb_text;
    double h = 0.1;
    long runs = 1000;
    unsigned long long seed = 1;
    unsigned threads = default_threads();
    cli.options.add_options()("scheme", po::value(&scheme)->default_value(scheme), "scheme (see --help --system X)")(
        "perturb", po::value(&perturb_text)->multitoken(),
        "parameters to perturb, name=spread (e.g. theta0=1e-3 u0=1e-3): run k moves each by spread u, u uniform "
        "in [-1, 1) from (seed, k). Default: every initial datum (a parameter described 'initial ...') by 1e-3")(
        "runs", po::value(&runs)->default_value(runs), "runs in the ensemble")(
        "h", po::value(&h)->default_value(h, "0.1"), "step size (must divide T)")(
        "path", po::value(&path_name)->default_value(path_name),
        "fast: the closed form where the system has one; generic: the Newton step built from L")(
        "seed", po::value(&seed)->default_value(seed), "seed of the perturbations")(
        "threads", po::value(&threads)->default_value(threads), "worker threads (the files do not depend on it)");
    if (!cli.parse(argc, argv)) return 0;

    // Validate everything before writing anything (every rank does, identically).
    const SystemInfo& sys = sysopt.system();
    EnsembleSpec spec;
    spec.base = sysopt.values();
    for (const auto& t : perturb_text) spec.perturb.push_back(parse_perturbation(t));
    if (perturb_text.empty())
      for (const auto& p : sys.params)
        if (p.doc.rfind("initial", 0) == 0) spec.perturb.push_back({p.name, 1e-3});
    spec.scheme = sys.scheme(scheme).name;
    spec.h = h;
    spec.path = parse_path(path_name);
    spec.runs = runs;
    spec.seed = seed;
    require(threads >= 1 && threads <= 256, "threads must be in [1, 256]");
    plan_ensemble(sys, spec);
    const SchemeInfo& sc = sys.scheme(spec.scheme);
    sysopt.warn_contact({spec.base}, {spec.scheme});
    const double T = sys.horizon(spec.base);
    const long N = step_count(h, T);
    const bool closed_form = spec.path == Path::fast && !sc.fast_path.empty();
    validate_ensemble(sys, spec);
    const auto dir = prepare_output_dir(cli.out, OtherRanks::compute);

    // Under mpirun every rank runs an equal share of the runs and rank 0 gathers them in run order.
    const Sweep& sweep = Sweep::world();
    Progress progress("ensemble", "runs", sweep.root());
    const auto t0 = std::chrono::steady_clock::now();
    const auto results = sweep.map<EnsembleRun>(
        static_cast<std::size_t>(runs), {},
        [&](std::size_t first, std::size_t last) {
          return run_ensemble(sys, spec, static_cast<long>(first), static_cast<long>(last), threads,
                              progress.active() ? std::function<void(std::size_t, std::size_t)>(
                                                      [&](std::size_t d, std::size_t n) { progress.update(d, n); })
                                                : nullptr);
        },
        [](const EnsembleRun& r) { return pack(r); }, unpack_ensemble_run);
    progress.done();
    if (!sweep.root()) return 0;  // rank 0 writes everything
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    const long failed = std::count_if(results.begin(), results.end(), [](const EnsembleRun& r) { return !r.ok(); });
    if (failed == runs)
      throw NumericalFailure(0, "every run", "no run of the ensemble reached T; run 0: " + results.front().failure);

    const int n = sys.dof;
    auto comp = [&](const std::string& base, int i) { return n == 1 ? base : base + std::to_string(i + 1); };
    // the final quantities, one column each, in the runs table and the summary
    std::vector<std::string> quantities;
    for (int i = 0; i < n; ++i) quantities.push_back(comp("q", i));
    for (int i = 0; i < n; ++i) quantities.push_back(comp("v", i));
    for (const char* c : {"z", "energy", "max_phi_d", "newton_mean"}) quantities.push_back(c);
    auto value_of = [&](const EnsembleRun& r, std::size_t c) {
      const auto nn = static_cast<std::size_t>(n);
      if (c < nn) return r.q[c];
      if (c < 2 * nn) return r.v[c - nn];
      const double rest[] = {r.z, r.energy, r.max_phi_d, r.newton_mean};
      return rest[c - 2 * nn];
    };

    Params params = sysopt.header();
    std::string perturbed;
    for (const auto& p : spec.perturb) perturbed += (perturbed.empty() ? "" : " ") + p.name + "=" + format_number(p.spread);
    params.insert(params.end(), {{"scheme", sc.name + ": " + sc.description()},
                                 {"path", closed_form ? "closed form " + sc.fast_path : "generic"},
                                 {"h", format_number(h)},
                                 {"steps", std::to_string(N)},
                                 {"runs", std::to_string(runs)},
                                 {"perturb", perturbed + " (p + spread u, u uniform in [-1, 1) from seed and run)"},
                                 {"seed", std::to_string(seed)},
                                 {"failed", std::to_string(failed)}});
    std::string stem = "ensemble_" + sys.name + "_" + sc.name;
    std::replace(stem.begin(), stem.end(), ':', '_');  // a composition "<family>:<base>": no colon in a file name

    {
      std::vector<std::string> cols{"run"};
      for (const auto& p : spec.perturb) cols.push_back(p.name);
      cols.push_back("energy0");
      cols.insert(cols.end(), quantities.begin(), quantities.end());
      cols.push_back("status");
      TsvWriter tsv(dir / (stem + "_runs.tsv"), "ensemble", params, cols);
      for (const auto& r : results) {
        std::vector<std::string> cells{std::to_string(r.k)};
        for (double v : r.values) cells.push_back(format_cell(v));
        cells.push_back(format_cell(r.energy0));
        for (std::size_t c = 0; c < quantities.size(); ++c)
          cells.push_back(r.ok() ? format_cell(value_of(r, c)) : "nan");
        std::string status = r.ok() ? "ok" : one_line(r.failure);
        std::replace(status.begin(), status.end(), '\t', ' ');
        cells.push_back(status);
        tsv.write_row(cells);
      }
      tsv.commit();
    }
    {
      TsvWriter tsv(dir / (stem + "_summary.tsv"), "ensemble", params,
                    {"quantity", "runs", "mean", "std", "min", "max"});
      for (std::size_t c = 0; c < quantities.size(); ++c) {
        std::vector<double> x;
        for (const auto& r : results)
          if (r.ok()) x.push_back(value_of(r, c));
        auto moments = [&x](double scale) {  // of x / scale, times scale
          double mean = 0, var = 0;
          for (double v : x) mean += v / scale;
          mean /= static_cast<double>(x.size());
          for (double v : x) var += (v / scale - mean) * (v / scale - mean);
          const double sd = x.size() > 1 ? std::sqrt(var / static_cast<double>(x.size() - 1)) : 0.0;
          return std::make_pair(scale * mean, scale * sd);
        };
        auto [mean, sd] = moments(1);
        if (!std::isfinite(mean) || !std::isfinite(sd)) {
          // finite values near overflow (a run close to blowing up) whose squares overflow: scaled by the largest
          double scale = 0;
          for (double v : x) scale = std::max(scale, std::abs(v));
          if (scale > 0 && std::isfinite(scale)) std::tie(mean, sd) = moments(scale);
        }
        const auto [lo, hi] = std::minmax_element(x.begin(), x.end());
        tsv.row(quantities[c], static_cast<long>(x.size()), mean, sd, *lo, *hi);
      }
      tsv.commit();
    }

    std::printf("%s, %s (%s), h = %g, %ld runs of %ld steps on %u thread%s x %d rank%s: %ld failed; "
                "%.4g runs/s, %.4g steps/s\n",
                sys.name.c_str(), sc.name.c_str(), closed_form ? ("closed form " + sc.fast_path).c_str() : "generic", h,
                runs, N, threads, threads == 1 ? "" : "s", sweep.size(), sweep.size() == 1 ? "" : "s", failed,
                static_cast<double>(runs) / seconds, static_cast<double>(runs) * static_cast<double>(N) / seconds);
    if (failed > 0) {  // one line for all of them: the status column names each
      const auto f = std::find_if(results.begin(), results.end(), [](const EnsembleRun& r) { return !r.ok(); });
      report_missing("run " + std::to_string(f->k) + " (" + std::to_string(failed) + " of " + std::to_string(runs) +
                         " runs failed, each named in the status column)",
                     f->failure);
    }

    // The figure, from the saved table: the final energy against the first perturbed parameter, and the final
    // positions (q1, q2) where there are two.
    const auto t = plots::read_tsv(dir / (stem + "_runs.tsv"));
    auto ok = [&](std::size_t r) { return t.text(r, "status") == "ok"; };
    const std::string& p0 = spec.perturb.front().name;
    plots::Figure fig;
    fig.title = sys.name + ", " + sc.name + ", h = " + format_number(h) + ", " + std::to_string(runs) + " runs, t = " +
                format_number(T);
    fig.cols = n >= 2 ? 2 : 1;
    fig.width_in = 4.4 * fig.cols;
    fig.height_in = 4;
    plots::Panel pe;
    pe.setup = "set xlabel '" + p0 + "'\nset ylabel 'E(T)'\nset key off\nset title 'final energy'\n";
    pe.series.push_back({t.numbers(p0, ok), t.numbers("energy", ok), "E(T)", "points pt 7 ps 0.3"});
    fig.panels.push_back(pe);
    if (n >= 2) {
      plots::Panel pq;
      pq.setup = "set xlabel 'q1(T)'\nset ylabel 'q2(T)'\nset key off\nset title 'final positions'\n";
      pq.series.push_back({t.numbers("q1", ok), t.numbers("q2", ok), "q(T)", "points pt 7 ps 0.3"});
      fig.panels.push_back(pq);
    }
    fig.draw(dir / stem);
    return 0;
  });
}
