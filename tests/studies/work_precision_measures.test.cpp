// What work_precision measures besides q (WorkPrecisionOptions::measures): the energy, a momentum and a formula of
// the state, each max_k |Q(run) - Q(reference)| on the grid of the largest h, for the schemes and the baselines
// alike. Held to the same quantity computed another way, and to the orders of the methods that carry it.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "geomint/error.hpp"
#include "geomint/registry.hpp"
#include "geomint/work_precision.hpp"

using namespace geomint;

namespace {

// The undamped oscillator: E = (q'^2 + q^2)/2, p = q', a closed-form reference.
const ParamValues conservative{{"alpha", 0}, {"T", 10}};

WorkPrecisionOptions options() {
  WorkPrecisionOptions opt;
  opt.schemes = {"la", "la-midpoint"};
  opt.hs = {0.1, 0.05, 0.025};
  opt.baselines = {"odeint-rk4"};
  opt.reps = 1;
  opt.measures = {"energy", "e=(v1^2 + q1^2)/2", "p1"};
  return opt;
}

std::vector<double> column(const WorkPrecisionStudy& s, const std::string& method, std::size_t measure) {
  std::vector<double> out;
  for (const auto& p : s.points)
    if (p.method == method) out.push_back(p.errors.at(measure));
  return out;
}

}  // namespace

TEST_CASE("work_precision's measures: the energy by AD equals the energy written as a formula, for every method",
          "[work_precision][measures]") {
  const SystemInfo& sys = find_system("oscillator");
  const WorkPrecisionStudy s = work_precision_study(sys, {conservative}, options());
  REQUIRE(s.points.size() == 9);
  for (const auto& p : s.points) {
    INFO(p.method << " " << p.knob << " = " << p.value << ": energy " << p.errors[1] << ", formula " << p.errors[2]);
    REQUIRE(p.errors.size() == 4);  // q, energy, the formula, p1
    CHECK(p.errors[3] > 0);  // p1 (la-midpoint keeps the energy: its error there is round-off)
    CHECK(std::abs(p.errors[1] - p.errors[2]) <= 1e-14);
  }
}

// On the undamped oscillator the quantities have laws of their own: the midpoint rule keeps every quadratic invariant,
// so la-midpoint's energy error is round-off; rk4 multiplies the energy by |R(ih)|^2 = 1 - h^6/72 + h^8/576 a step, so
// its error after T/h steps is E0 (1 - |R(ih)|^(2T/h)), of order 5 in h; the momentum p1 = q' errs at each method's
// order (2, 4) as the phase drifts.
TEST_CASE("work_precision's measures follow the laws of the methods: invariants kept, energy and momentum at order",
          "[work_precision][measures]") {
  const SystemInfo& sys = find_system("oscillator");
  const WorkPrecisionStudy s = work_precision_study(sys, {conservative}, options());
  const auto midpoint_energy = column(s, "la-midpoint", 1), rk4_energy = column(s, "odeint-rk4", 1);
  const double E0 = (0.75 * 0.75 + 0.25 * 0.25) / 2;  // the oscillator's default start (q0, p0) = (-0.25, 0.75)
  for (std::size_t k = 0; k < 3; ++k) {
    const double h = options().hs[k];
    INFO("h = " << h << ": la-midpoint " << midpoint_energy[k] << ", rk4 " << rk4_energy[k]);
    CHECK(midpoint_energy[k] <= 1e-14);
    // |R(ih)|^2 = 1 - delta exactly, delta = h^6/72 - h^8/576; the energy lost over N steps without cancellation
    const double delta = std::pow(h, 6) / 72 - std::pow(h, 8) / 576;
    const double law = -E0 * std::expm1(static_cast<double>(std::lround(10 / h)) * std::log1p(-delta));
    // the law is exact; what remains is round-off in the states, at most about N ulp(E0) = 400 x 5.6e-17 in all
    CHECK(rk4_energy[k] == Approx(law).epsilon(1e-9).margin(5e-14));
  }
  for (const auto& [method, order] : {std::pair<std::string, double>{"la-midpoint", 2}, {"odeint-rk4", 4}}) {
    const auto e = column(s, method, 3);  // p1
    for (std::size_t k = 0; k + 1 < e.size(); ++k) {
      INFO(method << ", p1, h = " << options().hs[k] << ": " << e[k] << " then " << e[k + 1]);
      CHECK(std::log2(e[k] / e[k + 1]) == Approx(order).margin(0.1));
    }
  }
}

TEST_CASE("work_precision's energy measure of a scheme is its run's energy column against the closed form",
          "[work_precision][measures]") {
  const SystemInfo& sys = find_system("oscillator");
  const WorkPrecisionStudy s = work_precision_study(sys, {conservative}, options());
  const auto energy = column(s, "la", 1);
  const double h_out = 0.1;
  for (std::size_t k = 0; k < 3; ++k) {
    const double h = options().hs[k];
    const long every = std::lround(h_out / h);
    // the stepper's own energy column, at t = k h_out, against E of the exact solution there
    const Run run = sys.run(conservative, "la", h, Path::fast, every);
    const Reference ref = sys.reference(conservative, h_out, 100, ReferenceKind::exact, 1e-13);
    double worst = 0;
    for (std::size_t j = 0; j < run.j.size(); ++j) {
      const double q = ref.q[j], v = ref.v[j];
      worst = std::max(worst, std::abs(run.energy[j] - (v * v + q * q) / 2));
    }
    INFO("h = " << h << ": the study " << energy[k] << ", by hand " << worst);
    CHECK(energy[k] > 1e-4);  // la's energy error is O(h)
    CHECK(std::abs(energy[k] - worst) <= 1e-14);
  }
}

TEST_CASE("work_precision refuses a measure it cannot take, before any work", "[work_precision][measures]") {
  const SystemInfo& sys = find_system("oscillator");
  auto refused = [&](std::vector<std::string> measures, const std::string& why, bool at_steps = false) {
    WorkPrecisionOptions opt = options();
    opt.measures = std::move(measures);
    opt.at_steps = at_steps;
    if (at_steps) {
      opt.tols = {1e-6};
      opt.baselines = {"odeint-dopri5"};
    }
    CHECK_THROWS_WITH(check_work_precision(sys, {conservative}, opt), Catch::Contains(why));
  };
  refused({"momentum"}, "unknown measure 'momentum' (known: energy, p1..p1");
  refused({"p2"}, "system 'oscillator' has 1 coordinate (p1..p1)");
  refused({"r=q1 + x"}, "column 6: unknown symbol 'x' (known: t, q1..q1, v1..v1, pi, alpha, q0, p0, T)");
  refused({"r=q1 +"}, "formula 'q1 +'");
  refused({"energy", "energy"}, "measure 'energy' is asked twice");
  refused({"energy=q1"}, "names a measure of its own");
  refused({"2r=q1"}, "a formula's measure is <name>=<formula>");
  refused({"energy"}, "the measures are taken on the output grid", true);
  CHECK_NOTHROW(check_work_precision(sys, {conservative}, options()));
}
