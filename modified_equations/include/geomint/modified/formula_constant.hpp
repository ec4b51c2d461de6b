#pragma once
// The numbers of a formula system exact in the symbolic parameter types: GiNaC expressions (the modified equations as
// formulas) and series over them (a surrogate's parameters, whose step is the engine's own h). Heavy (GiNaC):
// included by the symbolic translation units only.
#include <string>

#include "geomint/formula/formula_system.hpp"
#include "geomint/modified/series.hpp"
#include "geomint/modified/symbolic.hpp"

namespace geomint::formula {
// A decimal as written (0.1 = 1/10), pi as pi, a number differentiation made (a small integer, a product of
// written ones) as the rational value of its double.
template <>
struct FormulaConstant<GiNaC::ex> {
  static GiNaC::ex from(double x, const std::string& text) {
    if (text == "pi") return GiNaC::Pi;
    const std::size_t e = text.find_first_of("eE");
    const std::string mantissa = text.substr(0, e);
    const std::size_t dot = mantissa.find('.');
    const std::string digits = dot == std::string::npos ? mantissa : mantissa.substr(0, dot) + mantissa.substr(dot + 1);
    if (text.empty() || digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos)
      return modified::exact_rational(x);
    long exponent = dot == std::string::npos ? 0 : -static_cast<long>(mantissa.size() - dot - 1);
    if (e != std::string::npos) exponent += std::stol(text.substr(e + 1));
    const GiNaC::numeric value = GiNaC::numeric(digits.c_str()) * GiNaC::pow(GiNaC::numeric(10), GiNaC::numeric(exponent));
    // the text is the number: its double is the one the numeric path uses
    return GiNaC::ex(value);
  }
};
// A series' constant: the same exact number.
template <int E, int U, int L>
struct FormulaConstant<modified::BiSeries<E, U, L, GiNaC::ex>> {
  static modified::BiSeries<E, U, L, GiNaC::ex> from(double x, const std::string& text) {
    return modified::BiSeries<E, U, L, GiNaC::ex>(FormulaConstant<GiNaC::ex>::from(x, text));
  }
};
}  // namespace geomint::formula
