#pragma once
// The Foucault pendulum's scalars in the run's precision (FoucaultParams) and the continuous objects of (12), (13)
// written once over them: the constraint's covector and residual, its discretization Psi, the projection onto it,
// the energies. The scene they are read from is systems::FoucaultPendulum (scene.hpp).
#include <cmath>

#include <Eigen/Core>

namespace geomint {

template <class T>
using Vec2 = Eigen::Matrix<T, 2, 1>;

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

}  // namespace geomint
