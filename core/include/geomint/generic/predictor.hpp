#pragma once
// The predictor of the generic step: the initial guess of a step's unknowns x = (q_{j+1}, [z_{j+1}], lambda).
//
// Quadratic extrapolation of x from the last three steps; for the first two steps, Taylor from the initial
// velocity and acceleration (q_1 = q_0 + h v_0 + h^2/2 a_0, then the central difference q_2 = 2 q_1 - q_0 +
// h^2 a_0). Its error is O(h^3) throughout, so a nonlinear step needs about two Newton updates from it. A start
// from a discrete state (no velocity) repeats x_0 until the history fills.
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
    x0_ = x0;
    v0_ = v0;
    a0_ = a0;
    history_ = 0;
  }
  // A start from a discrete state (q_j, p_j, z_j): no velocity to extrapolate from.
  void restart(const VecK& x0) {
    x0_ = x0;
    v0_ = VecN::Zero();
    a0_ = VecN::Zero();
    history_ = -1;
  }

  VecK predict(T h) const {
    if (history_ >= 2) return 3 * x0_ - 3 * x1_ + x2_;
    if (history_ == 1) {
      VecK x = 2 * x0_ - x1_;
      x.template head<n>() += h * h * a0_;
      return x;
    }
    VecK x = x0_;
    if (history_ == 0) x.template head<n>() += h * v0_ + h * h / 2 * a0_;
    return x;
  }

  // The unknowns of the step just taken (at the new current step) enter the history.
  void accept(const VecK& x) {
    x2_ = x1_;
    x1_ = x0_;
    history_ = history_ < 0 ? 1 : std::min(history_ + 1, 2);
    x0_ = x;
  }

  const VecK& last() const { return x0_; }  // the unknowns at the current step
  int history() const { return history_; }  // steps taken since the start (at most 2; -1: discrete start)

 private:
  VecN v0_ = VecN::Zero(), a0_ = VecN::Zero();
  VecK x0_ = VecK::Zero(), x1_ = VecK::Zero(), x2_ = VecK::Zero();
  int history_ = 0;
};

}  // namespace geomint::generic
