// Uses each layer of an installed geomint, and fails if what it links is not what it compiled against: the core's
// registry (the damped pendulum, la-midpoint against Boost.Odeint), the studies' observed order and the modified
// equations, numeric and as GiNaC formulas.
#include <cmath>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "geomint/modified/automatic_registry.hpp"
#include "geomint/registry.hpp"
#include "geomint/study.hpp"

namespace {
int failures = 0;
void check(bool ok, const std::string& what) {
  std::printf("%s: %s\n", ok ? "ok" : "FAILED", what.c_str());
  if (!ok) ++failures;
}
}  // namespace

int main() try {
  using namespace geomint;
  const SystemInfo& pendulum = find_system("pendulum");
  const ParamValues params;  // the defaults: alpha = 0.1, q0 = 1, p0 = 0, T = 20
  const double T = pendulum.horizon(params);

  // la-midpoint's error at h and h/2 against Odeint on the grid of h/2 (tolerance 1e-12: 1e4 below the errors)
  const std::vector<double> h = {0.1, 0.05};
  const Reference ref = pendulum.reference(params, h[1], step_count(h[1], T), ReferenceKind::odeint, 1e-12);
  std::vector<double> err;
  for (double hk : h) err.push_back(pendulum.max_error(params, "la-midpoint", hk, Path::fast, ref));
  const double order = observed_orders(h, err)[1];
  std::printf("pendulum la-midpoint: max error %.10e at h = 0.1, %.10e at h = 0.05, order %.4f\n", err[0], err[1],
              order);
  // The value of geomint's own build (its Python module gives the same: python/pip_install.cmake)
  const double known = 5.3164828465e-03;
  check(std::abs(err[0] / known - 1) < 1e-6, "error at h = 0.1 is 5.3164828465e-03 to 1e-6");
  check(std::abs(order - 2) < 0.05, "la-midpoint is second order");

  // The modified equation at (q, v) = (1, 0): F_0 is the pendulum's own acceleration -sin q - alpha v; the
  // midpoint rule is symmetric, so F_1 = 0.
  const auto& modified = modified::find_modified_system("pendulum");
  const auto point = modified.at(params, "la-midpoint", 2, 0, {1.0}, {0.0}, 0, false);
  std::printf("modified equation at q = 1: F_0 = %.16g, F_1 = %.3g, F_2 = %.16g\n", point.F_at(0, 0),
              point.F_at(1, 0), point.F_at(2, 0));
  check(std::abs(point.F_at(0, 0) + std::sin(1.0)) < 1e-14, "F_0 = -sin(1)");
  check(std::abs(point.F_at(1, 0)) < 1e-14, "F_1 = 0");
  // The same as formulas (GiNaC): the order-0 row is the equation of motion, in sin of the angle and alpha.
  const auto formulas = modified.formulas(params, "la-midpoint", 2, 60, false);
  std::string f0;
  for (const auto& row : formulas.rows)
    if (row.quantity == "F" && row.k == 0) f0 = row.text;
  std::printf("formulas to order %d, F at h^0: %s\n", formulas.K, f0.c_str());
  check(formulas.K == 2 && f0.find("sin(") != std::string::npos && f0.find("alpha") != std::string::npos,
        "the order-0 formula is the equation of motion");
  return failures == 0 ? 0 : 1;
} catch (const std::exception& e) {
  std::fprintf(stderr, "consumer: %s\n", e.what());
  return 1;
}
