#pragma once
// What the long-horizon programs print and summarise from their saved TSVs (errors + timings, same row order):
// the CPU time each method needs to reach a target structural error, the best geometric scheme against the best
// adaptive method, the crossover horizon, and the slope of log(error) against log(CPU time).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "geomint/io.hpp"
#include "geomint/plots/figure.hpp"
#include "geomint/study.hpp"

namespace geomint::long_horizon {

struct Measure {
  std::string column, label;
  double target;  // the structural error the summary asks each method to reach
};

struct Table {
  const plots::TsvTable& d;   // errors: columns method, family, <group>, <horizon>, measures
  const plots::TsvTable& tt;  // timings, same rows: seconds_median
  std::string group, horizon;  // e.g. "alpha", "periods"

  std::vector<std::string> values(const std::string& col) const {
    std::vector<std::string> v;
    for (std::size_t r = 0; r < d.rows.size(); ++r)
      if (std::find(v.begin(), v.end(), d.text(r, col)) == v.end()) v.push_back(d.text(r, col));
    return v;
  }
  std::string family(const std::string& m) const {
    for (std::size_t r = 0; r < d.rows.size(); ++r)
      if (d.text(r, "method") == m) return d.text(r, "family");
    return "";
  }
  bool in(std::size_t r, const std::string& m, const std::string& g, const std::string& H) const {
    return d.text(r, "method") == m && d.text(r, group) == g && d.text(r, horizon) == H;
  }
  // The cheapest run of method m whose error is <= target (INFINITY: none).
  double time_to(const std::string& m, const std::string& g, const std::string& H, const Measure& M) const {
    double best = INFINITY;
    for (std::size_t r = 0; r < d.rows.size(); ++r)
      if (in(r, m, g, H) && d.number(r, M.column) <= M.target) best = std::min(best, tt.number(r, "seconds_median"));
    return best;
  }
  std::pair<double, double> best_geometric_adaptive(const std::string& g, const std::string& H, const Measure& M) const {
    double bg = INFINITY, ba = INFINITY;
    for (const auto& m : values("method")) {
      const double t = time_to(m, g, H, M);
      if (family(m) == "geometric") bg = std::min(bg, t);
      if (family(m) == "adaptive") ba = std::min(ba, t);
    }
    return {bg, ba};
  }
};

inline std::string ms_cell(double seconds) {
  if (!std::isfinite(seconds)) return "-";
  char b[32];
  std::snprintf(b, sizeof b, "%.3g", seconds * 1e3);
  return b;
}

// Prints the README table (markdown), the crossovers and the slopes; writes them to `summary_path`.
inline void summarise(const Table& T, const std::vector<Measure>& measures, const std::filesystem::path& summary_path,
                      const std::string& program, const Params& params) {
  const auto methods = T.values("method"), groups = T.values(T.group);
  auto horizons = T.values(T.horizon);
  std::sort(horizons.begin(), horizons.end(), [](const std::string& a, const std::string& b) { return std::stod(a) < std::stod(b); });
  TsvWriter sum(summary_path, program, params, {"kind", "measure", "target", T.group, T.horizon, "method", "value"});
  std::printf("\nCPU time (ms, median of repeats) to reach the target structural error; '-' = no run reached it\n");
  std::printf("| measure <= target | %s | %s |", T.group.c_str(), T.horizon.c_str());
  for (const auto& m : methods) std::printf(" %s |", m.c_str());
  std::printf(" best geometric / best adaptive |\n|---|---|---|");
  for (std::size_t i = 0; i <= methods.size(); ++i) std::printf("---|");
  std::printf("\n");
  for (const auto& M : measures)
    for (const auto& g : groups)
      for (const auto& H : horizons) {
        std::printf("| %s <= %s | %s | %s |", M.column.c_str(), format_number(M.target).c_str(), g.c_str(), H.c_str());
        for (const auto& m : methods) {
          const double t = T.time_to(m, g, H, M);
          sum.row("seconds_to_target", M.column, M.target, g, H, m, std::isfinite(t) ? t : std::nan(""));
          std::printf(" %s |", ms_cell(t).c_str());
        }
        const auto [bg, ba] = T.best_geometric_adaptive(g, H, M);
        const double ratio = std::isfinite(bg) && std::isfinite(ba) ? bg / ba : std::nan("");
        sum.row("geometric_over_adaptive", M.column, M.target, g, H, "-", std::isfinite(ratio) ? ratio : std::nan(""));
        if (std::isfinite(ratio)) {
          std::printf(" %.3g |\n", ratio);
        } else {
          std::printf(" %s |\n", std::isfinite(ba) ? "geometric never" : std::isfinite(bg) ? "adaptive never" : "neither");
        }
      }
  // Crossover: the shortest horizon run from which on (at it and every longer one) the best geometric scheme
  // reaches the target in less CPU time than the best adaptive method.
  std::printf("\nCrossover horizon (%s) from which a geometric scheme is cheaper at equal structural accuracy:\n", T.horizon.c_str());
  for (const auto& M : measures)
    for (const auto& g : groups) {
      std::string cross = "none";
      for (auto it = horizons.rbegin(); it != horizons.rend(); ++it) {
        const auto [bg, ba] = T.best_geometric_adaptive(g, *it, M);
        if (bg < ba) cross = *it; else break;
      }
      sum.row("crossover", M.column, M.target, g, "-", "-", cross == "none" ? std::nan("") : std::stod(cross));
      std::printf("  %-22s %s = %-6s %s\n", M.column.c_str(), T.group.c_str(), g.c_str(),
                  cross == "none" ? "none within the horizons run" : ("from " + cross).c_str());
    }
  // Slope of log(error) against log(CPU time) per method (points above 1e-15), at every horizon.
  std::printf("\nFitted slope d log(error) / d log(CPU time):\n");
  for (const auto& H : horizons)
    for (const auto& g : groups) {
      std::printf("  %s = %s, %s = %s\n  %-22s", T.horizon.c_str(), H.c_str(), T.group.c_str(), g.c_str(), "method");
      for (const auto& M : measures) std::printf(" %14.14s", M.column.c_str());
      std::printf("\n");
      for (const auto& m : methods) {
        std::printf("  %-22s", m.c_str());
        for (const auto& M : measures) {
          auto keep = [&](std::size_t i) { return T.in(i, m, g, H); };
          const auto fit = fit_order(T.tt.numbers("seconds_median", keep), T.d.numbers(M.column, keep), 1e-15);
          sum.row("slope_vs_cpu_time", M.column, M.target, g, H, m, fit.slope);
          std::printf(" %14s", std::isfinite(fit.slope) ? format_number(std::round(fit.slope * 100) / 100).c_str() : "-");
        }
        std::printf("\n");
      }
    }
  sum.commit();
}

// One panel per (group, measure) at one horizon: error against CPU time, one line per method.
inline void draw(const Table& T, const std::vector<Measure>& measures, const std::string& horizon_value,
                 const std::string& title, const std::filesystem::path& stem) {
  const auto methods = T.values("method"), groups = T.values(T.group);
  plots::Figure fig;
  fig.title = title;
  fig.rows = static_cast<int>(groups.size());
  fig.cols = static_cast<int>(measures.size());
  fig.width_in = 4.5 * fig.cols;
  fig.height_in = 4.2 * fig.rows;
  for (const auto& g : groups)
    for (const auto& M : measures) {
      plots::Panel p;
      p.setup = "set logscale xy\nset format x '10^{%L}'\nset format y '10^{%L}'\nset xlabel 'CPU time per run (s)'\n"
                "set ylabel '" + M.column + "' noenhanced\nset key bottom left font ',7'\nset title '" + M.label + ", " + T.group +
                " = " + g + "' font ',9' noenhanced\n";
      for (const auto& m : methods) {
        auto keep = [&](std::size_t i) { return T.in(i, m, g, horizon_value); };
        const auto xs = T.tt.numbers("seconds_median", keep), ys = T.d.numbers(M.column, keep);
        std::vector<double> x, y;
        for (std::size_t i = 0; i < xs.size(); ++i)
          if (std::isfinite(xs[i]) && std::isfinite(ys[i]) && ys[i] > 0) {
            x.push_back(xs[i]);
            y.push_back(ys[i]);
          }
        if (!x.empty()) p.series.push_back({x, y, m, plots::style_for(m, "linespoints")});
      }
      fig.panels.push_back(std::move(p));
    }
  fig.draw(stem);
}

}  // namespace geomint::long_horizon
