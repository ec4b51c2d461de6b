#pragma once
// How fast a scheme's solution drifts off an invariant of the exact flow: predicted from the modified equation, and
// measured on a run.
//
// Prediction. The discrete solution lies (to all orders, up to a bounded offset) on the flow of its modified
// equation q'' = F_0 + h F_1 + ... + h^K F_K, which keeps the modified constraint Phi_h = phi_0 + h phi_1 + ... = 0
// (nonholonomic schemes; ModifiedPoint). Along that flow an invariant I(t, q, q') of the exact flow changes at
//   dI/dt = I_t + I_q . q' + I_q' . (F_0 + h F_1 + ... + h^K F_K)
// evaluated on Phi_h = 0 (on the exact constraint Phi = phi_0 = 0 the h^0 part vanishes; off it, it does not, which
// is why the point is moved onto Phi_h = 0 first). Its average over the orbit is the secular rate: the drift per
// unit time that accumulates, while the rest of dI/dt integrates to a bounded oscillation. The orbit is the exact
// one (Odeint on the system's equations), which the modified orbit follows to O(h^p): the rate is O(h^r), so the
// error this makes is O(h^{r+p}).
// Measurement. I(t_j, q_j, v_j) along a run (v_j the velocity of the scheme's momentum p_j): the rate at t = 0 of
// the least-squares quadratic in t_j (a drift large enough to change the orbit changes its own rate; the quadratic
// term takes that up, and its linear term is the rate on the starting orbit, which is what is predicted). The
// start's O(h^p) offset is a constant and the bounded oscillation averages out over many periods; what is left of
// them is estimated by the same fit over the first half of the run alone (the spread).
#include <functional>
#include <string>
#include <vector>

#include "geomint/modified/automatic_registry.hpp"
#include "geomint/registry.hpp"

namespace geomint::modified {

// I(t, q, q') and, when grad is not null, its gradient (1 + 2n entries: d/dt, d/dq, d/dq').
using InvariantFunction = std::function<double(double t, const double* q, const double* v, double* grad)>;

struct DriftRate {
  double rate = 0;    // per unit time
  double spread = 0;  // |rate of the first half - rate of the second half| (its uncertainty)
  long samples = 0;
};

// The orbit average of dI/dt along the order-K modified flow of `scheme` at step h, over the points of `orbit` (an
// exact solution: Reference rows of q and q'), every `stride`-th; one rate per invariant (each point is moved onto
// Phi_h = 0 once for all of them).
std::vector<DriftRate> predicted_drift(const ModifiedSystem& me, const ParamValues& pv, const std::string& scheme, int K,
                                       double h, const Reference& orbit, long stride,
                                       const std::vector<InvariantFunction>& invariants);

// The same rate measured along a run of `scheme` at step h over [0, T] (generic path), keeping every `every`-th step.
struct MeasuredDrift {
  DriftRate slope;
  double offset = 0;         // I(0, q_0, v_0) - I of the exact start: what the scheme's start changed
  double max_deviation = 0;  // max_j |I_j - I_0| over the run
  long steps = 0;
};
MeasuredDrift measured_drift(const SystemInfo& sys, const ParamValues& pv, const std::string& scheme, double h, double T,
                             long every, const InvariantFunction& invariant, double exact_start_value);
// The same of a run already made (its kept rows).
MeasuredDrift measured_drift(const Run& run, const InvariantFunction& invariant, double exact_start_value);

// The power r in rate ~ C h^r fitted (least squares in log-log) over the points whose rate is above its spread;
// NaN with fewer than two.
double drift_power(const std::vector<double>& h, const std::vector<DriftRate>& rates);

}  // namespace geomint::modified
