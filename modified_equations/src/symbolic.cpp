#include "geomint/modified/symbolic.hpp"

#include <cctype>
#include <cmath>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

namespace geomint::modified {

using GiNaC::ex;
using GiNaC::ex_to;

ex exact_rational(double x) {
  if (!std::isfinite(x)) throw std::domain_error("symbolic: a non-finite constant in a formula");
  if (x == 0) return 0;
  int e = 0;
  const double m = std::frexp(x, &e);  // x = m 2^e, 0.5 <= |m| < 1: m 2^53 is an integer
  const auto mi = static_cast<long long>(std::ldexp(m, 53));
  return GiNaC::numeric(mi) * GiNaC::pow(GiNaC::numeric(2), e - 53);
}

ex reduce_trigonometric(const ex& e) {
  static const ex pattern = GiNaC::pow(GiNaC::cos(GiNaC::wild(0)), 2);
  static const ex replacement = 1 - GiNaC::pow(GiNaC::sin(GiNaC::wild(0)), 2);
  if (!e.has(pattern)) return e;
  return e.subs(pattern == replacement, GiNaC::subs_options::algebraic).expand();
}

ex simplify_coefficient(const ex& e) {
  const ex nd = e.normal().numer_denom();
  const ex n = reduce_trigonometric(nd.op(0)), d = reduce_trigonometric(nd.op(1));
  if (n.is_equal(nd.op(0)) && d.is_equal(nd.op(1))) return (n / d);
  return (n / d).normal();
}

namespace {

bool reserved(const std::string& name) {
  // names that sympy's sympify or Mathematica read as something else
  static const std::set<std::string> r{"I", "E", "N", "S", "O", "Q", "C", "D", "beta", "gamma", "zeta", "pi",
                                       "Pi", "lambda", "re", "im", "sign", "Abs", "lambda", "del", "if", "in", "is"};
  return r.count(name) > 0;
}

std::string tex_name(const std::string& name) {
  static const std::set<std::string> greek{"alpha", "beta", "gamma", "delta", "epsilon", "kappa", "lambda", "mu",
                                           "nu", "xi", "rho", "sigma", "tau", "phi", "psi", "omega", "theta",
                                           "eta", "zeta", "chi", "Omega", "Gamma", "Delta", "Theta", "Phi", "Psi"};
  std::string base = name, sub;
  while (!base.empty() && std::isdigit(static_cast<unsigned char>(base.back()))) {
    sub.insert(sub.begin(), base.back());
    base.pop_back();
  }
  std::string t = greek.count(base) ? "\\" + base : (base.size() > 1 ? "\\mathrm{" + base + "}" : base);
  return sub.empty() ? t : t + "_{" + sub + "}";
}

}  // namespace

FormulaSymbols::FormulaSymbols(int n) {
  for (int i = 0; i < n; ++i) {
    const std::string s = n == 1 ? "" : std::to_string(i + 1);
    const std::string ts = n == 1 ? "" : "_{" + s + "}";
    q.emplace_back("q" + s, "q" + ts);
    v.emplace_back("qdot" + s, "\\dot{q}" + ts);
  }
}

std::string printed_symbol_name(const std::string& name) { return reserved(name) ? name + "p" : name; }

GiNaC::symbol FormulaSymbols::param(const std::string& name) {
  const std::string printed = printed_symbol_name(name);
  for (const auto& p : params)
    if (p.get_name() == printed) return p;
  params.emplace_back(printed, tex_name(name));
  return params.back();
}

GiNaC::lst FormulaSymbols::all() const {
  GiNaC::lst l{t, h, z};
  for (const auto& s : q) l.append(s);
  for (const auto& s : v) l.append(s);
  for (const auto& s : params) l.append(s);
  return l;
}

namespace {

enum class Style { text, mathematica };

// Precedence of what is being printed into: 0 a sum's term, 1 a product's factor, 2 a power's base.
struct Printer {
  Style style;

  std::string number(const GiNaC::numeric& x) const {
    std::ostringstream os;
    if (!x.is_rational()) throw std::domain_error("formula printer: an inexact number in a formula");
    os << x;
    return os.str();
  }

  std::string function(const GiNaC::function& f) const {
    const std::string name = f.get_name();
    std::vector<std::string> args;
    for (std::size_t i = 0; i < f.nops(); ++i) args.push_back(print(f.op(i), 0));
    if (style == Style::text) {
      std::string s = name + "(";
      for (std::size_t i = 0; i < args.size(); ++i) s += (i ? ", " : "") + args[i];
      return s + ")";
    }
    static const std::map<std::string, std::string> mma{{"sin", "Sin"},       {"cos", "Cos"},       {"tan", "Tan"},
                                                        {"exp", "Exp"},       {"log", "Log"},       {"sinh", "Sinh"},
                                                        {"cosh", "Cosh"},     {"tanh", "Tanh"},     {"asin", "ArcSin"},
                                                        {"acos", "ArcCos"},   {"atan", "ArcTan"},   {"abs", "Abs"}};
    if (name == "atan2") return "ArcTan[" + args[1] + ", " + args[0] + "]";  // Mathematica's ArcTan[x, y]
    const auto it = mma.find(name);
    if (it == mma.end()) throw std::domain_error("formula printer: no Mathematica name for " + name);
    std::string s = it->second + "[";
    for (std::size_t i = 0; i < args.size(); ++i) s += (i ? ", " : "") + args[i];
    return s + "]";
  }

  // |e| and its sign, for the signs between the terms of a sum.
  static bool negative(const ex& e) {
    if (GiNaC::is_a<GiNaC::numeric>(e)) return ex_to<GiNaC::numeric>(e).is_negative();
    if (GiNaC::is_a<GiNaC::mul>(e)) {
      const ex c = e.op(e.nops() - 1);
      return GiNaC::is_a<GiNaC::numeric>(c) && ex_to<GiNaC::numeric>(c).is_negative();
    }
    return false;
  }

  std::string product(const ex& e, int level) const {
    GiNaC::numeric c = 1;
    std::vector<ex> num, den;
    for (std::size_t i = 0; i < e.nops(); ++i) {
      const ex f = e.op(i);
      if (GiNaC::is_a<GiNaC::numeric>(f)) {
        c *= ex_to<GiNaC::numeric>(f);
      } else if (GiNaC::is_a<GiNaC::power>(f) && GiNaC::is_a<GiNaC::numeric>(f.op(1)) &&
                 ex_to<GiNaC::numeric>(f.op(1)).is_negative()) {
        den.push_back(GiNaC::pow(f.op(0), -f.op(1)));
      } else {
        num.push_back(f);
      }
    }
    std::string s = c.is_negative() ? "-" : "";
    const GiNaC::numeric a = GiNaC::abs(c), an = a.numer(), ad = a.denom();
    std::vector<std::string> top;
    if (an != 1 || num.empty()) top.push_back(number(an));
    for (const auto& f : num) top.push_back(print(f, 1));
    for (std::size_t i = 0; i < top.size(); ++i) s += (i ? "*" : "") + top[i];
    std::vector<std::string> bottom;
    if (ad != 1) bottom.push_back(number(ad));
    for (const auto& f : den) bottom.push_back(print(f, 1));
    if (!bottom.empty()) {
      std::string b;
      for (std::size_t i = 0; i < bottom.size(); ++i) b += (i ? "*" : "") + bottom[i];
      s += "/" + (bottom.size() > 1 ? "(" + b + ")" : b);
    }
    const bool wrap = level >= 2 || (level >= 1 && c.is_negative());
    return wrap ? "(" + s + ")" : s;
  }

  std::string print(const ex& e, int level) const {
    if (GiNaC::is_a<GiNaC::numeric>(e)) {
      const auto& x = ex_to<GiNaC::numeric>(e);
      const std::string s = number(x);
      return (level >= 1 && (x.is_negative() || !x.is_integer())) ? "(" + s + ")" : s;
    }
    if (GiNaC::is_a<GiNaC::symbol>(e)) return ex_to<GiNaC::symbol>(e).get_name();
    if (GiNaC::is_a<GiNaC::constant>(e)) {
      if (e.is_equal(GiNaC::Pi)) return style == Style::text ? "pi" : "Pi";
      throw std::domain_error("formula printer: an unknown constant");
    }
    if (GiNaC::is_a<GiNaC::add>(e)) {
      std::string s;
      for (std::size_t i = 0; i < e.nops(); ++i) {
        const ex term = e.op(i);
        const bool neg = negative(term);
        const std::string body = print(neg ? ex(-term) : term, 0);
        s += i == 0 ? (neg ? "-" + body : body) : (neg ? " - " : " + ") + body;
      }
      return level >= 1 ? "(" + s + ")" : s;
    }
    if (GiNaC::is_a<GiNaC::mul>(e)) return product(e, level);
    if (GiNaC::is_a<GiNaC::power>(e)) {
      const ex b = e.op(0), x = e.op(1);
      if (GiNaC::is_a<GiNaC::numeric>(x) && ex_to<GiNaC::numeric>(x).is_negative()) {
        const std::string s = "1/" + print(GiNaC::pow(b, -x), 1);  // 1/b^k
        return level >= 1 ? "(" + s + ")" : s;
      }
      const bool plain = GiNaC::is_a<GiNaC::numeric>(x) && ex_to<GiNaC::numeric>(x).is_pos_integer();
      const std::string s = print(b, 2) + "^" + (plain ? print(x, 2) : "(" + print(x, 0) + ")");
      return level >= 2 ? "(" + s + ")" : s;
    }
    if (GiNaC::is_a<GiNaC::function>(e)) return function(ex_to<GiNaC::function>(e));
    std::ostringstream os;
    os << e;
    throw std::domain_error("formula printer: cannot print " + os.str());
  }
};

}  // namespace

std::string formula_text(const ex& e) { return Printer{Style::text}.print(e, 0); }
std::string formula_mathematica(const ex& e) { return Printer{Style::mathematica}.print(e, 0); }
std::string formula_latex(const ex& e) {
  std::ostringstream os;
  os << GiNaC::latex << e;
  return os.str();
}

ex display_form(const ex& e) {
  const ex nd = simplify_coefficient(e).numer_denom();
  return GiNaC::collect_common_factors(nd.op(0)) / GiNaC::collect_common_factors(nd.op(1));
}

ex collect_in_h(const std::vector<ex>& coefficients, const GiNaC::symbol& h) {
  ex s = 0;
  for (std::size_t k = 0; k < coefficients.size(); ++k) s += GiNaC::pow(h, static_cast<int>(k)) * display_form(coefficients[k]);
  return s;
}

}  // namespace geomint::modified
