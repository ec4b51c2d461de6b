// Stability maps of the oscillator schemes: the classification from the schemes' own code against
// boundaries derived by hand from the closed-form trace and determinant.
#include <catch2/catch.hpp>

#include <cmath>

#include "geomint/modified/stability.hpp"
#include "geomint/registry.hpp"

using namespace geomint;
using namespace geomint::modified;

namespace {
Region region_at(const std::string& s, double h, double a) { return classify(all_orders_by_name(s, h, a), a); }
}  // namespace

TEST_CASE("closed-form boundaries: LA unstable beyond h = alpha + sqrt(alpha^2 + 4)", "[stability]") {
  // |tr| <= 1 + det with tr = (2 + h a - h^2)/(1 + h a), det = 1/(1 + h a)  <=>  h^2 - a h - 4 <= 0
  for (double a : {0.001, 0.01, 0.1, 1.0, 3.0}) {
    const double hc = a + std::sqrt(a * a + 4);
    INFO("alpha " << a);
    CHECK(region_at("la", hc * (1 - 1e-7), a) != Region::unstable);
    CHECK(region_at("la", hc * (1 + 1e-7), a) == Region::unstable);
  }
}

TEST_CASE("closed-form boundaries: contact flips sign beyond h alpha = 1, unstable beyond h alpha = 2 or h = 2",
          "[stability]") {
  // det = 1 - h a changes sign at h a = 1 (with tr > 0, i.e. h < sqrt 2): one eigenvalue turns negative
  for (double a : {1.0, 2.0, 5.0}) {
    INFO("alpha " << a);
    CHECK(region_at("contact", (1 - 1e-7) / a, a) != Region::sign_flip);
    CHECK(region_at("contact", (1 + 1e-7) / a, a) == Region::sign_flip);
    CHECK(region_at("contact", (2 - 1e-7) / a, a) == Region::sign_flip);  // det -> -1
    CHECK(region_at("contact", (2 + 1e-7) / a, a) == Region::unstable);
  }
  for (double a : {0.001, 0.01, 0.1}) {  // -tr <= 1 + det  <=>  (2 - h a)(2 - h^2/2) >= 0  <=>  h <= 2
    INFO("alpha " << a);
    CHECK(region_at("contact", 2 * (1 - 1e-7), a) != Region::unstable);
    CHECK(region_at("contact", 2 * (1 + 1e-7), a) == Region::unstable);
  }
}

TEST_CASE("la-printed: unstable beyond h = sqrt(4 + 2 alpha)", "[stability]") {
  for (double a : {0.01, 0.1, 1.0}) {
    const double hc = std::sqrt(4 + 2 * a);
    INFO("alpha " << a);
    CHECK(region_at("la-printed", hc * (1 - 1e-7), a) != Region::unstable);
    CHECK(region_at("la-printed", hc * (1 + 1e-7), a) == Region::unstable);
  }
}

TEST_CASE("every analytic boundary separates the regions the schemes' code produces", "[stability]") {
  std::vector<double> alphas;
  for (int i = 0; i < 60; ++i) alphas.push_back(1e-3 * std::pow(1e4, i / 59.0));
  for (const char* s : {"la", "la-printed", "contact"}) {
    const auto bs = analytic_boundaries(s, alphas, 1e-2, 10);
    REQUIRE(bs.size() >= alphas.size());  // at least the stability boundary on every row
    for (const auto& b : bs) {
      // probe at 1e-7 relative, or a quarter of the gap to the next boundary on the same row (the
      // sign-flip slivers below the stability limits are narrower than 1e-7 at small alpha)
      double eps = 1e-7 * b.h;
      for (const auto& o : bs)
        if (o.alpha == b.alpha && o.h != b.h) eps = std::min(eps, std::abs(o.h - b.h) / 4);
      INFO(s << " h " << b.h << " alpha " << b.alpha << " probe " << eps);
      CHECK(region_at(s, b.h - eps, b.alpha) == b.below);
      CHECK(region_at(s, b.h + eps, b.alpha) == b.above);
    }
  }
}

TEST_CASE("spectral radius: det of LA is 1/(1 + h alpha), of contact 1 - h alpha", "[stability]") {
  for (double h : {0.01, 0.1, 0.5})
    for (double a : {0.01, 0.3, 1.0}) {
      CHECK(all_orders_by_name("la", h, a).det == Approx(1 / (1 + h * a)).epsilon(1e-14));
      CHECK(all_orders_by_name("contact", h, a).det == Approx(1 - h * a).epsilon(1e-14));
    }
}

TEST_CASE("the generic linear-map classification reproduces the oscillator maps from the closed forms",
          "[stability][generic]") {
  // The generic one-step matrix (the Newton step built from L, on unit vectors) against the closed forms' matrices
  // (long double), classified by eigenvalues against the continuous generator; cells within 1e-9 of a region
  // boundary of the closed-form classification are skipped (either answer is round-off there).
  const auto& osc = find_system("oscillator");
  const std::pair<const char*, const char*> pairs[] = {
      {"la", "la"}, {"contact", "contact"}, {"la-midpoint", "la-midpoint"}, {"la-trapezoid", "leapfrog"},
      {"contact-trapezoid", "contact-sym"}};
  int compared = 0;
  for (const auto& [gen, closed] : pairs)
    for (double h : {0.013, 0.1, 0.5, 1.3, 1.95, 2.2, 4.0, 9.0})
      for (double a : {0.002, 0.05, 0.3, 1.0, 1.9, 2.5, 7.0}) {
        const ParamValues pv{{"alpha", a}};
        const auto M = osc.one_step_matrix(pv, gen, h, Path::generic);
        const auto C = osc.continuous_matrix(pv);
        const auto g = classify_linear_map(M, C, 2, h);
        const AllOrders m = all_orders_by_name(closed, h, a);
        bool near = false;
        for (double dt : {-1e-9, 1e-9})
          for (double dd : {-1e-9, 1e-9})
            near = near || classify(all_orders_from_trace_det(m.tr + dt, m.det + dd, h), a) != classify(m, a);
        INFO(gen << " h = " << h << " alpha = " << a);
        // a double root (tr^2 = 4 det, e.g. la at h = 9, alpha = 7) moves by sqrt(eps) under round-off
        const double disc = double(m.tr * m.tr - 4 * m.det);
        CHECK(g.spectral_radius == Approx(m.spectral_radius).epsilon(std::abs(disc) < 1e-10 ? 1e-7 : 1e-12));
        if (!near) {
          CHECK(g.region == classify(m, a));
          ++compared;
        }
        if (m.valid && std::abs(std::log(double(m.det))) > 1e-6) CHECK(g.decay_ratio == Approx(m.a / a).epsilon(1e-8));
      }
  CHECK(compared > 250);  // nearly every cell of the 5 x 8 x 7 grid
}

TEST_CASE("the coupled oscillators' generator has the two modes' eigenvalues", "[stability][generic]") {
  const auto& sys = find_system("coupled-oscillators");
  const double a = 0.3, k = 4;
  const auto C = sys.continuous_matrix({{"alpha", a}, {"kappa", k}});
  const auto M = sys.one_step_matrix({{"alpha", a}, {"kappa", k}}, "la-trapezoid", 1e-3, Path::generic);
  const auto c = classify_linear_map(M, C, 4, 1e-3);
  CHECK(c.region == Region::faithful);
  // a small step resolves both modes: frequency ratios 1 + O(h^2), contraction rate exact to O(h^2)
  CHECK(c.freq_low == Approx(1).epsilon(1e-5));
  CHECK(c.freq_high == Approx(1).epsilon(1e-5));
  CHECK(c.decay_ratio == Approx(1).epsilon(1e-5));
  // the stiff mode (frequency 3) makes Stormer-Verlet unstable beyond h = 2/3
  CHECK(classify_linear_map(sys.one_step_matrix({{"alpha", 0.0}, {"kappa", k}}, "la-trapezoid", 0.66, Path::generic), C, 4, 0.66).region !=
        Region::unstable);
  CHECK(classify_linear_map(sys.one_step_matrix({{"alpha", 0.0}, {"kappa", k}}, "la-trapezoid", 0.68, Path::generic), C, 4, 0.68).region ==
        Region::unstable);
  CHECK_THROWS_WITH(find_system("pendulum").one_step_matrix({}, "la", 0.1, Path::generic), Catch::Contains("needs a linear system"));
}
