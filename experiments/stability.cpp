// Where the schemes of a linear system fail (the oscillator's by default): maps over (h, alpha) of the one-step
// map's spectral radius, the discrete decay rate and frequency relative to the exact ones, and the regions where a
// scheme is unstable, oscillates when it should not (or the reverse), or flips sign at every step.
// The analytic boundaries (from the closed-form trace and determinant) are drawn on the maps.
//   stability [--n 180] [--out out]   (also under mpirun -n N: the ranks share the grid cells)
// Writes out/oscillator_stability.tsv (one row per scheme and grid cell), out/oscillator_stability_boundaries.tsv and
// out/oscillator_stability_{regions,decay,frequency}.{png,pdf}.
// Any other linear system of the registry (e.g. --system coupled-oscillators) gets the same maps over (h, alpha)
// for every scheme built from it: the one-step matrix of the generic step, classified by its eigenvalues against
// the continuous generator's (out/<system>_stability.tsv and out/<system>_stability_{regions,decay,frequency}).
#include <cmath>
#include <cstdio>

#include "geomint/cli.hpp"
#include "geomint/error.hpp"
#include "geomint/io.hpp"
#include "geomint/modified/stability.hpp"
#include "geomint/plots/figure.hpp"
#include "geomint/sweep.hpp"
#include "geomint/system_cli.hpp"
#include "text_columns.hpp"

using namespace geomint;
using namespace geomint::modified;

int generic_stability(const Cli& cli, const SystemOptions& sysopt, std::vector<std::string> names, int n, double h_min,
                      double h_max, double a_min, double a_max);

int main(int argc, char** argv) {
  return guarded_main("stability", [&] {
    int n = 180;  // 180 x 180 per scheme: 4x the cells of the first version, in less time (binary heat maps)
    double h_min = 1e-2, h_max = 10, a_min = 1e-3, a_max = 10;
    std::vector<std::string> names{"la", "la-printed", "contact", "la-midpoint", "contact-sym", "leapfrog", "conformal-strang"};
    Cli cli("stability",
            "stability and fidelity maps of a linear system's schemes over (h, alpha).\n"
            "On the oscillator (the default system, with the analytic boundaries of its closed forms) alpha is an axis\n"
            "and no other parameter enters a one-step map: the maps take none of its parameters below. Another linear\n"
            "system (--system X) takes its own.");
    SystemOptions sysopt(cli, argc, argv, "oscillator", false);
    bool names_given = false;
    cli.options.add_options()("n", po::value(&n)->default_value(n), "grid points per axis (log-spaced)")(
        "h-min", po::value(&h_min)->default_value(h_min), "smallest h")("h-max", po::value(&h_max)->default_value(h_max),
                                                                          "largest h")(
        "alpha-min", po::value(&a_min)->default_value(a_min), "smallest alpha")(
        "alpha-max", po::value(&a_max)->default_value(a_max), "largest alpha")(
        "schemes", po::value(&names)->multitoken()->default_value(names, "la la-printed contact la-midpoint contact-sym leapfrog conformal-strang"),
        "schemes");
    if (!cli.parse(argc, argv)) return 0;
    for (int i = 1; i < argc; ++i) names_given = names_given || std::string(argv[i]).rfind("--schemes", 0) == 0;
    // the built-in oscillator itself, not a system that is only named so (a formula system may take any name)
    if (&sysopt.system() != &find_system("oscillator"))
      return generic_stability(cli, sysopt, names_given ? names : std::vector<std::string>{}, n, h_min, h_max, a_min, a_max);
    require(sysopt.values().empty(), "the oscillator maps take no system parameters (alpha is an axis of the map)");
    require(n >= 4 && n <= 1000, "n must be in [4, 1000]");
    require_positive(h_min, "h-min");
    require_positive(a_min, "alpha-min");
    require(h_max > h_min && std::isfinite(h_max), "h-max must be finite and exceed h-min");
    require(a_max > a_min && std::isfinite(a_max), "alpha-max must be finite and exceed alpha-min");
    for (const auto& s : names) all_orders_by_name(s, 0.1, 0.1);  // unknown names fail here
    const auto dir = prepare_output_dir(cli.out, OtherRanks::compute);
    const Sweep& sweep = Sweep::world();

    std::vector<double> hs, as;
    for (int i = 0; i < n; ++i) {
      hs.push_back(h_min * std::pow(h_max / h_min, i / (n - 1.0)));
      as.push_back(a_min * std::pow(a_max / a_min, i / (n - 1.0)));
    }
    const Params params{{"n", std::to_string(n)}, {"h", format_number(h_min) + ".." + format_number(h_max) + " log"},
                        {"alpha", format_number(a_min) + ".." + format_number(a_max) + " log"},
                        {"exact", "q'' + alpha q' + q = 0: decay rate alpha/2, frequency sqrt(1 - alpha^2/4)"}};
    // One cell per (scheme, alpha, h), in that order; under mpirun the ranks share the cells, rank 0 writes.
    struct Cell {
      double spectral_radius;
      int region;
      double decay_ratio, freq_ratio;
    };
    const std::size_t per = static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
    const auto cells = sweep.map<Cell>(
        names.size() * per, {},
        [&](std::size_t first, std::size_t last) {
          std::vector<Cell> out;
          for (std::size_t k = first; k < last; ++k) {
            const double a = as[k % per / static_cast<std::size_t>(n)], h = hs[k % static_cast<std::size_t>(n)];
            const auto m = all_orders_by_name(names[k / per], h, a);
            // decay ratio a_h / alpha; frequency ratio where both oscillate
            const double dr = m.valid ? m.a / a : missing_value;
            const double w = a < 2 && m.valid && m.oscillating ? std::sqrt(m.b - m.a * m.a / 4) / std::sqrt(1 - a * a / 4)
                                                             : missing_value;
            out.push_back({m.spectral_radius, static_cast<int>(classify(m, a)), dr, w});
          }
          return out;
        });
    if (!sweep.root()) return 0;
    TsvWriter tsv(dir / "oscillator_stability.tsv", "stability", params,
                  {"scheme", "h", "alpha", "spectral_radius", "region", "decay_ratio", "freq_ratio"});
    const int width = name_width(names, 12);
    std::printf("%-*s %10s %10s %10s %10s   (share of the grid)\n", width, "scheme", "faithful", "wrong-char", "sign-flip",
                "unstable");
    for (std::size_t si = 0; si < names.size(); ++si) {
      const auto& s = names[si];
      int count[4] = {0, 0, 0, 0};
      for (std::size_t k = si * per; k < (si + 1) * per; ++k) {
        const Cell& c = cells[k];
        ++count[c.region];
        tsv.row(s, hs[k % static_cast<std::size_t>(n)], as[k % per / static_cast<std::size_t>(n)], c.spectral_radius,
                c.region, c.decay_ratio, c.freq_ratio);
      }
      const double tot = static_cast<double>(n) * n;
      std::printf("%-*s %10.3f %10.3f %10.3f %10.3f\n", width, s.c_str(), count[0] / tot, count[1] / tot, count[2] / tot,
                  count[3] / tot);
    }
    tsv.commit();
    TsvWriter bt(dir / "oscillator_stability_boundaries.tsv", "stability", params, {"scheme", "h", "alpha", "below", "above"});
    std::vector<double> fine_a;
    for (int i = 0; i < 400; ++i) fine_a.push_back(a_min * std::pow(a_max / a_min, i / 399.0));
    for (const auto& s : names)
      for (const auto& b : analytic_boundaries(s, fine_a, h_min, h_max)) bt.row(s, b.h, b.alpha, region_name(b.below), region_name(b.above));
    bt.commit();

    const auto t = plots::read_tsv(dir / "oscillator_stability.tsv");
    const auto bd = plots::read_tsv(dir / "oscillator_stability_boundaries.tsv");
    struct Map {
      const char* stem;
      const char* column;
      const char* title;
      const char* palette;
    };
    const Map maps[] = {
        {"regions", "region", "regions: 0 faithful, 1 wrong oscillation character, 2 sign flip, 3 unstable",
         "set cbrange [-0.5:3.5]\nset palette maxcolors 4 defined (0 '#d9f0d3', 1 '#fdb863', 2 '#b2abd2', 3 '#d7191c')\n"
         "set cbtics ('faithful' 0, 'wrong char.' 1, 'sign flip' 2, 'unstable' 3)\n"},
        {"decay", "decay_ratio", "discrete decay rate / exact decay rate (a_h / alpha)",
         "set cbrange [0:2]\nset palette defined (0 '#2166ac', 1 '#f7f7f7', 2 '#b2182b')\n"},
        {"frequency", "freq_ratio", "discrete frequency / exact frequency",
         "set cbrange [0.5:1.5]\nset palette defined (0 '#2166ac', 1 '#f7f7f7', 2 '#b2182b')\n"},
    };
    for (const auto& mp : maps) {
      plots::Figure fig;
      fig.title = std::string("Oscillator schemes over (h, alpha): ") + mp.title;
      fig.cols = 4;
      fig.rows = static_cast<int>((names.size() + 3) / 4);
      fig.width_in = 17;
      fig.height_in = 4.2 * fig.rows;
      for (const auto& s : names) {
        plots::Panel p;
        p.setup = std::string("set xlabel 'log_{10} h'\nset ylabel 'log_{10} alpha'\nset title '") + s +
                  "'\nset key bottom left font ',7'\nset xrange [" + format_number(std::log10(h_min)) + ":" +
                  format_number(std::log10(h_max)) + "]\nset yrange [" + format_number(std::log10(a_min)) + ":" +
                  format_number(std::log10(a_max)) + "]\n" + mp.palette;
        auto keep = [&](size_t i) { return t.text(i, "scheme") == s; };
        auto lx = t.numbers("h", keep), ly = t.numbers("alpha", keep);
        for (auto& v : lx) v = std::log10(v);
        for (auto& v : ly) v = std::log10(v);
        plots::Series img{lx, ly, "", "image", t.numbers(mp.column, keep)};
        p.series.push_back(std::move(img));
        auto bkeep = [&](size_t i) { return bd.text(i, "scheme") == s; };
        auto bx = bd.numbers("h", bkeep), by = bd.numbers("alpha", bkeep);
        for (auto& v : bx) v = std::log10(v);
        for (auto& v : by) v = std::log10(v);
        if (!bx.empty()) p.series.push_back({bx, by, "analytic boundaries", "points pt 7 ps 0.15 lc rgb 'black'"});
        fig.panels.push_back(std::move(p));
      }
      fig.draw(dir / (std::string("oscillator_stability_") + mp.stem));
    }
    return 0;
  });
}

// Any linear system: the generic one-step matrices over (h, alpha), a map per scheme.
int generic_stability(const Cli& cli, const SystemOptions& sysopt, std::vector<std::string> names, int n, double h_min,
                      double h_max, double a_min, double a_max) {
  const SystemInfo& sys = sysopt.system();
  // A system file's linearity is not derived (the registry knows it of its own systems only): say that, rather than
  // call a linear system file nonlinear.
  require(sys.linear && sys.constraints == 0,
          "stability maps need a linear system without constraints; '" + sys.name +
              "' is not known to be one (the registry's linear systems: oscillator, forced-oscillator, "
              "coupled-oscillators; a system file's linearity is not derived)");
  bool has_alpha = false;
  for (const auto& p : sys.params) has_alpha = has_alpha || p.name == "alpha";
  require(has_alpha, "system '" + sys.name + "' has no parameter alpha to map");
  require(n >= 4 && n <= 1000, "n must be in [4, 1000]");
  require_positive(h_min, "h-min");
  require_positive(a_min, "alpha-min");
  require(h_max > h_min && std::isfinite(h_max), "h-max must be finite and exceed h-min");
  require(a_max > a_min && std::isfinite(a_max), "alpha-max must be finite and exceed alpha-min");
  names = sysopt.schemes(names);
  const ParamValues base = sysopt.values();
  for (const auto& [k, v] : base) require(k != "alpha", "alpha is an axis of the map: give --alpha-min/--alpha-max");
  const auto dir = prepare_output_dir(cli.out, OtherRanks::compute);
  const Sweep& sweep = Sweep::world();
  const int N = 2 * sys.dof;
  std::vector<double> hs, as;
  for (int i = 0; i < n; ++i) {
    hs.push_back(h_min * std::pow(h_max / h_min, i / (n - 1.0)));
    as.push_back(a_min * std::pow(a_max / a_min, i / (n - 1.0)));
  }
  struct Cell {
    double spectral_radius;
    int region;
    double decay_ratio, freq_low, freq_high;
  };
  const std::size_t per = static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
  auto with_alpha = [&](double a) {
    ParamValues pv = base;
    pv.emplace_back("alpha", a);
    return pv;
  };
  const auto cells = sweep.map<Cell>(
      names.size() * per, {},
      [&](std::size_t first, std::size_t last) {
        std::vector<Cell> out;
        for (std::size_t k = first; k < last; ++k) {
          const double a = as[k % per / static_cast<std::size_t>(n)], h = hs[k % static_cast<std::size_t>(n)];
          const ParamValues pv = with_alpha(a);
          Cell c{missing_value, static_cast<int>(Region::unstable), missing_value, missing_value, missing_value};
          try {
            const auto r = classify_linear_map(sys.one_step_matrix(pv, names[k / per], h, Path::generic), sys.continuous_matrix(pv), N, h);
            c = {r.spectral_radius, static_cast<int>(r.region), r.decay_ratio, r.freq_low, r.freq_high};
          } catch (const NumericalFailure&) {
            // a step that cannot be solved (a singular Newton matrix) is a missing value, classified unstable
          }
          out.push_back(c);
        }
        return out;
      });
  if (!sweep.root()) return 0;
  Params params = sysopt.header();
  params.insert(params.end(), {{"n", std::to_string(n)}, {"h", format_number(h_min) + ".." + format_number(h_max) + " log"},
                               {"alpha", format_number(a_min) + ".." + format_number(a_max) + " log"},
                               {"classification", "eigenvalues of the one-step matrix on (q, p) against exp(h C)"}});
  const std::string stem = sys.name + "_stability";
  TsvWriter tsv(dir / (stem + ".tsv"), "stability", params,
                {"scheme", "h", "alpha", "spectral_radius", "region", "decay_ratio", "freq_low", "freq_high"});
  const int width = name_width(names, 18);
  std::printf("%s: %-*s %10s %10s %10s %10s   (share of the grid)\n", sys.name.c_str(), width, "scheme", "faithful",
              "wrong-char", "sign-flip", "unstable");
  for (std::size_t si = 0; si < names.size(); ++si) {
    int count[4] = {0, 0, 0, 0};
    for (std::size_t k = si * per; k < (si + 1) * per; ++k) {
      const Cell& c = cells[k];
      ++count[c.region];
      tsv.row(names[si], hs[k % static_cast<std::size_t>(n)], as[k % per / static_cast<std::size_t>(n)], c.spectral_radius,
              c.region, c.decay_ratio, c.freq_low, c.freq_high);
    }
    const double tot = static_cast<double>(n) * n;
    std::printf("%s: %-*s %10.3f %10.3f %10.3f %10.3f\n", sys.name.c_str(), width, names[si].c_str(), count[0] / tot,
                count[1] / tot, count[2] / tot, count[3] / tot);
  }
  tsv.commit();
  const auto t = plots::read_tsv(dir / (stem + ".tsv"));
  struct Map {
    const char *stem, *column, *title, *palette;
  };
  const Map maps[] = {
      {"regions", "region", "regions: 0 faithful, 1 wrong oscillation character, 2 sign flip, 3 unstable",
       "set cbrange [-0.5:3.5]\nset palette maxcolors 4 defined (0 '#d9f0d3', 1 '#fdb863', 2 '#b2abd2', 3 '#d7191c')\n"
       "set cbtics ('faithful' 0, 'wrong char.' 1, 'sign flip' 2, 'unstable' 3)\n"},
      {"decay", "decay_ratio", "discrete / exact rate of phase-space contraction",
       "set cbrange [0:2]\nset palette defined (0 '#2166ac', 1 '#f7f7f7', 2 '#b2182b')\n"},
      {"frequency", "freq_high", "discrete / exact frequency of the fastest mode",
       "set cbrange [0.5:1.5]\nset palette defined (0 '#2166ac', 1 '#f7f7f7', 2 '#b2182b')\n"},
  };
  for (const auto& mp : maps) {
    plots::Figure fig;
    fig.title = sys.name + " over (h, alpha): " + mp.title;
    fig.cols = static_cast<int>(std::min<std::size_t>(names.size(), 4));
    fig.rows = static_cast<int>((names.size() + 3) / 4);
    fig.width_in = 4.25 * fig.cols;
    fig.height_in = 4.2 * fig.rows;
    for (const auto& s : names) {
      plots::Panel p;
      p.setup = std::string("unset key\nset xlabel 'log_{10} h'\nset ylabel 'log_{10} alpha'\nset title '") + s + "'\nset xrange [" +
                format_number(std::log10(h_min)) + ":" + format_number(std::log10(h_max)) + "]\nset yrange [" +
                format_number(std::log10(a_min)) + ":" + format_number(std::log10(a_max)) + "]\n" + mp.palette;
      auto keep = [&](size_t i) { return t.text(i, "scheme") == s; };
      auto lx = t.numbers("h", keep), ly = t.numbers("alpha", keep);
      for (auto& v : lx) v = std::log10(v);
      for (auto& v : ly) v = std::log10(v);
      p.series.push_back(plots::Series{lx, ly, "", "image", t.numbers(mp.column, keep)});
      fig.panels.push_back(std::move(p));
    }
    fig.draw(dir / (stem + "_" + mp.stem));
  }
  return 0;
}
