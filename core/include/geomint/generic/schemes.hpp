#pragma once
// Schemes built from a system: the paper's two principles, each with a choice of quadrature.
//
// Convention. The discrete action 𝓛(q_j, q_{j+1}) approximates the integral of L over [t_j, t_j + h]
// (the paper's L_d for LA; for contact the paper writes z_{j+1} - z_j = h L_d, so its L_d is 𝓛/h and its
// h D_i L_d are our D_i 𝓛). Every function is templated on the scalar S, so the same code runs in double,
// long double, quad, under automatic differentiation (Newton Jacobians, momenta) and over power series
// (modified equations).
//
// Lagrange–d'Alembert, the forced constrained discrete Euler–Lagrange equations (1):
//   D1 𝓛(q_j, q_{j+1}) + D2 𝓛(q_{j-1}, q_j) + F_d^+(q_{j-1}, q_j) + F_d^-(q_j, q_{j+1}) = A(t_j, q_j)^T lambda,
//   Phi_d(q_j, q_{j+1}) = 0.
// In position–momentum form, with the discrete Legendre transforms
//   p_j^- = D2 𝓛(q_{j-1}, q_j) + F_d^+(q_{j-1}, q_j),     p_j^+ = -D1 𝓛(q_j, q_{j+1}) - F_d^-(q_j, q_{j+1}),
// (1) reads p_j^+ = p_j^- - A^T lambda: a step (q_j, p_j) -> (q_{j+1}, p_{j+1}) solves
//   R = D1 𝓛(q_j, q_{j+1}) + F_d^-(q_j, q_{j+1}) + p_j - A(t_j, q_j)^T lambda = 0,  Phi_d = 0
// for (q_{j+1}, lambda), then p_{j+1} = D2 𝓛(q_j, q_{j+1}) + F_d^+(q_j, q_{j+1}).
//
// Contact, the constrained discrete Herglotz equations (3), (4), with z_{j+1} = z_j + 𝓛(q_j, q_{j+1}, z_j, z_{j+1}):
//   D1 𝓛_j + D2 𝓛_{j-1} (1 + D3 𝓛_j) / (1 - D4 𝓛_{j-1}) = A(t_j, q_j)^T lambda,   Phi_d = 0.
// With p_j = D2 𝓛_{j-1} / (1 - D4 𝓛_{j-1}) (Vermeeren–Bravetti–Seri's contact Legendre transform) a step
// solves
//   R = D1 𝓛(q_j, q_{j+1}, z_j, z_{j+1}) + (1 + D3 𝓛) p_j - A^T lambda = 0,  z_{j+1} - z_j - 𝓛 = 0 (when 𝓛 depends
//   on z_{j+1}),  Phi_d = 0,
// then p_{j+1} = D2 𝓛 / (1 - D4 𝓛).
//
// lambda is the constraint impulse over a step in both: (15)'s lambda_1 for LA, h times (18)'s lambda_1 for
// contact (whose rows are divided by h).
//
// Discrete constraints (Cortés–Martínez, as in (15), (18)): Phi_d = Phi o Psi with the quadrature's
// discretizing map Psi(q_j, q_{j+1}) = (t*, q*, (q_{j+1} - q_j)/h); for a system that gives its constraint as
// the derivative of a (possibly time-dependent) holonomic one g, Phi_d = g(t_{j+1}, q_{j+1}) (as SHAKE does).
#include <tuple>
#include <type_traits>

#include "geomint/generic/system.hpp"

namespace geomint::generic {

// Where a quadrature evaluates the continuous functions for the discrete constraint.
template <class S, int N>
struct Sample {
  S t;
  Vec<S, N> q, v;
};

// ---------------------------------------------------------------------------------------------------
// Quadratures of the Lagrange–d'Alembert principle: 𝓛, F_d^- (at q_j), F_d^+ (at q_{j+1}), Psi.

namespace la_quadrature {

// The paper's "linear order" (6), (15): 𝓛 = h L(t_j, q_j, v), F_d^- = h F(t_j, q_j, v), F_d^+ = 0.
struct Left {
  static constexpr const char* name = "left";
  static constexpr const char* scheme = "la";  // the scheme's name on command lines
  static constexpr int order = 1;
  static constexpr bool psi_at_start = true;  // Psi samples A and b at (t_j, q_j) (see constraint_block)
  template <class Sys, class S, int n = Sys::dof>
  static Sample<S, n> psi(const S& t, const S& h, const Vec<S, n>& q0, const Vec<S, n>& q1) {
    return {t, q0, (q1 - q0) / h};
  }
  template <class Sys, class S, int n = Sys::dof>
  static S action(const Sys& sys, const S& t, const S& h, const Vec<S, n>& q0, const Vec<S, n>& q1) {
    return h * sys.lagrangian(t, q0, Vec<S, n>((q1 - q0) / h));
  }
  template <class Sys, class S, int n = Sys::dof>
  static Vec<S, n> force_minus(const Sys& sys, const S& t, const S& h, const Vec<S, n>& q0, const Vec<S, n>& q1) {
    return h * force(sys, t, q0, Vec<S, n>((q1 - q0) / h));
  }
  template <class Sys, class S, int n = Sys::dof>
  static Vec<S, n> force_plus(const Sys&, const S&, const S&, const Vec<S, n>&, const Vec<S, n>&) {
    return Vec<S, n>::Zero();
  }
};

// Midpoint: 𝓛 = h L(t_j + h/2, (q_j + q_{j+1})/2, v), F_d^± = h/2 F(same point). Symmetric: second order.
struct Midpoint {
  static constexpr const char* name = "midpoint";
  static constexpr const char* scheme = "la-midpoint";
  static constexpr int order = 2;
  template <class Sys, class S, int n = Sys::dof>
  static Sample<S, n> psi(const S& t, const S& h, const Vec<S, n>& q0, const Vec<S, n>& q1) {
    return {t + h / 2, (q0 + q1) / 2, (q1 - q0) / h};
  }
  template <class Sys, class S, int n = Sys::dof>
  static S action(const Sys& sys, const S& t, const S& h, const Vec<S, n>& q0, const Vec<S, n>& q1) {
    const auto x = psi<Sys>(t, h, q0, q1);
    return h * sys.lagrangian(x.t, x.q, x.v);
  }
  template <class Sys, class S, int n = Sys::dof>
  static Vec<S, n> force_minus(const Sys& sys, const S& t, const S& h, const Vec<S, n>& q0, const Vec<S, n>& q1) {
    const auto x = psi<Sys>(t, h, q0, q1);
    return h / 2 * force(sys, x.t, x.q, x.v);
  }
  template <class Sys, class S, int n = Sys::dof>
  static Vec<S, n> force_plus(const Sys& sys, const S& t, const S& h, const Vec<S, n>& q0, const Vec<S, n>& q1) {
    return force_minus(sys, t, h, q0, q1);
  }
};

// Trapezoid: 𝓛 = h/2 [L(t_j, q_j, v) + L(t_{j+1}, q_{j+1}, v)], F_d^- = h/2 F(t_j, q_j, v),
// F_d^+ = h/2 F(t_{j+1}, q_{j+1}, v). For L = q'^2/2 - V(q) this is Störmer–Verlet (leapfrog); second order.
// Psi is the midpoint (symmetric).
struct Trapezoid {
  static constexpr const char* name = "trapezoid";
  static constexpr const char* scheme = "la-trapezoid";
  static constexpr int order = 2;
  template <class Sys, class S, int n = Sys::dof>
  static Sample<S, n> psi(const S& t, const S& h, const Vec<S, n>& q0, const Vec<S, n>& q1) {
    return Midpoint::psi<Sys>(t, h, q0, q1);
  }
  template <class Sys, class S, int n = Sys::dof>
  static S action(const Sys& sys, const S& t, const S& h, const Vec<S, n>& q0, const Vec<S, n>& q1) {
    const Vec<S, n> v = (q1 - q0) / h;
    return h / 2 * (sys.lagrangian(t, q0, v) + sys.lagrangian(S(t + h), q1, v));
  }
  template <class Sys, class S, int n = Sys::dof>
  static Vec<S, n> force_minus(const Sys& sys, const S& t, const S& h, const Vec<S, n>& q0, const Vec<S, n>& q1) {
    return h / 2 * force(sys, t, q0, Vec<S, n>((q1 - q0) / h));
  }
  template <class Sys, class S, int n = Sys::dof>
  static Vec<S, n> force_plus(const Sys& sys, const S& t, const S& h, const Vec<S, n>& q0, const Vec<S, n>& q1) {
    return h / 2 * force(sys, S(t + h), q1, Vec<S, n>((q1 - q0) / h));
  }
};

}  // namespace la_quadrature

// ---------------------------------------------------------------------------------------------------
// Quadratures of the Herglotz principle: 𝓛(q_j, q_{j+1}, z_j, z_{j+1}) and Psi.

namespace contact_quadrature {

// The paper's (10), (17): the potential part by the trapezoid rule in (t, q), z_j held:
// 𝓛 = h/2 [L(t_j, q_j, v, z_j) + L(t_{j+1}, q_{j+1}, v, z_j)]. Explicit in z (D4 𝓛 = 0). First order: the rule
// is a trapezoid in q, but z is held at its left end (hence the scheme's name `contact`, LaLeft's partner).
struct TrapezoidHeldZ {
  static constexpr const char* name = "left";
  static constexpr const char* scheme = "contact";
  static constexpr int order = 1;
  static constexpr bool implicit_z = false;
  static constexpr bool psi_at_start = true;
  template <class Sys, class S, int n = Sys::dof>
  static Sample<S, n> psi(const S& t, const S& h, const Vec<S, n>& q0, const Vec<S, n>& q1) {
    return {t, q0, (q1 - q0) / h};
  }
  template <class Sys, class S, int n = Sys::dof>
  static S action(const Sys& sys, const S& t, const S& h, const Vec<S, n>& q0, const Vec<S, n>& q1, const S& z0,
                  const S& /*z1*/) {
    const Vec<S, n> v = (q1 - q0) / h;
    return h / 2 * (sys.herglotz(t, q0, v, z0) + sys.herglotz(S(t + h), q1, v, z0));
  }
};

// Trapezoid in (t, q, z): 𝓛 = h/2 [L(t_j, q_j, v, z_j) + L(t_{j+1}, q_{j+1}, v, z_{j+1})], implicit in z_{j+1}.
// Symmetric: second order (the oscillator's `contact-sym`). Psi is the midpoint.
struct Trapezoid {
  static constexpr const char* name = "trapezoid";
  static constexpr const char* scheme = "contact-trapezoid";
  static constexpr int order = 2;
  static constexpr bool implicit_z = true;
  template <class Sys, class S, int n = Sys::dof>
  static Sample<S, n> psi(const S& t, const S& h, const Vec<S, n>& q0, const Vec<S, n>& q1) {
    return la_quadrature::Midpoint::psi<Sys>(t, h, q0, q1);
  }
  template <class Sys, class S, int n = Sys::dof>
  static S action(const Sys& sys, const S& t, const S& h, const Vec<S, n>& q0, const Vec<S, n>& q1, const S& z0,
                  const S& z1) {
    const Vec<S, n> v = (q1 - q0) / h;
    return h / 2 * (sys.herglotz(t, q0, v, z0) + sys.herglotz(S(t + h), q1, v, z1));
  }
};

}  // namespace contact_quadrature

// ---------------------------------------------------------------------------------------------------
// The discrete constraint (m rows) of the step q_j -> q_{j+1}.

template <class Sys, class Quad, class S, int n = Sys::dof>
Vec<S, Sys::constraints> discrete_constraint(const Sys& sys, const S& t, const S& h, const Vec<S, n>& q0,
                                             const Vec<S, n>& q1) {
  if constexpr (has_holonomic_v<Sys>) {
    return sys.holonomic(S(t + h), q1);
  } else {
    const auto x = Quad::template psi<Sys>(t, h, q0, q1);
    return constraint<Sys, S>(sys, x.t, x.q, x.v);
  }
}

// The size of the terms that cancel in Phi_d (|A| |v| + |b|, entrywise): its round-off scale. For a
// holonomic discretization the Jacobian term of the stopping rule (|dg/dq| |q|) is that scale already.
template <class Sys, class Quad, class S, int n = Sys::dof>
Vec<S, Sys::constraints> discrete_constraint_scale(const Sys& sys, const S& t, const S& h, const Vec<S, n>& q0,
                                                   const Vec<S, n>& q1) {
  if constexpr (has_holonomic_v<Sys>) {
    return Vec<S, Sys::constraints>::Zero();
  } else {
    using std::abs;
    const auto x = Quad::template psi<Sys>(t, h, q0, q1);
    return sys.constraint_matrix(x.t, x.q).cwiseAbs() * x.v.cwiseAbs() + sys.constraint_offset(x.t, x.q).cwiseAbs();
  }
}

// Phi_d and its round-off scale from one evaluation of A and b at the quadrature's point (the same values as
// the two functions above): what a step's rows need at every Newton iterate.
template <class S, int m>
struct ConstraintRows {
  Vec<S, m> value, scale;
};
template <class S, int n, int m>
ConstraintRows<S, m> constraint_rows_from(const Mat<S, m, n>& A, const Vec<S, m>& b, const Vec<S, n>& v) {
  return {A * v + b, A.cwiseAbs() * v.cwiseAbs() + b.cwiseAbs()};
}
template <class Sys, class Quad, class S, int n = Sys::dof>
ConstraintRows<S, Sys::constraints> discrete_constraint_rows(const Sys& sys, const S& t, const S& h, const Vec<S, n>& q0,
                                                             const Vec<S, n>& q1) {
  constexpr int m = Sys::constraints;
  if constexpr (has_holonomic_v<Sys>) {
    return {sys.holonomic(S(t + h), q1), Vec<S, m>::Zero()};
  } else {
    const auto x = Quad::template psi<Sys>(t, h, q0, q1);
    return constraint_rows_from<S, n, m>(sys.constraint_matrix(x.t, x.q), sys.constraint_offset(x.t, x.q), x.v);
  }
}

// Whether a quadrature's Psi samples the constraint at the start of the step, (t_j, q_j) (`psi_at_start`).
template <class Quad, class = void>
struct psi_at_start : std::false_type {};
template <class Quad>
struct psi_at_start<Quad, std::enable_if_t<Quad::psi_at_start>> : std::true_type {};

// The constraint's part of a step's rows, the same for both principles: Phi_d (with its scale) and the covector
// A(t_j, q_j) of the impulse -A^T lambda in the dynamics rows. The stepper also evaluates it alone, in dual numbers
// over q_{j+1}, to bring a Jacobian kept from the last step up to date in these rows and columns (generic/newton.hpp
// says why those and not the others).
template <class S, int n, int m>
struct ConstraintBlock {
  ConstraintRows<S, m> phi;
  Mat<S, m, n> A;
};
// Where Psi samples at (t_j, q_j), Phi_d is formed from that same A (a sin and a cos fewer on the knife edge).
template <class Sys, class Quad, class S, int n = Sys::dof>
ConstraintBlock<S, n, Sys::constraints> constraint_block(const Sys& sys, const S& t, const S& h, const Vec<S, n>& q0,
                                                         const Vec<S, n>& q1) {
  constexpr int m = Sys::constraints;
  const Mat<S, m, n> A = sys.constraint_matrix(t, q0);
  if constexpr (psi_at_start<Quad>::value && !has_holonomic_v<Sys>) {
    const auto x = Quad::template psi<Sys>(t, h, q0, q1);
    return {constraint_rows_from<S, n, m>(A, sys.constraint_offset(t, q0), x.v), A};
  } else {
    return {discrete_constraint_rows<Sys, Quad>(sys, t, h, q0, q1), A};
  }
}

// ---------------------------------------------------------------------------------------------------
// Partial derivatives of 𝓛 by one forward pass over the arguments of interest.

namespace detail {

// D1 (n entries, with respect to q_j) and, for contact, D3 (with respect to z_j), and the value.
template <class S, int n>
struct FirstSlot {
  S value;
  Vec<S, n> dq;
  S dz;
};

template <class S, int n, int K, class F>
FirstSlot<S, n> partials(const F& f, const Vec<S, n>& q, const S& z) {
  using D = Dual<S, K>;
  Vec<D, n> Q;
  for (int i = 0; i < n; ++i) Q(i) = D::variable(q(i), i);
  D Z(z);
  if constexpr (K > n) Z = D::variable(z, n);
  const D y = f(Q, Z);
  FirstSlot<S, n> out;
  out.value = y.v;
  for (int i = 0; i < n; ++i) out.dq(i) = y.d[static_cast<std::size_t>(i)];
  if constexpr (K > n)
    out.dz = y.d[static_cast<std::size_t>(n)];
  else
    out.dz = S(0);
  return out;
}

// 𝓛 and all its first partials D1 (q_j), D2 (q_{j+1}), D3 (z_j), D4 (z_{j+1}) in one forward pass: what a
// step needs at each Newton iterate (its rows, and at the solution p_{j+1} and z_{j+1} without another pass).
template <class S, int n>
struct AllSlots {
  S value, d3, d4;
  Vec<S, n> d1, d2;
};

// f(Q0, Q1, Z0, Z1); NZ = 0 (LA), 1 (z_j only) or 2 (z_j and z_{j+1}) z-directions.
template <class S, int n, int NZ, class F>
AllSlots<S, n> all_partials(const F& f, const Vec<S, n>& q0, const Vec<S, n>& q1, const S& z0, const S& z1) {
  constexpr int N = 2 * n + NZ;
  using D = Dual<S, N>;
  Vec<D, n> Q0, Q1;
  for (int i = 0; i < n; ++i) {
    Q0(i) = D::variable(q0(i), i);
    Q1(i) = D::variable(q1(i), n + i);
  }
  D Z0(z0), Z1(z1);
  if constexpr (NZ >= 1) Z0 = D::variable(z0, 2 * n);
  if constexpr (NZ >= 2) Z1 = D::variable(z1, 2 * n + 1);
  const D y = f(Q0, Q1, Z0, Z1);
  AllSlots<S, n> out;
  out.value = y.v;
  for (int i = 0; i < n; ++i) {
    out.d1(i) = y.d[static_cast<std::size_t>(i)];
    out.d2(i) = y.d[static_cast<std::size_t>(n + i)];
  }
  out.d3 = NZ >= 1 ? y.d[static_cast<std::size_t>(2 * n)] : S(0);
  out.d4 = NZ >= 2 ? y.d[static_cast<std::size_t>(N - 1)] : S(0);
  return out;
}

}  // namespace detail

// ---------------------------------------------------------------------------------------------------
// The principles. Each is a family over its quadratures: `Quad` picks 𝓛, F_d^± and Psi.

// What one step's equations are made of, in the scalar S: the rows of the residual and the size of the
// terms they are made of (the round-off scale of each row, for the stopping rule).
template <class S, int n, int m>
struct StepRows {
  Vec<S, n> dynamics;   // the n rows of (1) or (4)
  S action;             // z_{j+1} - z_j - 𝓛 (contact with implicit z; 0 otherwise)
  Vec<S, m> constraint; // Phi_d
  // d dynamics / d lambda = -A(t_j, q_j)^T: the rows are affine in lambda (it enters only as the constraint
  // impulse -A^T lambda, A taken at the start of the step), and no other row or output depends on it. The
  // stepper takes the Jacobian's lambda columns from here instead of differentiating the rows in m more
  // directions (checked against that full forward pass in tests/generic_checks.hpp).
  Mat<S, n, m> dynamics_lambda;
  Vec<S, n> dynamics_scale;
  S action_scale;
  Vec<S, m> constraint_scale;
  Vec<S, n> p_next;  // p_{j+1} at these (q_{j+1}, z_{j+1}): the step's output once the rows vanish
  S z_next;          // z_{j+1} (contact; z_j for LA)
};

template <class Quad>
struct LagrangeDAlembert {
  using quadrature = Quad;
  static constexpr bool contact = false;
  static constexpr bool implicit_z = false;
  static constexpr int order = Quad::order;

  // p_j^+ part: D1 𝓛(q_j, q_{j+1}) + F_d^-(q_j, q_{j+1}) = -p_j^+.
  template <class Sys, class S, int n = Sys::dof>
  static Vec<S, n> minus_p_plus(const Sys& sys, const S& t, const S& h, const Vec<S, n>& q0, const Vec<S, n>& q1,
                                Vec<S, n>* d1 = nullptr) {
    const auto D1 = detail::partials<S, n, n>(
        [&](const auto& Q, const auto&) {
          using D = typename std::decay_t<decltype(Q)>::Scalar;
          return Quad::action(sys, D(t), D(h), Q, Vec<D, n>(q1.template cast<D>()));
        },
        q0, S(0));
    if (d1) *d1 = D1.dq;
    return D1.dq + Quad::force_minus(sys, t, h, q0, q1);
  }

  // p_{j+1} = D2 𝓛(q_j, q_{j+1}) + F_d^+(q_j, q_{j+1}).
  template <class Sys, class S, int n = Sys::dof>
  static Vec<S, n> p_minus(const Sys& sys, const S& t, const S& h, const Vec<S, n>& q0, const Vec<S, n>& q1) {
    const auto D2 = detail::partials<S, n, n>(
        [&](const auto& Q, const auto&) {
          using D = typename std::decay_t<decltype(Q)>::Scalar;
          return Quad::action(sys, D(t), D(h), Vec<D, n>(q0.template cast<D>()), Q);
        },
        q1, S(0));
    return D2.dq + Quad::force_plus(sys, t, h, q0, q1);
  }

  // The rows of one step in position–momentum form (unknowns q_{j+1}, lambda; z is not used).
  template <class Sys, class S, int n = Sys::dof, int m = Sys::constraints>
  static StepRows<S, n, m> rows(const Sys& sys, const S& t, const S& h, const Vec<S, n>& q0, const Vec<S, n>& p0,
                                const S& z0, const Vec<S, n>& q1, const S& /*z1*/, const Vec<S, m>& lambda) {
    StepRows<S, n, m> r;
    const auto D = detail::all_partials<S, n, 0>(
        [&](const auto& Q0, const auto& Q1, const auto&, const auto&) {
          using DS = typename std::decay_t<decltype(Q0)>::Scalar;
          return Quad::action(sys, DS(t), DS(h), Q0, Q1);
        },
        q0, q1, S(0), S(0));
    const Vec<S, n> fm = Quad::force_minus(sys, t, h, q0, q1);
    r.dynamics = D.d1 + fm + p0;
    r.dynamics_scale = D.d1.cwiseAbs() + fm.cwiseAbs() + p0.cwiseAbs();
    if constexpr (m > 0) {
      const auto cb = constraint_block<Sys, Quad>(sys, t, h, q0, q1);
      const Vec<S, n> force = cb.A.transpose() * lambda;
      r.dynamics -= force;
      r.dynamics_lambda = -cb.A.transpose();
      r.dynamics_scale += force.cwiseAbs();
      r.constraint = cb.phi.value;
      r.constraint_scale = cb.phi.scale;
    }
    r.action = S(0);
    r.action_scale = S(0);
    r.p_next = D.d2 + Quad::force_plus(sys, t, h, q0, q1);
    r.z_next = z0;
    return r;
  }

  // The three-point residual of (1) at q_j (n rows), for tests and the modified equations.
  template <class Sys, class S, int n = Sys::dof, int m = Sys::constraints>
  static Vec<S, n> residual(const Sys& sys, const S& t, const S& h, const Vec<S, n>& qm, const Vec<S, n>& q,
                            const Vec<S, n>& qp, const Vec<S, m>& lambda) {
    return residual_between(sys, t, h, h, qm, q, qp, lambda);
  }
  // The same at q_j between a step h_before (from q_{j-1}) and a step h_after (to q_{j+1}): p_j^- of the step
  // before equals p_j^+ of the step after up to the impulse. It holds at every node of a composition's stages
  // (the modified equations of compositions, modified/composed_residual.hpp).
  template <class Sys, class S, int n = Sys::dof, int m = Sys::constraints>
  static Vec<S, n> residual_between(const Sys& sys, const S& t, const S& h_before, const S& h_after, const Vec<S, n>& qm,
                                    const Vec<S, n>& q, const Vec<S, n>& qp, const Vec<S, m>& lambda) {
    Vec<S, n> r = minus_p_plus(sys, t, h_after, q, qp) + p_minus(sys, S(t - h_before), h_before, qm, q);
    if constexpr (m > 0) r -= sys.constraint_matrix(t, q).transpose() * lambda;
    return r;
  }

  // The start: p_0 is the continuous momentum dL/dq' at the consistent initial velocity.
  template <class Sys, class T, int n = Sys::dof>
  static Vec<T, n> initial_momentum(const Sys& sys, const T& t, const Vec<T, n>& q, const Vec<T, n>& v, const T& /*z*/) {
    return momentum(sys, t, q, v);
  }
};

template <class Quad>
struct Herglotz {
  using quadrature = Quad;
  static constexpr bool contact = true;
  static constexpr bool implicit_z = Quad::implicit_z;
  static constexpr int order = Quad::order;

  // 𝓛 and its partials with respect to the first slot (q_j, z_j).
  template <class Sys, class S, int n = Sys::dof>
  static detail::FirstSlot<S, n> first_slot(const Sys& sys, const S& t, const S& h, const Vec<S, n>& q0,
                                            const Vec<S, n>& q1, const S& z0, const S& z1) {
    return detail::partials<S, n, n + 1>(
        [&](const auto& Q, const auto& Z) {
          using D = typename std::decay_t<decltype(Q)>::Scalar;
          return Quad::action(sys, D(t), D(h), Q, Vec<D, n>(q1.template cast<D>()), Z, D(z1));
        },
        q0, z0);
  }
  // 𝓛 and its partials with respect to the second slot (q_{j+1}, z_{j+1}).
  template <class Sys, class S, int n = Sys::dof>
  static detail::FirstSlot<S, n> second_slot(const Sys& sys, const S& t, const S& h, const Vec<S, n>& q0,
                                             const Vec<S, n>& q1, const S& z0, const S& z1) {
    return detail::partials<S, n, (Quad::implicit_z ? n + 1 : n)>(
        [&](const auto& Q, const auto& Z) {
          using D = typename std::decay_t<decltype(Q)>::Scalar;
          return Quad::action(sys, D(t), D(h), Vec<D, n>(q0.template cast<D>()), Q, D(z0), Z);
        },
        q1, z1);
  }

  // p_{j+1} = D2 𝓛 / (1 - D4 𝓛).
  template <class Sys, class S, int n = Sys::dof>
  static Vec<S, n> p_minus(const Sys& sys, const S& t, const S& h, const Vec<S, n>& q0, const Vec<S, n>& q1,
                           const S& z0, const S& z1) {
    const auto D = second_slot(sys, t, h, q0, q1, z0, z1);
    return D.dq / (S(1) - D.dz);
  }

  // z_{j+1} for a quadrature that is explicit in z: z_j + 𝓛(q_j, q_{j+1}, z_j).
  template <class Sys, class S, int n = Sys::dof>
  static S next_z(const Sys& sys, const S& t, const S& h, const Vec<S, n>& q0, const Vec<S, n>& q1, const S& z0) {
    return z0 + Quad::action(sys, t, h, q0, q1, z0, z0);
  }

  template <class Sys, class S, int n = Sys::dof, int m = Sys::constraints>
  static StepRows<S, n, m> rows(const Sys& sys, const S& t, const S& h, const Vec<S, n>& q0, const Vec<S, n>& p0,
                                const S& z0, const Vec<S, n>& q1, const S& z1, const Vec<S, m>& lambda) {
    using std::abs;
    StepRows<S, n, m> r;
    const auto D = detail::all_partials<S, n, (Quad::implicit_z ? 2 : 1)>(
        [&](const auto& Q0, const auto& Q1, const auto& Z0, const auto& Z1) {
          using DS = typename std::decay_t<decltype(Q0)>::Scalar;
          return Quad::action(sys, DS(t), DS(h), Q0, Q1, Z0, Z1);
        },
        q0, q1, z0, z1);
    const S c = S(1) + D.d3;
    r.dynamics = D.d1 + c * p0;
    r.dynamics_scale = D.d1.cwiseAbs() + abs(c) * p0.cwiseAbs();
    if constexpr (m > 0) {
      const auto cb = constraint_block<Sys, Quad>(sys, t, h, q0, q1);
      const Vec<S, n> force = cb.A.transpose() * lambda;
      r.dynamics -= force;
      r.dynamics_lambda = -cb.A.transpose();
      r.dynamics_scale += force.cwiseAbs();
      r.constraint = cb.phi.value;
      r.constraint_scale = cb.phi.scale;
    }
    if constexpr (Quad::implicit_z) {
      r.action = z1 - z0 - D.value;
      r.action_scale = abs(z1) + abs(z0) + abs(D.value);
      r.z_next = z1;
    } else {
      r.action = S(0);
      r.action_scale = S(0);
      r.z_next = z0 + D.value;
    }
    r.p_next = D.d2 / (S(1) - D.d4);
    return r;
  }

  // The three-point residual of (4) at q_j (n rows).
  template <class Sys, class S, int n = Sys::dof, int m = Sys::constraints>
  static Vec<S, n> residual(const Sys& sys, const S& t, const S& h, const Vec<S, n>& qm, const Vec<S, n>& q,
                            const Vec<S, n>& qp, const S& zm, const S& z, const S& zp, const Vec<S, m>& lambda) {
    return residual_between(sys, t, h, h, qm, q, qp, zm, z, zp, lambda);
  }
  // The same between a step h_before and a step h_after (as LagrangeDAlembert::residual_between).
  template <class Sys, class S, int n = Sys::dof, int m = Sys::constraints>
  static Vec<S, n> residual_between(const Sys& sys, const S& t, const S& h_before, const S& h_after, const Vec<S, n>& qm,
                                    const Vec<S, n>& q, const Vec<S, n>& qp, const S& zm, const S& z, const S& zp,
                                    const Vec<S, m>& lambda) {
    const auto D = first_slot(sys, t, h_after, q, qp, z, zp);
    Vec<S, n> r = D.dq + (S(1) + D.dz) * p_minus(sys, S(t - h_before), h_before, qm, q, zm, z);
    if constexpr (m > 0) r -= sys.constraint_matrix(t, q).transpose() * lambda;
    return r;
  }

  template <class Sys, class T, int n = Sys::dof>
  static Vec<T, n> initial_momentum(const Sys& sys, const T& t, const Vec<T, n>& q, const Vec<T, n>& v, const T& z) {
    return herglotz_momentum(sys, t, q, v, z);
  }
};

// The generic schemes: a principle over a quadrature. A new scheme is a new quadrature (a struct like the ones
// above, with its `scheme` name) and one entry in AllSchemesTuple below; every system then has it.
using LaLeft = LagrangeDAlembert<la_quadrature::Left>;
using LaMidpoint = LagrangeDAlembert<la_quadrature::Midpoint>;
using LaTrapezoid = LagrangeDAlembert<la_quadrature::Trapezoid>;
using ContactLeft = Herglotz<contact_quadrature::TrapezoidHeldZ>;
using ContactTrapezoid = Herglotz<contact_quadrature::Trapezoid>;

// Every generic scheme, for code that iterates over them (the registry, benchmarks).
using AllSchemesTuple = std::tuple<LaLeft, ContactLeft, LaMidpoint, LaTrapezoid, ContactTrapezoid>;

template <class Scheme>
constexpr const char* scheme_name() {
  return Scheme::quadrature::scheme;
}

}  // namespace geomint::generic
