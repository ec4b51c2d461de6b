#pragma once
// The affine step map: the whole step of a linear, autonomous system as one affine map of its inputs,
//   (q_{j+1}, [z_{j+1}], lambda, p_{j+1}) = c + G (q_j, p_j, [z_j]),
// built once per run from the scheme's own rows (the solution at the zero input and at each unit input), so a
// step is one small matrix-vector product. The stepper verifies it like every shortcut: every kVerify-th step is
// re-solved and its residual must be at round-off (generic/stepper.hpp).
#include "geomint/generic/system.hpp"

namespace geomint::generic {

// U inputs, Y outputs.
template <class T, int U, int Y>
class AffineStepMap {
 public:
  using VecU = Vec<T, U>;
  using VecY = Vec<T, Y>;

  // solve_at(u): the step's outputs from the inputs u (exact for an affine step: one Newton update from anywhere).
  template <class SolveAt>
  void build(SolveAt&& solve_at) {
    c_ = solve_at(VecU::Zero());
    for (int i = 0; i < U; ++i) G_.col(i) = solve_at(VecU::Unit(i)) - c_;
    ready_ = true;
  }
  bool ready() const { return ready_; }
  void reset() { ready_ = false; }
  VecY apply(const VecU& u) const { return c_ + G_ * u; }
  // No output depends on input i.
  bool column_zero(int i) const { return (G_.col(i).array() == T(0)).all(); }

 private:
  bool ready_ = false;
  VecY c_ = VecY::Zero();
  Mat<T, Y, U> G_ = Mat<T, Y, U>::Zero();
};

}  // namespace geomint::generic
