#pragma once
// The damped harmonic oscillator of Section 3.1 (m = 1): L = q'^2/2 - q^2/2 (5), Rayleigh force F = -alpha q',
// Herglotz form L - alpha z (9). Equation of motion q'' + alpha q' + q = 0, solved in closed form for every
// regime (oscillator.hpp). The paper's integrators (7) (derived: `la`) and (10) (`contact`), and the
// second-order comparators, are closed-form fast paths of the generic schemes (oscillator_schemes.hpp).
// Templated on the parameter type (Oscillator = OscillatorT<double>): a symbolic P gives the formulas.
#include "geomint/generic/fast_path.hpp"
#include "geomint/generic/schemes.hpp"
#include "geomint/oscillator.hpp"
#include "geomint/oscillator_schemes.hpp"

namespace geomint::systems {

template <class P = double>
struct OscillatorT {
  static constexpr const char* name = "oscillator";
  static constexpr const char* description = "damped harmonic oscillator (Section 3.1): q'' + alpha q' + q = 0";
  static constexpr int dof = 1;
  static constexpr int constraints = 0;
  static constexpr bool linear = true;
  static constexpr bool autonomous = true;  // no explicit t: the generic step is one fixed affine map

  P alpha = 0.01, q0 = -0.25, p0 = 0.75, T = 50;

  template <class V>
  void visit(V&& v) {
    v("alpha", alpha, "Rayleigh damping");
    v("q0", q0, "initial position");
    v("p0", p0, "initial momentum (= velocity)");
    v("T", T, "horizon");
  }
  void validate() const { OscillatorScene{alpha, q0, p0, T}.validate(); }

  template <class S>
  S lagrangian(const S&, const Vec<S, 1>& q, const Vec<S, 1>& v) const {
    return v(0) * v(0) / 2 - q(0) * q(0) / 2;
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
  template <class S>
  Phase<S, 1> exact(const S& t) const {
    const auto x = oscillator_exact<S>(S(alpha), S(q0), S(p0), t);
    return {Vec<S, 1>::Constant(x.q), Vec<S, 1>::Constant(x.v)};
  }
  void rhs(double, const Vec<double, 1>& q, const Vec<double, 1>& v, Vec<double, 1>& a) const {
    a(0) = -q(0) - alpha * v(0);
  }

  // Closed forms: each solves the generic scheme's equations for this system (derivations in oscillator_schemes.hpp).
  using fast_paths = std::tuple<generic::FastPath<generic::LaLeft, schemes::La>,
                                generic::FastPath<generic::ContactLeft, schemes::Contact>,
                                generic::FastPath<generic::LaMidpoint, schemes::LaMidpoint>,
                                generic::FastPath<generic::LaTrapezoid, schemes::Leapfrog>,
                                generic::FastPath<generic::ContactTrapezoid, schemes::ContactSymmetric>>;

  // Runs N steps of a closed form from the initial data, in the generic observer's terms (its state is
  // (q, p, z) already: the closed forms are position–momentum maps).
  template <class Closed, class R, class Observer>
  void run_fast(R h, long N, Observer&& observe) const {
    OscState<R> s{R(q0), R(p0), R(0)};
    Vec<R, 1> q, p;
    const Vec<R, 0> lambda;
    for (long j = 0;; ++j) {
      q(0) = s.q;
      p(0) = s.p;
      observe(generic::StepView<R, 1, 0>{j, R(j) * h, q, p, s.z, lambda});
      if (j == N) break;
      Closed::step(s, h, R(alpha));
      if (!std::isfinite(static_cast<double>(s.q)) || !std::isfinite(static_cast<double>(s.p)))
        throw NumericalFailure(j + 1, "state", "non-finite q or p");
    }
  }
};
using Oscillator = OscillatorT<>;

}  // namespace geomint::systems
