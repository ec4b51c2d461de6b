#pragma once
// The forced damped oscillator of the contact-integrator literature (Vermeeren–Bravetti–Seri; Bravetti,
// Seri, Vermeeren, Zadra): q'' + alpha q' + q = beta sin(omega t). The forcing is the time-dependent
// potential -q beta sin(omega t) inside L (in both forms), the damping a Rayleigh force (LA) or -alpha z
// (Herglotz). Started on the steady state
//   q_ss(t) = C sin(omega t - delta),  C = beta / sqrt((1 - omega^2)^2 + (alpha omega)^2),
//   delta = atan2(alpha omega, 1 - omega^2),
// plus an optional offset (dq0, dv0) whose transient is the damped oscillator's closed form.
// Templated on the parameter type (ForcedOscillator = ForcedOscillatorT<double>): a symbolic P gives the formulas.
#include <cmath>

#include "geomint/constants.hpp"
#include "geomint/error.hpp"
#include "geomint/generic/system.hpp"
#include "geomint/linear_oscillator.hpp"

namespace geomint::systems {

template <class P = double>
struct ForcedOscillatorT {
  static constexpr const char* name = "forced-oscillator";
  static constexpr const char* description = "forced damped oscillator: q'' + alpha q' + q = beta sin(omega t)";
  static constexpr int dof = 1;
  static constexpr int constraints = 0;
  static constexpr bool linear = true;  // L quadratic in (q, q'), F linear: every step is a linear solve

  P alpha = 0.1, beta = 0.3, omega = geomint::pi / 3, dq0 = 0, dv0 = 0, T = 50;

  template <class V>
  void visit(V&& v) {
    v("alpha", alpha, "Rayleigh damping");
    v("beta", beta, "forcing amplitude");
    v("omega", omega, "forcing frequency");
    v("dq0", dq0, "initial position minus the steady state's");
    v("dv0", dv0, "initial velocity minus the steady state's");
    v("T", T, "horizon");
  }
  void validate() const {
    require_nonnegative(alpha, "alpha");
    require_finite(beta, "beta");
    require_finite(omega, "omega");
    require(!(alpha == 0 && omega * omega == 1), "alpha = 0 with omega = 1 is resonant: no steady state");
    require_finite(dq0, "dq0");
    require_finite(dv0, "dv0");
    require_positive(T, "T");
  }

  template <class S>
  S lagrangian(const S& t, const Vec<S, 1>& q, const Vec<S, 1>& v) const {
    using std::sin;
    return v(0) * v(0) / 2 - q(0) * q(0) / 2 + beta * q(0) * sin(omega * t);
  }
  template <class S>
  S herglotz(const S& t, const Vec<S, 1>& q, const Vec<S, 1>& v, const S& z) const {
    return lagrangian(t, q, v) - alpha * z;
  }
  template <class S>
  Vec<S, 1> force(const S&, const Vec<S, 1>&, const Vec<S, 1>& v) const {
    return Vec<S, 1>::Constant(-alpha * v(0));
  }

  // The steady state at t.
  template <class S>
  Phase<S, 1> steady(const S& t) const {
    using std::atan2;
    using std::cos;
    using std::sin;
    using std::sqrt;
    const S a(alpha), w(omega), k = S(1) - w * w;
    const S C = S(beta) / sqrt(k * k + a * a * w * w), delta = atan2(a * w, k);
    return {Vec<S, 1>::Constant(C * sin(w * t - delta)), Vec<S, 1>::Constant(C * w * cos(w * t - delta))};
  }
  template <class S>
  Vec<S, 1> initial_position() const {
    return Vec<S, 1>::Constant(steady<S>(S(0)).q(0) + S(dq0));
  }
  template <class S>
  Vec<S, 1> initial_velocity() const {
    return Vec<S, 1>::Constant(steady<S>(S(0)).v(0) + S(dv0));
  }
  template <class S>
  Phase<S, 1> exact(const S& t) const {
    Phase<S, 1> x = steady(t);
    if (dq0 != 0 || dv0 != 0) {
      const auto tr = linear_oscillator_solution<S>(S(alpha), S(1), S(dq0), S(dv0), t);
      x.q(0) += tr.q;
      x.v(0) += tr.v;
    }
    return x;
  }
  void rhs(double t, const Vec<double, 1>& q, const Vec<double, 1>& v, Vec<double, 1>& a) const {
    a(0) = -q(0) - alpha * v(0) + beta * std::sin(omega * t);
  }
};
using ForcedOscillator = ForcedOscillatorT<>;

}  // namespace geomint::systems
