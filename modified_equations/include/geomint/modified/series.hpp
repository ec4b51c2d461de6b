#pragma once
// BiSeries<E, U, L>: a truncated power series in two small quantities, for pushing a scheme's own templated
// residual through the backward error analysis (geomint/modified/automatic.hpp):
//   eps — time along the modified flow (Taylor mode: the point t + eps of a trajectory), powers 0..E,
//   h   — the step size, Laurent: powers -L..U (the residuals divide by h: the chord (q1 - q0)/h, and its
//         derivative -1/h under the Dual of the discrete Legendre transforms).
// Value: sum a[j][k] eps^j h^k + O(degree p), where p is the *total-degree precision*: every coefficient with
// j + k >= p is unknown (stored as 0). Constants and monomials are exact (p = exact). Arithmetic propagates p
// the way truncated series do — (a + O(p_a))(b + O(p_b)) = ab + O(min(v_a + p_b, v_b + p_a)), v the lowest
// total degree present — so a division by h, which lowers the precision by one, can never leave a wrong
// coefficient behind unnoticed: the reader checks `known(j, k)`, and the engine sets the precision of its
// inputs so that only the coefficients it needs are computed (the cost adapts to the order asked for).
// Division by a series b needs b = h^v (b00 + ...) with b00 != 0 (a Laurent series in h with an invertible
// leading term): division by h whose numerator's leading coefficients vanish is then exact — they cancel
// exactly, because both sides of each difference are built from the same coefficients.
//
// Why our own type and not ADOL-C (libadolc-dev): the residual templates need a scalar that (1) nests inside
// Dual<S, N> (the partial derivatives D1, D2 of the discrete action) and works as an Eigen scalar, (2) carries
// negative powers of h with exact cancellation, and (3) is bivariate (eps along the flow, h the step).
// ADOL-C's Taylor mode is univariate, over double, on a tape of one function: it can expand the residual in
// one variable, but not under our Dual, not in Laurent form, and not in two variables at once.
//
// Math functions (sin, cos, exp, log, sqrt, pow) compose a univariate Taylor expansion at the constant term
// with the nilpotent rest; they need no negative powers of h (a system's L, F, Phi evaluated at points).
// Comparisons look at the constant term (branches follow the h -> 0, eps = 0 path).
//
// The coefficient type C is a parameter: double (the numbers, as always: the same operations in the same order,
// so the same bits), or a computer-algebra expression (geomint/modified/symbolic.hpp: GiNaC::ex), which turns the
// same engine into one that returns formulas. What the series needs of C beyond + - * / is in
// CoefficientTraits<C>: a zero test (the sparsity boxes and the precision rules read it, so a CAS type must
// keep its coefficients in a canonical form where zero is structurally zero — `normalize`, applied to every
// coefficient a product computes), and an exact conversion of the integers and dyadic constants the code writes.
#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <type_traits>

#include <Eigen/Core>

namespace geomint::modified {

inline constexpr int series_exact = 1 << 20;  // precision of an exact series (constants, monomials)

// What the series needs of its coefficient type (specialized for a CAS type in symbolic.hpp).
template <class C>
struct CoefficientTraits;
template <>
struct CoefficientTraits<double> {
  static bool is_zero(double c) { return c == 0; }
  template <class X>
  static double from_number(X x) {
    return static_cast<double>(x);
  }
  static double normalize(double c) { return c; }  // after each product: the canonical form of a coefficient
  static double simplify(double c) { return c; }   // after each solve: the compact form of a solved coefficient
};

template <int E, int U, int L = 2, class C = double>
class BiSeries {
  using Tr = CoefficientTraits<C>;
  // A scalar that mixes with a series: a built-in number (converted exactly) or a coefficient.
  template <class X>
  using if_scalar = std::enable_if_t<std::is_arithmetic_v<X> || std::is_same_v<X, C>, int>;

 public:
  static constexpr int NE = E + 1, NH = L + U + 1;
  static constexpr int eps_order = E, h_max = U, h_min = -L;
  using coefficient = C;

  std::array<C, NE * NH> a{};
  int p = series_exact;
  // A box [0, j1] x [k0, k1] outside which every coefficient is zero: the loops run over it only, so the cost
  // follows the coefficients in use (few at low order) rather than the storage.
  int j1 = -1, k0 = 0, k1 = -1;

  BiSeries() = default;
  BiSeries(const C& x) : j1(0), k0(0), k1(0) { a[L] = x; }  // NOLINT: constants convert implicitly
  template <class I, std::enable_if_t<std::is_arithmetic_v<I> && !std::is_same_v<I, C>, int> = 0>
  BiSeries(I x) : BiSeries(Tr::from_number(x)) {}  // NOLINT

  static BiSeries monomial(int j, int k, const C& c = C(1)) {
    BiSeries r;
    r.at(j, k) = c;
    r.j1 = j;
    r.k0 = r.k1 = k;
    return r;
  }
  static BiSeries h() { return monomial(0, 1); }
  static BiSeries eps() { return monomial(1, 0); }

  C& at(int j, int k) { return a[static_cast<std::size_t>(j * NH + k + L)]; }
  const C& at(int j, int k) const { return a[static_cast<std::size_t>(j * NH + k + L)]; }
  // The coefficient of eps^j h^k, or 0 outside the storage.
  C coeff(int j, int k) const { return (j < 0 || j > E || k < -L || k > U) ? C(0) : at(j, k); }
  bool known(int j, int k) const { return j >= 0 && j <= E && k >= -L && k <= U && j + k < p; }
  C value() const { return at(0, 0); }

  // After writing coefficients with at(): the tight box.
  void fit() {
    j1 = -1;
    k0 = U + 1;
    k1 = -L - 1;
    for (int j = 0; j <= E; ++j)
      for (int k = -L; k <= U; ++k)
        if (!Tr::is_zero(at(j, k))) {
          j1 = j;
          k0 = std::min(k0, k);
          k1 = std::max(k1, k);
        }
    if (j1 < 0) {
      k0 = 0;
      k1 = -1;
    }
  }

  // Lowest h power, highest h power and lowest total degree among the nonzero coefficients.
  struct Span {
    int kmin = series_exact, kmax = -series_exact, dmin = series_exact;
    bool zero() const { return kmin == series_exact; }
  };
  Span span() const {
    Span s;
    for (int j = 0; j <= j1; ++j)
      for (int k = k0; k <= k1; ++k)
        if (!Tr::is_zero(at(j, k))) {
          s.kmin = std::min(s.kmin, k);
          s.kmax = std::max(s.kmax, k);
          s.dmin = std::min(s.dmin, j + k);
        }
    return s;
  }

  // Drops what the precision says is unknown (keeps the representation canonical).
  void clip() {
    if (p >= series_exact) return;
    for (int j = 0; j <= j1; ++j)
      for (int k = std::max(k0, p - j); k <= k1; ++k) at(j, k) = C(0);
  }

  BiSeries& operator+=(const BiSeries& b) { return accumulate(b, false); }
  BiSeries& operator-=(const BiSeries& b) { return accumulate(b, true); }
  BiSeries& operator*=(const BiSeries& b) { return *this = *this * b; }
  BiSeries& operator/=(const BiSeries& b) { return *this = *this / b; }

  friend BiSeries operator+(const BiSeries& x) { return x; }
  friend BiSeries operator-(BiSeries x) {
    for (int j = 0; j <= x.j1; ++j)
      for (int k = x.k0; k <= x.k1; ++k) x.at(j, k) = -x.at(j, k);
    return x;
  }
  friend BiSeries operator+(BiSeries x, const BiSeries& y) { return x += y; }
  friend BiSeries operator-(BiSeries x, const BiSeries& y) { return x -= y; }
  // Mixed with a scalar: templates, so that an int or a double meets no ambiguity between the conversions to
  // C and to BiSeries when C is a class type.
  template <class X, if_scalar<X> = 0>
  friend BiSeries operator+(BiSeries x, const X& c) {
    return x += BiSeries(c);
  }
  template <class X, if_scalar<X> = 0>
  friend BiSeries operator+(const X& c, BiSeries x) {
    return x += BiSeries(c);
  }
  template <class X, if_scalar<X> = 0>
  friend BiSeries operator-(BiSeries x, const X& c) {
    return x -= BiSeries(c);
  }
  template <class X, if_scalar<X> = 0>
  friend BiSeries operator-(const X& c, const BiSeries& x) {
    return BiSeries(c) -= x;
  }
  template <class X, if_scalar<X> = 0>
  friend BiSeries operator*(BiSeries x, const X& c) {
    return x.scaled(to_coefficient(c));
  }
  template <class X, if_scalar<X> = 0>
  friend BiSeries operator*(const X& c, const BiSeries& x) {
    return BiSeries(x).scaled(to_coefficient(c));
  }
  template <class X, if_scalar<X> = 0>
  friend BiSeries operator/(const BiSeries& x, const X& c) {
    return BiSeries(x).scaled(C(1) / to_coefficient(c));
  }
  template <class X, if_scalar<X> = 0>
  friend BiSeries operator/(const X& c, const BiSeries& x) {
    return BiSeries(c) / x;
  }

  friend BiSeries operator*(const BiSeries& x, const BiSeries& y) {
    const Span sx = x.span(), sy = y.span();
    BiSeries r;
    if (sx.zero() && sy.zero()) {
      r.p = (x.p >= series_exact || y.p >= series_exact) ? series_exact : std::min(x.p + y.p, series_exact);
      return r;
    }
    // (x + O(p_x)) (y + O(p_y)): known below min(v_x + p_y, v_y + p_x); exact stays exact
    const int vx = sx.zero() ? x.p : sx.dmin, vy = sy.zero() ? y.p : sy.dmin;
    auto shift = [](int v, int p) { return p >= series_exact ? series_exact : std::min(v + p, series_exact); };
    r.p = std::min(shift(vx, y.p), shift(vy, x.p));
    if (sx.zero() || sy.zero()) return r;
    if (sx.kmin + sy.kmin < -L) throw std::domain_error("BiSeries: a power of h below the Laurent window");
    if (sx.kmax + sy.kmax > U) r.p = std::min(r.p, U + 1);  // truncated in h
    r.j1 = std::min(E, x.j1 + y.j1);
    r.k0 = sx.kmin + sy.kmin;
    r.k1 = std::min(U, sx.kmax + sy.kmax);
    for (int j = 0; j <= r.j1; ++j)
      for (int k = r.k0; k <= r.k1 && j + k < r.p; ++k) {
        C s = C(0);
        const int k1lo = std::max(sx.kmin, k - sy.kmax), k1hi = std::min(sx.kmax, k - sy.kmin);
        for (int ja = std::max(0, j - y.j1); ja <= std::min(j, x.j1); ++ja)
          for (int ka = k1lo; ka <= k1hi; ++ka) s += x.at(ja, ka) * y.at(j - ja, k - ka);
        r.at(j, k) = Tr::normalize(s);
      }
    return r;
  }

  // 1/y for y = h^v (y00 + ...), y00 != 0.
  friend BiSeries inverse(const BiSeries& y) {
    const Span s = y.span();
    if (s.zero() || Tr::is_zero(y.at(0, s.kmin)))
      throw std::domain_error("BiSeries: division by a series without an invertible leading term");
    const int v = s.kmin;
    if (-v < -L) throw std::domain_error("BiSeries: a power of h below the Laurent window");
    // yt = y h^{-v}: a power series with yt00 != 0, known below total degree y.p - v
    const int pt = y.p >= series_exact ? series_exact : y.p - v;
    const bool monomial = s.kmax == v && y.j1 == 0;
    const int top = U + v;  // the highest power of 1/yt that fits after the shift by h^{-v}
    const int pc = monomial ? pt : std::min(pt, top + 1);  // an infinite series is truncated at the window
    const C y00 = y.at(0, v);
    BiSeries r;
    if (monomial) {
      r = monomial_of(0, -v, Tr::normalize(C(1) / y00));
    } else {
      // ct[j][k] in lexicographic order: yt00 ct_jk = delta - sum_{(j',k') != (0,0)} yt_j'k' ct_{j-j',k-k'}
      std::array<C, NE * NH> ct{};
      auto Ct = [&](int j, int k) -> C& { return ct[static_cast<std::size_t>(j * NH + k)]; };
      const int kspan = std::min(top, NH - 1);
      for (int j = 0; j <= E; ++j)
        for (int k = 0; k <= kspan && j + k < pc; ++k) {
          C acc = (j == 0 && k == 0) ? C(1) : C(0);
          for (int ja = 0; ja <= std::min(j, y.j1); ++ja)
            for (int ka = 0; ka <= std::min(k, s.kmax - v); ++ka) {
              if (ja == 0 && ka == 0) continue;
              const C& yv = y.at(ja, ka + v);
              if (!Tr::is_zero(yv)) acc -= yv * Ct(j - ja, k - ka);
            }
          Ct(j, k) = Tr::normalize(acc / y00);
        }
      for (int j = 0; j <= E; ++j)
        for (int k = 0; k <= kspan && j + k < pc; ++k)
          if (k - v >= -L && k - v <= U) r.at(j, k - v) = Ct(j, k);
      r.fit();
    }
    r.p = pc >= series_exact ? series_exact : pc - v;
    r.clip();
    return r;
  }
  friend BiSeries operator/(const BiSeries& x, const BiSeries& y) { return x * inverse(y); }

  // x(eps + s h, h): the same function seen from a point s steps away (exact: (eps + s h)^j re-expanded). A
  // coefficient of total degree d needs those of x of degree d up to eps^d, so the result is known below total
  // degree E + 1 at most.
  friend BiSeries shifted_by_steps(const BiSeries& x, double s) {
    BiSeries r;
    r.p = std::min(x.p, E + 1);
    for (int j = 0; j <= x.j1; ++j)
      for (int k = x.k0; k <= x.k1 && j + k < r.p; ++k) {
        const C& a = x.at(j, k);
        if (Tr::is_zero(a)) continue;
        double b = 1;  // binom(j, rr) s^(j - rr), from rr = j down
        for (int rr = j; rr >= 0; --rr) {
          const int kk = k + j - rr;
          if (kk > U) {
            r.p = std::min(r.p, j + k);
            break;
          }
          r.at(rr, kk) += Tr::normalize(a * Tr::from_number(b));
          b = b * s * rr / (j - rr + 1);
        }
      }
    r.fit();
    r.clip();
    return r;
  }

  // f(x) = sum_r f_r (x - x00)^r with f_r = f^(r)(x00)/r!, given by `coef(r)`.
  template <class Coef>
  friend BiSeries compose(const BiSeries& x, Coef&& coef) {
    const Span s = x.span();
    if (!s.zero() && s.kmin < 0) throw std::domain_error("BiSeries: function of a series with negative powers of h");
    BiSeries u = x;
    u.at(0, 0) = C(0);  // nilpotent: every term has total degree >= 1
    if (u.span().zero()) {  // a constant
      BiSeries r(coef(0));
      r.p = x.p;
      return r;
    }
    // u^r has total degree >= r; with no positive power of h in u (a function of time t + eps alone, as in a
    // forcing or a rheonomic constraint) it vanishes beyond eps^E: stop there
    const int top = s.kmax <= 0 ? E : E + U;
    const int R = std::min(x.p >= series_exact ? top : x.p - 1, top);
    BiSeries r(coef(R));
    for (int k = R - 1; k >= 0; --k) r = r * u + coef(k);
    r.p = x.p >= series_exact ? std::min(r.p, U + 1) : std::min(r.p, x.p);
    r.clip();
    return r;
  }

  friend BiSeries sin(const BiSeries& x) {
    using std::cos;
    using std::sin;
    const C s = sin(x.value()), c = cos(x.value());
    return compose(x, [&](int r) -> C { return (r % 4 == 0 ? s : r % 4 == 1 ? c : r % 4 == 2 ? -s : -c) / factorial(r); });
  }
  friend BiSeries cos(const BiSeries& x) {
    using std::cos;
    using std::sin;
    const C s = sin(x.value()), c = cos(x.value());
    return compose(x, [&](int r) -> C { return (r % 4 == 0 ? c : r % 4 == 1 ? -s : r % 4 == 2 ? -c : s) / factorial(r); });
  }
  friend BiSeries exp(const BiSeries& x) {
    using std::exp;
    const C e = exp(x.value());
    return compose(x, [&](int r) -> C { return e / factorial(r); });
  }
  friend BiSeries log(const BiSeries& x) {
    using std::log;
    using std::pow;
    const C x0 = x.value();
    return compose(x, [&](int r) -> C {
      return r == 0 ? C(log(x0)) : C(Tr::from_number(r % 2 ? 1.0 : -1.0) / (Tr::from_number(r) * pow(x0, Tr::from_number(r))));
    });
  }
  friend BiSeries pow(const BiSeries& x, double e) {
    using std::pow;
    const C x0 = x.value(), ce = Tr::from_number(e);
    // f_r = x0^e binom(e, r) / x0^r
    return compose(x, [&](int r) -> C {
      C b = C(1);
      for (int i = 0; i < r; ++i) b *= (ce - Tr::from_number(i)) / Tr::from_number(i + 1);
      return pow(x0, C(ce - Tr::from_number(r))) * b;
    });
  }
  friend BiSeries sqrt(const BiSeries& x) { return pow(x, 0.5); }
  friend BiSeries abs(const BiSeries& x) { return x.value() < 0 ? -x : x; }
  friend BiSeries fabs(const BiSeries& x) { return abs(x); }
  friend bool isfinite(const BiSeries& x) {
    for (double c : x.a)
      if (!std::isfinite(c)) return false;
    return true;
  }

  friend bool operator<(const BiSeries& x, const BiSeries& y) { return x.value() < y.value(); }
  friend bool operator>(const BiSeries& x, const BiSeries& y) { return x.value() > y.value(); }
  friend bool operator<=(const BiSeries& x, const BiSeries& y) { return x.value() <= y.value(); }
  friend bool operator>=(const BiSeries& x, const BiSeries& y) { return x.value() >= y.value(); }
  friend bool operator==(const BiSeries& x, const BiSeries& y) { return x.a == y.a && x.p == y.p; }
  friend bool operator!=(const BiSeries& x, const BiSeries& y) { return !(x == y); }

 private:
  static BiSeries monomial_of(int j, int k, const C& c) { return monomial(j, k, c); }
  template <class X>
  static C to_coefficient(const X& c) {
    if constexpr (std::is_same_v<X, C>)
      return c;
    else
      return Tr::from_number(c);
  }
  // x c, coefficient by coefficient (c = 0 gives the exact zero constant).
  BiSeries& scaled(const C& c) {
    if (Tr::is_zero(c)) return *this = BiSeries(C(0));
    for (int j = 0; j <= j1; ++j)
      for (int k = k0; k <= k1; ++k) at(j, k) = Tr::normalize(at(j, k) * c);
    return *this;
  }
  BiSeries& accumulate(const BiSeries& b, bool subtract) {
    if (b.j1 >= 0) {
      if (j1 < 0) {
        j1 = b.j1;
        k0 = b.k0;
        k1 = b.k1;
      } else {
        j1 = std::max(j1, b.j1);
        k0 = std::min(k0, b.k0);
        k1 = std::max(k1, b.k1);
      }
      for (int j = 0; j <= b.j1; ++j)
        for (int k = b.k0; k <= b.k1; ++k) {
          if (subtract)
            at(j, k) -= b.at(j, k);
          else
            at(j, k) += b.at(j, k);
        }
    }
    p = std::min(p, b.p);
    clip();
    return *this;
  }
  static C factorial(int r) {
    double f = 1;
    for (int i = 2; i <= r; ++i) f *= i;
    return Tr::from_number(f);
  }
};

}  // namespace geomint::modified

namespace Eigen {
template <int E, int U, int L, class C>
struct NumTraits<geomint::modified::BiSeries<E, U, L, C>> : NumTraits<double> {
  using Real = geomint::modified::BiSeries<E, U, L, C>;
  using NonInteger = Real;
  using Nested = Real;
  using Literal = Real;
  enum {
    IsComplex = 0,
    IsInteger = 0,
    IsSigned = 1,
    RequireInitialization = 1,
    ReadCost = (E + 1) * (L + U + 1),
    AddCost = (E + 1) * (L + U + 1),
    MulCost = (E + 1) * (E + 1) * (L + U + 1) * (L + U + 1)
  };
};
template <int E, int U, int L, class C, class Op>
struct ScalarBinaryOpTraits<geomint::modified::BiSeries<E, U, L, C>, double, Op> {
  using ReturnType = geomint::modified::BiSeries<E, U, L, C>;
};
template <int E, int U, int L, class C, class Op>
struct ScalarBinaryOpTraits<double, geomint::modified::BiSeries<E, U, L, C>, Op> {
  using ReturnType = geomint::modified::BiSeries<E, U, L, C>;
};
}  // namespace Eigen
