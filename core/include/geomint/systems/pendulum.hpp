#pragma once
// The damped nonlinear pendulum: L = q'^2/2 - (1 - cos q), Rayleigh force F = -alpha q' (Herglotz form
// L - alpha z). Equation of motion q'' + alpha q' + sin q = 0. No closed form: the reference is Boost.Odeint
// on the equations the core derives from L (cross-checked against the hand-written rhs below).
// This header is the "add a system" example of docs/extending.md: it and one line in core/src/systems.def give the
// pendulum every generic scheme and every study.
// The parameter type P is a template parameter (Pendulum = PendulumT<double>): with a symbolic P the same
// Lagrangian gives the modified equations as formulas in alpha (geomint/modified/symbolic.hpp).
#include <cmath>

#include "geomint/error.hpp"
#include "geomint/generic/system.hpp"

namespace geomint::systems {

template <class P = double>
struct PendulumT {
  static constexpr const char* name = "pendulum";
  static constexpr const char* description = "damped nonlinear pendulum: q'' + alpha q' + sin q = 0";
  static constexpr int dof = 1;
  static constexpr int constraints = 0;

  P alpha = 0.1, q0 = 1, p0 = 0, T = 20;

  template <class V>
  void visit(V&& v) {
    v("alpha", alpha, "Rayleigh damping");
    v("q0", q0, "initial angle (rad)");
    v("p0", p0, "initial momentum (= angular velocity)");
    v("T", T, "horizon");
  }
  void validate() const {
    require_nonnegative(alpha, "alpha");
    require_finite(q0, "q0");
    require_finite(p0, "p0");
    require_positive(T, "T");
  }

  template <class S>
  S lagrangian(const S&, const Vec<S, 1>& q, const Vec<S, 1>& v) const {
    using std::cos;
    return v(0) * v(0) / 2 - (1 - cos(q(0)));
  }
  template <class S>
  S herglotz(const S& t, const Vec<S, 1>& q, const Vec<S, 1>& v, const S& z) const {
    return lagrangian(t, q, v) - alpha * z;
  }
  template <class S>
  Vec<S, 1> force(const S&, const Vec<S, 1>&, const Vec<S, 1>& v) const {
    return Vec<S, 1>::Constant(-alpha * v(0));
  }
  template <class S>
  Vec<S, 1> initial_position() const {
    return Vec<S, 1>::Constant(S(q0));
  }
  template <class S>
  Vec<S, 1> initial_velocity() const {
    return Vec<S, 1>::Constant(S(p0));
  }
  void rhs(double, const Vec<double, 1>& q, const Vec<double, 1>& v, Vec<double, 1>& a) const {
    a(0) = -std::sin(q(0)) - alpha * v(0);
  }
};
using Pendulum = PendulumT<>;

}  // namespace geomint::systems
