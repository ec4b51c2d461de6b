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

TEST_CASE("oscillator: contact-trapezoid with z_{j+1} solved inside the rows (one update, the affine step map) is the "
          "step with z_{j+1} an unknown", "[generic][newton]") {
  for (double alpha : {0.01, 0.5}) {
    systems::Oscillator sys;
    sys.alpha = alpha;
    check_z_elimination(sys, 0.1, 2000);
  }
}

namespace {
// Linear in (q, q') with a Rayleigh force, but its Herglotz Lagrangian is quadratic in z: a `linear` declaration that
// only the action row shows to be wrong (the rows in q_{j+1} stay affine).
struct QuadraticInZ : systems::Oscillator {
  template <class S>
  S herglotz(const S& t, const Vec<S, 1>& q, const Vec<S, 1>& v, const S& z) const {
    return lagrangian(t, q, v) - alpha * z - z * z / 2;
  }
};
}  // namespace

TEST_CASE("a linear system whose Herglotz Lagrangian is not affine in z is caught by the action row's check", "[generic][newton]") {
  // Declared linear, contact-trapezoid takes z_{j+1} from one Newton update of its action row, exact only when the
  // row is affine in z_{j+1}; the check of every 256th step of the shortcuts finds the row above round-off.
  QuadraticInZ sys;
  generic::Stepper<QuadraticInZ, generic::ContactTrapezoid> st(sys, 0.1);
  st.start(sys.initial_position<double>(), sys.initial_velocity<double>());
  CHECK_THROWS_WITH([&] { for (int j = 0; j < 600; ++j) st.step(); }(), Catch::Contains("is not affine in z_{j+1}"));
}
