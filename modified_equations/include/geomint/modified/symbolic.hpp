#pragma once
// GiNaC expressions as the coefficient type of the series engine (series.hpp, automatic.hpp): the same residual
// templates that step a scheme and give its modified equation in numbers give it as formulas, in t, q, q' (and
// z), with the system's parameters as symbols.
//
// Why GiNaC: it is a C++ library (the residual templates are C++ and must run unchanged on the coefficient
// type), it is in Debian 12's main archive (libginac-dev; SymEngine, the other C++ CAS, is not packaged there),
// and it has what the engine needs: exact rationals, sin/cos/exp/log of symbols, canonical sums and products,
// normal forms of rational functions, exact linear solves, differentiation. A hand-written polynomial type would
// stop at the pendulum's sin q.
//
// Canonical forms. The series decides which coefficients are zero structurally (its sparsity boxes and its
// precision rules read them), so every coefficient a product computes is expanded (`normalize`): polynomials in
// the atoms (symbols, sin q, cos q, powers of a denominator) are then canonical, and x - x is 0. A solved
// coefficient is brought to a normal form (`simplify`: numerator and denominator, with cos^2 written as
// 1 - sin^2 so that sin^2 + cos^2 = 1 is an identity the CAS sees) before the next order is built on it.
//
// Heavy (GiNaC's headers): included by the symbolic translation units and tests only, never by a program.
#include <chrono>
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include <ginac/ginac.h>

#include <Eigen/Core>

#include "geomint/generic/dual.hpp"
#include "geomint/generic/system.hpp"
#include "geomint/modified/series.hpp"

namespace geomint::modified {

// The exact rational value of a finite double (every finite double is a dyadic rational): constants the code
// writes as doubles (0.5, 0.25, binomials) enter a formula exactly.
GiNaC::ex exact_rational(double x);
// cos(x)^k -> cos(x)^(k mod 2) (1 - sin(x)^2)^(k div 2), expanded: the canonical form in which
// sin^2 + cos^2 - 1 simplifies to 0.
GiNaC::ex reduce_trigonometric(const GiNaC::ex& e);
// normal form (numerator/denominator, trigonometric squares reduced): what the engine keeps of each solved
// coefficient.
GiNaC::ex simplify_coefficient(const GiNaC::ex& e);
// A x = b, exactly. The engine solves with the same few matrices at every order (one per Taylor degree: the
// Jacobian, or the constrained system's saddle-point matrix, times binomials), while b grows with the order: an
// elimination on [A | b] carries b's swell through every pivot step (one such solve of the Chaplygin sleigh's
// order 2 ran for a minute). Each matrix's inverse is therefore found once, in normal form, kept on this thread
// (keyed by the matrix itself, a few at a time), and a solve is a product.
GiNaC::matrix solve_exact(const GiNaC::matrix& A, const GiNaC::matrix& b);
// The number of nodes of an expression's tree (symbols, numbers, functions, sums, products, powers): the size of a
// formula, as the benchmarks report it beside the seconds.
std::size_t expression_size(const GiNaC::ex& e);

template <>
struct CoefficientTraits<GiNaC::ex> {
  static bool is_zero(const GiNaC::ex& c) { return c.is_zero(); }
  template <class X>
  static GiNaC::ex from_number(X x) {
    if constexpr (std::is_integral_v<X>)
      return GiNaC::ex(static_cast<long>(x));
    else
      return exact_rational(static_cast<double>(x));
  }
  static GiNaC::ex normalize(const GiNaC::ex& c) { return c.expand(); }
  static GiNaC::ex simplify(const GiNaC::ex& c) { return simplify_coefficient(c); }
  template <int N>
  static Vec<GiNaC::ex, N> solve(const Mat<GiNaC::ex, N, N>& A, const Vec<GiNaC::ex, N>& b) {
    GiNaC::matrix M(N, N), rhs(N, 1);
    for (int i = 0; i < N; ++i) {
      for (int k = 0; k < N; ++k) M(i, k) = A(i, k);
      rhs(i, 0) = b(i);
    }
    const GiNaC::matrix s = solve_exact(M, rhs);
    Vec<GiNaC::ex, N> out;
    for (int i = 0; i < N; ++i) out(i) = s(i, 0);
    return out;
  }
};

// The symbols of a formula: time, the step, the state, and the names the printers give them.
struct FormulaSymbols {
  GiNaC::symbol t{"t"}, h{"h"}, z{"z"};
  std::vector<GiNaC::symbol> q, v;  // positions and velocities q'
  std::vector<GiNaC::symbol> params;
  std::vector<GiNaC::symbol> u;     // quasi-velocities, where a constraint chart made some (ConstraintChart)
  explicit FormulaSymbols(int n);
  // A parameter's symbol, made once per name; InputError for h, t, z, q<i>, v<i> (the formulas' own names).
  GiNaC::symbol param(const std::string& name);
  GiNaC::lst all() const;  // every symbol, for a parser's table
};

// The velocities on a linear constraint A(t, q) q' + b(t, q) = 0 (m rows of full rank, n coordinates) in n - m
// quasi-velocities: q' = S(t, q) u + w(t, q) with A S = 0 and A w = -b, so that a formula in (q, u) lives on the
// constraint and the constraint holds by construction (Maggi's and Hamel's formulations take the same view).
// The engine derives the chart from A and b: the kernel's columns e_i - A_D^-1 A_i from the nonzero m x m minor
// A_D with the fewest terms, made orthogonal (Gram-Schmidt in the coordinates) and each freed of denominators and
// common factors; w the least-squares solution -A^T (A A^T)^-1 b, orthogonal to them. A column e_i with no offset
// in its row keeps q'_i as its own quasi-velocity; the others get new symbols u1.. This gives the charts a text
// book takes for the systems here: the Chaplygin sleigh's q' = u1 (cos q3, sin q3, 0) + u2 (-a sin q3, a cos q3, 1)
// (its speed along the heading and its turning rate), the knife edge's q' = u1 (cos q3, sin q3, 0) + q'3 e3, the
// Foucault constraint (13)'s q' = u1 (q1, q2) + s (q2, -q1) (radial motion and the imposed turning).
// Derived rather than declared: it asks nothing of a system file, and a system that needs another chart has not
// been met yet. The chart holds on the constraint Phi = 0; the modified solution keeps the modified constraint
// Phi_h (an O(h) distance away), so the formulas on the chart are the modified vector field's values there, not a
// reduction of the modified flow. InputError for dependent rows.
struct ConstraintChart {
  std::vector<GiNaC::ex> v;  // q'_i(t, q, u), i = 0..n-1
  std::vector<int> mapped;   // the i whose q'_i is not itself a quasi-velocity (the rows printed as the map back)
  std::string how;           // one line: which basis was taken
};
ConstraintChart constraint_chart(const std::vector<std::vector<GiNaC::ex>>& A, const std::vector<GiNaC::ex>& b,
                                 FormulaSymbols& sy);

// The name a formula prints for a system parameter: its own (symbolic.cpp's printers escape for Mathematica).
std::string printed_symbol_name(const std::string& name);

// Printers, one order of terms in all (sorted by text, not GiNaC's serial-dependent order). `text`: the formula
// language (define_system reads it; sympy's parse_expr with the names as local symbols); `mathematica`: Sin[q1],
// capitalized names in Global`, exact rationals a/b in both; `latex`: \frac, \dot{q}_{1}. docs/formulas.md.
std::string formula_text(const GiNaC::ex& e);
std::string formula_mathematica(const GiNaC::ex& e);
std::string formula_latex(const GiNaC::ex& e);

// sum_k h^k c_k, each c_k in display form: normal form, trigonometric squares reduced, common factors
// collected (collect_common_factors), so the printed formula reads one power of h per term.
GiNaC::ex collect_in_h(const std::vector<GiNaC::ex>& coefficients, const GiNaC::symbol& h);
GiNaC::ex display_form(const GiNaC::ex& e);

// A time budget for one symbolic run (the orders stop being built once it is spent; the run says so).
struct SymbolicBudget {
  double seconds = 60;
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  double elapsed() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); }
  bool spent() const { return elapsed() > seconds; }
};

}  // namespace geomint::modified

namespace Eigen {
template <>
struct NumTraits<GiNaC::ex> : GenericNumTraits<GiNaC::ex> {
  using Real = GiNaC::ex;
  using NonInteger = GiNaC::ex;
  using Nested = GiNaC::ex;
  using Literal = GiNaC::ex;
  enum { IsComplex = 0, IsInteger = 0, IsSigned = 1, RequireInitialization = 1, ReadCost = 1, AddCost = 3, MulCost = 3 };
};
// A symbolic parameter times a vector of series or duals (a system's -(alpha m) v).
template <int E, int U, int L, class Op>
struct ScalarBinaryOpTraits<GiNaC::ex, geomint::modified::BiSeries<E, U, L, GiNaC::ex>, Op> {
  using ReturnType = geomint::modified::BiSeries<E, U, L, GiNaC::ex>;
};
template <int E, int U, int L, class Op>
struct ScalarBinaryOpTraits<geomint::modified::BiSeries<E, U, L, GiNaC::ex>, GiNaC::ex, Op> {
  using ReturnType = geomint::modified::BiSeries<E, U, L, GiNaC::ex>;
};
template <class T, int N, class Op>
struct ScalarBinaryOpTraits<GiNaC::ex, geomint::Dual<T, N>, Op> {
  using ReturnType = geomint::Dual<T, N>;
};
template <class T, int N, class Op>
struct ScalarBinaryOpTraits<geomint::Dual<T, N>, GiNaC::ex, Op> {
  using ReturnType = geomint::Dual<T, N>;
};
}  // namespace Eigen
