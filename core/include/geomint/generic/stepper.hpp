#pragma once
// One step of a generic scheme: Newton on the scheme's residual with the Jacobian by automatic
// differentiation (fixed-size Eigen types, no allocation in the loop).
//
// Unknowns x = (q_{j+1}, z_{j+1} if the quadrature is implicit in z, lambda): K = n + [1] + m.
// Predictor: quadratic extrapolation of x from the last three steps; for the first two, Taylor from the initial
// velocity and acceleration. Its error is O(h^3) in q.
// Jacobian policy (simplified Newton, as stiff solvers do): the LU of the last Jacobian is kept while it makes
// a step converge after one update (a linear step: the Jacobian never changes, so it is computed once per
// run); a step that needs a second update gets a fresh Jacobian at its next step, and a kept Jacobian that
// needs a second update within a step is refreshed at once.
// Stopping rule, at round-off: an iterate is accepted when every row of the residual is within kappa eps of
// its scale (the sum of the magnitudes of the terms that cancel in it, plus |J| times the size of the
// unknowns: what rounding the solution itself would leave), or when the next update would move every unknown
// by less than kappa eps of its size; both with an absolute floor of kappa times the smallest subnormal
// (kappa = 16). That last update is then applied without another evaluation, and p_{j+1}, z_{j+1} move with
// it by their derivatives from the last Jacobian: this final correction removes the error of order
// kappa eps that an accepted iterate may carry, which a kept Jacobian makes systematic (it would otherwise
// accumulate over a long run: measured on foucault-rotation, 4e-11 after 36000 steps without it).
// A step that does not converge within max_updates throws NumericalFailure with the step, the residual norm
// and the iteration count.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/LU>

#include "geomint/error.hpp"
#include "geomint/generic/schemes.hpp"

namespace geomint::generic {

template <class Sys, class Scheme, class T = double>
class Stepper {
 public:
  static constexpr int n = Sys::dof;
  static constexpr int m = Sys::constraints;
  static constexpr int nz = Scheme::implicit_z ? 1 : 0;
  static constexpr int K = n + nz + m;
  using VecN = Vec<T, n>;
  using VecM = Vec<T, m>;
  using VecK = Vec<T, K>;
  using MatK = Mat<T, K, K>;

  static constexpr int max_updates = 40;
  static constexpr int kappa = 16;

  struct State {
    long j = 0;
    T t = 0;
    VecN q = VecN::Zero(), p = VecN::Zero();
    T z = 0;
    VecM lambda = VecM::Zero();  // impulse of the step that arrived at q_j (0 at j = 0)
  };

  Stepper(const Sys& sys, T h, T t0 = T(0)) : sys_(sys), h_(h), t0_(t0) {}

  // The start from (q0, v0) at t0: v0 is projected onto the constraints (kinetic metric), and p0 is the
  // continuous momentum at that velocity — the first step is then the scheme's own discrete Legendre
  // transform (LA: p0 = dL/dq'; contact: p0 = dL/dq'(t0, q0, v0, z0)).
  void start(const VecN& q0, const VecN& v0, T z0 = T(0)) {
    const VecN v = consistent_velocity(sys_, t0_, q0, v0);
    s_ = State{};
    s_.t = t0_;
    s_.q = q0;
    s_.z = z0;
    s_.p = Scheme::initial_momentum(sys_, t0_, q0, v, z0);
    v0_ = v;
    // the initial acceleration, for the predictor of the first two steps (in double: a guess needs no more)
    a0_ = acceleration(sys_, static_cast<double>(t0_), Vec<double, n>(q0.template cast<double>()),
                       Vec<double, n>(v.template cast<double>()))
              .a.template cast<T>();
    reset_history(true);
  }

  // Starts from a discrete state (q_j, p_j, z_j) at step j; the predictor has no velocity to start from.
  void restart(long j, const VecN& q, const VecN& p, T z) {
    s_ = State{};
    s_.j = j;
    s_.t = t0_ + T(j) * h_;
    s_.q = q;
    s_.p = p;
    s_.z = z;
    v0_ = VecN::Zero();
    a0_ = VecN::Zero();
    reset_history(false);
  }

  void step() {
    advance(linear_lane_ && kMapLane ? x0_ : predict());
    s_.t = t0_ + T(s_.j) * h_;  // t_j = t0 + j h, never accumulated
  }

  // One step of size h() from the state `in` (its t, q, p, z; its lambda only sizes the stopping rule) to the
  // time t_next, Newton starting from `guess` = (q_{j+1}, [z_{j+1}], lambda). For a caller that chains steppers
  // and predicts for them: the stages of a composition (geomint/generic/composition.hpp), each a stepper with its
  // own step w_i h whose successive inputs come from the stage before it. The kept Jacobian and the linear lanes
  // carry over from call to call as they do for step().
  void step_from(const State& in, T t_next, const VecK& guess) {
    s_ = in;
    advance(guess);
    s_.t = t_next;
  }

  const State& state() const { return s_; }
  T h() const { return h_; }
  const Sys& system() const { return sys_; }
  int last_updates() const { return last_updates_; }
  long total_updates() const { return total_updates_; }
  long jacobians() const { return jacobians_; }

 private:
  // Solves the step from s_ starting at `guess` and moves s_ to its result (all but the time).
  void advance(const VecK& guess) {
    const VecK x = linear_lane_ ? solve_linear(guess) : solve(guess);
    // shift the history used by the predictor
    x2_ = x1_;
    x1_ = x0_;
    history_ = history_ < 0 ? 1 : std::min(history_ + 1, 2);
    s_.q = x.template head<n>();
    s_.p = out_.p_next;
    s_.z = out_.z_next;
    if constexpr (m > 0) s_.lambda = x.template tail<m>();
    x0_ = current();
    ++s_.j;
  }

  // The unknowns' values at the current step: (q_j, [z_j], lambda_j).
  VecK current() const {
    VecK x;
    x.template head<n>() = s_.q;
    if constexpr (nz == 1) x(n) = s_.z;
    if constexpr (m > 0) x.template tail<m>() = s_.lambda;
    return x;
  }

  void reset_history(bool have_velocity) {
    linear_lane_ = false;
    map_ready_ = false;
    x0_ = current();
    history_ = have_velocity ? 0 : -1;
    need_jacobian_ = true;
  }

  // x = (q_{j+1}, [z_{j+1}], lambda) extrapolated from the last three steps; for the first two steps q from the
  // initial velocity and acceleration (Taylor, then the central difference q_2 = 2 q_1 - q_0 + h^2 a): O(h^3)
  // throughout, so a nonlinear step needs two Newton updates from the start.
  VecK predict() const {
    if (history_ >= 2) return 3 * x0_ - 3 * x1_ + x2_;
    if (history_ == 1) {
      VecK x = 2 * x0_ - x1_;
      x.template head<n>() += h_ * h_ * a0_;
      return x;
    }
    VecK x = x0_;
    if (history_ == 0) x.template head<n>() += h_ * v0_ + h_ * h_ / 2 * a0_;
    return x;
  }

  // The step's rows at x in the scalar S (T for a residual, Dual<T, K> for a residual and its Jacobian).
  template <class S>
  StepRows<S, n, m> rows_at(const Vec<S, K>& x) const {
    const Vec<S, n> q1 = x.template head<n>();
    S z1 = S(s_.z);
    if constexpr (nz == 1) z1 = x(n);
    Vec<S, m> lambda;
    if constexpr (m > 0)
      lambda = x.template tail<m>();
    return Scheme::template rows<Sys, S>(sys_, S(s_.t), S(h_), Vec<S, n>(s_.q.template cast<S>()),
                                         Vec<S, n>(s_.p.template cast<S>()), S(s_.z), q1, z1, lambda);
  }

  template <class S>
  static void stack(const StepRows<S, n, m>& r, Vec<S, K>& R, Vec<S, K>& scale) {
    R.template head<n>() = r.dynamics;
    scale.template head<n>() = r.dynamics_scale;
    if constexpr (nz == 1) {
      R(n) = r.action;
      scale(n) = r.action_scale;
    }
    if constexpr (m > 0) {
      R.template tail<m>() = r.constraint;
      scale.template tail<m>() = r.constraint_scale;
    }
  }

  // Residual at x (the rows' p_{j+1}, z_{j+1} kept as the output if x is accepted).
  void evaluate(const VecK& x, VecK& R, VecK& scale) {
    const auto rows = rows_at<T>(x);
    stack(rows, R, scale);
    out_.p_next = rows.p_next;
    out_.z_next = rows.z_next;
  }

  // Residual and Jacobian at x (the Jacobian and its inverse kept). Out of line: rare after the first step
  // of a linear run, and it keeps the hot loop small.
  [[gnu::noinline]] void evaluate_with_jacobian(const VecK& x, VecK& R, VecK& scale) {
    using D = Dual<T, K>;
    Vec<D, K> X;
    for (int i = 0; i < K; ++i) X(i) = D::variable(x(i), i);
    Vec<D, K> RD, SD;
    const auto rows = rows_at<D>(X);
    stack(rows, RD, SD);
    for (int i = 0; i < n; ++i) {
      out_.p_next(i) = rows.p_next(i).v;
      for (int c = 0; c < K; ++c) dP_(i, c) = rows.p_next(i).d[static_cast<std::size_t>(c)];
    }
    out_.z_next = rows.z_next.v;
    for (int c = 0; c < K; ++c) dZ_(c) = rows.z_next.d[static_cast<std::size_t>(c)];
    for (int r = 0; r < K; ++r) {
      R(r) = RD(r).v;
      scale(r) = SD(r).v;
      for (int c = 0; c < K; ++c) J_(r, c) = RD(r).d[static_cast<std::size_t>(c)];
    }
    Jinv_ = Eigen::PartialPivLU<MatK>(J_).inverse();
    ++jacobians_;
  }

  // Size of each unknown, for the stopping rule: |x| + |its value at the start of the step|.
  VecK sizes(const VecK& x) const {
    using std::abs;
    VecK w = x.cwiseAbs();
    w.template head<n>() += s_.q.cwiseAbs();
    if constexpr (nz == 1) w(n) += abs(s_.z);
    if constexpr (m > 0) w.template tail<m>() += s_.lambda.cwiseAbs();
    return w;
  }

  // A system that declares itself linear (L quadratic in (q, q'), F and Phi affine: `static constexpr bool
  // linear = true`) has, with a quadrature explicit in z, a residual and outputs p_{j+1} affine in the unknowns:
  // one Newton update from any point is the solution (to the round-off of the linear solve), and p_{j+1} moves
  // with it exactly by its derivative. So one evaluation per step, at the predictor. z_{j+1} = z_j + 𝓛 (quadratic
  // in q_{j+1}) is evaluated at the solution in plain arithmetic. The declaration is checked: the first steps and
  // every kVerify-th step go through the full Newton solve with its stopping rule, and a lane step whose residual
  // is not then at round-off throws.
  //
  // A linear system that also declares itself autonomous (no explicit t) has one step map for the whole run:
  // (q_{j+1}, [z_{j+1}], lambda, p_{j+1}) = c + G (q_j, p_j, [z_j]), affine. The lane then builds c and G once,
  // from the scheme's own rows — the solution from x = 0 (one Newton update, exact for an affine residual) at
  // the zero input and at each unit input — and a step is one small matrix-vector product, verified like
  // the lane (every kVerify-th step, the full residual at round-off). z_{j+1} is still evaluated as above.
  static constexpr long kVerify = 256;
  static constexpr bool kMapLane = is_linear<Sys>() && is_autonomous<Sys>() && !Scheme::implicit_z;
  static constexpr int U = 2 * n + (Scheme::contact ? 1 : 0);  // inputs of the step map
  using VecU = Vec<T, U>;
  using VecY = Vec<T, K + n>;

  VecU map_input() const {
    VecU u;  // element by element: Eigen's packet copies into a block of a 1-vector trip -Warray-bounds
    for (int i = 0; i < n; ++i) {
      u(i) = s_.q(i);
      u(n + i) = s_.p(i);
    }
    if constexpr (Scheme::contact) u(2 * n) = s_.z;
    return u;
  }
  [[gnu::noinline]] void build_map() {
    const State keep = s_;
    const Output keep_out = out_;
    auto solve_at = [&](const VecU& u) {
      for (int i = 0; i < n; ++i) {
        s_.q(i) = u(i);
        s_.p(i) = u(n + i);
      }
      if constexpr (Scheme::contact) s_.z = u(2 * n);
      VecK R, scale;
      evaluate(VecK::Zero(), R, scale);
      const VecK x = -(Jinv_ * R);
      const VecN p = out_.p_next + dP_ * x;
      VecY y;
      for (int i = 0; i < K; ++i) y(i) = x(i);
      for (int i = 0; i < n; ++i) y(K + i) = p(i);
      return y;
    };
    map_c_ = solve_at(VecU::Zero());
    for (int i = 0; i < U; ++i) map_G_.col(i) = solve_at(VecU::Unit(i)) - map_c_;
    s_ = keep;
    out_ = keep_out;
    map_ready_ = true;
  }

  VecK solve_linear(VecK x) {
    if constexpr (kMapLane) {
      if (!map_ready_) build_map();
      const VecY y = map_c_ + map_G_ * map_input();
      for (int i = 0; i < K; ++i) x(i) = y(i);
      for (int i = 0; i < n; ++i) out_.p_next(i) = y(K + i);
    } else {
      VecK R, scale;
      evaluate(x, R, scale);
      const VecK dx = -(Jinv_ * R);
      x += dx;
      out_.p_next += dP_ * dx;
    }
    if constexpr (Scheme::contact) out_.z_next = Scheme::next_z(sys_, s_.t, h_, s_.q, VecN(x.template head<n>()), s_.z);
    last_updates_ = 1;
    ++total_updates_;
    if (++lane_steps_ % kVerify == 0) verify_linear(x);
    return x;
  }
  [[gnu::noinline]] void verify_linear(const VecK& x) {
    using std::abs;
    VecK R, scale;
    const Output keep = out_;
    evaluate(x, R, scale);
    const VecK w = sizes(x);
    const T tol = T(kappa) * std::numeric_limits<T>::epsilon();
    for (int r = 0; r < K; ++r) {
      T sc = scale(r);
      for (int c = 0; c < K; ++c) sc += abs(J_(r, c)) * w(c);
      if (!(abs(R(r)) <= tol * sc + T(kappa) * std::numeric_limits<T>::denorm_min()))
        fail(R, 1, kMapLane ? "the system declares itself linear and autonomous, but its fixed step map did not solve the step"
                            : "the system declares itself linear, but one Newton update did not solve the step");
    }
    out_ = keep;
  }

  VecK solve(VecK x) {
    using std::abs;
    using std::isfinite;
    const T eps = std::numeric_limits<T>::epsilon();
    const T tol = T(kappa) * eps;
    // below the normal range rounding is absolute (the spacing of subnormals): a decayed run stays solvable
    const T floor = T(kappa) * std::numeric_limits<T>::denorm_min();
    int updates = 0;
    bool fresh = false;
    VecK R, scale;
    for (;;) {
      if (need_jacobian_) {
        evaluate_with_jacobian(x, R, scale);
        need_jacobian_ = false;
        fresh = true;
      } else {
        evaluate(x, R, scale);
      }
      const VecK w = sizes(x);
      bool ok = true, finite = true;
      for (int r = 0; r < K; ++r) {
        T s = scale(r);
        for (int c = 0; c < K; ++c) s += abs(J_(r, c)) * w(c);
        if (!isfinite(R(r))) finite = false;
        if (!(abs(R(r)) <= tol * s + floor)) ok = false;
      }
      const VecK dx = -(Jinv_ * R);
      bool small = true;
      for (int c = 0; c < K; ++c)
        if (!(abs(dx(c)) <= tol * w(c) + floor)) small = false;
      if (ok || small) {
        // converged: the last Newton correction is applied without another evaluation (the outputs moved
        // with it by their derivatives from the last Jacobian); it removes the bias a kept Jacobian leaves
        // Within two ulps it is skipped for a linear system, whose one update is exact up to rounding (this keeps
        // its check off the critical path). Not for a nonlinear one: there a kept Jacobian leaves a bias of the
        // same sign step after step, and a composition's many stages add it up (la-midpoint with kahanli8 on the
        // pendulum, h = 0.00625, T = 10: max error 2e-10 with the skip, 5e-14 without).
        bool negligible = is_linear<Sys>();
        for (int c = 0; c < K && negligible; ++c)
          if (!(abs(dx(c)) <= T(2) * eps * w(c) + floor)) negligible = false;
        if (!negligible && dx.allFinite()) {
          x += dx;
          out_.p_next += dP_ * dx;
          out_.z_next += dZ_.dot(dx);
        }
        break;
      }
      if (!finite || updates >= max_updates) fail(R, updates, finite ? "Newton did not converge" : "non-finite residual");
      if (!dx.allFinite()) fail(R, updates, "singular Newton matrix");
      x += dx;
      ++updates;
      if (updates >= 2 && !fresh) need_jacobian_ = true;  // a kept Jacobian that converges slowly
    }
    // keep the Jacobian for the next step only if it made this one converge after one update
    if (updates > 1) need_jacobian_ = true;
    // a linear system enters the one-evaluation lane once its Jacobian has solved a step in one update
    if constexpr (is_linear<Sys>() && !Scheme::implicit_z)
      if (updates == 1 && !need_jacobian_ && history_ >= 1) linear_lane_ = true;
    last_updates_ = updates;
    total_updates_ += updates;
    return x;
  }

  [[noreturn, gnu::cold, gnu::noinline]] void fail(const VecK& R, int updates, const char* why) const {
    using std::abs;
    T norm = 0;
    for (int r = 0; r < K; ++r) norm = std::max<T>(norm, abs(R(r)));
    throw NumericalFailure(s_.j + 1, "newton",
                           std::string(why) + " (residual norm " + show(static_cast<double>(norm)) + " after " +
                               std::to_string(updates) + " iterations, t = " + show(static_cast<double>(s_.t)) + ")");
  }

  Sys sys_;
  T h_, t0_;
  State s_;
  VecN v0_ = VecN::Zero(), a0_ = VecN::Zero();
  VecK x0_ = VecK::Zero(), x1_ = VecK::Zero(), x2_ = VecK::Zero();
  int history_ = 0;
  bool need_jacobian_ = true;
  MatK J_ = MatK::Zero();
  // The inverse, not an LU: K is a handful, a step is then multiplications only, and an inaccurate inverse
  // (an ill-conditioned J) can only slow Newton down — the residual test decides when a step is done.
  MatK Jinv_ = MatK::Zero();
  Mat<T, n, K> dP_ = Mat<T, n, K>::Zero();  // d p_{j+1} / dx at the last Jacobian
  VecK dZ_ = VecK::Zero();                   // d z_{j+1} / dx
  struct Output {
    VecN p_next = VecN::Zero();
    T z_next = 0;
  } out_;  // p_{j+1}, z_{j+1} at the last iterate whose rows were evaluated
  int last_updates_ = 0;
  long total_updates_ = 0, jacobians_ = 0;
  bool linear_lane_ = false, map_ready_ = false;
  long lane_steps_ = 0;
  VecY map_c_ = VecY::Zero();
  Mat<T, K + n, U> map_G_ = Mat<T, K + n, U>::Zero();
};

}  // namespace geomint::generic
