#pragma once
// The predictor of the generic step: the initial guess of a step's unknowns x = (q_{j+1}, [z_{j+1}], lambda).
//
// Polynomial extrapolation of x from the last steps, of degree 2, 3 or 4 (through the last 3, 4 or 5 points:
// errors O(h^3), O(h^4), O(h^5)); for the first two steps, Taylor from the initial velocity and acceleration
// (q_1 = q_0 + h v_0 + h^2/2 a_0, then the central difference q_2 = 2 q_1 - q_0 + h^2 a_0), quadratic until five
// points are known. The degree is chosen at every step by the step just taken: the one whose prediction of it
// came closest. A higher degree is not always better: its coefficients grow (they sum in magnitude to 7, 15, 31),
// so where h is not small against the motion's time scale it amplifies more than it gains, and the last step's
// errors measure that directly. Why not always 2: one Newton update from a fresh Jacobian squares the guess's
// error, so it reaches round-off only from a guess within about sqrt(eps) (bench_generic, Newton updates a step
// in runs of T: the pendulum's `la-midpoint` 2.00 -> 1.42, the knife edge's `la-midpoint` and `la-trapezoid`
// 3.37 -> 2.56). A start from a discrete state (no velocity) repeats x_0 until the history fills.
#include <algorithm>

#include "geomint/generic/system.hpp"

namespace geomint::generic {

template <class T, int K, int n>
class Predictor {
 public:
  using VecK = Vec<T, K>;
  using VecN = Vec<T, n>;

  // A start from a continuous state: the unknowns at step 0, and the initial velocity and acceleration.
  void start(const VecK& x0, const VecN& v0, const VecN& a0) {
    clear(x0);
    v0_ = v0;
    a0_ = a0;
    history_ = 0;
  }
  // A start from a discrete state (q_j, p_j, z_j): no velocity to extrapolate from.
  void restart(const VecK& x0) {
    clear(x0);
    v0_ = VecN::Zero();
    a0_ = VecN::Zero();
    history_ = -1;
  }

  VecK predict(T h) const {
    if (history_ >= 2) {
      VecK x = d_[0] + d_[1] + d_[2];
      if (history_ >= 4 && degree_ >= 3) x += d_[3];
      if (history_ >= 4 && degree_ == 4) x += d_[4];
      return x;
    }
    if (history_ == 1) {
      VecK x = d_[0] + d_[1];
      x.template head<n>() += h * h * a0_;
      return x;
    }
    VecK x = d_[0];
    if (history_ == 0) x.template head<n>() += h * v0_ + h * h / 2 * a0_;
    return x;
  }

  // The unknowns of the step just taken (at the new current step) enter the history: the backward differences
  // at x. The extrapolation of degree k missed x by its (k+1)-th difference there, so the degree for the next
  // step is the one whose difference is smallest.
  void accept(const VecK& x) {
    const bool full = history_ >= 4;  // five points before x: its fifth difference is known
    VecK next = x;                    // the differences at x, one by one
    for (int i = 0; i < 5; ++i) {
      const VecK d = next;
      next = d - d_[i];
      d_[i] = d;
    }
    history_ = history_ < 0 ? 1 : std::min(history_ + 1, 4);
    if (full) {
      const T e2 = d_[3].cwiseAbs().maxCoeff(), e3 = d_[4].cwiseAbs().maxCoeff(), e4 = next.cwiseAbs().maxCoeff();
      degree_ = e4 <= e3 && e4 <= e2 ? 4 : e3 <= e2 ? 3 : 2;
    }
  }

  const VecK& last() const { return d_[0]; }  // the unknowns at the current step
  int history() const { return history_; }     // steps taken since the start (at most 4; -1: discrete start)
  int degree() const { return history_ >= 4 ? degree_ : history_ >= 2 ? 2 : history_; }  // of the next prediction

 private:
  void clear(const VecK& x0) {
    d_[0] = x0;
    for (int i = 1; i < 5; ++i) d_[i] = VecK::Zero();
    degree_ = 2;
  }
  VecN v0_ = VecN::Zero(), a0_ = VecN::Zero();
  VecK d_[5] = {VecK::Zero(), VecK::Zero(), VecK::Zero(), VecK::Zero(), VecK::Zero()};  // x and its backward differences 1-4
  int history_ = 0;
  int degree_ = 2;
};

}  // namespace geomint::generic
