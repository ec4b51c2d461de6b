// Every system of the registry with every scheme built from it: fitted orders against the reference, the
// discrete constraint at round-off, Newton's cost. Runs through the run-time registry (as the programs do),
// so a new system added to core/src/systems.def is tested here without touching this file.
#include <catch2/catch.hpp>

#include <cmath>

#include "geomint/error.hpp"
#include "geomint/registry.hpp"
#include "geomint/study.hpp"
#include "geomint/sweep.hpp"

using namespace geomint;

namespace {
// The step sizes a system's expectations declare.
std::vector<double> test_steps(const Expectations& x) { return halving_sequence(x.h_max, x.h_max / std::pow(2.0, x.halvings)); }
}  // namespace

TEST_CASE("every generic scheme converges at its expected order on every system", "[generic][systems]") {
  // What each system expects (parameters, step sizes, the order a scheme shows there) is declared with it
  // (SystemInfo::expectations); the order is fitted on the asymptotic range (asymptotic_order). A series that is
  // still pre-asymptotic over the declared steps is reported (WARN), its error must still fall.
  for (const auto& sys : all_systems()) {
    const Expectations& x = sys.expectations;
    std::vector<std::string> generic;
    for (const auto& sc : sys.schemes)
      if (sc.generic) generic.push_back(sc.name);  // a scheme the system declares as a closed form has tests of its own
    const auto study = convergence_study(sys, {x.params}, generic, test_steps(x), Path::generic, ReferenceKind::automatic,
                                         1e-13, Sweep::world());
    for (const auto& se : study.series) {
      const int expected = x.order_of(se.scheme, se.expected_order);
      const auto& a = se.asymptotic;
      INFO(sys.name << " " << se.scheme << ": " << a.describe() << ", expected " << expected << " (" << x.why
                    << "), against " << study.reference);
      for (const auto& f : se.failure) CHECK(f.empty());
      if (a.asymptotic()) {
        CHECK(std::abs(a.slope - expected) <= x.order_tolerance);
      } else {
        WARN(sys.name << " " << se.scheme << " over h = " << se.h.front() << " ... " << se.h.back() << ": " << a.describe());
        CHECK(se.err.back() < se.err.front());
      }
    }
  }
}

TEST_CASE("fast paths and generic schemes give the same errors through the registry", "[generic][systems]") {
  for (const auto& sys : all_systems()) {
    const ParamValues pv = sys.expectations.params;
    const double T = sys.horizon(pv), h = 0.05;
    const auto ref = sys.reference(pv, h, step_count(h, T), ReferenceKind::automatic, 1e-13);
    for (const auto& sc : sys.schemes) {
      if (sc.fast_path.empty() || !sc.generic) continue;
      const double a = sys.max_error(pv, sc.name, h, Path::fast, ref), b = sys.max_error(pv, sc.name, h, Path::generic, ref);
      INFO(sys.name << " " << sc.name << " (" << sc.fast_path << "): " << a << " vs " << b);
      // the errors differ by at most the runs' difference: round-off growth, which for the Foucault closed forms
      // (two-step recurrences in q) is quadratic in the number of steps (Henrici; tests/generic_fast_paths)
      const double N = double(step_count(h, T));
      CHECK(std::abs(a - b) <= N * N * 2.2e-16);
      CHECK(a > 1e-6);  // a real error, not a degenerate comparison
    }
  }
}

TEST_CASE("the nonholonomic schemes keep their discrete constraint at round-off", "[generic][systems]") {
  for (const auto& sys : all_systems()) {
    if (sys.constraints == 0) continue;
    for (const auto& sc : sys.schemes) {
      if (!sc.generic) continue;
      const Run run = sys.run({}, sc.name, 0.1, Path::generic, 1000000);
      INFO(sys.name << " " << sc.name << ": max |Phi_d| = " << run.max_phi_d << " over " << run.steps << " steps");
      // the terms of Phi_d are O(1) here (|A| |v| with |A| = 1 for the knife edge, |a| ~ 1 for the particle,
      // |q| |v| / 10 for the pendulum): a few eps
      CHECK(run.max_phi_d < 2e-15);
      CHECK(run.steps == step_count(0.1, sys.horizon({})));
    }
  }
}

TEST_CASE("Newton needs at most two iterations per step on the pendulum at h = 0.1", "[generic][systems][newton]") {
  const auto& sys = find_system("pendulum");
  for (const auto& sc : sys.schemes) {
    if (!sc.generic) continue;
    const Run run = sys.run({}, sc.name, 0.1, Path::generic, 1);
    INFO(sc.name << ": " << run.newton_mean << " iterations per step");
    CHECK(run.newton_mean <= 2.0);
    CHECK(run.newton_mean >= 0.9);  // the predictor is not the solution: (nearly) every step does real work
  }
}

TEST_CASE("the registry refuses unknown names and bad parameters with one clear message", "[generic][registry]") {
  CHECK_THROWS_WITH(find_system("nosuch"), Catch::Contains("unknown system 'nosuch'") && Catch::Contains("pendulum"));
  const auto& p = find_system("pendulum");
  CHECK_THROWS_WITH(p.scheme("nosuch"), Catch::Contains("unknown scheme 'nosuch'") && Catch::Contains("la-midpoint"));
  CHECK_THROWS_WITH(p.validate({{"nosuch", 1}}), Catch::Contains("no parameter 'nosuch'") && Catch::Contains("alpha"));
  CHECK_THROWS_WITH(p.validate({{"alpha", -1}}), Catch::Contains("alpha must be a non-negative"));
  CHECK_THROWS_WITH(p.run({}, "la", 0.3, Path::generic, 1), Catch::Contains("not an integer"));
  CHECK_THROWS_WITH(find_system("oscillator").reference({}, 0.1, 10, ReferenceKind::odeint, 1e-20), Catch::Contains("tol"));
  CHECK_THROWS_WITH(find_system("knife-edge").reference({}, 0.1, 10, ReferenceKind::exact, 1e-12),
                    Catch::Contains("no closed-form solution"));
  // the header names every parameter with its value, overrides included
  const auto hdr = p.header({{"alpha", 0.25}});
  CHECK(hdr.front() == std::make_pair(std::string("system"), std::string("pendulum")));
  CHECK(std::find(hdr.begin(), hdr.end(), std::make_pair(std::string("alpha"), std::string("0.25"))) != hdr.end());
  // the contact family needs a Herglotz form: every registered system has one
  for (const auto& s : all_systems()) CHECK(s.has_herglotz);
}

TEST_CASE("a numerical failure names the system, the scheme and the step", "[generic][registry][failure]") {
  // la on the oscillator is unstable beyond h = alpha + sqrt(alpha^2 + 4): h = 2.5 overflows within T = 5000
  const auto& osc = find_system("oscillator");
  try {
    osc.run({{"T", 5000}}, "la", 2.5, Path::generic, 1000);
    FAIL("no failure");
  } catch (const NumericalFailure& e) {
    const std::string what = e.what();
    CHECK(what.find("system oscillator, scheme la (generic), h = 2.5") != std::string::npos);
    CHECK(e.step > 100);
  }
}
