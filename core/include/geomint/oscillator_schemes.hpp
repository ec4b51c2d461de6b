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
    s.p = (s.p - h * s.q) / (1 + h * alpha);
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
    s.p = (s.p - h * s.q) / (1 + alpha);
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
    const T v = (qn - s.q) / h;
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
    const T d = 1 + h * alpha / 2;
    const T ph = (s.p - h / 2 * s.q) / d;
    s.q = s.q + h * ph;
    s.p = ph - h / 2 * (s.q + alpha * ph);
  }
};

}  // namespace geomint::schemes
