// The automatic-modified-equation programs: bad input gets one line, exit 2, nothing written; the table that
// `make figures` writes has the promised columns and the pendulum's F_0 = -sin q - alpha q'.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>

#include "geomint/plots/figure.hpp"
#include "helpers.hpp"

using namespace geomint::testing;

TEST_CASE("modified-equation programs reject bad input", "[programs][modified]") {
  check_rejected("modified_equation", "--order 7", "order must be in");
  check_rejected("modified_equation", "--order=-1", "order must be in");
  check_rejected("modified_equation", "--system nosuch", "unknown system 'nosuch'");
  check_rejected("modified_equation", "--schemes nosuch", "unknown scheme 'nosuch'");
  check_rejected("modified_equation", "--q 0.1 0.2", "degrees of freedom");
  check_rejected("modified_equation", "--q nan", "q must be finite");
  // the system's parameters are options of their own, as in every program with --system
  check_rejected("modified_equation", "--alpha abc", "the argument ('abc') for option '--alpha' is invalid");
  check_rejected("modified_equation", "--nosuch 1", "unrecognised option '--nosuch'");
  check_rejected("modified_equation", "--alpha -1", "alpha must be a non-negative");
  check_rejected("modified_equation", "--system pendulum --kappa 1", "unrecognised option '--kappa'");  // the knife edge's
  check_rejected("modified_agreement", "--orders 9 --h-max 0.2", "orders must be in");
  check_rejected("modified_agreement", "--orders 1 2 --h-max 0.1 0.2 0.3", "one per order");
  check_rejected("modified_agreement", "--systems knife-edge", "is constrained");
  check_rejected("modified_agreement", "--h-max 0.3 --T 1", "not an integer");
  check_rejected("modified_agreement", "--tol 1", "tol must be in");
  check_rejected("nonholonomic_modified", "--systems pendulum", "has no constraint");
  check_rejected("nonholonomic_modified", "--radii 1", "radii must be in");
  check_rejected("modified_agreement", "--alpha=-1", "alpha must be a non-negative");
  check_rejected("nonholonomic_modified", "--alpha nan", "alpha must be a non-negative");
}

TEST_CASE("modified_equation writes F_k per scheme, k and component", "[programs][modified]") {
  const auto dir = fresh_dir("modified-equation");
  const auto r = run_program("modified_equation", "--order 2 --out " + dir.string());
  REQUIRE(r.exit_code == 0);
  const auto t = geomint::plots::read_tsv(dir / "modified_equation.tsv");
  CHECK(t.columns == std::vector<std::string>{"system", "scheme", "alpha", "k", "component", "value"});
  int found = 0;
  for (std::size_t i = 0; i < t.rows.size(); ++i)
    if (t.number(i, "k") == 0 && t.text(i, "component") == "F0") {
      CHECK(t.number(i, "value") == Approx(-std::sin(0.5) - 0.1 * 0.3).epsilon(1e-15));
      ++found;
    }
  CHECK(found == 2);  // la and contact
  std::filesystem::remove_all(dir);
}
