#pragma once
// All-orders modified equations of the linear oscillator schemes. Each scheme is a linear recurrence
// (q_{j+1}, p_{j+1}) = M (q_j, p_j), so q_j satisfies q_{j+2} - tr(M) q_{j+1} + det(M) q_j = 0 and samples
// exactly the solution of q'' + a_h q' + b_h q = 0 with lambda = exp(h mu), mu roots of mu^2 + a_h mu + b_h.
// (a_h, b_h) are the modified damping and stiffness to all orders in h; their expansions must reproduce
// the first-order modified equations (8) and (11).
#include <cmath>
#include <vector>

#include <string>

#include "geomint/error.hpp"
#include "geomint/registry.hpp"

namespace geomint::modified {

struct AllOrders {
  double a = missing_value;      // modified damping coefficient (q'' + a q' + b q = 0)
  double b = missing_value;      // modified stiffness
  double tr = missing_value, det = missing_value;
  bool oscillating = false;     // complex eigenvalues
  bool valid = false;           // false when an eigenvalue is <= 0 (no continuous flow samples it)
  double spectral_radius = missing_value;
};

// Computed in long double: a_h = -ln(det)/h and b_h lose about log10(1/h) digits to cancellation, which
// double would show as a deviation growing to 1e-9 over 32 000 steps.
AllOrders all_orders_from_trace_det(long double tr, long double det, long double h);

// max_j |q_j - q^(t_j)| where q^ solves q'' + a_h q' + b_h q = 0 through (t_0, q_0) and (t_1, q_1).
// Round-off level when the recurrence samples that flow exactly.
double all_orders_deviation(const AllOrders& m, const std::vector<double>& t, const std::vector<double>& q);

// The all-orders coefficients of any scheme of the registry's oscillator (by its name or an alias), from its
// closed form's one-step matrix in long double. InputError for an unknown name.
AllOrders all_orders_by_name(const std::string& scheme, double h, double alpha);

// The same for any linear system without constraints and any of its schemes or compositions (n degrees of freedom).
// The step is x_{j+1} = M x_j on x = (q, p) (a forcing term aside), so x_j = exp(G t_j) x_0 with G = log(M)/h, the
// principal logarithm: the flow of x' = G x passes through every step, which makes x' = G x the modified equation to
// all orders, wherever M has no real eigenvalue <= 0 (the logarithm is real there). Eliminating p (q' = G_qq q + G_qp p)
// gives it in q alone, q'' = A_v q' + A_q q with B = G_qp G_pp G_qp^-1, A_v = G_qq + B, A_q = G_qp G_pq - B G_qq: the
// sum of every h^k F_k of the automatic modified equation, which a truncation at K reaches to O(h^(K+1)). For n = 1,
// A_v = tr G = -a_h and A_q = -det G = -b_h.
struct LinearModified {
  int n = 0;
  std::vector<long double> G;      // 2n x 2n, row-major, on (q, p)
  std::vector<long double> A_q, A_v;  // n x n, row-major
};
// InputError for a system that is not linear or has constraints (registry's one_step_matrix); NumericalFailure where
// M has a real eigenvalue <= 0 or G_qp is singular (no modified equation in q alone).
LinearModified all_orders_linear(const SystemInfo& sys, const ParamValues& pv, const std::string& scheme, double h,
                                 Path path);

// max_j |q_j - (exp(G t_j) x_0)_q| over a run of the same scheme and h, x_0 = (q_0, p_0), each exponential taken
// afresh (not by powers): round-off where the flow of x' = G x passes through the steps. Missing when the steps are
// affine rather than linear (a forcing term): a step leaves the homogeneous map exp(G h) by more than 1e-9 relative,
// far above round-off and far below any forcing that shows.
double linear_flow_deviation(const LinearModified& lm, const Run& run);

// The truncated series' A_q, A_v: sum_{k <= K} h^k of the Jacobians of F_k in q and q' (exact differences, F_k
// being affine in (q, q') for a linear system), from the automatic modified equation of `scheme`. A linear system
// only (the caller's check: the differences are not Jacobians otherwise).
struct LinearSeries {
  int n = 0, K = 0;
  std::vector<double> A_q, A_v;  // n x n, row-major
};
LinearSeries linear_series(const SystemInfo& sys, const ParamValues& pv, const std::string& scheme, int K, double h);

}  // namespace geomint::modified
