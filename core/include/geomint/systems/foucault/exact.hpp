#pragma once
// The Foucault pendulum's continuous solution: the closed form on (13), and the multiplier ODE that the systems'
// right-hand side, every baseline and the reference integrate.
#include <array>
#include <cmath>
#include <vector>

#include "geomint/linear_oscillator.hpp"
#include "geomint/systems/foucault/params.hpp"

namespace geomint {
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

// The Boost.Odeint reference (dense-output dopri5 at tolerance `tol`) of the multiplier ODE from
// (q0, consistent_velocity(q0, v0)): (x, y, x', y') at every time.
std::vector<std::array<double, 4>> foucault_reference(const systems::FoucaultPendulum& scene,
                                                      const std::vector<double>& times, double tol = 1e-12);

}  // namespace geomint
