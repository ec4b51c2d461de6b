#pragma once
// The paper's equations restated literally, for tests only: each closed form (a fast path of its system) is held
// to the equation it was derived from, written here independently of the closed form and of the generic schemes.
#include <cmath>
#include <type_traits>

#include <Eigen/Core>

#include "geomint/constants.hpp"
#include "geomint/systems/foucault.hpp"

namespace geomint::testing {

// ---- the damped oscillator (Section 3.1), three-point residuals at q_j given q_{j-1}, q_j, q_{j+1}

// Forced discrete Euler–Lagrange residual (1) of `la`: L_d = h L(q_j, v_j), F_d^- = -alpha h v_j.
template <class T>
T la_residual(T qm, T q, T qp, T h, T alpha) {
  return -(qp - q) / h - h * q + (q - qm) / h - alpha * (qp - q);
}

// Forced DEL residual of `la-midpoint`: the midpoint L_d and split forces.
template <class T>
T la_midpoint_residual(T qm, T q, T qp, T h, T alpha) {
  const T v0 = (q - qm) / h, v1 = (qp - q) / h;
  return -v1 - h * (q + qp) / 4 + v0 - h * (qm + q) / 4 - h * alpha / 2 * (v0 + v1);
}

// Discrete Herglotz residual of `contact`, (3) with (10)'s L_d:
// D1 L_d(q_j,q_{j+1},z_j) + D2 L_d(q_{j-1},q_j,z_{j-1}) (1 + D3 L_d(q_j,q_{j+1},z_j)), D3 L_d = -h alpha.
template <class T>
T contact_residual(T qm, T q, T qp, T h, T alpha) {
  const T d1 = -(qp - q) / h - h * q / 2;
  const T d2 = (q - qm) / h - h * q / 2;
  return d1 + d2 * (1 - h * alpha);
}

// ---- the Foucault pendulum (Section 3.2)

// The paper's parameters restated here, not taken from FoucaultParams.
struct Literal {
  double m, w2, s, alpha;
  explicit Literal(const systems::FoucaultPendulum& sc)
      : m(sc.m), w2(sc.g / sc.l), s(sc.Omega * std::sin(sc.beta_deg * geomint::pi / 180)), alpha(sc.alpha) {}
};

// Rows of (15) exactly as printed, with the sum of the absolute values of their terms (the round-off scale).
inline void la_rows(const Literal& P, double h, const Vec2<double>& a, const Vec2<double>& b, const Vec2<double>& c,
             double l1, double row[3], double scale[3]) {
  const double xm = a(0), ym = a(1), x = b(0), y = b(1), xp = c(0), yp = c(1);
  row[0] = (-xp + 2 * x - xm) / h - h * P.w2 * x - P.alpha * (xp - x) + l1 * y / P.m;
  row[1] = (-yp + 2 * y - ym) / h - h * P.w2 * y - P.alpha * (yp - y) - l1 * x / P.m;
  row[2] = -y * (xp - x) / h + x * (yp - y) / h + P.s * (x * x + y * y);
  scale[0] = (std::abs(xp) + 2 * std::abs(x) + std::abs(xm)) / h + h * P.w2 * std::abs(x) +
             P.alpha * (std::abs(xp) + std::abs(x)) + std::abs(l1 * y / P.m);
  scale[1] = (std::abs(yp) + 2 * std::abs(y) + std::abs(ym)) / h + h * P.w2 * std::abs(y) +
             P.alpha * (std::abs(yp) + std::abs(y)) + std::abs(l1 * x / P.m);
  scale[2] = std::hypot(x, y) * (std::hypot(x, y) + std::hypot(xp, yp)) / h;
}

// Rows of (18) exactly as printed.
inline void contact_rows(const Literal& P, double h, const Vec2<double>& a, const Vec2<double>& b, const Vec2<double>& c,
                  double l1, double row[3], double scale[3]) {
  const double xm = a(0), ym = a(1), x = b(0), y = b(1), xp = c(0), yp = c(1);
  const double gl = P.w2;
  row[0] = (-xp + 2 * x - xm) / (h * h) - gl * x - P.alpha * ((x - xm) / h - h * gl / 2 * x) + l1 * y / P.m;
  row[1] = (-yp + 2 * y - ym) / (h * h) - gl * y - P.alpha * ((y - ym) / h - h * gl / 2 * y) - l1 * x / P.m;
  row[2] = -y * (xp - x) / h + x * (yp - y) / h + P.s * (x * x + y * y);
  scale[0] = (std::abs(xp) + 2 * std::abs(x) + std::abs(xm)) / (h * h) + gl * std::abs(x) +
             P.alpha * ((std::abs(x) + std::abs(xm)) / h + h * gl / 2 * std::abs(x)) + std::abs(l1 * y / P.m);
  scale[1] = (std::abs(yp) + 2 * std::abs(y) + std::abs(ym)) / (h * h) + gl * std::abs(y) +
             P.alpha * ((std::abs(y) + std::abs(ym)) / h + h * gl / 2 * std::abs(y)) + std::abs(l1 * x / P.m);
  scale[2] = std::hypot(x, y) * (std::hypot(x, y) + std::hypot(xp, yp)) / h;
}

template <class Scheme>
void literal_rows(const Literal& P, double h, const Vec2<double>& a, const Vec2<double>& b, const Vec2<double>& c,
                  double l1, double row[3], double scale[3]) {
  if constexpr (std::is_same_v<Scheme, systems::FoucaultPendulum::La>)
    la_rows(P, h, a, b, c, l1, row, scale);
  else
    contact_rows(P, h, a, b, c, l1, row, scale);
}

// Rows 1-2 of (15) or (18) with the force along n(phi_j) instead of A(q_j), and the row n(phi_{j+1}).q_{j+1} of
// the rotation discretization (foucault-rotation), at (q_{j-1}, q_j, q_{j+1}, lambda_1).
template <class Scheme, class T>
Eigen::Matrix<T, 3, 1> rotation_rows(const FoucaultParams<T>& p, const Vec2<T>& qm, const Vec2<T>& q, const Vec2<T>& qn, T lambda1, T h,
                      const FoucaultLine<T>& L, const FoucaultLine<T>& Ln) {
  const T xm = qm(0), ym = qm(1), x = q(0), y = q(1), xn = qn(0), yn = qn(1);
  Eigen::Matrix<T, 3, 1> r;
  if constexpr (std::is_same_v<Scheme, systems::FoucaultPendulum::La>) {
    r(0) = (-xn + 2 * x - xm) / h - h * p.w2 * x - p.alpha * (xn - x) - lambda1 * L.n(0) / p.m;
    r(1) = (-yn + 2 * y - ym) / h - h * p.w2 * y - p.alpha * (yn - y) - lambda1 * L.n(1) / p.m;
  } else {
    r(0) = (-xn + 2 * x - xm) / (h * h) - p.w2 * x - p.alpha * ((x - xm) / h - h * p.w2 / 2 * x) - lambda1 * L.n(0) / p.m;
    r(1) = (-yn + 2 * y - ym) / (h * h) - p.w2 * y - p.alpha * ((y - ym) / h - h * p.w2 / 2 * y) - lambda1 * L.n(1) / p.m;
  }
  r(2) = Ln.n(0) * xn + Ln.n(1) * yn;
  return r;
}

// ---- the Foucault pendulum's steps (15), (18) as printed: the literal 3x3 linear system of one step in the
// unknowns z = (x_{j+1}, y_{j+1}, lambda_1), for the closed forms' cross-check and the PartialPivLU benchmark
// (experiments/bench_steps.cpp)

template <class T>
struct LinearStep {
  Eigen::Matrix<T, 3, 3> A;
  Eigen::Matrix<T, 3, 1> b;
};

// (15) (Scheme = FoucaultPendulum::La) or (18) (::Contact) as a linear system in (x_{j+1}, y_{j+1}, lambda_1).
template <class Scheme, class T>
LinearStep<T> paper_system(const FoucaultParams<T>& p, const Vec2<T>& qm, const Vec2<T>& q, T h) {
  if constexpr (std::is_same_v<Scheme, systems::FoucaultPendulum::La>) {
    const T xm = qm(0), ym = qm(1), x = q(0), y = q(1);
    const T c = 1 / h + p.alpha;
    LinearStep<T> ls;
    ls.A << -c, 0, y / p.m,  //
        0, -c, -x / p.m,     //
        -y / h, x / h, 0;
    ls.b << -(2 * x - xm) / h + h * p.w2 * x - p.alpha * x,  //
        -(2 * y - ym) / h + h * p.w2 * y - p.alpha * y,      //
        -p.s * (x * x + y * y);
    return ls;
  } else {
    static_assert(std::is_same_v<Scheme, systems::FoucaultPendulum::Contact>, "(15) or (18)");
    const T xm = qm(0), ym = qm(1), x = q(0), y = q(1);
    const T k = 1 / (h * h);
    LinearStep<T> ls;
    ls.A << -k, 0, y / p.m,  //
        0, -k, -x / p.m,     //
        -y / h, x / h, 0;
    ls.b << -(2 * x - xm) * k + p.w2 * x + p.alpha * ((x - xm) / h - h * p.w2 / 2 * x),  //
        -(2 * y - ym) * k + p.w2 * y + p.alpha * ((y - ym) / h - h * p.w2 / 2 * y),      //
        -p.s * (x * x + y * y);
    return ls;
  }
}

// The rotation step's 3x3 system: the paper's (paper_system) with the force column -n(phi_j)/m and
// the constraint row n(phi_{j+1}).q_{j+1} = 0.
template <class Scheme, class T>
LinearStep<T> rotation_system(const FoucaultParams<T>& p, const Vec2<T>& qm, const Vec2<T>& q, T h,
                              const FoucaultLine<T>& L, const FoucaultLine<T>& Ln) {
  LinearStep<T> ls = paper_system<Scheme>(p, qm, q, h);
  ls.A(0, 2) = -L.n(0) / p.m;
  ls.A(1, 2) = -L.n(1) / p.m;
  ls.A(2, 0) = Ln.n(0);
  ls.A(2, 1) = Ln.n(1);
  ls.b(2) = 0;
  return ls;
}

}  // namespace geomint::testing
