#pragma once
// The time-perturbed Kepler problem of the contact-integrator literature (Bravetti, Seri, Vermeeren, Zadra,
// "Numerical integration in celestial mechanics: a case for contact geometry", Celest. Mech. Dyn. Astron. 132
// (2020) 7; code: github.com/mseri/contact-integrators):
//   Herglotz L = |q'|^2/2 + 1/|q| - f(t) z,   f(t) = alpha + a sin(theta t),
// equivalently the Rayleigh force F = -f(t) q' for Lagrange–d'Alembert: q'' = -q/|q|^3 - f(t) q'. Their contact
// Hamiltonian is H = |p|^2/2 + f(t) s - 1/|q| with alpha = 0; the constant part alpha (default 0) is a weak mean
// dissipation for long-horizon studies (with alpha = 0 the perturbation has zero mean).
// Initial data on the unperturbed ellipse of eccentricity e and semi-major axis 1, at its pericentre:
//   q0 = (1 - e, 0),   q0' = (0, sqrt((1 + e)/(1 - e))),   period 2 pi.
// Two exact laws of the perturbed flow (the tests hold the reference to them): the angular momentum
//   M = q x q' obeys M' = -f M, so M(t) = M(0) exp(-alpha t - (a/theta)(1 - cos theta t));
// and the energy E = |q'|^2/2 - 1/|q| obeys E' = -f |q'|^2.
// Defaults: the friction of the anchor's first comparison, (a, theta) = (-0.07, 2 pi), e = 0.4, over T = 10 (1.6
// orbits, where even the first-order schemes are in their asymptotic range from h = 0.1; the anchor's settings
// themselves are presets of geomint/kepler_anchor.hpp).
// The parameter type P is a template parameter (Kepler = KeplerT<double>): with a symbolic P the modified
// equations come as formulas in a, theta, alpha (geomint/modified/symbolic.hpp). No closed form: the reference is Boost.Odeint on the
// equations the core derives from L (cross-checked against rhs below, and against Kepler's equation at a = 0).
#include <cmath>

#include "geomint/constants.hpp"
#include "geomint/error.hpp"
#include "geomint/generic/system.hpp"

namespace geomint::systems {

template <class P = double>
struct KeplerT {
  static constexpr const char* name = "kepler";
  static constexpr const char* description =
      "time-perturbed Kepler problem: q'' = -q/|q|^3 - (alpha + a sin(theta t)) q' (Herglotz L = |q'|^2/2 + 1/|q| - f(t) z)";
  static constexpr int dof = 2;
  static constexpr int constraints = 0;

  P a = -0.07, theta = geomint::two_pi, alpha = 0, e = 0.4, T = 10;

  template <class V>
  void visit(V&& v) {
    v("a", a, "amplitude of the periodic friction f(t) = alpha + a sin(theta t)");
    v("theta", theta, "frequency of the periodic friction");
    v("alpha", alpha, "constant part of the friction (weak mean dissipation)");
    v("e", e, "eccentricity of the initial (unperturbed) orbit, 0 <= e < 1");
    v("T", T, "horizon (one unperturbed orbit is 2 pi)");
  }
  void validate() const {
    require_finite(a, "a");
    require_finite(theta, "theta");
    require_nonnegative(alpha, "alpha");
    require(std::isfinite(e) && e >= 0 && e < 1, "e must be in [0, 1), got " + show(e));
    require_positive(T, "T");
  }

  template <class S>
  S friction(const S& t) const {
    using std::sin;
    return alpha + a * sin(theta * t);
  }
  template <class S>
  S lagrangian(const S&, const Vec<S, 2>& q, const Vec<S, 2>& v) const {
    using std::sqrt;
    return v.squaredNorm() / 2 + 1 / sqrt(q.squaredNorm());
  }
  template <class S>
  S herglotz(const S& t, const Vec<S, 2>& q, const Vec<S, 2>& v, const S& z) const {
    return lagrangian(t, q, v) - friction(t) * z;
  }
  template <class S>
  Vec<S, 2> force(const S& t, const Vec<S, 2>&, const Vec<S, 2>& v) const {
    return -friction(t) * v;
  }
  template <class S>
  Vec<S, 2> initial_position() const {
    return Vec<S, 2>(S(1 - e), S(0));
  }
  template <class S>
  Vec<S, 2> initial_velocity() const {
    using std::sqrt;
    return Vec<S, 2>(S(0), sqrt(S(1 + e) / S(1 - e)));
  }
  void rhs(double t, const Vec<double, 2>& q, const Vec<double, 2>& v, Vec<double, 2>& acc) const {
    const double r = q.norm();
    acc = -q / (r * r * r) - friction(t) * v;
  }

  // The separable form the logH scheme runs on (generic/logh.hpp): H = T(p) - U(q) with p = q' (the momentum of L),
  // T = |p|^2/2, U = 1/|q|, and the force -f(t) q' = -f(t) p. tests/schemes/logh.test.cpp holds each to L and the force.
  template <class S>
  S kinetic(const Vec<S, 2>& p) const {
    return p.squaredNorm() / 2;
  }
  template <class S>
  Vec<S, 2> kinetic_gradient(const Vec<S, 2>& p) const {
    return p;
  }
  template <class S>
  S attraction(const Vec<S, 2>& q) const {
    using std::sqrt;
    return 1 / sqrt(q.squaredNorm());
  }
  // grad ln U = -q/|q|^2: the logH kick needs no square root.
  template <class S>
  Vec<S, 2> log_attraction_gradient(const Vec<S, 2>& q) const {
    return -q / q.squaredNorm();
  }
  // int_{t0}^{t1} f: alpha (t1 - t0) + (a/theta)(cos theta t0 - cos theta t1) (the cosines only where a != 0).
  double damping_integral(double t0, double t1) const {
    const double periodic = (a != 0 && theta != 0) ? a / theta * (std::cos(theta * t0) - std::cos(theta * t1)) : 0.0;
    return alpha * (t1 - t0) + periodic;
  }

  // Whether f is a constant (a = 0 or theta = 0), and which: the logH drift then has an exact flow.
  bool constant_damping(double& gamma) const {
    if (a != 0 && theta != 0) return false;
    gamma = alpha;  // f = alpha + a sin(0) where theta = 0
    return true;
  }

  // The exact angular momentum law, M(t) / M(0) (for the tests and the studies' structural measures).
  double angular_momentum_factor(double t) const {
    return std::exp(-alpha * t - (theta != 0 ? a / theta * (1 - std::cos(theta * t)) : 0.0));
  }
};
using Kepler = KeplerT<>;

}  // namespace geomint::systems
