// long_horizon --system kepler: what its numbers must be on a short horizon (20 orbits), and its bad-input contract.
#include <catch2/catch.hpp>

#include <cmath>
#include <string>

#include "geomint/constants.hpp"
#include "geomint/plots/figure.hpp"
#include "geomint/study.hpp"
#include "helpers.hpp"

using namespace geomint::testing;

TEST_CASE("long_horizon --system kepler rejects bad input with one line, exit 2, and writes nothing", "[programs][long_horizon]") {
  check_rejected("long_horizon", "--system kepler --e 0.05", "e must be in [0.1, 0.9]");
  check_rejected("long_horizon", "--system kepler --k 12", "multiple of --outputs");
  check_rejected("long_horizon", "--system kepler --orbits 1.5", "orbits must be whole numbers");
  check_rejected("long_horizon", "--system kepler --reference-tol 1e-20", "reference-tol must be in");
  check_rejected("long_horizon", "--system kepler --tol 0", "tol must be in");
  check_rejected("long_horizon", "--system kepler --schemes nope", "nope");
  check_rejected("long_horizon", "--system kepler --schemes nope:logh", "nope");
  check_rejected("long_horizon", "--system kepler --alpha=-1", "alpha");
  check_rejected("long_horizon", "--system kepler --orbits 1000000 --k 100000 --outputs 8", "steps");
}

TEST_CASE("long_horizon --system kepler: the trapezoid keeps the momentum law to round-off, the compositions show their order, "
          "the reference is tight, the counts are the methods' own, and the errors are the same bits twice",
          "[programs][long_horizon][kepler]") {
  const auto a = fresh_dir("lhk-a"), b = fresh_dir("lhk-b");
  for (const auto& d : {a, b}) {
    const auto r = run_program("long_horizon",
                               "--system kepler --orbits 20 --k 64 128 256 --tol 1e-8 1e-10 --reps 1 --schemes la-trapezoid "
                               "yoshida4:la-trapezoid kahanli8:la-trapezoid --out " + d.string());
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
  }
  const std::string sa = read_bytes(a / "kepler_long_horizon.tsv");
  CHECK(!sa.empty());
  CHECK(sa == read_bytes(b / "kepler_long_horizon.tsv"));
  CHECK(sa.find("# git: ") != std::string::npos);

  const auto t = geomint::plots::read_tsv(a / "kepler_long_horizon.tsv");
  auto column = [&](const std::string& method, const std::string& col) {
    return t.numbers(col, [&](std::size_t r) { return t.text(r, "method") == method; });
  };
  // The trapezoid's discrete momentum law M_{j+1} = M_j (1 - alpha h/2)/(1 + alpha h/2) is exp(-alpha h) to
  // (alpha h)^3/12 = 2e-18 a step: what is left over 5120 steps is round-off. RK4 keeps no such law.
  for (double e : column("la-trapezoid", "momentum_err")) CHECK(e < 1e-12);
  for (double e : column("kahanli8:la-trapezoid", "momentum_err")) CHECK(e < 1e-12);
  const auto rk4_momentum = column("odeint-rk4", "momentum_err");
  REQUIRE(rk4_momentum.size() == 3);
  CHECK(rk4_momentum[0] > 1e-9);

  // Orders from fitted slopes over k = 64 .. 256 (h = 2 pi/k): the trapezoid's energy error (its phase error is
  // O(1) there, not asymptotic), the compositions' position error: 2, 4 and, for the eighth order between its two
  // coarser points, 8 (its finest nears the reference's floor).
  const std::vector<double> hs{geomint::two_pi / 64, geomint::two_pi / 128, geomint::two_pi / 256};
  const auto y4 = column("yoshida4:la-trapezoid", "phase_err"), k8 = column("kahanli8:la-trapezoid", "phase_err"),
             tr = column("la-trapezoid", "energy_err");
  REQUIRE(y4.size() == 3);
  const double p2 = geomint::fit_order(hs, tr).slope, p4 = geomint::fit_order(hs, y4).slope,
               p8 = std::log2(k8[0] / k8[1]);
  INFO("orders: trapezoid " << p2 << ", yoshida4 " << p4 << ", kahanli8 " << p8);
  CHECK(std::abs(p2 - 2) < 0.2);
  CHECK(std::abs(p4 - 4) < 0.3);
  CHECK(std::abs(p8 - 8) < 0.5);

  // The reference against itself at 100 times its tolerance (the files' header: about 1e-12 over 20 orbits), far
  // below the errors the fits above read (>= 1e-10); and the eighth order agrees with it to 1e-11 at k = 256.
  const auto pos = sa.find("against tol x 100: ");
  REQUIRE(pos != std::string::npos);
  const double ref_diff = std::stod(sa.substr(pos + 19));
  CHECK(ref_diff < 1e-11);
  CHECK(k8[2] < 1e-11);

  // Evaluations: RK4 calls the right-hand side 4 times a step; a composition of s stages evaluates its residual at
  // least twice a stage (once before its update, once where it accepts).
  const auto rk4_evals = column("odeint-rk4", "evals"), rk4_steps = column("odeint-rk4", "steps");
  for (std::size_t i = 0; i < rk4_evals.size(); ++i) CHECK(rk4_evals[i] == 4 * rk4_steps[i]);
  const auto y4_evals = column("yoshida4:la-trapezoid", "evals"), y4_steps = column("yoshida4:la-trapezoid", "steps");
  for (std::size_t i = 0; i < y4_evals.size(); ++i) CHECK(y4_evals[i] >= 6 * y4_steps[i]);
  for (const char* f : {"kepler_long_horizon_timings.tsv", "kepler_long_horizon_summary.tsv",
                        "kepler_long_horizon_summary_evals.tsv", "kepler_long_horizon.png"})
    CHECK(std::filesystem::exists(a / f));
}

TEST_CASE("long_horizon --system kepler runs the logH schemes: the momentum law at round-off, order 4 in phase, the "
          "kicks counted", "[programs][long_horizon][kepler]") {
  const auto d = fresh_dir("lhk-logh");
  const auto r = run_program("long_horizon", "--system kepler --orbits 20 --k 64 128 --tol 1e-8 --reps 1 --alpha 1e-3 "
                                             "--schemes logh yoshida4:logh --out " + d.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const auto t = geomint::plots::read_tsv(d / "kepler_long_horizon.tsv");
  auto column = [&](const std::string& method, const std::string& col) {
    return t.numbers(col, [&](std::size_t i) { return t.text(i, "method") == method; });
  };
  // friction over the drifts' dt: the law at round-off at every output time (partial steps included)
  for (const char* m : {"logh", "yoshida4:logh"})
    for (double e : column(m, "momentum_err")) CHECK(e < 1e-12);
  // the phase at the output times, reached by partial steps of the method: order 4 between k = 64 and 128
  const auto y4 = column("yoshida4:logh", "phase_err");
  REQUIRE(y4.size() == 2);
  INFO("yoshida4:logh phase " << y4[0] << " -> " << y4[1]);
  CHECK(std::abs(std::log2(y4[0] / y4[1]) - 4) < 0.4);
  // evaluations are kicks: 3 a step of the composition, and more for the partial steps at 8 outputs an orbit
  const auto ev = column("yoshida4:logh", "evals"), st = column("yoshida4:logh", "steps");
  for (std::size_t i = 0; i < ev.size(); ++i) {
    CHECK(ev[i] > 3 * st[i]);
    CHECK(ev[i] < 3 * st[i] + 3 * 8 * 20 * 8);
  }
}
