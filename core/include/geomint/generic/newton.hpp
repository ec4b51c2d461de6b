#pragma once
// Newton's method for one generic step, in the parts a reader (or a faster replacement) can take one at a time:
//
//   Linearization     the Jacobian J = dR/dx of the step's rows, and the derivatives of its outputs p_{j+1},
//                     z_{j+1} with respect to the unknowns x (assembled by the stepper, by automatic differentiation)
//   JacobianInverse   the linear solve: the Newton update dx = -J^{-1} R
//   StoppingRule      when an iterate is accepted (at round-off), and when an update is negligible
//   Newton            the iteration with its Jacobian policy (simplified Newton, as stiff solvers do): the last
//                     Jacobian and its inverse are kept while they make a step converge after one update, and
//                     reassembled within a step whenever an update fails to shrink the residual by 4; with
//                     constraints, a kept one has its constraint block brought up to date at every step, and after
//                     a kept one had to be reassembled the next steps assemble their own for a while (below)
//
// Stopping rule, at round-off: an iterate is accepted when every row of the residual is within kappa eps of its
// scale (the sum of the magnitudes of the terms that cancel in it, plus |J| times the size of the unknowns: what
// rounding the solution itself would leave), or when the next update would move every unknown by less than
// kappa eps of its size; both with an absolute floor of kappa times the smallest subnormal (kappa = 16; below the
// normal range rounding is absolute, so a decayed run stays solvable). That last update is then applied without
// another evaluation, and p_{j+1}, z_{j+1} move with it by their derivatives from the last Jacobian: this final
// correction removes the error of order kappa eps that an accepted iterate may carry, which a kept Jacobian makes
// systematic (it would otherwise accumulate over a long run: measured on foucault-rotation, 4e-11 after 36000
// steps without it). A step that does not converge within max_updates fails with the residual norm and the count.
#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/LU>

#include "geomint/generic/system.hpp"

namespace geomint::generic {

// What a step outputs besides its unknowns: p_{j+1} and z_{j+1} at the last iterate whose rows were evaluated.
template <class T, int n>
struct StepOutput {
  Vec<T, n> p_next = Vec<T, n>::Zero();
  T z_next = 0;
};

template <class T, int K, int n>
struct Linearization {
  Mat<T, K, K> J = Mat<T, K, K>::Zero();      // dR/dx
  Mat<T, n, K> dP = Mat<T, n, K>::Zero();     // d p_{j+1} / dx
  Vec<T, K> dZ = Vec<T, K>::Zero();           // d z_{j+1} / dx
};

// The inverse, not an LU: K is a handful, an update is then multiplications only, and an inaccurate inverse (an
// ill-conditioned J) can only slow Newton down — the stopping rule decides when a step is done. Up to 4 x 4 it is
// Eigen's closed form (cofactors, a hundred flops); beyond, partial-pivoting LU, whose inverse goes through
// Eigen's general blocked triangular solves (on the knife edge's 4 x 4, 1500 instructions a factorization: a
// fifth of a step that assembles a Jacobian, measured with callgrind).
//
// With m multipliers the step's J has the saddle-point form [[B, C], [D, 0]]: B the rows' derivatives in the
// unknowns they depend on nonlinearly (q_{j+1}, [z_{j+1}]), C the multiplier columns (-A^T), D the constraint
// rows, and no row depends on lambda but through C (StepRows). Its inverse is then assembled from B^{-1} and the
// m x m matrix S = D B^{-1} C:
//   J^{-1} = [[B^{-1} - B^{-1} C S^{-1} D B^{-1},  B^{-1} C S^{-1}],  [S^{-1} D B^{-1},  -S^{-1}]],
// so that a kept Jacobian whose C and D were brought up to date (refresh_constraint) is inverted again from the
// B^{-1} it kept: a few dozen flops instead of a new K x K inverse. A B that is not invertible (a J that is only
// as a whole) falls back to the inverse of J.
template <class T, int K, int m = 0>
class JacobianInverse {
 public:
  static constexpr int Nx = K - m;
  using VecK = Vec<T, K>;
  using MatK = Mat<T, K, K>;
  void factor(const MatK& J) {
    if constexpr (m > 0) {
      binv_ = inverse_of(Mat<T, Nx, Nx>(J.template topLeftCorner<Nx, Nx>()));
      blocks_ = binv_.allFinite();
    }
    refresh_constraint(J);
  }
  // J's constraint rows D and multiplier columns C changed, B did not.
  void refresh_constraint(const MatK& J) {
    if constexpr (m > 0) {
      if (blocks_) {
        const Mat<T, Nx, m> binv_c = binv_ * J.template topRightCorner<Nx, m>();
        const Mat<T, m, m> sinv = inverse_of(Mat<T, m, m>(J.template bottomLeftCorner<m, Nx>() * binv_c));
        if (sinv.allFinite()) {
          const Mat<T, m, Nx> sinv_d_binv = sinv * J.template bottomLeftCorner<m, Nx>() * binv_;
          inverse_.template topLeftCorner<Nx, Nx>() = binv_ - binv_c * sinv_d_binv;
          inverse_.template topRightCorner<Nx, m>() = binv_c * sinv;
          inverse_.template bottomLeftCorner<m, Nx>() = sinv_d_binv;
          inverse_.template bottomRightCorner<m, m>() = -sinv;
          return;
        }
      }
    }
    inverse_ = inverse_of(J);
  }
  VecK update(const VecK& R) const { return -(inverse_ * R); }  // dx = -J^{-1} R

 private:
  template <int N>
  static Mat<T, N, N> inverse_of(const Mat<T, N, N>& M) {
    if constexpr (N <= 4)
      return M.inverse();
    else
      return Eigen::PartialPivLU<Mat<T, N, N>>(M).inverse();
  }
  MatK inverse_ = MatK::Zero();
  bool blocks_ = false;                         // B^{-1} is finite
  Mat<T, Nx, Nx> binv_ = Mat<T, Nx, Nx>::Zero();  // kept for refresh_constraint
};

template <class T, int K>
struct StoppingRule {
  using VecK = Vec<T, K>;
  using MatK = Mat<T, K, K>;
  static constexpr int kappa = 16;
  static T tolerance() { return T(kappa) * std::numeric_limits<T>::epsilon(); }
  static T floor() { return T(kappa) * std::numeric_limits<T>::denorm_min(); }

  // The round-off bound of every row: kappa eps times its scale, scale + |J| w (w: the sizes of the unknowns),
  // plus the floor.
  static VecK bounds(const VecK& scale, const MatK& J, const VecK& w) {
    using std::abs;
    const T tol = tolerance(), fl = floor();
    VecK b;
    for (int r = 0; r < K; ++r) {
      T s = scale(r);
      for (int c = 0; c < K; ++c) s += abs(J(r, c)) * w(c);
      b(r) = tol * s + fl;
    }
    return b;
  }
  // Every row within its round-off bound. `finite` is cleared when a row is not finite.
  static bool residual_at_roundoff(const VecK& R, const VecK& scale, const MatK& J, const VecK& w, bool& finite) {
    using std::abs;
    using std::isfinite;
    const VecK b = bounds(scale, J, w);
    bool ok = true;
    finite = true;
    for (int r = 0; r < K; ++r) {
      if (!isfinite(R(r))) finite = false;
      if (!(abs(R(r)) <= b(r))) ok = false;
    }
    return ok;
  }
  // One scalar row at round-off against its scale (the sum of its terms' sizes). The floor is compared, not
  // added: arithmetic on a subnormal costs a microcode assist.
  static bool scalar_at_roundoff(T r, T scale) {
    using std::abs;
    return abs(r) <= tolerance() * scale || abs(r) <= floor();
  }
  // The update moves every unknown by less than kappa eps of its size.
  static bool update_at_roundoff(const VecK& dx, const VecK& w) { return within(dx, w, tolerance()); }
  // The update is within two ulps of every unknown: applying it would change nothing worth an operation.
  static bool update_negligible(const VecK& dx, const VecK& w) {
    return within(dx, w, T(2) * std::numeric_limits<T>::epsilon());
  }

 private:
  static bool within(const VecK& dx, const VecK& w, T rel) {
    using std::abs;
    const T fl = floor();
    bool small = true;
    for (int c = 0; c < K; ++c)
      if (!(abs(dx(c)) <= rel * w(c) + fl)) small = false;
    return small;
  }
};

// The Newton iteration of one step with the Jacobian policy: a kept Jacobian that needs a second update within a
// step is reassembled at once, and a step that needed more than one update gets a fresh Jacobian at the next step.
// Why kept Jacobians failed on the constrained systems, and the two measures taken. The multiplier lambda is
// fixed by the constraint rows through the multiplier columns -A(t_j, q_j)^T, and those move from step to step
// (with q_j; with t_{j+1} for a rheonomic constraint): a step-old A turns the projection that determines lambda
// by O(h), and lambda's update, which carries the momentum divided by h, is then wrong by O(1) — a kept Jacobian
// contracted lambda's row by 0.04 or not at all (knife edge, h = 0.1), so every second step took three updates
// and a fresh Jacobian. So (1) a kept Jacobian has those rows and columns brought up to date at the start of
// every step (`refresh`, the stepper's cheap pass over the constraint alone; the dynamics block, which ages by
// O(h) relative, stays), and (2) where a kept Jacobian still fails within a step, the next `wait` steps
// assemble their own at the predictor: trying it costs a step two updates and a Jacobian where a fresh one costs
// one update; the wait doubles with every failure up to 64 steps and is cleared when a kept Jacobian converges
// in one update. Measured (bench_generic, Newton updates and Jacobians a step, before -> after): Foucault `la`
// 2.00 and 1.42 -> 1.00 and 0.00, `foucault-rotation` 1.56 and 1.00 -> 1.00 and 0.00, the particle in runs of T
// 2.00 and 1.00 -> 1.00 and 0.005, the knife edge's `la` in runs of T the same; the pendulum's, where kept
// Jacobians worked, unchanged.
template <class T, int K, int n, int m = 0>
class Newton {
 public:
  using VecK = Vec<T, K>;
  using Rule = StoppingRule<T, K>;
  static constexpr int max_updates = 40;

  // Solves from the guess x. start: the unknowns at the start of the step (with x, the sizes in the stopping
  // rule). residual(x, R, scale, out): the rows at x, their round-off scales, and the outputs there;
  // jacobian(x, R, scale, out, lin): the same and the linearization; refresh(x, J): brings a kept J up to date
  // in its constraint rows and multiplier columns, at the start of a step (returns whether it changed them);
  // fail(R, bounds, updates, why) throws (bounds: the rows' round-off bounds, so that the message can say how far
  // from them the rows are). Returns the solution; `updates` is the number of Newton updates it took. linear: the
  // rows are affine in x (the system declares it), so a last update within two ulps may be skipped.
  template <class Residual, class Jacobian, class Refresh, class Fail>
  VecK solve(VecK x, const VecK& start, Residual&& residual, Jacobian&& jacobian, Refresh&& refresh,
             StepOutput<T, n>& out, Fail&& fail, int& updates, bool linear) {
    updates = 0;
    bool fresh = false;
    const bool kept = !need_jacobian_;  // this step starts with the Jacobian of an earlier step
    bool kept_failed = false;           // ... which had to be reassembled within it
    VecK R, scale;
    T last_size = -1;  // max |R| at the previous iterate (-1: none yet)
    for (;;) {
      if (need_jacobian_) {
        jacobian(x, R, scale, out, lin_);
        solver_.factor(lin_.J);
        ++jacobians_;
        need_jacobian_ = false;
        fresh = true;
      } else {
        if (updates == 0 && refresh(x, lin_.J)) solver_.refresh_constraint(lin_.J);
        residual(x, R, scale, out);
      }
      const VecK w = x.cwiseAbs() + start.cwiseAbs();
      bool finite;
      const bool ok = Rule::residual_at_roundoff(R, scale, lin_.J, w, finite);
      const VecK dx = solver_.update(R);
      if (ok || Rule::update_at_roundoff(dx, w)) {
        // converged: the last update is applied without another evaluation (the outputs move with it by their
        // derivatives); it removes the bias a kept Jacobian leaves. Within two ulps it is skipped for a linear
        // system, whose one update is exact up to rounding (this keeps its check off the critical path). Not for
        // a nonlinear one: there a kept Jacobian leaves a bias of the same sign step after step, and a
        // composition's many stages add it up (la-midpoint with kahanli8 on the pendulum, h = 0.00625, T = 10:
        // max error 2e-10 with the skip, 5e-14 without).
        if (!(linear && Rule::update_negligible(dx, w)) && dx.allFinite()) {
          x += dx;
          out.p_next += lin_.dP * dx;
          out.z_next += lin_.dZ.dot(dx);
        }
        break;
      }
      if (!finite || updates >= max_updates)
        fail(R, Rule::bounds(scale, lin_.J, w), updates, finite ? "Newton did not converge" : "non-finite residual");
      if (!dx.allFinite()) fail(R, Rule::bounds(scale, lin_.J, w), updates, "singular Newton matrix");
      x += dx;
      ++updates;
      // A Jacobian that converges slowly is reassembled at the current iterate: a kept one from an earlier step, and
      // also one assembled earlier in this step that no longer contracts the residual by 4 an update (assembled at
      // the predictor, far from the solution where J changes fast: the Kepler problem's midpoint rule near
      // pericentre contracted by 0.48 an update and failed after 40, 1.1-2.5 times its round-off bound).
      const T size = R.cwiseAbs().maxCoeff();
      if (updates >= 2 && (!fresh || !(size <= last_size / 4))) {
        need_jacobian_ = true;
        if (!fresh) kept_failed = true;
      }
      last_size = size;
    }
    // keep the Jacobian for the next step only if it made this one converge after one update, and not while
    // waiting after a kept one failed (above)
    if (kept && kept_failed) {
      backoff_ = std::min(std::max(2 * backoff_, 1), 64);
      wait_ = backoff_;
    } else if (kept && updates <= 1) {
      backoff_ = 0;
    }
    if (!kept && wait_ > 0) --wait_;
    if (updates > 1 || wait_ > 0) need_jacobian_ = true;
    return x;
  }

  // Brings the kept Jacobian's constraint block up to date at x, for a step that takes its one update outside
  // solve (the stepper's single-update path); refresh as in solve.
  template <class Refresh>
  void refresh_kept(const VecK& x, Refresh&& refresh) {
    if (refresh(x, lin_.J)) solver_.refresh_constraint(lin_.J);
  }

  void invalidate() {  // the next evaluation assembles a fresh Jacobian, and the policy starts over
    need_jacobian_ = true;
    backoff_ = wait_ = 0;
  }
  bool jacobian_kept() const { return !need_jacobian_; }
  const Linearization<T, K, n>& linearization() const { return lin_; }
  const JacobianInverse<T, K, m>& solver() const { return solver_; }
  long jacobians() const { return jacobians_; }

 private:
  bool need_jacobian_ = true;
  int backoff_ = 0;  // the wait after the last failure of a kept Jacobian
  int wait_ = 0;     // steps left before a Jacobian may be kept again
  Linearization<T, K, n> lin_;
  JacobianInverse<T, K, m> solver_;
  long jacobians_ = 0;
};

}  // namespace geomint::generic
