#pragma once
// FormulaSystemT<n, m, holonomic, P>: a system defined by its formulas (model.hpp), in the shape the generic core
// takes (generic/system.hpp): every scheme, the stepper, the continuous equations and the automatic modified
// equations run it unchanged, in every scalar type they use. P is the type of the parameter values: double,
// or a symbolic type (then the parameters are symbols, and every derived value and every evaluation is symbolic).
//
// The core needs n and m at compile time (fixed-size Eigen types: no allocation in a step), so a formula system is
// one type per shape: n = 1..12 coordinates, m = 0..min(6, n - 1) rows, the rows linear in the velocities or
// holonomic. The registry compiles the shapes core/src/formula/shapes.def lists (every one up to n = 4, m = 2, and
// more on a line each); with_formula_system() picks, at run time, among those up to n = 4, m = 2, for the code that
// needs a model's type (tests).
//
// Compared with a system header, every member is present: a model without a Herglotz Lagrangian throws
// InputError from herglotz() (the contact schemes need one: has_herglotz() says, at run time, whether it has
// one); without a force, force() is zero; without an energy, energy() is the Lagrangian energy q'.L_q' - L. A
// holonomic system's A and b are dg/dq and dg/dt, derived from g symbolically.
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "geomint/error.hpp"
#include "geomint/formula/checks.hpp"
#include "geomint/formula/model.hpp"
#include "geomint/generic/system.hpp"

namespace geomint::formula {

// A number of the formulas (its value, and its text as written: "0.1", "pi"; empty where differentiation made it)
// in the parameter type: P(x). A symbolic type specializes it to keep the number exact (modified/symbolic.hpp's
// users: 1/10, not the double nearest 0.1).
template <class P>
struct FormulaConstant {
  static P from(double x, const std::string&) { return P(x); }
};

template <int N, int M = 0, bool Holonomic = false, class P = double>
class FormulaSystemT {
  static_assert(supported_shape(N, M), "formula systems have 1..12 coordinates and 0..min(6, n - 1) constraint rows");
  static_assert(M > 0 || !Holonomic, "a holonomic formula system has at least one constraint row");

 public:
  static constexpr int dof = N;
  static constexpr int constraints = M;
  static constexpr bool is_holonomic = Holonomic;
  using Param = P;

  // The model's defaults as the parameter values.
  explicit FormulaSystemT(std::shared_ptr<const FormulaModel> model) : model_(std::move(model)) {
    check_shape();
    pv_.reserve(static_cast<std::size_t>(model_->table_size()));
    add_numbers();
    for (const auto& p : model_->parameters) pv_.push_back(P(p.value));
    refresh();
  }
  // Given parameter values, one per model parameter in its order (a symbolic P: the parameters' symbols).
  FormulaSystemT(std::shared_ptr<const FormulaModel> model, const std::vector<P>& parameters) : model_(std::move(model)) {
    check_shape();
    require(parameters.size() == model_->parameters.size(),
            "system '" + model_->name + "' has " + std::to_string(model_->parameters.size()) + " parameters (" +
                model_->parameter_names() + "), got " + std::to_string(parameters.size()) + " values");
    add_numbers();
    for (const P& p : parameters) pv_.push_back(p);
    refresh();
  }

  const FormulaModel& model() const { return *model_; }
  const std::shared_ptr<const FormulaModel>& model_ptr() const { return model_; }
  const std::string& name() const { return model_->name; }
  const std::string& description() const { return model_->description; }
  bool has_herglotz() const { return model_->has_herglotz(); }
  bool linear_dynamics_found() const { return model_->linear_dynamics; }

  // The parameters by name, as a header system's fields (v(name, value, doc)); the derived values follow.
  template <class V>
  void visit(V&& v) {
    const int o = model_->parameter_offset();
    for (std::size_t i = 0; i < model_->parameters.size(); ++i)
      v(model_->parameters[i].name.c_str(), pv_[static_cast<std::size_t>(o) + i], model_->parameters[i].doc.c_str());
    refresh();
  }
  void set_parameter(const std::string& pname, const P& value) {
    pv_[static_cast<std::size_t>(model_->parameter_offset() + index_of(pname))] = value;
    refresh();
  }
  const P& parameter(const std::string& pname) const {
    return pv_[static_cast<std::size_t>(model_->parameter_offset() + index_of(pname))];
  }
  P horizon() const { return parameter("T"); }
  // The tapes' parameter table (numbers | parameters | derived values, FormulaModel): what checks.hpp takes.
  const std::vector<P>& parameter_table() const { return pv_; }

  // Input errors that depend on the parameter values, each naming its place: a non-finite parameter, derived
  // value or initial datum; T <= 0; an initial position off a holonomic constraint; constraint rows that are
  // dependent at the initial position; a Lagrangian (or Herglotz Lagrangian) whose velocity Hessian is singular
  // at the initial data; and, when the model asks for it (strict_herglotz), a Herglotz form inconsistent with
  // the force. Checks what it can compute: nothing for a symbolic P.
  void validate() const;
  // The Herglotz form checked against the force (when not strict): empty, or one message.
  std::vector<std::string> warnings() const;

  // ---------------------------------------------------------------------------------------------------
  // The system, for the generic core (generic/system.hpp)

  template <class S>
  S lagrangian(const S& t, const Vec<S, N>& q, const Vec<S, N>& v) const {
    S r;
    run(model_->lagrangian, t, q.data(), v.data(), nullptr, &r);
    return r;
  }
  template <class S>
  S herglotz(const S& t, const Vec<S, N>& q, const Vec<S, N>& v, const S& z) const {
    if (!model_->has_herglotz())
      throw InputError("system '" + model_->name +
                       "' has no Herglotz Lagrangian (herglotz = ... in [dynamics]): the contact schemes need one");
    S r;
    run(model_->herglotz, t, q.data(), v.data(), &z, &r);
    return r;
  }
  template <class S>
  Vec<S, N> force(const S& t, const Vec<S, N>& q, const Vec<S, N>& v) const {
    Vec<S, N> f;
    if (model_->has_force())
      run(model_->force, t, q.data(), v.data(), nullptr, f.data());
    else
      f.setZero();
    return f;
  }
  template <class S>
  Mat<S, M, N> constraint_matrix(const S& t, const Vec<S, N>& q) const {
    Mat<S, M, N> A;
    if constexpr (M > 0) run(model_->constraint_matrix, t, q.data(), nullptr, nullptr, A.data());
    return A;
  }
  template <class S>
  Vec<S, M> constraint_offset(const S& t, const Vec<S, N>& q) const {
    Vec<S, M> b;
    if constexpr (M > 0) run(model_->constraint_offset, t, q.data(), nullptr, nullptr, b.data());
    return b;
  }
  // Present only for a holonomic shape: the schemes then impose g(t_{j+1}, q_{j+1}) = 0.
  template <class S, bool H = Holonomic, std::enable_if_t<H, int> = 0>
  Vec<S, M> holonomic(const S& t, const Vec<S, N>& q) const {
    Vec<S, M> g;
    run(model_->holonomic_g, t, q.data(), nullptr, nullptr, g.data());
    return g;
  }
  template <class S>
  S energy(const S& t, const Vec<S, N>& q, const Vec<S, N>& v) const {
    if (model_->has_energy()) {
      S r;
      run(model_->energy, t, q.data(), v.data(), nullptr, &r);
      return r;
    }
    // the default of generic::energy, written the same way
    return generic::momentum(*this, t, q, v).dot(v) - lagrangian(t, q, v);
  }
  template <class S>
  Vec<S, N> initial_position() const {
    return initial<S>().template head<N>();
  }
  template <class S>
  Vec<S, N> initial_velocity() const {
    return initial<S>().template tail<N>();
  }
  // t0 and z0 ([initial] t0 = ..., z0 = ...; 0 where not given): every run starts at t0 with z(t0) = z0.
  template <class S>
  S initial_time() const {
    return start<S>()(0);
  }
  template <class S>
  S initial_action() const {
    return start<S>()(1);
  }
  // The exact solution of [exact] (q as formulas in t, q' given or derived from them), at the absolute time t.
  bool has_exact_solution() const { return model_->has_exact(); }
  template <class S>
  Phase<S, N> exact(const S& t) const {
    if (!model_->has_exact())
      throw InputError("system '" + model_->name + "' has no exact solution ([exact] q1 = ... in its file)");
    const Vec<S, N> none = Vec<S, N>::Zero();
    Vec<S, 3 * N> x;  // q, q', q'' (the second derivative for the check of the solution against the equations)
    run(model_->exact, t, none.data(), none.data(), nullptr, x.data());
    return Phase<S, N>{x.template head<N>(), x.template segment<N>(N)};
  }

 private:
  void check_shape() const {
    require(model_ != nullptr, "formula system without a model");
    require(model_->n == N && model_->m == M && (M == 0 || model_->holonomic == Holonomic),
            "system '" + model_->name + "' has n = " + std::to_string(model_->n) + ", m = " + std::to_string(model_->m) +
                (model_->holonomic ? " (holonomic)" : "") + ", not the shape of this instantiation (n = " + std::to_string(N) +
                ", m = " + std::to_string(M) + (Holonomic ? ", holonomic" : "") + ")");
  }
  void add_numbers() {
    for (std::size_t i = 0; i < model_->numbers.size(); ++i)
      pv_.push_back(FormulaConstant<P>::from(model_->numbers[i], i < model_->number_texts.size() ? model_->number_texts[i] : std::string()));
  }
  int index_of(const std::string& pname) const {
    const int i = model_->parameter_index(pname);
    require(i >= 0, "system '" + model_->name + "' has no parameter '" + pname + "' (known: " + model_->parameter_names() + ")");
    return i;
  }

  // The derived values from the parameters (the prelude, in P).
  void refresh() {
    const int k = model_->derived_offset();
    pv_.resize(static_cast<std::size_t>(model_->table_size()));
    std::vector<const P*> in(static_cast<std::size_t>(k));
    for (int i = 0; i < k; ++i) in[static_cast<std::size_t>(i)] = &pv_[static_cast<std::size_t>(i)];
    model_->prelude.evaluate(in.data(), pv_.data(), pv_.data() + k);
  }

  template <class S>
  struct Same {
    using type = S;
  };
  // z and v may be null (a tape that does not read them): not deduced from them.
  template <class S>
  void run(const Tape& tape, const S& t, const S* q, const typename Same<S>::type* v, const typename Same<S>::type* z,
           S* out) const {
    std::array<const S*, 2 * N + 2> in;
    in[0] = &t;
    for (int i = 0; i < N; ++i) {
      in[static_cast<std::size_t>(1 + i)] = q + i;
      in[static_cast<std::size_t>(1 + N + i)] = v ? v + i : nullptr;
    }
    in[2 * N + 1] = z;
    tape.evaluate(in.data(), pv_.data(), out);
  }

  // (q(0), q'(0)) in S, from the numbers and parameters in S.
  template <class S>
  Vec<S, 2 * N> initial() const {
    return constants<S, 2 * N>(model_->initial);
  }

  // (t0, z0) in S.
  template <class S>
  Vec<S, 2> start() const {
    return constants<S, 2>(model_->start);
  }

  // The K outputs of a tape that reads only the numbers and parameters (no point of the motion), in S.
  template <class S, int K>
  Vec<S, K> constants(const Tape& tape) const {
    const int k = model_->derived_offset();
    std::vector<S> values;
    values.reserve(static_cast<std::size_t>(k));
    for (int i = 0; i < k; ++i) values.push_back(S(pv_[static_cast<std::size_t>(i)]));
    std::vector<const S*> in(static_cast<std::size_t>(k));
    for (int i = 0; i < k; ++i) in[static_cast<std::size_t>(i)] = &values[static_cast<std::size_t>(i)];
    Vec<S, K> x;
    tape.evaluate(in.data(), pv_.data(), x.data());
    return x;
  }

  std::shared_ptr<const FormulaModel> model_;
  std::vector<P> pv_;  // numbers | parameters | derived values (FormulaModel)
};

template <int N, int M = 0, bool Holonomic = false>
using FormulaSystem = FormulaSystemT<N, M, Holonomic, double>;

// ---------------------------------------------------------------------------------------------------
// Checks: on the model at run-time dimensions (checks.hpp), compiled once for every shape

template <int N, int M, bool H, class P>
void FormulaSystemT<N, M, H, P>::validate() const {
  if constexpr (std::is_same_v<P, double>) validate_model(*model_, pv_);
}

template <int N, int M, bool H, class P>
std::vector<std::string> FormulaSystemT<N, M, H, P>::warnings() const {
  if constexpr (std::is_same_v<P, double>) {
    if (!model_->strict_herglotz) {
      std::string why = herglotz_mismatch(*model_, pv_);
      if (!why.empty()) return {std::move(why)};
    }
  }
  return {};
}

// ---------------------------------------------------------------------------------------------------
// The shape of a model at run time

// Calls f(FormulaSystemT<n, m, holonomic, P>(model)) for the model's shape. Every supported shape is compiled
// for f: use it where f is the one place a formula system enters typed code (a registry entry), not in loops.
template <class P = double, class F>
decltype(auto) with_formula_system(const std::shared_ptr<const FormulaModel>& model, F&& f) {
  require(model != nullptr, "formula system without a model");
  const int n = model->n, m = model->m;
  const bool h = model->holonomic;
#define GEOMINT_FORMULA_SHAPE(N_, M_, H_) \
  if (n == N_ && m == M_ && h == H_) return f(FormulaSystemT<N_, M_, H_, P>(model));
  GEOMINT_FORMULA_SHAPE(1, 0, false)
  GEOMINT_FORMULA_SHAPE(2, 0, false)
  GEOMINT_FORMULA_SHAPE(2, 1, false)
  GEOMINT_FORMULA_SHAPE(2, 1, true)
  GEOMINT_FORMULA_SHAPE(3, 0, false)
  GEOMINT_FORMULA_SHAPE(3, 1, false)
  GEOMINT_FORMULA_SHAPE(3, 1, true)
  GEOMINT_FORMULA_SHAPE(3, 2, false)
  GEOMINT_FORMULA_SHAPE(3, 2, true)
  GEOMINT_FORMULA_SHAPE(4, 0, false)
  GEOMINT_FORMULA_SHAPE(4, 1, false)
  GEOMINT_FORMULA_SHAPE(4, 1, true)
  GEOMINT_FORMULA_SHAPE(4, 2, false)
  GEOMINT_FORMULA_SHAPE(4, 2, true)
#undef GEOMINT_FORMULA_SHAPE
  throw InputError("system '" + model->name + "': with_formula_system takes the shapes up to n = 4, m = 2, not n = " +
                   std::to_string(n) + ", m = " + std::to_string(m) + " (a registry entry takes every compiled shape)");
}

}  // namespace geomint::formula
