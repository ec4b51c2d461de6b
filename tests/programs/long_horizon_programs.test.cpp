// long_horizon's studies: bad input is one line and exit 2 with nothing written; the error files are
// the same bits for the same command (timings live in the separate *_timings.tsv).
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "geomint/plots/figure.hpp"
#include "geomint/registry.hpp"
#include "geomint/study.hpp"
#include "geomint/work_precision.hpp"
#include "helpers.hpp"

using namespace geomint::testing;

TEST_CASE("long-horizon programs reject bad input with one line, exit 2, and write nothing", "[programs][long_horizon]") {
  check_rejected("long_horizon", "--system oscillator --alpha 3", "alpha must be in (0, 2)");
  check_rejected("long_horizon", "--system oscillator --periods 1.5", "periods must be whole numbers");
  check_rejected("long_horizon", "--system oscillator --m 3", "m must be a whole number");
  check_rejected("long_horizon", "--system oscillator --tol 0", "tol must be in");
  check_rejected("long_horizon", "--system oscillator --periods 102", "multiple of --window-periods");
  check_rejected("long_horizon", "--system oscillator --alpha 1 --window-periods 5", "lower --window-periods");
  check_rejected("long_horizon", "--system oscillator --reps 0", "reps must be in");
  check_rejected("long_horizon", "--system oscillator --compositions la-trapezoid", "--compositions takes <family>:<base>");
  check_rejected("long_horizon", "--system oscillator --compositions yoshida4:la", "cannot be composed");
  check_rejected("long_horizon", "--system oscillator --compositions nosuch:la-trapezoid", "nosuch");
  check_rejected("long_horizon", "--system foucault --h 0.07", "not an integer");
  check_rejected("long_horizon", "--system foucault --T 10", "T must be in");
  check_rejected("long_horizon", "--system foucault --alpha=-1", "alpha");
  check_rejected("long_horizon", "--system foucault --tol 1", "tol must be in");
  check_rejected("long_horizon", "--system foucault --l -1", "l must be a positive finite number");
  check_rejected("long_horizon", "--system foucault --beta 95", "beta must be a latitude");
  check_rejected("long_horizon", "--system forced-oscillator --alpha 0", "alpha must be positive");
  check_rejected("long_horizon", "--system forced-oscillator --m 1", "m must be in");
  check_rejected("long_horizon", "--system forced-oscillator --periods 2", "periods must be in");
}

// One program, a study per system: --help --system X is X's study (its options), and an unknown system is refused.
TEST_CASE("long_horizon: --help --system X shows X's study", "[programs][long_horizon]") {
  const std::vector<std::pair<std::string, std::string>> own{
      {"oscillator", "--window-periods"}, {"foucault", "--beta"}, {"forced-oscillator", "--omega"},
      {"kepler", "--reference-tol"}, {"knife-edge", "--methods"}, {"pendulum", "--horizons"}, {"duffing", "--rel-target"}};
  for (const auto& [system, option] : own) {
    const auto r = run_program("long_horizon", "--help --system " + system);
    INFO(system << ": " << r.out);
    CHECK(r.exit_code == 0);
    CHECK(r.out.find(option) != std::string::npos);
  }
  check_rejected("long_horizon", "--system nosuch", "nosuch");
  check_rejected("long_horizon", "--system pendulum --T 10 20", "give one --T");
  check_rejected("long_horizon", "--system pendulum --alpha 0.1 0.2 --q0 1 2", "sweeps one parameter besides the horizon");
  check_rejected("long_horizon", "--system pendulum --horizons 0.5", "horizons must be multiples of T");
  check_rejected("long_horizon", "--system pendulum --rel-target 0", "rel-target must be a positive error");
}

TEST_CASE("long-horizon programs give byte-identical error files for the same command", "[programs][reproducible][long_horizon]") {
  const auto a = fresh_dir("lh-repro-a"), b = fresh_dir("lh-repro-b");
  for (const auto& d : {a, b}) {
    REQUIRE(run_program("long_horizon", "--system oscillator --periods 20 40 --m 16 32 --tol 1e-6 1e-8 --reps 1 --out " + d.string()).exit_code == 0);
    REQUIRE(run_program("long_horizon", "--system foucault --T 200 --h 0.1 0.05 --tol 1e-6 1e-8 --reps 1 --out " + d.string()).exit_code == 0);
    REQUIRE(run_program("long_horizon", "--system forced-oscillator --periods 8 16 --m 8 16 --tol 1e-6 1e-8 --reps 1 --out " + d.string()).exit_code == 0);
  }
  for (const char* f : {"oscillator_long_horizon.tsv", "foucault_long_horizon.tsv", "foucault_long_horizon_drift.tsv",
                        "forced-oscillator_long_horizon.tsv"}) {
    const std::string sa = read_bytes(a / f), sb = read_bytes(b / f);
    INFO(f);
    CHECK(!sa.empty());
    CHECK(sa == sb);
    CHECK(sa.find("# git: ") != std::string::npos);
    CHECK(sa.find("# program: ") != std::string::npos);
  }
  for (const char* f : {"oscillator_long_horizon_timings.tsv", "oscillator_long_horizon_summary.tsv", "oscillator_long_horizon.png",
                        "foucault_long_horizon.png", "forced-oscillator_long_horizon.png"})
    CHECK(std::filesystem::exists(a / f));
}

// The Foucault study takes the scene's parameters under the names the --system programs use, and runs the scene it
// was given: its header (written from the scene that ran) names the values, and its errors move with them.
TEST_CASE("long_horizon --system foucault runs the scene its options describe", "[programs][long_horizon]") {
  const auto a = fresh_dir("lh-scene-a"), b = fresh_dir("lh-scene-b");
  const std::string common = "--T 200 --h 0.1 --tol 1e-6 --reps 1 --out ";
  REQUIRE(run_program("long_horizon", "--system foucault " + common + a.string()).exit_code == 0);
  REQUIRE(run_program("long_horizon", "--system foucault " + common + b.string() + " --l 50 --x0 0.5 --beta 30").exit_code == 0);
  const std::string sa = read_bytes(a / "foucault_long_horizon.tsv"), sb = read_bytes(b / "foucault_long_horizon.tsv");
  CHECK(sa.find("\n# l: 67\n") != std::string::npos);
  CHECK(sb.find("\n# l: 50\n") != std::string::npos);
  CHECK(sb.find("\n# q0: 0.5,0\n") != std::string::npos);
  CHECK(sb.find("\n# beta_deg: 30\n") != std::string::npos);
  // the data rows (after the header) differ: another pendulum, another run
  CHECK(sa.substr(sa.find("\nmethod")) != sb.substr(sb.find("\nmethod")));
}

// The generic study's relative error (WorkPrecisionOptions::relative_window), computed here again from the registry's
// run and closed form, with the window's maximum taken by brute force (the study keeps a sliding maximum): the same
// number to round-off of the closed form (1e-12 relative: two evaluations of one formula), on one and on two degrees
// of freedom (the norm over components), with a window of T/5 so that most t_k have a whole window behind them. And
// an order from it: `la` is first order in the relative error too on the oscillator over 2 T (1.07, 1.04 locally;
// on the coupled oscillators h = 0.1 .. 0.0125 is still pre-asymptotic, local orders 2.4, 0.07, 0.64).
TEST_CASE("work_precision_study: the relative error is max_k |q_k - q(t_k)| / max |q| over the last window",
          "[study][long_horizon]") {
  using namespace geomint;
  for (const char* name : {"oscillator", "coupled-oscillators"}) {
    INFO(name);
    const SystemInfo& sys = find_system(name);
    const double T0 = sys.horizon({});
    const ParamValues pv{{"T", 2 * T0}};
    WorkPrecisionOptions opt;
    opt.schemes = {"la"};
    opt.hs = {0.1, 0.05, 0.025};
    opt.baselines = {};
    opt.tols = {};
    opt.reps = 1;
    opt.relative_window = T0 / 5;
    const auto study = work_precision_study(sys, {pv}, opt);
    REQUIRE(study.points.size() == 3);
    const double h_out = 0.1, h_ref = reference_step(sys, opt.hs);
    const long N_ref = step_count(h_ref, 2 * T0), every_ref = std::lround(h_out / h_ref);
    std::vector<double> times;
    for (long i = 0; i <= N_ref; ++i) times.push_back(static_cast<double>(i) * h_ref);
    const std::vector<double> exact = sys.exact_positions(pv, times);
    const int n = sys.dof;
    auto at = [&](long i, int c) { return exact[static_cast<std::size_t>(i * n + c)]; };
    auto size_at = [&](long i) {
      double a = 0;
      for (int c = 0; c < n; ++c) a = std::max(a, std::abs(at(i, c)));
      return a;
    };
    const long w = std::lround(opt.relative_window / h_ref);
    std::vector<double> rel;
    for (std::size_t s = 0; s < opt.hs.size(); ++s) {
      const double h = opt.hs[s];
      const long every = std::lround(h_out / h);
      const Run r = sys.run(pv, "la", h, Path::fast, every);
      double worst = 0;
      for (std::size_t k = 0; k < r.j.size(); ++k) {
        const long i = r.j[k] / every * every_ref;  // t_k on the reference grid
        double a = 0;
        for (long m = std::max(0L, i - w); m <= i; ++m) a = std::max(a, size_at(m));
        double d = 0;
        for (int c = 0; c < n; ++c) d = std::max(d, std::abs(r.q[k * static_cast<std::size_t>(n) + static_cast<std::size_t>(c)] - at(i, c)));
        worst = std::max(worst, d / a);
      }
      const auto& p = study.points[s];
      REQUIRE(p.errors.size() == 2);
      INFO("h = " << h << ": study " << p.errors[1] << ", here " << worst);
      CHECK(std::abs(p.errors[1] - worst) <= 1e-12 * worst);
      rel.push_back(p.errors[1]);
    }
    if (std::string(name) == "oscillator") {
      const double order = fit_order(opt.hs, rel).slope;
      INFO("order of la's relative error: " << order);
      CHECK(std::abs(order - 1) < 0.1);
    }
  }
}

// Against an Odeint reference the relative error counts only where the reference resolves the solution
// (relative_size_floor, 1e8 times its tolerance): on the pendulum at T = 2000 (100 of its horizons; its amplitude
// falls as e^{-t/20}) an eighth-order composition at h = 0.1 stays at its own 4e-8. Counted down to the reference's
// tolerance it read 1.0 for every method (the reference's noise), and 4.9e-6 with a floor of 1e6 times it.
TEST_CASE("long_horizon: the relative error stops where an Odeint reference stops resolving the solution",
          "[programs][long_horizon]") {
  const auto d = fresh_dir("lh-floor");
  const auto r = run_program("long_horizon", "--system pendulum --horizons 100 --h-max 0.1 --h-min 0.1 --schemes "
                                             "kahanli8:la-trapezoid --baselines odeint-rk4 --reps 1 --out " + d.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const auto t = geomint::plots::read_tsv(d / "pendulum_long_horizon.tsv");
  const auto k8 = t.numbers("err_rel", [&](std::size_t i) { return t.text(i, "method") == "kahanli8:la-trapezoid"; });
  REQUIRE(k8.size() == 1);
  CHECK(k8[0] < 1e-6);
  CHECK(read_bytes(d / "pendulum_long_horizon.tsv").find("# err_rel: ") != std::string::npos);
}
