// The forced damped oscillator: its equations derived from L (with the time-dependent potential) and the
// closed-form steady state plus transient.
#include <catch2/catch.hpp>

#include "generic_checks.hpp"
#include "geomint/systems/forced_oscillator.hpp"

using namespace geomint;
using namespace geomint::testing;

TEST_CASE("forced oscillator: equations from L, both forms; the closed form solves them", "[generic][equations]") {
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
