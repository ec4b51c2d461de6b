// Numerical failure is data: a run that blows up stops with the step index and the quantity; inside a
// sweep it becomes a missing value (NaN in the TSV, no point in the figure), never a crash.
#include <catch2/catch.hpp>

#include <fstream>
#include <string>
#include <sstream>

#include "geomint/error.hpp"
#include "geomint/registry.hpp"
#include "geomint/systems/oscillator.hpp"
#include "helpers.hpp"

using namespace geomint;

TEST_CASE("an unstable run reports the step where the state stopped being finite", "[failure]") {
  // contact at h = 2.5 > 2 is unstable (see the stability maps): |q| grows geometrically, and z (which sums
  // h L ~ h |p|^2) with twice its rate, until it overflows.
  // The first non-finite step, found by a plain loop:
  long first_bad = -1;
  {
    OscState<double> r{-0.25, 0.75, 0};
    for (long j = 1; j <= 100000 && first_bad < 0; ++j) {
      systems::Oscillator::Contact::step(r, 2.5, 0.01);
      if (!std::isfinite(r.q) || !std::isfinite(r.p) || !std::isfinite(r.z)) first_bad = j;
    }
  }
  REQUIRE(first_bad > 100);  // it takes hundreds of steps to overflow from O(1)
  // the registry's run (the closed form, finiteness checked per block of steps) names the exact step
  try {
    find_system("oscillator").run({{"alpha", 0.01}, {"T", 2.5 * 100000}}, "contact", 2.5, Path::fast, 1000);
    FAIL("no failure reported");
  } catch (const NumericalFailure& e) {
    CHECK(e.step == first_bad);
    CHECK(e.quantity == "state");
    CHECK(std::string(e.what()).find("step " + std::to_string(e.step)) != std::string::npos);
    CHECK(std::string(e.what()).find("system oscillator, scheme contact (fast), h = 2.5") != std::string::npos);
  }
}

TEST_CASE("a Newton failure says which row kept the step from round-off, and by how much", "[failure][newton]") {
  // la-midpoint on the pendulum at h = 4: Newton wanders on sin((q0 + q1)/2) and stops after max_updates (at h = 2
  // it converges, in 12 updates a step, since a Jacobian that stops contracting is reassembled)
  try {
    find_system("pendulum").run({{"T", 4}}, "la-midpoint", 4, Path::generic, 1);
    FAIL("no failure reported");
  } catch (const NumericalFailure& e) {
    const std::string what = e.what();
    INFO(what);
    CHECK(e.quantity == "newton");
    CHECK(what.find("system pendulum, scheme la-midpoint (generic), h = 4: Newton did not converge (after 40 updates: "
                    "dynamics row 1 ") != std::string::npos);
    // the size against the bound, both as numbers: the row is not at round-off by a ratio far above 1
    const auto times = what.find(" times its round-off bound ");
    REQUIRE(times != std::string::npos);
    const auto comma = what.rfind(", ", times);
    REQUIRE(comma != std::string::npos);
    CHECK(std::stod(what.substr(comma + 2, times - comma - 2)) > 1e6);
  }
}

TEST_CASE("a sweep records a blown-up run as a missing value and still completes", "[failure]") {
  const auto dir = testing::fresh_dir("failure-sweep");
  // h = 2.5 over T = 5000 (2000 steps): contact is unstable beyond h = 2 and la beyond
  // h = alpha + sqrt(alpha^2 + 4) ~ 2.01, so both overflow before the end.
  const auto r = testing::run_program(
      "convergence", "--system oscillator --h-max 2.5 --h-min 2.5 --T 5000 --alpha 0.01 --schemes contact la --out " +
                         dir.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  std::ifstream in(dir / "oscillator_convergence.tsv");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string tsv = ss.str();
  CHECK(tsv.find("oscillator\tcontact\t2.5\t2000\tnan") != std::string::npos);
  CHECK(tsv.find("oscillator\tla\t2.5\t2000\tnan") != std::string::npos);
  CHECK(std::filesystem::exists(dir / "oscillator_convergence.png"));
}
