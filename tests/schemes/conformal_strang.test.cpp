// A scheme a system declares beyond the generic ones (the oscillator's conformal-strang): in the one registry
// by its name, second order, and conformal symplectic (the one-step map's determinant is exactly e^{-alpha h}).
#include <catch2/catch.hpp>

#include <cmath>

#include "geomint/error.hpp"
#include "geomint/modified/all_orders.hpp"
#include "geomint/registry.hpp"
#include "geomint/study.hpp"

using namespace geomint;

TEST_CASE("conformal-strang: area contracts at exactly the continuous rate", "[example][scheme]") {
  for (double h : {0.01, 0.1, 0.5})
    for (double a : {0.01, 0.3, 2.0}) {
      const auto m = modified::all_orders_by_name("conformal-strang", h, a);
      CHECK(m.det == Approx(std::exp(-a * h)).epsilon(1e-14));
      // hence its all-orders modified damping equals alpha exactly (where it oscillates)
      if (m.valid && m.oscillating) CHECK(m.a == Approx(a).epsilon(1e-11));
    }
}

TEST_CASE("conformal-strang: registered by name and second order", "[example][scheme]") {
  const auto& osc = find_system("oscillator");
  CHECK(osc.scheme("conformal-strang").order == 2);
  CHECK_FALSE(osc.scheme("conformal-strang").generic);
  const auto hs = halving_sequence(0.2, 0.003);
  for (double a : {0.01, 0.1, 1.0}) {
    const ParamValues pv{{"alpha", a}, {"q0", -0.25}, {"p0", 0.75}, {"T", 50}};
    std::vector<double> e;
    for (double h : hs)
      e.push_back(osc.max_error(pv, "conformal-strang", h, Path::fast, osc.reference(pv, h, step_count(h, 50), ReferenceKind::exact, 0)));
    INFO("alpha " << a);
    CHECK(fit_order(hs, e).slope == Approx(2).margin(0.05));
  }
}

TEST_CASE("a scheme a system declares has no generic step and says so", "[example][scheme][registry]") {
  const auto& osc = find_system("oscillator");
  CHECK_THROWS_WITH(osc.run({}, "la-printed", 0.1, Path::generic, 1),
                    Catch::Contains("la-printed") && Catch::Contains("no generic step"));
  // the paper's names of closed forms are aliases of the one entry
  CHECK(&osc.scheme("leapfrog") == &osc.scheme("la-trapezoid"));
  CHECK(&osc.scheme("contact-sym") == &osc.scheme("contact-trapezoid"));
  CHECK(osc.scheme_names() == std::vector<std::string>{"la", "contact", "la-midpoint", "la-trapezoid", "contact-trapezoid",
                                                       "la-printed", "conformal-strang"});
}
