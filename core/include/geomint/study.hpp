#pragma once
// Studies as data: what a convergence study returns (h, errors, steps, local orders, fits, failures as missing
// values), the fits it is summarised by, and the rule that says when a fitted order is asymptotic. Programs write
// these; tests assert on them (the model: DiffEqDevTools' ConvergenceSimulation).
#include <limits>
#include <string>
#include <vector>

#include "geomint/error.hpp"
#include "geomint/registry.hpp"

namespace geomint {

class Sweep;

struct OrderFit {
  double slope = missing_value;
  double intercept = missing_value;
  int points = 0;  // points used after dropping non-finite and round-off ones
};

// Least-squares slope of log(err) against log(h). Points with err <= floor (round-off) or non-finite
// are dropped; fewer than three remaining points give slope NaN.
OrderFit fit_order(const std::vector<double>& h, const std::vector<double>& err, double floor = 1e-13);

// Observed order between successive entries: log(e_{i-1}/e_i) / log(h_{i-1}/h_i); NaN for the first.
std::vector<double> observed_orders(const std::vector<double>& h, const std::vector<double>& err);

// h0, h0/2, h0/4, ... down to the first value <= h_min.
std::vector<double> halving_sequence(double h0, double h_min);

// The fitted order on the asymptotic range of a convergence series, and whether there is one.
//
// The rule (one rule, stated here, for every test and program): drop failed points and points at round-off
// (err <= floor); take the local orders between successive remaining points (observed_orders); the asymptotic
// range is the longest run of the finest points whose local orders all lie within `spread` of each other; the
// order is the least-squares slope over that range (fit_order). The fit is
//   asymptotic       with at least three points in the range (two local orders that agree): the slope is the order;
//   pre_asymptotic   with fewer: the local orders still drift at the finest h — a crossover between error terms of
//                    different order, or step sizes too large — and the slope over the last two points is reported
//                    as what it is, not as an order;
//   too_few_points   with fewer than two usable points.
// A crossover seen over a range of h (the Duffing oscillator's contact: local orders 0.6 ... 0.9 over h = 0.1 ...
// 0.003) is pre-asymptotic there, and asymptotic at the order on a finer range.
struct AsymptoticOrder {
  enum class Status { asymptotic, pre_asymptotic, too_few_points };
  Status status = Status::too_few_points;
  double slope = missing_value;
  int points = 0;                                             // points in the range
  double h_max = missing_value;    // the range's largest and smallest h
  double h_min = missing_value;
  std::vector<double> local_orders;                           // of the usable points, coarse to fine
  bool asymptotic() const { return status == Status::asymptotic; }
  // One line for a report: "order 1.00 over h = 0.0125 ... 0.00156 (4 points)" or "pre-asymptotic: local orders
  // 0.61 0.74 0.86 0.93 ... (no three finest agree within 0.1)".
  std::string describe() const;
};
AsymptoticOrder asymptotic_order(const std::vector<double>& h, const std::vector<double>& err, double spread = 0.1,
                                 double floor = 1e-13);

// ---------------------------------------------------------------------------------------------------------------
// Convergence study

// One series: the error of one scheme of a system at one parameter combination, for every h.
struct ConvergenceSeries {
  std::string scheme;                  // as asked (its name or an alias)
  ParamValues params;                  // the combination
  std::vector<double> h, err;          // err: max_j |q(t_j) - q_ref(t_j)| in the study's norm, NaN where the run failed
  std::vector<std::vector<double>> measures;  // per h: the system's measures (ConvergenceStudy::measures), NaN where failed
  std::vector<long> steps;             // T/h
  std::vector<std::string> failure;    // why a point is missing ("" where it is not)
  std::vector<double> local_order;     // observed_orders(h, err)
  OrderFit fit;                        // least squares over every point above round-off
  AsymptoticOrder asymptotic;          // the rule above
  int expected_order = 0;              // the scheme's (SchemeInfo::order)
};

struct ConvergenceStudy {
  std::string reference;               // what the errors are measured against (Reference::kind)
  ErrorNorm norm = ErrorNorm::max;     // over the components of q
  std::vector<MeasureInfo> measures;   // what the system measures on a run beyond the error (SystemInfo::measures)
  std::vector<ConvergenceSeries> series;  // combination after combination, each with every scheme
};

// Every (combination, scheme, h) run of `sys` against its reference on the finest h of `hs` (on half of it where
// the system declares measures, which look at t_{j+1/2}; computed once per combination: the closed form or
// Boost.Odeint at `tol`, as check_reference allows), split over the ranks of `sweep` (under mpirun rank 0 gets the
// study, the others an empty one). Each run gives its error in `norm` and the system's measures in one pass. A
// numerical failure is a missing value (NaN, its message in `failure`), reported on stderr with the system,
// scheme, parameters and h.
ConvergenceStudy convergence_study(const SystemInfo& sys, const std::vector<ParamValues>& combos,
                                   const std::vector<std::string>& schemes, const std::vector<double>& hs, Path path,
                                   ReferenceKind kind, double tol, const Sweep& sweep, ErrorNorm norm = ErrorNorm::max);
// The step of the reference a study on `sys` with steps `hs` uses: the finest h, or half of it when the system
// declares measures (they read the reference between steps, e.g. the Foucault chord energy at t_{j+1/2}).
double reference_step(const SystemInfo& sys, const std::vector<double>& hs);

// The series' fits from its h and err (local orders, least-squares and asymptotic fits).
void fit_series(ConvergenceSeries& s);

}  // namespace geomint
