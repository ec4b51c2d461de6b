#pragma once
// The paper's integrators (15) and (18) in closed form: the fast paths of the generic `la` and `contact` on both
// constraint systems, each with the paper's third row and the remedy's, in components shared with the ensembles.
#include <cmath>

#include "geomint/systems/foucault/scene.hpp"
#include "geomint/systems/foucault/steps.hpp"

namespace geomint {
namespace systems {

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


}  // namespace systems
}  // namespace geomint
