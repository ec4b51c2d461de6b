#pragma once
// Studies as data: what a convergence study returns (h, errors, steps, local orders, fits, failures as missing
// values), the fits it is summarised by, and the rule that says when a fitted order is asymptotic. Programs write
// these; tests assert on them (the model: DiffEqDevTools' ConvergenceSimulation).
#include <cmath>
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

// Where a fitted order may look: the errors above what the reference resolves and below blow-up.
//   floor    round-off (1e-13) against a closed form; against Odeint, reference_floor_factor times its tolerance
//            (its error over a horizon is a few times the tolerance: a scheme's error near it reads the reference's);
//   ceiling  the size of the solution, max_j |q_ref(t_j)| in the study's norm: an error as large as the solution
//            says the run has lost it (a blow-up, or a phase error that has saturated) and carries no order.
// A point outside the band (or non-finite) is dropped from every fit; fewer than three left is no order.
struct FitBand {
  double floor = 1e-13;
  double ceiling = std::numeric_limits<double>::infinity();
  bool holds(double err) const { return std::isfinite(err) && err > floor && err < ceiling; }
  std::string describe() const;  // "errors in (1e-11, 1.2)"
};
constexpr double reference_floor_factor = 100;
// The band of a study: round-off against a closed form, else reference_floor_factor * tol; below solution_size.
FitBand fit_band(bool exact_reference, double tol, double solution_size);
// max_j |q_ref(t_j)| in `norm`.
double solution_size(const Reference& ref, ErrorNorm norm);

// Least-squares slope of log(err) against log(h) over the points in the band (by default: above round-off);
// fewer than three of them give slope NaN.
OrderFit fit_order(const std::vector<double>& h, const std::vector<double>& err, const FitBand& band);
OrderFit fit_order(const std::vector<double>& h, const std::vector<double>& err, double floor = 1e-13);

// Observed order between successive entries: log(e_{i-1}/e_i) / log(h_{i-1}/h_i); NaN for the first.
std::vector<double> observed_orders(const std::vector<double>& h, const std::vector<double>& err);

// h0, h0/2, h0/4, ... down to the first value <= h_min.
std::vector<double> halving_sequence(double h0, double h_min);

// The fitted order on the asymptotic range of a convergence series, and whether there is one.
//
// The rule (one rule, stated here, for every test and program): drop failed points and points outside the band
// (FitBand: at the reference's floor, or blown up); take the local orders between successive remaining points (observed_orders); the asymptotic
// range is the longest run of the finest points whose local orders all lie within `spread` of each other; the
// order is the least-squares slope over that range (fit_order). The fit is
//   asymptotic       with at least three points in the range (two local orders that agree): the slope is the order;
//   pre_asymptotic   with fewer: the local orders still drift at the finest h — a crossover between error terms of
//                    different order, or step sizes too large — and the slope over the last two points is reported
//                    as what it is, not as an order;
//   too_few_points   with fewer than two usable points (describe() names the band).
// A crossover seen over a range of h (the Duffing oscillator's contact: local orders 0.6 ... 0.9 over h = 0.1 ...
// 0.003) is pre-asymptotic there, and asymptotic at the order on a finer range.
struct AsymptoticOrder {
  enum class Status { asymptotic, pre_asymptotic, too_few_points };
  Status status = Status::too_few_points;
  double slope = missing_value;
  int points = 0;                                             // points in the range
  double h_max = missing_value;    // the range's largest and smallest h
  double h_min = missing_value;
  FitBand band;                                               // the band the points were taken from
  int dropped = 0;                                            // finite points outside it
  std::vector<double> local_orders;                           // of the usable points, coarse to fine
  bool asymptotic() const { return status == Status::asymptotic; }
  // One line for a report: "order 1.00 over h = 0.0125 ... 0.00156 (4 points)" or "pre-asymptotic: local orders
  // 0.61 0.74 0.86 0.93 ... (no three finest agree within 0.1)".
  std::string describe() const;
};
AsymptoticOrder asymptotic_order(const std::vector<double>& h, const std::vector<double>& err, const FitBand& band,
                                 double spread = 0.1);
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
  FitBand band;                        // where its fits look (fit_band of the combination's reference)
  OrderFit fit;                        // least squares over every point in the band
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

// The convergence program's plan: every combination's T/h steps of every h, one step of every scheme each, at
// their step costs, against the time budget (budget.hpp).
void plan_convergence(const SystemInfo& sys, const std::vector<ParamValues>& combos,
                      const std::vector<std::string>& schemes, const std::vector<double>& hs, Path path);

// The series' fits from its h, err and band (local orders, least-squares and asymptotic fits).
void fit_series(ConvergenceSeries& s);

}  // namespace geomint
