#pragma once
// A composition is a scheme given by its one-step map: a symmetric scheme of the generic core (la-midpoint,
// la-trapezoid, contact-trapezoid, with or without constraints) composed with a coefficient family
// (composition_families.hpp). One step t_j -> t_j + h is s stages,
//   stage i: the base scheme's step of size w_i h from t_j + c_i h,   c_i = w_1 + ... + w_{i-1},
// each in position–momentum form (q, p, [z]) -> (q', p', [z']), so a stage is exactly the base scheme's step and
// the composition inherits its structure (variational, contact, constrained).
//
// Negative stage steps (every family of order > 2 has some) are the base scheme's equations with h < 0: the
// residuals of schemes.hpp divide by h and never assume its sign, and contact's factor (1 + D3 𝓛) =
// 1 - (h/2) dL/dz stays away from zero for |w_i h| dL/dz < 2, as it must for h > 0.
//
// Constrained bases. The LA and contact rows apply the constraint impulse A(t_j, q_j)^T lambda at the start of a
// step, so a step followed by the step of size -h returns q exactly but p only up to a multiple of A(t_j, q_j)^T:
// the map on (q, p) is not symmetric. It is symmetric on (q, p mod A(q)^T), which is all the next step sees (a
// normal part of p_j is absorbed into its lambda), so compositions keep their order in q (measured in
// tests/schemes/composition_orders.test.cpp; the symmetry itself in tests/schemes/composition.test.cpp).
//
// Cost. Each stage is its own Stepper with step w_i h, so it keeps its own Jacobian (simplified Newton) from one
// step to the next, and its own predictor: the stage's increment (q' - q, [z' - z], lambda), a smooth function of
// t_j of size O(h), extrapolated quadratically from the last three steps, error O(h^4) — no worse than a lone
// stepper's O((w_i h)^3), so a composition step costs the Newton updates of its stages' steps and no more
// (experiments/bench_compose.cpp measures the ratio). The family is run-time data: one instantiation per
// (system, base scheme, scalar), whatever the number of families.
#include <algorithm>
#include <string>
#include <vector>

#include "geomint/error.hpp"
#include "geomint/generic/composition_families.hpp"
#include "geomint/generic/stepper.hpp"

namespace geomint::generic {

template <class Sys, class Scheme, class T = double>
class Composition {
  // The core's second-order quadratures (midpoint, trapezoid) are its symmetric ones: 𝓛, F_d^± and Psi are
  // invariant under (q_j, q_{j+1}, t, h) -> (q_{j+1}, q_j, t + h, -h). A first-order base would compose to order
  // 2 at best.
  static_assert(Scheme::order == 2, "a composition needs a symmetric (second-order) base scheme");

 public:
  using Stage = Stepper<Sys, Scheme, T>;
  using State = typename Stage::State;
  static constexpr int n = Stage::n, m = Stage::m, nz = Stage::nz, K = Stage::K;
  using VecN = typename Stage::VecN;
  using VecM = typename Stage::VecM;
  using VecK = typename Stage::VecK;

  Composition(const Sys& sys, const CompositionFamily& family, T h) : Composition(sys, family, h, initial_time<T>(sys)) {}
  Composition(const Sys& sys, const CompositionFamily& family, T h, T t0) : family_(family.name), h_(h), t0_(t0) {
    require(!family.weights.empty(), "composition family '" + family.name + "' has no weights");
    long double c = 0;  // c_i = w_1 + ... + w_{i-1}, summed in long double
    const auto H = static_cast<long double>(h);
    for (const long double w : family.weights) {
      offset_.push_back(static_cast<T>(c * H));
      ratio_.push_back(weights_.empty() || weights_.back() == 0 ? T(0) : static_cast<T>(w / weights_.back()));
      weights_.push_back(w);
      stages_.emplace_back(sys, static_cast<T>(w * H), t0);
      c += w;
    }
    offset_.push_back(static_cast<T>(c * H));
    history_.resize(stages_.size());
  }

  // As Stepper::start: v0 projected onto the constraints, p0 the continuous momentum. The first stage of the
  // first step then uses that stepper's own start (Taylor from v0 and the initial acceleration).
  void start(const VecN& q0, const VecN& v0) { start(q0, v0, initial_action<T>(system())); }
  void start(const VecN& q0, const VecN& v0, T z0) {
    stages_.front().start(q0, v0, z0);
    s_ = stages_.front().state();
    from_start_ = true;
    reset_history();
  }

  // Starts from a discrete state (q_j, p_j, z_j) at step j (no velocity: the first stage starts Newton at q_j).
  void restart(long j, const VecN& q, const VecN& p, T z) {
    s_ = State{j, t0_ + T(j) * h_, q, p, z, VecM::Zero()};
    from_start_ = false;
    reset_history();
  }

  void step() {
    step([](std::size_t, const State&, const State&) {});
  }

  // A step that shows each stage to on_stage(i, in, out) once it is done (its input and output states; the
  // stage's step is stage_h(i)): for diagnostics such as the discrete constraint of every stage.
  template <class OnStage>
  void step(OnStage&& on_stage) {
    const long j = s_.j;
    const T tj = t0_ + T(j) * h_;
    State in = s_;
    VecM lambda = VecM::Zero();
    int updates = 0;
    const std::size_t s = stages_.size();
    for (std::size_t i = 0; i < s; ++i) {
      Stage& st = stages_[i];
      in.j = j;
      in.t = tj + offset_[i];
      in.lambda = st.state().lambda;  // the stage's own last impulse: the size of its unknown lambda
      const T t_next = i + 1 == s ? t0_ + T(j + 1) * h_ : tj + offset_[i + 1];
      try {
        if (i == 0 && from_start_)
          st.step();  // from the state start() gave it, with its Taylor predictor
        else
          st.step_from(in, t_next, guess(i, in));
      } catch (const NumericalFailure& e) {
        throw NumericalFailure(j + 1, e.quantity,
                               "stage " + std::to_string(i + 1) + " of " + std::to_string(s) + " of " + family_ +
                                   " (step " + show(static_cast<double>(st.h())) + "): " + e.detail);
      }
      const State& out = st.state();
      on_stage(i, in, out);
      remember(i, in, out);
      lambda += out.lambda;
      updates += st.last_updates();
      in = out;
    }
    from_start_ = false;
    s_ = in;
    s_.j = j + 1;
    s_.t = t0_ + T(j + 1) * h_;  // t_j = t0 + j h, never accumulated
    s_.lambda = lambda;          // the step's total impulse: the sum of its stages'
    last_updates_ = updates;
  }

  const State& state() const { return s_; }
  T h() const { return h_; }
  const Sys& system() const { return stages_.front().system(); }
  int stages() const { return static_cast<int>(stages_.size()); }
  T stage_h(std::size_t i) const { return stages_[i].h(); }
  const std::string& family() const { return family_; }
  // Newton updates of the last step (all its stages), and totals over the run.
  int last_updates() const { return last_updates_; }
  long total_updates() const {
    long u = 0;
    for (const auto& st : stages_) u += st.total_updates();
    return u;
  }
  long jacobians() const {
    long u = 0;
    for (const auto& st : stages_) u += st.jacobians();
    return u;
  }

 private:
  // The stage's increment of the unknowns and its impulse: (q' - q, [z' - z], lambda), for the predictor.
  struct History {
    VecK y0 = VecK::Zero(), y1 = VecK::Zero(), y2 = VecK::Zero();
    int count = 0;
  };

  void reset_history() {
    for (auto& h : history_) h = History{};
  }

  void remember(std::size_t i, const State& in, const State& out) {
    History& h = history_[i];
    h.y2 = h.y1;
    h.y1 = h.y0;
    h.y0.template head<n>() = out.q - in.q;
    if constexpr (nz == 1) h.y0(n) = out.z - in.z;
    if constexpr (m > 0) h.y0.template tail<m>() = out.lambda;
    h.count = std::min(h.count + 1, 3);
  }

  // Newton's starting point for stage i from `in`: the stage's increment extrapolated over the last steps
  // (quadratic once three are known: O(h^4)); on the first step, the increment of the stage before it scaled by
  // the ratio of their steps (an increment is w h q' + O(h^2), an impulse O(w h)).
  VecK guess(std::size_t i, const State& in) const {
    const History& h = history_[i];
    VecK y = VecK::Zero();
    if (h.count >= 3)
      y = 3 * h.y0 - 3 * h.y1 + h.y2;
    else if (h.count == 2)
      y = 2 * h.y0 - h.y1;
    else if (h.count == 1)
      y = h.y0;
    else if (i > 0 && history_[i - 1].count > 0)
      y = ratio_[i] * history_[i - 1].y0;
    VecK x = y;
    x.template head<n>() += in.q;
    if constexpr (nz == 1) x(n) += in.z;
    return x;
  }

  std::string family_;
  std::vector<long double> weights_;
  std::vector<T> offset_;  // c_i h: stage i starts at t_j + c_i h (i = 1..s+1)
  std::vector<T> ratio_;   // w_i / w_{i-1} (0 for the first stage)
  std::vector<Stage> stages_;
  std::vector<History> history_;
  T h_, t0_;
  State s_;
  bool from_start_ = false;
  int last_updates_ = 0;
};

}  // namespace geomint::generic
