#pragma once
// Tape: formulas compiled to a flat list of instructions over registers, evaluated by one interpreter loop in
// any scalar type S of the core — double, long double, Dual<S, N> nested (the stepper's Jacobians, the partial
// derivatives of the discrete action, the Hessians of the continuous equations), the modified equations'
// BiSeries, and a symbolic type — with the parameters in their own type P (double, or a symbol type: then the
// parameters of a formula system are symbols, and so is everything computed from them).
//
// Why a tape and not a tree of virtual nodes: an evaluation is one pass over a contiguous array with a switch
// per instruction; no virtual call, no allocation (registers live on the stack, or in a thread-local buffer
// reused across calls for the rare tape too large for it). Registers are reused once their value is dead, so a
// long formula needs few of them.
//
// Two kinds of tape. A state tape (L, the force, the constraint rows...) takes the variables t, q, v, z as its
// inputs; every subexpression that depends on parameters and numbers only is computed once per parameter set,
// in P (FormulaModel::prelude), and enters the tape as an operand `pv[k]` of a mixed instruction (mul_p: a * c)
// — as a header system writes `alpha * z` with a double alpha. The mixed instructions give the bits of that
// header code in every scalar type (for a Dual they skip the zero derivatives of the constant, which changes at
// most the sign of a zero). A constant tape (the prelude, the initial data) takes the numbers and parameters as
// its inputs and is evaluated entirely in one type: P for the prelude, the run's scalar for the initial data
// (a long double run starts from long double initial data computed from the double parameters, as the headers do).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <vector>

#include "geomint/formula/expression.hpp"
#include "geomint/generic/dual.hpp"

namespace geomint::formula {

enum class Op : std::uint8_t {
  add, sub, mul, div, pow,                                     // x[a] . x[b]
  add_p, sub_p, rsub_p, mul_p, div_p, rdiv_p, pow_p, rpow_p,   // x[a] . pv[b]  (rsub_p: pv[b] - x[a], ...)
  pow_int,                                                     // x[a]^k, k = int16(b): repeated products
  neg, sin, cos, tan, exp, log, sqrt, atan2,                   // f(x[a]) (atan2: x[a], x[b])
  // Two instructions in one, where the first's value is used once, by the second (p is the first's value,
  // computed exactly as alone): one dispatch and one register round trip less on the most common shapes of a
  // Lagrangian (m/2*v*v, k*q*q, L - alpha*z, a sum of products)
  add_mul,    // x[a] + p,   p = x[b] * x[c]   (also p + x[a]: addition commutes, bit for bit)
  sub_mul,    // x[a] - p,   p = x[b] * x[c]
  mul_sub,    // p - x[a],   p = x[b] * x[c]
  add_mulp,   // x[a] + p,   p = x[b] * pv[c]
  sub_mulp,   // x[a] - p,   p = x[b] * pv[c]
  mulp_sub,   // p - x[a],   p = x[b] * pv[c]
  mul_divp,   // p / pv[a],  p = x[b] * x[c]
  mulp_mul,   // p * x[a],   p = x[b] * pv[c]
  mul_mulp    // x[a] * p,   p = x[b] * pv[c]  (a product of series does not commute bit for bit: both orders)
};

// dst is a register; a, b and c are slots (or parameter indices, by the op): slot < inputs is the caller's input,
// else register slot - inputs.
struct Instr {
  Op op;
  std::uint16_t dst, a, b, c;
};

struct TapeOutput {
  enum Kind : std::uint8_t { slot, param, zero } kind = zero;
  std::uint16_t index = 0;
};

namespace detail {

// ---------------------------------------------------------------------------------------------------
// Scalar helpers: what each instruction does in a scalar S with a parameter of type P.

template <class S, class P, class = void>
struct mixes : std::false_type {};
template <class S, class P>
struct mixes<S, P, std::void_t<decltype(std::declval<const S&>() * std::declval<const P&>()),
                               decltype(std::declval<const P&>() - std::declval<const S&>())>>
    : std::bool_constant<std::is_same_v<std::decay_t<decltype(std::declval<const S&>() * std::declval<const P&>())>, S>> {};

// Whether S has tan, atan2 and pow of its own (found by argument-dependent lookup, or in std for the built-in
// types); the series type of the modified equations has neither tan nor atan2. A function found that does not
// give the type back is not the type's own: GiNaC's templates take any argument (so a series over GiNaC::ex finds
// them by its coefficient type) and return a GiNaC::function or ex, which a series is not.
namespace adl {
using std::atan2;
using std::pow;
using std::tan;
template <class S>
auto try_tan(const S& a) -> decltype(tan(a));
template <class S>
auto try_atan2(const S& y, const S& x) -> decltype(atan2(y, x));
template <class S, class E>
auto try_pow(const S& a, const E& e) -> decltype(pow(a, e));
}  // namespace adl

template <class S, class = void>
struct has_tan : std::false_type {};
template <class S>
struct has_tan<S, std::void_t<decltype(adl::try_tan(std::declval<const S&>()))>>
    : std::is_convertible<decltype(adl::try_tan(std::declval<const S&>())), S> {};

template <class S, class = void>
struct has_atan2 : std::false_type {};
template <class S>
struct has_atan2<S, std::void_t<decltype(adl::try_atan2(std::declval<const S&>(), std::declval<const S&>()))>>
    : std::is_convertible<decltype(adl::try_atan2(std::declval<const S&>(), std::declval<const S&>())), S> {};

template <class S, class E, class = void>
struct has_pow : std::false_type {};
template <class S, class E>
struct has_pow<S, E, std::void_t<decltype(adl::try_pow(std::declval<const S&>(), std::declval<const E&>()))>>
    : std::is_same<std::decay_t<decltype(adl::try_pow(std::declval<const S&>(), std::declval<const E&>()))>, S> {};

// Dual overloads first (more specialized), so that the generic ones below find them for nested duals.
template <class T, int N, class P>
Dual<T, N> add_p(const Dual<T, N>& a, const P& c);
template <class T, int N, class P>
Dual<T, N> sub_p(const Dual<T, N>& a, const P& c);
template <class T, int N, class P>
Dual<T, N> rsub_p(const P& c, const Dual<T, N>& a);
template <class T, int N, class P>
Dual<T, N> mul_p(const Dual<T, N>& a, const P& c);
template <class T, int N, class P>
Dual<T, N> div_p(const Dual<T, N>& a, const P& c);
template <class T, int N, class P>
Dual<T, N> pow_p(const Dual<T, N>& a, const P& c);

template <class S, class P>
S add_p(const S& a, const P& c) {
  if constexpr (mixes<S, P>::value)
    return a + c;
  else
    return a + S(c);
}
template <class S, class P>
S sub_p(const S& a, const P& c) {
  if constexpr (mixes<S, P>::value)
    return a - c;
  else
    return a - S(c);
}
template <class S, class P>
S rsub_p(const P& c, const S& a) {
  if constexpr (mixes<S, P>::value)
    return c - a;
  else
    return S(c) - a;
}
template <class S, class P>
S mul_p(const S& a, const P& c) {
  if constexpr (mixes<S, P>::value)
    return a * c;
  else
    return a * S(c);
}
template <class S, class P>
S div_p(const S& a, const P& c) {
  if constexpr (mixes<S, P>::value)
    return a / c;
  else
    return a / S(c);
}
template <class S, class P>
S rdiv_p(const P& c, const S& a) {
  if constexpr (mixes<S, P>::value)
    return c / a;
  else
    return S(c) / a;
}

// For a Dual the constant has no derivatives: the products and sums with its zeros are skipped (a header's
// `alpha * z` computes them; the results are the same numbers).
template <class T, int N, class P>
Dual<T, N> add_p(const Dual<T, N>& a, const P& c) {
  Dual<T, N> r = a;
  r.v = add_p(a.v, c);
  return r;
}
template <class T, int N, class P>
Dual<T, N> sub_p(const Dual<T, N>& a, const P& c) {
  Dual<T, N> r = a;
  r.v = sub_p(a.v, c);
  return r;
}
template <class T, int N, class P>
Dual<T, N> rsub_p(const P& c, const Dual<T, N>& a) {
  Dual<T, N> r;
  r.v = rsub_p(c, a.v);
  for (int i = 0; i < N; ++i) r.d[static_cast<std::size_t>(i)] = -a.d[static_cast<std::size_t>(i)];
  return r;
}
template <class T, int N, class P>
Dual<T, N> mul_p(const Dual<T, N>& a, const P& c) {
  Dual<T, N> r;
  r.v = mul_p(a.v, c);
  for (int i = 0; i < N; ++i) r.d[static_cast<std::size_t>(i)] = mul_p(a.d[static_cast<std::size_t>(i)], c);
  return r;
}
// Dual's division multiplies by the reciprocal of the divisor, computed in the innermost scalar (dual.hpp);
// dividing by a constant does the same, so x / 2 has the header's bits.
template <class T, int N, class P>
Dual<T, N> div_p(const Dual<T, N>& a, const P& c) {
  using R = decltype(primal(a));
  const R inv = R(1) / R(c);
  return mul_p(a, inv);
}

// tan and atan2 where the type has them; a Dual is taken apart here rather than by its own tan and atan2, which
// require them of the type below (a Dual over the series type has neither). Same formulas as Dual's.
template <class S>
S tan_of(const S& a) {
  using std::cos;
  using std::sin;
  using std::tan;
  if constexpr (has_tan<S>::value)
    return tan(a);
  else
    return sin(a) / cos(a);
}
template <class T, int N>
Dual<T, N> tan_of(const Dual<T, N>& a) {
  const T t = tan_of(a.v);
  return chain(a, t, T(1) + t * t);
}

template <class S>
S atan2_of(const S& y, const S& x) {
  using std::atan2;
  if constexpr (has_atan2<S>::value)
    return atan2(y, x);
  else
    throw std::domain_error("atan2 is not available in this scalar type");
}
template <class T, int N>
Dual<T, N> atan2_of(const Dual<T, N>& y, const Dual<T, N>& x) {
  Dual<T, N> r;
  r.v = atan2_of(y.v, x.v);
  const T inv = T(1) / (x.v * x.v + y.v * y.v);
  for (int i = 0; i < N; ++i)
    r.d[static_cast<std::size_t>(i)] = (x.v * y.d[static_cast<std::size_t>(i)] - y.v * x.d[static_cast<std::size_t>(i)]) * inv;
  return r;
}

// x^c for a constant exponent c (not a small integer).
template <class S, class P>
S pow_p(const S& a, const P& c) {
  using std::exp;
  using std::log;
  using std::pow;
  if constexpr (has_pow<S, P>::value)
    return pow(a, c);
  else
    return exp(mul_p(log(a), c));
}
// Dual's own pow takes a Dual over a built-in scalar only; this one nests (the chain rule, as Dual's).
template <class T, int N, class P>
Dual<T, N> pow_p(const Dual<T, N>& a, const P& c) {
  return chain(a, pow_p(a.v, c), mul_p(pow_p(a.v, P(c - 1)), c));
}

// x^y for two variable quantities: exp(y log x) where the type has no pow of its own.
template <class S>
S pow_any(const S& a, const S& b) {
  using std::exp;
  using std::log;
  using std::pow;
  if constexpr (has_pow<S, S>::value)
    return pow(a, b);
  else
    return exp(b * log(a));
}
// x^k by products in the order a header writes them: x*x*x = (x*x)*x.
template <class S>
S pow_int(const S& a, int k) {
  if (k == 0) return S(1);
  const int n = k < 0 ? -k : k;
  S r = a;
  for (int i = 1; i < n; ++i) r = r * a;
  if (k < 0) return S(1) / r;
  return r;
}

// Registers: stack storage for the common case, a thread-local buffer for a tape too large for it. The
// evaluation is a leaf (it calls no other tape), so one buffer per scalar type and thread is enough.
template <class S, bool Trivial = std::is_trivially_copyable_v<S>>
class Registers;

template <class S>
class Registers<S, true> {
  union Slot {
    S v;
    Slot() {}
  };
  static constexpr std::size_t stack_count = std::max<std::size_t>(8, 1024 / sizeof(S));

 public:
  explicit Registers(int n) : p_(static_cast<std::size_t>(n) <= stack_count ? stack_ : overflow(static_cast<std::size_t>(n))) {}
  Registers(const Registers&) = delete;
  Registers& operator=(const Registers&) = delete;
  const S& operator[](int i) const { return p_[i].v; }
  // Through a local value and a whole-object copy: the register is then written with uniform wide stores, which
  // the next instruction's loads can forward from (a Dual written element by element and read back with wider
  // loads stalls the store buffer, measured 2-4x slower evaluations).
  template <class F>
  void set(int i, F&& f) {
    const S value = f();
    std::memcpy(static_cast<void*>(&p_[i].v), &value, sizeof(S));
  }

 private:
  static Slot* overflow(std::size_t n) {
    thread_local std::vector<Slot> buffer;
    if (buffer.size() < n) buffer.resize(n);
    return buffer.data();
  }
  Slot stack_[stack_count];
  Slot* p_;
};

template <class S>
class Registers<S, false> {
 public:
  explicit Registers(int n) {
    thread_local std::vector<S> buffer;
    if (buffer.size() < static_cast<std::size_t>(n)) buffer.resize(static_cast<std::size_t>(n));
    p_ = buffer.data();
  }
  Registers(const Registers&) = delete;
  Registers& operator=(const Registers&) = delete;
  const S& operator[](int i) const { return p_[i]; }
  template <class F>
  void set(int i, F&& f) {
    p_[i] = f();
  }

 private:
  S* p_;
};

}  // namespace detail

// The scalars Tape::eval_duals takes: a built-in B, Dual<B, N>, Dual<Dual<B, K>, N> (B = double, long double),
// laid out as B values only (a Dual is its value followed by its derivatives).
template <class S>
struct nested_dual : std::false_type {};
template <>
struct nested_dual<double> : std::true_type {
  using base = double;
  static constexpr int depth = 0;
};
template <>
struct nested_dual<long double> : std::true_type {
  using base = long double;
  static constexpr int depth = 0;
};
namespace detail {
template <class T, int N, bool = nested_dual<T>::value>
struct nested_dual_of : std::false_type {};
template <class T, int N>
struct nested_dual_of<T, N, true> : std::bool_constant<(nested_dual<T>::depth < 2)> {
  using base = typename nested_dual<T>::base;
  static constexpr int depth = nested_dual<T>::depth + 1;
  static constexpr int outer = N;
  static_assert(sizeof(Dual<T, N>) == (N + 1) * sizeof(T), "a Dual is its value followed by its derivatives");
};
}  // namespace detail
template <class T, int N>
struct nested_dual<Dual<T, N>> : detail::nested_dual_of<T, N> {};

class Tape {
 public:
  int inputs = 0;     // slots 0..inputs-1: the caller's values
  int registers = 0;  // scratch values the interpreter needs at most
  std::vector<Instr> code;
  std::vector<TapeOutput> outputs;

  bool empty() const { return outputs.empty(); }
  std::size_t size() const { return outputs.size(); }

  // out[k] = output k, with in[i] the input slots and pv the parameter values (pv[b] of the mixed instructions):
  // by eval_duals for a nested dual over a built-in scalar with double parameters, else by eval.
  template <class S, class P>
  void evaluate(const S* const* in, const P* pv, S* out) const;

  // The interpreter for any scalar type S (instantiated for each).
  template <class S, class P>
  void eval(const S* const* in, const P* pv, S* out) const;
  // The interpreter for nested duals over B of depth Depth (0: B itself) with `directions` (outermost first)
  // given at run time: compiled once (tape_duals.cpp) for B = double, long double, with the bits of eval.
  template <class B, int Depth>
  void eval_duals(const int* directions, const B* const* in, const double* pv, B* out) const;
};

extern template void Tape::eval_duals<double, 0>(const int*, const double* const*, const double*, double*) const;
extern template void Tape::eval_duals<double, 1>(const int*, const double* const*, const double*, double*) const;
extern template void Tape::eval_duals<double, 2>(const int*, const double* const*, const double*, double*) const;
extern template void Tape::eval_duals<long double, 0>(const int*, const long double* const*, const double*,
                                                      long double*) const;
extern template void Tape::eval_duals<long double, 1>(const int*, const long double* const*, const double*,
                                                      long double*) const;
extern template void Tape::eval_duals<long double, 2>(const int*, const long double* const*, const double*,
                                                      long double*) const;

// The interpreter for the scalars of the stepper's hot loop, compiled once (tape_duals.cpp): a built-in scalar
// and a Dual over it with a few directions (fixed at compile time: its loops unrolled, measured 1.4x faster than
// eval_duals with the directions at run time).
#define GEOMINT_TAPE_EVAL(S) extern template void Tape::eval<S, double>(const S* const*, const double*, S*) const;
#define GEOMINT_TAPE_EVAL_DUALS(B)                                                                                  \
  GEOMINT_TAPE_EVAL(B)                                                                                              \
  GEOMINT_TAPE_EVAL(Dual<B COMMA 1>) GEOMINT_TAPE_EVAL(Dual<B COMMA 2>) GEOMINT_TAPE_EVAL(Dual<B COMMA 3>)            \
  GEOMINT_TAPE_EVAL(Dual<B COMMA 4>) GEOMINT_TAPE_EVAL(Dual<B COMMA 5>) GEOMINT_TAPE_EVAL(Dual<B COMMA 6>)            \
  GEOMINT_TAPE_EVAL(Dual<B COMMA 7>) GEOMINT_TAPE_EVAL(Dual<B COMMA 8>) GEOMINT_TAPE_EVAL(Dual<B COMMA 9>)            \
  GEOMINT_TAPE_EVAL(Dual<B COMMA 10>)
#define COMMA ,
GEOMINT_TAPE_EVAL_DUALS(double)
GEOMINT_TAPE_EVAL_DUALS(long double)
#undef COMMA
#undef GEOMINT_TAPE_EVAL_DUALS
#undef GEOMINT_TAPE_EVAL

// The largest number of directions of a Dual that eval handles from its compiled instances.
inline constexpr int compiled_dual_directions = 10;

template <class S, class P>
void Tape::evaluate(const S* const* in, const P* pv, S* out) const {
  if constexpr (std::is_same_v<P, double> && nested_dual<S>::value) {
    constexpr int depth = nested_dual<S>::depth;
    if constexpr (depth == 0) {
      eval(in, pv, out);
    } else if constexpr (depth == 1 && nested_dual<S>::outer <= compiled_dual_directions) {
      eval(in, pv, out);
    } else {
      using B = typename nested_dual<S>::base;
      int directions[2] = {0, 0};
      directions[0] = nested_dual<S>::outer;
      if constexpr (depth == 2) directions[1] = nested_dual<typename std::remove_cv_t<decltype(std::declval<S>().v)>>::outer;
      // the caller's values as arrays of B (standard layout, no padding: the static_assert in nested_dual)
      std::array<const B*, 64> flat;
      if (inputs > 64) throw std::length_error("Tape::evaluate: more than 64 inputs");
      for (int i = 0; i < inputs; ++i) flat[static_cast<std::size_t>(i)] = reinterpret_cast<const B*>(in[i]);
      eval_duals<B, depth>(directions, flat.data(), pv, reinterpret_cast<B*>(out));
    }
  } else {
    eval(in, pv, out);
  }
}

template <class S, class P>
void Tape::eval(const S* const* in, const P* pv, S* out) const {
  // (copying the inputs into the register file instead, to save the branch, measured 30 % slower)
  detail::Registers<S> R(registers);
  const int ni = inputs;
  const auto x = [&](std::uint16_t o) -> const S& { return o < ni ? *in[o] : R[o - ni]; };
  for (const Instr& c : code) {
    switch (c.op) {
      case Op::add:
        R.set(c.dst, [&] { return S(x(c.a) + x(c.b)); });
        break;
      case Op::sub:
        R.set(c.dst, [&] { return S(x(c.a) - x(c.b)); });
        break;
      case Op::mul:
        R.set(c.dst, [&] { return S(x(c.a) * x(c.b)); });
        break;
      case Op::div:
        R.set(c.dst, [&] { return S(x(c.a) / x(c.b)); });
        break;
      case Op::pow:
        R.set(c.dst, [&] { return detail::pow_any(x(c.a), x(c.b)); });
        break;
      case Op::add_p:
        R.set(c.dst, [&] { return detail::add_p(x(c.a), pv[c.b]); });
        break;
      case Op::sub_p:
        R.set(c.dst, [&] { return detail::sub_p(x(c.a), pv[c.b]); });
        break;
      case Op::rsub_p:
        R.set(c.dst, [&] { return detail::rsub_p(pv[c.b], x(c.a)); });
        break;
      case Op::mul_p:
        R.set(c.dst, [&] { return detail::mul_p(x(c.a), pv[c.b]); });
        break;
      case Op::div_p:
        R.set(c.dst, [&] { return detail::div_p(x(c.a), pv[c.b]); });
        break;
      case Op::rdiv_p:
        R.set(c.dst, [&] { return detail::rdiv_p(pv[c.b], x(c.a)); });
        break;
      case Op::pow_p:
        R.set(c.dst, [&] { return detail::pow_p(x(c.a), pv[c.b]); });
        break;
      case Op::rpow_p:
        R.set(c.dst, [&] {
          using std::exp;
          using std::log;
          return S(exp(detail::mul_p(x(c.a), P(log(pv[c.b])))));
        });
        break;
      case Op::pow_int:
        R.set(c.dst, [&] { return detail::pow_int(x(c.a), static_cast<std::int16_t>(c.b)); });
        break;
      case Op::neg:
        R.set(c.dst, [&] { return S(-x(c.a)); });
        break;
      case Op::sin:
        R.set(c.dst, [&] {
          using std::sin;
          return S(sin(x(c.a)));
        });
        break;
      case Op::cos:
        R.set(c.dst, [&] {
          using std::cos;
          return S(cos(x(c.a)));
        });
        break;
      case Op::tan:
        R.set(c.dst, [&] { return detail::tan_of(x(c.a)); });
        break;
      case Op::exp:
        R.set(c.dst, [&] {
          using std::exp;
          return S(exp(x(c.a)));
        });
        break;
      case Op::log:
        R.set(c.dst, [&] {
          using std::log;
          return S(log(x(c.a)));
        });
        break;
      case Op::sqrt:
        R.set(c.dst, [&] {
          using std::sqrt;
          return S(sqrt(x(c.a)));
        });
        break;
      case Op::atan2:
        R.set(c.dst, [&] { return detail::atan2_of(x(c.a), x(c.b)); });
        break;
      case Op::add_mul:
        R.set(c.dst, [&] {
          const S p = x(c.b) * x(c.c);
          return S(x(c.a) + p);
        });
        break;
      case Op::sub_mul:
        R.set(c.dst, [&] {
          const S p = x(c.b) * x(c.c);
          return S(x(c.a) - p);
        });
        break;
      case Op::mul_sub:
        R.set(c.dst, [&] {
          const S p = x(c.b) * x(c.c);
          return S(p - x(c.a));
        });
        break;
      case Op::add_mulp:
        R.set(c.dst, [&] {
          const S p = detail::mul_p(x(c.b), pv[c.c]);
          return S(x(c.a) + p);
        });
        break;
      case Op::sub_mulp:
        R.set(c.dst, [&] {
          const S p = detail::mul_p(x(c.b), pv[c.c]);
          return S(x(c.a) - p);
        });
        break;
      case Op::mulp_sub:
        R.set(c.dst, [&] {
          const S p = detail::mul_p(x(c.b), pv[c.c]);
          return S(p - x(c.a));
        });
        break;
      case Op::mul_divp:
        R.set(c.dst, [&] {
          const S p = x(c.b) * x(c.c);
          return detail::div_p(p, pv[c.a]);
        });
        break;
      case Op::mulp_mul:
        R.set(c.dst, [&] {
          const S p = detail::mul_p(x(c.b), pv[c.c]);
          return S(p * x(c.a));
        });
        break;
      case Op::mul_mulp:
        R.set(c.dst, [&] {
          const S p = detail::mul_p(x(c.b), pv[c.c]);
          return S(x(c.a) * p);
        });
        break;
    }
  }
  for (std::size_t k = 0; k < outputs.size(); ++k) {
    const TapeOutput& o = outputs[k];
    if (o.kind == TapeOutput::slot)
      out[k] = x(o.index);
    else if (o.kind == TapeOutput::param)
      out[k] = S(pv[o.index]);
    else
      out[k] = S(0);
  }
}

// ---------------------------------------------------------------------------------------------------
// Compiling

// The parameter table of a system's state tapes, pv = (numbers | parameters | derived): the derived values are
// the subexpressions that depend on numbers and parameters only, numbered as the tapes first need them.
class ConstantTable {
 public:
  ConstantTable(int numbers, int parameters) : numbers_(numbers), parameters_(parameters) {}
  int numbers() const { return numbers_; }
  int parameters() const { return parameters_; }
  int size() const { return numbers_ + parameters_ + static_cast<int>(derived_.size()); }
  // The node's index in pv (a number, a parameter, or a derived value, assigned on first request).
  int index_of(const Expressions& ex, int node);
  const std::vector<int>& derived() const { return derived_; }

 private:
  int numbers_, parameters_;
  std::vector<int> derived_;
  std::vector<std::pair<int, int>> index_;  // node -> pv index, for the derived values
};

// A state tape with outputs `roots`; inputs are the variables (Variables numbering).
Tape compile_state_tape(const Expressions& ex, const std::vector<int>& roots, ConstantTable& constants);
// A constant tape with outputs `roots` (nodes of numbers and parameters only); inputs are the numbers, then the
// parameters.
Tape compile_constant_tape(const Expressions& ex, const std::vector<int>& roots, int numbers, int parameters);

}  // namespace geomint::formula
