#include "geomint/work_precision.hpp"

#include <algorithm>

#include "geomint/study.hpp"

namespace geomint {

namespace {
// Doubles compared as keys: the same value, or both NaN (no group, one horizon).
bool same_key(double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); }
bool in(const WorkPoint& p, const std::string& method, double group, double horizon) {
  return p.method == method && same_key(p.group, group) && same_key(p.horizon, horizon);
}
std::string family_of(const std::vector<WorkPoint>& points, const std::string& method) {
  for (const auto& p : points)
    if (p.method == method) return p.family;
  return "";
}
std::pair<double, double> best_geometric_adaptive(const std::vector<WorkPoint>& points, double group, double horizon,
                                                  std::size_t measure, double target) {
  double bg = INFINITY, ba = INFINITY;
  for (const auto& m : work_methods(points)) {
    const double t = time_to_target(points, m, group, horizon, measure, target);
    const std::string f = family_of(points, m);
    if (f == "geometric") bg = std::min(bg, t);
    if (f == "adaptive") ba = std::min(ba, t);
  }
  return {bg, ba};
}
}  // namespace

std::vector<std::string> work_methods(const std::vector<WorkPoint>& points) {
  std::vector<std::string> v;
  for (const auto& p : points)
    if (std::find(v.begin(), v.end(), p.method) == v.end()) v.push_back(p.method);
  return v;
}

std::vector<double> work_groups(const std::vector<WorkPoint>& points) {
  std::vector<double> v;
  for (const auto& p : points)
    if (std::find_if(v.begin(), v.end(), [&](double g) { return same_key(g, p.group); }) == v.end()) v.push_back(p.group);
  return v;
}

std::vector<double> work_horizons(const std::vector<WorkPoint>& points) {
  std::vector<double> v;
  for (const auto& p : points)
    if (std::find_if(v.begin(), v.end(), [&](double h) { return same_key(h, p.horizon); }) == v.end())
      v.push_back(p.horizon);
  std::sort(v.begin(), v.end());
  return v;
}

double time_to_target(const std::vector<WorkPoint>& points, const std::string& method, double group, double horizon,
                      std::size_t measure, double target) {
  double best = INFINITY;
  for (const auto& p : points)
    if (in(p, method, group, horizon) && measure < p.errors.size() && p.errors[measure] <= target)
      best = std::min(best, p.time.median);
  return best;
}

std::vector<WorkSummaryRow> summarise_work(const std::vector<WorkPoint>& points, const std::vector<WorkMeasure>& measures) {
  const auto methods = work_methods(points);
  const auto groups = work_groups(points);
  const auto horizons = work_horizons(points);
  const double nan = WorkPoint::nan;
  std::vector<WorkSummaryRow> rows;
  for (std::size_t k = 0; k < measures.size(); ++k) {
    const auto& M = measures[k];
    for (double g : groups)
      for (double H : horizons) {
        for (const auto& m : methods) {
          const double t = time_to_target(points, m, g, H, k, M.target);
          rows.push_back({"seconds_to_target", M.column, M.target, g, H, m, std::isfinite(t) ? t : nan});
        }
        const auto [bg, ba] = best_geometric_adaptive(points, g, H, k, M.target);
        const double ratio = std::isfinite(bg) && std::isfinite(ba) ? bg / ba : nan;
        rows.push_back({"geometric_over_adaptive", M.column, M.target, g, H, "-", ratio});
      }
  }
  for (std::size_t k = 0; k < measures.size(); ++k) {
    const auto& M = measures[k];
    for (double g : groups) {
      double cross = nan;
      for (auto it = horizons.rbegin(); it != horizons.rend(); ++it) {
        const auto [bg, ba] = best_geometric_adaptive(points, g, *it, k, M.target);
        if (bg < ba)
          cross = *it;
        else
          break;
      }
      rows.push_back({"crossover", M.column, M.target, g, nan, "-", cross});
    }
  }
  for (double H : horizons)
    for (double g : groups)
      for (const auto& m : methods)
        for (std::size_t k = 0; k < measures.size(); ++k) {
          std::vector<double> t, e;
          for (const auto& p : points)
            if (in(p, m, g, H) && k < p.errors.size()) {
              t.push_back(p.time.median);
              e.push_back(p.errors[k]);
            }
          rows.push_back({"slope_vs_cpu_time", measures[k].column, measures[k].target, g, H, m, fit_order(t, e, measures[k].floor).slope});
        }
  return rows;
}

}  // namespace geomint
