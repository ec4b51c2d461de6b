// Integrates any registered system with any of its schemes and writes the trajectory, the energy and the
// constraint residuals (the discrete one the scheme imposes, and the continuous one at the discrete state).
//   integrate --system pendulum --scheme contact [--h 0.1] [--path fast|generic] [--every 1] [--alpha 0.2 ...]
// Writes out/<system>_<scheme>.tsv (one row per kept step) and out/<system>_<scheme>.{png,pdf} (a composition
// <family>:<base> as <family>_<base>).
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "geomint/budget.hpp"
#include "geomint/cli.hpp"
#include "geomint/error.hpp"
#include "geomint/io.hpp"
#include "geomint/plots/figure.hpp"
#include "geomint/system_cli.hpp"
#include "geomint/run_checks.hpp"
#include "geomint/step_cost.hpp"

using namespace geomint;

int main(int argc, char** argv) {
  return guarded_main("integrate", [&] {
    Cli cli("integrate", "integrate a system with one scheme: trajectory, energy, constraint residual");
    SystemOptions sysopt(cli, argc, argv, "pendulum", false);
    std::string scheme = "la", path_name = "fast";
    double h = 0.1;
    long every = 1;
    cli.options.add_options()("scheme", po::value(&scheme)->default_value(scheme), "scheme (see --help --system X)")(
        "h", po::value(&h)->default_value(h, "0.1"), "step size (must divide T)")(
        "path", po::value(&path_name)->default_value(path_name),
        "fast: the closed form where the system has one; generic: the Newton step built from L")(
        "every", po::value(&every)->default_value(every), "keep every k-th step in the table (and the last)");
    if (!cli.parse(argc, argv)) return 0;
    const SystemInfo& sys = sysopt.system();
    const ParamValues pv = sysopt.values();
    const SchemeInfo& sc = sys.scheme(scheme);
    const Path path = parse_path(path_name);
    require_positive(h, "h");
    const double T = sys.horizon(pv);
    plan_run(sys, sc.name, path, h, T, every);
    sysopt.warn_contact({pv}, {sc.name});
    const long N = step_count(h, T);
    require(N / every <= 2000000, "the table would have " + std::to_string(N / every) +
                                      " rows (limit 2e6): raise --every");
    const auto dir = prepare_output_dir(cli.out);

    const Run run = sys.run(pv, scheme, h, path, every);
    require_finite_run(run, "system " + sys.name + ", scheme " + sc.name + " (" + to_string(path) + "), h = " + show(h));
    const int n = run.n, m = run.m;
    Params params = sysopt.header();
    params.insert(params.end(), {{"scheme", sc.name + ": " + sc.description()},
                                 {"h", format_number(h)},
                                 {"steps", std::to_string(N)},
                                 {"path", to_string(path) + std::string(path == Path::fast && sc.fast_path.empty()
                                                                            ? " (no closed form: generic)" : "")},
                                 {"newton_mean", format_number(run.newton_mean)},
                                 {"max_phi_d", format_number(run.max_phi_d)}});
    std::vector<std::string> cols{"j", "t"};
    auto comp = [&](const std::string& base, int k, int count) {
      return count == 1 ? base : base + std::to_string(k + 1);
    };
    for (int i = 0; i < n; ++i) cols.push_back(comp("q", i, n));
    for (int i = 0; i < n; ++i) cols.push_back(comp("p", i, n));
    for (int i = 0; i < n; ++i) cols.push_back(comp("v", i, n));
    cols.push_back("z");
    for (int c = 0; c < m; ++c) cols.push_back(comp("lambda", c, m));
    for (const char* c : {"energy", "phi_d", "phi", "newton"}) cols.push_back(c);
    std::string stem = sys.name + "_" + sc.name;
    std::replace(stem.begin(), stem.end(), ':', '_');  // a composition "<family>:<base>": no colon in a file name
    TsvWriter tsv(dir / (stem + ".tsv"), "integrate", params, cols);
    for (std::size_t r = 0; r < run.t.size(); ++r) {
      std::vector<std::string> cells{std::to_string(run.j[r]), format_cell(run.t[r])};
      for (int i = 0; i < n; ++i) cells.push_back(format_cell(run.q[r * n + i]));
      for (int i = 0; i < n; ++i) cells.push_back(format_cell(run.p[r * n + i]));
      for (int i = 0; i < n; ++i) cells.push_back(format_cell(run.v[r * n + i]));
      cells.push_back(format_cell(run.z[r]));
      for (int c = 0; c < m; ++c) cells.push_back(format_cell(run.lambda[r * m + c]));
      cells.push_back(format_cell(run.energy[r]));
      cells.push_back(format_cell(run.phi_d[r]));
      cells.push_back(format_cell(run.phi[r]));
      cells.push_back(std::to_string(run.newton[r]));
      tsv.write_row(cells);
    }
    tsv.commit();
    char newton_buf[32];
    std::snprintf(newton_buf, sizeof newton_buf, "%.3f", run.newton_mean);
    const std::string newton = run.newton_mean < 0 ? "- (closed form)" : newton_buf;
    std::printf("%s, %s (%s), h = %g, %ld steps: E(0) = %.10g, E(T) = %.10g, max |Phi_d| = %.3g, "
                "Newton iterations per step %s\n",
                sys.name.c_str(), sc.name.c_str(),
                path == Path::fast && !sc.fast_path.empty() ? ("closed form " + sc.fast_path).c_str() : "generic", h, N, run.energy.front(), run.energy.back(),
                run.max_phi_d, newton.c_str());

    // The figure, from the saved table.
    const auto t = plots::read_tsv(dir / (stem + ".tsv"));
    auto all = [](std::size_t) { return true; };
    const std::string xrange = "set xrange [0:" + format_number(T) + "]\n";  // also when few rows are kept
    plots::Figure fig;
    fig.title = sys.name + ", " + sc.name + ", h = " + format_number(h);
    fig.cols = m > 0 ? 3 : 2;
    fig.width_in = 4.4 * fig.cols;
    fig.height_in = 4;
    plots::Panel pq;
    pq.setup = xrange + "set xlabel 't'\nset ylabel 'q'\nset key top right\nset title 'positions'\n";
    for (int i = 0; i < n; ++i)
      pq.series.push_back({t.numbers("t", all), t.numbers(comp("q", i, n), all), comp("q", i, n), "lines lw 1.2"});
    fig.panels.push_back(pq);
    plots::Panel pe;
    pe.setup = xrange + "set xlabel 't'\nset ylabel 'E'\nset key top right\nset title 'energy E(q_j, v_j), v_j from p_j'\n";
    pe.series.push_back({t.numbers("t", all), t.numbers("energy", all), "energy", plots::style_for(sc.name)});
    fig.panels.push_back(pe);
    if (m > 0) {
      plots::Panel pc;
      pc.setup = xrange + "set logscale y\nset format y '10^{%L}'\nset xlabel 't'\nset ylabel 'max_c |residual|'\n"
                 "set key bottom right\nset title 'constraint residuals'\n";
      auto positive = [&](std::size_t r, const char* col) { return t.number(r, col) > 0; };
      pc.series.push_back({t.numbers("t", [&](std::size_t r) { return positive(r, "phi_d"); }),
                           t.numbers("phi_d", [&](std::size_t r) { return positive(r, "phi_d"); }),
                           "discrete, imposed (Phi_d)", "points pt 7 ps 0.3"});
      pc.series.push_back({t.numbers("t", [&](std::size_t r) { return positive(r, "phi"); }),
                           t.numbers("phi", [&](std::size_t r) { return positive(r, "phi"); }),
                           "continuous Phi(q_j, v_j)", "lines lw 1.2"});
      fig.panels.push_back(pc);
    }
    fig.draw(dir / stem);
    return 0;
  });
}
