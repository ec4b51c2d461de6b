#pragma once
// The plane of oscillation along a run: the one record of turning points and plane angles that the system's
// measures, the diagnostics, the ensembles' summaries and the long-horizon study feed.
#include <cmath>
#include <vector>

#include "geomint/error.hpp"
#include "geomint/observers.hpp"

namespace geomint {
// A turning point: a local maximum of r_j = |q_j| (j = 0 counts when r_0 >= r_1).
struct FoucaultTurn {
  long j;
  double t, x, y, r;
  double energy;  // E_{j+1/2}
  double angle;   // plane of oscillation, atan2(y, x) unwrapped modulo pi (continuous across turns), rad
  double jump;    // angle - previous angle, rad (NaN for the first)
};

// Least-squares slope of angle against t over the turning points (GSL); NaN with fewer than 3.
double fit_precession_rate(const std::vector<FoucaultTurn>& turns, int* points = nullptr);

// The turning points of a run and the plane at each, continued modulo pi from turn to turn: the one record the
// diagnostics, the ensembles' summaries and the convergence measures take the precession rate from.
struct PlaneTurns {
  std::vector<FoucaultTurn> turns;
  // The step j -> j+1 as |q_{j-1}|, q_j = (x, y), |q_{j+1}| at t_j (E: the chord energy E_{j+1/2}); the radii
  // compared in the run's own precision T. True when q_j is a turning point, which is then the last of `turns`.
  template <class T>
  bool observe(long j, double t, T r_prev, double x, double y, T r, T r_next, double E) {
    if (!is_turning_point(j == 0, r_prev, r, r_next)) return false;
    double a = std::atan2(y, x), jump = missing_value;
    if (!turns.empty()) {
      a = line_angle(x, y, turns.back().angle);
      jump = a - turns.back().angle;
    }
    turns.push_back({j, t, x, y, static_cast<double>(r), E, a, jump});
    return true;
  }
  double rate(int* points = nullptr) const { return fit_precession_rate(turns, points); }
};

}  // namespace geomint
