#pragma once
// Step-by-step agreement of a discrete solution with its modified equation and with the original one.
//
// Initial data. The discrete data are (q0, p0). The naive start q~(0) = q0, q~'(0) = p0 makes the
// comparison O(h): p_j is not the velocity of the modified solution, but a discrete Legendre transform of
// it. Expanding each scheme's own momentum map along a smooth curve gives the modified momentum maps
//   LA:       p_j = (q_j - q_{j-1})/h                 => p~ = q~' - (h/2) q~''           + O(h^2)
//   contact:  p_j = [(q_{j+1}-q_j)/h + h q_j/2]/(1-h alpha)
//                                                     => p~ = (1 + h alpha/2) q~' = dL_mod/dq'  (11) + O(h^2)
// The consistent start solves p~(q0, q~'(0)) = p0 for q~'(0). The errors in p are measured against p~(t_j).
// For contact, z~' = L_mod along the modified solution, z~(0) = z0 = 0.
#include <array>
#include <string>
#include <vector>

namespace geomint::modified {

enum class Start { consistent, naive };
const char* start_name(Start s);

struct ModifiedSolution {
  std::vector<double> t, q, v, p, z;  // p: the modified momentum map p~ at t_j
};

// Solution of the modified equation of `scheme` ("la" or "contact") at t_j = j h, j = 0..N, with Odeint
// (dense output, tolerance tol). sign = -1 flips the O(h) term (a wrong modified equation);
// h_eq = 0 gives the original equation (and its exact momentum p = q').
ModifiedSolution modified_solution(const std::string& scheme, double alpha, double h, double h_eq, double T, double q0,
                                   double p0, Start start, double sign = 1, double tol = 1e-12);

// The initial velocity q~'(0) of the modified solution.
double modified_initial_velocity(const std::string& scheme, double alpha, double h_eq, double q0, double p0,
                                 Start start, double sign = 1);

// Right-hand side of the modified equation as a first-order system in (q, v, z) (z' = 0 for LA).
std::array<double, 3> modified_rhs(const std::string& scheme, double alpha, double h_eq, double sign,
                                   const std::array<double, 3>& x);

// The truncated modified equation is linear here: q'' = -b q - a q'. Its (a, b), read off the
// AD-derived vector field of (8) or (11) (so they come from the code of the modified Lagrangian).
struct LinearCoefficients {
  double a, b;
};
LinearCoefficients modified_coefficients(const std::string& scheme, double alpha, double h_eq);

struct Agreement {
  double err_modified, err_original;      // max_j |q_j - q~(t_j)|, max_j |q_j - q(t_j)|
  double err_p_modified, err_p_original;  // the same for p
  double err_z_modified, err_z_original;  // the same for z (contact; NaN for LA)
};

Agreement agreement(const std::string& scheme, double alpha, double h, double T, double q0, double p0, Start start,
                    double sign = 1, double tol = 1e-12);

// The same modified solution integrated with GSL's rk8pd (cross-check of the Odeint solution).
std::vector<std::array<double, 3>> modified_solution_gsl(const std::string& scheme, double alpha, double h_eq,
                                                         const std::vector<double>& times, std::array<double, 3> x0,
                                                         double tol = 1e-12);

}  // namespace geomint::modified
