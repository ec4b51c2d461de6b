#pragma once
// Closed-form fast paths. A hand-derived step that solves exactly the equations of a generic scheme on one
// system is registered as FastPath<GenericScheme, ClosedForm>; the system says how to run it (its
// `run_fast<ClosedForm>`), and tests/generic_fast_paths.test.cpp holds every pair to step-by-step agreement.
#include <tuple>

#include "geomint/generic/system.hpp"

namespace geomint::generic {

template <class Generic, class Closed>
struct FastPath {
  using generic = Generic;
  using closed = Closed;
};

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

template <class Sys, class = void>
struct fast_paths_of {
  using type = std::tuple<>;
};
template <class Sys>
struct fast_paths_of<Sys, std::void_t<typename Sys::fast_paths>> {
  using type = typename Sys::fast_paths;
};

}  // namespace geomint::generic
