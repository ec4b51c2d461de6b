// Every program answers bad input with one line on stderr, a nonzero exit, and no output file.
#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "helpers.hpp"

using namespace geomint::testing;

namespace {

struct BadInput {
  const char* program;
  const char* args;
  const char* expect;  // a piece of the message
};

const BadInput bad_inputs[] = {
    {"regularized_error", "--system oscillator --reference leapfrog --h 0", "h must be a positive"},
    {"regularized_error", "--system oscillator --reference leapfrog --h=-0.1", "h must be a positive"},
    {"regularized_error", "--system oscillator --reference leapfrog --h 100", "exceeds the horizon"},
    {"regularized_error", "--system oscillator --reference leapfrog --h 0.3", "not an integer"},
    {"regularized_error", "--system oscillator --reference nosuch", "unknown scheme 'nosuch'"},
    {"regularized_error", "--system oscillator --reference leapfrog --ref-factor 0", "ref-factor must be an integer"},
    {"regularized_error", "--system pendulum", "no closed-form solution to measure against"},
    {"regularized_error", "--system oscillator --reference leapfrog --alpha nan", "alpha must be a non-negative"},
    {"regularized_error", "--system oscillator --reference leapfrog --alpha=-1", "alpha must be a non-negative"},
    {"regularized_error", "--system oscillator --reference leapfrog --schemes la nosuch", "unknown scheme 'nosuch'"},
    {"regularized_error", "--system oscillator --reference leapfrog --T inf", "T must be a positive"},
    {"regularized_error", "--system oscillator --reference leapfrog --bogus 1", "unrecognised option"},
    {"regularized_error", "--system oscillator --reference leapfrog --h abc", "invalid"},
    {"convergence", "--system oscillator --h-max 0", "h_max must be a positive"},
    {"convergence", "--system oscillator --h-max 100", "exceeds the horizon"},
    {"convergence", "--system oscillator --alpha nan", "alpha must be a non-negative"},
    {"convergence", "--system oscillator --schemes nosuch", "unknown scheme"},
    {"work_precision", "--alpha nan", "alpha must be a non-negative"},
    {"work_precision", "--reps 0", "reps must be in"},
    {"stability", "--n 2", "n must be in"},
    {"stability", "--h-min 0", "h-min must be a positive"},
    {"stability", "--h-min 1 --h-max 0.5", "h-max must be finite and exceed"},
    {"stability", "--schemes nosuch", "unknown scheme"},
    {"work_precision", "--system foucault --alpha=-1", "alpha"},
    {"work_precision", "--baselines nosuch", "unknown baseline 'nosuch'"},
    {"work_precision", "--system pendulum --adaptive-error steps", "needs a closed-form solution"},
    // every header system writes its equations by hand; a system written as formulas has only those derived from L
    {"work_precision", "--system-file " GEOMINT_SOURCE_DIR "/docs/systems/pendulum.geomint --equations rhs", "no hand-written rhs"},
    {"work_precision", "--equations x", "unknown equations 'x'"},
    {"work_precision", "--target 0", "target must be a positive number"},
    {"work_precision", "--target nan", "target must be a positive number"},
};

}  // namespace

TEST_CASE("programs reject bad input with one line, exit 2, and write nothing", "[programs]") {
  for (const auto& b : bad_inputs) check_rejected(b.program, b.args, b.expect);
}

TEST_CASE("bench_steps rejects bad input with one line, exit 2, and answers --help", "[programs][bench]") {
  check_rejected("bench_steps", "--steps 10", "steps must be in [1000, 1e8]");
  check_rejected("bench_steps", "--steps 1000000000000000", "steps must be in [1000, 1e8]");
  check_rejected("bench_steps", "--reps 1", "reps must be in [3, 1000]");
  check_rejected("bench_steps", "--reps 2147483647", "reps must be in [3, 1000]");
  CHECK(run_program("bench_steps", "--help").exit_code == 0);
}

TEST_CASE("an unwritable output folder is refused", "[programs]") {
  const auto dir = fresh_dir("unwritable");
  std::ofstream(dir / "file") << "x";  // a file where a folder should be
  const auto r = run_program("regularized_error", "--out " + (dir / "file" / "sub").string());
  INFO(r.err);
  CHECK(r.exit_code == 2);
  CHECK(r.err.find("output folder") != std::string::npos);
}

TEST_CASE("--help prints usage and exits 0", "[programs]") {
  for (const char* p : {"regularized_error", "convergence", "modified_agreement", "work_precision", "stability"}) {
    const auto r = run_program(p, "--help");
    INFO(p);
    CHECK(r.exit_code == 0);
  }
}

TEST_CASE("the same command gives byte-identical data files", "[programs][reproducible]") {
  const auto a = fresh_dir("repro-a"), b = fresh_dir("repro-b");
  for (const auto& d : {a, b}) {
    // the paper's Figure 1
    REQUIRE(run_program("regularized_error", "--system oscillator --schemes la la-printed contact --reference leapfrog --trajectory --out " + d.string()).exit_code == 0);
    // the backward-error preset on a short horizon: the bits of every Odeint solve, shooting, logarithm and fit
    REQUIRE(run_program("modified_agreement", "--systems oscillator --schemes la contact --orders 0 1 --alpha 0.1 1 --T 10 "
                                              "--h-max 0.2 --halvings 2 --start shooting naive --all-orders --out " + d.string())
                .exit_code == 0);
  }
  for (const char* f : {"oscillator_regularized_error_trajectory.tsv", "oscillator_regularized_error.tsv",
                        "oscillator_modified_agreement.tsv", "oscillator_modified_agreement_fits.tsv",
                        "oscillator_modified_agreement_all_orders.tsv"}) {
    const std::string sa = read_bytes(a / f), sb = read_bytes(b / f);
    INFO(f);
    CHECK(!sa.empty());
    CHECK(sa == sb);
    CHECK(sa.find("# git: ") != std::string::npos);
  }
  // no temporary file left behind
  for (const auto& d : {a, b})
    for (const auto& e : std::filesystem::directory_iterator(d)) CHECK(e.path().extension() != ".tmp");
}
