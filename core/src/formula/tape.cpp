#include "geomint/formula/tape.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <unordered_map>

#include "geomint/error.hpp"

namespace geomint::formula {

int ConstantTable::index_of(const Expressions& ex, int node) {
  const Node& x = ex[node];
  if (x.kind == Kind::number) return x.index;
  if (x.kind == Kind::param) return numbers_ + x.index;
  for (const auto& [n, i] : index_)
    if (n == node) return i;
  const int i = size();
  derived_.push_back(node);
  index_.emplace_back(node, i);
  return i;
}

namespace {

constexpr int max_slots = std::numeric_limits<std::uint16_t>::max();

// What the compiler sees of a node: an input slot, a parameter value (state tapes), or a value it computes.
enum class Role { input, param, computed };

class Compiler {
 public:
  // A state tape (inputs: the variables; constants from `constants`), or a constant tape (inputs: `numbers`
  // numbers, then the parameters).
  Compiler(const Expressions& ex, bool state, int inputs, ConstantTable* constants, int numbers)
      : ex_(ex), state_(state), inputs_(inputs), numbers_(numbers), constants_(constants) {}

  Tape run(const std::vector<int>& roots) {
    for (int r : roots) visit(r);
    const int count = static_cast<int>(order_.size());
    // how often each computed value is read (by the nodes that use it, and as an output)
    std::unordered_map<int, int> uses;
    for (int id : order_)
      for (int c : {ex_[id].a, ex_[id].b})
        if (c >= 0 && role(c) == Role::computed) ++uses[c];
    for (int r : roots)
      if (role(r) == Role::computed) ++uses[r];
    // the emitted units: a node alone, or a node fused into the next one (tape.hpp), which then reads its operands
    struct Unit {
      int id, inner = -1;
      Op fused = Op::add;
    };
    std::vector<Unit> units;
    for (int i = 0; i < count; ++i) {
      const int id = order_[static_cast<std::size_t>(i)];
      Op op;
      if (i + 1 < count && uses[id] == 1 && fusion(id, order_[static_cast<std::size_t>(i + 1)], op)) {
        units.push_back({order_[static_cast<std::size_t>(i + 1)], id, op});
        ++i;
      } else {
        units.push_back({id});
      }
    }
    // the computed values each unit reads, and the last unit that reads each (outputs live to the end)
    auto reads = [&](const Unit& u) {
      std::vector<int> r;
      const Node& x = ex_[u.id];
      for (int c : {x.a, x.b})
        if (c >= 0 && c != u.inner && role(c) == Role::computed) r.push_back(c);
      if (u.inner >= 0)
        for (int c : {ex_[u.inner].a, ex_[u.inner].b})
          if (c >= 0 && role(c) == Role::computed) r.push_back(c);
      std::sort(r.begin(), r.end());
      r.erase(std::unique(r.begin(), r.end()), r.end());
      return r;
    };
    const int end = static_cast<int>(units.size());
    std::unordered_map<int, int> last;
    for (int i = 0; i < end; ++i)
      for (int c : reads(units[static_cast<std::size_t>(i)])) last[c] = i;
    for (int r : roots)
      if (role(r) == Role::computed) last[r] = end;

    Tape tape;
    tape.inputs = inputs_;
    std::vector<std::uint16_t> free;
    int registers = 0;
    for (int i = 0; i < end; ++i) {
      const Unit& u = units[static_cast<std::size_t>(i)];
      // the destination is taken before the operands are released: an instruction never writes a register it
      // reads (the scalar types compute their result in place)
      std::uint16_t dst;
      if (!free.empty()) {
        dst = free.back();
        free.pop_back();
      } else {
        if (registers + inputs_ >= max_slots) throw InputError("formula too large for a tape (more than 65535 values)");
        dst = static_cast<std::uint16_t>(registers++);
      }
      tape.code.push_back(u.inner >= 0 ? fused_instruction(u.inner, u.id, u.fused, dst) : instruction(ex_[u.id], dst));
      reg_[u.id] = dst;
      for (int c : reads(u))
        if (last[c] == i) free.push_back(reg_[c]);
    }
    tape.registers = registers;
    for (int r : roots) tape.outputs.push_back(output(r));
    return tape;
  }

 private:
  Role role(int id) const {
    const Node& x = ex_[id];
    if (state_) {
      if (x.kind == Kind::var) return Role::input;
      if (x.uses == 0) return Role::param;
      return Role::computed;
    }
    if (x.kind == Kind::var) throw std::logic_error("constant tape: a variable in a constant expression");
    if (x.kind == Kind::number || x.kind == Kind::param) return Role::input;
    return Role::computed;
  }

  // The slot of an input or computed operand.
  std::uint16_t slot(int id) const {
    const Node& x = ex_[id];
    if (role(id) == Role::input) {
      if (state_) return static_cast<std::uint16_t>(x.index);
      return static_cast<std::uint16_t>(x.kind == Kind::number ? x.index : numbers_ + x.index);
    }
    return static_cast<std::uint16_t>(inputs_ + reg_.at(id));
  }
  std::uint16_t pv(int id) {
    const int i = constants_->index_of(ex_, id);
    if (i >= max_slots) throw InputError("formula too large for a tape (more than 65535 constants)");
    return static_cast<std::uint16_t>(i);
  }

  void visit(int id) {
    if (role(id) != Role::computed || seen_.count(id)) return;
    seen_[id] = true;
    const Node& x = ex_[id];
    if (x.a >= 0) visit(x.a);
    if (x.b >= 0) visit(x.b);
    order_.push_back(id);
  }

  static bool small_integer(const Node& n, int& k) {
    if (n.kind != Kind::number || !(std::abs(n.value) <= 64) || n.value != std::floor(n.value)) return false;
    k = static_cast<int>(n.value);
    return true;
  }

  Instr instruction(const Node& x, std::uint16_t dst) {
    Instr in{Op::add, dst, 0, 0, 0};
    const bool pa = x.a >= 0 && role(x.a) == Role::param, pb = x.b >= 0 && role(x.b) == Role::param;
    auto mixed = [&](Op with_b, Op with_a, bool commutes) {
      if (pb) {
        in.op = with_b;
        in.a = slot(x.a);
        in.b = pv(x.b);
      } else {
        in.op = commutes ? with_b : with_a;
        in.a = slot(x.b);
        in.b = pv(x.a);
      }
    };
    switch (x.kind) {
      case Kind::neg:
        in.op = Op::neg;
        in.a = slot(x.a);
        return in;
      case Kind::add:
      case Kind::sub:
      case Kind::mul:
      case Kind::div: {
        static constexpr Op plain[] = {Op::add, Op::sub, Op::mul, Op::div};
        static constexpr Op with_b[] = {Op::add_p, Op::sub_p, Op::mul_p, Op::div_p};
        static constexpr Op with_a[] = {Op::add_p, Op::rsub_p, Op::mul_p, Op::rdiv_p};
        const int k = x.kind == Kind::add ? 0 : x.kind == Kind::sub ? 1 : x.kind == Kind::mul ? 2 : 3;
        if (pa || pb) {
          mixed(with_b[k], with_a[k], k == 0 || k == 2);
        } else {
          in.op = plain[k];
          in.a = slot(x.a);
          in.b = slot(x.b);
        }
        return in;
      }
      case Kind::pow: {
        int k = 0;
        if (small_integer(ex_[x.b], k)) {
          in.op = Op::pow_int;
          in.a = slot(x.a);
          in.b = static_cast<std::uint16_t>(static_cast<std::int16_t>(k));
        } else if (pa || pb) {
          mixed(Op::pow_p, Op::rpow_p, false);
        } else {
          in.op = Op::pow;
          in.a = slot(x.a);
          in.b = slot(x.b);
        }
        return in;
      }
      case Kind::call: {
        static constexpr Op ops[] = {Op::sin, Op::cos, Op::tan, Op::exp, Op::log, Op::sqrt, Op::atan2};
        in.op = ops[static_cast<int>(x.fn)];
        if (x.fn == Fn::atan2) {
          if (pa || pb) throw std::logic_error("compile_state_tape: atan2 of a variable with a constant");
          in.b = slot(x.b);
        }
        in.a = slot(x.a);
        return in;
      }
      default:
        throw std::logic_error("tape compiler: a leaf reached the instruction selection");
    }
  }

  // A product (of two values, or of a value and a constant) whose only use is the next node fuses with it when
  // the pair is one of the fused instructions (tape.hpp).
  bool plain_product(int id) const {
    const Node& x = ex_[id];
    return x.kind == Kind::mul && role(x.a) != Role::param && role(x.b) != Role::param;
  }
  bool mixed_product(int id) const {
    const Node& x = ex_[id];
    return x.kind == Kind::mul && (role(x.a) == Role::param) != (role(x.b) == Role::param);
  }
  bool fusion(int inner, int outer, Op& op) const {
    if (!state_) return false;  // constant tapes are evaluated once per parameter set
    const Node& y = ex_[outer];
    // only the four arithmetic operations fuse; a unary node has no second operand to read (its b is -1)
    if (y.kind != Kind::add && y.kind != Kind::sub && y.kind != Kind::mul && y.kind != Kind::div) return false;
    const bool plain = plain_product(inner), mixed = mixed_product(inner);
    if (!plain && !mixed) return false;
    if (y.a == y.b) return false;
    const bool first = y.a == inner;  // the product is the outer node's first operand
    if (!first && y.b != inner) return false;
    const int other = first ? y.b : y.a;
    if (y.kind == Kind::div && plain && first && role(other) == Role::param) {
      op = Op::mul_divp;
      return true;
    }
    if (role(other) == Role::param) return false;
    switch (y.kind) {
      case Kind::add:
        op = plain ? Op::add_mul : Op::add_mulp;
        return true;
      case Kind::sub:
        op = first ? (plain ? Op::mul_sub : Op::mulp_sub) : (plain ? Op::sub_mul : Op::sub_mulp);
        return true;
      case Kind::mul:
        if (!mixed) return false;
        op = first ? Op::mulp_mul : Op::mul_mulp;
        return true;
      default:
        return false;
    }
  }
  Instr fused_instruction(int inner, int outer, Op op, std::uint16_t dst) {
    const Node& p = ex_[inner];
    const Node& y = ex_[outer];
    Instr in{op, dst, 0, 0, 0};
    if (plain_product(inner)) {
      in.b = slot(p.a);
      in.c = slot(p.b);
    } else {  // x * c or c * x: the value, then the constant (a product with a constant commutes bit for bit)
      const bool const_first = role(p.a) == Role::param;
      in.b = slot(const_first ? p.b : p.a);
      in.c = pv(const_first ? p.a : p.b);
    }
    const int other = y.a == inner ? y.b : y.a;
    in.a = op == Op::mul_divp ? pv(other) : slot(other);
    return in;
  }

  TapeOutput output(int id) {
    TapeOutput o;
    switch (role(id)) {
      case Role::param:
        if (ex_.is_number(id, 0)) {
          o.kind = TapeOutput::zero;
        } else {
          o.kind = TapeOutput::param;
          o.index = pv(id);
        }
        break;
      case Role::input:
      case Role::computed:
        o.kind = TapeOutput::slot;
        o.index = slot(id);
        break;
    }
    return o;
  }

 private:
  const Expressions& ex_;
  bool state_;
  int inputs_, numbers_;
  ConstantTable* constants_;
  std::unordered_map<int, bool> seen_;
  std::vector<int> order_;
  std::unordered_map<int, std::uint16_t> reg_;
};

}  // namespace

Tape compile_state_tape(const Expressions& ex, const std::vector<int>& roots, ConstantTable& constants) {
  return Compiler(ex, true, ex.variables().count(), &constants, constants.numbers()).run(roots);
}

Tape compile_constant_tape(const Expressions& ex, const std::vector<int>& roots, int numbers, int parameters) {
  return Compiler(ex, false, numbers + parameters, nullptr, numbers).run(roots);
}

}  // namespace geomint::formula
