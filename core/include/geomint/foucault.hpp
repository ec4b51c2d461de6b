#pragma once
// The damped Foucault pendulum of Section 3.2, reduced to the plane q = (x, y):
//   L = m/2 |q'|^2 - m w2/2 |q|^2  (12), (14),   w2 = g/l,
//   Rayleigh force F = -alpha m q'  (LA)   or   L - alpha z  (Herglotz, (16)),
//   nonholonomic constraint (13):  Phi(q, q') = -y x' + x y' + s (x^2 + y^2) = 0,   s = Omega sin(beta).
// Writing A(q) = (-y, x) for the covector of (13), Phi = A(q).q' + s |q|^2: affine in q'.
//
// What is here, in the order of the design (scene -> scheme -> integrate -> observer):
//   FoucaultScene            parameters, initial data, horizon (double; validate() for user input)
//   FoucaultParams<T>        the scalars a step needs, in the scalar type T (double, long double, ...)
//   schemes::LaNh            the LA nonholonomic integrator, eq. (15)            name "la-nh"
//   schemes::ContactNh       the contact nonholonomic integrator, eq. (18)       name "contact-nh"
//   FoucaultStart            how q_1 is obtained from (q0, q0') (see below)
//   FoucaultConstraint       which discretization of (13): "paper" (the third row of (15), (18); default)
//                            or "rotation" (the remedy: the plane angle carried exactly; see below)
//   integrate_foucault       fixed count of steps, two-step recurrence (q_{j-1}, q_j) -> (q_j, q_{j+1})
//   FoucaultDiagnostics<T>   observer: energy, constraint residual, lambda, min distance, plane angle
//   foucault_exact / foucault_reference   closed-form solution and the Boost.Odeint reference
//
// Both steps are linear in (q_{j+1}, lambda): the two dynamic rows give q_{j+1} as an affine function
// of lambda, and substituting that into the discrete constraint (the third row, (13) composed with the
// discretizing map Psi(q_j, q_{j+1}) = (q_j, (q_{j+1} - q_j)/h)) gives lambda in closed form, with
// r_j^2 = x_j^2 + y_j^2 in the denominator. `system()` builds the literal 3x3 system for tests and for
// an Eigen PartialPivLU cross-check; `residual()` restates the equations as printed.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "geomint/error.hpp"
#include "geomint/oscillator.hpp"  // linear_oscillator_solution

namespace geomint {

inline constexpr double foucault_pi = 3.14159265358979323846;

template <class T>
using Vec2 = Eigen::Matrix<T, 2, 1>;
template <class T>
using Vec3 = Eigen::Matrix<T, 3, 1>;
template <class T>
using Mat3 = Eigen::Matrix<T, 3, 3>;

// ---------------------------------------------------------------------------------------------------
// Scene

struct FoucaultScene {
  double m = 28;             // kg
  double l = 67;             // m
  double g = 9.81;           // m/s^2
  double beta_deg = 49;      // latitude, degrees
  double Omega = 7.2921e-5;  // Earth's angular velocity, rad/s
  double alpha = 1e-3;       // Rayleigh damping, 1/s
  double x0 = 0.67, y0 = 0;  // q(0), m
  double vx0 = 0, vy0 = 0;   // q'(0), m/s (the paper's (0, 0) violates (13): see FoucaultStart)
  double T = 3600;           // horizon, s
  // Throws InputError naming the first bad parameter.
  void validate() const;
  double w2() const { return g / l; }
  double s() const;  // Omega sin(beta)
};

// The scene's physical parameters and initial data as header lines for output files.
std::vector<std::pair<std::string, std::string>> foucault_scene_params(const FoucaultScene& sc);

// Checks a sweep before anything is written: at least one h and one alpha, every h divides T, and the scene
// is valid at every alpha (throws InputError).
void validate_foucault_sweep(const FoucaultScene& base, const std::vector<double>& hs, const std::vector<double>& alphas);

// The scalars of one run in the scalar type T. sin(beta) is evaluated in T, so a long double run is a
// long double run of the same (double) scene, not a long double run of a rounded s.
template <class T>
struct FoucaultParams {
  T m, w2, s, alpha;
  explicit FoucaultParams(const FoucaultScene& sc)
      : m(sc.m), w2(T(sc.g) / T(sc.l)), s(T(sc.Omega) * sin_deg(T(sc.beta_deg))), alpha(sc.alpha) {}

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
// Requires q != 0 (FoucaultScene::validate refuses q0 = 0).
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
//     O(h^2) at small alpha only with this start; see convergence_foucault).
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
// paper (default; reproduces Section 3.2): the third row of (15) and (18), (13) o Psi,
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
// rotation (the remedy): in polar coordinates q = r e(theta), (13) reads r^2 (theta' + s) = 0: off the
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
enum class FoucaultConstraint { paper, rotation };

FoucaultConstraint parse_foucault_constraint(const std::string& name);  // InputError for an unknown name
const char* to_string(FoucaultConstraint c);

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

namespace schemes {

namespace detail {
template <class T>
void require_solvable(T r2, long j) {
  using std::isfinite;
  if (!(r2 > 0) || !isfinite(r2))
    throw NumericalFailure(j, "r_j^2",
                           "q_j is at the origin or not finite: the constraint (13) gives no equation for lambda");
}
}  // namespace detail

namespace detail {
// The rotation discretization changes the same entries of either scheme's 3x3 system: the force column
// becomes -n(phi_j)/m and the constraint row n(phi_{j+1}) . q_{j+1} = 0.
template <class T>
LinearStep<T> to_rotation_system(LinearStep<T> ls, const FoucaultParams<T>& p, const FoucaultLine<T>& L,
                                 const FoucaultLine<T>& Ln) {
  ls.A(0, 2) = -L.n(0) / p.m;
  ls.A(1, 2) = -L.n(1) / p.m;
  ls.A(2, 0) = Ln.n(0);
  ls.A(2, 1) = Ln.n(1);
  ls.b(2) = 0;
  return ls;
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
struct LaNh {
  static constexpr const char* name = "la-nh";
  static constexpr int order = 1;

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

  // (15) as printed, left-hand sides of the three rows.
  template <class T>
  static Vec3<T> residual(const FoucaultParams<T>& p, const Vec2<T>& qm, const Vec2<T>& q, const Vec2<T>& qn,
                          T lambda1, T h) {
    const T xm = qm(0), ym = qm(1), x = q(0), y = q(1), xn = qn(0), yn = qn(1);
    Vec3<T> r;
    r(0) = (-xn + 2 * x - xm) / h - h * p.w2 * x - p.alpha * (xn - x) + lambda1 * y / p.m;
    r(1) = (-yn + 2 * y - ym) / h - h * p.w2 * y - p.alpha * (yn - y) - lambda1 * x / p.m;
    r(2) = -y * (xn - x) / h + x * (yn - y) / h + p.s * (x * x + y * y);
    return r;
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
  // r_j << h |q'| of the origin (found by the long double comparison in tests/foucault.test.cpp).
  // `j` only labels a NumericalFailure.
  template <class T>
  static void step(const FoucaultParams<T>& p, const Vec2<T>& qm, const Vec2<T>& q, T h, Vec2<T>& qn, T& lambda1,
                   long j = -1) {
    detail::paper_step<LaNh>(p, qm, q, h, qn, lambda1, j);
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

  // ----- rotation discretization of (13) (see FoucaultConstraint): L = line of phi_j, Ln = line of phi_{j+1}.
  // Rows 1-2 of (15) with lambda_1 (y_j, -x_j)/m = -lambda_1 A(q_j)/m replaced by -lambda_1 n(phi_j)/m;
  // row 3: n(phi_{j+1}).q_{j+1}. lambda_1 is an impulse (N s); lambda_1/h is the force.
  template <class T>
  static Vec3<T> residual_rotation(const FoucaultParams<T>& p, const Vec2<T>& qm, const Vec2<T>& q,
                                   const Vec2<T>& qn, T lambda1, T h, const FoucaultLine<T>& L,
                                   const FoucaultLine<T>& Ln) {
    const T xm = qm(0), ym = qm(1), x = q(0), y = q(1), xn = qn(0), yn = qn(1);
    Vec3<T> r;
    r(0) = (-xn + 2 * x - xm) / h - h * p.w2 * x - p.alpha * (xn - x) - lambda1 * L.n(0) / p.m;
    r(1) = (-yn + 2 * y - ym) / h - h * p.w2 * y - p.alpha * (yn - y) - lambda1 * L.n(1) / p.m;
    r(2) = Ln.n(0) * xn + Ln.n(1) * yn;
    return r;
  }

  template <class T>
  static LinearStep<T> system_rotation(const FoucaultParams<T>& p, const Vec2<T>& qm, const Vec2<T>& q, T h,
                                       const FoucaultLine<T>& L, const FoucaultLine<T>& Ln) {
    return detail::to_rotation_system(system(p, qm, q, h), p, L, Ln);
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
struct ContactNh {
  static constexpr const char* name = "contact-nh";
  static constexpr int order = 1;

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

  // (18) as printed, left-hand sides of the three rows.
  template <class T>
  static Vec3<T> residual(const FoucaultParams<T>& p, const Vec2<T>& qm, const Vec2<T>& q, const Vec2<T>& qn,
                          T lambda1, T h) {
    const T xm = qm(0), ym = qm(1), x = q(0), y = q(1), xn = qn(0), yn = qn(1);
    Vec3<T> r;
    r(0) = (-xn + 2 * x - xm) / (h * h) - p.w2 * x - p.alpha * ((x - xm) / h - h * p.w2 / 2 * x) +
           lambda1 * y / p.m;
    r(1) = (-yn + 2 * y - ym) / (h * h) - p.w2 * y - p.alpha * ((y - ym) / h - h * p.w2 / 2 * y) -
           lambda1 * x / p.m;
    r(2) = -y * (xn - x) / h + x * (yn - y) / h + p.s * (x * x + y * y);
    return r;
  }

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
  // (q_{j-1} x q_j computed directly: see LaNh::step for why).
  template <class T>
  static void step(const FoucaultParams<T>& p, const Vec2<T>& qm, const Vec2<T>& q, T h, Vec2<T>& qn, T& lambda1,
                   long j = -1) {
    detail::paper_step<ContactNh>(p, qm, q, h, qn, lambda1, j);
  }

  // In components, r2 = x^2 + y^2 given (shared with the ensembles; see LaNh::step_xy). lm = lambda_1 / m.
  template <class T>
  static void step_xy(const FoucaultParams<T>& p, T h, T xm, T ym, T x, T y, T r2, T& xn, T& yn, T& lm) {
    const T damp = 1 - h * p.alpha;
    const T k = h * h * p.w2 * (1 - h * p.alpha / 2), hh = h * h;
    lm = (p.s * h * r2 + damp * (xm * y - ym * x)) / (hh * r2);  // cross(q_{j-1}, q_j)
    const T g = hh * lm;
    xn = x + damp * (x - xm) - k * x + g * y;
    yn = y + damp * (y - ym) - k * y + g * -x;
  }

  // ----- rotation discretization of (13) (see FoucaultConstraint): rows 1-2 of (18) with
  // lambda_1 (y_j, -x_j)/m replaced by -lambda_1 n(phi_j)/m; row 3: n(phi_{j+1}).q_{j+1}. lambda_1 is a force (N).
  template <class T>
  static Vec3<T> residual_rotation(const FoucaultParams<T>& p, const Vec2<T>& qm, const Vec2<T>& q,
                                   const Vec2<T>& qn, T lambda1, T h, const FoucaultLine<T>& L,
                                   const FoucaultLine<T>& Ln) {
    const T xm = qm(0), ym = qm(1), x = q(0), y = q(1), xn = qn(0), yn = qn(1);
    Vec3<T> r;
    r(0) = (-xn + 2 * x - xm) / (h * h) - p.w2 * x - p.alpha * ((x - xm) / h - h * p.w2 / 2 * x) -
           lambda1 * L.n(0) / p.m;
    r(1) = (-yn + 2 * y - ym) / (h * h) - p.w2 * y - p.alpha * ((y - ym) / h - h * p.w2 / 2 * y) -
           lambda1 * L.n(1) / p.m;
    r(2) = Ln.n(0) * xn + Ln.n(1) * yn;
    return r;
  }

  template <class T>
  static LinearStep<T> system_rotation(const FoucaultParams<T>& p, const Vec2<T>& qm, const Vec2<T>& q, T h,
                                       const FoucaultLine<T>& L, const FoucaultLine<T>& Ln) {
    return detail::to_rotation_system(system(p, qm, q, h), p, L, Ln);
  }

  // Closed form: q_{j+1} = qh - mu n(phi_j) with
  // qh = q_j + (1 - h alpha)(q_j - q_{j-1}) - h^2 w2 (1 - h alpha/2) q_j and mu = h^2 lambda_1/m
  // = n_{j+1}.qh / (n_{j+1}.n_j), built in the basis of the new line (see LaNh::step_rotation).
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

}  // namespace schemes

// Calls f(schemes::LaNh{}) or f(schemes::ContactNh{}) by name; InputError naming both otherwise.
template <class F>
decltype(auto) visit_foucault_scheme(const std::string& name, F&& f) {
  if (name == schemes::LaNh::name) return f(schemes::LaNh{});
  if (name == schemes::ContactNh::name) return f(schemes::ContactNh{});
  throw InputError("unknown scheme '" + name + "' (known: la-nh contact-nh)");
}
const std::vector<std::string>& foucault_scheme_names();

// ---------------------------------------------------------------------------------------------------
// Integration

// One step as an observer sees it: q_{j-1} (virtual for j = 0), q_j, q_{j+1}, and the multiplier of the
// step j -> j+1 (lambda_1 as in the paper, and the continuous-equivalent force multiplier).
// For the rotation discretization the step also carries the plane angle phi_{j+1} of q_{j+1}'s line.
template <class T>
struct FoucaultStep {
  long j;
  T t;  // t_j = j h
  const Vec2<T>& qm;
  const Vec2<T>& q;
  const Vec2<T>& qn;
  T lambda1, lambda;
  FoucaultConstraint constraint;
  T phin;  // phi_{j+1} = phi_0 - s t_{j+1} (rotation); NaN for paper
};

// The failure of step j -> j+1 when q_{j+1} is not finite.
inline NumericalFailure state_failure(long j) { return NumericalFailure(j + 1, "state", "non-finite q_{j+1}"); }

// The rotations R(-s h b), b < K, that carry the line of the rotation discretization from its anchor (evaluated
// with cos and sin every K steps) to the K - 1 steps after it. Shared by integrate_foucault_steps and the
// ensembles, so both turn a line by the same arithmetic.
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

// Steps j = j0 .. j1-1 of `Scheme` from (q_{j0-1}, q_{j0}): the observer is called with the step j -> j+1, so
// it sees every q_j, j = j0..j1. t_j = j h (never accumulated). For the rotation discretization phi_0 is the
// plane angle at t = 0 (phi_j = phi_0 - s t_j); it is unused for paper. No allocation happens here.
// integrate_foucault below is this with j0 = 0 after the start; this form restarts a run mid-way (e.g. a
// higher-precision rerun of one pass from the double state just before it).
template <class Scheme, class T, class Observer>
void integrate_foucault_steps(const FoucaultParams<T>& p, Vec2<T> qm, Vec2<T> q, long j0, long j1, T h,
                              FoucaultConstraint constraint, T phi0, Observer&& observe) {
  using std::isfinite;
  Vec2<T> qn;
  T lambda1;
  if (constraint == FoucaultConstraint::paper) {
    const T nan = std::numeric_limits<T>::quiet_NaN();
    for (long j = j0; j < j1; ++j) {
      Scheme::step(p, qm, q, h, qn, lambda1, j);
      if (!isfinite(qn(0)) || !isfinite(qn(1))) throw state_failure(j);
      observe(FoucaultStep<T>{j, T(j) * h, qm, q, qn, lambda1, Scheme::lambda_force(lambda1, h),
                              FoucaultConstraint::paper, nan});
      qm = q;
      q = qn;
    }
    return;
  }
  // The line of q_k is at phi_k = phi0 - s t_k. Its cos and sin are evaluated afresh every K steps (the
  // anchor) and in between by one rotation from a table of the rotations by -s h b, b < K: the same
  // direction to a few ulps (tests/foucault_anomaly.test.cpp checks the angle of every q_k against
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
    Scheme::step_rotation(p, qm, q, h, L, Ln, qn, lambda1);
    if (!isfinite(qn(0)) || !isfinite(qn(1))) throw state_failure(j);
    observe(FoucaultStep<T>{j, T(j) * h, qm, q, qn, lambda1, Scheme::lambda_force_rotation(lambda1, h, q, L),
                            FoucaultConstraint::rotation, phin});
    qm = q;
    q = qn;
    L = Ln;
  }
}

// N steps of `Scheme` from (q0, v0): the observer is called for j = 0 .. N-1 with the step j -> j+1, so
// it sees every q_j, j = 0..N. t_j = j h (never accumulated). No allocation happens here.
// `constraint` selects the discretization of (13); paper (the default) is (15)/(18) as printed.
template <class Scheme, class T, class Observer>
void integrate_foucault(const FoucaultParams<T>& p, const Vec2<T>& q0, const Vec2<T>& v0, T h, long N,
                        FoucaultStart start, Observer&& observe,
                        FoucaultConstraint constraint = FoucaultConstraint::paper) {
  using std::atan2;
  integrate_foucault_steps<Scheme>(p, Scheme::previous_point(p, q0, v0, h, start), q0, 0, N, h, constraint,
                                   atan2(q0(1), q0(0)), observe);
}

// ---------------------------------------------------------------------------------------------------
// Diagnostics, kept only as dense as the figures need.

struct FoucaultSample {
  long j;
  double t;          // t_j
  double x, y;       // q_j
  double energy;     // chord energy E_{j+1/2} (at t_j + h/2)
  double lambda;     // continuous-equivalent multiplier of the step j -> j+1 (kg/s)
  double residual;   // Phi_d(q_j, q_{j+1}) / discrete_constraint_scale
  bool turning;      // q_j is a turning point (also in FoucaultDiagnostics::turns)
};

// A turning point: a local maximum of r_j = |q_j| (j = 0 counts when r_0 >= r_1).
struct FoucaultTurn {
  long j;
  double t, x, y, r;
  double energy;  // E_{j+1/2}
  double angle;   // plane of oscillation, atan2(y, x) unwrapped modulo pi (continuous across turns), rad
  double jump;    // angle - previous angle, rad (NaN for the first)
};

struct FoucaultSummary {
  double E0 = 0;                 // continuous energy of the consistent initial state
  double E_final = 0;            // E_{N-1/2}
  double t_final = 0;            // T - h/2
  double max_residual = 0;       // max_j |Phi_d| / scale (round-off units of eps at most a few); rotation: see operator()
  double max_abs_residual = 0;   // max_j |Phi_d|, m^2/s (rotation: |n(phi_{j+1}).q_{j+1}|, m)
  double max_abs_lambda = 0;     // max_j |lambda| (continuous-equivalent), kg/s
  double min_r = 0;              // min_j |q_j|, j = 0..N
  double t_min_r = 0;
  // min_j |q_j| / |q_{j+1} - q_j|: how close a step lands to the origin, in units of the step. Near the
  // origin the discrete constraint makes q_{j+1} - q_j nearly parallel to q_j, so a step landing at this
  // ratio rho turns the plane of oscillation by about s h / rho (the "anomaly" when rho is small).
  double min_pass_ratio = std::numeric_limits<double>::infinity();
  double t_min_pass_ratio = 0;
  double max_jump = 0;           // max_k |angle_k - angle_{k-1}|, rad
  double t_max_jump = 0;
  // Largest loss of energy between successive turning points beyond the exact factor e^{-alpha dt}
  // (at extrema of a damped linear oscillator the energy ratio is exactly e^{-alpha dt}).
  double max_energy_loss = 0;
  double t_max_energy_loss = 0;
  double rate = std::numeric_limits<double>::quiet_NaN();  // least-squares d(angle)/dt, rad/s
  int rate_points = 0;
  long turns = 0;
};

// Least-squares slope of angle against t over the turning points (GSL); NaN with fewer than 3.
double fit_precession_rate(const std::vector<FoucaultTurn>& turns, int* points = nullptr);

template <class T>
class FoucaultDiagnostics {
 public:
  // sample_every: keep every k-th step (plus every turning point and the last step).
  FoucaultDiagnostics(const FoucaultParams<T>& p, T h, long N, long sample_every, const Vec2<T>& q0,
                      const Vec2<T>& v0)
      : p_(p), h_(h), N_(N), every_(sample_every) {
    require(sample_every >= 1, "sample_every must be a positive integer");
    summary_.E0 = static_cast<double>(foucault_energy(p, q0, consistent_velocity(p, q0, v0)));
    summary_.min_r = static_cast<double>(q0.norm());
    // Reserve once: turning points come twice per period 2 pi / sqrt(w2 - s^2); doubled for safety.
    const double period = 2 * foucault_pi / std::sqrt(std::abs(static_cast<double>(p.w2 - p.s * p.s)));
    const auto turns_est = static_cast<std::size_t>(4 * N * static_cast<double>(h) / period) + 16;
    turns.reserve(turns_est);
    samples.reserve(static_cast<std::size_t>(N / sample_every) + 2 + turns_est);
  }

  void operator()(const FoucaultStep<T>& st) {
    using std::abs;
    const T r = st.q.norm(), rn = st.qn.norm();
    const double t = static_cast<double>(st.t);
    const T E = chord_energy(p_, st.q, st.qn, h_);
    // The residual of the discretization that was imposed: Phi_d (paper) or n(phi_{j+1}).q_{j+1} (rotation,
    // scaled by |q_j| + |q_{j+1}|, the size of the step's inputs and output).
    const bool rot = st.constraint == FoucaultConstraint::rotation;
    const T phid = rot ? foucault_line<T>(st.phin).n.dot(st.qn) : discrete_constraint(p_, st.q, st.qn, h_);
    const T scale = rot ? T(st.q.norm() + rn) : discrete_constraint_scale(st.q, st.qn, h_);
    const double res = static_cast<double>(scale > 0 ? abs(phid) / scale : abs(phid));
    auto& S = summary_;
    S.max_residual = std::max(S.max_residual, res);
    S.max_abs_residual = std::max(S.max_abs_residual, static_cast<double>(abs(phid)));
    S.max_abs_lambda = std::max(S.max_abs_lambda, static_cast<double>(abs(st.lambda)));
    if (static_cast<double>(rn) < S.min_r) {
      S.min_r = static_cast<double>(rn);
      S.t_min_r = static_cast<double>(T(st.j + 1) * h_);
    }
    const T step_len = (st.qn - st.q).norm();
    if (step_len > 0 && static_cast<double>(r / step_len) < S.min_pass_ratio) {
      S.min_pass_ratio = static_cast<double>(r / step_len);
      S.t_min_pass_ratio = t;
    }
    const bool turning = st.j == 0 ? r >= rn : (r > st.qm.norm() && r >= rn);
    if (turning) add_turn(st, t, static_cast<double>(r), static_cast<double>(E));
    if (turning || st.j % every_ == 0 || st.j == N_ - 1)
      samples.push_back({st.j, t, static_cast<double>(st.q(0)), static_cast<double>(st.q(1)), static_cast<double>(E),
                         static_cast<double>(st.lambda), res, turning});
    if (st.j == N_ - 1) {
      S.E_final = static_cast<double>(E);
      S.t_final = static_cast<double>(st.t + h_ / 2);
    }
  }

  // Completes the summary (precession fit) after the run.
  FoucaultSummary summary() const {
    FoucaultSummary s = summary_;
    s.rate = fit_precession_rate(turns, &s.rate_points);
    s.turns = static_cast<long>(turns.size());
    return s;
  }

  std::vector<FoucaultSample> samples;
  std::vector<FoucaultTurn> turns;

 private:
  void add_turn(const FoucaultStep<T>& st, double t, double r, double E) {
    const double x = static_cast<double>(st.q(0)), y = static_cast<double>(st.q(1));
    double a = std::atan2(y, x), jump = std::nan("");
    if (!turns.empty()) {
      // The plane is a line: its angle is defined modulo pi. Pick the representative nearest the last.
      const double prev = turns.back().angle;
      a += foucault_pi * std::round((prev - a) / foucault_pi);
      jump = a - prev;
      auto& S = summary_;
      if (std::abs(jump) > S.max_jump) {
        S.max_jump = std::abs(jump);
        S.t_max_jump = t;
      }
      const double dt = t - turns.back().t;
      const double loss = 1 - E / turns.back().energy * std::exp(static_cast<double>(p_.alpha) * dt);
      if (loss > S.max_energy_loss) {
        S.max_energy_loss = loss;
        S.t_max_energy_loss = t;
      }
    }
    turns.push_back({st.j, t, x, y, r, E, a, jump});
  }

  FoucaultParams<T> p_;
  T h_;
  long N_, every_;
  FoucaultSummary summary_;
};

// A run as the programs use it: scheme by name, double precision, decimated diagnostics.
struct FoucaultRun {
  std::vector<FoucaultSample> samples;
  std::vector<FoucaultTurn> turns;
  FoucaultSummary summary;
};
// Runs N = T/h steps (step_count refuses h that does not divide T). Throws InputError for bad input and
// NumericalFailure (with the step index) when a step cannot be solved.
FoucaultRun run_foucault(const std::string& scheme, const FoucaultScene& scene, double h, FoucaultStart start,
                         long sample_every, FoucaultConstraint constraint = FoucaultConstraint::paper);

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
// (from -y x'' + x y'' + 2 s (x x' + y y') = 0), integrated with Boost.Odeint (dense-output dopri5)
// at tolerance `tol` from (q0, consistent_velocity(q0, v0)). Returns (x, y, x', y') at every time.
// The multiplier is singular at the origin but the force lambda (y, -x)/m stays bounded; at r = 0
// exactly (never met in practice) the equivalent on-constraint form -alpha s J q - 2 s J q' + 2 s^2 q is used.
std::vector<std::array<double, 4>> foucault_reference(const FoucaultScene& scene, const std::vector<double>& times,
                                                      double tol = 1e-12);

// The right-hand side foucault_reference integrates, on u = (x, y, x', y'), for other ODE solvers.
struct FoucaultMultiplierOde {
  double w2, s, a;
  explicit FoucaultMultiplierOde(const FoucaultParams<double>& p) : w2(p.w2), s(p.s), a(p.alpha) {}
  template <class State>
  void operator()(const State& u, State& du, double) const {
    const double x = u[0], y = u[1], vx = u[2], vy = u[3];
    const double r2 = x * x + y * y;
    double fx, fy;  // constraint force per unit mass, lambda (y, -x)/m
    if (r2 > 0) {
      const double lm = (a * (y * vx - x * vy) + 2 * s * (x * vx + y * vy)) / r2;  // lambda/m
      fx = lm * y;
      fy = -lm * x;
    } else {  // -alpha s J q - 2 s J q' + 2 s^2 q at q = 0
      fx = 2 * s * vy;
      fy = -2 * s * vx;
    }
    du[0] = vx;
    du[1] = vy;
    du[2] = -w2 * x - a * vx + fx;
    du[3] = -w2 * y - a * vy + fy;
  }
};

}  // namespace geomint
