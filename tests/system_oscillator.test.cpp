// The oscillator of Section 3.1 as a generic system: its closed forms (la, contact, la-midpoint, leapfrog,
// contact-sym) are the generic schemes' fast paths, and the generic residuals are their defining equations.
#include <catch2/catch.hpp>

#include "generic_checks.hpp"
#include "geomint/generic/schemes.hpp"
#include "geomint/systems/oscillator.hpp"
#include "paper_restatements.hpp"

using namespace geomint;
using namespace geomint::testing;
using V1 = Vec<double, 1>;

namespace {
V1 v1(double x) { return V1::Constant(x); }
}  // namespace

TEST_CASE("generic LA residuals on the oscillator are the closed forms' defining equations", "[generic][residual]") {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-1, 1);
  systems::Oscillator sys;
  for (int k = 0; k < 100; ++k) {
    sys.alpha = std::abs(u(rng));
    const double h = 0.05 + 0.2 * std::abs(u(rng)), qm = u(rng), q = u(rng), qp = u(rng);
    const Vec<double, 0> none;
    // (1) with the left quadrature is la's residual (the derivation of (7)), the midpoint one la-midpoint's
    CHECK(generic::LaLeft::residual(sys, 0.0, h, v1(qm), v1(q), v1(qp), none)(0) ==
          Approx(testing::la_residual(qm, q, qp, h, sys.alpha)).margin(1e-14));
    CHECK(generic::LaMidpoint::residual(sys, 0.0, h, v1(qm), v1(q), v1(qp), none)(0) ==
          Approx(testing::la_midpoint_residual(qm, q, qp, h, sys.alpha)).margin(1e-14));
    // the contact residual (3) with the paper's quadrature: D1 L_d + D2 L_d (1 + D3 L_d), D3 L_d = -h alpha
    const double z = u(rng);
    CHECK(generic::ContactLeft::residual(sys, 0.0, h, v1(qm), v1(q), v1(qp), z, z, z, none)(0) ==
          Approx(testing::contact_residual(qm, q, qp, h, sys.alpha)).margin(1e-14));
  }
}

TEST_CASE("oscillator closed forms (la, contact, la-midpoint, leapfrog, contact-sym) follow their generic schemes",
          "[generic][fast]") {
  for (double alpha : {0.01, 0.5}) {
    systems::Oscillator sys;
    sys.alpha = alpha;
    check_all_fast_paths(sys, 0.1, 200000);
  }
}

TEST_CASE("oscillator: equations derived from L equal the hand-written ones, the closed form solves them",
          "[generic][equations]") {
  check_equations(systems::Oscillator{});
  check_exact_solves(systems::Oscillator{}, 2.0);
}
