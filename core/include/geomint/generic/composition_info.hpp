#pragma once
// add_composition_operations<Sys>(info): what only compositions have (SystemInfo::symmetry, composition_steps,
// base_steps), put into the system's registry entry in its generated translation unit, next to
// make_system_info<Sys>(): a Composition<Sys, G> reuses the Stepper<Sys, G> instantiated there, so the compositions
// add one thin layer per symmetric base scheme and nothing per family. Heavy: include it only there and in tests of
// typed pieces.
#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>
#include <vector>

#include "geomint/registry.hpp"
#include "geomint/error.hpp"
#include "geomint/generic/composition.hpp"
#include "geomint/generic/system_info.hpp"
#include "geomint/timing.hpp"

namespace geomint::generic {

template <class Sys, class G>
SymmetryDefect symmetry_defect(const Sys& sys, double h, long steps) {
  constexpr int n = Sys::dof, m = Sys::constraints;
  require(steps >= 0, "steps must be non-negative");
  Stepper<Sys, G> forward(sys, h);
  forward.start(sys.template initial_position<double>(), sys.template initial_velocity<double>());
  for (long j = 0; j < steps; ++j) forward.step();
  const auto x0 = forward.state();
  forward.step();
  const auto x1 = forward.state();
  Stepper<Sys, G> back(sys, -h, x1.t);
  back.restart(0, x1.q, x1.p, x1.z);
  back.step();
  const auto& b = back.state();
  SymmetryDefect d;
  d.dq = (b.q - x0.q).template lpNorm<Eigen::Infinity>();
  d.dz = std::abs(b.z - x0.z);
  const Vec<double, n> dp = b.p - x0.p;
  d.dp = dp.template lpNorm<Eigen::Infinity>();
  d.dp_tangent = d.dp;
  if constexpr (m > 0) {
    // the part of dp orthogonal to the rows of A(t_j, q_j), where the forward step applied its impulse
    const Mat<double, m, n> A = sys.constraint_matrix(x0.t, x0.q);
    const Mat<double, m, m> AAt = A * A.transpose();
    const Vec<double, n> normal = A.transpose() * Eigen::PartialPivLU<Mat<double, m, m>>(AAt).solve(A * dp);
    d.dp_tangent = (dp - normal).template lpNorm<Eigen::Infinity>();
  }
  d.q = x0.q.template lpNorm<Eigen::Infinity>();
  d.p = x0.p.template lpNorm<Eigen::Infinity>();
  return d;
}

template <class Sys>
void add_composition_operations(SystemInfo& info) {
  info.composition_steps = [](const ParamValues& pv, const std::string& name, double h, long N) {
    const Sys sys = make_system<Sys>(pv);
    sys.validate();
    require(std::isfinite(h) && h != 0 && N >= 0, "steps needs a finite nonzero h and N >= 0");
    return visit_composition<Sys>(name, [&](auto g, const CompositionFamily& f) {
      Composition<Sys, decltype(g)> c(sys, f, h);
      c.start(sys.template initial_position<double>(), sys.template initial_velocity<double>());
      for (long j = 0; j < N; ++j) c.step();
      do_not_optimize(c.state().q(0));
      return c.total_updates();
    });
  };
  info.base_steps = [](const ParamValues& pv, const std::string& base, double h, long N) {
    const Sys sys = make_system<Sys>(pv);
    sys.validate();
    require(std::isfinite(h) && h != 0 && N >= 0, "base_steps needs a finite nonzero h and N >= 0");
    return visit_composable<Sys>(base, [&](auto g) {
      Stepper<Sys, decltype(g)> st(sys, h);
      st.start(sys.template initial_position<double>(), sys.template initial_velocity<double>());
      for (long j = 0; j < N; ++j) st.step();
      do_not_optimize(st.state().q(0));
      return st.total_updates();
    });
  };
  info.symmetry = [](const ParamValues& pv, const std::string& base, double h, long steps) {
    const Sys sys = make_system<Sys>(pv);
    sys.validate();
    return visit_composable<Sys>(base, [&](auto g) { return symmetry_defect<Sys, decltype(g)>(sys, h, steps); });
  };
}

}  // namespace geomint::generic
