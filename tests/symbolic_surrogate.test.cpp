// Surrogates (modified/surrogate.hpp): built by the modified-equation engine, certified by it (the surrogate's own
// modified equation under the same scheme is the base's equation to h^K: orders 1..K vanish as formulas, and in
// numbers at random points on the surrogate read back from its system file), and the orders the scheme then shows
// on the base, fitted on the asymptotic range against Odeint at 1e-13 — each against the scheme on the base itself.
#include <catch2/catch.hpp>

#include <cmath>
#include <string>
#include <vector>

#include "geomint/formula/formula_registry.hpp"
#include "geomint/formula/model.hpp"
#include "geomint/modified/surrogate.hpp"
#include "geomint/study.hpp"

using namespace geomint;

namespace {

std::shared_ptr<const formula::FormulaModel> file_model(const std::string& name) {
  return formula::load_system_file(std::string(GEOMINT_SOURCE_DIR) + "/docs/systems/" + name + ".geomint");
}

// The conservative pendulum L = q'^2/2 + cos q (the scratch check is on it).
std::shared_ptr<const formula::FormulaModel> pendulum() {
  formula::SystemDescription d;
  d.name = "pendulum-conservative";
  d.coordinates = 1;
  d.parameters.push_back({"q0", formula::formula_text("1", "parameter q0"), ""});
  d.parameters.push_back({"T", formula::formula_text("10", "parameter T"), ""});
  d.lagrangian = formula::formula_text("v1^2/2 + cos(q1)", "L");
  d.initial_q.push_back(formula::formula_text("q0", "q1"));
  d.initial_v.push_back(formula::formula_text("0", "v1"));
  return formula::compile_model(d);
}

struct Orders {
  std::vector<double> h, base, surrogate;
  AsymptoticOrder base_fit, surrogate_fit;
};

// max_j |q_j - q(t_j)| of `scheme` on the base and on its surrogate (its step parameter set to each h), against
// Odeint (dopri5, 1e-13) on the base's equations.
Orders orders(const std::shared_ptr<const formula::FormulaModel>& base, const modified::SurrogateSystem& s,
              const ParamValues& pv, double h_max, int halvings) {
  const auto b = formula::formula_system_info(base);
  const auto sur = formula::formula_system_info(formula::compile_model(s.description));
  const double T = b->horizon(pv);
  Orders o;
  for (int k = 0; k <= halvings; ++k) {
    const double h = h_max / std::pow(2.0, k);
    const long N = std::lround(T / h);
    const Reference ref = b->reference(pv, h, N, ReferenceKind::odeint, 1e-13);
    ParamValues sp = pv;
    sp.emplace_back(s.step_parameter, h);
    o.h.push_back(h);
    o.base.push_back(b->max_error(pv, s.scheme, h, Path::generic, ref));
    o.surrogate.push_back(sur->max_error(sp, s.scheme, h, Path::generic, ref));
  }
  o.base_fit = asymptotic_order(o.h, o.base);
  o.surrogate_fit = asymptotic_order(o.h, o.surrogate);
  return o;
}

void certified(const modified::SurrogateSystem& s, int K, double expected_slope) {
  INFO(s.file_text);
  REQUIRE(s.K == K);
  REQUIRE(s.checks.size() >= static_cast<std::size_t>(K));
  for (int k = 1; k <= K; ++k) {
    INFO("order " << k);
    CHECK(s.checks[static_cast<std::size_t>(k - 1)].symbolic_zero);
  }
  // in numbers, on the surrogate read back from its file: the defect of its modified equation at step h0 against
  // the base's equation falls like h0^(K+1) (K+2 for a symmetric scheme at even K)
  INFO("defect slope " << s.defect_slope);
  CHECK(s.defect_slope == Approx(expected_slope).margin(0.15));
}

}  // namespace

TEST_CASE("surrogate of the midpoint rule on the pendulum: certified to h^2, order 4", "[surrogate]") {
  const auto base = pendulum();
  const auto s = modified::build_surrogate(base, "la-midpoint", 2);
  certified(s, 2, 4);
  CHECK(s.force_free);  // a conservative variational scheme: the correction stays in the Lagrangian
  // the correction is -(h^2/24)(U'^2 + U'' q'^2), U = -cos q: Vermeeren's modified Lagrangian with its sign flipped
  bool found = false;
  for (const auto& t : s.terms)
    if (t.quantity == "L") {
      CHECK(t.k == 2);
      found = true;
    }
  CHECK(found);
  const auto sur = formula::formula_system_info(formula::compile_model(s.description));
  (void)sur;
  const Orders o = orders(base, s, {{"T", 10.0}}, 0.2, 4);
  INFO("base: " << o.base_fit.describe() << "; surrogate: " << o.surrogate_fit.describe());
  CHECK(o.base_fit.slope == Approx(2).margin(0.1));
  CHECK(o.surrogate_fit.slope == Approx(4).margin(0.15));
}

TEST_CASE("surrogates of the paper's first-order schemes on the damped oscillator: order 2", "[surrogate]") {
  const auto base = file_model("oscillator");
  const ParamValues pv{{"alpha", 0.1}, {"T", 10.0}};
  for (const std::string scheme : {"la", "contact"}) {
    const auto s = modified::build_surrogate(base, scheme, 1);
    INFO(scheme);
    certified(s, 1, 2);
    const Orders o = orders(base, s, pv, 0.1, 4);
    INFO("base: " << o.base_fit.describe() << "; surrogate: " << o.surrogate_fit.describe());
    CHECK(o.base_fit.slope == Approx(1).margin(0.1));
    CHECK(o.surrogate_fit.slope == Approx(2).margin(0.1));
  }
}
