// The forward-mode dual number of the generic core, checked against Eigen's AutoDiffScalar (first
// derivatives) and against hand-derived second derivatives (nested duals).
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include <Eigen/Core>
#include <unsupported/Eigen/AutoDiff>

#include "geomint/generic/dual.hpp"

using namespace geomint;

namespace {
// A function of two variables using every elementary function the systems use.
template <class S>
S f(const S& x, const S& y) {
  using std::atan2;
  using std::cos;
  using std::exp;
  using std::log;
  using std::sin;
  using std::sqrt;
  using std::tanh;
  return sin(x) * exp(y) / (S(1) + x * x) + atan2(y, x) + sqrt(S(2) + cos(x * y)) - log(S(3) + y * y) +
         tanh(x - y) + pow(S(1.5) + x * x, 1.5) - S(2) * x / (y * y + S(1));
}
}  // namespace

TEST_CASE("dual numbers: gradients equal Eigen AutoDiffScalar's", "[dual]") {
  using AD = Eigen::AutoDiffScalar<Eigen::Vector2d>;
  using D = Dual<double, 2>;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-2, 2);
  double worst = 0;
  for (int k = 0; k < 200; ++k) {
    const double x = u(rng), y = u(rng);
    const AD a = f(AD(x, 2, 0), AD(y, 2, 1));
    const D d = f(D::variable(x, 0), D::variable(y, 1));
    worst = std::max({worst, std::abs(a.value() - d.v), std::abs(a.derivatives()(0) - d.d[0]),
                      std::abs(a.derivatives()(1) - d.d[1])});
  }
  CHECK(worst < 1e-13);
}

TEST_CASE("nested dual numbers give second derivatives", "[dual]") {
  // g(x, y) = x^3 y^2 + sin(x y): g_xx = 6 x y^2 - y^2 sin(x y), g_xy = 6 x^2 y + cos(x y) - x y sin(x y)
  using In = Dual<double, 2>;
  using Out = Dual<In, 2>;
  const double x = 0.7, y = -1.3;
  const Out X = Out::variable(In::variable(x, 0), 0), Y = Out::variable(In::variable(y, 1), 1);
  using std::sin;
  const Out g = X * X * X * Y * Y + sin(X * Y);
  CHECK(g.d[0].d[0] == Approx(6 * x * y * y - y * y * std::sin(x * y)).epsilon(1e-14));
  CHECK(g.d[0].d[1] == Approx(6 * x * x * y + std::cos(x * y) - x * y * std::sin(x * y)).epsilon(1e-14));
  CHECK(g.d[1].d[0] == Approx(g.d[0].d[1]).epsilon(1e-15));
  CHECK(primal(g) == Approx(x * x * x * y * y + std::sin(x * y)).epsilon(1e-15));
}
