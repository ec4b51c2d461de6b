// Systems defined by formulas as registry entries (formula_registry.hpp, formula_modified.hpp): the entry of a
// formula file runs what its header's entry runs, bit for bit where the typed formula system does
// (tests/formula/formula_systems.test.cpp: pendulum, knife edge), through the same registry calls the programs and the
// Python module make; its modified equations are the header's; any number of entries live and run at once.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <memory>
#include <thread>
#include <vector>

#include "geomint/error.hpp"
#include "geomint/formula/formula_registry.hpp"
#include "geomint/modified/formula_modified.hpp"
#include "geomint/registry.hpp"
#include "helpers.hpp"
#include "geomint/study.hpp"

using namespace geomint;

namespace {

std::string system_file(const std::string& name) { return std::string(GEOMINT_SOURCE_DIR) + "/docs/systems/" + name + ".geomint"; }

// Every scheme of the header, generic path: the formula entry's run and error equal the header's.
void same_as_header(const std::string& name, const ParamValues& pv, double h) {
  const auto entry = formula::formula_system_info(formula::load_system_file(system_file(name)));
  const SystemInfo& header = find_system(name);
  CHECK(entry->name == name);
  CHECK(entry->dof == header.dof);
  CHECK(entry->constraints == header.constraints);
  REQUIRE(entry->scheme_names() == header.scheme_names());
  const Reference ref = header.reference(pv, h / 2, step_count(h / 2, header.horizon(pv)), ReferenceKind::odeint, 1e-12);
  for (const auto& scheme : header.scheme_names()) {
    INFO(name << ", " << scheme);
    const Run a = entry->run(pv, scheme, h, Path::generic, 1), b = header.run(pv, scheme, h, Path::generic, 1);
    REQUIRE(a.steps == b.steps);
    CHECK(a.q == b.q);
    CHECK(a.p == b.p);
    CHECK(a.z == b.z);
    CHECK(a.lambda == b.lambda);
    CHECK(a.energy == b.energy);
    CHECK(a.phi_d == b.phi_d);
    CHECK(entry->max_error(pv, scheme, h, Path::generic, ref) == header.max_error(pv, scheme, h, Path::generic, ref));
  }
}

// A quartic oscillator (n = 1, no Herglotz Lagrangian): the pendulum file's shape with other formulas.
std::shared_ptr<const formula::FormulaModel> quartic(const std::string& name = "quartic") {
  return formula::compile_model([&] {
    formula::SystemDescription d;
    d.name = name;
    d.coordinates = 1;
    d.lagrangian = formula::formula_text("v1^2/2 - k*q1^4/4", "L");
    d.parameters.push_back({"k", formula::formula_text("2", "parameter k"), "stiffness"});
    d.parameters.push_back({"T", formula::formula_text("3", "parameter T"), "horizon"});
    d.initial_q.push_back(formula::formula_text("1", "q1"));
    d.initial_v.push_back(formula::formula_text("0", "v1"));
    return d;
  }());
}

}  // namespace

TEST_CASE("a formula file's registry entry runs its header's bits", "[formula][registry]") {
  same_as_header("pendulum", {{"alpha", 0.3}, {"q0", 1.2}, {"T", 4}}, 0.05);
  same_as_header("knife-edge", {{"alpha", 0.3}, {"omega0", 0.7}, {"T", 4}}, 0.05);
}

// A start whose unknowns have no size (y, theta and the multiplier stay exactly 0): the stopping rule's scales come
// from the terms and |J| times the unknowns, and 0 must still be seen at round-off ("did not converge, residual
// norm 3e-16 after 40 iterations" was once the answer at 4 of 7 step sizes). Every scheme, every h of the sweep,
// converges at its order against Odeint; the turning start too.
TEST_CASE("a sleigh started at the origin: Newton stops at round-off on structurally zero unknowns", "[formula][registry][newton]") {
  const auto entry = formula::formula_system_info(formula::load_system_file(system_file("chaplygin-sleigh")));
  for (const ParamValues& pv : {ParamValues{{"omega0", 0}}, ParamValues{}}) {
    const auto hs = halving_sequence(0.1, 0.1 / 64);
    const Reference ref = entry->reference(pv, hs.back(), step_count(hs.back(), entry->horizon(pv)), ReferenceKind::odeint, 1e-13);
    for (const auto& scheme : entry->scheme_names()) {
      std::vector<double> err;
      for (double h : hs) err.push_back(entry->max_error(pv, scheme, h, Path::generic, ref));  // a failure throws
      const auto fit = fit_order(hs, err);
      INFO("omega0 " << (pv.empty() ? 0.5 : 0.0) << ", " << scheme << ": errors " << err.front() << " ... " << err.back()
                     << ", fitted order " << fit.slope);
      for (double e : err) CHECK(std::isfinite(e));
      // orders 1 and 2 over the whole range; a composition's errors reach round-off within it (finite is its check)
      if (entry->scheme(scheme).order <= 2) CHECK(std::abs(fit.slope - entry->scheme(scheme).order) < 0.05);
    }
    if (pv.empty()) continue;
    // straight along x: y and theta exactly 0 at every step of every scheme
    for (const auto& scheme : entry->scheme_names()) {
      const Run r = entry->run(pv, scheme, 0.05, Path::generic, 1);
      double off = 0;
      for (long j = 0; j <= r.steps; ++j) off = std::max({off, std::abs(r.q[std::size_t(3 * j + 1)]), std::abs(r.q[std::size_t(3 * j + 2)])});
      INFO(scheme);
      CHECK(off == 0);
    }
  }
}

TEST_CASE("a formula entry's parameters, schemes and messages are its model's", "[formula][registry]") {
  // no Herglotz Lagrangian: no contact scheme offered
  const auto model = quartic();
  const auto entry = formula::formula_system_info(model);
  CHECK(entry->scheme_names() == std::vector<std::string>{"la", "la-midpoint", "la-trapezoid"});
  REQUIRE(entry->params.size() == 2);
  CHECK(entry->params[0].name == "k");
  CHECK(entry->params[0].value == 2);
  CHECK(entry->horizon({}) == 3);
  CHECK(entry->horizon({{"T", 5}}) == 5);
  CHECK_THROWS_WITH(entry->run({{"c", 1}}, "la", 0.1, Path::generic, 1), Catch::Contains("system 'quartic' has no parameter 'c'"));
  CHECK_THROWS_WITH(entry->run({}, "leapfrog", 0.1, Path::generic, 1), Catch::Contains("unknown scheme 'leapfrog' for system 'quartic'"));
}

// Three uncoupled quartic oscillators, the third held at -0.5 by a holonomic row: n = 3, m = 1 holonomic, a shape
// compiled without modified equations.
std::shared_ptr<const formula::FormulaModel> three_quartics() {
  return formula::compile_model([] {
    formula::SystemDescription d;
    d.name = "three-quartics";
    d.coordinates = 3;
    d.lagrangian = formula::formula_text("(v1^2 + v2^2 + v3^2)/2 - (q1^4 + q2^4 + q3^4)/4", "L");
    d.constraint_kind = formula::ConstraintKind::holonomic;
    d.constraints.push_back(formula::formula_text("q3 + 0.5", "g1"));
    d.parameters.push_back({"T", formula::formula_text("2", "parameter T"), "horizon"});
    for (const char* q : {"1", "0.5", "-0.5"}) d.initial_q.push_back(formula::formula_text(q, "q"));
    for (int i = 0; i < 3; ++i) d.initial_v.push_back(formula::formula_text("0", "v"));
    return d;
  }());
}

TEST_CASE("with compilation at first use off, a shape the build does not compile is refused with one line naming the file that adds it", "[formula][registry]") {
  const auto model = three_quartics();
  if (formula::formula_shape_compiled(3, 1, true)) {  // the plain build compiles every shape up to n = 4, m = 2
    const auto entry = formula::formula_system_info(model);
    const Run r = entry->run({}, "la", 0.1, Path::generic, 1);
    CHECK(r.steps == 20);
    CHECK(r.q[3 * 20] != r.q[0]);  // it moved
  } else {  // the sanitizer build compiles the shapes its tests use; the others, at their first use unless that is off
    const testing::ScopedEnv off("GEOMINT_SHAPE_JIT", "0");
    CHECK_THROWS_WITH(formula::formula_system_info(model), Catch::Contains("core/src/formula/shapes.def"));
  }
  // modified equations are compiled for fewer shapes (a 1 in the line's last column adds them); the others are compiled
  // at their first use unless that path is off (formula/jit.hpp; tests/formula/jit.test.cpp)
  const testing::ScopedEnv off("GEOMINT_SHAPE_JIT", "0");
  CHECK_THROWS_WITH(modified::formula_modified_system(model), Catch::Contains("shapes.def"));
}

// An entry holds its own model: any number live at once, and each runs its own formulas whatever other entries run
// beside it, on this thread or others (the same bits as alone).
TEST_CASE("formula entries hold their models: a hundred at once, run from several threads", "[formula][registry]") {
  // two models of one shape (n = 1), told apart by their horizons and their motions
  const auto pendulum = formula::load_system_file(system_file("pendulum"));
  const auto other = quartic();
  std::vector<std::shared_ptr<const SystemInfo>> alive;
  for (int i = 0; i < 100; ++i) alive.push_back(formula::formula_system_info(i % 2 == 0 ? pendulum : other));
  const ParamValues pv{{"T", 2}};
  const Run alone_p = formula::formula_system_info(pendulum)->run(pv, "la-midpoint", 0.05, Path::generic, 1);
  const Run alone_q = formula::formula_system_info(other)->run(pv, "la-midpoint", 0.05, Path::generic, 1);
  REQUIRE(alone_p.q != alone_q.q);
  std::vector<Run> runs(alive.size());
  std::vector<std::thread> threads;
  for (std::size_t w = 0; w < 4; ++w)
    threads.emplace_back([&, w] {
      for (std::size_t i = w; i < alive.size(); i += 4) runs[i] = alive[i]->run(pv, "la-midpoint", 0.05, Path::generic, 1);
    });
  for (auto& t : threads) t.join();
  std::size_t same = 0;
  for (std::size_t i = 0; i < alive.size(); ++i) {
    INFO("entry " << i);
    CHECK(alive[i]->name == (i % 2 == 0 ? "pendulum" : "quartic"));
    CHECK(alive[i]->horizon({}) == (i % 2 == 0 ? find_system("pendulum").horizon({}) : 3.0));
    same += runs[i].q == (i % 2 == 0 ? alone_p.q : alone_q.q) ? 1 : 0;
  }
  CHECK(same == alive.size());
}

TEST_CASE("a formula file's modified equations are its header's, through the registry", "[formula][registry][modified]") {
  const auto entry = modified::formula_modified_system(formula::load_system_file(system_file("pendulum")));
  const auto& header = modified::find_modified_system("pendulum");
  CHECK(entry->schemes == header.schemes);
  const ParamValues pv{{"alpha", 0.3}};
  for (const auto& scheme : header.schemes) {
    INFO(scheme);
    const auto a = entry->at(pv, scheme, 4, 0.3, {0.4}, {-0.2}, 0.1, true);
    const auto b = header.at(pv, scheme, 4, 0.3, {0.4}, {-0.2}, 0.1, true);
    CHECK(a.F == b.F);
    CHECK(a.Z == b.Z);
    CHECK(a.lagrangian == b.lagrangian);
    CHECK(a.residual <= 1e-12 * (1 + std::abs(a.F[0])));
  }
}

TEST_CASE("an entry's modified equations and compositions are found through the entry, never by its name",
          "[formula][registry][modified]") {
  // a quartic oscillator that calls itself "pendulum": a lookup by name would give the header pendulum's equations
  const auto entry = formula::formula_system_info(quartic("pendulum"));
  const auto own = modified::modified_system(*entry);
  const auto header = modified::modified_system(find_system("pendulum"));
  CHECK(header.get() == &modified::find_modified_system("pendulum"));
  const auto a = own->at({}, "la", 2, 0.0, {0.5}, {0.1}, 0.0, true);
  const auto b = header->at({}, "la", 2, 0.0, {0.5}, {0.1}, 0.0, true);
  CHECK(a.F_at(0, 0) == Approx(-2 * 0.125).epsilon(1e-15));  // F_0 = -k q^3, k = 2
  CHECK(b.F_at(0, 0) != Approx(a.F_at(0, 0)).epsilon(1e-3));
  // a shape compiles its compositions' runs, not the symmetry defect and step counts of the tests and benchmarks
  CHECK(entry->run({}, "yoshida4:la-midpoint", 0.1, Path::generic, 1).steps == 30);
  CHECK_THROWS_WITH(entry->symmetry({}, "la-midpoint", 0.1, 1), Catch::Contains("defined by formulas"));
  CHECK_THROWS_WITH(entry->composition_steps({}, "yoshida4:la-midpoint", 0.1, 10), Catch::Contains("header systems only"));
  CHECK_THROWS_AS(entry->base_steps({}, "la-midpoint", 0.1, 10), InputError);
  CHECK(entry->index == -1);
  CHECK(find_system("pendulum").model == nullptr);
}
