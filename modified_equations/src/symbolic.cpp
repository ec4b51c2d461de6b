#include "geomint/modified/symbolic.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

#include "geomint/error.hpp"

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

bool same_matrix(const GiNaC::matrix& a, const GiNaC::matrix& b) {
  if (a.rows() != b.rows() || a.cols() != b.cols()) return false;
  for (unsigned i = 0; i < a.rows(); ++i)
    for (unsigned k = 0; k < a.cols(); ++k)
      if (!a(i, k).is_equal(b(i, k))) return false;
  return true;
}

}  // namespace

GiNaC::matrix solve_exact(const GiNaC::matrix& A, const GiNaC::matrix& b) {
  // a handful: one matrix per Taylor degree of the order asked, at most a few engines on a thread at once
  constexpr std::size_t kept = 32;
  thread_local std::vector<std::pair<GiNaC::matrix, GiNaC::matrix>> inverses;
  const GiNaC::matrix* inverse = nullptr;
  for (const auto& [M, I] : inverses)
    if (same_matrix(M, A)) inverse = &I;
  if (!inverse) {
    GiNaC::matrix I = A.inverse();
    for (unsigned i = 0; i < I.rows(); ++i)
      for (unsigned k = 0; k < I.cols(); ++k) I(i, k) = simplify_coefficient(I(i, k));
    if (inverses.size() == kept) inverses.erase(inverses.begin());
    inverses.emplace_back(A, std::move(I));
    inverse = &inverses.back().second;
  }
  return inverse->mul(b);
}

std::size_t expression_size(const ex& e) {
  std::size_t n = 1;
  for (std::size_t i = 0; i < e.nops(); ++i) n += expression_size(e.op(i));
  return n;
}

namespace {

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
  for (std::size_t i = 0; (i = t.find('_', i)) != std::string::npos; i += 2) t.replace(i, 1, "\\_");
  return sub.empty() ? t : t + "_{" + sub + "}";
}

// q<k> or v<k> with 1 <= k <= n: a coordinate or velocity of the formula language.
bool state_name(const std::string& name, int n) {
  if (name.size() < 2 || (name[0] != 'q' && name[0] != 'v') || name[1] == '0') return false;
  for (std::size_t i = 1; i < name.size(); ++i)
    if (!std::isdigit(static_cast<unsigned char>(name[i]))) return false;
  return name.size() < 6 && std::stoi(name.substr(1)) <= n;
}

}  // namespace

// The names of the formula language (docs/systems/README.md): q1..qn, v1..vn whatever n, so that a printed
// formula is read back by define_system as it stands.
FormulaSymbols::FormulaSymbols(int n) {
  for (int i = 0; i < n; ++i) {
    const std::string s = std::to_string(i + 1);
    q.emplace_back("q" + s, "q_{" + s + "}");
    v.emplace_back("v" + s, "\\dot{q}_{" + s + "}");
  }
}

std::string printed_symbol_name(const std::string& name) { return name; }

GiNaC::symbol FormulaSymbols::param(const std::string& name) {
  // a parameter printed under the name of the step or of the state would make the formulas ambiguous
  require(name != "h" && name != "t" && name != "z" && !state_name(name, static_cast<int>(q.size())),
          "parameter '" + name + "': the formulas of the modified equation use " + name +
              " for the step (h), the time (t), the Herglotz action (z) or the state (q1.., v1..): rename the parameter");
  for (const auto& p : params)
    if (p.get_name() == name) return p;
  params.emplace_back(name, tex_name(name));
  return params.back();
}

GiNaC::lst FormulaSymbols::all() const {
  GiNaC::lst l{t, h, z};
  for (const auto& s : q) l.append(s);
  for (const auto& s : v) l.append(s);
  for (const auto& s : params) l.append(s);
  for (const auto& s : u) l.append(s);
  return l;
}

namespace {

std::size_t terms(const ex& e) {
  const ex x = e.expand();
  return GiNaC::is_a<GiNaC::add>(x) ? x.nops() : 1;
}

// The m-subsets of 0..n-1 in lexicographic order.
std::vector<std::vector<int>> subsets(int n, int m) {
  std::vector<std::vector<int>> out;
  std::vector<int> c(static_cast<std::size_t>(m));
  for (int i = 0; i < m; ++i) c[static_cast<std::size_t>(i)] = i;
  while (true) {
    out.push_back(c);
    int i = m - 1;
    while (i >= 0 && c[static_cast<std::size_t>(i)] == n - m + i) --i;
    if (i < 0) return out;
    ++c[static_cast<std::size_t>(i)];
    for (int k = i + 1; k < m; ++k) c[static_cast<std::size_t>(k)] = c[static_cast<std::size_t>(k - 1)] + 1;
  }
}

}  // namespace

ConstraintChart constraint_chart(const std::vector<std::vector<ex>>& A, const std::vector<ex>& b, FormulaSymbols& sy) {
  const int m = static_cast<int>(A.size()), n = static_cast<int>(sy.q.size());
  require(m >= 1 && m < n && static_cast<int>(b.size()) == m, "a constraint chart needs 1 <= m < n rows");
  const auto U = [](int i) { return static_cast<std::size_t>(i); };
  // the pivot columns D: the nonzero m x m minor with the fewest terms
  std::vector<int> D;
  std::size_t best = 0;
  for (const auto& c : subsets(n, m)) {
    GiNaC::matrix M(U(m), U(m));
    for (int r = 0; r < m; ++r)
      for (int k = 0; k < m; ++k) M(U(r), U(k)) = A[U(r)][U(c[U(k)])];
    const ex d = simplify_coefficient(M.determinant());
    if (d.is_zero()) continue;
    if (D.empty() || terms(d) < best) {
      D = c;
      best = terms(d);
    }
  }
  if (D.empty())
    throw InputError("the constraint rows are dependent (every " + std::to_string(m) + " x " + std::to_string(m) +
                     " minor of their matrix is 0): no chart on the constraint");
  GiNaC::matrix AD(U(m), U(m));
  for (int r = 0; r < m; ++r)
    for (int k = 0; k < m; ++k) AD(U(r), U(k)) = A[U(r)][U(D[U(k)])];
  const GiNaC::matrix ADinv = AD.inverse();
  // a column without denominators and without a common factor (the trigonometric atoms taken as symbols)
  auto tidy = [&](std::vector<ex> col) {
    ex scale = 1;
    for (auto& e : col) {
      e = simplify_coefficient(e);
      const ex d = e.normal().denom();
      if (!GiNaC::is_a<GiNaC::numeric>(d) && !GiNaC::is_a<GiNaC::numeric>(simplify_coefficient(scale / d).normal().denom()))
        scale = scale * d;
    }
    GiNaC::exmap atoms;
    std::vector<ex> poly;
    ex g = 0;
    for (auto& e : col) {
      e = simplify_coefficient(e * scale);
      poly.push_back(e.to_polynomial(atoms));
      g = g.is_zero() ? poly.back() : GiNaC::gcd(g, poly.back());
    }
    g = g.subs(atoms);
    if (!GiNaC::is_a<GiNaC::numeric>(g))
      for (auto& e : col) e = simplify_coefficient(e / g);
    return col;
  };
  // the kernel's columns, one per velocity outside D, made orthogonal (Gram-Schmidt in the coordinates' metric):
  // e_i - A_D^-1 A_i spans the kernel; orthogonal, it gives the charts the text books take (the sleigh's
  // (cos q3, sin q3, 0) and (-a sin q3, a cos q3, 1): its speed along the heading and its turning rate)
  std::vector<int> I;
  for (int i = 0; i < n; ++i)
    if (std::find(D.begin(), D.end(), i) == D.end()) I.push_back(i);
  std::vector<std::vector<ex>> cols;
  for (int i : I) {
    GiNaC::matrix Ai(U(m), 1);
    for (int r = 0; r < m; ++r) Ai(U(r), 0) = A[U(r)][U(i)];
    const GiNaC::matrix x = ADinv.mul(Ai);
    std::vector<ex> col(U(n), ex(0));
    col[U(i)] = 1;
    for (int k = 0; k < m; ++k) col[U(D[U(k)])] = -x(U(k), 0);
    col = tidy(col);
    for (const auto& p : cols) {
      ex cp = 0, pp = 0;
      for (int k = 0; k < n; ++k) {
        cp += col[U(k)] * p[U(k)];
        pp += p[U(k)] * p[U(k)];
      }
      const ex f = simplify_coefficient(cp / pp);
      if (f.is_zero()) continue;
      for (int k = 0; k < n; ++k) col[U(k)] -= f * p[U(k)];
      col = tidy(col);
    }
    cols.push_back(col);
  }
  // the particular solution: least squares, orthogonal to the kernel
  std::vector<ex> w(U(n), ex(0));
  bool offset = false;
  for (const auto& x : b) offset = offset || !simplify_coefficient(x).is_zero();
  if (offset) {
    GiNaC::matrix bb(U(m), 1), AA(U(m), U(n));
    for (int r = 0; r < m; ++r) {
      bb(U(r), 0) = b[U(r)];
      for (int i = 0; i < n; ++i) AA(U(r), U(i)) = A[U(r)][U(i)];
    }
    const GiNaC::matrix x = AA.transpose().mul(AA.mul(AA.transpose()).inverse().mul(bb));
    for (int i = 0; i < n; ++i) w[U(i)] = simplify_coefficient(-x(U(i), 0));
  }
  // the quasi-velocities' names: u1..u(n-m), unless a parameter has one of them
  std::string prefix = "u";
  for (const char* candidate : {"u", "w", "r", "uq"}) {
    prefix = candidate;
    bool clash = false;
    for (const auto& p : sy.params)
      for (int k = 1; k <= n - m; ++k) clash = clash || p.get_name() == prefix + std::to_string(k);
    if (!clash) break;
  }
  ConstraintChart chart;
  chart.v = w;
  for (std::size_t c = 0; c < cols.size(); ++c) {
    const int i = I[c];
    // a column e_i with no offset in its row: q'_i is its own quasi-velocity (the other columns are orthogonal to
    // e_i: none has an entry in row i)
    bool unit = w[U(i)].is_zero();
    for (int k = 0; k < n; ++k) unit = unit && (cols[c][U(k)] - (k == i ? 1 : 0)).is_zero();
    ex u = sy.v[U(i)];
    if (!unit) {
      sy.u.emplace_back(prefix + std::to_string(sy.u.size() + 1));
      u = sy.u.back();
    }
    for (int k = 0; k < n; ++k) chart.v[U(k)] += cols[c][U(k)] * u;
  }
  for (int i = 0; i < n; ++i) {
    chart.v[U(i)] = simplify_coefficient(chart.v[U(i)]);
    if (!chart.v[U(i)].is_equal(sy.v[U(i)])) chart.mapped.push_back(i);
  }
  // the chart lies on the constraint, identically
  for (int r = 0; r < m; ++r) {
    ex phi = b[U(r)];
    for (int i = 0; i < n; ++i) phi += A[U(r)][U(i)] * chart.v[U(i)];
    if (!simplify_coefficient(phi).is_zero())
      throw std::logic_error("constraint chart: row " + std::to_string(r + 1) + " does not vanish on the chart");
  }
  chart.how = "an orthogonal basis of the constraint's kernel" +
              (sy.u.empty() ? std::string() : ", quasi-velocities " + prefix + "1.." + prefix + std::to_string(sy.u.size())) +
              (offset ? ", the offset by least squares" : "");
  return chart;
}

namespace {

enum class Style { text, mathematica, latex };

// Precedence of what is being printed into: 0 a sum's term, 1 a product's factor, 2 a power's base.
//
// The order of a sum's terms and of a product's factors is the printer's, not GiNaC's: GiNaC orders them by
// hashes of its symbols' serial numbers, which depend on how many symbols the process made before, so the same
// formula printed in two calls (or two processes) could read differently. Here terms and factors are sorted by
// their text form (the unsigned term; numbers first), the same order in every style.
struct Printer {
  Style style;

  static std::string key(const ex& e) { return Printer{Style::text}.print(e, 0); }

  static std::vector<ex> sorted(std::vector<ex> xs) {
    std::vector<std::pair<std::string, ex>> keyed;
    for (const auto& x : xs) keyed.emplace_back(key(x), x);
    std::stable_sort(keyed.begin(), keyed.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    for (std::size_t i = 0; i < xs.size(); ++i) xs[i] = keyed[i].second;
    return xs;
  }

  std::string open() const { return style == Style::latex ? "\\left(" : "("; }
  std::string close() const { return style == Style::latex ? "\\right)" : ")"; }
  std::string paren(const std::string& s) const { return open() + s + close(); }
  std::string times() const { return style == Style::latex ? " " : "*"; }

  std::string integer(const GiNaC::numeric& x) const {
    std::ostringstream os;
    os << x;
    return os.str();
  }

  std::string number(const GiNaC::numeric& x) const {
    if (!x.is_rational()) throw std::domain_error("formula printer: an inexact number in a formula");
    if (style == Style::latex && !x.is_integer()) {
      const GiNaC::numeric a = GiNaC::abs(x);
      return (x.is_negative() ? "-" : "") + std::string("\\frac{") + integer(a.numer()) + "}{" + integer(a.denom()) + "}";
    }
    return integer(x);
  }

  // Mathematica reserves names that begin with a capital (its built-ins: I, E, N, C, D, ...) and has no '_' in
  // names: such a parameter is written in the Global` context and with \[LetterSpace] for '_' (reversed by
  // dropping "Global`" and writing '_' back).
  static std::string mathematica_name(const std::string& name) {
    std::string s = std::isupper(static_cast<unsigned char>(name[0])) ? "Global`" + name : name;
    for (std::size_t i = 0; (i = s.find('_', i)) != std::string::npos;) s.replace(i, 1, "\\[LetterSpace]");
    return s;
  }

  std::string symbol(const GiNaC::symbol& x) const {
    if (style == Style::latex) return x.get_TeX_name();
    return style == Style::mathematica ? mathematica_name(x.get_name()) : x.get_name();
  }

  std::string function(const GiNaC::function& f) const {
    const std::string name = f.get_name();
    std::vector<std::string> args;
    for (std::size_t i = 0; i < f.nops(); ++i) args.push_back(print(f.op(i), 0));
    auto join = [&](const std::string& sep) {
      std::string s;
      for (std::size_t i = 0; i < args.size(); ++i) s += (i ? sep : "") + args[i];
      return s;
    };
    if (style == Style::text) return name + "(" + join(", ") + ")";
    if (style == Style::latex) {
      static const std::set<std::string> tex{"sin", "cos", "tan", "exp", "log", "sinh", "cosh", "tanh"};
      static const std::map<std::string, std::string> arc{{"asin", "\\arcsin"}, {"acos", "\\arccos"}, {"atan", "\\arctan"}};
      if (name == "abs") return "\\left|" + join(", ") + "\\right|";
      if (tex.count(name)) return "\\" + name + paren(join(", "));
      const auto it = arc.find(name);
      return (it != arc.end() ? it->second : "\\operatorname{" + name + "}") + paren(join(", "));
    }
    static const std::map<std::string, std::string> mma{{"sin", "Sin"},       {"cos", "Cos"},       {"tan", "Tan"},
                                                        {"exp", "Exp"},       {"log", "Log"},       {"sinh", "Sinh"},
                                                        {"cosh", "Cosh"},     {"tanh", "Tanh"},     {"asin", "ArcSin"},
                                                        {"acos", "ArcCos"},   {"atan", "ArcTan"},   {"abs", "Abs"}};
    if (name == "atan2") return "ArcTan[" + args[1] + ", " + args[0] + "]";  // Mathematica's ArcTan[x, y]
    const auto it = mma.find(name);
    if (it == mma.end()) throw std::domain_error("formula printer: no Mathematica name for " + name);
    return it->second + "[" + join(", ") + "]";
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

  std::string factors(const std::vector<std::string>& fs) const {
    std::string s;
    for (std::size_t i = 0; i < fs.size(); ++i) s += (i ? times() : "") + fs[i];
    return s;
  }

  // Whether a sum's first term in the printed order is negative. A product's sign is a choice between c*s and
  // (-c)*(-s), which GiNaC makes by its own term order (its symbols' serial numbers): the printer makes it by the
  // printed order instead, so that every sum factor starts with a positive term.
  static bool leads_negative(const ex& sum) {
    std::size_t first = 0;
    std::string best;
    for (std::size_t i = 0; i < sum.nops(); ++i) {
      const std::string k = key(negative(sum.op(i)) ? ex(-sum.op(i)) : sum.op(i));
      if (i == 0 || k < best) {
        best = k;
        first = i;
      }
    }
    return sum.nops() > 0 && negative(sum.op(first));
  }

  // f with its sum (or the sum it is a power of) turned to start with a positive term; c takes the sign.
  static ex with_positive_lead(const ex& f, GiNaC::numeric& c) {
    if (GiNaC::is_a<GiNaC::add>(f) && leads_negative(f)) {
      const ex g = -f;
      if (!GiNaC::is_a<GiNaC::add>(g)) return f;
      c = -c;
      return g;
    }
    if (GiNaC::is_a<GiNaC::power>(f) && GiNaC::is_a<GiNaC::add>(f.op(0)) && GiNaC::is_a<GiNaC::numeric>(f.op(1)) &&
        ex_to<GiNaC::numeric>(f.op(1)).is_integer() && leads_negative(f.op(0))) {
      const ex b = -f.op(0);
      if (!GiNaC::is_a<GiNaC::add>(b)) return f;
      if (ex_to<GiNaC::numeric>(f.op(1)).is_odd()) c = -c;
      return GiNaC::pow(b, f.op(1));
    }
    return f;
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
        den.push_back(with_positive_lead(GiNaC::pow(f.op(0), -f.op(1)), c));
      } else {
        num.push_back(with_positive_lead(f, c));
      }
    }
    std::string s = c.is_negative() ? "-" : "";
    const GiNaC::numeric a = GiNaC::abs(c), an = a.numer(), ad = a.denom();
    std::vector<std::string> top;
    if (an != 1 || num.empty()) top.push_back(integer(an));
    for (const auto& f : sorted(num)) top.push_back(print(f, 1));
    std::vector<std::string> bottom;
    if (ad != 1) bottom.push_back(integer(ad));
    for (const auto& f : sorted(den)) bottom.push_back(print(f, 1));
    if (style == Style::latex) {
      s += bottom.empty() ? factors(top) : "\\frac{" + factors(top) + "}{" + factors(bottom) + "}";
    } else {
      s += factors(top);
      if (!bottom.empty()) s += "/" + (bottom.size() > 1 ? paren(factors(bottom)) : factors(bottom));
    }
    const bool wrap = level >= 2 || (level >= 1 && c.is_negative());
    return wrap ? paren(s) : s;
  }

  std::string print(const ex& e, int level) const {
    if (GiNaC::is_a<GiNaC::numeric>(e)) {
      const auto& x = ex_to<GiNaC::numeric>(e);
      const std::string s = number(x);
      const bool wrap = x.is_negative() ? level >= 1 : !x.is_integer() && level >= (style == Style::latex ? 2 : 1);
      return wrap ? paren(s) : s;
    }
    if (GiNaC::is_a<GiNaC::symbol>(e)) return symbol(ex_to<GiNaC::symbol>(e));
    if (GiNaC::is_a<GiNaC::constant>(e)) {
      if (e.is_equal(GiNaC::Pi)) return style == Style::text ? "pi" : style == Style::latex ? "\\pi" : "Pi";
      throw std::domain_error("formula printer: an unknown constant");
    }
    if (GiNaC::is_a<GiNaC::add>(e)) {
      std::vector<ex> terms;
      for (std::size_t i = 0; i < e.nops(); ++i) terms.push_back(negative(e.op(i)) ? ex(-e.op(i)) : e.op(i));
      std::vector<std::size_t> order(terms.size());
      for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
      std::vector<std::string> keys;
      for (const auto& t : terms) keys.push_back(key(t));
      std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return keys[a] < keys[b]; });
      std::string s;
      for (std::size_t j = 0; j < order.size(); ++j) {
        const std::size_t i = order[j];
        const bool neg = negative(e.op(i));
        const std::string body = print(terms[i], 0);
        s += j == 0 ? (neg ? "-" + body : body) : (neg ? " - " : " + ") + body;
      }
      return level >= 1 ? paren(s) : s;
    }
    if (GiNaC::is_a<GiNaC::mul>(e)) return product(e, level);
    if (GiNaC::is_a<GiNaC::power>(e)) {
      const ex b = e.op(0), x = e.op(1);
      if (GiNaC::is_a<GiNaC::numeric>(x) && ex_to<GiNaC::numeric>(x).is_negative()) {
        const ex inverse = GiNaC::pow(b, -x);
        const std::string s = style == Style::latex ? "\\frac{1}{" + print(inverse, 0) + "}" : "1/" + print(inverse, 1);
        return level >= 1 && style != Style::latex ? paren(s) : s;
      }
      const bool plain = GiNaC::is_a<GiNaC::numeric>(x) && ex_to<GiNaC::numeric>(x).is_pos_integer();
      const std::string s = style == Style::latex ? "{" + print(b, 2) + "}^{" + print(x, 0) + "}"
                                                  : print(b, 2) + "^" + (plain ? print(x, 2) : paren(print(x, 0)));
      return level >= 2 ? paren(s) : s;
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
std::string formula_latex(const ex& e) { return Printer{Style::latex}.print(e, 0); }

namespace {

// The symbols of e, sorted by name: an order that does not depend on GiNaC's hashes.
std::vector<GiNaC::symbol> symbols_by_name(const ex& e) {
  std::map<std::string, GiNaC::symbol> by_name;
  for (auto it = e.preorder_begin(); it != e.preorder_end(); ++it)
    if (GiNaC::is_a<GiNaC::symbol>(*it)) by_name.emplace(ex_to<GiNaC::symbol>(*it).get_name(), ex_to<GiNaC::symbol>(*it));
  std::vector<GiNaC::symbol> out;
  for (const auto& [name, x] : by_name) out.push_back(x);
  return out;
}

// A point that the symbols' names alone fix: the j-th by name at 1.1 + 0.37 j, exactly.
GiNaC::exmap canonical_point(const std::vector<GiNaC::symbol>& symbols) {
  GiNaC::exmap at;
  for (std::size_t j = 0; j < symbols.size(); ++j) at[symbols[j]] = GiNaC::numeric(static_cast<long>(110 + 37 * j), 100);
  return at;
}

// +1 or -1: the sign of p at the canonical point, so that p and -p are told apart the same way in every run. A p
// that is not a real number there counts as positive.
int canonical_sign(const ex& p, const std::vector<GiNaC::symbol>& symbols) {
  const ex x = p.subs(canonical_point(symbols)).evalf();
  if (!GiNaC::is_a<GiNaC::numeric>(x) || !ex_to<GiNaC::numeric>(x).is_real()) return 1;
  return ex_to<GiNaC::numeric>(x).is_negative() ? -1 : 1;
}

}  // namespace

// GiNaC orders terms and factors by hashes seeded with the addresses of its type names, which change from run to
// run (address-space randomization), and normal() follows that order: the same quotient came back with its
// denominator as (q1^2 + q2^2)^3 in one run and expanded in another. So the quotient is shown in a form that its
// value alone fixes: numerator and denominator expanded, the denominator positive at a point fixed by the symbols'
// names, and shown square-free factored (sqrfree, in the symbols by name), each factor positive at that point.
ex display_form(const ex& e) {
  const ex nd = simplify_coefficient(e).numer_denom();
  ex num = nd.op(0).expand(), den = nd.op(1).expand();
  if (GiNaC::is_a<GiNaC::numeric>(den)) return GiNaC::collect_common_factors((num / den).expand());
  const auto symbols = symbols_by_name(den);
  const int sign = canonical_sign(den, symbols);
  num = (sign * num).expand();
  den = (sign * den).expand();
  GiNaC::lst vars;
  for (const auto& x : symbols) vars.append(x);
  ex shown = GiNaC::collect_common_factors(den);
  if (!symbols.empty() && den.is_polynomial(vars)) {
    const ex f = GiNaC::sqrfree(den, vars);
    ex product = 1;  // the factors that are not numbers, each positive at the point
    for (std::size_t i = 0; i < (GiNaC::is_a<GiNaC::mul>(f) ? f.nops() : 1); ++i) {
      const ex x = GiNaC::is_a<GiNaC::mul>(f) ? f.op(i) : f;
      const bool raised = GiNaC::is_a<GiNaC::power>(x) && GiNaC::is_a<GiNaC::numeric>(x.op(1));
      const ex base = raised ? x.op(0) : x, exponent = raised ? x.op(1) : ex(1);
      if (GiNaC::is_a<GiNaC::numeric>(base)) continue;
      product *= GiNaC::pow(GiNaC::collect_common_factors((canonical_sign(base, symbols) * base).expand()), exponent);
    }
    // the number in front: den / product at a rational point where product does not vanish, exactly; checked
    const GiNaC::exmap at = canonical_point(symbols);
    const ex p_at = product.subs(at).expand();
    if (GiNaC::is_a<GiNaC::numeric>(p_at) && !p_at.is_zero()) {
      const ex c = (den.subs(at) / p_at).expand();
      if (GiNaC::is_a<GiNaC::numeric>(c) && (c * product - den).expand().is_zero()) shown = c * product;
    }
  }
  return GiNaC::collect_common_factors(num) / shown;
}

ex collect_in_h(const std::vector<ex>& coefficients, const GiNaC::symbol& h) {
  ex s = 0;
  for (std::size_t k = 0; k < coefficients.size(); ++k) s += GiNaC::pow(h, static_cast<int>(k)) * display_form(coefficients[k]);
  return s;
}

}  // namespace geomint::modified
