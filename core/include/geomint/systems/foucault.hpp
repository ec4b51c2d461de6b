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
// r_j^2 = x_j^2 + y_j^2 in the denominator. `system()` builds the literal 3x3 system (for an Eigen
// PartialPivLU cross-check); tests/paper_restatements.hpp restates the equations as printed.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "geomint/constants.hpp"
#include "geomint/error.hpp"
#include "geomint/generic/system_schemes.hpp"
#include "geomint/generic/schemes.hpp"
#include "geomint/linear_oscillator.hpp"
#include "geomint/observers.hpp"
#include "geomint/registry.hpp"

namespace geomint {


template <class T>
using Vec2 = Eigen::Matrix<T, 2, 1>;
template <class T>
using Vec3 = Eigen::Matrix<T, 3, 1>;
template <class T>
using Mat3 = Eigen::Matrix<T, 3, 3>;

namespace systems {
struct FoucaultPendulum;
}

// The scalars of one run in the scalar type T. sin(beta) is evaluated in T, so a long double run is a
// long double run of the same (double) scene, not a long double run of a rounded s.
template <class T>
struct FoucaultParams {
  T m, w2, s, alpha;
  explicit FoucaultParams(const systems::FoucaultPendulum& sc);

 private:
  static T sin_deg(T deg) {
    using std::acos;
    using std::sin;
    return sin(deg * acos(T(-1)) / 180);
  }
};

// ---------------------------------------------------------------------------------------------------
// The continuous objects

template <class T>
T cross(const Vec2<T>& a, const Vec2<T>& b) {
  return a(0) * b(1) - a(1) * b(0);
}

// A(q) = (-y, x): the covector of the velocities in (13); the constraint force is lambda A(q).
template <class T>
Vec2<T> constraint_covector(const Vec2<T>& q) {
  return Vec2<T>(-q(1), q(0));
}

// Phi(q, v) of (13).
template <class T>
T foucault_constraint(const FoucaultParams<T>& p, const Vec2<T>& q, const Vec2<T>& v) {
  return -q(1) * v(0) + q(0) * v(1) + p.s * q.squaredNorm();
}

// The discrete constraint Phi_d(q_j, q_{j+1}) = Phi(Psi(q_j, q_{j+1})), Psi(q_j, q_{j+1}) = (q_j, (q_{j+1}-q_j)/h):
// the third row of (15) and of (18) (the same in both, as the paper notes).
template <class T>
T discrete_constraint(const FoucaultParams<T>& p, const Vec2<T>& q, const Vec2<T>& qn, T h) {
  return -q(1) * (qn(0) - q(0)) / h + q(0) * (qn(1) - q(1)) / h + p.s * q.squaredNorm();
}

// The round-off scale of Phi_d: storing q_{j+1} to relative precision eps moves Phi_d by up to
// eps |q_j| |q_{j+1}| / h, and the products in Phi_d add eps |q_j| |q_j| / h. Residuals are reported
// divided by this, so "round-off" means a few units.
template <class T>
T discrete_constraint_scale(const Vec2<T>& q, const Vec2<T>& qn, T h) {
  return q.norm() * (q.norm() + qn.norm()) / h;
}

// The minimal-norm change of v that satisfies (13) at q: v - Phi(q, v)/|q|^2 A(q).
// Requires q != 0 (FoucaultPendulum::validate refuses q0 = 0).
template <class T>
Vec2<T> consistent_velocity(const FoucaultParams<T>& p, const Vec2<T>& q, const Vec2<T>& v) {
  return v - foucault_constraint(p, q, v) / q.squaredNorm() * constraint_covector(q);
}

// E = m/2 |v|^2 + m w2/2 |q|^2, from (12).
template <class T>
T foucault_energy(const FoucaultParams<T>& p, const Vec2<T>& q, const Vec2<T>& v) {
  return p.m / 2 * v.squaredNorm() + p.m * p.w2 / 2 * q.squaredNorm();
}

// The discrete energy used in every diagnostic: at the half step t_{j+1/2}, with the chord velocity
// (q_{j+1} - q_j)/h and the midpoint position (q_j + q_{j+1})/2. Both are O(h^2)-accurate at t_{j+1/2},
// the definition does not depend on the scheme (so LA and contact are measured with the same ruler),
// and it needs no step beyond q_N.
template <class T>
T chord_energy(const FoucaultParams<T>& p, const Vec2<T>& q, const Vec2<T>& qn, T h) {
  return foucault_energy<T>(p, (q + qn) / 2, (qn - q) / h);
}

// ---------------------------------------------------------------------------------------------------
// The plane of oscillation along a run

// A turning point: a local maximum of r_j = |q_j| (j = 0 counts when r_0 >= r_1).
struct FoucaultTurn {
  long j;
  double t, x, y, r;
  double energy;  // E_{j+1/2}
  double angle;   // plane of oscillation, atan2(y, x) unwrapped modulo pi (continuous across turns), rad
  double jump;    // angle - previous angle, rad (NaN for the first)
};

// Least-squares slope of angle against t over the turning points (GSL); NaN with fewer than 3.
double fit_precession_rate(const std::vector<FoucaultTurn>& turns, int* points = nullptr);

// The turning points of a run and the plane at each, continued modulo pi from turn to turn: the one record the
// diagnostics, the ensembles' summaries and the convergence measures take the precession rate from.
struct PlaneTurns {
  std::vector<FoucaultTurn> turns;
  // The step j -> j+1 as |q_{j-1}|, q_j = (x, y), |q_{j+1}| at t_j (E: the chord energy E_{j+1/2}); the radii
  // compared in the run's own precision T. True when q_j is a turning point, which is then the last of `turns`.
  template <class T>
  bool observe(long j, double t, T r_prev, double x, double y, T r, T r_next, double E) {
    if (!is_turning_point(j == 0, r_prev, r, r_next)) return false;
    double a = std::atan2(y, x), jump = missing_value;
    if (!turns.empty()) {
      a = line_angle(x, y, turns.back().angle);
      jump = a - turns.back().angle;
    }
    turns.push_back({j, t, x, y, static_cast<double>(r), E, a, jump});
    return true;
  }
  double rate(int* points = nullptr) const { return fit_precession_rate(turns, points); }
};

// ---------------------------------------------------------------------------------------------------
// Starting procedure
//
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

// ---------------------------------------------------------------------------------------------------
// Two discretizations of the constraint (13)
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

// The literal 3x3 linear system of one step, unknowns z = (x_{j+1}, y_{j+1}, lambda_1).
template <class T>
struct LinearStep {
  Mat3<T> A;
  Vec3<T> b;
};

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

// ---------------------------------------------------------------------------------------------------
// Continuous solution

// Closed form from (13). In the frame rotating with the plane, rho = R(s t) q (R: rotation), the
// Lagrange–d'Alembert equations below become rho'' = -(w2 - s^2) rho - alpha rho' (each component a
// damped linear oscillator), and q = R(-s t) rho, q' = R(-s t)(rho' - s J rho), J = rotation by +90 deg.
// Derivation: on (13), r' e_perp = J q' - s q (with q = r e), so the constraint force of the ODE below,
// lambda/m (y, -x), equals -alpha s J q - 2 s J q' + 2 s^2 q; substituting q = R(-s t) rho, the Coriolis
// and centrifugal terms of the rotating frame cancel these exactly. For consistent data rho' is parallel
// to rho (rho x rho' = Phi = 0), so the bob moves on a line through the origin that turns at the
// constant rate -s: the plane angle is theta(t) = theta0 - s t, and the signed radius obeys
// r'' = -(w2 - s^2) r - alpha r'.
template <class T>
struct FoucaultState {
  Vec2<T> q, v;
};

template <class T>
FoucaultState<T> foucault_exact(const FoucaultParams<T>& p, const Vec2<T>& q0, const Vec2<T>& v0_consistent, T t) {
  using std::cos;
  using std::sin;
  const Vec2<T> rho_dot0 = v0_consistent + p.s * constraint_covector(q0);  // v0 + s J q0
  const T b = p.w2 - p.s * p.s;
  const auto cx = linear_oscillator_solution<T>(p.alpha, b, q0(0), rho_dot0(0), t);
  const auto cy = linear_oscillator_solution<T>(p.alpha, b, q0(1), rho_dot0(1), t);
  const Vec2<T> rho(cx.q, cy.q), rho_dot(cx.v, cy.v);
  const T c = cos(p.s * t), sn = sin(p.s * t);  // R(-s t) = [[c, sn], [-sn, c]]
  auto rot = [&](const Vec2<T>& u) { return Vec2<T>(c * u(0) + sn * u(1), -sn * u(0) + c * u(1)); };
  return {rot(rho), rot(rho_dot - p.s * constraint_covector(rho))};
}

// The Lagrange–d'Alembert equations with a multiplier, made an ODE by differentiating (13):
//   x'' = -w2 x - alpha x' + lambda y/m,   y'' = -w2 y - alpha y' - lambda x/m,
//   lambda = m [alpha (y x' - x y') + 2 s (x x' + y y')] / (x^2 + y^2)
// (from -y x'' + x y'' + 2 s (x x' + y y') = 0). The multiplier is singular at the origin but the force
// lambda (y, -x)/m stays bounded; at r = 0 exactly (never met in practice) the equivalent on-constraint form
// -alpha s J q - 2 s J q' + 2 s^2 q is used. The one statement of this ODE: the systems' hand-written rhs and
// every Odeint or GSL baseline call it.
template <class T>
void foucault_multiplier_acceleration(T w2, T s, T alpha, T x, T y, T vx, T vy, T& ax, T& ay) {
  const T r2 = x * x + y * y;
  T fx, fy;  // constraint force per unit mass, lambda (y, -x)/m
  if (r2 > 0) {
    const T lm = (alpha * (y * vx - x * vy) + 2 * s * (x * vx + y * vy)) / r2;  // lambda/m
    fx = lm * y;
    fy = -lm * x;
  } else {  // -alpha s J q - 2 s J q' + 2 s^2 q at q = 0
    fx = 2 * s * vy;
    fy = -2 * s * vx;
  }
  ax = -w2 * x - alpha * vx + fx;
  ay = -w2 * y - alpha * vy + fy;
}

// The multiplier ODE on u = (x, y, x', y') for Odeint steppers and GSL (its constants evaluated once).
struct FoucaultMultiplierOde {
  double w2, s, a;
  explicit FoucaultMultiplierOde(const FoucaultParams<double>& p) : w2(p.w2), s(p.s), a(p.alpha) {}
  template <class State>
  void operator()(const State& u, State& du, double) const {
    du[0] = u[2];
    du[1] = u[3];
    foucault_multiplier_acceleration(w2, s, a, u[0], u[1], u[2], u[3], du[2], du[3]);
  }
};

namespace systems {

// ---------------------------------------------------------------------------------------------------
// The equations, written once over the combinations they use: mass(), w2() = g/l, damping() = alpha,
// s() = Omega sin(beta), phi0() (the rotation's plane at t = 0). The double systems below read them from their
// scene; the symbolic instantiations (FoucaultT<P>, FoucaultRotationT<P>, P a computer-algebra type) make each a
// symbol of its own, so the modified equations come as formulas in m, w2, alpha, s as docs/formulas.md writes them.

template <class P>
struct FoucaultT;
template <class P>
struct FoucaultRotationT;

template <class Self>
struct FoucaultDynamics {
  template <class S>
  S lagrangian(const S&, const Vec<S, 2>& q, const Vec<S, 2>& v) const {
    const Self& p = self();
    return p.mass() / 2 * v.squaredNorm() - p.mass() * p.w2() / 2 * q.squaredNorm();
  }
  template <class S>
  S herglotz(const S& t, const Vec<S, 2>& q, const Vec<S, 2>& v, const S& z) const {
    return lagrangian(t, q, v) - self().damping() * z;
  }
  template <class S>
  Vec<S, 2> force(const S&, const Vec<S, 2>&, const Vec<S, 2>& v) const {
    return -(self().damping() * self().mass()) * v;
  }

 private:
  const Self& self() const { return static_cast<const Self&>(*this); }
};

// The paper's constraint (13): A(q) = (-y, x), b = s |q|^2.
template <class Self>
struct PaperConstraint {
  template <class S>
  Mat<S, 1, 2> constraint_matrix(const S&, const Vec<S, 2>& q) const {
    return Mat<S, 1, 2>(-q(1), q(0));
  }
  template <class S>
  Vec<S, 1> constraint_offset(const S&, const Vec<S, 2>& q) const {
    return Vec<S, 1>::Constant(static_cast<const Self&>(*this).s() * q.squaredNorm());
  }
};

// The remedy's rheonomic holonomic constraint g(t, q) = n(phi(t)).q, phi(t) = phi_0 - s t.
template <class Self>
struct RotationConstraint {
  template <class S>
  Mat<S, 1, 2> constraint_matrix(const S& t, const Vec<S, 2>&) const {
    using std::cos;
    using std::sin;
    const S phi = plane(t);
    return Mat<S, 1, 2>(-sin(phi), cos(phi));
  }
  template <class S>
  Vec<S, 1> constraint_offset(const S& t, const Vec<S, 2>& q) const {
    using std::cos;
    using std::sin;
    const S phi = plane(t);
    return Vec<S, 1>::Constant(static_cast<const Self&>(*this).s() * (cos(phi) * q(0) + sin(phi) * q(1)));
  }
  template <class S>
  Vec<S, 1> holonomic(const S& t, const Vec<S, 2>& q) const {
    using std::cos;
    using std::sin;
    const S phi = plane(t);
    return Vec<S, 1>::Constant(-sin(phi) * q(0) + cos(phi) * q(1));
  }

 private:
  template <class S>
  S plane(const S& t) const {
    const Self& p = static_cast<const Self&>(*this);
    return S(p.phi0()) - p.s() * t;
  }
};

// ---------------------------------------------------------------------------------------------------
// The scene and what both constraint discretizations share

struct FoucaultPendulum : FoucaultDynamics<FoucaultPendulum> {
  static constexpr int dof = 2;
  static constexpr int constraints = 1;

  double m = 28;             // kg
  double l = 67;             // m
  double g = 9.81;           // m/s^2
  double beta_deg = 49;      // latitude, degrees
  double Omega = 7.2921e-5;  // Earth's angular velocity, rad/s
  double alpha = 1e-3;       // Rayleigh damping, 1/s
  double x0 = 0.67, y0 = 0;  // q(0), m
  double vx0 = 0, vy0 = 0;   // q'(0), m/s (the paper's (0, 0) violates (13): see FoucaultStart)
  double T = 3600;           // horizon, s

  template <class V>
  void visit(V&& v) {
    v("m", m, "mass (kg)");
    v("l", l, "length (m)");
    v("g", g, "gravity (m/s^2)");
    v("beta", beta_deg, "latitude (degrees)");
    v("Omega", Omega, "Earth's angular velocity (rad/s)");
    v("alpha", alpha, "Rayleigh damping (1/s)");
    v("x0", x0, "initial x (m)");
    v("y0", y0, "initial y (m)");
    v("vx0", vx0, "initial x' (m/s; projected onto (13))");
    v("vy0", vy0, "initial y' (m/s; projected onto (13))");
    v("T", T, "horizon (s)");
  }
  // Throws InputError naming the first bad parameter.
  void validate() const;
  double w2() const { return g / l; }
  double s() const;  // Omega sin(beta)
  double mass() const { return m; }
  double damping() const { return alpha; }
  double phi0() const { return std::atan2(y0, x0); }
  // The values of the symbolic instantiations' parameters (FoucaultSymbols below) at this scene.
  template <class V>
  void visit_symbols(V&& v) const {
    v("m", m);
    v("w2", w2());
    v("alpha", alpha);
    v("s", s());
    v("x0", x0);
    v("y0", y0);
  }
  // The physical parameters and initial data as header lines for output files.
  std::vector<std::pair<std::string, std::string>> header_params() const;
  // The projection onto (13) in closed form (consistent_velocity above), which the closed forms start from: the
  // generic step and the references start from the same bits.
  Vec<double, 2> project_velocity(double, const Vec<double, 2>& q, const Vec<double, 2>& v) const {
    return consistent_velocity(FoucaultParams<double>(*this), Vec2<double>(q), Vec2<double>(v));
  }
  // What a convergence study measures on a run beyond the error in q (below).
  class Measures;
  // The convergence tests run the first quarter swing: the paper's constraint is singular at the origin (first pass
  // at t = pi/(2 sqrt(w2 - s^2)) = 4.1 s, where a landing kicks the plane by s h / rho: docs/where-methods-fail.md), with a damping
  // large enough to be seen over 4 s.
  static Expectations expectations() {
    Expectations e;
    e.params = {{"T", 4}, {"alpha", 0.1}};
    e.why = "T = 4 s: before the first pass through the origin; alpha = 0.1: a visible damping";
    return e;
  }

  template <class S>
  Vec<S, 2> initial_position() const {
    return Vec<S, 2>(S(x0), S(y0));
  }
  template <class S>
  Vec<S, 2> initial_velocity() const {
    return Vec<S, 2>(S(vx0), S(vy0));
  }
  // The closed form (foucault_exact) from the consistent initial velocity.
  template <class S>
  Phase<S, 2> exact(const S& t) const {
    const FoucaultParams<S> p(*this);
    const Vec<S, 2> q0 = initial_position<S>();
    const auto x = foucault_exact<S>(p, q0, geomint::consistent_velocity<S>(p, q0, initial_velocity<S>()), t);
    return {x.q, x.v};
  }
  // The multiplier ODE (foucault_multiplier_acceleration).
  void rhs(double, const Vec<double, 2>& q, const Vec<double, 2>& v, Vec<double, 2>& a) const {
    foucault_multiplier_acceleration(w2(), s(), alpha, q(0), q(1), v(0), v(1), a(0), a(1));
  }

  // ---------------------------------------------------------------------------------------------------------
  // The paper's integrators: closed forms of the generic `la` and `contact` on both systems.

  struct La;
  struct Contact;
  using fast_paths = std::tuple<La, Contact>;

 protected:
  // N steps of closed form C on system Self (its own constraint row), reported as the generic scheme sees them:
  // p_j is that scheme's discrete Legendre transform of (q_{j-1}, q_j), z_j its action (the closed forms do not
  // carry z), lambda the impulse of the step into q_j.
  template <class Self, class C, class R, class Observer>
  static void run_as_generic(const Self& self, R h, long N, Observer&& observe);
  // The same q_j alone: observe(j, t_j, q_j). The two-step forms carry no momentum, so the generic p_j (and z_j)
  // beside them cost more than the step itself; a run that reads only q skips them.
  template <class Self, class C, class R, class Observer>
  static void positions_of(const Self& self, R h, long N, Observer&& observe);
};

// What a convergence study measures on a run of either constraint beyond the error in q (SystemInfo::measures),
// step j -> j+1 against the reference on a grid of h/2 (it holds t_j and t_{j+1/2}, with velocities):
//   energy_err    max_j |E_{j+1/2} - E_ref(t_{j+1/2})| / E0: the chord energy against the reference's energy
//   plane_err     max_j |angle(q_j) - angle(q_ref(t_j))| mod pi (rad), over the steps where the reference is in the
//                 outer half of its swing (|q_ref| >= |q0| e^{-alpha t/2}/2), where the polar angle is the plane's
//   rate_rel_err  |fitted precession rate / (-Omega sin beta) - 1| over the turning points (at least 3)
//   min_r         min_j |q_j| (m): how close the run passes by the origin, where (13) is singular
// The bob's distance from the reference, max_j |q_j - q_ref(t_j)| in the Euclidean norm, is the study's error
// with --norm 2.
class FoucaultPendulum::Measures {
 public:
  static std::vector<MeasureInfo> info();
  Measures(const FoucaultPendulum& sys, double h, long N, const Reference& ref);
  void operator()(long j, double t, const Vec<double, 2>& q);  // every q_j, j = 0..N, in order
  std::vector<double> values() const;

 private:
  FoucaultParams<double> p_;
  const Reference& ref_;
  double h_, alpha_, s_, r0_, E0_;
  long stride_;  // reference rows per step
  Vec2<double> qm_, q_;
  double t_ = 0;
  double energy_err_ = 0, plane_err_ = 0, min_r_;
  PlaneTurns plane_;
};

namespace detail {
template <class T>
void require_solvable(T r2, long j) {
  using std::isfinite;
  if (!(r2 > 0) || !isfinite(r2))
    throw NumericalFailure(j, "r_j^2",
                           "q_j is at the origin or not finite: the constraint (13) gives no equation for lambda");
}
// A paper step of either scheme through its component form: check r_j^2, solve, repack.
template <class Scheme, class T>
void paper_step(const FoucaultParams<T>& p, const Vec2<T>& qm, const Vec2<T>& q, T h, Vec2<T>& qn, T& lambda1, long j) {
  const T r2 = q.squaredNorm();
  require_solvable(r2, j);
  T xn, yn, lm;
  Scheme::step_xy(p, h, qm(0), qm(1), q(0), q(1), r2, xn, yn, lm);
  qn = Vec2<T>(xn, yn);
  lambda1 = lm * p.m;
}

// The constraint row of a rotation step, shared by both schemes: q_{j+1} = qh - mu n(phi_j) with
// n(phi_{j+1}).q_{j+1} = 0, built in the basis of the new line (n(phi_{j+1}) = (-e1, e0)).
template <class T>
inline void finish_rotation_step(T qhx, T qhy, T ln0, T ln1, T e0, T e1, T& xn, T& yn, T& mu) {
  const T n0 = -e1, n1 = e0;
  mu = (n0 * qhx + n1 * qhy) / (n0 * ln0 + n1 * ln1);
  const T r = (e0 * qhx + e1 * qhy) - mu * (e0 * ln0 + e1 * ln1);
  xn = r * e0;
  yn = r * e1;
}
}  // namespace detail

// Lagrange–d'Alembert nonholonomic integrator, eq. (15): the forced constrained discrete Euler–Lagrange
// equations (1) with L_d(q_j, q_{j+1}) = h L(q_j, (q_{j+1}-q_j)/h), F_d^-(q_j, q_{j+1}) = -alpha m (q_{j+1}-q_j),
// F_d^+ = 0, and the discrete constraint (13) o Psi. Rows 1-2 of (15) are m^{-1} times
//   D1 L_d(q_j, q_{j+1}) + D2 L_d(q_{j-1}, q_j) + F_d^-(q_j, q_{j+1}) = lambda_1 A(q_j),
// so lambda_1 is an impulse over one step (N s / m); the continuous multiplier is lambda_1 / h.
struct FoucaultPendulum::La {
  static constexpr const char* name = "(15)";
  static constexpr const char* alias = "la-nh";
  using solves = generic::LaLeft;

  template <class T>
  static T lambda_force(T lambda1, T h) {
    return lambda1 / h;
  }

  // Virtual q_{-1} of the chosen start (see FoucaultStart).
  template <class T>
  static Vec2<T> previous_point(const FoucaultParams<T>& p, const Vec2<T>& q0, const Vec2<T>& v0, T h,
                                FoucaultStart start) {
    if (start == FoucaultStart::taylor) return q0 - h * v0;
    return q0 - h * consistent_velocity(p, q0, v0);
  }

  // (15) as a linear system in (x_{j+1}, y_{j+1}, lambda_1).
  template <class T>
  static LinearStep<T> system(const FoucaultParams<T>& p, const Vec2<T>& qm, const Vec2<T>& q, T h) {
    const T xm = qm(0), ym = qm(1), x = q(0), y = q(1);
    const T c = 1 / h + p.alpha;
    LinearStep<T> ls;
    ls.A << -c, 0, y / p.m,  //
        0, -c, -x / p.m,     //
        -y / h, x / h, 0;
    ls.b << -(2 * x - xm) / h + h * p.w2 * x - p.alpha * x,  //
        -(2 * y - ym) / h + h * p.w2 * y - p.alpha * y,      //
        -p.s * (x * x + y * y);
    return ls;
  }

  // Closed form. Rows 1-2:  c q_{j+1} = c q_j + (q_j - q_{j-1})/h - h w2 q_j + (lambda_1/m)(y_j, -x_j),
  // c = 1/h + alpha. Row 3 is q_j x q_{j+1} = -s h r_j^2 (x: the planar cross product), and
  // q_j x (y_j, -x_j) = -r_j^2, q_j x q_j = 0, so
  //   lambda_1/m = c s h + (q_{j-1} x q_j) / (h r_j^2).
  // Round-off: q_{j-1} x q_j is computed directly, with absolute error ~ eps |q_{j-1}| |q_j|, which moves
  // q_{j+1} by ~ eps |q_{j-1}|, the size of the rounding of the inputs themselves. Writing it as
  // q_{j-1} x (q_j - q_{j-1}) instead looks better (no cancellation far from the origin) but near the
  // origin carries eps |q_{j-1}|^2 / r_j into q_{j+1}: 10^3-10^5 times worse when a step lands within
  // r_j << h |q'| of the origin (found by the long double comparison in tests/systems/foucault.test.cpp).
  // `j` only labels a NumericalFailure.
  template <class T>
  static void step(const FoucaultParams<T>& p, const Vec2<T>& qm, const Vec2<T>& q, T h, Vec2<T>& qn, T& lambda1,
                   long j = -1) {
    detail::paper_step<La>(p, qm, q, h, qn, lambda1, j);
  }

  // The closed form in components, r2 = x^2 + y^2 given: what step() and the structure-of-arrays ensembles
  // (foucault_ensemble.cpp) both call, so a run gives the same bits one at a time or many to a vector.
  // lm = lambda_1 / m. No check: the caller tests r2 (require_solvable) and the result.
  template <class T>
  static void step_xy(const FoucaultParams<T>& p, T h, T xm, T ym, T x, T y, T r2, T& xn, T& yn, T& lm) {
    const T c = 1 / h + p.alpha;
    // 1/h and 1/c are loop-invariant: multiplying by them keeps the only division per step the
    // data-dependent one by h r_j^2 (<= 1 ulp per product; the long double tests bound the result)
    const T ih = 1 / h, ic = 1 / c, hw2 = h * p.w2;
    lm = c * p.s * h + (xm * y - ym * x) / (h * r2);  // cross(q_{j-1}, q_j)
    xn = x + ((x - xm) * ih - hw2 * x + lm * y) * ic;
    yn = y + ((y - ym) * ih - hw2 * y + lm * -x) * ic;
  }

  // Closed form. Rows 1-2: q_{j+1} = qh - mu n(phi_j), with the unconstrained point
  // qh = q_j + ((q_j - q_{j-1})/h - h w2 q_j)/c and mu = lambda_1/(m c); row 3 gives
  // mu = n_{j+1}.qh / (n_{j+1}.n_j), n_{j+1}.n_j = cos(s h). q_{j+1} is then built in the basis of the new
  // line, q_{j+1} = (e_{j+1}.qh - mu e_{j+1}.n_j) e_{j+1}: the same solution in exact arithmetic, and in floating
  // point its angle is phi_{j+1} to round-off however close to the origin it lands.
  template <class T>
  static void step_rotation(const FoucaultParams<T>& p, const Vec2<T>& qm, const Vec2<T>& q, T h,
                            const FoucaultLine<T>& L, const FoucaultLine<T>& Ln, Vec2<T>& qn, T& lambda1) {
    const T c = 1 / h + p.alpha;
    T xn, yn, mu;
    step_rotation_xy(p, h, qm(0), qm(1), q(0), q(1), L.n(0), L.n(1), Ln.e(0), Ln.e(1), xn, yn, mu);
    qn = Vec2<T>(xn, yn);
    lambda1 = mu * p.m * c;
  }

  // In components (shared with the ensembles): (ln0, ln1) = n(phi_j), (e0, e1) = e(phi_{j+1}).
  template <class T>
  static void step_rotation_xy(const FoucaultParams<T>& p, T h, T xm, T ym, T x, T y, T ln0, T ln1, T e0, T e1,
                               T& xn, T& yn, T& mu) {
    const T c = 1 / h + p.alpha, hw2 = h * p.w2;
    const T qhx = x + ((x - xm) / h - hw2 * x) / c, qhy = y + ((y - ym) / h - hw2 * y) / c;
    detail::finish_rotation_step(qhx, qhy, ln0, ln1, e0, e1, xn, yn, mu);
  }

  // The continuous-equivalent (13) multiplier of a rotation step: lambda_force / r_j, r_j = e(phi_j).q_j.
  template <class T>
  static T lambda_force_rotation(T lambda1, T h, const Vec2<T>& q, const FoucaultLine<T>& L) {
    return lambda1 / h / L.e.dot(q);
  }
};

// Contact nonholonomic integrator, eq. (18): the constrained discrete Herglotz equations (4) with
// L_d(q_j, q_{j+1}, z_j) = h [ m/2 |(q_{j+1}-q_j)/h|^2 - (V(q_j) + V(q_{j+1}))/2 - alpha z_j ] (as in (10), (17)),
// so D3 L_d = -h alpha, D4 L_d = 0, and the same discrete constraint. Rows 1-2 of (18) are (m h)^{-1} times
//   D1 L_d(q_j, q_{j+1}) + D2 L_d(q_{j-1}, q_j) (1 - h alpha) = h lambda_1 A(q_j),
// so lambda_1 is already a force multiplier (kg/s), comparable with the continuous lambda.
struct FoucaultPendulum::Contact {
  static constexpr const char* name = "(18)";
  static constexpr const char* alias = "contact-nh";
  using solves = generic::ContactLeft;

  template <class T>
  static T lambda_force(T lambda1, T /*h*/) {
    return lambda1;
  }

  template <class T>
  static Vec2<T> previous_point(const FoucaultParams<T>& p, const Vec2<T>& q0, const Vec2<T>& v0, T h,
                                FoucaultStart start) {
    if (start == FoucaultStart::taylor) return q0 - h * v0;
    return q0 - h * consistent_velocity(p, q0, v0) - h * h * p.w2 / 2 * q0;
  }

  // (18) as a linear system in (x_{j+1}, y_{j+1}, lambda_1).
  template <class T>
  static LinearStep<T> system(const FoucaultParams<T>& p, const Vec2<T>& qm, const Vec2<T>& q, T h) {
    const T xm = qm(0), ym = qm(1), x = q(0), y = q(1);
    const T k = 1 / (h * h);
    LinearStep<T> ls;
    ls.A << -k, 0, y / p.m,  //
        0, -k, -x / p.m,     //
        -y / h, x / h, 0;
    ls.b << -(2 * x - xm) * k + p.w2 * x + p.alpha * ((x - xm) / h - h * p.w2 / 2 * x),  //
        -(2 * y - ym) * k + p.w2 * y + p.alpha * ((y - ym) / h - h * p.w2 / 2 * y),      //
        -p.s * (x * x + y * y);
    return ls;
  }

  // Closed form. Rows 1-2:
  //   q_{j+1} = q_j + (1 - h alpha)(q_j - q_{j-1}) - h^2 w2 (1 - h alpha/2) q_j + h^2 (lambda_1/m)(y_j, -x_j),
  // and row 3, q_j x q_{j+1} = -s h r_j^2, with q_j x q_j = 0, gives
  //   lambda_1/m = [ s h r_j^2 + (1 - h alpha) q_{j-1} x q_j ] / (h^2 r_j^2)
  // (q_{j-1} x q_j computed directly: see La::step for why).
  template <class T>
  static void step(const FoucaultParams<T>& p, const Vec2<T>& qm, const Vec2<T>& q, T h, Vec2<T>& qn, T& lambda1,
                   long j = -1) {
    detail::paper_step<Contact>(p, qm, q, h, qn, lambda1, j);
  }

  // In components, r2 = x^2 + y^2 given (shared with the ensembles; see La::step_xy). lm = lambda_1 / m.
  template <class T>
  static void step_xy(const FoucaultParams<T>& p, T h, T xm, T ym, T x, T y, T r2, T& xn, T& yn, T& lm) {
    const T damp = 1 - h * p.alpha;
    const T k = h * h * p.w2 * (1 - h * p.alpha / 2), hh = h * h;
    lm = (p.s * h * r2 + damp * (xm * y - ym * x)) / (hh * r2);  // cross(q_{j-1}, q_j)
    const T g = hh * lm;
    xn = x + damp * (x - xm) - k * x + g * y;
    yn = y + damp * (y - ym) - k * y + g * -x;
  }

  // Closed form: q_{j+1} = qh - mu n(phi_j) with
  // qh = q_j + (1 - h alpha)(q_j - q_{j-1}) - h^2 w2 (1 - h alpha/2) q_j and mu = h^2 lambda_1/m
  // = n_{j+1}.qh / (n_{j+1}.n_j), built in the basis of the new line (see La::step_rotation).
  template <class T>
  static void step_rotation(const FoucaultParams<T>& p, const Vec2<T>& qm, const Vec2<T>& q, T h,
                            const FoucaultLine<T>& L, const FoucaultLine<T>& Ln, Vec2<T>& qn, T& lambda1) {
    T xn, yn, mu;
    step_rotation_xy(p, h, qm(0), qm(1), q(0), q(1), L.n(0), L.n(1), Ln.e(0), Ln.e(1), xn, yn, mu);
    qn = Vec2<T>(xn, yn);
    lambda1 = mu * p.m / (h * h);
  }

  // In components (shared with the ensembles): (ln0, ln1) = n(phi_j), (e0, e1) = e(phi_{j+1}).
  template <class T>
  static void step_rotation_xy(const FoucaultParams<T>& p, T h, T xm, T ym, T x, T y, T ln0, T ln1, T e0, T e1,
                               T& xn, T& yn, T& mu) {
    const T damp = 1 - h * p.alpha, k = h * h * p.w2 * (1 - h * p.alpha / 2);
    const T qhx = x + damp * (x - xm) - k * x, qhy = y + damp * (y - ym) - k * y;
    detail::finish_rotation_step(qhx, qhy, ln0, ln1, e0, e1, xn, yn, mu);
  }

  template <class T>
  static T lambda_force_rotation(T lambda1, T /*h*/, const Vec2<T>& q, const FoucaultLine<T>& L) {
    return lambda1 / L.e.dot(q);
  }
};

// ---------------------------------------------------------------------------------------------------
// The two systems

struct Foucault : FoucaultPendulum, PaperConstraint<Foucault> {
  static constexpr const char* name = "foucault";
  static constexpr const char* description = "damped Foucault pendulum (Section 3.2) with the nonholonomic constraint (13)";
  static constexpr const char* discretization = "paper";  // the third row of (15), (18): (13) o Psi
  static constexpr bool linear_dynamics = true;  // L quadratic, F linear; (13)'s A and b are not affine
  using PaperConstraint<Foucault>::constraint_matrix;
  using PaperConstraint<Foucault>::constraint_offset;
  template <class P>
  using symbolic = FoucaultT<P>;  // the same equations with symbolic parameters (below)

  // Steps j = j0 .. j1-1 of closed form C from (q_{j0-1}, q_{j0}) with the paper's third row: the observer is
  // called with the step j -> j+1 (FoucaultStep), so it sees every q_j, j = j0..j1. t_j = j h (never
  // accumulated); phi0 is not used. No allocation happens here. A mid-run start (j0 > 0) reruns a stretch of a
  // run, e.g. in a wider precision from the double state just before it.
  template <class C, class T, class Observer>
  void closed_steps(const FoucaultParams<T>& p, Vec2<T> qm, Vec2<T> q, long j0, long j1, T h, T /*phi0*/,
                    Observer&& observe) const {
    using std::isfinite;
    Vec2<T> qn;
    T lambda1;
    const T nan = T(missing_value);  // no residual: a closed form solves nothing
    for (long j = j0; j < j1; ++j) {
      C::step(p, qm, q, h, qn, lambda1, j);
      if (!isfinite(qn(0)) || !isfinite(qn(1))) throw state_failure(j);
      observe(FoucaultStep<T>{j, T(j) * h, qm, q, qn, lambda1, C::lambda_force(lambda1, h), nan});
      qm = q;
      q = qn;
    }
  }

  // The discrete constraint this system imposes at a step, and its round-off scale (for diagnostics).
  template <class T>
  static T imposed_constraint(const FoucaultParams<T>& p, const FoucaultStep<T>& st, T h) {
    return discrete_constraint(p, st.q, st.qn, h);
  }
  template <class T>
  static T imposed_constraint_scale(const FoucaultStep<T>& st, T h) {
    return discrete_constraint_scale(st.q, st.qn, h);
  }

  template <class C, class R, class Observer>
  void run_fast(R h, long N, Observer&& observe) const {
    run_as_generic<Foucault, C>(*this, h, N, observe);
  }
  template <class C, class R, class Observer>
  void run_positions(R h, long N, Observer&& observe) const {
    positions_of<Foucault, C>(*this, h, N, observe);
  }
};

// The remedy: in polar coordinates q = r e(theta), (13) reads r^2 (theta' + s) = 0, so on consistent data the
// plane turns at exactly -s and (13) is r times the derivative of g(t, q) = n(phi(t)).q (see above). Its
// closed forms carry the plane angle as state, phi_j = phi_0 - s t_j, and are regular at the origin.
struct FoucaultRotation : FoucaultPendulum, RotationConstraint<FoucaultRotation> {
  static constexpr const char* name = "foucault-rotation";
  static constexpr const char* description =
      "damped Foucault pendulum, constraint (13) as the exact rotation of the plane (the remedy for the anomaly)";
  static constexpr const char* discretization = "rotation";  // n(phi_{j+1}).q_{j+1} = 0, force along n(phi_j)
  // Not `linear`: each step is a linear solve, but its matrix turns with the plane (A = n(phi(t_j))), so a kept
  // Jacobian is stale — the linear lane's check caught this declaration. Linear dynamics with g = n(phi(t)).q
  // affine in q: the single-update path brings the constraint block of the kept Jacobian up to date every step.
  static constexpr bool linear_dynamics = true;

  using RotationConstraint<FoucaultRotation>::constraint_matrix;
  using RotationConstraint<FoucaultRotation>::constraint_offset;
  using RotationConstraint<FoucaultRotation>::holonomic;
  template <class P>
  using symbolic = FoucaultRotationT<P>;

  // Steps j = j0 .. j1-1 of closed form C with the rotation row (see Foucault::closed_steps); phi0 is the plane
  // angle at t = 0 (phi_j = phi0 - s t_j).
  template <class C, class T, class Observer>
  void closed_steps(const FoucaultParams<T>& p, Vec2<T> qm, Vec2<T> q, long j0, long j1, T h, T phi0,
                    Observer&& observe) const {
    using std::isfinite;
    Vec2<T> qn;
    T lambda1;
    // The line of q_k is at phi_k = phi0 - s t_k. Its cos and sin are evaluated afresh every K steps (the
    // anchor) and in between by one rotation from a table of the rotations by -s h b, b < K: the same
    // direction to a few ulps (tests/studies/foucault_anomaly.test.cpp checks the angle of every q_k against
    // phi0 - s t_k), without a sincos per step (which would double the cost of a step).
    const RotationTable<T> rot(p.s, h);
    FoucaultLine<T> anchor = foucault_line<T>(phi0 - p.s * (T(j0) * h)), L = anchor, Ln;
    long b = 0;
    for (long j = j0; j < j1; ++j) {
      const T phin = phi0 - p.s * (T(j + 1) * h);
      if (++b == RotationTable<T>::K) {
        b = 0;
        anchor = foucault_line<T>(phin);
        Ln = anchor;
      } else {
        T e0, e1;
        rot.line(b, anchor.e(0), anchor.e(1), e0, e1);
        Ln.e = Vec2<T>(e0, e1);
        Ln.n = Vec2<T>(-e1, e0);
      }
      C::step_rotation(p, qm, q, h, L, Ln, qn, lambda1);
      if (!isfinite(qn(0)) || !isfinite(qn(1))) throw state_failure(j);
      observe(FoucaultStep<T>{j, T(j) * h, qm, q, qn, lambda1, C::lambda_force_rotation(lambda1, h, q, L), phin});
      qm = q;
      q = qn;
      L = Ln;
    }
  }

  // The constraint this system imposes, n(phi_{j+1}).q_{j+1}, scaled by |q_j| + |q_{j+1}| (the size of the
  // step's inputs and output).
  template <class T>
  static T imposed_constraint(const FoucaultParams<T>&, const FoucaultStep<T>& st, T) {
    return foucault_line<T>(st.phin).n.dot(st.qn);
  }
  template <class T>
  static T imposed_constraint_scale(const FoucaultStep<T>& st, T) {
    return T(st.q.norm() + st.qn.norm());
  }

  template <class C, class R, class Observer>
  void run_fast(R h, long N, Observer&& observe) const {
    run_as_generic<FoucaultRotation, C>(*this, h, N, observe);
  }
  template <class C, class R, class Observer>
  void run_positions(R h, long N, Observer&& observe) const {
    positions_of<FoucaultRotation, C>(*this, h, N, observe);
  }
};

// The symbolic instantiations: the same equations (FoucaultDynamics and the constraint rows above) with each
// combination a parameter of type P (a computer-algebra symbol; geomint/modified/symbolic_system.hpp).
// FoucaultT<double> is not the registered system (that is Foucault, whose parameters are the physical scene).
template <class P>
struct FoucaultSymbols {
  static constexpr int dof = 2;
  static constexpr int constraints = 1;
  P m = 0, w2_ = 0, alpha = 0, s_ = 0, x0 = 0, y0 = 0;
  template <class V>
  void visit(V&& v) {
    v("m", m, "mass");
    v("w2", w2_, "g/l");
    v("alpha", alpha, "Rayleigh damping");
    v("s", s_, "Omega sin(beta)");
    v("x0", x0, "initial x");
    v("y0", y0, "initial y");
  }
  const P& mass() const { return m; }
  const P& w2() const { return w2_; }
  const P& damping() const { return alpha; }
  const P& s() const { return s_; }
};
template <class P>
struct FoucaultT : FoucaultSymbols<P>, FoucaultDynamics<FoucaultT<P>>, PaperConstraint<FoucaultT<P>> {
  static constexpr const char* name = Foucault::name;
};
template <class P>
struct FoucaultRotationT : FoucaultSymbols<P>, FoucaultDynamics<FoucaultRotationT<P>>,
                           RotationConstraint<FoucaultRotationT<P>> {
  static constexpr const char* name = FoucaultRotation::name;
  // phi_0 = atan2(y0, x0), as a formula in the initial position's symbols
  P phi0() const { return atan2(this->y0, this->x0); }
};

// N steps of closed form C on system Sys (Foucault or FoucaultRotation) from the scene's initial data (q0, v0),
// in the scalar T: the observer is called for j = 0 .. N-1 with the step j -> j+1, so it sees every q_j,
// j = 0..N. phi_0 = atan2(y0, x0) in T (the rotation's plane at t = 0; for consistent data the exact plane passes
// through q_0).
template <class C, class Sys, class T, class Observer>
void run_closed_form(const Sys& sys, const FoucaultParams<T>& p, const Vec2<T>& q0, const Vec2<T>& v0, T h, long N,
                     FoucaultStart start, Observer&& observe) {
  using std::atan2;
  sys.template closed_steps<C>(p, C::previous_point(p, q0, v0, h, start), q0, 0, N, h, atan2(q0(1), q0(0)), observe);
}

template <class Self, class C, class R, class Observer>
void FoucaultPendulum::run_as_generic(const Self& self, R h, long N, Observer&& observe) {
  using Generic = typename C::solves;
  const FoucaultParams<R> p(self);
  const Vec<R, 2> q0 = self.template initial_position<R>(), v0 = self.template initial_velocity<R>();
  Vec<R, 2> pj = Generic::initial_momentum(self, R(0), q0, geomint::consistent_velocity<R>(p, q0, v0), R(0));
  R z = 0;
  Vec<R, 1> lambda = Vec<R, 1>::Zero();
  Vec<R, 2> qlast = q0;
  run_closed_form<C>(self, p, q0, v0, h, N, FoucaultStart::legendre, [&](const FoucaultStep<R>& st) {
    observe(generic::StepView<R, 2, 1>{st.j, st.t, st.q, pj, z, lambda});
    // the generic impulse: (15)'s lambda_1 for LA, h lambda_1 for contact ((18)'s rows are divided by h)
    lambda(0) = Generic::contact ? h * st.lambda1 : st.lambda1;
    if constexpr (Generic::contact) {
      const R zn = Generic::next_z(self, st.t, h, st.q, st.qn, z);
      pj = Generic::p_minus(self, st.t, h, st.q, st.qn, z, zn);
      z = zn;
    } else {
      pj = Generic::p_minus(self, st.t, h, st.q, st.qn);
    }
    qlast = st.qn;
  });
  observe(generic::StepView<R, 2, 1>{N, R(N) * h, qlast, pj, z, lambda});
}

template <class Self, class C, class R, class Observer>
void FoucaultPendulum::positions_of(const Self& self, R h, long N, Observer&& observe) {
  const FoucaultParams<R> p(self);
  const Vec<R, 2> q0 = self.template initial_position<R>(), v0 = self.template initial_velocity<R>();
  Vec<R, 2> qlast = q0;
  run_closed_form<C>(self, p, q0, v0, h, N, FoucaultStart::legendre, [&](const FoucaultStep<R>& st) {
    observe(st.j, st.t, st.q);
    qlast = st.qn;
  });
  observe(N, R(N) * h, qlast);
}

// Calls f(Foucault{}) or f(FoucaultRotation{}) for a system name, or for the name of its discretization of (13)
// ("paper", "rotation"); InputError naming them otherwise. For the typed code of the two systems (ensembles).
template <class F>
decltype(auto) visit_foucault_system(const std::string& name, F&& f) {
  if (name == Foucault::name || name == Foucault::discretization) return f(Foucault{});
  if (name == FoucaultRotation::name || name == FoucaultRotation::discretization) return f(FoucaultRotation{});
  throw InputError("unknown constraint discretization '" + name +
                   "' of the Foucault pendulum (known: paper = system foucault, rotation = system foucault-rotation)");
}

// The registry name of a Foucault system given by name or by its discretization, and its discretization's name.
inline std::string foucault_system_name(const std::string& name) {
  return visit_foucault_system(name, [](auto s) { return std::string(decltype(s)::name); });
}
inline std::string foucault_discretization(const std::string& name) {
  return visit_foucault_system(name, [](auto s) { return std::string(decltype(s)::discretization); });
}

}  // namespace systems

template <class T>
FoucaultParams<T>::FoucaultParams(const systems::FoucaultPendulum& sc)
    : m(sc.m), w2(T(sc.g) / T(sc.l)), s(T(sc.Omega) * sin_deg(T(sc.beta_deg))), alpha(sc.alpha) {}

// The Boost.Odeint reference (dense-output dopri5 at tolerance `tol`) of the multiplier ODE from
// (q0, consistent_velocity(q0, v0)): (x, y, x', y') at every time.
std::vector<std::array<double, 4>> foucault_reference(const systems::FoucaultPendulum& scene,
                                                      const std::vector<double>& times, double tol = 1e-12);

// Checks a sweep before anything is written: at least one h and one alpha, every h divides T, and the scene
// is valid at every alpha (throws InputError).
void validate_foucault_sweep(const systems::FoucaultPendulum& base, const std::vector<double>& hs,
                             const std::vector<double>& alphas);

}  // namespace geomint
