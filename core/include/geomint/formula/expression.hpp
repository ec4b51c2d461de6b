#pragma once
// The formulas of one system as a single expression graph: every node is stored once (structurally equal
// subexpressions are shared, so a definition used in L and in a constraint is one node), built by the parser,
// differentiated symbolically where the system needs a derivative of a formula (the rows A = dPhi/dq' and the
// offset b = Phi(q' = 0) of a constraint written as Phi; A = dg/dq and b = dg/dt of a holonomic g), and compiled
// to flat tapes (tape.hpp) that every scalar type of the core evaluates.
//
// The constructors simplify only where the result is the same number for every finite operand (x + 0, x * 1,
// 0 * x, x / 1, -(-x), x^1): a formula a user writes is evaluated with exactly the operations written, in the
// order written, so a formula written like a system header gives the header's bits (tests/formula/formula_systems.test.cpp).
// No number is folded with another (2 * 3 stays a product, computed with the parameters in their own scalar
// type, tape.hpp): a symbolic parameter type keeps exact constants.
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

namespace geomint::formula {

enum class Kind : std::uint8_t { number, param, var, neg, add, sub, mul, div, pow, call };
enum class Fn : std::uint8_t { sin, cos, tan, exp, log, sqrt, atan2 };

const char* fn_name(Fn f);
int fn_arity(Fn f);
// The function called `name`, if the grammar has one.
bool find_fn(const std::string& name, Fn& f);

// The variables of a system with n coordinates, numbered as the tapes take them: t, q1..qn, v1..vn, z.
struct Variables {
  int n = 0;
  int count() const { return 2 * n + 2; }
  static int t() { return 0; }
  int q(int i) const { return 1 + i; }  // i = 0..n-1
  int v(int i) const { return 1 + n + i; }
  int z() const { return 2 * n + 1; }
  std::uint32_t bit(int slot) const { return std::uint32_t(1) << slot; }
  std::uint32_t q_bits() const { return ((std::uint32_t(1) << n) - 1) << 1; }
  std::uint32_t v_bits() const { return ((std::uint32_t(1) << n) - 1) << (1 + n); }
  std::string name(int slot) const;  // "t", "q2", "v1", "z"
  // "q1, v2" for the variables in `bits`.
  std::string names(std::uint32_t bits) const;
};

struct Node {
  Kind kind = Kind::number;
  Fn fn = Fn::sin;
  int a = -1, b = -1;         // operands (node ids); b: second operand of a binary node or of atan2
  int index = -1;             // number: its place in the number table; param: parameter number; var: slot
  double value = 0;           // number
  std::uint32_t uses = 0;     // the variables the node depends on (bit = slot)
  bool has_param = false;     // depends on a parameter (a parameter's default may not)
  int depth = 1;              // longest path to a leaf
};

class Expressions {
 public:
  static constexpr int max_coordinates = 15;  // variables fit the 32-bit `uses` masks
  // The deepest expression accepted (definitions nest formulas): the graph algorithms recurse this deep.
  static constexpr int max_depth = 4000;

  explicit Expressions(int n);
  const Variables& variables() const { return vars_; }
  const Node& operator[](int id) const { return nodes_[static_cast<std::size_t>(id)]; }
  int size() const { return static_cast<int>(nodes_.size()); }

  int number(double v, const std::string& text = "");
  int param(int index);
  int var(int slot);
  int neg(int a);
  int add(int a, int b);
  int sub(int a, int b);
  int mul(int a, int b);
  int div(int a, int b);
  int pow(int a, int b);
  int call(Fn f, int a, int b = -1);

  bool is_number(int id, double v) const;
  bool is_constant(int id) const { return (*this)[id].uses == 0; }  // numbers and parameters only

  // The literal numbers, in the order of their `index` (what a tape's parameter table starts with), with the
  // text they were written as ("0.5", "pi"; empty for numbers made by differentiation).
  const std::vector<double>& numbers() const { return numbers_; }
  const std::vector<std::string>& number_texts() const { return number_texts_; }

  // d(node)/d(variable slot), simplified as above.
  int derivative(int id, int slot);
  // The node with every variable in `bits` replaced by 0.
  int substitute_zero(int id, std::uint32_t bits);
  // The node with every variable slot s for which by[s] >= 0 replaced by the node by[s] (a time transformation
  // writes the physical velocity v_i as v_i / v_{n+1} and the time t as q_{n+1}).
  int substitute(int id, const std::vector<int>& by);

 private:
  struct Key {
    std::uint64_t head, operands, value;
    bool operator==(const Key& o) const { return head == o.head && operands == o.operands && value == o.value; }
  };
  struct KeyHash {
    std::size_t operator()(const Key& k) const;
  };
  int intern(const Node& n);

  Variables vars_;
  std::vector<Node> nodes_;
  std::unordered_map<Key, int, KeyHash> index_;
  std::vector<double> numbers_;
  std::vector<std::string> number_texts_;
  std::unordered_map<std::uint64_t, int> number_index_;  // bits of a value -> its place in numbers_
  std::unordered_map<std::uint64_t, int> derivatives_;  // (node, slot) -> node
};

// The value of a node that depends on numbers only (a parameter's default), in double.
double constant_value(const Expressions& ex, int id);

}  // namespace geomint::formula
