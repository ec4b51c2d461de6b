// Stability maps of the oscillator schemes: the classification from the schemes' own code against
// boundaries derived by hand from the closed-form trace and determinant.
#include <catch2/catch.hpp>

#include <cmath>

#include "geomint/modified/stability.hpp"

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
