// The composition as a scheme: its base steps are symmetric maps (q exactly; p up to the constraint impulse),
// negative stages keep the constraint and the contact action right, failures name the stage, and bad names are
// refused. Orders: tests/schemes/composition_orders.test.cpp; coefficients: tests/schemes/composition_families.test.cpp.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "geomint/constants.hpp"
#include "geomint/error.hpp"
#include "geomint/generic/composition_families.hpp"
#include "geomint/study.hpp"
#include "geomint/sweep.hpp"

using namespace geomint;

namespace {
const double eps = std::numeric_limits<double>::epsilon();
ParamValues params_of(const std::string& system) {
  if (system.rfind("foucault", 0) == 0) return {{"alpha", 0.1}};  // a visible damping
  return {};
}
}  // namespace

TEST_CASE("a step of h then -h returns q to round-off, and p up to the constraint impulse", "[composition][symmetry]") {
  for (const auto& sys : all_systems()) {
    for (const auto& base : sys.composition_bases())
      for (double h : {0.1, -0.1}) {
        const SymmetryDefect d = sys.symmetry(params_of(sys.name), base, h, 7);
        const double size = d.q + d.p + 1;
        INFO(sys.name << " " << base << " h = " << h << ": |dq| " << d.dq << ", |dz| " << d.dz << ", |dp| " << d.dp
                         << ", tangent part " << d.dp_tangent << " (|q| " << d.q << ", |p| " << d.p << ")");
        // two Newton solves, each accepted within 16 eps of its terms: a few eps (measured <= 4 eps)
        CHECK(d.dq <= 32 * eps * size);
        CHECK(d.dz <= 32 * eps * size);
        CHECK(d.dp_tangent <= 32 * eps * size);
        if (sys.constraints == 0) {
          CHECK(d.dp <= 32 * eps * size);
        } else {
          // the impulse the forward step applied at its start, A(t_j, q_j)^T lambda, is not undone: O(h) (here
          // 1e-5 for the Foucault pendulum's small A = (-y, x) s, 0.02 .. 0.13 for the knife edge and the particle)
          CHECK(d.dp > 1e6 * eps * size);
        }
      }
  }
}

TEST_CASE("negative stages keep every stage's discrete constraint at round-off", "[composition][constraints]") {
  for (const auto& sys : all_systems()) {
    if (sys.constraints == 0) continue;
    // the Foucault pendulum over 40 s, not its hour: five passes through the origin, where the discrete constraint
    // is hardest (its chord is shortest); an hour adds 90 times the same steps (110 s of the sanitizer build's tests)
    ParamValues pv = params_of(sys.name);
    if (sys.name.rfind("foucault", 0) == 0) pv.push_back({"T", 40});
    for (const auto& base : sys.composition_bases())
      for (const auto& fam : generic::composition_families()) {
        const std::string name = generic::composition_name(fam.name, base);
        const Run run = sys.run(pv, name, 0.1, Path::generic, 1000000);
        INFO(sys.name << " " << name << ": max |Phi_d| over " << run.steps << " steps x " << fam.stages()
                         << " stages = " << run.max_phi_d);
        // as for the base schemes at h = 0.1 (tests/systems/generic_systems.test.cpp: 2e-15, the terms of Phi_d are O(1)
        // here), with the rounding of the chord (q_{j+1} - q_j)/(w_i h) of the shortest stage
        double w_min = 1;
        for (const long double w : fam.weights) w_min = std::min(w_min, std::abs(static_cast<double>(w)));
        CHECK(run.max_phi_d < 2e-15 / w_min);
        CHECK(run.steps == step_count(0.1, sys.horizon(pv)));
      }
  }
}

TEST_CASE("the contact action z of a composition converges at the family's order", "[composition][contact]") {
  // z carries the (1 + D3 𝓛) factor of every stage, negative ones included; on these systems q does not depend
  // on z (dL/dz is a function of t only), so z is checked on its own: z(T) against the finest run of a ladder of
  // ratio sqrt(2) from h = 1, fitted over the finest points (at most four) that are above the round-off floor
  // (1e-11; z's is 1e-14 here) and at least 50 times the finest run's own error (skipping rungs next to it).
  for (const char* system : {"pendulum", "kepler"}) {
    const SystemInfo& sys = find_system(system);
    const double T = 10;
    for (const auto& fam : generic::composition_families()) {
      const std::string name = generic::composition_name(fam.name, "contact-trapezoid");
      std::vector<double> hs, zT;
      for (int k = 0; k < 13; ++k) {
        const long N = std::lround(T * std::pow(std::sqrt(2.0), k));
        hs.push_back(T / static_cast<double>(N));
        try {
          zT.push_back(sys.run({{"T", T}}, name, hs.back(), Path::generic, N).z.back());
        } catch (const NumericalFailure&) {
          zT.push_back(std::nan(""));  // a coarse rung outside Newton's reach
        }
      }
      // the error falls by 2^(p/2) per rung: skip the rungs within a factor 50 of the finest
      const auto skip = static_cast<std::size_t>(std::ceil(std::log2(50.0) / (fam.order / 2.0)));
      std::vector<double> h_fit, e_fit;
      for (std::size_t k = hs.size() - 1 - skip + 1; k-- > 0 && h_fit.size() < 4;) {
        const double e = std::abs(zT[k] - zT.back());
        if (!(e > 1e-11)) {
          if (!h_fit.empty()) break;
          continue;
        }
        h_fit.push_back(hs[k]);
        e_fit.push_back(e);
      }
      const OrderFit fit = fit_order(h_fit, e_fit, 1e-11);
      std::string errs;
      for (double e : e_fit) errs += " " + show(e);
      INFO(system << " " << name << ": |z(T) - z_finest(T)|" << errs << "; fitted order " << fit.slope << " over "
                  << fit.points << " points");
      CHECK(fit.points >= 3);
      CHECK(std::abs(fit.slope - fam.order) <= 0.3);
    }
  }
}

TEST_CASE("a composition that fails names the system, the composition, the step and the stage", "[composition][failure]") {
  // the Kepler orbit at 16 steps an orbit: the midpoint rule's third stage of Yoshida's 6A (step -0.46, from just
  // past pericentre) has no solution Newton can reach: after 40 updates its row is still 0.13
  try {
    find_system("kepler").run({{"a", 0}, {"alpha", 1e-4}, {"T", geomint::two_pi}}, "yoshida6a:la-midpoint", geomint::two_pi / 16,
                               Path::generic, 1);
    FAIL("no failure");
  } catch (const NumericalFailure& e) {
    const std::string what = e.what();
    INFO(what);
    CHECK(what.find("system kepler, composition yoshida6a:la-midpoint, h = 0.39") != std::string::npos);
    CHECK(what.find("stage 3 of 7 of yoshida6a (step -0.46") != std::string::npos);
    CHECK(e.step >= 1);
  }
}

TEST_CASE("compositions are schemes of every system, refused by name when the family or the base is not one",
          "[composition][registry]") {
  const SystemInfo& sys = find_system("pendulum");
  CHECK(sys.composition_bases() == std::vector<std::string>{"la-midpoint", "la-trapezoid", "contact-trapezoid"});
  // every family on every base, named, ordered and described by the registry, out of the default set
  CHECK(sys.compositions.size() == generic::composition_families().size() * sys.composition_bases().size());
  const SchemeInfo& y6 = sys.scheme("yoshida6a:contact-trapezoid");
  CHECK(y6.order == 6);
  CHECK(y6.base == "contact-trapezoid");
  CHECK(y6.quadrature == "trapezoid");
  CHECK(y6.principle.find("7 stages") != std::string::npos);
  const auto defaults = sys.scheme_names();
  CHECK(std::find(defaults.begin(), defaults.end(), "yoshida4:la-trapezoid") == defaults.end());
  for (const auto& s : all_systems())
    for (const auto& c : s.compositions) CHECK(s.scheme(c.base).order == 2);
  CHECK_THROWS_WITH(sys.scheme("yoshida4:la"), Catch::Contains("scheme 'la' of system 'pendulum' cannot be composed") &&
                                                   Catch::Contains("la-midpoint, la-trapezoid, contact-trapezoid"));
  CHECK_THROWS_WITH(sys.run({}, "yoshida4:la", 0.1, Path::generic, 1),
                    Catch::Contains("scheme 'la' of system 'pendulum' cannot be composed") &&
                        Catch::Contains("la-midpoint, la-trapezoid, contact-trapezoid"));
  CHECK_THROWS_WITH(sys.scheme("nosuch:la-trapezoid"), Catch::Contains("unknown composition family 'nosuch'"));
  CHECK_THROWS_WITH(sys.run({}, "nosuch:la-trapezoid", 0.1, Path::generic, 1),
                    Catch::Contains("unknown composition family 'nosuch'"));
  CHECK_THROWS_WITH(sys.scheme("yoshida4:"), Catch::Contains("<family>:<scheme>"));
  CHECK_THROWS_WITH(sys.scheme("nosuch"), Catch::Contains("compositions <family>:<base> of families yoshida4, suzuki4"));
  CHECK_THROWS_WITH(sys.run({}, "yoshida4:la-trapezoid", 0.3, Path::generic, 1), Catch::Contains("not an integer"));
  // the entries are numbered by their places in systems.def, which the libraries above the core list in the same order
  for (std::size_t i = 0; i < all_systems().size(); ++i) CHECK(all_systems()[i].index == static_cast<int>(i));
}

TEST_CASE("a study takes compositions by name: the convergence study fits their orders beside the base's",
          "[composition][registry][study]") {
  // the pendulum over T = 10 (its expectations' horizon is 20; 10 keeps the run short), h = 0.2 halved three times:
  // errors from 1e-3 (base) and 1e-6 .. 1e-10 (compositions) down to above the 1e-13 floor of the fit
  const SystemInfo& sys = find_system("pendulum");
  const std::vector<std::string> schemes{"la-trapezoid", "yoshida4:la-trapezoid", "suzuki4:la-trapezoid",
                                         "yoshida6a:contact-trapezoid"};
  const std::vector<double> hs{0.2, 0.1, 0.05, 0.025};
  const auto study =
      convergence_study(sys, {{{"T", 10}}}, schemes, hs, Path::generic, ReferenceKind::automatic, 1e-14, Sweep::world());
  REQUIRE(study.series.size() == schemes.size());
  for (const auto& s : study.series) {
    std::string errs;
    for (double e : s.err) errs += " " + show(e);
    INFO(s.scheme << ": errors" << errs << "; fitted order " << s.fit.slope << " over " << s.fit.points << " points");
    CHECK(s.expected_order == sys.scheme(s.scheme).order);
    CHECK(s.fit.points >= 3);
    CHECK(std::abs(s.fit.slope - s.expected_order) <= 0.15);
  }
}

TEST_CASE("a composition's one-step matrix: on the undamped oscillator det 1 and a phase error of order p + 1 per step",
          "[composition][registry][stability]") {
  // la-trapezoid (leapfrog) is symplectic on q'' = -q, so every stage's matrix has det 1 and so has their product;
  // the product's rotation angle theta(h) = acos(tr/2) is h + O(h^(p+1)) for a composition of order p. Fitted
  // over h = 0.4 .. 0.1, where |theta - h| stays above 1e-13 (kahanli8 is left out: its error is below it there).
  const SystemInfo& osc = find_system("oscillator");
  for (const char* name : {"la-trapezoid", "yoshida4:la-trapezoid", "suzuki4:la-trapezoid", "yoshida6a:la-trapezoid"}) {
    const int p = osc.scheme(name).order;
    std::vector<double> hs, err;
    for (double h : {0.4, 0.2, 0.1}) {
      const auto M = osc.one_step_matrix({{"alpha", 0}}, name, h, Path::generic);
      REQUIRE(M.size() == 4);
      const long double det = M[0] * M[3] - M[1] * M[2];
      INFO(name << " h = " << h << ": det - 1 = " << static_cast<double>(det - 1));
      CHECK(std::abs(static_cast<double>(det - 1)) <= 64 * eps);
      hs.push_back(h);
      err.push_back(std::abs(std::acos(static_cast<double>((M[0] + M[3]) / 2)) - h));
    }
    const OrderFit fit = fit_order(hs, err, 1e-13);
    INFO(name << ": |theta(h) - h| = " << err[0] << " " << err[1] << " " << err[2] << ", slope " << fit.slope);
    CHECK(fit.points == 3);
    CHECK(std::abs(fit.slope - (p + 1)) <= 0.15);
  }
}
