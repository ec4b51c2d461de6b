#include "geomint/formula/parser.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>

namespace geomint::formula {

namespace {

bool name_start(char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_'; }
bool name_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

std::string describe(char c) {
  const auto u = static_cast<unsigned char>(c);
  if (u >= 0x20 && u < 0x7f) return std::string("'") + c + "'";
  char buf[16];
  std::snprintf(buf, sizeof buf, "byte 0x%02x", u);
  return buf;
}

class Parser {
 public:
  Parser(Expressions& ex, const std::string& text, const Resolver& resolve) : ex_(ex), s_(text), resolve_(resolve) {}

  int parse() {
    if (s_.size() > max_formula_length)
      throw ParseError(1, "formula longer than " + std::to_string(max_formula_length) + " characters");
    skip();
    if (at_end()) throw ParseError(1, "empty formula");
    const int root = formula();
    skip();
    if (!at_end()) {
      if (peek() == ')') throw ParseError(col(), "unbalanced ')'");
      throw ParseError(col(), "unexpected " + describe(peek()) + " after a complete formula" + missing_operator_hint());
    }
    return root;
  }

 private:
  bool at_end() const { return i_ >= s_.size(); }
  char peek() const { return at_end() ? '\0' : s_[i_]; }
  int col() const { return static_cast<int>(i_) + 1; }
  void skip() {
    while (!at_end() && (s_[i_] == ' ' || s_[i_] == '\t')) ++i_;
  }
  std::string missing_operator_hint() const {
    const char c = peek();
    if (name_start(c) || std::isdigit(static_cast<unsigned char>(c)) || c == '(' || c == '.')
      return " (missing operator? products are written with '*')";
    return "";
  }

  struct Depth {
    Parser& p;
    explicit Depth(Parser& p_) : p(p_) {
      if (++p.depth_ > max_formula_depth)
        throw ParseError(p.col(), "formula nested more than " + std::to_string(max_formula_depth) + " levels deep");
    }
    ~Depth() { --p.depth_; }
  };

  // The depth is counted in unary() alone: every level of nesting (a parenthesis, a function's argument, an
  // exponent, a sign) passes through it once, so max_formula_depth is the number of levels a user can write.
  int formula() {
    int left = term();
    for (;;) {
      skip();
      const char c = peek();
      if (c != '+' && c != '-') return left;
      ++i_;
      const int right = term();
      left = c == '+' ? ex_.add(left, right) : ex_.sub(left, right);
    }
  }

  int term() {
    int left = unary();
    for (;;) {
      skip();
      const char c = peek();
      if (c == '*' && !(i_ + 1 < s_.size() && s_[i_ + 1] == '*')) {
        ++i_;
        left = ex_.mul(left, unary());
      } else if (c == '/') {
        ++i_;
        left = ex_.div(left, unary());
      } else {
        return left;
      }
    }
  }

  int unary() {
    Depth guard(*this);
    skip();
    if (peek() == '-') {
      ++i_;
      return ex_.neg(unary());
    }
    if (peek() == '+') {
      ++i_;
      return unary();
    }
    return power();
  }

  int power() {
    const int base = primary();
    skip();
    if (peek() == '^') {
      ++i_;
      return ex_.pow(base, unary());
    }
    if (peek() == '*' && i_ + 1 < s_.size() && s_[i_ + 1] == '*') {
      i_ += 2;
      return ex_.pow(base, unary());
    }
    return base;
  }

  int primary() {
    skip();
    if (at_end()) throw ParseError(col(), "formula ends where a number, a name or '(' was expected");
    const char c = peek();
    const int start = col();
    if (c == '(') {
      ++i_;
      const int e = formula();
      skip();
      if (peek() != ')') {
        if (at_end()) throw ParseError(start, "'(' is never closed");
        throw ParseError(col(), "expected ')' to close the '(' at column " + std::to_string(start) + ", found " +
                                    describe(peek()) + missing_operator_hint());
      }
      ++i_;
      return e;
    }
    if (std::isdigit(static_cast<unsigned char>(c)) || c == '.') return number();
    if (name_start(c)) return name();
    if (c == ')') throw ParseError(col(), "unexpected ')' where a number, a name or '(' was expected");
    if (c == '*' || c == '/' || c == '^' || c == ',')
      throw ParseError(col(), "unexpected " + describe(c) + " where a number, a name or '(' was expected");
    throw ParseError(col(), "unexpected character " + describe(c));
  }

  int number() {
    const int start = col();
    std::size_t j = i_;
    while (j < s_.size() && (std::isdigit(static_cast<unsigned char>(s_[j])) || s_[j] == '.')) ++j;
    if (j < s_.size() && (s_[j] == 'e' || s_[j] == 'E')) {
      std::size_t k = j + 1;
      if (k < s_.size() && (s_[k] == '+' || s_[k] == '-')) ++k;
      if (k < s_.size() && std::isdigit(static_cast<unsigned char>(s_[k]))) {
        j = k;
        while (j < s_.size() && std::isdigit(static_cast<unsigned char>(s_[j]))) ++j;
      }
    }
    const std::string text = s_.substr(i_, j - i_);
    double v = 0;
    const auto r = std::from_chars(text.data(), text.data() + text.size(), v, std::chars_format::general);
    if (r.ec == std::errc::result_out_of_range || (r.ec == std::errc() && !std::isfinite(v)))
      throw ParseError(start, "number '" + text + "' is out of range");
    if (r.ec != std::errc() || r.ptr != text.data() + text.size())
      throw ParseError(start, "malformed number '" + text + "'");
    i_ = j;
    return ex_.number(v, text);
  }

  int name() {
    const int start = col();
    std::size_t j = i_;
    while (j < s_.size() && name_char(s_[j])) ++j;
    const std::string id = s_.substr(i_, j - i_);
    i_ = j;
    std::size_t k = i_;
    while (k < s_.size() && (s_[k] == ' ' || s_[k] == '\t')) ++k;
    Fn f;
    const bool is_fn = find_fn(id, f);
    if (k < s_.size() && s_[k] == '(') {
      if (!is_fn)
        throw ParseError(start, "unknown function '" + id +
                                    "' (functions: sin cos tan exp log sqrt atan2; a product is written with '*')");
      i_ = k + 1;
      const int a = formula();
      skip();
      int b = -1;
      if (peek() == ',') {
        if (fn_arity(f) != 2) throw ParseError(col(), std::string(fn_name(f)) + " takes one argument");
        ++i_;
        b = formula();
        skip();
      } else if (fn_arity(f) == 2) {
        throw ParseError(col(), std::string(fn_name(f)) + " takes two arguments: " + fn_name(f) + "(y, x)");
      }
      if (peek() != ')') {
        if (at_end()) throw ParseError(start, std::string(fn_name(f)) + "( is never closed");
        throw ParseError(col(), "expected ')' to close " + std::string(fn_name(f)) + "( at column " + std::to_string(start) +
                                    ", found " + describe(peek()) + missing_operator_hint());
      }
      ++i_;
      return ex_.call(f, a, b);
    }
    if (is_fn) throw ParseError(start, "'" + id + "' is a function: write " + id + "(...)");
    return resolve_(id, start);
  }

  Expressions& ex_;
  const std::string& s_;
  const Resolver& resolve_;
  std::size_t i_ = 0;
  int depth_ = -1;  // the formula itself is level 0, each nesting one more
};

}  // namespace

int parse_formula(Expressions& ex, const std::string& text, const Resolver& resolve) {
  return Parser(ex, text, resolve).parse();
}

}  // namespace geomint::formula
