#pragma once
// The modified Lagrangians of the paper, written as close to the printed formulas as code allows.
// Each functor is templated on the scalar so automatic differentiation can push its own types through.
// `sign` = +1 is the paper; sign = -1 flips the O(h) term (a deliberately wrong modified equation, used by
// the tests to show that the agreement check can fail).

namespace geomint::modified {

// Herglotz description, eq. (9): L(q, q', z) = q'^2/2 - q^2/2 - alpha z, and the contact integrator's
// modified Lagrangian, eq. (11): L_mod = L + h alpha/2 (q'^2/2 - q^2/2 - alpha z) + O(h^2).
struct ContactModifiedLagrangian {
  double alpha, h, sign = 1;
  template <class S>
  S operator()(const S& q, const S& v, const S& z) const {
    const S L = v * v / 2 - q * q / 2 - alpha * z;
    return L + sign * h * alpha / 2 * (v * v / 2 - q * q / 2 - alpha * z);
  }
};

// Lagrange–d'Alembert description, eqs. (5) and (8), m = 1:
//   L_mod(q, q', q'') = q'^2/2 - q^2/2 + h/2 q' q''       (the h-term is d/dt(h q'^2/4): a total derivative)
//   F_mod(q, q', q'') = -alpha q' - h alpha/2 q''
// The acceleration q'' is an argument; the equation builder truncates it (see equations.hpp).
struct LaModifiedLagrangian {
  double alpha, h, sign = 1;
  template <class S>
  S lagrangian(const S& q, const S& v, const S& a) const {
    return v * v / 2 - q * q / 2 + h / 2 * v * a;
  }
  template <class S>
  S force(const S& /*q*/, const S& v, const S& a) const {
    return -alpha * v - sign * h * alpha / 2 * a;
  }
  // The primitive G with dG/dt = h/2 q' q'' (tests check the identity by AD): the q'q'' term changes
  // no equation of motion.
  template <class S>
  S total_derivative_primitive(const S& /*q*/, const S& v) const {
    return h / 4 * v * v;
  }
  LaModifiedLagrangian original() const { return {alpha, 0.0, sign}; }
};

}  // namespace geomint::modified
