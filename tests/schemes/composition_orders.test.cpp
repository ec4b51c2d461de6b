// Every composition family on every symmetric scheme of every registered system converges at its order: fitted
// slopes of max_j |q_j - q(t_j)| against h, the reference the system's own (closed form or Boost.Odeint at
// tol 1e-14). h runs down a ladder of ratio sqrt(2) (N = T/h steps, an integer) so that order 8 shows over four
// points above the round-off floor in double: the error drops 16x per rung. The fit uses the finest points above
// the floor (at most four consecutive ones: a factor 2.8 in h, the asymptotic range; coarser rungs may be
// pre-asymptotic or fail, which the fit ignores) and needs at least three.
// Contact and nonholonomic bases included: the constrained ones keep their order in q although their map on
// (q, p) is not symmetric (generic/composition.hpp; tests/schemes/composition.test.cpp measures the symmetry).
// The fitted orders are printed (WARN) as a table: build/tests/geomint_tests "[composition][orders]".
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "geomint/error.hpp"
#include "geomint/generic/composition_families.hpp"
#include "geomint/study.hpp"

using namespace geomint;

namespace {

struct Ladder {
  ParamValues params;
  double T;
  double h_max;
  int rungs;
  double floor;  // errors below it are near round-off: ten times the worst floor measured on that system
};

// Horizons of a few oscillations. The Foucault pendulum (period 16 s, |q| <= 0.67 m, round-off floor <= 1e-15)
// over 3 s with coarse steps, 0.28 m from the origin at the end: at T = 4 s (0.03 m from the origin, where the
// covector of (13) vanishes) kahanli8:la-midpoint's error passes through a crossing of two terms (local slopes
// 6.1 .. 7.2 for h = 1 .. 0.25, the same to three digits in long double: not round-off), at T = 3 s it is 8.0 from
// h = 0.75 down to round-off. Kepler (period 2 pi, pericentre 0.6) further down, where its asymptotic range starts.
// The linear systems step with one update of a kept Jacobian or a fixed affine map (the stepper's linear lanes),
// whose rounding repeats at every step: their floor is higher (7e-12 on the oscillator).
Ladder ladder_of(const SystemInfo& sys) {
  if (sys.name.rfind("foucault", 0) == 0) return {{{"T", 3}, {"alpha", 0.1}}, 3, 1.5, 9, 1e-13};
  if (sys.name == "kepler") return {{{"T", 10}}, 10, 0.8, 11, 1e-11};
  const double T = std::min(10.0, sys.horizon({}));
  return {{{"T", T}}, T, 0.8, 9, sys.linear ? 1e-10 : 1e-11};
}

constexpr double kTolerance = 0.3;  // on the fitted order

// The finest run of consecutive points above the floor, at most `most` of them, and its fitted slope.
OrderFit fit_finest(const std::vector<double>& h, const std::vector<double>& err, int most, double floor) {
  std::vector<double> hs, es;
  for (std::size_t k = h.size(); k-- > 0;) {
    if (!(std::isfinite(err[k]) && err[k] > floor)) {
      if (!hs.empty()) break;
      continue;
    }
    hs.push_back(h[k]);
    es.push_back(err[k]);
    if (static_cast<int>(hs.size()) == most) break;
  }
  return fit_order(hs, es, floor);
}

}  // namespace

TEST_CASE("every composition family reaches its order on every system and symmetric scheme", "[composition][orders]") {
  const auto& families = generic::composition_families();
  for (const auto& sys : all_systems()) {
    const Ladder L = ladder_of(sys);
    std::vector<double> hs;
    std::vector<Reference> refs;
    for (int k = 0; k < L.rungs; ++k) {
      const long N = std::lround(L.T / L.h_max * std::pow(std::sqrt(2.0), k));
      hs.push_back(L.T / static_cast<double>(N));
      refs.push_back(sys.reference(L.params, hs.back(), N, ReferenceKind::automatic, 1e-14));
    }
    std::string table = sys.name + ": fitted orders (" + refs.front().kind + ")";
    for (const auto& base : sys.composition_bases()) {
      table += "\n  " + base + ":";
      for (const auto& fam : families) {
        const std::string name = generic::composition_name(fam.name, base);
        std::vector<double> err;
        for (std::size_t k = 0; k < hs.size(); ++k) {
          try {
            err.push_back(sys.max_error(L.params, name, hs[k], Path::generic, refs[k]));
          } catch (const NumericalFailure&) {
            err.push_back(std::nan(""));  // a coarse rung outside the range of Newton's convergence
          }
        }
        const OrderFit fit = fit_finest(hs, err, 4, L.floor);
        char cell[64];
        std::snprintf(cell, sizeof cell, " %s %.2f", fam.name.c_str(), fit.slope);
        table += cell;
        std::string errs;
        for (double e : err) errs += " " + show(e);
        INFO(sys.name << " " << name << ": errors" << errs << "; fitted order " << fit.slope << " over " << fit.points
                      << " points");
        CHECK(fit.points >= 3);
        CHECK(std::abs(fit.slope - fam.order) <= kTolerance);
      }
    }
    WARN(table);
  }
}
