#pragma once
// Worked example for README "Add a system": one new header (this file) plus its test file.
//
// The damped nonholonomic particle: q = (x, y, z) in R^3, L = m/2 |q'|^2 - m w2/2 |q|^2, Rayleigh force
// -alpha m q', and the nonholonomic constraint z' = y x' (Bloch's "nonholonomic particle"), i.e.
// Phi(q, q') = a(q) . q' = 0 with a(q) = (-y, 0, 1).
//
// LA nonholonomic integrator, as (15) for the pendulum: forced discrete Euler–Lagrange equations (1) with
// L_d = h L(q_j, v_j), F_d^- = -alpha m h v_j, v_j = (q_{j+1} - q_j)/h, discrete constraint a(q_j) . v_j = 0:
//   m v_{j-1} - m (1 + h alpha) v_j - h m w2 q_j = lambda a(q_j).
// With the predictor v* = (v_{j-1} - h w2 q_j)/(1 + h alpha) this is linear in (v_j, lambda):
//   lambda/m = (1 + h alpha) (a . v*) / |a|^2,   v_j = v* - (a . v*) a / |a|^2,
// the projection of v* onto the constraint plane. |a|^2 = 1 + y^2 >= 1: never singular (unlike (13)).
#include <array>
#include <cmath>

#include <Eigen/Core>

#include "geomint/error.hpp"

namespace geomint {

struct NonholonomicParticle {
  double m = 1, w2 = 1, alpha = 0.1;
  void validate() const {
    require_positive(m, "m");
    require_positive(w2, "w2");
    require_nonnegative(alpha, "alpha");
  }
  template <class T>
  static Eigen::Matrix<T, 3, 1> covector(const Eigen::Matrix<T, 3, 1>& q) {
    return {-q(1), T(0), T(1)};
  }
  template <class T>
  T energy(const Eigen::Matrix<T, 3, 1>& q, const Eigen::Matrix<T, 3, 1>& v) const {
    return m / 2 * v.squaredNorm() + m * w2 / 2 * q.squaredNorm();
  }
  // Continuous Lagrange–d'Alembert equations made an ODE by differentiating the constraint:
  // a . q'' + a' . q' = 0, a' . q' = -y' x', so lambda/m = (a . (w2 q + alpha q') + x' y') / |a|^2.
  std::array<double, 6> rhs(const std::array<double, 6>& s) const {
    const Eigen::Vector3d q(s[0], s[1], s[2]), v(s[3], s[4], s[5]);
    const Eigen::Vector3d a = covector(q);
    const double lm = (a.dot(w2 * q + alpha * v) + v(0) * v(1)) / a.squaredNorm();
    const Eigen::Vector3d acc = -w2 * q - alpha * v + lm * a;
    return {v(0), v(1), v(2), acc(0), acc(1), acc(2)};
  }
};

namespace schemes {

struct ParticleLaNh {
  static constexpr const char* name = "particle-la-nh";
  static constexpr int order = 1;
  // (q_j, v_{j-1}) -> (q_{j+1}, v_j); returns lambda_1 / m.
  template <class T>
  static T step(const NonholonomicParticle& P, Eigen::Matrix<T, 3, 1>& q, Eigen::Matrix<T, 3, 1>& v, T h) {
    const Eigen::Matrix<T, 3, 1> a = NonholonomicParticle::covector(q);
    const Eigen::Matrix<T, 3, 1> vs = (v - h * T(P.w2) * q) / (1 + h * T(P.alpha));
    const T c = a.dot(vs) / a.squaredNorm();
    v = vs - c * a;
    q = q + h * v;
    return (1 + h * T(P.alpha)) * c;
  }
};

}  // namespace schemes
}  // namespace geomint
