// The damped pendulum, the README's "add a system" example: its equations derived from L. (Its schemes,
// orders and Newton cost are tested through the registry in generic_systems.test.cpp, like any new system.)
#include <catch2/catch.hpp>

#include "generic_checks.hpp"
#include "geomint/systems/pendulum.hpp"

using namespace geomint;
using namespace geomint::testing;

TEST_CASE("pendulum: equations derived from L equal q'' = -sin q - alpha q', in both forms", "[generic][equations]") {
  check_equations(systems::Pendulum{});
}
