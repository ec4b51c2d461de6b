#pragma once
// Two damped oscillators coupled by a spring: a linear system with two modes, for stability maps and modified
// equations beyond one degree of freedom.
//   L = (q1'^2 + q2'^2)/2 - (q1^2 + q2^2)/2 - kappa/2 (q1 - q2)^2,  Rayleigh force -alpha q' (Herglotz: L - alpha z).
// Normal modes: u = (q1 + q2)/2 with u'' + alpha u' + u = 0, w = (q1 - q2)/2 with w'' + alpha w' + (1 + 2 kappa) w = 0,
// each in closed form (oscillator.hpp). Templated on the parameter type (CoupledOscillators =
// CoupledOscillatorsT<double>): a symbolic P gives the formulas.
#include "geomint/error.hpp"
#include "geomint/generic/system.hpp"
#include "geomint/linear_oscillator.hpp"
#include "geomint/registry.hpp"

namespace geomint::systems {

template <class P = double>
struct CoupledOscillatorsT {
  static constexpr const char* name = "coupled-oscillators";
  static constexpr const char* description = "two damped oscillators coupled by a spring (frequencies 1 and sqrt(1 + 2 kappa))";
  static constexpr int dof = 2;
  static constexpr int constraints = 0;
  static constexpr bool linear = true;
  static constexpr bool autonomous = true;  // no explicit t: the generic step is one fixed affine map

  P alpha = 0.1, kappa = 4, q10 = 1, q20 = 0, v10 = 0, v20 = 0, T = 50;

  template <class V>
  void visit(V&& v) {
    v("alpha", alpha, "Rayleigh damping");
    v("kappa", kappa, "coupling stiffness");
    v("q10", q10, "initial q1");
    v("q20", q20, "initial q2");
    v("v10", v10, "initial q1'");
    v("v20", v20, "initial q2'");
    v("T", T, "horizon");
  }
  void validate() const {
    require_nonnegative(alpha, "alpha");
    require_nonnegative(kappa, "kappa");
    for (double f : {q10, q20, v10, v20}) require_finite(f, "initial data");
    require_positive(T, "T");
  }
  // What the tests expect: contact's O(h) error terms are small against its O(h^2) ones at alpha = 0.1 (~ alpha^2, as
  // on the oscillator): over h = 0.1 ... 0.0125 it shows order 2 (local orders 1.97, 1.95, 1.89; generic path,
  // T = 20) and crosses over to its order 1 below (1.77 ... 1.10, then 1.02, 1.00 at h = 0.0002).
  static Expectations expectations() {
    Expectations e;
    e.params = {{"T", 20}};
    e.halvings = 3;
    e.orders = {{"contact", 2}};
    e.why = "h >= 0.0125: contact's O(h) terms (~ alpha^2) are below its O(h^2) terms";
    return e;
  }

  template <class S>
  S lagrangian(const S&, const Vec<S, 2>& q, const Vec<S, 2>& v) const {
    const S d = q(0) - q(1);
    return (v(0) * v(0) + v(1) * v(1)) / 2 - (q(0) * q(0) + q(1) * q(1)) / 2 - kappa / 2 * d * d;
  }
  template <class S>
  S herglotz(const S& t, const Vec<S, 2>& q, const Vec<S, 2>& v, const S& z) const {
    return lagrangian(t, q, v) - alpha * z;
  }
  template <class S>
  Vec<S, 2> force(const S&, const Vec<S, 2>&, const Vec<S, 2>& v) const {
    return -alpha * v;
  }
  template <class S>
  Vec<S, 2> initial_position() const {
    return Vec<S, 2>(S(q10), S(q20));
  }
  template <class S>
  Vec<S, 2> initial_velocity() const {
    return Vec<S, 2>(S(v10), S(v20));
  }
  template <class S>
  Phase<S, 2> exact(const S& t) const {
    const auto u = linear_oscillator_solution<S>(S(alpha), S(1), S((q10 + q20) / 2), S((v10 + v20) / 2), t);
    const auto w = linear_oscillator_solution<S>(S(alpha), S(1 + 2 * kappa), S((q10 - q20) / 2), S((v10 - v20) / 2), t);
    return {Vec<S, 2>(u.q + w.q, u.q - w.q), Vec<S, 2>(u.v + w.v, u.v - w.v)};
  }
  void rhs(double, const Vec<double, 2>& q, const Vec<double, 2>& v, Vec<double, 2>& a) const {
    a(0) = -q(0) - kappa * (q(0) - q(1)) - alpha * v(0);
    a(1) = -q(1) + kappa * (q(0) - q(1)) - alpha * v(1);
  }
};
using CoupledOscillators = CoupledOscillatorsT<>;

}  // namespace geomint::systems
