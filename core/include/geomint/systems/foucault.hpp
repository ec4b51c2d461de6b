#pragma once
// The damped Foucault pendulum of Section 3.2, reduced to the plane q = (x, y), as two systems of the registry:
//   L = m/2 |q'|^2 - m w2/2 |q|^2  (12), (14),   w2 = g/l,
//   Rayleigh force F = -alpha m q'  (LA)   or   L - alpha z  (Herglotz, (16)),
//   foucault:           the nonholonomic constraint (13), Phi(q, q') = -y x' + x y' + s (x^2 + y^2) = 0,
//                       s = Omega sin(beta); A(q) = (-y, x) = the covector of (13), b = s |q|^2;
//   foucault-rotation:  the remedy for the anomaly (below): the rheonomic holonomic constraint
//                       g(t, q) = n(phi(t)).q = 0, phi(t) = phi_0 - s t, whose derivative is (13) on consistent
//                       data; A(t) = n(phi(t)) never vanishes, and the schemes impose g(t_{j+1}, q_{j+1}) = 0.
// Both share the scene (FoucaultPendulum: parameters, initial data, horizon, the Lagrangian, the closed-form
// solution, the multiplier ODE) and the paper's integrators (15) and (18) as the closed-form fast paths of the
// generic `la` and `contact` (FoucaultPendulum::La, ::Contact), each with the paper's third row (on `foucault`)
// and the remedy's (on `foucault-rotation`). The closed forms are the paper's two-step recurrences
// (q_{j-1}, q_j) -> q_{j+1}: the paper's bits, vectorized by the ensembles (foucault_ensemble.hpp); the generic
// (q, p) step of the same schemes carries less round-off (docs/generic-core.md).
//
// Both steps are linear in (q_{j+1}, lambda): the two dynamic rows give q_{j+1} as an affine function
// of lambda, and substituting that into the discrete constraint (the third row, (13) composed with the
// discretizing map Psi(q_j, q_{j+1}) = (q_j, (q_{j+1} - q_j)/h)) gives lambda in closed form, with
// r_j^2 = x_j^2 + y_j^2 in the denominator. tests/paper_restatements.hpp restates the equations as printed and
// builds the literal 3x3 system of a step (paper_system, for an Eigen PartialPivLU cross-check).
// The folder foucault/ holds each part: params (the scalars and the continuous objects), plane (the record of
// turning points and plane angles), exact (the closed-form solution and the multiplier ODE), steps (the start,
// the discretizations of (13), the rotation table), scene (FoucaultPendulum and the equations' mix-ins),
// closed_forms ((15) and (18)) and systems (foucault, foucault-rotation).
#include "geomint/systems/foucault/systems.hpp"
