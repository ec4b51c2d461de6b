#pragma once
// One step of a generic scheme: Newton on the scheme's residual with the Jacobian by automatic differentiation
// (fixed-size Eigen types, no allocation in the loop), put together from parts a reader can take one at a time:
//   the rows        Scheme::rows (generic/schemes.hpp) at the unknowns x = (q_{j+1}, [z_{j+1}], lambda):
//                   K = n + [1] + m rows, their round-off scales, and the outputs p_{j+1}, z_{j+1}
//   the Jacobian    assembled here by forward-mode AD of the rows (one pass of Dual<T, K>): J, dp/dx, dz/dx
//   the solve       JacobianInverse (by blocks with constraints), the stopping rule and Newton's Jacobian policy
//                   (generic/newton.hpp), with a kept Jacobian's constraint block brought up to date every step
//                   (refresh_constraint_block)
//   the predictor   the initial guess from the last steps (generic/predictor.hpp)
//   the action row  of a quadrature implicit in z (contact-trapezoid), solved for z_{j+1} inside the rows, so that
//                   Newton's unknowns are (q_{j+1}, lambda) as for every other scheme (solved_z below)
//   two shortcuts   for systems that declare themselves `linear`, or their dynamics linear on a scheme whose rows
//                   are then affine (one Newton update solves every step: the single-update path), and also
//                   `autonomous` (the whole step is one fixed affine map: generic/affine_step_map.hpp), each
//                   verified every kVerify-th step.
// A step that does not converge throws NumericalFailure with the step, the residual norm and the iteration count.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "geomint/error.hpp"
#include "geomint/generic/affine_step_map.hpp"
#include "geomint/generic/newton.hpp"
#include "geomint/generic/predictor.hpp"
#include "geomint/generic/schemes.hpp"

// The residual and Jacobian of a step are flattened (every call inlined) in optimized builds; not in the
// sanitizer build, where it would only lengthen the compile of the instrumented units.
#if defined(__SANITIZE_ADDRESS__)
#define GEOMINT_HOT_FLATTEN
#else
#define GEOMINT_HOT_FLATTEN gnu::flatten
#endif

namespace geomint::generic {

// EliminateZ = false keeps z_{j+1} of an implicit-z quadrature as a Newton unknown beside q_{j+1} and lambda: the
// step as the scheme's rows state it, which the tests hold the default (z_{j+1} solved inside the rows) to.
template <class Sys, class Scheme, class T = double, bool EliminateZ = true>
class Stepper {
 public:
  static constexpr int n = Sys::dof;
  static constexpr int m = Sys::constraints;
  static constexpr bool eliminate_z = Scheme::implicit_z && EliminateZ;
  static constexpr int nz = Scheme::implicit_z && !eliminate_z ? 1 : 0;
  static constexpr int K = n + nz + m;
  static constexpr int Nx = n + nz;  // the unknowns the rows depend on nonlinearly: all but lambda
  using VecN = Vec<T, n>;
  using VecM = Vec<T, m>;
  using VecK = Vec<T, K>;
  using MatK = Mat<T, K, K>;

  static constexpr int max_updates = Newton<T, K, n, m>::max_updates;
  static constexpr int kappa = StoppingRule<T, K>::kappa;

  struct State {
    long j = 0;
    T t = 0;
    VecN q = VecN::Zero(), p = VecN::Zero();
    T z = 0;
    VecM lambda = VecM::Zero();  // impulse of the step that arrived at q_j (0 at j = 0)
  };

  // Without t0: the system's start (generic::initial_time), so that every run of a system that starts later
  // (a formula system's t0) steps on its own clock.
  Stepper(const Sys& sys, T h) : Stepper(sys, h, initial_time<T>(sys)) {}
  Stepper(const Sys& sys, T h, T t0) : sys_(sys), h_(h), t0_(t0), affine_rows_(affine_rows_of(sys)) {}

  // The start from (q0, v0) at t0: v0 is projected onto the constraints (kinetic metric), and p0 is the
  // continuous momentum at that velocity — the first step is then the scheme's own discrete Legendre
  // transform (LA: p0 = dL/dq'; contact: p0 = dL/dq'(t0, q0, v0, z0)).
  // z0: the system's initial action (generic::initial_action) unless given.
  void start(const VecN& q0, const VecN& v0) { start(q0, v0, initial_action<T>(sys_)); }
  void start(const VecN& q0, const VecN& v0, T z0) {
    const VecN v = consistent_velocity(sys_, t0_, q0, v0);
    s_ = State{};
    s_.t = t0_;
    s_.q = q0;
    s_.z = z0;
    s_.p = Scheme::initial_momentum(sys_, t0_, q0, v, z0);
    // the initial acceleration, for the predictor of the first two steps (in double: a guess needs no more)
    const VecN a0 = acceleration(sys_, static_cast<double>(t0_), Vec<double, n>(q0.template cast<double>()),
                                 Vec<double, n>(v.template cast<double>()))
                        .a.template cast<T>();
    predictor_.start(current(), v, a0);
    reset_shortcuts();
  }

  // Starts from a discrete state (q_j, p_j, z_j) at step j; the predictor has no velocity to start from.
  void restart(long j, const VecN& q, const VecN& p, T z) {
    s_ = State{};
    s_.j = j;
    s_.t = t0_ + T(j) * h_;
    s_.q = q;
    s_.p = p;
    s_.z = z;
    predictor_.restart(current());
    reset_shortcuts();
  }

  void step() {
    // the affine step map needs no guess, nor a history to extrapolate
    const bool map = single_update_ && kAffineMap;
    advance(map ? predictor_.last() : predictor_.predict(h_), !map);
    s_.t = t0_ + T(s_.j) * h_;  // t_j = t0 + j h, never accumulated
  }

  // One step of size h() from the state `in` (its t, q, p, z; its lambda only sizes the stopping rule) to the
  // time t_next, Newton starting from `guess` = (q_{j+1}, [z_{j+1}], lambda). For a caller that chains steppers
  // and predicts for them: the stages of a composition (geomint/generic/composition.hpp), each a stepper with its
  // own step w_i h whose successive inputs come from the stage before it. The kept Jacobian and the shortcuts
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
  // The shortcuts of linear systems and of linear dynamics (below) off, or on again (the default): every step then
  // goes through Newton with its stopping rule, the reference the shortcuts are tested against.
  void allow_shortcuts(bool on) {
    shortcuts_ = on;
    single_update_ = false;
  }
  bool on_single_update_path() const { return single_update_; }
  long total_updates() const { return total_updates_; }
  // Checked steps of the single-update path that Newton had to finish (verify_single_update).
  long shortcut_misses() const { return shortcut_misses_; }
  long jacobians() const { return newton_.jacobians(); }

  // The rows at x = (q_{j+1}, [z_{j+1}], lambda) from the current state, and their linearization as Newton
  // assembles it: for tests that check the assembly against a forward pass of the rows in every direction.
  struct Linearized {
    VecK R, scale;
    StepOutput<T, n> out;
    Linearization<T, K, n> lin;
  };
  Linearized linearized_at(const VecK& x) const {
    Linearized l;
    jacobian(x, l.R, l.scale, l.out, l.lin);
    return l;
  }

  // The constraint rows of a kept Jacobian (dPhi_d / dq_{j+1}) and its multiplier columns (-A(t_j, q_j)^T),
  // assembled anew at x from the scheme's constraint block alone: the parts of J that move with q_j (and with
  // t_{j+1} for a rheonomic constraint) and to which lambda is most sensitive (generic/newton.hpp). A pass of
  // Dual<T, n> over the m constraint rows, against the full Jacobian's pass over every row with the Lagrangian's
  // partials nested inside it. The dynamics block and the outputs' derivatives dP, dZ (used only by the final
  // correction, an update at round-off) stay as kept. The entries are those the full pass gives (the same
  // functions in the same dual type, direction by direction), so a system whose A and b are constant keeps its
  // bits (tests/generic_checks.hpp compares them entry for entry). An implicit-z row's entries stay as kept:
  // Phi_d does not depend on z_{j+1}.
  [[GEOMINT_HOT_FLATTEN]] bool refresh_constraint_block(const VecK& x, MatK& J) const {
    if constexpr (m == 0) {
      return false;
    } else {
      using D = Dual<T, n>;
      Vec<D, n> Q1;
      for (int i = 0; i < n; ++i) Q1(i) = D::variable(x(i), i);
      const auto cb = constraint_block<Sys, typename Scheme::quadrature>(sys_, D(s_.t), D(h_),
                                                                          Vec<D, n>(s_.q.template cast<D>()), Q1);
      for (int r = 0; r < m; ++r)
        for (int c = 0; c < n; ++c) J(n + nz + r, c) = cb.phi.value(r).d[static_cast<std::size_t>(c)];
      for (int r = 0; r < n; ++r)
        for (int c = 0; c < m; ++c) J(r, Nx + c) = -cb.A(c, r).v;
      return true;
    }
  }

  // z_{j+1} of an implicit-z quadrature at the given q_{j+1}, from the current state: its action row
  // z_{j+1} = z_j + 𝓛(q_j, q_{j+1}, z_j, z_{j+1}) solved by Newton in z_{j+1} alone, to round-off (the row's
  // own scale, as Newton's stopping rule measures every row). In the Jacobian's duals the result carries
  // dz_{j+1}/dq_{j+1}: Newton's map has zero derivative at its fixed point, so the last update from a converged
  // value gives the implicit function's derivative. When 𝓛 is affine in z_{j+1} (every Lagrangian L - alpha z)
  // the first update is exact and a second only confirms it; a system that declares itself linear has that
  // (its Herglotz equations are linear), so it takes the one update, and the check every kVerify-th step of the
  // shortcuts holds the action row to round-off. With z_{j+1} gone from the unknowns, a step is a system in
  // (q_{j+1}, lambda) as for every other scheme: one fewer direction in every dual, and a linear system's rows
  // are affine in them again, so its shortcuts apply.
  template <class S>
  S solved_z(const Vec<S, n>& q1) const {
    using std::abs;
    using Quad = typename Scheme::quadrature;
    using Z = Dual<S, 1>;
    const S t = S(s_.t), h = S(h_), z0 = S(s_.z);
    const Vec<S, n> q0 = s_.q.template cast<S>();
    const Vec<Z, n> Q0 = q0.template cast<Z>(), Q1 = q1.template cast<Z>();
    // the start: the explicit estimate z_j + 𝓛(.., z_j, z_j), O(h^2) from the solution, or z_j for one exact update
    S z1 = z0;
    if constexpr (!is_linear<Sys>()) z1 += Quad::action(sys_, t, h, q0, q1, z0, z0);
    for (int k = 0; k < max_updates; ++k) {
      const Z L = Quad::action(sys_, Z(t), Z(h), Q0, Q1, Z(z0), Z::variable(z1, 0));
      const S r = z1 - z0 - L.v;
      const bool done = StoppingRule<T, K>::scalar_at_roundoff(primal(r), abs(primal(z1)) + abs(primal(z0)) + abs(primal(L.v)));
      z1 -= r / (S(1) - L.d[0]);
      if (done || is_linear<Sys>()) return z1;
    }
    throw NumericalFailure(s_.j + 1, "newton",
                           "the action row z_{j+1} = z_j + L_d did not converge in z_{j+1} (t = " +
                               show(static_cast<double>(s_.t)) + ")");
  }

 private:
  // Solves the step from s_ starting at `guess` and moves s_ to its result (all but the time); `remember`: the
  // result enters the predictor's history (the affine step map, which ignores the guess, skips it: the map stays
  // in use until the next start).
  void advance(const VecK& guess, bool remember = true) {
    const VecK x = single_update_ ? solve_single_update(guess) : solve(guess);
    s_.q = x.template head<n>();
    s_.p = out_.p_next;
    s_.z = out_.z_next;
    if constexpr (m > 0) s_.lambda = x.template tail<m>();
    if (remember) predictor_.accept(current());
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

  void reset_shortcuts() {
    single_update_ = false;
    affine_map_.reset();
    newton_.invalidate();
  }

  // ---------------------------------------------------------------------------------------------------------
  // The rows and their Jacobian

  // The step's rows at x in the scalar S (T for a residual, Dual<T, K> for a residual and its Jacobian).
  template <class S>
  StepRows<S, n, m> rows_at(const Vec<S, K>& x) const {
    const Vec<S, n> q1 = x.template head<n>();
    S z1 = S(s_.z);
    if constexpr (nz == 1) z1 = x(n);
    if constexpr (eliminate_z) z1 = solved_z<S>(q1);
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

  // Residual at x, and the outputs p_{j+1}, z_{j+1} there. Flattened (everything it calls inlined into it): the
  // dual arithmetic of the Lagrangian's partials is then straight-line code instead of calls that pass each
  // dual through memory (measured: a third fewer instructions per step; see bench_generic).
  [[GEOMINT_HOT_FLATTEN]] void residual(const VecK& x, VecK& R, VecK& scale, StepOutput<T, n>& out) const {
    const auto rows = rows_at<T>(x);
    stack(rows, R, scale);
    out.p_next = rows.p_next;
    out.z_next = rows.z_next;
  }

  // Residual and its Jacobian at x by one forward pass of Dual<T, Nx> over the unknowns the rows depend on
  // nonlinearly, (q_{j+1}, [z_{j+1}]); the lambda columns are the rows' own -A^T (StepRows::dynamics_lambda:
  // the rows are affine in lambda, which no output depends on), so lambda rides along as a constant. That is
  // the same Jacobian, entry for entry, as a pass in all K directions (tests/generic_checks.hpp), at Nx + 1
  // instead of K + 1 values per dual. Out of line: rare after the first step of a linear run, and it keeps the
  // hot loop small.
  [[gnu::noinline, GEOMINT_HOT_FLATTEN]] void jacobian(const VecK& x, VecK& R, VecK& scale, StepOutput<T, n>& out,
                                                Linearization<T, K, n>& lin) const {
    using D = Dual<T, Nx>;
    Vec<D, K> X;
    for (int i = 0; i < K; ++i) X(i) = i < Nx ? D::variable(x(i), i) : D(x(i));
    Vec<D, K> RD, SD;
    const auto rows = rows_at<D>(X);
    stack(rows, RD, SD);
    lin.dP.setZero();
    lin.dZ.setZero();
    lin.J.setZero();
    for (int i = 0; i < n; ++i) {
      out.p_next(i) = rows.p_next(i).v;
      for (int c = 0; c < Nx; ++c) lin.dP(i, c) = rows.p_next(i).d[static_cast<std::size_t>(c)];
    }
    out.z_next = rows.z_next.v;
    for (int c = 0; c < Nx; ++c) lin.dZ(c) = rows.z_next.d[static_cast<std::size_t>(c)];
    for (int r = 0; r < K; ++r) {
      R(r) = RD(r).v;
      scale(r) = SD(r).v;
      for (int c = 0; c < Nx; ++c) lin.J(r, c) = RD(r).d[static_cast<std::size_t>(c)];
    }
    for (int r = 0; r < n; ++r)
      for (int c = 0; c < m; ++c) lin.J(r, Nx + c) = rows.dynamics_lambda(r, c).v;
  }

  // ---------------------------------------------------------------------------------------------------------
  // Newton

  VecK solve(const VecK& guess) {
    int updates = 0;
    const VecK x = newton_.solve(
        guess, current(), [&](const VecK& y, VecK& R, VecK& scale, StepOutput<T, n>& out) { residual(y, R, scale, out); },
        [&](const VecK& y, VecK& R, VecK& scale, StepOutput<T, n>& out, Linearization<T, K, n>& lin) {
          jacobian(y, R, scale, out, lin);
        },
        [&](const VecK& y, MatK& J) { return refresh_constraint_block(y, J); }, out_,
        [&](const VecK& R, const VecK& bounds, int u, const char* why) { fail(R, bounds, u, why); }, updates,
        affine_rows_);
    // rows affine in the unknowns take the single-update path once a kept Jacobian has solved a step in one update
    if (affine_rows_)
      if (shortcuts_ && updates == 1 && newton_.jacobian_kept() && predictor_.history() >= 1) single_update_ = true;
    last_updates_ = updates;
    total_updates_ += updates;
    return x;
  }

  // ---------------------------------------------------------------------------------------------------------
  // The shortcuts of linear systems
  //
  // A system that declares itself linear (L quadratic in (q, q'), F and Phi affine: `static constexpr bool
  // linear = true`) has, with z_{j+1} not among the unknowns (explicit in the quadrature, or solved inside the
  // rows), a residual and outputs p_{j+1} affine in the unknowns: one Newton update from any point is the solution
  // (to the round-off of the linear solve), and p_{j+1} moves with it exactly by its derivative. So one evaluation
  // per step, at the predictor (the single-update path). z_{j+1} (z_j + 𝓛, or the solved action row: quadratic in
  // q_{j+1}) is evaluated at the solution in plain arithmetic. The declaration is
  // checked: the first steps and every kVerify-th step go through the full Newton solve with its stopping rule,
  // and a step whose residual is not then at round-off throws.
  //
  // The same holds of a system that declares linear dynamics (L and F as above, the constraint's A and b any
  // functions) on the schemes whose rows sample the constraint at the start of the step, (t_j, q_j): la and
  // contact. Within a step A(t_j, q_j) and b(t_j, q_j) are fixed, the impulse -A^T lambda is linear in lambda, and
  // Phi_d = A v + b affine in q_{j+1}: the rows are affine in the unknowns again. With a holonomic constraint g
  // affine in q (foucault-rotation's n(phi(t)).q), g(t_{j+1}, q_{j+1}) is affine in q_{j+1} on every scheme. Only
  // the constraint block of J moves from step to step, and the single-update path brings a kept J's up to date
  // before its update (refresh_constraint_block), as Newton does. This is the knife edge, the nonholonomic particle
  // and both Foucault pendulums: one evaluation of the rows a step instead of two.
  //
  // A linear system that also declares itself autonomous (no explicit t) has one step map for the whole run: the
  // affine step map (generic/affine_step_map.hpp), built from the scheme's own rows — the solution from x = 0 (one
  // Newton update, exact for an affine residual) at the zero input and at each unit input — and verified like
  // the single-update path. z_{j+1} is still evaluated as above.
  static constexpr long kVerify = 256;
  static bool affine_rows_of(const Sys& sys) {
    if constexpr (nz == 1)
      return false;
    else if constexpr (is_linear<Sys>())
      return true;
    else
      return (has_holonomic_v<Sys> || psi_at_start<typename Scheme::quadrature>::value) && linear_dynamics_of(sys);
  }
  static constexpr bool kAffineMap = is_linear<Sys>() && is_autonomous<Sys>() && nz == 0;
  static constexpr int U = 2 * n + (Scheme::contact ? 1 : 0);  // inputs of the step map
  using VecU = Vec<T, U>;
  using VecY = Vec<T, K + n>;

  VecU map_input() const {
    VecU u;  // element by element: Eigen's packet copies into a block of a 1-vector trip -Warray-bounds
    for (int i = 0; i < n; ++i) {
      u(i) = s_.q(i);
      u(n + i) = s_.p(i);
    }
    if constexpr (Scheme::contact) u(2 * n) = z_in_map_ ? s_.z : T(0);
    return u;
  }
  [[gnu::noinline]] void build_affine_map() {
    const State keep = s_;
    const StepOutput<T, n> keep_out = out_;
    affine_map_.build([&](const VecU& u) {
      for (int i = 0; i < n; ++i) {
        s_.q(i) = u(i);
        s_.p(i) = u(n + i);
      }
      if constexpr (Scheme::contact) s_.z = u(2 * n);
      VecK R, scale;
      residual(VecK::Zero(), R, scale, out_);
      const VecK x = newton_.solver().update(R);
      const VecN p = out_.p_next + newton_.linearization().dP * x;
      VecY y;
      for (int i = 0; i < K; ++i) y(i) = x(i);
      for (int i = 0; i < n; ++i) y(K + i) = p(i);
      return y;
    });
    s_ = keep;
    out_ = keep_out;
    if constexpr (Scheme::contact) z_in_map_ = !affine_map_.column_zero(2 * n);
  }
  // When no output depends on z_j (a Herglotz Lagrangian L - alpha z: its damping does not depend on the action),
  // the map is fed 0 for it: the same sums (0 * z added nothing), but z_{j+1}, solved after the map,
  // leaves the chain from one step's map to the next, which halves the oscillator's contact step.
  bool z_in_map_ = true;

  VecK solve_single_update(VecK x) {
    if constexpr (kAffineMap) {
      if (!affine_map_.ready()) build_affine_map();
      const VecY y = affine_map_.apply(map_input());
      for (int i = 0; i < K; ++i) x(i) = y(i);
      for (int i = 0; i < n; ++i) out_.p_next(i) = y(K + i);
    } else {
      if constexpr (m > 0) newton_.refresh_kept(x, [&](const VecK& y, MatK& J) { return refresh_constraint_block(y, J); });
      VecK R, scale;
      residual(x, R, scale, out_);
      const VecK dx = newton_.solver().update(R);
      x += dx;
      out_.p_next += newton_.linearization().dP * dx;
    }
    if constexpr (eliminate_z)
      out_.z_next = solved_z<T>(VecN(x.template head<n>()));
    else if constexpr (Scheme::contact)
      out_.z_next = Scheme::next_z(sys_, s_.t, h_, s_.q, VecN(x.template head<n>()), s_.z);
    last_updates_ = 1;
    ++total_updates_;
    if (++shortcut_steps_ % kVerify == 0 && !verify_single_update(x)) {
      // rows above round-off on linear dynamics: the step is finished by Newton, and the path is earned again
      single_update_ = false;
      ++shortcut_misses_;
      return solve(x);
    }
    return x;
  }
  // Whether one update solved the step: the rows at round-off, p_{j+1} where its derivative moved it, z_{j+1}'s
  // action row. A system declared linear that fails throws: its declaration is wrong. One with linear dynamics
  // whose rows alone are above round-off has the step finished by Newton instead (returns false): one update from
  // an exact J also leaves cond(J) eps of the update, and near a singular constraint that exceeds the bound
  // (measured: the Foucault pendulum's (13) passing near the origin, 15 times the bound, in 10 of 500 perturbed
  // runs of the hour). Its p_{j+1} check still throws: that is the declaration, not the conditioning.
  [[gnu::noinline]] bool verify_single_update(const VecK& x) {
    VecK R, scale;
    StepOutput<T, n> scratch;
    residual(x, R, scale, scratch);
    if constexpr (eliminate_z) verify_action_row(VecN(x.template head<n>()), out_.z_next);
    bool finite;
    const VecK w = x.cwiseAbs() + current().cwiseAbs();
    // p_{j+1} moved with the update by its derivative: its value at x where it is affine in x, as the declaration
    // promises. The rows alone would not tell: contact's rows take dL/dq at q_j only and stay affine in q_{j+1} for
    // any L quadratic in q', but its p_{j+1} = D2 L_d takes dL/dq at q_{j+1}.
    if constexpr (!kAffineMap) {
      using std::abs;
      const auto& dP = newton_.linearization().dP;
      for (int i = 0; i < n; ++i) {
        T size = abs(out_.p_next(i));
        for (int c = 0; c < K; ++c) size += abs(dP(i, c)) * w(c);
        const T diff = scratch.p_next(i) - out_.p_next(i);
        if (!StoppingRule<T, K>::scalar_at_roundoff(diff, size))
          throw NumericalFailure(s_.j + 1, "newton",
                                 std::string(is_linear<Sys>() ? "the system declares itself linear"
                                                              : "the system has linear dynamics (declared, or found in its formulas)") +
                                     ", but p_{j+1} is not affine in the unknowns: one update left it " +
                                     show(static_cast<double>(diff)) + " from its value at the solution (round-off scale " +
                                     show(static_cast<double>(size)) + "; t = " + show(static_cast<double>(s_.t)) + ")");
      }
    }
    if (StoppingRule<T, K>::residual_at_roundoff(R, scale, newton_.linearization().J, w, finite)) return true;
    if (!is_linear<Sys>() && finite) return false;
    fail(R, StoppingRule<T, K>::bounds(scale, newton_.linearization().J, w), 1,
         kAffineMap         ? "the system declares itself linear and autonomous, but its affine step map did not solve the step"
         : is_linear<Sys>() ? "the system declares itself linear, but one Newton update did not solve the step"
                            : "non-finite residual after one Newton update");
  }

  // The action row at the solution (z_{j+1} from one update of solved_z): at round-off when 𝓛 is affine in z_{j+1},
  // as a linear system's is.
  void verify_action_row(const VecN& q1, T z1) const {
    using std::abs;
    const T L = Scheme::quadrature::action(sys_, s_.t, h_, s_.q, q1, s_.z, z1);
    const T r = z1 - s_.z - L;
    const T scale = abs(z1) + abs(s_.z) + abs(L);
    if (!StoppingRule<T, K>::scalar_at_roundoff(r, scale))
      throw NumericalFailure(s_.j + 1, "newton",
                             "the system declares itself linear, but its action row z_{j+1} = z_j + L_d is not affine "
                             "in z_{j+1} (one update left " + show(static_cast<double>(r)) + " against the scale " +
                                 show(static_cast<double>(scale)) + "; t = " + show(static_cast<double>(s_.t)) + ")");
  }

  // The row farthest from its round-off bound (a non-finite one first), with its size against that bound: what
  // kept the step from being accepted.
  [[noreturn, gnu::cold, gnu::noinline]] void fail(const VecK& R, const VecK& bounds, int updates, const char* why) const {
    using std::abs;
    using std::isfinite;
    int worst = 0;
    T ratio = -1;
    for (int r = 0; r < K; ++r) {
      const T q = isfinite(R(r)) ? abs(R(r)) / bounds(r) : std::numeric_limits<T>::infinity();
      if (q > ratio) {
        ratio = q;
        worst = r;
      }
    }
    const std::string row = worst < n ? "dynamics row " + std::to_string(worst + 1)
                            : (nz == 1 && worst == n) ? std::string("action row")
                                                      : "constraint row " + std::to_string(worst - n - nz + 1);
    std::string detail = row + " " + show(static_cast<double>(R(worst)));
    if (isfinite(R(worst)))
      detail += ", " + show(static_cast<double>(ratio)) + " times its round-off bound " + show(static_cast<double>(bounds(worst)));
    throw NumericalFailure(s_.j + 1, "newton",
                           std::string(why) + " (after " + std::to_string(updates) + " updates: " + detail +
                               "; t = " + show(static_cast<double>(s_.t)) + ")");
  }

  Sys sys_;
  T h_, t0_;
  State s_;
  Predictor<T, K, n> predictor_;
  Newton<T, K, n, m> newton_;
  StepOutput<T, n> out_;  // p_{j+1}, z_{j+1} at the last iterate whose rows were evaluated
  int last_updates_ = 0;
  long total_updates_ = 0;
  bool single_update_ = false;
  bool shortcuts_ = true;
  bool affine_rows_;  // the rows are affine in the unknowns (affine_rows_of)
  long shortcut_steps_ = 0;
  long shortcut_misses_ = 0;
  AffineStepMap<T, U, K + n> affine_map_;
};

}  // namespace geomint::generic
