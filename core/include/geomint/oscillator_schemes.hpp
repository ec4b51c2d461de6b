#pragma once
// Integrators for the damped oscillator (Section 3.1). Each scheme is one struct: its name, its order,
// one step (closed form, templated on the scalar) and the residual of the equation it comes from, so
// tests can check that the fast step zeroes its own defining equation.
#include "geomint/oscillator.hpp"

namespace geomint::schemes {

// Lagrange–d'Alembert, derived from the forced discrete Euler–Lagrange equations (1) with
// L_d = h L(q_j, v_j), F_d^- = h F(q_j, v_j) = -alpha h v_j, F_d^+ = 0, v_j = (q_{j+1}-q_j)/h:
//   -v_j - h q_j + v_{j-1} - alpha h v_j = 0.
// Discrete Legendre transform p_j = -D1 L_d - F_d^- = (1 + h alpha) v_j + h q_j, p_{j+1} = D2 L_d = v_j:
//   p_{j+1} = (p_j - h q_j) / (1 + h alpha),   q_{j+1} = q_j + h p_{j+1}.
// The paper's eq. (7) prints the denominator as (1 + alpha); see LaPrinted.
struct La {
  static constexpr const char* name = "la";
  static constexpr int order = 1;
  template <class T>
  static void step(OscState<T>& s, T h, T alpha) {
    // multiply by the reciprocal: loop-invariant, so the division leaves the step's critical path
    const T c = 1 / (1 + h * alpha);
    s.p = (s.p - h * s.q) * c;
    s.q = s.q + h * s.p;
  }
  // Forced discrete Euler–Lagrange residual (1) at q_j given q_{j-1}, q_j, q_{j+1}.
  template <class T>
  static T residual(T qm, T q, T qp, T h, T alpha) {
    return -(qp - q) / h - h * q + (q - qm) / h - alpha * (qp - q);
  }
};

// Eq. (7) exactly as printed: p_j = (p_{j-1} - h q_{j-1}) / (1 + alpha). Kept so users can see what it
// does: it damps by 1/(1+alpha) per step whatever h is, so it does not converge as h -> 0.
struct LaPrinted {
  static constexpr const char* name = "la-printed";
  static constexpr int order = 0;
  template <class T>
  static void step(OscState<T>& s, T h, T alpha) {
    const T c = 1 / (1 + alpha);
    s.p = (s.p - h * s.q) * c;
    s.q = s.q + h * s.p;
  }
};

// Contact integrator, eq. (10): discrete Herglotz equations (3) with
// L_d(q_j, q_{j+1}, z_j) = h [ v_j^2/2 - (q_j^2 + q_{j+1}^2)/4 - alpha z_j ],  z_{j+1} = z_j + L_d.
//   q_{j+1} = (1 - h^2/2) q_j + h (1 - h alpha) p_j,
//   p_{j+1} = (1 - h alpha) p_j - h/2 (q_{j+1} + q_j).
struct Contact {
  static constexpr const char* name = "contact";
  static constexpr int order = 1;
  template <class T>
  static void step(OscState<T>& s, T h, T alpha) {
    const T qn = (1 - h * h / 2) * s.q + h * (1 - h * alpha) * s.p;
    const T inv_h = 1 / h;  // loop-invariant reciprocal: no division inside a run
    const T v = (qn - s.q) * inv_h;
    s.z = s.z + h * (v * v / 2 - (s.q * s.q + qn * qn) / 4 - alpha * s.z);
    s.p = (1 - h * alpha) * s.p - h / 2 * (qn + s.q);
    s.q = qn;
  }
  // Discrete Herglotz residual: D1 L_d(q_j,q_{j+1},z_j) + D2 L_d(q_{j-1},q_j,z_{j-1}) (1 + D3 L_d(q_j,q_{j+1},z_j)),
  // with D3 L_d = -h alpha.
  template <class T>
  static T residual(T qm, T q, T qp, T h, T alpha) {
    const T d1 = -(qp - q) / h - h * q / 2;
    const T d2 = (q - qm) / h - h * q / 2;
    return d1 + d2 * (1 - h * alpha);
  }
};

// Implicit leapfrog: Störmer–Verlet (Lobatto IIIA–IIIB) for q' = p, p' = f(q, p) = -q - alpha p:
//   p_{j+1/2} = p_j + h/2 f(q_j, p_{j+1/2})          (implicit, linear: closed form)
//   q_{j+1}   = q_j + h p_{j+1/2}
//   p_{j+1}   = p_{j+1/2} + h/2 f(q_{j+1}, p_{j+1/2})  (explicit)
// The two half kicks are adjoint, so the step is symmetric and second order. The paper's reference at h/10.
struct Leapfrog {
  static constexpr const char* name = "leapfrog";
  static constexpr int order = 2;
  template <class T>
  static void step(OscState<T>& s, T h, T alpha) {
    const T d = 1 / (1 + h * alpha / 2);
    const T ph = (s.p - h / 2 * s.q) * d;
    s.q = s.q + h * ph;
    s.p = ph - h / 2 * (s.q + alpha * ph);
  }
};

// Second-order comparators (what a user would pick instead of the first-order schemes).

// Midpoint forced variational integrator: L_d = h L((q_j+q_{j+1})/2, v_j), F_d^+ = F_d^- = h/2 F(., v_j).
// Discrete Legendre transforms p_j = -D1 L_d - F_d^-, p_{j+1} = D2 L_d + F_d^+ give, with c = 1 + h alpha/2 + h^2/4,
//   v = (p_j - h q_j/2) / c,  q_{j+1} = q_j + h v,  p_{j+1} = (1 - h alpha/2 - h^2/4) v - h q_j/2.
// Symmetric, hence second order.
struct LaMidpoint {
  static constexpr const char* name = "la-midpoint";
  static constexpr int order = 2;
  template <class T>
  static void step(OscState<T>& s, T h, T alpha) {
    const T v = (s.p - h * s.q / 2) * (1 / (1 + h * alpha / 2 + h * h / 4));
    s.p = (1 - h * alpha / 2 - h * h / 4) * v - h * s.q / 2;
    s.q = s.q + h * v;
  }
  // Forced DEL residual with the midpoint L_d and split forces.
  template <class T>
  static T residual(T qm, T q, T qp, T h, T alpha) {
    const T v0 = (q - qm) / h, v1 = (qp - q) / h;
    return -v1 - h * (q + qp) / 4 + v0 - h * (qm + q) / 4 - h * alpha / 2 * (v0 + v1);
  }
};

// Symmetric contact integrator (trapezoidal Herglotz): L_d = h [ v^2/2 - (q_j^2+q_{j+1}^2)/4 - alpha (z_j+z_{j+1})/2 ]
// with z_{j+1} = z_j + L_d, solved for z_{j+1} (linear), so L_d(q_j,q_{j+1},z_j) = h (A - alpha z_j)/(1 + h alpha/2),
// A = v^2/2 - (q_j^2+q_{j+1}^2)/4. The contact Legendre maps p_j = -D1 L_d / (1 + D3 L_d), p_{j+1} = D2 L_d give
//   v = (1 - h alpha/2) p_j - h q_j/2,  q_{j+1} = q_j + h v,  p_{j+1} = (v - h q_{j+1}/2)/(1 + h alpha/2).
struct ContactSymmetric {
  static constexpr const char* name = "contact-sym";
  static constexpr int order = 2;
  template <class T>
  static void step(OscState<T>& s, T h, T alpha) {
    const T v = (1 - h * alpha / 2) * s.p - h * s.q / 2;
    const T qn = s.q + h * v;
    const T A = v * v / 2 - (s.q * s.q + qn * qn) / 4;
    const T d = 1 / (1 + h * alpha / 2);
    s.z = ((1 - h * alpha / 2) * s.z + h * A) * d;
    s.p = (v - h * qn / 2) * d;
    s.q = qn;
  }
};

}  // namespace geomint::schemes
