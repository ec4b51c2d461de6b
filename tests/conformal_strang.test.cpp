// The README's "add a scheme" example: registered by name, second order, and conformal symplectic
// (the one-step map's determinant is exactly e^{-alpha h}).
#include <catch2/catch.hpp>

#include <cmath>

#include "geomint/modified/all_orders.hpp"
#include "geomint/oscillator_registry.hpp"
#include "geomint/schemes/conformal_strang.hpp"
#include "geomint/study.hpp"

using namespace geomint;

TEST_CASE("conformal-strang: area contracts at exactly the continuous rate", "[example][scheme]") {
  for (double h : {0.01, 0.1, 0.5})
    for (double a : {0.01, 0.3, 2.0}) {
      const auto m = modified::all_orders<schemes::ConformalStrang>(h, a);
      CHECK(m.det == Approx(std::exp(-a * h)).epsilon(1e-14));
      // hence its all-orders modified damping equals alpha exactly (where it oscillates)
      if (m.valid && m.oscillating) CHECK(m.a == Approx(a).epsilon(1e-11));
    }
}

TEST_CASE("conformal-strang: registered by name and second order", "[example][scheme]") {
  const auto& s = find_oscillator_scheme("conformal-strang");
  const auto hs = halving_sequence(0.2, 0.003);
  for (double a : {0.01, 0.1, 1.0}) {
    std::vector<double> e;
    for (double h : hs) e.push_back(s.max_error({a, -0.25, 0.75, 50}, h));
    INFO("alpha " << a);
    CHECK(fit_order(hs, e).slope == Approx(2).margin(0.05));
  }
}
