// The bivariate truncated series of the automatic modified equations: Laurent division by h with exact
// cancellation, precision tracking, and the math functions against their Taylor expansions.
#include <catch2/catch.hpp>

#include <cmath>

#include "geomint/constants.hpp"
#include "geomint/modified/series.hpp"

using namespace geomint::modified;
using S = BiSeries<3, 6, 2>;

TEST_CASE("series: 1/(1 + h) and 1/h", "[series]") {
  const S h = S::h();
  const S r = 1.0 / (1.0 + h);
  for (int k = 0; k <= 6; ++k) {
    CHECK(r.known(0, k));
    CHECK(r.coeff(0, k) == (k % 2 ? -1.0 : 1.0));
  }
  const S inv = 1.0 / h;
  CHECK(inv.p == series_exact);  // a monomial stays exact
  CHECK(inv.coeff(0, -1) == 1.0);
  CHECK((inv * h).coeff(0, 0) == 1.0);
}

TEST_CASE("series: a difference quotient divides by h exactly and loses one degree of precision", "[series]") {
  // q(eps) = 1 + 2 eps + 3 eps^2 + 5 eps^3 known below total degree 5; (q(eps + h) - q(eps))/h
  auto shifted = [](double s) {
    S x;
    const double c[4] = {1, 2, 3, 5};
    for (int j = 0; j <= 3; ++j)
      for (int k = 0; j + k <= 3; ++k) {
        double b = 1;
        for (int i = 0; i < k; ++i) b = b * (j + k - i) / (i + 1);  // binom(j + k, k)
        x.at(j, k) = c[j + k] * b * std::pow(s, k);
      }
    x.fit();
    x.p = 5;
    return x;
  };
  const S d = (shifted(1) - shifted(0)) / S::h();
  CHECK(d.p == 4);
  CHECK(d.coeff(0, -1) == 0.0);                  // the constant cancelled exactly
  CHECK(d.coeff(0, 0) == 2.0);                   // q'(0)
  CHECK(d.coeff(1, 0) == 6.0);                   // q''(eps) at order eps
  CHECK(d.coeff(0, 1) == 3.0);                   // h q''/2
  CHECK(d.coeff(0, 2) == 5.0);                   // h^2 q'''/6
  CHECK_FALSE(d.known(0, 4));
}

TEST_CASE("series: sin, cos, exp, log, sqrt against their Taylor coefficients", "[series]") {
  // x = 0.3 + h + 2 eps: f(x) coefficient of eps^j h^k = f^(j+k)(0.3) binom(j+k, j) 2^j / (j+k)!
  const S x = 0.3 + S::h() + 2.0 * S::eps();
  auto check = [&](const S& fx, auto df) {
    for (int j = 0; j <= 3; ++j)
      for (int k = 0; k <= 6 - j; ++k) {
        double fact = 1, b = 1;
        for (int i = 2; i <= j + k; ++i) fact *= i;
        for (int i = 0; i < j; ++i) b = b * (j + k - i) / (i + 1);
        INFO("j " << j << " k " << k);
        CHECK(fx.coeff(j, k) == Approx(df(j + k) * b * std::pow(2.0, j) / fact).epsilon(1e-13).margin(1e-15));
      }
  };
  check(sin(x), [](int r) { return std::sin(0.3 + r * geomint::pi / 2); });
  check(cos(x), [](int r) { return std::cos(0.3 + r * geomint::pi / 2); });
  check(exp(x), [](int) { return std::exp(0.3); });
  check(log(x), [](int r) {
    if (r == 0) return std::log(0.3);
    double f = 1;
    for (int i = 2; i < r; ++i) f *= i;
    return (r % 2 ? 1.0 : -1.0) * f / std::pow(0.3, r);
  });
  check(sqrt(x), [](int r) {
    double c = 1;
    for (int i = 0; i < r; ++i) c *= 0.5 - i;
    return c * std::pow(0.3, 0.5 - r);
  });
  // exp(log(x)) = x: the intermediate coefficients grow like (2/0.3)^(j+k), so the bound is relative to them
  const S lx = log(x), e = exp(lx) - x;
  for (int j = 0; j <= 3; ++j)
    for (int k = 0; j + k <= 6; ++k) {
      INFO("j " << j << " k " << k << ": " << e.coeff(j, k));
      CHECK(std::abs(e.coeff(j, k)) < 1e-14 * std::pow(2 / 0.3, j + k));
    }
}

TEST_CASE("series: a function of negative powers of h and a non-invertible division are refused", "[series]") {
  CHECK_THROWS_AS(sin(1.0 / S::h()), std::domain_error);
  CHECK_THROWS_AS(1.0 / S::eps(), std::domain_error);
}
