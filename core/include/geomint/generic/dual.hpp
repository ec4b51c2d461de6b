#pragma once
// Dual<T, N>: forward-mode automatic differentiation with N directions over any scalar T, nestable
// (Dual<Dual<double, 2>, 3> carries second derivatives) and usable as an Eigen scalar.
//
// Why not Eigen's AutoDiffScalar (unsupported/Eigen/AutoDiff), which the tests also use: the generic core
// pushes the same templated residual through double, long double, Boost quad, nested duals and (for the
// modified equations) truncated power series. AutoDiffScalar's value type is tied to its derivative
// vector's scalar and its expression templates need per-type workarounds when nested over non-double
// scalars; this plain value-plus-array type composes with any T that has + - * / and the <cmath>
// functions, compiles to straight-line code for the small fixed N of a step (no allocation), and is
// checked against AutoDiffScalar in tests/schemes/dual.test.cpp.
#include <array>
#include <cmath>
#include <type_traits>

#include <Eigen/Core>

namespace geomint {

template <class T, int N>
class Dual;

template <class X>
struct is_dual : std::false_type {};
template <class T, int N>
struct is_dual<Dual<T, N>> : std::true_type {};

// The innermost value of a (possibly nested) dual, or the scalar itself.
template <class X>
auto primal(const X& x) {
  if constexpr (is_dual<X>::value)
    return primal(x.v);
  else
    return x;
}

// Built-in numbers, and duals over them (nested at any depth): the scalars whose products with a constant
// built-in number skip the constant's (zero) derivatives.
template <class X>
struct over_builtin : std::is_arithmetic<X> {};
template <class T, int N>
struct over_builtin<Dual<T, N>> : over_builtin<T> {};

template <class T, int N>
class Dual {
 public:
  using value_type = T;
  T v{};
  std::array<T, N> d{};

  Dual() = default;
  Dual(const T& x) : v(x) {}  // NOLINT: a constant converts implicitly, as for a built-in scalar
  // Any other constant the value type is made from: a built-in number, or a system parameter of a symbolic
  // type (a formula times a dual, in a system templated on its parameter type).
  template <class U, std::enable_if_t<!std::is_same_v<U, T> && !is_dual<U>::value && std::is_constructible_v<T, const U&>, int> = 0>
  Dual(const U& x) : v(static_cast<T>(x)) {}  // NOLINT

  // The independent variable number i (0 <= i < N) at value x.
  static Dual variable(const T& x, int i) {
    Dual r(x);
    r.d[static_cast<std::size_t>(i)] = T(1);
    return r;
  }

  Dual& operator+=(const Dual& b) {
    v += b.v;
    for (int i = 0; i < N; ++i) d[i] += b.d[i];
    return *this;
  }
  Dual& operator-=(const Dual& b) {
    v -= b.v;
    for (int i = 0; i < N; ++i) d[i] -= b.d[i];
    return *this;
  }
  Dual& operator*=(const Dual& b) { return *this = *this * b; }
  Dual& operator/=(const Dual& b) { return *this = *this / b; }

  friend Dual operator+(const Dual& a) { return a; }
  friend Dual operator-(const Dual& a) {
    Dual r;
    r.v = -a.v;
    for (int i = 0; i < N; ++i) r.d[i] = -a.d[i];
    return r;
  }
  friend Dual operator+(Dual a, const Dual& b) { return a += b; }
  friend Dual operator-(Dual a, const Dual& b) { return a -= b; }
  friend Dual operator*(const Dual& a, const Dual& b) {
    Dual r;
    r.v = a.v * b.v;
    for (int i = 0; i < N; ++i) r.d[i] = a.d[i] * b.v + a.v * b.d[i];
    return r;
  }
  friend Dual operator/(const Dual& a, const Dual& b) {
    Dual r;
    const T inv = T(1) / b.v;
    r.v = a.v * inv;
    for (int i = 0; i < N; ++i) r.d[i] = (a.d[i] - r.v * b.d[i]) * inv;
    return r;
  }

  // A built-in constant c: c a, a c, a / c, a + c, a - c, c + a, c - a carry no derivative of c, so they are
  // N (+ 1) operations on the parts instead of a full product (a system's parameters, quadrature weights; the
  // same values: a.d[i] c where the full product adds a.v 0). Only over built-in value types, whose products
  // with a built-in number are defined.
  template <class C>
  using if_constant = std::enable_if_t<std::is_arithmetic_v<C> && over_builtin<T>::value, int>;
  template <class C, if_constant<C> = 0>
  friend Dual operator*(const Dual& a, const C& c) {
    Dual r;
    r.v = a.v * c;
    for (int i = 0; i < N; ++i) r.d[i] = a.d[i] * c;
    return r;
  }
  template <class C, if_constant<C> = 0>
  friend Dual operator*(const C& c, const Dual& a) {
    Dual r;
    r.v = c * a.v;
    for (int i = 0; i < N; ++i) r.d[i] = c * a.d[i];
    return r;
  }
  template <class C, if_constant<C> = 0>
  friend Dual operator/(const Dual& a, const C& c) {
    Dual r;
    r.v = a.v / c;
    for (int i = 0; i < N; ++i) r.d[i] = a.d[i] / c;
    return r;
  }

  // Comparisons look at the value only (branches in a model follow the primal path).
  friend bool operator<(const Dual& a, const Dual& b) { return a.v < b.v; }
  friend bool operator>(const Dual& a, const Dual& b) { return a.v > b.v; }
  friend bool operator<=(const Dual& a, const Dual& b) { return a.v <= b.v; }
  friend bool operator>=(const Dual& a, const Dual& b) { return a.v >= b.v; }
  friend bool operator==(const Dual& a, const Dual& b) { return a.v == b.v; }
  friend bool operator!=(const Dual& a, const Dual& b) { return a.v != b.v; }

  // Chain rule for a unary function with value f and derivative df at a.v.
  friend Dual chain(const Dual& a, const T& f, const T& df) {
    Dual r;
    r.v = f;
    for (int i = 0; i < N; ++i) r.d[i] = df * a.d[i];
    return r;
  }

  friend Dual sin(const Dual& a) {
    using std::cos;
    using std::sin;
    return chain(a, sin(a.v), cos(a.v));
  }
  friend Dual cos(const Dual& a) {
    using std::cos;
    using std::sin;
    return chain(a, cos(a.v), -sin(a.v));
  }
  friend Dual tan(const Dual& a) {
    using std::tan;
    const T t = tan(a.v);
    return chain(a, t, T(1) + t * t);
  }
  friend Dual exp(const Dual& a) {
    using std::exp;
    const T e = exp(a.v);
    return chain(a, e, e);
  }
  friend Dual log(const Dual& a) {
    using std::log;
    return chain(a, log(a.v), T(1) / a.v);
  }
  friend Dual sqrt(const Dual& a) {
    using std::sqrt;
    const T s = sqrt(a.v);
    return chain(a, s, T(1) / (2 * s));
  }
  friend Dual sinh(const Dual& a) {
    using std::cosh;
    using std::sinh;
    return chain(a, sinh(a.v), cosh(a.v));
  }
  friend Dual cosh(const Dual& a) {
    using std::cosh;
    using std::sinh;
    return chain(a, cosh(a.v), sinh(a.v));
  }
  friend Dual tanh(const Dual& a) {
    using std::tanh;
    const T t = tanh(a.v);
    return chain(a, t, T(1) - t * t);
  }
  friend Dual atan(const Dual& a) {
    using std::atan;
    return chain(a, atan(a.v), T(1) / (T(1) + a.v * a.v));
  }
  friend Dual asin(const Dual& a) {
    using std::asin;
    using std::sqrt;
    return chain(a, asin(a.v), T(1) / sqrt(T(1) - a.v * a.v));
  }
  friend Dual acos(const Dual& a) {
    using std::acos;
    using std::sqrt;
    return chain(a, acos(a.v), -T(1) / sqrt(T(1) - a.v * a.v));
  }
  friend Dual atan2(const Dual& y, const Dual& x) {
    using std::atan2;
    Dual r;
    r.v = atan2(y.v, x.v);
    const T inv = T(1) / (x.v * x.v + y.v * y.v);
    for (int i = 0; i < N; ++i) r.d[i] = (x.v * y.d[i] - y.v * x.d[i]) * inv;
    return r;
  }
  friend Dual pow(const Dual& a, double p) {
    using std::pow;
    return chain(a, pow(a.v, T(p)), T(p) * pow(a.v, T(p - 1)));
  }
  friend Dual abs(const Dual& a) { return a.v < T(0) ? -a : a; }
  friend Dual fabs(const Dual& a) { return abs(a); }
  friend bool isfinite(const Dual& a) {
    using std::isfinite;
    if (!isfinite(a.v)) return false;
    for (int i = 0; i < N; ++i)
      if (!isfinite(a.d[i])) return false;
    return true;
  }
};

}  // namespace geomint

// Dual as an Eigen scalar: fixed-size vectors and matrices of duals, mixed with double constants.
namespace Eigen {
template <class T, int N>
struct NumTraits<geomint::Dual<T, N>> : NumTraits<double> {
  using Real = geomint::Dual<T, N>;
  using NonInteger = Real;
  using Nested = Real;
  using Literal = Real;
  enum {
    IsComplex = 0,
    IsInteger = 0,
    IsSigned = 1,
    RequireInitialization = 1,
    ReadCost = (N + 1) * NumTraits<T>::ReadCost,
    AddCost = (N + 1) * NumTraits<T>::AddCost,
    MulCost = (2 * N + 1) * NumTraits<T>::MulCost
  };
  static Real epsilon() { return Real(NumTraits<T>::epsilon()); }
  static Real dummy_precision() { return Real(NumTraits<T>::dummy_precision()); }
  static Real highest() { return Real(NumTraits<T>::highest()); }
  static Real lowest() { return Real(NumTraits<T>::lowest()); }
  static int digits10() { return NumTraits<T>::digits10(); }
};
template <class T, int N, class Op>
struct ScalarBinaryOpTraits<geomint::Dual<T, N>, double, Op> {
  using ReturnType = geomint::Dual<T, N>;
};
template <class T, int N, class Op>
struct ScalarBinaryOpTraits<double, geomint::Dual<T, N>, Op> {
  using ReturnType = geomint::Dual<T, N>;
};
}  // namespace Eigen
