#pragma once
// integrate_const: a fixed number of steps, t_j = t0 + j h, the observer called at j = 0..N.
// No allocation happens here; observers own whatever they keep.
#include <cmath>

#include "geomint/error.hpp"
#include "geomint/oscillator.hpp"

namespace geomint {

template <class Scheme, class T, class Observer>
void integrate_const(OscState<T>& s, T h, long N, T alpha, Observer&& observe) {
  using std::isfinite;
  observe(0L, s);
  for (long j = 1; j <= N; ++j) {
    Scheme::step(s, h, alpha);
    if (!isfinite(s.q) || !isfinite(s.p)) throw NumericalFailure(j, "state", "non-finite q or p");
    observe(j, s);
  }
}

}  // namespace geomint
