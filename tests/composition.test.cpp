// The composition as a scheme: its base steps are symmetric maps (q exactly; p up to the constraint impulse),
// negative stages keep the constraint and the contact action right, failures name the stage, and bad names are
// refused. Orders: tests/composition_orders.test.cpp; coefficients: tests/composition_families.test.cpp.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "geomint/composition_registry.hpp"
#include "geomint/error.hpp"
#include "geomint/generic/composition_families.hpp"
#include "geomint/study.hpp"

using namespace geomint;

namespace {
const double eps = std::numeric_limits<double>::epsilon();
ParamValues params_of(const std::string& system) {
  if (system.rfind("foucault", 0) == 0) return {{"alpha", 0.1}};  // a visible damping
  return {};
}
}  // namespace

TEST_CASE("a step of h then -h returns q to round-off, and p up to the constraint impulse", "[composition][symmetry]") {
  for (const auto& comp : all_compositions()) {
    const SystemInfo& sys = find_system(comp.system);
    for (const auto& base : comp.bases)
      for (double h : {0.1, -0.1}) {
        const SymmetryDefect d = comp.symmetry(params_of(comp.system), base, h, 7);
        const double size = d.q + d.p + 1;
        INFO(comp.system << " " << base << " h = " << h << ": |dq| " << d.dq << ", |dz| " << d.dz << ", |dp| " << d.dp
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
  for (const auto& comp : all_compositions()) {
    const SystemInfo& sys = find_system(comp.system);
    if (sys.constraints == 0) continue;
    for (const auto& base : comp.bases)
      for (const auto& fam : generic::composition_families()) {
        const std::string name = generic::composition_name(fam.name, base);
        const Run run = comp.run(params_of(comp.system), name, 0.1, 1000000);
        INFO(comp.system << " " << name << ": max |Phi_d| over " << run.steps << " steps x " << fam.stages()
                         << " stages = " << run.max_phi_d);
        // as for the base schemes at h = 0.1 (tests/generic_systems.test.cpp: 2e-15, the terms of Phi_d are O(1)
        // here), with the rounding of the chord (q_{j+1} - q_j)/(w_i h) of the shortest stage
        double w_min = 1;
        for (const long double w : fam.weights) w_min = std::min(w_min, std::abs(static_cast<double>(w)));
        CHECK(run.max_phi_d < 2e-15 / w_min);
        CHECK(run.steps == step_count(0.1, sys.horizon(params_of(comp.system))));
      }
  }
}

TEST_CASE("the contact action z of a composition converges at the family's order", "[composition][contact]") {
  // z carries the (1 + D3 𝓛) factor of every stage, negative ones included; on these systems q does not depend
  // on z (dL/dz is a function of t only), so z is checked on its own: z(T) against the finest run of a ladder of
  // ratio sqrt(2) from h = 1, fitted over the finest points (at most four) that are above the round-off floor
  // (1e-11; z's is 1e-14 here) and at least 50 times the finest run's own error (skipping rungs next to it).
  for (const char* system : {"pendulum", "kepler"}) {
    const auto& comp = find_compositions(system);
    const double T = 10;
    for (const auto& fam : generic::composition_families()) {
      const std::string name = generic::composition_name(fam.name, "contact-trapezoid");
      std::vector<double> hs, zT;
      for (int k = 0; k < 13; ++k) {
        const long N = std::lround(T * std::pow(std::sqrt(2.0), k));
        hs.push_back(T / static_cast<double>(N));
        try {
          zT.push_back(comp.run({{"T", T}}, name, hs.back(), N).z.back());
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
  // the knife edge at h = 0.4: the triple jump's middle stage (step -0.68, turning the blade by ~1.4 rad) starts
  // Newton too far from its solution
  const auto& comp = find_compositions("knife-edge");
  try {
    comp.run({{"T", 10}}, "yoshida4:la-trapezoid", 0.4, 1);
    FAIL("no failure");
  } catch (const NumericalFailure& e) {
    const std::string what = e.what();
    INFO(what);
    CHECK(what.find("system knife-edge, composition yoshida4:la-trapezoid, h = 0.4") != std::string::npos);
    CHECK(what.find("stage 2 of 3 of yoshida4 (step -0.68") != std::string::npos);
    CHECK(e.step >= 1);
  }
}

TEST_CASE("compositions are refused by name when the family or the base is not one", "[composition][registry]") {
  const auto& comp = find_compositions("pendulum");
  CHECK(comp.bases == std::vector<std::string>{"la-midpoint", "la-trapezoid", "contact-trapezoid"});
  CHECK_THROWS_WITH(comp.run({}, "yoshida4:la", 0.1, 1),
                    Catch::Contains("scheme 'la' of system 'pendulum' cannot be composed") &&
                        Catch::Contains("la-midpoint, la-trapezoid, contact-trapezoid"));
  CHECK_THROWS_WITH(comp.run({}, "nosuch:la-trapezoid", 0.1, 1), Catch::Contains("unknown composition family 'nosuch'"));
  CHECK_THROWS_WITH(comp.run({}, "la-trapezoid", 0.1, 1), Catch::Contains("<family>:<scheme>"));
  CHECK_THROWS_WITH(comp.run({}, "yoshida4:la-trapezoid", 0.3, 1), Catch::Contains("not an integer"));
  CHECK_THROWS_WITH(find_compositions("nosuch"), Catch::Contains("unknown system 'nosuch'") && Catch::Contains("kepler"));
  CHECK(all_compositions().size() == all_systems().size());
}
