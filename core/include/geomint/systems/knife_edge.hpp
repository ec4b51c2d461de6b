#pragma once
// A smooth damped nonholonomic system: the knife edge (Chaplygin skate) in a harmonic well.
// q = (x, y, theta): the blade's contact point and heading. Its velocity must point along the blade,
//   Phi = sin(theta) x' - cos(theta) y' = 0,   A(q) = (sin theta, -cos theta, 0): |A| = 1, never singular
// (unlike the Foucault pendulum's (13), whose covector vanishes at the origin).
//   L = m/2 (x'^2 + y'^2) + I/2 theta'^2 - k/2 (x^2 + y^2) - kappa/2 theta^2,
// Rayleigh damping F = -alpha (m x', m y', I theta') (Herglotz form L - alpha z).
// The heading is a damped linear oscillator decoupled from the rest (closed form); the forward speed
// u = x' cos theta + y' sin theta obeys m u' = -k (x cos theta + y sin theta) - alpha m u, so the motion is
// bounded and decays. Reference: Boost.Odeint on the Lagrange–d'Alembert equations the core derives from
// L and Phi, cross-checked against the hand-written rhs below.
// Templated on the parameter type (KnifeEdge = KnifeEdgeT<double>): a symbolic P gives the formulas.
#include <cmath>

#include "geomint/error.hpp"
#include "geomint/generic/system.hpp"

namespace geomint::systems {

template <class P = double>
struct KnifeEdgeT {
  static constexpr const char* name = "knife-edge";
  static constexpr const char* description = "damped knife edge (Chaplygin skate) in a harmonic well, constraint sin(th) x' = cos(th) y'";
  static constexpr int dof = 3;
  static constexpr int constraints = 1;
  static constexpr bool linear_dynamics = true;  // L quadratic, F linear; the blade's A(q) is not affine

  P m = 1, I = 0.5, k = 1, kappa = 2, alpha = 0.1;
  P x0 = 1, y0 = 0, theta0 = 0.8, u0 = 0.5, omega0 = 0, T = 20;

  template <class V>
  void visit(V&& v) {
    v("m", m, "mass");
    v("I", I, "moment of inertia about the contact point");
    v("k", k, "stiffness of the well");
    v("kappa", kappa, "torsional stiffness");
    v("alpha", alpha, "Rayleigh damping");
    v("x0", x0, "initial x");
    v("y0", y0, "initial y");
    v("theta0", theta0, "initial heading (rad)");
    v("u0", u0, "initial speed along the blade");
    v("omega0", omega0, "initial turning rate");
    v("T", T, "horizon");
  }
  void validate() const {
    require_positive(m, "m");
    require_positive(I, "I");
    require_nonnegative(k, "k");
    require_nonnegative(kappa, "kappa");
    require_nonnegative(alpha, "alpha");
    for (double f : {x0, y0, theta0, u0, omega0}) require_finite(f, "initial data");
    require_positive(T, "T");
  }

  template <class S>
  S lagrangian(const S&, const Vec<S, 3>& q, const Vec<S, 3>& v) const {
    return m / 2 * (v(0) * v(0) + v(1) * v(1)) + I / 2 * v(2) * v(2) - k / 2 * (q(0) * q(0) + q(1) * q(1)) -
           kappa / 2 * q(2) * q(2);
  }
  template <class S>
  S herglotz(const S& t, const Vec<S, 3>& q, const Vec<S, 3>& v, const S& z) const {
    return lagrangian(t, q, v) - alpha * z;
  }
  template <class S>
  Vec<S, 3> force(const S&, const Vec<S, 3>&, const Vec<S, 3>& v) const {
    return Vec<S, 3>(-alpha * m * v(0), -alpha * m * v(1), -alpha * I * v(2));
  }
  template <class S>
  Mat<S, 1, 3> constraint_matrix(const S&, const Vec<S, 3>& q) const {
    using std::cos;
    using std::sin;
    return Mat<S, 1, 3>(sin(q(2)), -cos(q(2)), S(0));
  }
  template <class S>
  Vec<S, 1> constraint_offset(const S&, const Vec<S, 3>&) const {
    return Vec<S, 1>::Zero();
  }
  template <class S>
  Vec<S, 3> initial_position() const {
    return Vec<S, 3>(S(x0), S(y0), S(theta0));
  }
  template <class S>
  Vec<S, 3> initial_velocity() const {
    using std::cos;
    using std::sin;
    return Vec<S, 3>(S(u0) * cos(S(theta0)), S(u0) * sin(S(theta0)), S(omega0));
  }
  // Lagrange–d'Alembert by hand: m x'' = -k x - alpha m x' + lambda sin th, m y'' = -k y - alpha m y' - lambda cos th,
  // I th'' = -kappa th - alpha I th', and d/dt Phi = 0 gives lambda = k (x sin th - y cos th) - m th' u
  // (+ alpha m Phi, zero on the constraint), u = x' cos th + y' sin th.
  void rhs(double, const Vec<double, 3>& q, const Vec<double, 3>& v, Vec<double, 3>& a) const {
    const double s = std::sin(q(2)), c = std::cos(q(2)), u = v(0) * c + v(1) * s;
    const double lambda = k * (q(0) * s - q(1) * c) - m * v(2) * u + alpha * m * (v(0) * s - v(1) * c);
    a(0) = (-k * q(0) - alpha * m * v(0) + lambda * s) / m;
    a(1) = (-k * q(1) - alpha * m * v(1) - lambda * c) / m;
    a(2) = (-kappa * q(2) - alpha * I * v(2)) / I;
  }
};
using KnifeEdge = KnifeEdgeT<>;

}  // namespace geomint::systems
