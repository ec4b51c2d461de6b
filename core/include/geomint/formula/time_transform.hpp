#pragma once
// Runs of a time-transformed formula system (description.hpp's time_transform; docs/time-transformation.md) read
// at a physical time. The model steps in the fictitious time sigma with a fixed step h; its last coordinate is the
// time t(sigma). A study that compares at fixed t (an error against a reference in t) needs the state where
// t(sigma) = t_end, which falls between two steps: it is found by cubic Hermite interpolation in sigma of the
// positions Q = (q, t) and their sigma-velocities Q' = (q', t') at the two steps around it, t(sigma*) = t_end solved
// by Newton's method on the interpolant. The interpolant is exact for cubics, so its error is O(h^4) on top of the
// scheme's O(h^p): the error in t keeps the scheme's order up to p = 4 (an order-6 or 8 composition is held to 4
// there; its error at the steps themselves keeps its order). The velocity dq/dt = q'/t' is read from the
// interpolant's derivative (O(h^3)); z, of the contact schemes, linearly (O(h^2)).
#include <string>
#include <vector>

#include "geomint/formula/model.hpp"
#include "geomint/registry.hpp"

namespace geomint::formula {

struct PhysicalState {
  double t = 0, sigma = 0;
  std::vector<double> q, v;  // the physical positions and velocities dq/dt (n of each)
  double z = 0;
};

// The state of `run` (every step kept) of a time-transformed model with n physical coordinates at physical time
// t_end; InputError when the run does not reach t_end.
PhysicalState at_physical_time(const Run& run, int n, double t_end);

struct PhysicalRun {
  Run run;                 // in sigma, every step kept
  PhysicalState end;       // at t = t_end
  double residual = 0;     // max_j |w_j|, w = kappa (t' - g) at the steps: zero on the exact flow
  double sigma_horizon = 0;
};

// Runs `scheme` with step h in sigma on `info` (the registry entry of the time-transformed `model`) until t(sigma)
// passes t_end (the sigma horizon T a multiple of h, from t_end / g0 and doubled until t_end is reached), and reads
// it at t_end.
PhysicalRun run_to_physical_time(const SystemInfo& info, const FormulaModel& model, ParamValues pv,
                                 const std::string& scheme, double h, double t_end, Path path);

// The velocities Q'_j of a run of a time-transformed model from its momenta p_j (and its energy column from them):
// Newton's method on dLbar/dQ' = p started from the previous step's Q' (the first from the exact Q'(0)). The
// extended Lagrangian's Legendre map is one-to-one only near the motion (t' > 0, w small); the registry's run
// starts its Newton at Q' = p, where p_t = -E < 0, and can land on another root: its v and energy columns of a
// time-transformed model would not be right: the registry entry of such a model (formula_registry.hpp) replaces
// them with these. `pv`: the tapes' parameter table.
void time_transform_velocities(const FormulaModel& model, const std::vector<double>& pv, Run& run);

// The tapes' parameter table (numbers | parameters | derived values) of `model` at `pv`, its defaults elsewhere.
std::vector<double> parameter_table(const FormulaModel& model, const ParamValues& pv);

// w = kappa (t' - g) at (sigma, Q, Q') at the parameter values `pv` (the model's defaults elsewhere).
double time_transform_residual(const FormulaModel& model, const ParamValues& pv, double sigma, const std::vector<double>& Q,
                               const std::vector<double>& Qv);

}  // namespace geomint::formula
