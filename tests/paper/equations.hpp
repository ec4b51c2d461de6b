#pragma once
// Equations of motion derived from Lagrangians by automatic differentiation (Eigen's AutoDiff module,
// nested once for second derivatives) — not by hand.
//
// Herglotz equations (2):  L_q - d/dt L_v + L_v L_z = 0,  z' = L.
//   With d/dt L_v = L_vq v + L_vv a + L_vz z' this gives  a = (L_q + L_v L_z - L_vq v - L_vz L) / L_vv.
// Forced Euler–Lagrange equations:  L_q - d/dt L_v + F = 0  =>  a = (L_q - L_vq v + F) / L_vv.
//   When the force depends on the acceleration (the O(h) term of F_mod in (8)), the standard truncation
//   replaces q'' inside the O(h) term by the leading-order acceleration a0 (the same equation at h = 0);
//   the difference is O(h^2), below the order the modified equation claims.
//   Terms of L_mod that depend on q'' must be total derivatives (checked in the tests for (8)); they
//   change no equation and are dropped by evaluating L at q'' = 0.
#include <type_traits>

#include <Eigen/Core>
#include <unsupported/Eigen/AutoDiff>

namespace geomint::modified {

using AdInner = Eigen::AutoDiffScalar<Eigen::Vector3d>;
using AdOuter = Eigen::AutoDiffScalar<Eigen::Matrix<AdInner, 3, 1>>;

struct Derivatives3 {
  double value;
  Eigen::Vector3d grad;
  Eigen::Matrix3d hess;
};

// Value, gradient and Hessian of f: R^3 -> R at x, by nested forward-mode AD.
template <class F>
Derivatives3 derivatives3(const F& f, const Eigen::Vector3d& x) {
  AdOuter X[3];
  for (int i = 0; i < 3; ++i) {
    X[i].value() = AdInner(x[i], 3, i);
    X[i].derivatives().setConstant(AdInner(0.0));
    for (int k = 0; k < 3; ++k) X[i].derivatives()[k].derivatives().setZero();
    X[i].derivatives()[i] = AdInner(1.0);
    X[i].derivatives()[i].derivatives().setZero();
  }
  const AdOuter y = f(X[0], X[1], X[2]);
  Derivatives3 d;
  d.value = y.value().value();
  d.grad = y.value().derivatives();
  for (int i = 0; i < 3; ++i) d.hess.row(i) = y.derivatives()[i].derivatives().transpose();
  return d;
}

struct HerglotzField {
  double a, zdot;
};

// Herglotz equations (2) of a one-degree-of-freedom L(q, v, z).
template <class Lagrangian>
HerglotzField herglotz_field(const Lagrangian& L, double q, double v, double z) {
  const auto d = derivatives3([&](const auto& Q, const auto& V, const auto& Z) { return L(Q, V, Z); },
                              Eigen::Vector3d(q, v, z));
  const double Lq = d.grad(0), Lv = d.grad(1), Lz = d.grad(2);
  const double Lvq = d.hess(1, 0), Lvv = d.hess(1, 1), Lvz = d.hess(1, 2);
  return {(Lq + Lv * Lz - Lvq * v - Lvz * d.value) / Lvv, d.value};
}

// Forced Euler–Lagrange equations of a one-degree-of-freedom L(q, v, a) with force F(q, v, a), truncated
// as described above. `Model` provides lagrangian(q, v, a), force(q, v, a) and original() (h = 0).
template <class Model>
double forced_acceleration(const Model& M, double q, double v) {
  // L at a = 0 (its a-dependent part is a total derivative); the third AD variable carries a.
  const auto d = derivatives3(
      [&](const auto& Q, const auto& V, const auto&) {
        using S = std::decay_t<decltype(Q)>;
        return M.lagrangian(Q, V, S(0.0));
      },
      Eigen::Vector3d(q, v, 0.0));
  const double Lq = d.grad(0), Lvq = d.hess(1, 0), Lvv = d.hess(1, 1);
  const auto orig = M.original();
  const double a0 = (Lq - Lvq * v + orig.force(q, v, 0.0)) / Lvv;  // leading order (force at h = 0)
  return (Lq - Lvq * v + M.force(q, v, a0)) / Lvv;
}

}  // namespace geomint::modified
