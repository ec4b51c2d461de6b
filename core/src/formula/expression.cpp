#include "geomint/formula/expression.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "geomint/error.hpp"

namespace geomint::formula {

namespace {

struct FnEntry {
  Fn fn;
  const char* name;
  int arity;
};
constexpr FnEntry fn_table[] = {{Fn::sin, "sin", 1}, {Fn::cos, "cos", 1},   {Fn::tan, "tan", 1},    {Fn::exp, "exp", 1},
                                {Fn::log, "log", 1}, {Fn::sqrt, "sqrt", 1}, {Fn::atan2, "atan2", 2}};

std::uint64_t bits_of(double v) {
  std::uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

}  // namespace

const char* fn_name(Fn f) {
  for (const auto& e : fn_table)
    if (e.fn == f) return e.name;
  return "?";
}

int fn_arity(Fn f) {
  for (const auto& e : fn_table)
    if (e.fn == f) return e.arity;
  return 1;
}

bool find_fn(const std::string& name, Fn& f) {
  for (const auto& e : fn_table)
    if (name == e.name) {
      f = e.fn;
      return true;
    }
  return false;
}

std::string Variables::name(int slot) const {
  if (slot == t()) return "t";
  if (slot == z()) return "z";
  if (slot <= n) return "q" + std::to_string(slot);
  return "v" + std::to_string(slot - n);
}

std::string Variables::names(std::uint32_t bits) const {
  std::string out;
  for (int s = 0; s < count(); ++s)
    if (bits & bit(s)) out += (out.empty() ? "" : ", ") + name(s);
  return out;
}

std::size_t Expressions::KeyHash::operator()(const Key& k) const {
  std::uint64_t h = k.head * 0x9E3779B97F4A7C15ull;
  h ^= k.operands + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
  h ^= k.value + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
  return static_cast<std::size_t>(h);
}

Expressions::Expressions(int n) {
  require(n >= 1 && n <= max_coordinates, "an expression graph needs 1 to " + std::to_string(max_coordinates) +
                                              " coordinates, got " + std::to_string(n));
  vars_.n = n;
}

int Expressions::intern(const Node& node) {
  const Key key{(std::uint64_t(node.kind) << 56) | (std::uint64_t(node.fn) << 48) | std::uint32_t(node.index),
                (std::uint64_t(std::uint32_t(node.a)) << 32) | std::uint32_t(node.b),
                node.kind == Kind::number ? bits_of(node.value) : 0};
  const auto it = index_.find(key);
  if (it != index_.end()) return it->second;
  Node n = node;
  for (int c : {n.a, n.b})
    if (c >= 0) {
      n.uses |= (*this)[c].uses;
      n.has_param = n.has_param || (*this)[c].has_param;
      n.depth = std::max(n.depth, (*this)[c].depth + 1);
    }
  if (n.depth > max_depth)
    throw InputError("more than " + std::to_string(max_depth) +
                     " operations deep (counting those of the definitions it uses, and of the derivatives taken of it)");
  nodes_.push_back(n);
  const int id = size() - 1;
  index_.emplace(key, id);
  return id;
}

int Expressions::number(double v, const std::string& text) {
  Node n;
  n.kind = Kind::number;
  n.value = v;
  // one table entry per distinct value (by its bits: 0 and -0 differ)
  const auto it = number_index_.find(bits_of(v));
  if (it != number_index_.end()) {
    n.index = it->second;
    if (number_texts_[static_cast<std::size_t>(n.index)].empty()) number_texts_[static_cast<std::size_t>(n.index)] = text;
    return intern(n);
  }
  numbers_.push_back(v);
  number_texts_.push_back(text);
  n.index = static_cast<int>(numbers_.size()) - 1;
  number_index_.emplace(bits_of(v), n.index);
  return intern(n);
}

int Expressions::param(int index) {
  Node n;
  n.kind = Kind::param;
  n.index = index;
  n.has_param = true;
  return intern(n);
}

int Expressions::var(int slot) {
  Node n;
  n.kind = Kind::var;
  n.index = slot;
  n.uses = vars_.bit(slot);
  return intern(n);
}

bool Expressions::is_number(int id, double v) const {
  const Node& n = (*this)[id];
  return n.kind == Kind::number && n.value == v;
}

int Expressions::neg(int a) {
  const Node& x = (*this)[a];
  if (x.kind == Kind::neg) return x.a;  // -(-x) = x
  if (x.kind == Kind::number) return number(-x.value);
  Node n;
  n.kind = Kind::neg;
  n.a = a;
  return intern(n);
}

namespace {
Node binary(Kind k, int a, int b) {
  Node n;
  n.kind = k;
  n.a = a;
  n.b = b;
  return n;
}
}  // namespace

int Expressions::add(int a, int b) {
  if (is_number(a, 0)) return b;
  if (is_number(b, 0)) return a;
  return intern(binary(Kind::add, a, b));
}

int Expressions::sub(int a, int b) {
  if (is_number(b, 0)) return a;
  if (is_number(a, 0)) return neg(b);
  return intern(binary(Kind::sub, a, b));
}

int Expressions::mul(int a, int b) {
  if (is_number(a, 0) || is_number(b, 0)) return number(0);
  if (is_number(a, 1)) return b;
  if (is_number(b, 1)) return a;
  if (is_number(a, -1)) return neg(b);
  if (is_number(b, -1)) return neg(a);
  return intern(binary(Kind::mul, a, b));
}

int Expressions::div(int a, int b) {
  if (is_number(b, 1)) return a;
  if (is_number(a, 0) && !is_number(b, 0)) return number(0);
  return intern(binary(Kind::div, a, b));
}

int Expressions::pow(int a, int b) {
  if (is_number(b, 1)) return a;
  if (is_number(b, 0)) return number(1);
  return intern(binary(Kind::pow, a, b));
}

int Expressions::call(Fn f, int a, int b) {
  Node n;
  n.kind = Kind::call;
  n.fn = f;
  n.a = a;
  n.b = fn_arity(f) == 2 ? b : -1;
  return intern(n);
}

int Expressions::derivative(int id, int slot) {
  const Node x = (*this)[id];  // a copy: interning below may grow the node table
  if (!(x.uses & vars_.bit(slot))) return number(0);
  const std::uint64_t key = (std::uint64_t(std::uint32_t(id)) << 8) | std::uint32_t(slot);
  const auto it = derivatives_.find(key);
  if (it != derivatives_.end()) return it->second;
  int d = -1;
  switch (x.kind) {
    case Kind::number:
    case Kind::param:
      d = number(0);
      break;
    case Kind::var:
      d = number(x.index == slot ? 1 : 0);
      break;
    case Kind::neg:
      d = neg(derivative(x.a, slot));
      break;
    case Kind::add:
      d = add(derivative(x.a, slot), derivative(x.b, slot));
      break;
    case Kind::sub:
      d = sub(derivative(x.a, slot), derivative(x.b, slot));
      break;
    case Kind::mul:
      d = add(mul(derivative(x.a, slot), x.b), mul(x.a, derivative(x.b, slot)));
      break;
    case Kind::div: {
      const int da = derivative(x.a, slot), db = derivative(x.b, slot);
      d = is_number(db, 0) ? div(da, x.b) : sub(div(da, x.b), div(mul(x.a, db), mul(x.b, x.b)));
      break;
    }
    case Kind::pow: {
      const int da = derivative(x.a, slot);
      if (is_constant(x.b)) {
        // (a^c)' = c a^(c-1) a'
        const Node& c = (*this)[x.b];
        const int c1 = c.kind == Kind::number ? number(c.value - 1) : sub(x.b, number(1));
        d = mul(mul(x.b, pow(x.a, c1)), da);
      } else {
        // (a^b)' = a^b (b' log a + b a'/a)
        const int db = derivative(x.b, slot);
        d = mul(id, add(mul(db, call(Fn::log, x.a)), div(mul(x.b, da), x.a)));
      }
      break;
    }
    case Kind::call: {
      const int da = derivative(x.a, slot);
      switch (x.fn) {
        case Fn::sin:
          d = mul(call(Fn::cos, x.a), da);
          break;
        case Fn::cos:
          d = neg(mul(call(Fn::sin, x.a), da));
          break;
        case Fn::tan: {
          const int t = id;
          d = mul(add(number(1), mul(t, t)), da);
          break;
        }
        case Fn::exp:
          d = mul(id, da);
          break;
        case Fn::log:
          d = div(da, x.a);
          break;
        case Fn::sqrt:
          d = div(da, mul(number(2), id));
          break;
        case Fn::atan2: {
          // atan2(y, x)' = (x y' - y x') / (x^2 + y^2)
          const int y = x.a, xx = x.b, dy = da, dx = derivative(x.b, slot);
          d = div(sub(mul(xx, dy), mul(y, dx)), add(mul(xx, xx), mul(y, y)));
          break;
        }
      }
      break;
    }
  }
  derivatives_.emplace(key, d);
  return d;
}

int Expressions::substitute(int id, const std::vector<int>& by) {
  std::uint32_t bits = 0;
  for (std::size_t s = 0; s < by.size(); ++s)
    if (by[s] >= 0) bits |= vars_.bit(static_cast<int>(s));
  std::unordered_map<int, int> memo;
  auto go = [&](auto&& self, int e) -> int {
    const Node x = (*this)[e];
    if (!(x.uses & bits)) return e;
    const auto it = memo.find(e);
    if (it != memo.end()) return it->second;
    int r = -1;
    switch (x.kind) {
      case Kind::number:
      case Kind::param:
        r = e;
        break;
      case Kind::var:
        r = by[static_cast<std::size_t>(x.index)];
        break;
      case Kind::neg:
        r = neg(self(self, x.a));
        break;
      case Kind::add:
        r = add(self(self, x.a), self(self, x.b));
        break;
      case Kind::sub:
        r = sub(self(self, x.a), self(self, x.b));
        break;
      case Kind::mul:
        r = mul(self(self, x.a), self(self, x.b));
        break;
      case Kind::div:
        r = div(self(self, x.a), self(self, x.b));
        break;
      case Kind::pow:
        r = pow(self(self, x.a), self(self, x.b));
        break;
      case Kind::call:
        r = call(x.fn, self(self, x.a), x.b >= 0 ? self(self, x.b) : -1);
        break;
    }
    memo.emplace(e, r);
    return r;
  };
  return go(go, id);
}

int Expressions::substitute_zero(int id, std::uint32_t bits) {
  if (!((*this)[id].uses & bits)) return id;
  const int zero = number(0);
  std::vector<int> by(32, -1);
  for (int s = 0; s < 32; ++s)
    if (bits & vars_.bit(s)) by[static_cast<std::size_t>(s)] = zero;
  return substitute(id, by);
}

double constant_value(const Expressions& ex, int id) {
  const Node& x = ex[id];
  auto a = [&] { return constant_value(ex, x.a); };
  auto b = [&] { return constant_value(ex, x.b); };
  switch (x.kind) {
    case Kind::number:
      return x.value;
    case Kind::param:
    case Kind::var:
      throw std::logic_error("constant_value: the expression is not constant");
    case Kind::neg:
      return -a();
    case Kind::add:
      return a() + b();
    case Kind::sub:
      return a() - b();
    case Kind::mul:
      return a() * b();
    case Kind::div:
      return a() / b();
    case Kind::pow:
      return std::pow(a(), b());
    case Kind::call:
      switch (x.fn) {
        case Fn::sin:
          return std::sin(a());
        case Fn::cos:
          return std::cos(a());
        case Fn::tan:
          return std::tan(a());
        case Fn::exp:
          return std::exp(a());
        case Fn::log:
          return std::log(a());
        case Fn::sqrt:
          return std::sqrt(a());
        case Fn::atan2:
          return std::atan2(a(), b());
      }
  }
  return 0;
}

}  // namespace geomint::formula
