// The long-horizon programs: bad input is one line and exit 2 with nothing written; the error files are
// the same bits for the same command (timings live in the separate *_timings.tsv).
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "helpers.hpp"

using namespace geomint::testing;

TEST_CASE("long-horizon programs reject bad input with one line, exit 2, and write nothing", "[programs][long_horizon]") {
  check_rejected("long_horizon_oscillator", "--alpha 3", "alpha must be in (0, 2)");
  check_rejected("long_horizon_oscillator", "--periods 1.5", "periods must be whole numbers");
  check_rejected("long_horizon_oscillator", "--m 3", "m must be a whole number");
  check_rejected("long_horizon_oscillator", "--tol 0", "tol must be in");
  check_rejected("long_horizon_oscillator", "--periods 102", "multiple of --window-periods");
  check_rejected("long_horizon_oscillator", "--alpha 1 --window-periods 5", "lower --window-periods");
  check_rejected("long_horizon_oscillator", "--reps 0", "reps must be in");
  check_rejected("long_horizon_oscillator", "--compositions la-trapezoid", "--compositions takes <family>:<base>");
  check_rejected("long_horizon_oscillator", "--compositions yoshida4:la", "cannot be composed");
  check_rejected("long_horizon_oscillator", "--compositions nosuch:la-trapezoid", "nosuch");
  check_rejected("long_horizon_foucault", "--h 0.07", "not an integer");
  check_rejected("long_horizon_foucault", "--T 10", "T must be in");
  check_rejected("long_horizon_foucault", "--alpha=-1", "alpha");
  check_rejected("long_horizon_foucault", "--tol 1", "tol must be in");
  check_rejected("long_horizon_foucault", "--l -1", "l must be a positive finite number");
  check_rejected("long_horizon_foucault", "--beta 95", "beta must be a latitude");
  check_rejected("long_horizon_forced", "--alpha 0", "alpha must be positive");
  check_rejected("long_horizon_forced", "--m 1", "m must be in");
  check_rejected("long_horizon_forced", "--periods 2", "periods must be in");
}

TEST_CASE("long-horizon programs: --help exits 0", "[programs][long_horizon]") {
  for (const char* p : {"long_horizon_oscillator", "long_horizon_foucault", "long_horizon_forced"}) {
    INFO(p);
    CHECK(run_program(p, "--help").exit_code == 0);
  }
}

TEST_CASE("long-horizon programs give byte-identical error files for the same command", "[programs][reproducible][long_horizon]") {
  const auto a = fresh_dir("lh-repro-a"), b = fresh_dir("lh-repro-b");
  for (const auto& d : {a, b}) {
    REQUIRE(run_program("long_horizon_oscillator", "--periods 20 40 --m 16 32 --tol 1e-6 1e-8 --reps 1 --out " + d.string()).exit_code == 0);
    REQUIRE(run_program("long_horizon_foucault", "--T 200 --h 0.1 0.05 --tol 1e-6 1e-8 --reps 1 --out " + d.string()).exit_code == 0);
    REQUIRE(run_program("long_horizon_forced", "--periods 8 16 --m 8 16 --tol 1e-6 1e-8 --reps 1 --out " + d.string()).exit_code == 0);
  }
  for (const char* f : {"long_horizon_oscillator.tsv", "long_horizon_foucault.tsv", "long_horizon_foucault_drift.tsv",
                        "long_horizon_forced.tsv"}) {
    const std::string sa = read_bytes(a / f), sb = read_bytes(b / f);
    INFO(f);
    CHECK(!sa.empty());
    CHECK(sa == sb);
    CHECK(sa.find("# git: ") != std::string::npos);
    CHECK(sa.find("# program: ") != std::string::npos);
  }
  for (const char* f : {"long_horizon_oscillator_timings.tsv", "long_horizon_oscillator_summary.tsv", "long_horizon_oscillator.png",
                        "long_horizon_foucault.png", "long_horizon_forced.png"})
    CHECK(std::filesystem::exists(a / f));
}

// The Foucault study takes the scene's parameters under the names the --system programs use, and runs the scene it
// was given: its header (written from the scene that ran) names the values, and its errors move with them.
TEST_CASE("long_horizon_foucault runs the scene its options describe", "[programs][long_horizon]") {
  const auto a = fresh_dir("lh-scene-a"), b = fresh_dir("lh-scene-b");
  const std::string common = "--T 200 --h 0.1 --tol 1e-6 --reps 1 --out ";
  REQUIRE(run_program("long_horizon_foucault", common + a.string()).exit_code == 0);
  REQUIRE(run_program("long_horizon_foucault", common + b.string() + " --l 50 --x0 0.5 --beta 30").exit_code == 0);
  const std::string sa = read_bytes(a / "long_horizon_foucault.tsv"), sb = read_bytes(b / "long_horizon_foucault.tsv");
  CHECK(sa.find("\n# l: 67\n") != std::string::npos);
  CHECK(sb.find("\n# l: 50\n") != std::string::npos);
  CHECK(sb.find("\n# q0: 0.5,0\n") != std::string::npos);
  CHECK(sb.find("\n# beta_deg: 30\n") != std::string::npos);
  // the data rows (after the header) differ: another pendulum, another run
  CHECK(sa.substr(sa.find("\nmethod")) != sb.substr(sb.find("\nmethod")));
}
