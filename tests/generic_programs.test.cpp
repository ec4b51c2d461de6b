// The programs that take any system by name: bad input refused with one line, and what they write.
#include <catch2/catch.hpp>

#include <cmath>
#include <fstream>
#include <iterator>
#include <sstream>

#include "geomint/plots/figure.hpp"
#include "helpers.hpp"

using namespace geomint;
using namespace geomint::testing;

TEST_CASE("generic programs refuse bad input with one line, exit 2, and write nothing", "[programs][generic]") {
  const struct {
    const char *program, *args, *expect;
  } bad[] = {
      {"integrate", "--system nosuch", "unknown system 'nosuch'"},
      {"integrate", "--system pendulum --scheme nosuch", "unknown scheme 'nosuch' for system 'pendulum'"},
      {"integrate", "--system pendulum --h 0.3", "not an integer"},
      {"integrate", "--system pendulum --alpha -1", "alpha must be a non-negative"},
      {"integrate", "--system pendulum --alpha 0.1 0.2", "--alpha takes one value"},
      {"integrate", "--system pendulum --beta 1", "unrecognised option"},
      {"integrate", "--system knife-edge --path nosuch", "unknown path 'nosuch'"},
      {"integrate", "--system pendulum --every 0", "every must be a positive integer"},
      {"convergence", "--system nosuch", "unknown system"},
      {"convergence", "--system pendulum --schemes la nosuch", "unknown scheme 'nosuch'"},
      {"convergence", "--system pendulum --h-max 0", "h_max must be a positive"},
      {"convergence", "--system knife-edge --reference exact", "no closed-form solution"},
      {"convergence", "--system pendulum --reference nosuch", "unknown reference"},
      {"convergence", "--system pendulum --tol 1e-30", "tol must be in"},
      {"regularized_error", "--system pendulum", "has no closed-form solution"},
      {"regularized_error", "--system forced-oscillator --alpha 0 --omega 1", "resonant"},
      {"work_precision", "--system pendulum --schemes nosuch", "unknown scheme 'nosuch'"},
      {"work_precision", "--system pendulum --h-max 0.3", "not an integer"},
      {"work_precision", "--norm 3", "unknown norm '3'"},
      {"stability", "--system pendulum", "stability maps need a linear system"},
      {"stability", "--system coupled-oscillators --alpha 0.1", "alpha is an axis of the map"},
      {"stability", "--q0 1", "take no system parameters"},
      {"stability", "--system coupled-oscillators --schemes nosuch", "unknown scheme 'nosuch'"},
  };
  for (const auto& b : bad) check_rejected(b.program, b.args, b.expect);
}

TEST_CASE("bench_generic rejects bad options with one line, exit 2", "[programs][generic][bench]") {
  check_rejected("bench_generic", "--steps 10", "steps must be in");
  check_rejected("bench_generic", "--reps 1", "reps must be in");
  check_rejected("bench_generic", "--benchmark_nosuch=1", "unrecognised benchmark flag");
}

TEST_CASE("negative numbers are values, after a several-value option too", "[programs][generic]") {
  const auto dir = fresh_dir("negative-values");
  const auto r = run_program("modified_equation", "--system knife-edge --order 1 --q 0 0 -0.3 --v 1 0 -0.5 --out " + dir.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const std::string text = read_bytes(dir / "knife-edge_modified_equation.tsv");
  CHECK(text.find("# q: 0,0,-0.3\n") != std::string::npos);
  CHECK(text.find("# v: 1,0,-0.5\n") != std::string::npos);
  // a word that starts with '-' and is no option is a stray word, named
  check_rejected("modified_equation", "--system knife-edge -x", "unexpected argument '-x'");
}

TEST_CASE("integrate writes the trajectory with the discrete constraint at round-off", "[programs][generic]") {
  const auto dir = fresh_dir("integrate");
  const auto r = run_program("integrate", "--system knife-edge --scheme la-midpoint --path generic --out " + dir.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const auto t = plots::read_tsv(dir / "knife-edge_la-midpoint.tsv");
  REQUIRE(t.rows.size() == 201);
  double worst = 0;
  for (std::size_t i = 0; i < t.rows.size(); ++i) worst = std::max(worst, t.number(i, "phi_d"));
  CHECK(worst < 2e-15);
  // the energy decays (Rayleigh damping)
  CHECK(t.number(200, "energy") < 0.5 * t.number(0, "energy"));
  CHECK(std::filesystem::exists(dir / "knife-edge_la-midpoint.png"));
}

TEST_CASE("regularized_error writes the forced-oscillator table in the literature's columns", "[programs][generic]") {
  const auto dir = fresh_dir("regularized");
  const auto r = run_program("regularized_error", "--system forced-oscillator --alpha 0.01 0.1 1 2 --out " + dir.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const auto t = plots::read_tsv(dir / "forced-oscillator_regularized_error.tsv");
  CHECK(t.columns == std::vector<std::string>{"system", "scheme", "alpha", "h", "max_rel_err"});
  CHECK(t.rows.size() == 5 * 4);
  for (std::size_t i = 0; i < t.rows.size(); ++i) {
    const double e = t.number(i, "max_rel_err");
    CHECK(std::isfinite(e));
    CHECK(e > 1e-7);  // a first/second-order scheme at h = 0.1 has a visible error
    CHECK(e < 0.05);
  }
}

TEST_CASE("convergence sweeps a parameter and fits orders per scheme", "[programs][generic]") {
  const auto dir = fresh_dir("convergence");
  const auto r = run_program("convergence", "--system pendulum --alpha 0.05 0.2 --h-min 0.01 --schemes la la-midpoint --out " +
                                                dir.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const auto f = plots::read_tsv(dir / "pendulum_convergence_fits.tsv");
  REQUIRE(f.rows.size() == 4);
  for (std::size_t i = 0; i < f.rows.size(); ++i) {
    INFO(f.text(i, "scheme") << " alpha " << f.number(i, "alpha"));
    CHECK(f.number(i, "fitted_order") == Approx(f.number(i, "expected_order")).margin(0.1));
  }
}
