#pragma once
// The comparison of Bravetti, Seri, Vermeeren, Zadra, "Numerical integration in celestial mechanics: a case for
// contact geometry" (Celest. Mech. Dyn. Astron. 132 (2020) 7; notebooks "The Time-Perturbed Kepler model" and
// "... -- Error Analysis" of github.com/mseri/contact-integrators), redone with geomint's schemes on the
// `kepler` system (systems/kepler.hpp).
//
// Their settings: e = 0.4, (a, theta, T) = (-0.07, 2 pi, 40) and (-0.01, pi, 55), tau = 0.5 — second- and
// sixth-order contact integrators (a splitting of H = |p|^2/2 + f(t) s - 1/|q| and its Yoshida 6A composition)
// against fixed-step RK4; and the error analysis a = 0.01, theta = 2 pi, e in {0, 0.2, 0.5}, tau = 0.05, T = 200.
// Their measures: the "error on the contact Hamiltonian", |H(t_j) - H_ref(t_j)| with H = |p|^2/2 + f(t) - 1/|q|
// as their code writes it (the f(t) term cancels in the difference: it is the mechanical energy's error), and the
// error on the trajectory |q_j - q_ref(t_j)|, both against their own sixth-order integrator at tau/20 (tau/10 for
// T = 55); in the error analysis, |x_2nd - x_6th| as the second-order integrator's error.
// Here: geomint's contact-trapezoid (discrete Herglotz, trapezoid in (t, q, z): second order, symmetric) and its
// yoshida6a composition (their sixth-order coefficients, to 26 digits), Odeint's runge_kutta4 on the equations the
// core derives from L, and the Lagrange–d'Alembert twins la-trapezoid and yoshida6a:la-trapezoid; every error
// against a tight Odeint reference (Bulirsch–Stoer with dense output, checked against dopri5), plus the exact
// angular-momentum law
// M(t) = M(0) exp(-a/theta (1 - cos theta t)) as a structural measure that needs no reference.
//
// Their first setting sits at the forcing's Nyquist limit: theta tau = pi, so f(t_j) = a sin(pi j) = 0 at every
// grid point. A scheme that samples f on the grid only (contact-trapezoid, la-trapezoid; also their own
// "variational 2nd") integrates the unperturbed Kepler problem there; their splitting evaluates f at t_j + tau/2,
// and the compositions' stages fall between the grid points.
#include <string>
#include <vector>

namespace geomint {

struct KeplerSetting {
  std::string name;  // "anchor-1", ...
  double a, theta, e, T, tau;
  long every;  // keep every `every`-th step in the traces
};

// anchor-1, anchor-2 (their comparison with RK4) and error-e0, error-e0.2, error-e0.5 (their error analysis).
std::vector<KeplerSetting> kepler_anchor_settings();
// contact-trapezoid, yoshida6a:contact-trapezoid, odeint-rk4, la-trapezoid, yoshida6a:la-trapezoid.
std::vector<std::string> kepler_anchor_methods();

// One method in one setting, at the kept steps.
struct KeplerTrace {
  std::string setting, method;
  std::vector<double> t, q1, q2;
  std::vector<double> q1_ref, q2_ref;  // the reference at the same times
  std::vector<double> energy_err;    // |E_j - E(t_j)|, E = |p|^2/2 - 1/|q| (p = q' here): their measure
  std::vector<double> position_err;  // |q_j - q(t_j)| (Euclidean)
  std::vector<double> momentum_err;  // |M_j / M(t_j) - 1| against the exact law
};

struct KeplerScore {
  std::string setting, method;
  int order = 0;
  double max_energy_err, max_position_err, final_position_err, max_momentum_err;
  // max_j |q_j - q_j(yoshida6a:contact-trapezoid)|: the error as the anchor measures it in its error analysis
  // (NaN when that method is not in the comparison)
  double diff_to_sixth;
  double work_per_step;   // Newton updates (all stages) per step, or right-hand-side evaluations (RK4)
  std::string work_unit;  // "newton" or "rhs"
  double reference_err;   // max |q_ref - q_check|, the reference against dopri5 at the same tolerance
  std::string failure;    // why the run stopped (then every error is NaN); empty otherwise
};

struct KeplerAnchor {
  std::string reference;  // what the reference is
  std::vector<KeplerTrace> traces;
  std::vector<KeplerScore> scores;
};

// Runs every method on every setting. Methods: any scheme of the kepler system, any composition
// "<family>:<scheme>", or odeint-rk4. A method that fails numerically is recorded with its failure and NaN errors.
KeplerAnchor kepler_anchor(const std::vector<KeplerSetting>& settings, const std::vector<std::string>& methods,
                           double tol = 1e-13);

// Median CPU seconds of one run of `method` in `setting` (timings are not reproducible bit for bit: kept apart).
double kepler_anchor_seconds(const KeplerSetting& setting, const std::string& method, int reps);

}  // namespace geomint
