#pragma once
// What an observer of a run sees at each step, on the generic step and on every closed-form fast path alike, so
// one observer serves both (generic/system_schemes.hpp says how a system runs its fast paths).
#include "geomint/generic/schemes.hpp"

namespace geomint::generic {

// What an observer of a run sees at step j (generic and fast paths alike): t_j, q_j, the discrete momentum
// p_j (the scheme's own Legendre transform), z_j (contact), and the impulse lambda of the step into q_j.
template <class T, int n, int m>
struct StepView {
  long j;
  T t;
  const Vec<T, n>& q;
  const Vec<T, n>& p;
  T z;
  const Vec<T, m>& lambda;
};

}  // namespace geomint::generic
