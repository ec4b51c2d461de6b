#include "geomint/formula/state_formula.hpp"

#include <cctype>
#include <cmath>

#include "geomint/constants.hpp"
#include "geomint/error.hpp"
#include "geomint/formula/parser.hpp"

namespace geomint::formula {

namespace {

// q<k> / v<k>, k = 1..n written without leading zeros: the slot's index k - 1, or -1.
int coordinate(const std::string& s, char letter, int n) {
  if (s.size() < 2 || s.size() > 4 || s[0] != letter || s[1] == '0') return -1;
  for (std::size_t i = 1; i < s.size(); ++i)
    if (!std::isdigit(static_cast<unsigned char>(s[i]))) return -1;
  const int k = std::stoi(s.substr(1));
  return k <= n ? k - 1 : -1;
}

int checked(int n) {
  require(n >= 1 && n <= Expressions::max_coordinates,
          "a state formula needs 1.." + std::to_string(Expressions::max_coordinates) + " coordinates, got " + std::to_string(n));
  return n;
}

}  // namespace

StateFormula::StateFormula(const std::string& text, int n, const std::vector<std::pair<std::string, double>>& parameters)
    : text_(text), ex_(checked(n)) {
  const Variables& V = ex_.variables();
  auto resolve = [&](const std::string& name, int column) {
    if (name == "pi") return ex_.number(pi, "pi");
    if (name == "t") return ex_.var(V.t());
    if (const int i = coordinate(name, 'q', n); i >= 0) return ex_.var(V.q(i));
    if (const int i = coordinate(name, 'v', n); i >= 0) return ex_.var(V.v(i));
    for (const auto& [p, value] : parameters)
      if (p == name) return ex_.number(value, name);
    std::string known = "t, q1..q" + std::to_string(n) + ", v1..v" + std::to_string(n) + ", pi";
    for (const auto& [p, value] : parameters) known += ", " + p;
    throw ParseError(column, "unknown symbol '" + name + "' (known: " + known + ")");
  };
  try {
    root_ = parse_formula(ex_, text, resolve);
  } catch (const ParseError& e) {
    throw InputError("formula '" + text + "', column " + std::to_string(e.column) + ": " + e.what());
  }
}

double StateFormula::operator()(double t, const double* q, const double* v) const {
  // Operands are interned before the nodes that use them: one pass in id order evaluates every node.
  std::vector<double> x(static_cast<std::size_t>(root_ + 1));
  const Variables& V = ex_.variables();
  for (int id = 0; id <= root_; ++id) {
    const Node& d = ex_[id];
    auto a = [&] { return x[static_cast<std::size_t>(d.a)]; };
    auto b = [&] { return x[static_cast<std::size_t>(d.b)]; };
    double r = 0;
    switch (d.kind) {
      case Kind::number:
        r = d.value;
        break;
      case Kind::param:  // parameters are resolved to their values
        r = missing_value;
        break;
      case Kind::var:
        r = d.index == V.t() ? t : d.index <= V.n ? q[d.index - 1] : d.index <= 2 * V.n ? v[d.index - 1 - V.n] : missing_value;
        break;
      case Kind::neg:
        r = -a();
        break;
      case Kind::add:
        r = a() + b();
        break;
      case Kind::sub:
        r = a() - b();
        break;
      case Kind::mul:
        r = a() * b();
        break;
      case Kind::div:
        r = a() / b();
        break;
      case Kind::pow:
        r = std::pow(a(), b());
        break;
      case Kind::call:
        switch (d.fn) {
          case Fn::sin: r = std::sin(a()); break;
          case Fn::cos: r = std::cos(a()); break;
          case Fn::tan: r = std::tan(a()); break;
          case Fn::exp: r = std::exp(a()); break;
          case Fn::log: r = std::log(a()); break;
          case Fn::sqrt: r = std::sqrt(a()); break;
          case Fn::atan2: r = std::atan2(a(), b()); break;
        }
        break;
    }
    x[static_cast<std::size_t>(id)] = r;
  }
  return x[static_cast<std::size_t>(root_)];
}

}  // namespace geomint::formula
