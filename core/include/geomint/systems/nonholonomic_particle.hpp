#pragma once
// The damped nonholonomic particle: q = (x, y, z) in R^3, L = m/2 |q'|^2 - m w2/2 |q|^2, Rayleigh force
// -alpha m q', and Bloch's nonholonomic constraint z' = y x', i.e. Phi = a(q).q' with a(q) = (-y, 0, 1)
// (|a|^2 = 1 + y^2 >= 1: never singular, unlike (13)).
//
// Its LA integrator in the shape of (15) (NonholonomicParticle::La) is the closed-form fast path of the generic
// `la` scheme: forced discrete Euler–Lagrange equations (1) with L_d = h L(q_j, v_j), F_d^- = -alpha m h v_j,
// v_j = (q_{j+1} - q_j)/h, discrete constraint a(q_j).v_j = 0:
//   m v_{j-1} - m (1 + h alpha) v_j - h m w2 q_j = lambda a(q_j).
// With the predictor v* = (v_{j-1} - h w2 q_j)/(1 + h alpha) this is linear in (v_j, lambda):
//   lambda/m = (1 + h alpha) (a . v*) / |a|^2,   v_j = v* - (a . v*) a / |a|^2,
// the projection of v* onto the constraint plane.
// Templated on the parameter type (NonholonomicParticle = NonholonomicParticleT<double>): a symbolic P gives the
// formulas.
#include <array>
#include <cmath>

#include <Eigen/Core>

#include "geomint/error.hpp"
#include "geomint/generic/system_schemes.hpp"
#include "geomint/generic/schemes.hpp"

namespace geomint {

namespace systems {

template <class P = double>
struct NonholonomicParticleT {
  static constexpr const char* name = "particle";
  static constexpr const char* description = "damped nonholonomic particle in a harmonic well, constraint z' = y x'";
  static constexpr int dof = 3;
  static constexpr int constraints = 1;
  static constexpr bool linear_dynamics = true;  // L quadratic, F linear; z' = y x' is not affine

  P m = 1, w2 = 1, alpha = 0.1;
  P x0 = 1, y0 = 0.5, z0 = -0.3, vx0 = 0.2, vy0 = -0.4, vz0 = 0.1, T = 10;

  template <class V>
  void visit(V&& v) {
    v("m", m, "mass");
    v("w2", w2, "squared frequency of the well");
    v("alpha", alpha, "Rayleigh damping");
    v("x0", x0, "initial x");
    v("y0", y0, "initial y");
    v("z0", z0, "initial z");
    v("vx0", vx0, "initial x' (projected onto the constraint)");
    v("vy0", vy0, "initial y'");
    v("vz0", vz0, "initial z'");
    v("T", T, "horizon");
  }
  void validate() const {
    require_positive(m, "m");
    require_positive(w2, "w2");
    require_nonnegative(alpha, "alpha");
    for (double f : {x0, y0, z0, vx0, vy0, vz0}) require_finite(f, "initial data");
    require_positive(T, "T");
  }

  template <class S>
  S lagrangian(const S&, const Vec<S, 3>& q, const Vec<S, 3>& v) const {
    return m / 2 * v.squaredNorm() - m * w2 / 2 * q.squaredNorm();
  }
  template <class S>
  S herglotz(const S& t, const Vec<S, 3>& q, const Vec<S, 3>& v, const S& z) const {
    return lagrangian(t, q, v) - alpha * z;
  }
  template <class S>
  Vec<S, 3> force(const S&, const Vec<S, 3>&, const Vec<S, 3>& v) const {
    return -(alpha * m) * v;
  }
  template <class S>
  static Vec<S, 3> covector(const Vec<S, 3>& q) {
    return {-q(1), S(0), S(1)};
  }
  template <class S>
  Mat<S, 1, 3> constraint_matrix(const S&, const Vec<S, 3>& q) const {
    return covector<S>(q).transpose();
  }
  template <class S>
  Vec<S, 1> constraint_offset(const S&, const Vec<S, 3>&) const {
    return Vec<S, 1>::Zero();
  }
  template <class S>
  Vec<S, 3> initial_position() const {
    return Vec<S, 3>(S(x0), S(y0), S(z0));
  }
  template <class S>
  Vec<S, 3> initial_velocity() const {
    return Vec<S, 3>(S(vx0), S(vy0), S(vz0));
  }
  template <class S>
  S energy(const S&, const Vec<S, 3>& q, const Vec<S, 3>& v) const {
    return m / 2 * v.squaredNorm() + m * w2 / 2 * q.squaredNorm();
  }
  // Continuous Lagrange–d'Alembert equations made an ODE by differentiating the constraint:
  // a . q'' + a' . q' = 0, a' . q' = -y' x', so lambda/m = (a . (w2 q + alpha q') + x' y') / |a|^2.
  void rhs(double, const Vec<double, 3>& q, const Vec<double, 3>& v, Vec<double, 3>& acc) const {
    const Eigen::Vector3d a = covector<double>(q);
    const double lm = (a.dot(w2 * q + alpha * v) + v(0) * v(1)) / a.squaredNorm();
    acc = -w2 * q - alpha * v + lm * a;
  }
  std::array<double, 6> rhs(const std::array<double, 6>& s) const {
    Vec<double, 3> a;
    rhs(0.0, Vec<double, 3>(s[0], s[1], s[2]), Vec<double, 3>(s[3], s[4], s[5]), a);
    return {s[3], s[4], s[5], a(0), a(1), a(2)};
  }

  // The closed form of `la` (above): (q_j, v_{j-1}) -> (q_{j+1}, v_j); returns lambda_1 / m.
  struct La {
    static constexpr const char* name = "particle-la-nh";
    using solves = generic::LaLeft;
    template <class T>
    static T step(const NonholonomicParticleT& sys, Eigen::Matrix<T, 3, 1>& q, Eigen::Matrix<T, 3, 1>& v, T h) {
      const Eigen::Matrix<T, 3, 1> a = covector<T>(q);
      const Eigen::Matrix<T, 3, 1> vs = (v - h * T(sys.w2) * q) / (1 + h * T(sys.alpha));
      const T c = a.dot(vs) / a.squaredNorm();
      v = vs - c * a;
      q = q + h * v;
      return (1 + h * T(sys.alpha)) * c;
    }
  };
  using fast_paths = std::tuple<La>;
  template <class Closed, class R, class Observer>
  void run_fast(R h, long N, Observer&& observe) const;
};
using NonholonomicParticle = NonholonomicParticleT<>;

}  // namespace systems

// The closed form started as the generic LA: p_0 = m v0 at the projected velocity, i.e. v_{-1} = v0; then p_j = m v_{j-1}.
template <class P>
template <class Closed, class R, class Observer>
void systems::NonholonomicParticleT<P>::run_fast(R h, long N, Observer&& observe) const {
  Vec<R, 3> q = initial_position<R>();
  Vec<R, 3> v = generic::consistent_velocity<NonholonomicParticleT, R>(*this, R(0), q, initial_velocity<R>());
  Vec<R, 1> lambda = Vec<R, 1>::Zero();
  for (long j = 0;; ++j) {
    const Vec<R, 3> p = R(m) * v;
    observe(generic::StepView<R, 3, 1>{j, R(j) * h, q, p, R(0), lambda});
    if (j == N) break;
    lambda(0) = R(m) * Closed::step(*this, q, v, h);
    if (!q.allFinite()) throw NumericalFailure(j + 1, "state", "non-finite q");
  }
}

}  // namespace geomint
