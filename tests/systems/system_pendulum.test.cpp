// The damped pendulum, the "add a system" example of docs/extending.md: its equations derived from L. (Its schemes,
// orders and Newton cost are tested through the registry in generic_systems.test.cpp, like any new system.)
#include <catch2/catch.hpp>

#include "generic_checks.hpp"
#include "geomint/systems/oscillator.hpp"
#include "geomint/systems/pendulum.hpp"

using namespace geomint;
using namespace geomint::testing;

TEST_CASE("pendulum: equations derived from L equal q'' = -sin q - alpha q', in both forms", "[generic][equations]") {
  check_equations(systems::Pendulum{});
}

namespace {
struct NotLinear : systems::Pendulum {
  static constexpr bool linear = true;
};
}  // namespace

TEST_CASE("a system that wrongly declares itself linear is caught by the single-update path's check", "[generic][newton]") {
  // The pendulum is not linear; declared so, the stepper takes one Newton update per step (the single-update path) and
  // its periodic check finds the residual above round-off.
  NotLinear sys;
  sys.q0 = 2.5;  // large swings: strongly nonlinear
  generic::Stepper<NotLinear, generic::LaMidpoint> st(sys, 0.1);
  st.start(sys.initial_position<double>(), sys.initial_velocity<double>());
  CHECK_THROWS_WITH([&] { for (int j = 0; j < 2000; ++j) st.step(); }(), Catch::Contains("declares itself linear"));
  // the oscillator, which is linear, runs the single-update path with its residual at round-off at every check
  systems::Oscillator osc;
  generic::Stepper<systems::Oscillator, generic::ContactLeft> so(osc, 0.1);
  so.start(osc.initial_position<double>(), osc.initial_velocity<double>());
  for (int j = 0; j < 20000; ++j) so.step();
  CHECK(so.jacobians() == 1);
  CHECK(so.total_updates() == 20000);
}

namespace {
struct NotLinearDynamics : systems::Pendulum {
  static constexpr bool linear_dynamics = true;
};
}  // namespace

TEST_CASE("a system that wrongly declares linear dynamics is caught by the single-update path's check", "[generic][newton]") {
  // The pendulum's L is not quadratic in q. Its `contact` rows are affine in q_{j+1} all the same (they take dL/dq
  // at q_j alone), but its p_{j+1} = D2 L_d takes dL/dq at q_{j+1}: declared so, the stepper takes one update a step,
  // p_{j+1} moves with it by its derivative, and the periodic check finds it off its value at the solution. (On `la`
  // the declaration would be true enough: L quadratic in q' makes its rows and p_{j+1} affine.)
  NotLinearDynamics sys;
  sys.q0 = 2.5;
  generic::Stepper<NotLinearDynamics, generic::ContactLeft> st(sys, 0.1);
  st.start(sys.initial_position<double>(), sys.initial_velocity<double>());
  CHECK_THROWS_WITH([&] { for (int j = 0; j < 2000; ++j) st.step(); }(), Catch::Contains("has linear dynamics"));
}

TEST_CASE("pendulum: Newton's Jacobian (z_{j+1} solved inside the rows for contact-trapezoid) is the full forward pass's", "[generic][newton]") {
  testing::check_linearization(systems::Pendulum{}, 0.1);
}

TEST_CASE("pendulum: contact-trapezoid with z_{j+1} solved inside the rows is the step with z_{j+1} an unknown", "[generic][newton]") {
  testing::check_z_elimination(systems::Pendulum{}, 0.1, 2000);
}
