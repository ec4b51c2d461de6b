#pragma once
// Surrogate Lagrangians: higher order from a low-order scheme by changing the system, not the scheme
// (De La Torre–Murphey's surrogate Lagrangians; Chartier–Hairer–Vilmart's modifying integrators), built by the
// modified-equation engine from the scheme's own residual, for forced, contact and constrained systems.
//
// The construction. Write the modified equation of a scheme applied to data D (the Lagrangian, the force, the
// Herglotz Lagrangian, the constraint rows) as q'' = F_0[D] + h F_1[D] + h^2 F_2[D] + ... . For surrogate data
// D~ = D + h D_1 + h^2 D_2 + ..., with the step h in D~ expanded together with the scheme's own h, the modified
// equation of D~ is F_0[D] + h (F_1[D] + F_0'[D].D_1) + h^2 (F_2[D] + F_1'[D].D_1 + F_0'[D].D_2 + (1/2) F_0''[D](D_1, D_1))
// + ...: the order-k coefficient is F_0'[D].D_k plus terms of D_1 .. D_{k-1} only. So the corrections are found one
// order at a time: with D_1 .. D_{k-1} in place (orders 1 .. k-1 of the surrogate's modified equation vanish),
// the engine's order-k coefficient F_k of the surrogate is what D_k must cancel, F_0'[D].D_k = -F_k, a linear
// condition on D_k with the continuous equations' linearization F_0' — nothing of the scheme enters it. Solved:
//   Lagrange–d'Alembert: D_k = (l_k, f_k) with l_k = -(order-k meshed Lagrangian of the scheme on the surrogate)
//     (ModifiedEquation::mesh_lagrangian; dropped when its Euler–Lagrange expression vanishes identically, a total
//     derivative) and the force f_k = -M F_k - E[l_k] (M = L_q'q', E the Euler–Lagrange expression on the flow) —
//     zero when l_k alone does it, as it does for a conservative variational scheme (checked, reported);
//   contact: the Herglotz Lagrangian's correction c_k = -Z_k (z' = L must hold to order k), and whether its
//     Herglotz equations then also cancel F_k is the certification's question;
//   constrained (rows linear in the velocities): the engine's modified constraint Phi_h = sum h^k phi_k is what the
//     discrete solution keeps, so the rows get -phi_k — possible only where phi_k is linear in the velocities
//     (a holonomic row g(t_{j+1}, q_{j+1}) = 0 is kept exactly and needs none); then the force cancels F_k.
// Iterating this is the recursion L~ = L - h L_1 - h^2 (L_2 - DL_1[L].L_1) + ... (the Frechet-derivative terms are
// what the engine finds when it is run on the corrected data), with everything symbolic (GiNaC) and the surrogate's
// own h a series in the engine's h (the formula system's parameter h is the engine's series variable).
// Certification: the engine, run once more on the final surrogate, gives F_1 .. F_K (Z_k, phi_k) = 0 symbolically,
// and the same engine in numbers, on the surrogate read back from its own system file, gives them at round-off.
//
// The surrogate is a formula system (a system file): the base's parameters plus the step h, a parameter named
// `step`, which a run must set to the step it takes (SurrogateSystem::step_parameter). Its initial velocity is the one whose momentum (the
// continuous momentum of L~, as the stepper starts) is the scheme's discrete momentum along the base's exact flow,
// to order K: without it a first-order scheme would stay first order whatever L~.
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "geomint/formula/description.hpp"
#include "geomint/formula/model.hpp"

namespace geomint::modified {

// One correction, printed three ways (as FormulaRow): quantity L, F<i> (force), herglotz, phi<c> (constraint row),
// v<i> (the initial velocity), at power k of h.
struct SurrogateTerm {
  std::string quantity;
  int k = 0;
  std::string text, mathematica, latex;
};

// The certification of one order k of the surrogate's modified equation under the same scheme.
struct SurrogateCheck {
  int k = 0;
  bool symbolic_zero = false;  // F_k, Z_k and phi_k simplified to 0
  std::string leading;         // for the first order beyond K that does not vanish: what it is (text), else ""
};

struct SurrogateSystem {
  std::string base, scheme;
  int K_asked = 0, K = 0;         // the order asked and the order reached (the budget, or a correction not possible)
  bool stopped = false;           // the budget ran out
  std::string why_short;          // why K < K_asked when not the budget ("" otherwise)
  double seconds = 0, budget = 0;
  std::string step_parameter = "step";
  bool force_free = true;         // the corrections of an LA scheme stayed in the Lagrangian (no force added)
  bool constraint_linear = true;  // every constraint correction was linear in the velocities
  std::vector<SurrogateTerm> terms;
  std::vector<SurrogateCheck> checks;  // k = 1 .. K (+ the first beyond, when it was computed)
  // In numbers: the surrogate read back from its system file, its step parameter h0, the engine (numbers, the
  // formula registry's) at step h0: the defect max |sum_{k<=J} h0^k F_k - F_0[base]| / |F_0[base]| over random
  // points (J the last order certified), for h0 = 0.1 / 2^i, and its fitted slope: K + 1 (K + 2 for a symmetric
  // scheme and even K) when the surrogate is what the formulas say.
  std::vector<double> defect_h, defect;
  double defect_slope = 0;
  formula::SystemDescription description;  // the surrogate as a system
  std::string file_text;                   // the same as a system file (docs/systems/README.md)
};

// The surrogate of `scheme` (la, contact, la-midpoint, la-trapezoid, contact-trapezoid) for the formula system
// `base`, to order K (the scheme on it is exact for the base to h^K: order K + 1 for a first-order scheme, K + 2
// for a symmetric one with even K), within `budget_seconds`. InputError for a shape the build has not compiled
// surrogates for, an unknown scheme, K out of [1, 5].
SurrogateSystem build_surrogate(const std::shared_ptr<const formula::FormulaModel>& base, const std::string& scheme,
                                int K, double budget_seconds = 120, double step = 0.1);

// The shapes (n, m, holonomic) surrogates are compiled for, for messages.
std::string surrogate_shapes();

}  // namespace geomint::modified
