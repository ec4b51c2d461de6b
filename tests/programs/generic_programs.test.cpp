// The programs that take any system by name: bad input refused with one line, and what they write.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <sstream>

#include "geomint/io.hpp"
#include "geomint/plots/figure.hpp"
#include "geomint/study.hpp"
#include "geomint/work_precision.hpp"
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
  CHECK(t.columns == std::vector<std::string>{"system", "scheme", "alpha", "h", "max_rel_err", "max_abs_err"});
  CHECK(t.rows.size() == 5 * 4);
  for (std::size_t i = 0; i < t.rows.size(); ++i) {
    const double e = t.number(i, "max_rel_err");
    CHECK(std::isfinite(e));
    CHECK(e > 1e-7);  // a first/second-order scheme at h = 0.1 has a visible error
    CHECK(e < 0.05);
  }
}

// The paper's Figure 1: against the leapfrog at h/10 (a scheme reference), with the closed form beside it. The two
// errors of a scheme differ by at most the reference's own error (the triangle inequality, step by step), which the
// trajectory's reference rows carry; every step's relative error is there, and their maximum is the table's.
TEST_CASE("regularized_error against a scheme at h/10 (the paper's Figure 1) and the closed form agree within the "
          "reference's own error", "[programs][generic]") {
  const auto dir = fresh_dir("regularized-fig1");
  const auto r = run_program("regularized_error", "--system oscillator --alpha 0.01 0.1 --schemes la la-printed contact "
                                                  "--reference leapfrog --trajectory --out " + dir.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const auto t = plots::read_tsv(dir / "oscillator_regularized_error.tsv");
  const auto tr = plots::read_tsv(dir / "oscillator_regularized_error_trajectory.tsv");
  REQUIRE(t.rows.size() == 6);
  for (std::size_t i = 0; i < t.rows.size(); ++i) {
    const std::string scheme = t.text(i, "scheme");
    const double alpha = t.number(i, "alpha");
    INFO(scheme << " alpha " << alpha);
    auto of = [&](const std::string& s) {
      return [&, s](std::size_t k) { return tr.text(k, "scheme") == s && tr.number(k, "alpha") == alpha; };
    };
    const auto ref_err = tr.numbers("abs_err_exact", of("leapfrog-ref"));
    const auto rel = tr.numbers("rel_err", of(scheme));
    REQUIRE(ref_err.size() == 501);
    REQUIRE(rel.size() == 501);
    const double d = *std::max_element(ref_err.begin(), ref_err.end());
    CHECK(d < 1e-3);  // second order at h = 0.01 over 50 time units
    CHECK(std::abs(t.number(i, "max_abs_err") - t.number(i, "max_abs_err_exact")) <= d);
    CHECK(*std::max_element(rel.begin(), rel.end()) == t.number(i, "max_rel_err"));
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

TEST_CASE("stability maps the built-in oscillator only, not a system file that takes its name", "[programs][generic]") {
  // A quartic well saved as `name = oscillator`: the oscillator's closed-form maps would be a silently wrong answer.
  const auto dir = fresh_dir("stability-named-oscillator");
  std::ofstream(dir / "quartic.geomint") << "[system]\nname = oscillator\ncoordinates = 1\n[parameters]\nalpha = 0.1\n"
                                            "T = 10\n[dynamics]\nL = v1^2/2 - q1^4/4\nF1 = -alpha*v1\n[initial]\nq1 = 1\nv1 = 0\n";
  check_rejected("stability", "--system-file " + (dir / "quartic.geomint").string(),
                 "'oscillator' is not known to be one");
}

// work_precision's summary is each method's cheapest time to the --target the user sets, per combination: read back
// from the error and timing tables it wrote beside it, at two targets (a summary that ignored --target would give
// the same cells at both).
TEST_CASE("work_precision's summary gives each method's CPU time to the user's target, per combination",
          "[programs][generic][work_precision]") {
  std::vector<int> reached_at;
  int ratios = 0;
  for (const double target : {1e-3, 1e-6}) {
    const auto dir = fresh_dir("work-precision-target");
    const auto r = run_program("work_precision", "--system oscillator --alpha 0.1 1 --T 10 --h-max 0.1 --h-min 0.0125 "
                                                 "--schemes la la-midpoint --baselines odeint-rk4 odeint-dopri5 "
                                                 "--tol 1e-3 1e-5 1e-7 1e-9 --reps 1 --target " + format_number(target) +
                                                 " --out " + dir.string());
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
    const auto d = plots::read_tsv(dir / "oscillator_work_precision.tsv");
    const auto tt = plots::read_tsv(dir / "oscillator_work_precision_timings.tsv");
    const auto s = plots::read_tsv(dir / "oscillator_work_precision_summary.tsv");
    REQUIRE(d.rows.size() == tt.rows.size());
    int reached = 0, missed = 0;
    for (std::size_t i = 0; i < s.rows.size(); ++i) {
      const std::string kind = s.text(i, "kind"), method = s.text(i, "method");
      const double alpha = s.number(i, "alpha");
      INFO("target " << target << " " << kind << " " << method << " alpha " << alpha);
      CHECK(s.number(i, "target") == target);
      // the cheapest time of a method over the rows of its combination whose error is within the target
      auto best = [&](const std::string& family) {
        double b = INFINITY;
        for (std::size_t k = 0; k < d.rows.size(); ++k) {
          const std::string m = d.text(k, "method");
          const bool geometric = m == "la" || m == "la-midpoint", adaptive = m == "odeint-dopri5";
          const bool of = family.empty() ? m == method : family == "geometric" ? geometric : adaptive;
          if (of && d.number(k, "alpha") == alpha && d.number(k, "err_max") <= target)
            b = std::min(b, tt.number(k, "seconds_median"));
        }
        return b;
      };
      if (kind == "seconds_to_target") {
        const double expect = best("");
        if (std::isfinite(expect)) {
          ++reached;
          CHECK(s.number(i, "value") == expect);
        } else {
          ++missed;
          CHECK(std::isnan(s.number(i, "value")));
        }
      } else if (kind == "geometric_over_adaptive") {
        const double g = best("geometric"), a = best("adaptive");
        if (std::isfinite(g) && std::isfinite(a)) {
          ++ratios;
          CHECK(s.number(i, "value") == Approx(g / a).epsilon(1e-12));
        } else {
          CHECK(std::isnan(s.number(i, "value")));
        }
      }
    }
    // 4 methods x 2 combinations, each cell either way
    CHECK(reached + missed == 8);
    CHECK(r.out.find("CPU time to reach max error <= " + format_number(target)) != std::string::npos);
    reached_at.push_back(reached);
  }
  // the tighter target is missed where the looser one is reached: the summary reads the target it is given; and
  // somewhere both families reach it (a ratio is computed, not only refused)
  CHECK(reached_at[0] > reached_at[1]);
  CHECK(ratios > 0);
}

// The summary's slopes keep the harness's fitting rule: no point at or below the reference's floor (the pendulum's
// reference is Odeint at 1e-13, so its floor is 100 times that), fewer than three above it is no slope. rk4's finest
// runs go below the floor: its slope read back from the error and timing tables, fitted over the points above it,
// is the summary's, and a fit through every point would differ.
TEST_CASE("work_precision's slopes against CPU time leave out the reference's floor", "[programs][generic][work_precision]") {
  const auto dir = fresh_dir("work-precision-floor");
  const auto r = run_program("work_precision", "--system pendulum --T 5 --h-max 0.1 --h-min 4e-4 --schemes la-midpoint "
                                               "--baselines odeint-rk4 --reps 1 --out " + dir.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const auto d = plots::read_tsv(dir / "pendulum_work_precision.tsv");
  const auto tt = plots::read_tsv(dir / "pendulum_work_precision_timings.tsv");
  const auto s = plots::read_tsv(dir / "pendulum_work_precision_summary.tsv");
  const std::string header = geomint::testing::read_bytes(dir / "pendulum_work_precision_summary.tsv");
  CHECK(header.find("# slope_floor: 1e-11 ") != std::string::npos);
  int below = 0, slopes = 0;
  for (const std::string method : {"la-midpoint", "odeint-rk4"}) {
    std::vector<double> t, e;
    for (std::size_t k = 0; k < d.rows.size(); ++k)
      if (d.text(k, "method") == method) {
        t.push_back(tt.number(k, "seconds_median"));
        e.push_back(d.number(k, "err_max"));
        below += e.back() <= 1e-11;
      }
    const auto above = fit_order(t, e, 1e-11), all = fit_order(t, e, 0.0);
    for (std::size_t i = 0; i < s.rows.size(); ++i)
      if (s.text(i, "kind") == "slope_vs_cpu_time" && s.text(i, "method") == method) {
        INFO(method << ": summary " << s.number(i, "value") << ", above the floor " << above.slope << " (" << above.points
                    << " points), all " << all.slope);
        REQUIRE(above.points >= 3);
        CHECK(s.number(i, "value") == Approx(above.slope).epsilon(1e-9));
        if (above.points < all.points) CHECK(std::abs(all.slope - above.slope) > 0.05);
        ++slopes;
      }
  }
  CHECK(slopes == 2);
  CHECK(below >= 2);  // rk4's finest runs are at the floor: the rule is exercised
  std::filesystem::remove_all(dir);
}

// --measure: the program's columns are the study's (the same run in this process, the table's 15 digits), its summary
// and its header name each measure, and a formula the user writes reaches the table and never the figure's commands.
TEST_CASE("work_precision --measure writes each measure's errors, as the study measures them", "[programs][generic][work_precision]") {
  const auto dir = fresh_dir("work-precision-measures");
  const auto r = run_program("work_precision", "--system pendulum --T 4 --h-max 0.1 --h-min 0.05 --schemes la-midpoint "
                                               "--baselines odeint-rk4 odeint-dopri5 --tol 1e-6 1e-8 --reps 1 "
                                               "--measure energy 'side=sin(q1)*v1' --out " + dir.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const auto d = plots::read_tsv(dir / "pendulum_work_precision.tsv");
  WorkPrecisionOptions opt;
  opt.schemes = {"la-midpoint"};
  opt.hs = {0.1, 0.05};
  opt.baselines = {"odeint-rk4", "odeint-dopri5"};
  opt.tols = {1e-6, 1e-8};
  opt.reps = 1;
  opt.measures = {"energy", "side=sin(q1)*v1"};
  const auto study = work_precision_study(find_system("pendulum"), {{{"T", 4}}}, opt);
  REQUIRE(d.rows.size() == study.points.size());
  for (std::size_t i = 0; i < d.rows.size(); ++i) {
    const WorkPoint& p = study.points[i];
    INFO(p.method << " " << p.value);
    CHECK(d.text(i, "method") == p.method);
    CHECK(d.text(i, "energy_err") == format_cell(p.errors[1]));
    CHECK(d.text(i, "side_err") == format_cell(p.errors[2]));
    CHECK(p.errors[1] > 0);
    CHECK(p.errors[2] > 0);
  }
  const auto s = plots::read_tsv(dir / "pendulum_work_precision_summary.tsv");
  int energy = 0, side = 0;
  for (std::size_t i = 0; i < s.rows.size(); ++i) {
    energy += s.text(i, "measure") == "energy_err";
    side += s.text(i, "measure") == "side_err";
  }
  CHECK(energy == side);
  CHECK(energy >= 3);  // a time to target per method at least
  std::ifstream in(dir / "pendulum_work_precision.tsv");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CHECK(text.find("side_err: max_k |Q(t_k, q_k, v_k) - Q(t_k, q_ref, v_ref)|") != std::string::npos);
  CHECK(text.find("Q = sin(q1)*v1") != std::string::npos);
  check_rejected("work_precision", "--system pendulum --measure 'x=q1 + y'", "unknown symbol 'y'");
}
