#pragma once
// Worked example for README "Add a scheme": one new file plus one registry line.
//
// Conformal symplectic Strang splitting for q'' + alpha q' + q = 0: the damping flow p' = -alpha p is solved
// exactly for h/2 on each side of an undamped Störmer–Verlet step. Every substep is symplectic or scales p
// exactly, so the one-step map contracts phase-space area by exactly e^{-alpha h}, the continuous rate
// (a conformal symplectic method). Symmetric, hence second order.
#include <cmath>

#include "geomint/oscillator.hpp"

namespace geomint::schemes {

struct ConformalStrang {
  static constexpr const char* name = "conformal-strang";
  static constexpr int order = 2;
  template <class T>
  static void step(OscState<T>& s, T h, T alpha) {
    using std::exp;
    const T damp = exp(-alpha * h / 2);  // loop-invariant: hoisted out of a run
    s.p *= damp;
    s.p -= h / 2 * s.q;
    s.q += h * s.p;
    s.p -= h / 2 * s.q;
    s.p *= damp;
  }
};

}  // namespace geomint::schemes
