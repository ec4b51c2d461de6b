// The forced damped oscillator: its equations derived from L (with the time-dependent potential) and the
// closed-form steady state plus transient.
#include <catch2/catch.hpp>

#include "generic_checks.hpp"
#include "geomint/systems/forced_oscillator.hpp"

using namespace geomint;
using namespace geomint::testing;

TEST_CASE("forced oscillator: equations from L, both forms, the closed form solves them", "[generic][equations]") {
  systems::ForcedOscillator f;
  check_equations(f);
  for (double t : {0.0, 3.3, 40.0}) check_exact_solves(f, t);
  f.dq0 = 0.2;  // off the steady state: the transient is in the closed form too
  f.dv0 = -0.1;
  for (double t : {0.5, 7.0}) check_exact_solves(f, t);
  // started on the steady state: the exact solution is the steady state at every time
  const systems::ForcedOscillator g;
  CHECK(g.exact(12.3).q(0) == Approx(g.steady(12.3).q(0)).epsilon(1e-15));
}

namespace {
struct NotAutonomous : systems::ForcedOscillator {  // linear, but its forcing depends on t
  static constexpr bool autonomous = true;
};
}  // namespace

TEST_CASE("a linear system that wrongly declares itself autonomous is caught by the affine step map's check", "[generic][newton]") {
  // Declared autonomous, the stepper builds one affine step map at the first single-update step and ignores the forcing's
  // time dependence from then on; the full Newton re-solve of every 256th step finds the residual above round-off.
  NotAutonomous sys;
  generic::Stepper<NotAutonomous, generic::LaLeft> st(sys, 0.1);
  st.start(sys.initial_position<double>(), sys.initial_velocity<double>());
  CHECK_THROWS_WITH([&] { for (int j = 0; j < 600; ++j) st.step(); }(),
                    Catch::Contains("declares itself linear and autonomous"));
  // the same system as declared (not autonomous) runs the single-update path at round-off
  const systems::ForcedOscillator ok;
  generic::Stepper<systems::ForcedOscillator, generic::LaLeft> so(ok, 0.1);
  so.start(ok.initial_position<double>(), ok.initial_velocity<double>());
  for (int j = 0; j < 600; ++j) so.step();
  CHECK(so.jacobians() == 1);
}
