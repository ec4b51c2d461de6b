#pragma once
// How the long-horizon studies report their study (a set of WorkPoints, work_precision.hpp): the summary
// (summarise_work: the CPU time each method needs to reach a target structural error, the best geometric scheme
// against the best adaptive method, the crossover horizon, the slope of log(error) against log(CPU time)) written
// and printed, and the figure drawn from the saved TSVs.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "geomint/io.hpp"
#include "geomint/plots/figure.hpp"
#include "geomint/long_horizon_study.hpp"
#include "geomint/study.hpp"
#include "geomint/work_precision.hpp"

namespace geomint::long_horizon {

using Measure = WorkMeasure;

// The saved tables, for the figures (drawn from the files, as every figure is).
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
  bool in(std::size_t r, const std::string& m, const std::string& g, const std::string& H) const {
    return d.text(r, "method") == m && d.text(r, group) == g && d.text(r, horizon) == H;
  }
};

inline std::string ms_cell(double seconds, double scale = 1e3) {
  if (!std::isfinite(seconds)) return "-";
  char b[32];
  std::snprintf(b, sizeof b, "%.3g", seconds * scale);
  return b;
}

// The study's summary (summarise_work): written to `summary_path`, and printed as the table of docs/speed-accuracy.md (markdown),
// the crossovers and the slopes. The cost is the points' CPU time, printed in ms; a study that charges another cost
// (evaluations of the equations) puts it in the points' times and names it, with the factor it is printed at.
inline void summarise(const std::vector<WorkPoint>& points, const std::vector<Measure>& measures,
                      const std::string& group, const std::string& horizon, const std::filesystem::path& summary_path,
                      const std::string& program, const Params& params,
                      const std::string& cost = "CPU time (ms, median of repeats)", double scale = 1e3) {
  const auto rows = summarise_work(points, measures);
  const auto methods = work_methods(points);
  TsvWriter sum(summary_path, program, params, {"kind", "measure", "target", group, horizon, "method", "value"});
  for (const auto& r : rows)
    sum.row(r.kind, r.measure, r.target, format_number(r.group), r.kind == "crossover" ? "-" : format_number(r.horizon),
            r.method, r.value);
  sum.commit();
  std::printf("\n%s to reach the target structural error; '-' = no run reached it\n", cost.c_str());
  std::printf("| measure <= target | %s | %s |", group.c_str(), horizon.c_str());
  for (const auto& m : methods) std::printf(" %s |", m.c_str());
  std::printf(" best geometric / best adaptive |\n|---|---|---|");
  for (std::size_t i = 0; i <= methods.size(); ++i) std::printf("---|");
  std::printf("\n");
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto& r = rows[i];
    if (r.kind == "seconds_to_target") {
      if (r.method == methods.front())
        std::printf("| %s <= %s | %s | %s |", r.measure.c_str(), format_number(r.target).c_str(),
                    format_number(r.group).c_str(), format_number(r.horizon).c_str());
      std::printf(" %s |", ms_cell(r.value, scale).c_str());
    } else if (r.kind == "geometric_over_adaptive") {
      if (std::isfinite(r.value)) {
        std::printf(" %.3g |\n", r.value);
      } else {  // which family reached the target, if any
        bool geo = false, ada = false;
        for (std::size_t k = i - methods.size(); k < i; ++k) {
          const bool reached = std::isfinite(rows[k].value);
          for (const auto& p : points)
            if (p.method == rows[k].method) {
              geo = geo || (reached && p.family == "geometric");
              ada = ada || (reached && p.family == "adaptive");
              break;
            }
        }
        std::printf(" %s |\n", ada ? "geometric never" : geo ? "adaptive never" : "neither");
      }
    }
  }
  std::printf("\nCrossover horizon (%s) from which a geometric scheme is cheaper at equal structural accuracy:\n", horizon.c_str());
  for (const auto& r : rows)
    if (r.kind == "crossover")
      std::printf("  %-22s %s = %-6s %s\n", r.measure.c_str(), group.c_str(), format_number(r.group).c_str(),
                  std::isnan(r.value) ? "none within the horizons run" : ("from " + format_number(r.value)).c_str());
  std::printf("\nFitted slope d log(error) / d log(cost):\n");
  const std::size_t M = measures.size();
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto& r = rows[i];
    if (r.kind != "slope_vs_cpu_time") continue;
    if (r.method == methods.front() && r.measure == measures.front().column) {
      std::printf("  %s = %s, %s = %s\n  %-22s", horizon.c_str(), format_number(r.horizon).c_str(), group.c_str(),
                  format_number(r.group).c_str(), "method");
      for (const auto& m : measures) std::printf(" %14.14s", m.column.c_str());
      std::printf("\n");
    }
    if (r.measure == measures.front().column) std::printf("  %-22s", r.method.c_str());
    std::printf(" %14s", std::isfinite(r.value) ? format_number(std::round(r.value * 100) / 100).c_str() : "-");
    if (r.measure == measures[M - 1].column) std::printf("\n");
  }
}

// One panel: the error `M` against CPU time, a line per method, over the rows in(row, method) selects.
template <class In>
plots::Panel cost_panel(const plots::TsvTable& d, const plots::TsvTable& tt, const Measure& M,
                        const std::vector<std::string>& methods, const std::string& title, In&& in) {
  plots::Panel p;
  p.setup = "set logscale xy\nset format x '10^{%L}'\nset format y '10^{%L}'\nset xlabel 'CPU time per run (s)'\n"
            "set ylabel '" + M.column + "' noenhanced\nset key bottom left font ',7'\nset title '" + title +
            "' font ',9' noenhanced\n";
  for (const auto& m : methods) {
    auto keep = [&](std::size_t i) { return in(i, m); };
    const auto xs = tt.numbers("seconds_median", keep), ys = d.numbers(M.column, keep);
    std::vector<double> x, y;
    for (std::size_t i = 0; i < xs.size(); ++i)
      if (std::isfinite(xs[i]) && std::isfinite(ys[i]) && ys[i] > 0) {
        x.push_back(xs[i]);
        y.push_back(ys[i]);
      }
    if (!x.empty()) p.series.push_back({x, y, m, plots::style_for(m, "linespoints")});
  }
  return p;
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
    for (const auto& M : measures)
      fig.panels.push_back(cost_panel(T.d, T.tt, M, methods, M.label + ", " + T.group + " = " + g,
                                      [&](std::size_t i, const std::string& m) { return T.in(i, m, g, horizon_value); }));
  fig.draw(stem);
}

// The figure of a study from the two files it has just saved, <stem>.tsv and <stem>_timings.tsv in `dir`,
// at its longest horizon: out/<stem>.{png,pdf}.
inline void draw_saved(const std::filesystem::path& dir, const std::string& stem, const std::string& group,
                       const std::string& horizon, const std::vector<Measure>& measures, const std::string& horizon_value,
                       const std::string& title) {
  const auto d = plots::read_tsv(dir / (stem + ".tsv"));
  const auto tt = plots::read_tsv(dir / (stem + "_timings.tsv"));
  draw(Table{d, tt, group, horizon}, measures, horizon_value, title, dir / stem);
}

// What a study of long_horizon_study (studies/long_horizon_study.hpp) writes: <stem>.tsv (method, family, <group>,
// T, knob, value, steps, evals, the measures: the same bits for the same command), <stem>_timings.tsv, the summary
// <stem>_summary.tsv, and the figure at the longest horizon drawn from the saved files. `group` names the parameter
// the points are grouped by (its value at every point: `group_value`).
inline void write_study(const std::filesystem::path& dir, const std::string& stem, const Params& params,
                        const LongHorizonResult& result, const std::vector<Measure>& measures, const std::string& group,
                        double group_value, const std::string& title) {
  std::vector<WorkPoint> pts = result.points;
  for (auto& p : pts) p.group = group_value;
  std::vector<std::string> head{"method", "family", group, "T", "knob", "value", "steps", "evals"};
  for (const auto& m : measures) head.push_back(m.column);
  TsvWriter data(dir / (stem + ".tsv"), "long_horizon", params, head);
  TsvWriter tim(dir / (stem + "_timings.tsv"), "long_horizon", params,
                {"method", "family", group, "T", "knob", "value", "seconds_median", "seconds_min", "seconds_max", "reps"});
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const auto& p = pts[i];
    std::vector<std::string> row{p.method, p.family, format_cell(p.group), format_cell(p.horizon), p.knob,
                                 format_cell(p.value), std::to_string(p.steps), format_cell(result.evaluations[i])};
    for (double e : p.errors) row.push_back(format_cell(e));
    data.write_row(row);
    tim.row(p.method, p.family, p.group, p.horizon, p.knob, p.value, p.time.median, p.time.min, p.time.max, p.time.reps);
  }
  data.commit();
  tim.commit();
  summarise(pts, measures, group, "T", dir / (stem + "_summary.tsv"), "long_horizon", params);
  draw_saved(dir, stem, group, "T", measures, format_number(work_horizons(pts).back()), title);
}

}  // namespace geomint::long_horizon
