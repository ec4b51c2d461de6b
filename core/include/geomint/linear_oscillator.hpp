#pragma once
// The closed-form solution of the damped linear oscillator q'' + a q' + b q = 0, the building block of every
// closed-form solution in geomint: the paper's oscillator (a = alpha, b = 1), the forced and the coupled
// oscillators' transients and normal modes, the Foucault pendulum's signed radius in the rotating frame
// (b = w2 - s^2), and the all-orders modified equations of the linear schemes.
#include <cmath>

namespace geomint {

template <class T>
struct LinearOscillatorSolution {
  T q, v;
};

// q(t), q'(t) from q(0) = q0, q'(0) = v0, for every regime: under-damped (cos, sin/omega), critically damped
// (1, t) and over-damped (cosh, sinh/kappa). sin(w t)/w stays accurate as w -> 0, so only w == 0 exactly needs
// the critical branch.
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

}  // namespace geomint
