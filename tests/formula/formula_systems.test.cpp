// Every header system written as formulas (docs/systems/*.geomint) against its header: the generic steps of
// every scheme, step by step (both through the registry, as the programs and the Python module run them), and the continuous equations.
//
// Bit for bit where the formula file associates as the header's C++ does and both take the same solver path
// (pendulum, knife edge, Foucault, Foucault with its holonomic constraint at the paper's initial data). Elsewhere
// to a bound from the round-off of one step and its growth:
// - the oscillators are declared `linear` in their headers, so their generic step is the fixed affine map (or
//   one Newton update) of the linear lane, the formula system's a full Newton solve. Each solves the same step
//   equations, and the stopping rule accepts a solution within kappa eps (kappa = 16, stepper.hpp) of the scale of
//   its terms: the two steps differ by at most 2 kappa eps |x| each, and on a damped (stable) discrete flow the
//   differences of the steps add up at most linearly: |dq_j| <= 2 kappa eps j max|q|.
// - the particle's header sums its squares with Eigen's squaredNorm, whose association depends on the scalar
//   type; z takes one such difference per step: the same bound.
// - Foucault with the holonomic constraint off the x axis: its offset b = dg/dt is derived symbolically, with
//   another association than the header's; b enters only the projection of the initial velocity: the same bound.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <tuple>

#include "geomint/formula/checks.hpp"
#include "geomint/formula/formula_registry.hpp"
#include "geomint/formula/formula_system.hpp"
#include "geomint/generic/schemes.hpp"
#include "geomint/registry.hpp"
#include "geomint/systems/coupled_oscillators.hpp"
#include "geomint/systems/forced_oscillator.hpp"
#include "geomint/systems/foucault.hpp"
#include "geomint/systems/knife_edge.hpp"
#include "geomint/systems/nonholonomic_particle.hpp"
#include "geomint/systems/oscillator.hpp"
#include "geomint/systems/pendulum.hpp"

using namespace geomint;

namespace {

std::string system_file(const std::string& name) { return std::string(GEOMINT_SOURCE_DIR) + "/docs/systems/" + name + ".geomint"; }

struct StepDiff {
  double q = 0, p = 0, z = 0, lambda = 0;  // largest differences over the run
  double qmax = 0, pmax = 0, zmax = 0, lmax = 0;  // largest values
  long steps = 0;
};

void compare(const std::vector<double>& a, const std::vector<double>& b, double& diff, double& size) {
  REQUIRE(a.size() == b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    diff = std::max(diff, std::abs(a[i] - b[i]));
    size = std::max(size, std::abs(b[i]));
  }
}

enum class Expect { bits, bound };

// Every generic scheme of the core (the quadratures of AllSchemesTuple) on system `name`: the entry of its formula
// file against the header's entry, both on the generic path, with parameters pv and step h.
void cross_check(const std::string& name, const ParamValues& pv, double h, Expect expect) {
  const auto entry = formula::formula_system_info(formula::load_system_file(system_file(name)));
  const SystemInfo& header = find_system(name);
  std::apply([&](auto... g) {
    for (const auto& scheme : {std::string(generic::scheme_name<decltype(g)>())...}) {
      const Run a = entry->run(pv, scheme, h, Path::generic, 1), b = header.run(pv, scheme, h, Path::generic, 1);
      StepDiff d;
      d.steps = b.steps;
      REQUIRE(a.steps == b.steps);
      compare(a.q, b.q, d.q, d.qmax);
      compare(a.p, b.p, d.p, d.pmax);
      compare(a.z, b.z, d.z, d.zmax);
      compare(a.lambda, b.lambda, d.lambda, d.lmax);
      INFO(name << " " << scheme << ", " << d.steps << " steps: max |dq| " << d.q << " (|q| <= " << d.qmax << "), |dp| " << d.p
                << ", |dz| " << d.z << ", |dlambda| " << d.lambda);
      CHECK(d.steps == step_count(h, header.horizon(pv)));
      CHECK(d.qmax > 0.1);  // a real motion, not a comparison of zeros
      if (expect == Expect::bits) {
        CHECK(d.q == 0);
        CHECK(d.p == 0);
        CHECK(d.z == 0);
        CHECK(d.lambda == 0);
      } else {
        const double kappa = 16, eps = 2.220446049250313e-16, N = double(d.steps);
        CHECK(d.q <= 2 * kappa * eps * N * d.qmax);
        CHECK(d.p <= 2 * kappa * eps * N * d.pmax);
        CHECK(d.z <= 2 * kappa * eps * N * d.zmax);
        CHECK(d.lambda <= 2 * kappa * eps * N * d.lmax);
      }
    }
  }, generic::AllSchemesTuple{});
}

}  // namespace

TEST_CASE("header systems written as formulas step to the headers' bits", "[formula][cross]") {
  cross_check("pendulum", {{"alpha", 0.3}, {"q0", 1.2}, {"p0", 0.4}, {"T", 5}}, 0.05, Expect::bits);
  cross_check("knife-edge", {{"alpha", 0.3}, {"theta0", 0.5}, {"omega0", 0.7}, {"T", 10}}, 0.05, Expect::bits);
  cross_check("foucault", {{"alpha", 0.1}, {"T", 4}, {"y0", 0.2}}, 0.02, Expect::bits);
  cross_check("foucault-rotation", {{"alpha", 0.1}, {"T", 4}}, 0.02, Expect::bits);
}

TEST_CASE("header systems written as formulas step within the round-off bound of their headers", "[formula][cross]") {
  cross_check("oscillator", {{"alpha", 0.3}, {"q0", 0.5}, {"T", 10}}, 0.05, Expect::bound);
  cross_check("forced-oscillator", {{"alpha", 0.3}, {"beta", 0.5}, {"dq0", 0.1}, {"T", 10}}, 0.05, Expect::bound);
  cross_check("coupled-oscillators", {{"alpha", 0.3}, {"kappa", 2}, {"q20", 0.4}, {"T", 10}}, 0.05, Expect::bound);
  cross_check("particle", {{"alpha", 0.3}, {"y0", 0.7}, {"T", 10}}, 0.05, Expect::bound);
  cross_check("foucault-rotation", {{"alpha", 0.1}, {"T", 4}, {"y0", 0.3}}, 0.02, Expect::bound);
}

TEST_CASE("systems written as formulas find the linear dynamics their headers declare", "[formula][cross]") {
  // L quadratic in (q, v) and F affine with constant coefficients, the constraint anything (a holonomic g affine in
  // q): the stepper then takes one Newton update a step on the schemes whose rows are affine (generic/system.hpp).
  // Declared in a header, found from the formulas (formula/model.cpp): the same answer for every header system,
  // which is also what makes the formula systems' steps the headers' bits above.
  auto check = [](const char* name, bool expected) {
    const auto model = formula::load_system_file(system_file(name));
    INFO(name);
    CHECK(model->linear_dynamics == expected);
  };
  check("pendulum", generic::has_linear_dynamics<systems::Pendulum>());
  check("oscillator", generic::has_linear_dynamics<systems::Oscillator>());
  check("forced-oscillator", generic::has_linear_dynamics<systems::ForcedOscillator>());
  check("coupled-oscillators", generic::has_linear_dynamics<systems::CoupledOscillators>());
  check("knife-edge", generic::has_linear_dynamics<systems::KnifeEdge>());
  check("particle", generic::has_linear_dynamics<systems::NonholonomicParticle>());
  check("foucault", generic::has_linear_dynamics<systems::Foucault>());
  check("foucault-rotation", generic::has_linear_dynamics<systems::FoucaultRotation>());
  // without headers: the sleigh and the rolling disk (quadratic L, rows nonlinear in q) have it; the double pendulum
  // (gravity cos q, a mass matrix that depends on the angles) and the Cartesian one (quadratic g) do not
  check("chaplygin-sleigh", true);
  check("rolling-disk", true);
  check("double-pendulum", false);
  check("double-pendulum-cartesian", false);
}

TEST_CASE("the continuous equations from the formulas are the headers' (Odeint right-hand side)", "[formula][cross]") {
  std::mt19937 gen(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (const char* name : {"pendulum", "oscillator", "forced-oscillator", "coupled-oscillators", "knife-edge", "particle", "foucault",
                           "foucault-rotation"}) {
    const auto model = formula::load_system_file(system_file(name));
    std::vector<double> pv = model->numbers;
    for (const auto& p : model->parameters) pv.push_back(p.value);
    // the derived values, as a system computes them
    formula::with_formula_system(model, [&](const auto& fs) {
      pv.clear();
      pv.insert(pv.end(), model->numbers.begin(), model->numbers.end());
      for (const auto& p : model->parameters) pv.push_back(fs.parameter(p.name));
      pv.resize(std::size_t(model->table_size()));
      std::vector<const double*> in;
      for (int i = 0; i < model->derived_offset(); ++i) in.push_back(&pv[std::size_t(i)]);
      model->prelude.evaluate(in.data(), pv.data(), pv.data() + model->derived_offset());
      return 0;
    });
    const auto ode = find_system(name).ode({});
    const int n = model->n;
    for (int k = 0; k < 10; ++k) {
      std::vector<double> x(static_cast<std::size_t>(2 * n)), dx(x.size()), q(static_cast<std::size_t>(n)), v(q.size());
      for (int i = 0; i < n; ++i) {
        q[std::size_t(i)] = x[std::size_t(i)] = 0.5 + 0.4 * u(gen);
        v[std::size_t(i)] = x[std::size_t(n + i)] = 0.5 * u(gen);
      }
      const double t = 1 + u(gen);
      ode(t, x.data(), dx.data());
      const auto a = formula::continuous_acceleration(*model, pv, t, q, v, 0, false);
      double worst = 0, scale = 0;
      for (int i = 0; i < n; ++i) {
        worst = std::max(worst, std::abs(a.a[std::size_t(i)] - dx[std::size_t(n + i)]));
        scale = std::max(scale, std::abs(dx[std::size_t(n + i)]));
      }
      INFO(name << " at t = " << t << ": |a_formula - a_header| = " << worst << " (|a| <= " << scale << ")");
      // the same equations, through Eigen's fixed- and run-time-sized LU: a few ulps of the terms
      CHECK(worst <= 1e-13 * (1 + scale));
      if (model->has_herglotz()) {
        // the Herglotz equations with z along the flow agree with LA with the force (the files' check)
        const auto h = formula::continuous_acceleration(*model, pv, t, q, v, 0.3, true);
        for (int i = 0; i < n; ++i) CHECK(std::abs(h.a[std::size_t(i)] - a.a[std::size_t(i)]) <= 1e-13 * (1 + scale));
      }
    }
  }
}
