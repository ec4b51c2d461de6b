// Systems written as formulas (docs/systems/*.geomint) against the same systems written as headers.
#include <catch2/catch.hpp>

#include <cmath>
#include <tuple>

#include "geomint/formula/formula_system.hpp"
#include "geomint/generic/stepper.hpp"
#include "geomint/registry.hpp"

using namespace geomint;

namespace {

std::string system_file(const std::string& name) { return std::string(GEOMINT_SOURCE_DIR) + "/docs/systems/" + name + ".geomint"; }

struct StepDiff {
  double q = 0, p = 0, z = 0, lambda = 0, qscale = 0;
  long steps = 0;
};

// Every generic step of `scheme` on the formula system against the header system's run through the registry.
template <class FS, class G>
StepDiff compare_steps(const FS& fs, const SystemInfo& header, const ParamValues& pv, double h) {
  constexpr int n = FS::dof, m = FS::constraints;
  const Run run = header.run(pv, generic::scheme_name<G>(), h, Path::generic, 1);
  generic::Stepper<FS, G> st(fs, h);
  st.start(fs.template initial_position<double>(), fs.template initial_velocity<double>());
  StepDiff d;
  d.steps = run.steps;
  for (long j = 0; j <= run.steps; ++j) {
    if (j > 0) st.step();
    const auto& s = st.state();
    const std::size_t r = static_cast<std::size_t>(j);
    for (int i = 0; i < n; ++i) {
      d.q = std::max(d.q, std::abs(s.q(i) - run.q[r * n + static_cast<std::size_t>(i)]));
      d.p = std::max(d.p, std::abs(s.p(i) - run.p[r * n + static_cast<std::size_t>(i)]));
      d.qscale = std::max(d.qscale, std::abs(run.q[r * n + static_cast<std::size_t>(i)]));
    }
    d.z = std::max(d.z, std::abs(s.z - run.z[r]));
    for (int c = 0; c < m; ++c) d.lambda = std::max(d.lambda, std::abs(s.lambda(c) - run.lambda[r * m + static_cast<std::size_t>(c)]));
  }
  return d;
}

}  // namespace

TEST_CASE("pendulum as formulas steps bit for bit with its header", "[formula][cross]") {
  const auto model = formula::load_system_file(system_file("pendulum"));
  formula::FormulaSystem<1, 0> fs(model);
  ParamValues pv{{"alpha", 0.3}, {"q0", 1.2}, {"T", 5}};
  for (const auto& [k, v] : pv) fs.set_parameter(k, v);
  fs.validate();
  const auto& header = find_system("pendulum");
  std::apply([&](auto... g) {
    ((void)[&] {
      using G = decltype(g);
      const StepDiff d = compare_steps<formula::FormulaSystem<1, 0>, G>(fs, header, pv, 0.05);
      INFO(generic::scheme_name<G>() << ": " << d.steps << " steps, max |dq| " << d.q << ", |dp| " << d.p << ", |dz| " << d.z);
      CHECK(d.steps == 100);
      CHECK(d.q == 0);
      CHECK(d.p == 0);
      CHECK(d.z == 0);
    }(), ...);
  }, generic::AllSchemesTuple{});
}
