#pragma once
// The formula grammar, parsed by hand into the expression graph (expression.hpp):
//   formula := term (('+' | '-') term)*
//   term    := unary (('*' | '/') unary)*
//   unary   := ('-' | '+') unary | power            -a^2 = -(a^2), -a*b = (-a)*b, 2^-1 = 1/2
//   power   := primary (('^' | '**') unary)?       right-associative: a^b^c = a^(b^c)
//   primary := number | name | name '(' formula [',' formula] ')' | '(' formula ')'
// Numbers are decimal (1, 0.5, .5, 7.2921e-5), read with std::from_chars (independent of the locale). A name is
// resolved by the caller (the parameters, definitions and variables of the system); a name followed by '(' is
// one of the functions sin cos tan exp log sqrt atan2.
//
// Why a hand-written recursive-descent parser: the grammar is five precedence levels, and every error must name
// its column in the user's words; Boost.Spirit would add a heavy template library to the build for the same
// grammar and make those messages harder, and an expression library (muparser, exprtk) evaluates in double only,
// where the core needs its own scalar types (tape.hpp). Nothing in a formula is executed or handed to another
// program: the text becomes graph nodes, and only the tape interpreter evaluates them.
#include <functional>
#include <stdexcept>
#include <string>

#include "geomint/formula/expression.hpp"

namespace geomint::formula {

// A parse error at a column of the formula (1-based, counted in bytes).
struct ParseError : std::runtime_error {
  int column;
  ParseError(int column_, const std::string& what) : std::runtime_error(what), column(column_) {}
};

// Maps a name at `column` to a node of the graph; throws ParseError for a name it does not know.
using Resolver = std::function<int(const std::string& name, int column)>;

// Limits that keep a hostile or mistaken input from exhausting memory or the stack.
inline constexpr std::size_t max_formula_length = 20000;
inline constexpr int max_formula_depth = 200;

// Parses `text` into `ex` and returns the root node.
int parse_formula(Expressions& ex, const std::string& text, const Resolver& resolve);

}  // namespace geomint::formula
