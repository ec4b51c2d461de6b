#pragma once
// Observers of a run that several studies share, written once: the angle of a line continued across its
// branches (the plane of oscillation of the Foucault pendulum, a phase), and the turning-point test.
#include <cmath>

#include "geomint/constants.hpp"

namespace geomint {

// The representative of an angle a, defined modulo `period`, nearest to `target`: how an angle is continued
// along a run (target: the previous value, or where the motion is expected to be), and with target 0 how a
// difference of angles is reduced to (-period/2, period/2].
inline double nearest_branch(double a, double target, double period) {
  return a + period * std::round((target - a) / period);
}

// The angle of the line through the origin and (x, y), continued from the previous one: a line's angle is
// defined modulo pi (the bob of a pendulum passes through the origin and its polar angle jumps by pi there).
inline double line_angle(double x, double y, double previous) {
  return nearest_branch(std::atan2(y, x), previous, pi);
}

// A turning point of a swing: q_j is a local maximum of r_j = |q_j| (any increasing function of it, e.g.
// |q_j|^2), given r_{j-1}, r_j, r_{j+1}; the first point counts when r_0 >= r_1. Every comparison is evaluated
// (& and |, not && and ||): with -ftrapping-math GCC may not speculate a comparison that the source evaluates
// only conditionally, and that alone keeps the ensembles' loop from being vectorized.
template <class T>
inline bool is_turning_point(bool first, T r_prev, T r, T r_next) {
  return (r >= r_next) & (first | (r > r_prev));
}

}  // namespace geomint
