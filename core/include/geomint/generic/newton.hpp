#pragma once
// Newton's method for one generic step, in the parts a reader (or a faster replacement) can take one at a time:
//
//   Linearization     the Jacobian J = dR/dx of the step's rows, and the derivatives of its outputs p_{j+1},
//                     z_{j+1} with respect to the unknowns x (assembled by the stepper, by automatic differentiation)
//   JacobianInverse   the linear solve: the Newton update dx = -J^{-1} R
//   StoppingRule      when an iterate is accepted (at round-off), and when an update is negligible
//   Newton            the iteration with its Jacobian policy (simplified Newton, as stiff solvers do): the last
//                     Jacobian and its inverse are kept while they make a step converge after one update, and
//                     refreshed within a step whenever an update fails to shrink the residual by 4
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
template <class T, int K>
class JacobianInverse {
 public:
  using VecK = Vec<T, K>;
  using MatK = Mat<T, K, K>;
  void factor(const MatK& J) {
    if constexpr (K <= 4)
      inverse_ = J.inverse();
    else
      inverse_ = Eigen::PartialPivLU<MatK>(J).inverse();
  }
  VecK update(const VecK& R) const { return -(inverse_ * R); }  // dx = -J^{-1} R

 private:
  MatK inverse_ = MatK::Zero();
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
// step is refreshed at once, and a step that needed more than one update gets a fresh Jacobian at the next step.
template <class T, int K, int n>
class Newton {
 public:
  using VecK = Vec<T, K>;
  using Rule = StoppingRule<T, K>;
  static constexpr int max_updates = 40;

  // Solves from the guess x. start: the unknowns at the start of the step (with x, the sizes in the stopping
  // rule). residual(x, R, scale, out): the rows at x, their round-off scales, and the outputs there;
  // jacobian(x, R, scale, out, lin): the same and the linearization. fail(R, bounds, updates, why) throws (bounds:
  // the rows' round-off bounds, so that the message can say how far from them the rows are). Returns the
  // solution; `updates` is the number of Newton updates it took. linear: the rows are affine in x (the system
  // declares it), so a last update within two ulps may be skipped.
  template <class Residual, class Jacobian, class Fail>
  VecK solve(VecK x, const VecK& start, Residual&& residual, Jacobian&& jacobian, StepOutput<T, n>& out, Fail&& fail,
             int& updates, bool linear) {
    updates = 0;
    bool fresh = false;
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
      // A Jacobian that converges slowly is refreshed at the current iterate: a kept one from an earlier step, and
      // also one assembled earlier in this step that no longer contracts the residual by 4 an update (assembled at
      // the predictor, far from the solution where J changes fast: the Kepler problem's midpoint rule near
      // pericentre contracted by 0.48 an update and failed after 40, 1.1-2.5 times its round-off bound).
      const T size = R.cwiseAbs().maxCoeff();
      if (updates >= 2 && (!fresh || !(size <= last_size / 4))) need_jacobian_ = true;
      last_size = size;
    }
    // keep the Jacobian for the next step only if it made this one converge after one update
    if (updates > 1) need_jacobian_ = true;
    return x;
  }

  void invalidate() { need_jacobian_ = true; }  // the next evaluation assembles a fresh Jacobian
  bool jacobian_kept() const { return !need_jacobian_; }
  const Linearization<T, K, n>& linearization() const { return lin_; }
  const JacobianInverse<T, K>& solver() const { return solver_; }
  long jacobians() const { return jacobians_; }

 private:
  bool need_jacobian_ = true;
  Linearization<T, K, n> lin_;
  JacobianInverse<T, K> solver_;
  long jacobians_ = 0;
};

}  // namespace geomint::generic
