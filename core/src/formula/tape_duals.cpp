// The tape's interpreters compiled once, for every system shape:
// - Tape::eval for the scalars of the stepper's hot loop (double, long double, and a Dual over them with up to 10
//   directions), explicitly instantiated here;
// - Tape::eval_duals: nested duals over a built-in scalar B (Dual<Dual<B, K>, N>, and wider Duals) with the
//   numbers of directions known at run time. It replaces the interpreter's instantiation for every Dual type of
//   every system shape (about thirty per shape: 40 % of a formula shape's compile time, measured), and gives the
//   same bits: every operation below is Dual's own formula (generic/dual.hpp) or the tape's mixed instruction
//   (tape.hpp), in the same order, on the same layout (a Dual is its value followed by its N derivatives; nested,
//   each of those is a Dual).
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "geomint/formula/tape.hpp"

namespace geomint::formula {

namespace {

// The largest inner value a temporary holds: a Dual<B, K> with K < 32 (the core's duals have at most 2n + 2
// <= 10 directions).
constexpr int max_inner = 32;

// Outputs are __restrict: no operation writes a value it reads (the tape compiler gives every instruction a
// register none of its operands occupies), and without it every store would reload the operands.
// Top: the outermost level; Fixed > 0: its number of directions, known at compile time (the hot case, a Dual over
// B with a few directions: the loops are then unrolled), 0: given at run time in n[Top].
template <class B, int Top, int Fixed>
struct Duals {
  int n[3];     // n[L]: directions at level L (L >= 1; level 0 is B itself)
  int size[3];  // size[L]: how many B a value of level L holds (size[0] = 1)

  // size[L] and n[L], known at compile time for B itself and for a fixed outermost level
  template <int L>
  int count() const {
    if constexpr (L == 0)
      return 1;
    else if constexpr (L == Top && Fixed > 0)
      return (Fixed + 1) * count<L - 1>();
    else
      return size[L];
  }
  template <int L>
  int dirs() const {
    if constexpr (L == Top && Fixed > 0)
      return Fixed;
    else
      return n[L];
  }

  template <int L>
  void copy(const B* a, B* __restrict r) const {
    for (int k = 0; k < count<L>(); ++k) r[k] = a[k];
  }
  template <int L>
  void zero(B* __restrict r) const {
    for (int k = 0; k < count<L>(); ++k) r[k] = B(0);
  }
  // A constant c at level L: value c, no derivatives.
  template <int L>
  void constant(B c, B* __restrict r) const {
    zero<L>(r);
    r[0] = c;
  }
  template <int L>
  void add(const B* a, const B* b, B* __restrict r) const {
    for (int k = 0; k < count<L>(); ++k) r[k] = a[k] + b[k];
  }
  template <int L>
  void sub(const B* a, const B* b, B* __restrict r) const {
    for (int k = 0; k < count<L>(); ++k) r[k] = a[k] - b[k];
  }
  template <int L>
  void neg(const B* a, B* __restrict r) const {
    for (int k = 0; k < count<L>(); ++k) r[k] = -a[k];
  }
  // T(0) - a, as Dual's division writes it (the same as -a but for the sign of a zero).
  template <int L>
  void zero_minus(const B* a, B* __restrict r) const {
    for (int k = 0; k < count<L>(); ++k) r[k] = B(0) - a[k];
  }
  // 2 * a (Dual(2) * a: the products with the constant's zero derivatives add nothing).
  template <int L>
  void twice(const B* a, B* __restrict r) const {
    for (int k = 0; k < count<L>(); ++k) r[k] = B(2) * a[k];
  }

  // r.v = a.v b.v; r.d[i] = a.d[i] b.v + a.v b.d[i]
  template <int L>
  void mul(const B* a, const B* b, B* __restrict r) const {
    if constexpr (L == 0) {
      r[0] = a[0] * b[0];
    } else {
      const int s = count<L - 1>();
      mul<L - 1>(a, b, r);
      B t1[max_inner], t2[max_inner];
      for (int i = 1; i <= dirs<L>(); ++i) {
        mul<L - 1>(a + i * s, b, t1);
        mul<L - 1>(a, b + i * s, t2);
        add<L - 1>(t1, t2, r + i * s);
      }
    }
  }
  // inv = T(1) / b.v; r.v = a.v inv; r.d[i] = (a.d[i] - r.v b.d[i]) inv
  template <int L>
  void div(const B* a, const B* b, B* __restrict r) const {
    if constexpr (L == 0) {
      r[0] = a[0] / b[0];
    } else {
      const int s = count<L - 1>();
      B inv[max_inner], t[max_inner], u[max_inner];
      recip<L - 1>(b, inv);
      mul<L - 1>(a, inv, r);
      for (int i = 1; i <= dirs<L>(); ++i) {
        mul<L - 1>(r, b + i * s, t);
        sub<L - 1>(a + i * s, t, u);
        mul<L - 1>(u, inv, r + i * s);
      }
    }
  }
  // T(1) / b: a division whose numerator is the constant 1.
  template <int L>
  void recip(const B* b, B* __restrict r) const {
    if constexpr (L == 0) {
      r[0] = B(1) / b[0];
    } else {
      const int s = count<L - 1>();
      B inv[max_inner], one[max_inner], t[max_inner], u[max_inner];
      recip<L - 1>(b, inv);
      constant<L - 1>(B(1), one);
      mul<L - 1>(one, inv, r);
      for (int i = 1; i <= dirs<L>(); ++i) {
        mul<L - 1>(r, b + i * s, t);
        zero_minus<L - 1>(t, u);
        mul<L - 1>(u, inv, r + i * s);
      }
    }
  }
  // c / a for a constant c (Dual(c) / a).
  template <int L>
  void rdiv_const(B c, const B* a, B* __restrict r) const {
    if constexpr (L == 0) {
      r[0] = c / a[0];
    } else {
      const int s = count<L - 1>();
      B inv[max_inner], cst[max_inner], t[max_inner], u[max_inner];
      recip<L - 1>(a, inv);
      constant<L - 1>(c, cst);
      mul<L - 1>(cst, inv, r);
      for (int i = 1; i <= dirs<L>(); ++i) {
        mul<L - 1>(r, a + i * s, t);
        zero_minus<L - 1>(t, u);
        mul<L - 1>(u, inv, r + i * s);
      }
    }
  }
  // Dual's chain rule: r.v = f, r.d[i] = df a.d[i] (f written by the caller into r).
  template <int L>
  void chain(const B* a, const B* df, B* __restrict r) const {
    const int s = count<L - 1>();
    for (int i = 1; i <= dirs<L>(); ++i) mul<L - 1>(df, a + i * s, r + i * s);
  }

  // sin and cos of a together: the values (and every derivative) need both of the same argument, and one
  // libm sincos computes both (the value and the derivative of Dual's sin and cos, the same numbers)
  template <int L>
  void sincos(const B* a, B* __restrict s, B* __restrict c) const {
    if constexpr (L == 0) {
      const B v = a[0];
      s[0] = std::sin(v);
      c[0] = std::cos(v);
    } else {
      const int w = count<L - 1>();
      B ms[max_inner];
      sincos<L - 1>(a, s, c);
      neg<L - 1>(s, ms);
      for (int i = 1; i <= dirs<L>(); ++i) {
        mul<L - 1>(c, a + i * w, s + i * w);  // sin' = cos
        mul<L - 1>(ms, a + i * w, c + i * w);  // cos' = -sin
      }
    }
  }
  template <int L>
  void sin(const B* a, B* __restrict r) const {
    if constexpr (L == 0) {
      r[0] = std::sin(a[0]);
    } else {
      B c[max_inner];
      sincos<L - 1>(a, r, c);
      chain<L>(a, c, r);
    }
  }
  template <int L>
  void cos(const B* a, B* __restrict r) const {
    if constexpr (L == 0) {
      r[0] = std::cos(a[0]);
    } else {
      B s[max_inner], df[max_inner];
      sincos<L - 1>(a, s, r);
      neg<L - 1>(s, df);
      chain<L>(a, df, r);
    }
  }
  // the tape's tan: Dual's formula, tan' = 1 + tan^2
  template <int L>
  void tan(const B* a, B* __restrict r) const {
    if constexpr (L == 0) {
      r[0] = std::tan(a[0]);
    } else {
      B tt[max_inner], df[max_inner];
      tan<L - 1>(a, r);
      mul<L - 1>(r, r, tt);
      copy<L - 1>(tt, df);
      df[0] = B(1) + tt[0];
      chain<L>(a, df, r);
    }
  }
  template <int L>
  void exp(const B* a, B* __restrict r) const {
    if constexpr (L == 0) {
      r[0] = std::exp(a[0]);
    } else {
      B e[max_inner];
      exp<L - 1>(a, r);
      copy<L - 1>(r, e);
      chain<L>(a, e, r);
    }
  }
  template <int L>
  void log(const B* a, B* __restrict r) const {
    if constexpr (L == 0) {
      r[0] = std::log(a[0]);
    } else {
      B df[max_inner];
      log<L - 1>(a, r);
      recip<L - 1>(a, df);
      chain<L>(a, df, r);
    }
  }
  template <int L>
  void sqrt(const B* a, B* __restrict r) const {
    if constexpr (L == 0) {
      r[0] = std::sqrt(a[0]);
    } else {
      B two_s[max_inner], df[max_inner];
      sqrt<L - 1>(a, r);
      twice<L - 1>(r, two_s);
      recip<L - 1>(two_s, df);
      chain<L>(a, df, r);
    }
  }
  // the tape's atan2: Dual's formula
  template <int L>
  void atan2(const B* y, const B* x, B* __restrict r) const {
    if constexpr (L == 0) {
      r[0] = std::atan2(y[0], x[0]);
    } else {
      const int s = count<L - 1>();
      B xx[max_inner], yy[max_inner], sum[max_inner], inv[max_inner], t1[max_inner], t2[max_inner], d[max_inner];
      atan2<L - 1>(y, x, r);
      mul<L - 1>(x, x, xx);
      mul<L - 1>(y, y, yy);
      add<L - 1>(xx, yy, sum);
      recip<L - 1>(sum, inv);
      for (int i = 1; i <= dirs<L>(); ++i) {
        mul<L - 1>(x, y + i * s, t1);
        mul<L - 1>(y, x + i * s, t2);
        sub<L - 1>(t1, t2, d);
        mul<L - 1>(d, inv, r + i * s);
      }
    }
  }

  // The mixed instructions with a constant c (tape.hpp): the constant's zero derivatives are skipped.
  template <int L>
  void add_const(const B* a, B c, B* __restrict r) const {
    copy<L>(a, r);
    r[0] = a[0] + c;
  }
  template <int L>
  void sub_const(const B* a, B c, B* __restrict r) const {
    copy<L>(a, r);
    r[0] = a[0] - c;
  }
  template <int L>
  void const_sub(B c, const B* a, B* __restrict r) const {
    r[0] = c - a[0];
    for (int k = 1; k < count<L>(); ++k) r[k] = -a[k];
  }
  template <int L>
  void mul_const(const B* a, B c, B* __restrict r) const {
    for (int k = 0; k < count<L>(); ++k) r[k] = a[k] * c;
  }
  // a / c: B's division for a plain number, Dual's (a product with the reciprocal) for a dual
  template <int L>
  void div_const(const B* a, B c, B* __restrict r) const {
    if constexpr (L == 0)
      r[0] = a[0] / c;
    else
      mul_const<L>(a, B(1) / c, r);
  }
  // a^c: the chain rule down to std::pow (tape.hpp's pow_p)
  template <int L>
  void pow_const(const B* a, B c, B* __restrict r) const {
    if constexpr (L == 0) {
      r[0] = std::pow(a[0], c);
    } else {
      B p[max_inner], df[max_inner];
      pow_const<L - 1>(a, c, r);
      pow_const<L - 1>(a, B(c - 1), p);
      mul_const<L - 1>(p, c, df);
      chain<L>(a, df, r);
    }
  }
  // t: scratch for one value of level L
  template <int L>
  void pow_int(const B* a, int k, B* __restrict r, B* __restrict t) const {
    if (k == 0) {
      constant<L>(B(1), r);
      return;
    }
    const int m = k < 0 ? -k : k;
    copy<L>(a, r);
    for (int i = 1; i < m; ++i) {
      mul<L>(r, a, t);
      copy<L>(t, r);
    }
    if (k < 0) {
      copy<L>(r, t);
      rdiv_const<L>(B(1), t, r);
    }
  }
  // a^b = exp(b log a) for two variable quantities (std::pow for plain numbers); t, u: scratch
  template <int L>
  void pow_any(const B* a, const B* b, B* __restrict r, B* __restrict t, B* __restrict u) const {
    if constexpr (L == 0) {
      r[0] = std::pow(a[0], b[0]);
    } else {
      log<L>(a, t);
      mul<L>(b, t, u);
      exp<L>(u, r);
    }
  }
};

template <class B, int D, int Fixed>
void eval_nested(const Tape& tape, const int* directions, const B* const* in, const double* pv, B* out) {
  int n[3] = {0, 0, 0}, size[3] = {1, 1, 1};
  if constexpr (D >= 1) n[D] = directions[0];
  if constexpr (D == 2) n[1] = directions[1];
  for (int L = 1; L <= D; ++L) size[L] = size[L - 1] * (n[L] + 1);
  for (int L = 0; L < D; ++L)
    if (size[L] > max_inner) throw std::length_error("Tape::eval_duals: a dual with more than 31 directions");
  const Duals<B, D, Fixed> ops{{n[0], n[1], n[2]}, {size[0], size[1], size[2]}};
  const int stride = ops.template count<D>(), ni = tape.inputs;
  // registers: on the stack when they fit (the common case), else a thread-local buffer (the evaluation is a
  // leaf: it calls no other tape); two more values of scratch for the powers
  constexpr int stack = 512;
  const int need = (tape.registers + 2) * stride;
  B local[stack];
  B* R = local;
  if (need > stack) {
    thread_local std::vector<B> buffer;
    if (buffer.size() < static_cast<std::size_t>(need)) buffer.resize(static_cast<std::size_t>(need));
    R = buffer.data();
  }
  B* const t0 = R + tape.registers * stride;
  B* const t1 = t0 + stride;
  const auto x = [&](std::uint16_t o) -> const B* { return o < ni ? in[o] : R + (o - ni) * stride; };
  for (const Instr& c : tape.code) {
    B* const r = R + c.dst * stride;
    switch (c.op) {
      case Op::add:
        ops.template add<D>(x(c.a), x(c.b), r);
        break;
      case Op::sub:
        ops.template sub<D>(x(c.a), x(c.b), r);
        break;
      case Op::mul:
        ops.template mul<D>(x(c.a), x(c.b), r);
        break;
      case Op::div:
        ops.template div<D>(x(c.a), x(c.b), r);
        break;
      case Op::pow:
        ops.template pow_any<D>(x(c.a), x(c.b), r, t0, t1);
        break;
      case Op::add_p:
        ops.template add_const<D>(x(c.a), B(pv[c.b]), r);
        break;
      case Op::sub_p:
        ops.template sub_const<D>(x(c.a), B(pv[c.b]), r);
        break;
      case Op::rsub_p:
        ops.template const_sub<D>(B(pv[c.b]), x(c.a), r);
        break;
      case Op::mul_p:
        ops.template mul_const<D>(x(c.a), B(pv[c.b]), r);
        break;
      case Op::div_p:
        ops.template div_const<D>(x(c.a), B(pv[c.b]), r);
        break;
      case Op::rdiv_p:
        ops.template rdiv_const<D>(B(pv[c.b]), x(c.a), r);
        break;
      case Op::pow_p:
        ops.template pow_const<D>(x(c.a), B(pv[c.b]), r);
        break;
      case Op::rpow_p:
        ops.template mul_const<D>(x(c.a), B(std::log(pv[c.b])), t0);
        ops.template exp<D>(t0, r);
        break;
      case Op::pow_int:
        ops.template pow_int<D>(x(c.a), static_cast<std::int16_t>(c.b), r, t0);
        break;
      case Op::neg:
        ops.template neg<D>(x(c.a), r);
        break;
      case Op::sin:
        ops.template sin<D>(x(c.a), r);
        break;
      case Op::cos:
        ops.template cos<D>(x(c.a), r);
        break;
      case Op::tan:
        ops.template tan<D>(x(c.a), r);
        break;
      case Op::exp:
        ops.template exp<D>(x(c.a), r);
        break;
      case Op::log:
        ops.template log<D>(x(c.a), r);
        break;
      case Op::sqrt:
        ops.template sqrt<D>(x(c.a), r);
        break;
      case Op::atan2:
        ops.template atan2<D>(x(c.a), x(c.b), r);
        break;
      // the fused pairs: the first instruction into the scratch t0, then the second
      case Op::add_mul:
        ops.template mul<D>(x(c.b), x(c.c), t0);
        ops.template add<D>(x(c.a), t0, r);
        break;
      case Op::sub_mul:
        ops.template mul<D>(x(c.b), x(c.c), t0);
        ops.template sub<D>(x(c.a), t0, r);
        break;
      case Op::mul_sub:
        ops.template mul<D>(x(c.b), x(c.c), t0);
        ops.template sub<D>(t0, x(c.a), r);
        break;
      case Op::add_mulp:
        ops.template mul_const<D>(x(c.b), B(pv[c.c]), t0);
        ops.template add<D>(x(c.a), t0, r);
        break;
      case Op::sub_mulp:
        ops.template mul_const<D>(x(c.b), B(pv[c.c]), t0);
        ops.template sub<D>(x(c.a), t0, r);
        break;
      case Op::mulp_sub:
        ops.template mul_const<D>(x(c.b), B(pv[c.c]), t0);
        ops.template sub<D>(t0, x(c.a), r);
        break;
      case Op::mul_divp:
        ops.template mul<D>(x(c.b), x(c.c), t0);
        ops.template div_const<D>(t0, B(pv[c.a]), r);
        break;
      case Op::mulp_mul:
        ops.template mul_const<D>(x(c.b), B(pv[c.c]), t0);
        ops.template mul<D>(t0, x(c.a), r);
        break;
      case Op::mul_mulp:
        ops.template mul_const<D>(x(c.b), B(pv[c.c]), t0);
        ops.template mul<D>(x(c.a), t0, r);
        break;
    }
  }
  for (std::size_t k = 0; k < tape.outputs.size(); ++k) {
    const TapeOutput& o = tape.outputs[k];
    B* dst = out + static_cast<std::ptrdiff_t>(k) * stride;
    if (o.kind == TapeOutput::slot)
      ops.template copy<D>(x(o.index), dst);
    else if (o.kind == TapeOutput::param)
      ops.template constant<D>(B(pv[o.index]), dst);
    else
      ops.template zero<D>(dst);
  }
}

}  // namespace

template <class B, int Depth>
void Tape::eval_duals(const int* directions, const B* const* in, const double* pv, B* out) const {
  eval_nested<B, Depth, 0>(*this, directions, in, pv, out);
}

#define GEOMINT_TAPE_EVAL(S) template void Tape::eval<S, double>(const S* const*, const double*, S*) const;
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

template void Tape::eval_duals<double, 0>(const int*, const double* const*, const double*, double*) const;
template void Tape::eval_duals<double, 1>(const int*, const double* const*, const double*, double*) const;
template void Tape::eval_duals<double, 2>(const int*, const double* const*, const double*, double*) const;
template void Tape::eval_duals<long double, 0>(const int*, const long double* const*, const double*, long double*) const;
template void Tape::eval_duals<long double, 1>(const int*, const long double* const*, const double*, long double*) const;
template void Tape::eval_duals<long double, 2>(const int*, const long double* const*, const double*, long double*) const;

}  // namespace geomint::formula
