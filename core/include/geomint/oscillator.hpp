#pragma once
// The damped harmonic oscillator of Section 3.1: m = 1, L = q'^2/2 - q^2/2, force F = -alpha q'
// (Herglotz form: L = q'^2/2 - q^2/2 - alpha z). Equation of motion q'' + alpha q' + q = 0.
#include <cmath>

#include "geomint/error.hpp"

namespace geomint {

// The scene: the least the oscillator experiments need.
struct OscillatorScene {
  double alpha = 0.01;  // damping
  double q0 = -0.25;    // initial position
  double p0 = 0.75;     // initial momentum (= velocity, m = 1)
  double T = 50;        // horizon
  void validate() const {
    require_nonnegative(alpha, "alpha");
    require_finite(q0, "q0");
    require_finite(p0, "p0");
    require_positive(T, "T");
  }
};

template <class T>
struct OscState {
  T q{}, p{}, z{};  // z: Herglotz action, carried by the contact schemes only
};

template <class T>
T oscillator_energy(T q, T p) { return p * p / 2 + q * q / 2; }

// Closed-form solution of q'' + a q' + b q = 0, q(0) = q0, q'(0) = v0, for every regime:
// under-damped (cos, sin/omega), critically damped (1, t) and over-damped (cosh, sinh/kappa).
// sin(w t)/w stays accurate as w -> 0, so only w == 0 exactly needs the critical branch.
template <class T>
struct LinearOscillatorSolution {
  T q, v;
};

template <class T>
LinearOscillatorSolution<T> linear_oscillator_solution(T a, T b, T q0, T v0, T t) {
  using std::cos; using std::sin; using std::cosh; using std::sinh; using std::sqrt; using std::exp;
  const T disc = b - a * a / 4;  // omega^2 (> 0 under-damped)
  T c, s, cdot, sdot;            // fundamental pair: c(0)=1,c'(0)=0 for the undamped-shifted system
  if (disc > 0) {
    const T w = sqrt(disc);
    c = cos(w * t); s = sin(w * t) / w; cdot = -w * sin(w * t); sdot = cos(w * t);
  } else if (disc < 0) {
    const T k = sqrt(-disc);
    c = cosh(k * t); s = sinh(k * t) / k; cdot = k * sinh(k * t); sdot = cosh(k * t);
  } else {
    c = 1; s = t; cdot = 0; sdot = 1;
  }
  // q = e^{-a t/2} (q0 c + (v0 + a q0/2) s)
  const T e = exp(-a * t / 2);
  const T B = v0 + a * q0 / 2;
  const T u = q0 * c + B * s;
  const T udot = q0 * cdot + B * sdot;
  return {e * u, e * (udot - a / 2 * u)};
}

// Exact solution of the paper's oscillator (a = alpha, b = 1).
template <class T>
LinearOscillatorSolution<T> oscillator_exact(T alpha, T q0, T p0, T t) {
  return linear_oscillator_solution<T>(alpha, T(1), q0, p0, t);
}

// One-step matrix of a linear oscillator Scheme on (q, p), by stepping the unit vectors (long double,
// so the all-orders coefficients and stability maps computed from it keep their digits).
template <class Scheme>
void one_step_matrix(long double h, long double alpha, long double M[2][2]) {
  OscState<long double> e1{1, 0, 0}, e2{0, 1, 0};
  Scheme::step(e1, h, alpha);
  Scheme::step(e2, h, alpha);
  M[0][0] = e1.q; M[1][0] = e1.p;
  M[0][1] = e2.q; M[1][1] = e2.p;
}

}  // namespace geomint
