// The knife edge: its constrained equations derived from L and Phi, and the start on the constraint.
#include <catch2/catch.hpp>

#include "generic_checks.hpp"
#include "geomint/systems/knife_edge.hpp"

using namespace geomint;
using namespace geomint::testing;

TEST_CASE("knife edge: equations derived from L and Phi equal the hand-written ones", "[generic][equations]") {
  check_equations(systems::KnifeEdge{});
}

TEST_CASE("the kinetic-metric projection puts the initial velocity on the constraint", "[generic][equations]") {
  systems::KnifeEdge k;
  k.I = 3;  // a metric that is not a multiple of the identity
  const Vec<double, 3> q(0.3, -0.2, 0.7), v(1.0, 0.4, -0.5);
  const Vec<double, 3> w = generic::consistent_velocity(k, 0.0, q, v);
  CHECK(std::abs(generic::constraint<systems::KnifeEdge, double>(k, 0.0, q, w)(0)) < 1e-15);
  // the change is M^{-1} A^T mu with A = (sin th, -cos th, 0): the heading rate is untouched
  CHECK(w(2) == Approx(v(2)).epsilon(1e-15));
}

TEST_CASE("knife edge: Newton's Jacobian, lambda columns from the rows, is the full forward pass's", "[generic][newton]") {
  check_linearization(systems::KnifeEdge{}, 0.1);
}

TEST_CASE("knife edge: a kept Jacobian, its constraint block brought up to date, solves a step in one update, and with linear dynamics without a second evaluation",
          "[generic][newton]") {
  check_kept_jacobian(systems::KnifeEdge{}, 0.1, 2000);  // ten times the horizon: the shortcut's check runs
}

TEST_CASE("knife edge: contact-trapezoid with z_{j+1} solved inside the rows is the step with z_{j+1} an unknown", "[generic][newton]") {
  check_z_elimination(systems::KnifeEdge{}, 0.1, 2000);
}
