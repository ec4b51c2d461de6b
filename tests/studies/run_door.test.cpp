// The one door (core/include/geomint/run/): the baselines' drivers and their counted evaluations, run_method on
// schemes, closed forms and baselines alike, and a study of the studies layer built on it (the knife edge's
// long-horizon probe, held to the order of the schemes it watches).
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "geomint/error.hpp"
#include "geomint/registry.hpp"
#include "geomint/run/baselines.hpp"
#include "geomint/run/method.hpp"
#include "geomint/work_precision.hpp"

using namespace geomint;

namespace {

// x'' = -x from (1, 0): x = cos t
const OdeRhs harmonic = [](double, const double* x, double* dx) {
  dx[0] = x[1];
  dx[1] = -x[0];
};

}  // namespace

TEST_CASE("run_baseline: rk4 counts four evaluations a step and falls at order 4", "[run][baselines]") {
  double err[2];
  for (int k = 0; k < 2; ++k) {
    BaselineSetup b;
    b.name = "odeint-rk4";
    b.h = 0.05 / (1 << k);
    b.steps = 200 << k;  // T = 10
    double last = 0;
    const BaselineObserver watch = [&](std::size_t, double, const double* x) { last = x[0]; };
    const BaselineCount c = run_baseline(b, harmonic, {1, 0}, &watch);
    CHECK(c.steps == b.steps);
    CHECK(c.calls == 4 * b.steps);
    err[k] = std::abs(last - std::cos(10.0));
  }
  CHECK(std::log2(err[0] / err[1]) == Approx(4).margin(0.1));
}

TEST_CASE("run_baseline: every adaptive baseline meets its tolerance at the output times, its calls counted",
          "[run][baselines]") {
  std::vector<double> times;
  for (int i = 0; i <= 100; ++i) times.push_back(0.1 * i);
  for (const char* name : {"odeint-dopri5", "odeint-bulirsch-stoer", "gsl-rk8pd"}) {
    BaselineSetup b;
    b.name = name;
    b.abs_tol = b.rel_tol = 1e-10;
    b.watch = BaselineWatch::outputs;
    b.times = times;
    double worst = 0;
    std::size_t seen = 0;
    long calls = 0;
    const OdeRhs counted = [&](double t, const double* x, double* dx) {
      ++calls;
      harmonic(t, x, dx);
    };
    const BaselineObserver watch = [&](std::size_t k, double t, const double* x) {
      CHECK(t == times[k]);  // dense output at the time itself; rk8pd's last step there shortened to land on it
      worst = std::max(worst, std::abs(x[0] - std::cos(t)));
      ++seen;
    };
    const BaselineCount c = run_baseline(b, counted, {1, 0}, &watch);
    INFO(name << ": max error " << worst << " over t <= 10, " << c.steps << " steps");
    CHECK(seen == times.size());
    CHECK(c.calls == calls);
    CHECK(worst < 1e-8);  // a local tolerance of 1e-10 over ~10 time units
    CHECK(worst > 1e-15);
  }
}

TEST_CASE("run_baseline: windows that change nothing leave rk4's bits alone, and a blow-up says where", "[run][baselines]") {
  auto run = [](long windows) {
    BaselineSetup b;
    b.name = "odeint-rk4";
    b.h = 0.01;
    b.steps = 1000;
    b.windows = windows;
    long ends = 0;
    b.window_end = [&](long, double, double*) { return ++ends < 0; };
    std::vector<double> xs;
    const BaselineObserver watch = [&](std::size_t, double, const double* x) { xs.push_back(x[0]); };
    run_baseline(b, harmonic, {1, 0}, &watch);
    CHECK(ends == windows);
    return xs;
  };
  CHECK(run(7) == run(1));
  // x' = x^2 from 1 leaves the finite numbers at t = 1
  BaselineSetup b;
  b.name = "odeint-rk4";
  b.h = 0.01;
  b.steps = 200;
  CHECK_THROWS_AS(run_baseline(b, [](double, const double* x, double* dx) { dx[0] = x[0] * x[0]; }, {1}, nullptr),
                  NumericalFailure);
  b.name = "nosuch";
  CHECK_THROWS_AS(run_baseline(b, harmonic, {1, 0}, nullptr), InputError);
}

TEST_CASE("run_method: a closed form, a generic scheme and a baseline through one door", "[run][method]") {
  const SystemInfo& sys = find_system("oscillator");
  const ParamValues pv{{"alpha", 0.1}, {"T", 10}};
  const auto exact = sys.exact_positions(pv, {10.0});
  auto end_error = [&](const std::string& name, double knob, Path path, MethodWork* w) {
    MethodOptions opt;
    opt.path = path;
    double t_end = 0, q_end = 0;
    long seen = 0;
    *w = run_method(sys, pv, find_method(sys, name), knob, opt, [&](double t, const double* q, const double*) {
      t_end = t;
      q_end = q[0];
      ++seen;
    });
    CHECK(t_end == Approx(10).epsilon(1e-12));
    return std::make_pair(std::abs(q_end - exact[0]), seen);
  };
  MethodWork w;
  // leapfrog's closed form and the generic step of la-trapezoid solve the same residual: the same q to round-off
  const auto [e_fast, n_fast] = end_error("leapfrog", 0.01, Path::fast, &w);
  CHECK(n_fast == 1001);
  CHECK(std::isnan(w.evaluations));  // a closed form evaluates no residual
  const auto [e_generic, n_generic] = end_error("la-trapezoid", 0.01, Path::generic, &w);
  CHECK(n_generic == 1001);
  CHECK(w.evaluations >= 1000);  // at least one evaluation of the residual a step
  CHECK(e_generic == Approx(e_fast).epsilon(1e-6));
  CHECK(e_fast < 1e-4);
  const auto [e_dopri, n_dopri] = end_error("odeint-dopri5", 1e-10, Path::fast, &w);
  CHECK(e_dopri < 1e-8);
  CHECK(w.evaluations >= 6 * static_cast<double>(n_dopri - 1));  // six stages a step, first-same-as-last
  CHECK_THROWS_AS(find_method(sys, "nosuch"), InputError);
}

TEST_CASE("work_precision_study runs gsl-rk8pd on a system without a closed form, to its tolerance",
          "[run][baselines][work_precision]") {
  const SystemInfo& sys = find_system("kepler");
  WorkPrecisionOptions opt;
  opt.hs = {0.1, 0.05};
  opt.schemes = {"la-trapezoid"};
  opt.baselines = {"gsl-rk8pd", "odeint-dopri5"};
  opt.tols = {1e-6, 1e-10};
  opt.reps = 1;
  const auto study = work_precision_study(sys, {{{"T", 6}}}, opt);
  std::vector<double> rk8;
  for (const auto& p : study.points)
    if (p.method == "gsl-rk8pd") rk8.push_back(p.errors.front());
  REQUIRE(rk8.size() == 2);
  INFO("gsl-rk8pd errors at tol 1e-6, 1e-10: " << rk8[0] << " " << rk8[1]);
  // over 6 time units rk8pd beats its tolerance by far (1.6e-10 at 1e-6); at 1e-10 it reads the reference's floor
  CHECK(rk8[0] < 1e-4);
  CHECK(rk8[1] < 1e-8);
}
