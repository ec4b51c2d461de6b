// The generic schemes' residuals against the paper's printed equations and the hand-derived closed forms'
// own residuals, written independently: the same equation, restated.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "geomint/generic/schemes.hpp"
#include "geomint/systems/foucault.hpp"
#include "geomint/systems/oscillator.hpp"

using namespace geomint;
using V1 = Vec<double, 1>;
using V2 = Vec<double, 2>;

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
    // (1) with the left quadrature is schemes::La's residual (the derivation of (7)), the midpoint one LaMidpoint's
    CHECK(generic::LaLeft::residual(sys, 0.0, h, v1(qm), v1(q), v1(qp), none)(0) ==
          Approx(schemes::La::residual(qm, q, qp, h, sys.alpha)).margin(1e-14));
    CHECK(generic::LaMidpoint::residual(sys, 0.0, h, v1(qm), v1(q), v1(qp), none)(0) ==
          Approx(schemes::LaMidpoint::residual(qm, q, qp, h, sys.alpha)).margin(1e-14));
    // the contact residual (3) with the paper's quadrature: D1 L_d + D2 L_d (1 + D3 L_d), D3 L_d = -h alpha
    const double z = u(rng);
    CHECK(generic::ContactLeft::residual(sys, 0.0, h, v1(qm), v1(q), v1(qp), z, z, z, none)(0) ==
          Approx(schemes::Contact::residual(qm, q, qp, h, sys.alpha)).margin(1e-14));
  }
}

TEST_CASE("generic nonholonomic residuals on the Foucault pendulum are (15) and (18) as printed", "[generic][residual]") {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-1, 1);
  systems::Foucault sys;
  sys.scene.alpha = 0.05;
  sys.scene.Omega = 0.1;  // a large s, so the constraint terms are not lost in round-off
  const FoucaultParams<double> p(sys.scene);
  for (int k = 0; k < 100; ++k) {
    const double h = 0.1;
    const V2 qm(u(rng), u(rng)), q(u(rng), u(rng)), qp(u(rng), u(rng));
    const double lambda1 = u(rng);
    // (15): rows 1-2 are (D1 L_d + D2 L_d + F_d^- - lambda A) / m with the generic lambda = lambda_1
    const auto la15 = schemes::LaNh::residual(p, qm, q, qp, lambda1, h);
    const V2 la = generic::LaLeft::residual(sys, 0.0, h, qm, q, qp, Vec<double, 1>(Vec<double, 1>::Constant(lambda1))) / p.m;
    CHECK(la(0) == Approx(la15(0)).margin(1e-13));
    CHECK(la(1) == Approx(la15(1)).margin(1e-13));
    // (18): rows 1-2 are the generic rows divided by m h, with the generic lambda = h lambda_1
    const auto c18 = schemes::ContactNh::residual(p, qm, q, qp, lambda1, h);
    const V2 c = generic::ContactLeft::residual(sys, 0.0, h, qm, q, qp, 0.0, 0.0, 0.0,
                                                Vec<double, 1>(Vec<double, 1>::Constant(h * lambda1))) / (p.m * h);
    CHECK(c(0) == Approx(c18(0)).margin(1e-12));
    CHECK(c(1) == Approx(c18(1)).margin(1e-12));
    // the third row of both: the discrete constraint (13) o Psi
    const double phid = generic::discrete_constraint<systems::Foucault, generic::la_quadrature::Left>(sys, 0.0, h, q, qp)(0);
    CHECK(phid == Approx(la15(2)).margin(1e-14));
    CHECK(phid == Approx(c18(2)).margin(1e-14));
  }
}
