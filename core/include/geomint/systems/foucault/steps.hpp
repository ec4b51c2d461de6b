#pragma once
// What the two-step closed forms share: their start, the two discretizations of (13), the plane's line, the step
// their observers see, and the rotation table of the remedy.
#include <array>
#include <cmath>
#include <string>

#include "geomint/error.hpp"
#include "geomint/systems/foucault/params.hpp"

namespace geomint {

// A two-step scheme needs q_1 (equivalently a virtual q_{-1}) besides q_0. The paper gives
// q(0) = (0.67, 0), q'(0) = (0, 0), which violates (13) (Phi = s |q0|^2 != 0), and does not say how the
// first step was taken. Two choices, selectable:
//
//   legendre (default): project q'(0) onto (13) at q0 (minimal-norm change along A(q0)), take the
//     continuous momentum p0 = m v0 as the discrete momentum p_0^- of the scheme, and solve the scheme's
//     own discrete Legendre transform with the constraint force,
//         p_0^+ = p_0^- - lambda A(q0),   Phi_d(q0, q1) = 0,
//     which is linear in (q1, lambda). This is what a variational integrator means by "start from
//     (q0, p0)": the first step is the j = 0 equation of the scheme with D2 L_d(q_{-1}, q_0) replaced by
//     p0. Equivalently, it is the regular step from a virtual q_{-1} with D2 L_d(q_{-1}, q0) = p0:
//         LA (15):       p_0^- = m (q0 - q_{-1})/h                       => q_{-1} = q0 - h v0
//         contact (18):  p_0^- = D2 L_d = m ((q0 - q_{-1})/h - h w2 q0/2)  => q_{-1} = q0 - h v0 - h^2 w2 q0/2
//     (for contact, p_j = D2 L_d(q_{j-1}, q_j, z_{j-1}) = -D1 L_d(q_j, q_{j+1}, z_j)/(1 - h alpha) as in
//     eq. (10)). We chose it because it is the scheme's own map from (q, p) to (q_j, q_{j+1}), so the
//     first step carries no extra error: both schemes keep their observed orders (contact's error looks
//     O(h^2) at small alpha only with this start; see `convergence --system foucault`).
//   taylor: the naive backward Euler start q_{-1} = q0 - h q'(0) with the raw (unprojected) q'(0).
//     For LA it is the same start as legendre: the A(q0)-component of q'(0) that the projection removes
//     is absorbed by lambda, and F_d^+ = 0 makes p_0^- = m (q0 - q_{-1})/h. For contact it misses the
//     h w2 q0/2 term of the discrete momentum: an O(h) error in the initial velocity, so an O(h) global
//     error (and a different sequence of passes near the origin).
// The projection matters for the continuous reference, which must start on (13).
enum class FoucaultStart { legendre, taylor };

FoucaultStart parse_foucault_start(const std::string& name);  // InputError for an unknown name
const char* to_string(FoucaultStart s);

//
// paper (the system `foucault`; reproduces Section 3.2): the third row of (15) and (18), (13) o Psi,
//     A(q_j).(q_{j+1} - q_j)/h + s |q_j|^2 = 0    <=>    q_j x q_{j+1} = -s h |q_j|^2,
//   with the constraint force along A(q_j) in rows 1-2. The covector A(q) = (-y, x) = |q| n(theta(q))
//   vanishes at the origin, so the step's 3x3 determinant is proportional to |q_j|^2; and the row reads
//   the direction of the plane off the point q_j itself: "the part of q_{j+1} normal to q_j is
//   -s h |q_j|". Applied to the step into a point q_L that lands next to the origin, it says
//       sin(angle from q_{L-1} to q_L) = -s h |q_{L-1}| / |q_L|      (signed radii along the plane),
//   so when |q_L| = rho |q_{L+1} - q_L| with rho << 1 the plane turns by asin(s h |q_{L-1}|/|q_L|)
//   ~ s h / rho in one step, and the next step (whose force is along A(q_L)) removes the velocity across
//   the new direction: the energy drops by sin^2 of that angle. This is the anomaly; the detector and the
//   ensembles that measure it are in foucault_ensemble.hpp.
//
// rotation (the remedy; the system `foucault-rotation`): in polar coordinates q = r e(theta), (13) reads r^2 (theta' + s) = 0: off the
//   origin the plane turns at exactly -s (theta(t) = theta_0 - s t, see foucault_exact). So on consistent
//   data (13) is r times the time derivative of the rheonomic, holonomic constraint
//       g(q, t) = n(phi(t)).q = 0,   phi(t) = phi_0 - s t,   e(phi) = (cos phi, sin phi),  n(phi) = (-sin phi, cos phi)
//   (d/dt g = n.q' - phi' e.q = n.q' + s r on the line, and r (n.q' + s r) = A(q).q' + s r^2 = Phi).
//   The remedy carries the plane angle as part of the state, phi_j = phi_0 - s t_j with t_j = j h (so
//   phi_{j+1} - phi_j = -h Omega sin(beta) exactly, evaluated afresh at every step, never accumulated),
//   phi_0 = atan2(y_0, x_0) (for consistent data the exact plane passes through q_0), and
//     - replaces the third row of (15)/(18) by   n(phi_{j+1}) . q_{j+1} = 0   (q_{j+1} on the rotated line;
//       equivalently theta_{j+1} - theta_j = -h s modulo pi, the "exact rotation of the polar angle"
//       — modulo pi, because the bob passes through the origin and its polar angle then jumps by pi);
//     - replaces the force direction A(q_j) = (-y_j, x_j) in rows 1-2 by the unit covector n(phi_j);
//     - keeps everything else in rows 1-2 of (15)/(18) as printed.
//   Each step stays linear in (q_{j+1}, lambda_1); the determinant of the 3x3 system is c n(phi_{j+1}).n(phi_j)/m
//   = c cos(s h)/m (c = 1/h + alpha for LA, 1/h^2 for contact): independent of q_j, never singular. (The
//   paper's is c |q_j|^2 / (m h).)
//   Why the force along n(phi_j), not along A(q_j) or n(phi_{j+1}):
//     (1) It is the paper's direction. q_j lies on the line L(phi_j), q_j = r_j e(phi_j) with r_j signed, so
//         A(q_j) = r_j n(phi_j): the force keeps the direction of (15)/(18) and the multiplier is rescaled,
//         lambda_1(paper) = lambda_1(rotation) / r_j. The factor r_j that makes the paper's system singular
//         at the origin moves out of the unknown; the force itself was always bounded.
//     (2) It is d'Alembert's principle at t_j: rows 1-2 are the variation at q_j, the admissible variations
//         there are along L(phi_j) (the kernel of A(q_j), i.e. the direction of q_j), and the force must do
//         no work on them. The constraint is imposed at the new point, as (15)/(18) (and SHAKE for holonomic
//         constraints) do.
//     (3) A(q_j) itself would keep the singularity (the determinant becomes c r_j cos(s h)/m); n(phi_{j+1})
//         (orthogonal projection onto the new line) is regular too but is not the direction at q_j: it adds
//         a tangential force sin(s h) lambda_1, an O(h) change of the same size as the schemes' own error.
//   The multiplier lambda_1 of the rotation rows is an impulse per step (LA, N s) or a force (contact, N); its
//   continuous-equivalent (13) multiplier is lambda_force / r_j (kg/s, comparable with the paper's).
//   This remedy uses that (13) integrates to a rotation of the plane, which holds for this constraint; it is
//   not a general cure for nonholonomic constraints whose covector vanishes.
// The plane of oscillation at angle phi: direction e(phi) and normal n(phi).
template <class T>
struct FoucaultLine {
  Vec2<T> e, n;
};

template <class T>
FoucaultLine<T> foucault_line(T phi) {
  using std::cos;
  using std::sin;
  const T c = cos(phi), sn = sin(phi);
  return {Vec2<T>(c, sn), Vec2<T>(-sn, c)};
}

// One step as the closed forms' observers see it: q_{j-1} (virtual for j = 0), q_j, q_{j+1}, and the multiplier
// of the step j -> j+1 (lambda_1 as in the paper, and the continuous-equivalent force multiplier). On
// foucault-rotation the step also carries the plane angle phi_{j+1} of q_{j+1}'s line (NaN on foucault).
template <class T>
struct FoucaultStep {
  long j;
  T t;  // t_j = j h
  const Vec2<T>& qm;
  const Vec2<T>& q;
  const Vec2<T>& qn;
  T lambda1, lambda;
  T phin;
};

// The failure of step j -> j+1 when q_{j+1} is not finite.
inline NumericalFailure state_failure(long j) { return NumericalFailure(j + 1, "state", "non-finite q_{j+1}"); }

// The rotations R(-s h b), b < K, that carry the line of the rotation discretization from its anchor (evaluated
// with cos and sin every K steps) to the K - 1 steps after it. Shared by FoucaultRotation's
// closed-form loop and the ensembles, so both turn a line by the same arithmetic.
template <class T>
struct RotationTable {
  static constexpr long K = 64;
  std::array<T, K> cb, sb;  // R(-s h b) = [[cb, -sb], [sb, cb]]
  RotationTable(T s, T h) {
    using std::cos;
    using std::sin;
    for (long b = 0; b < K; ++b) {
      const T a = s * (T(b) * h);
      cb[static_cast<std::size_t>(b)] = cos(a);
      sb[static_cast<std::size_t>(b)] = -sin(a);
    }
  }
  // e(phi_anchor - s h b) from e(phi_anchor) = (a0, a1).
  void line(long b, T a0, T a1, T& e0, T& e1) const {
    const T c = cb[static_cast<std::size_t>(b)], sn = sb[static_cast<std::size_t>(b)];
    e0 = c * a0 - sn * a1;
    e1 = sn * a0 + c * a1;
  }
};
}  // namespace geomint
