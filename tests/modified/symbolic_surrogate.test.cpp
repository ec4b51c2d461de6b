// Surrogates (modified/surrogate.hpp): built by the modified-equation engine, certified by it (the surrogate's own
// modified equation under the same scheme is the base's equation to h^K: orders 1..K vanish as formulas, and in
// numbers, on the surrogate read back from its system file, the defect falls like h^(K+1)), and the orders the
// scheme then shows on the base, fitted on the asymptotic range against Odeint at 1e-13 — each beside the scheme
// on the base itself.
#include <catch2/catch.hpp>

#include <cmath>
#include <string>
#include <vector>

#include "geomint/error.hpp"
#include "geomint/formula/formula_registry.hpp"
#include "geomint/formula/formula_system.hpp"
#include "geomint/formula/model.hpp"
#include "geomint/modified/surrogate.hpp"
#include "geomint/study.hpp"

using namespace geomint;

namespace {

std::shared_ptr<const formula::FormulaModel> file_model(const std::string& name) {
  return formula::load_system_file(std::string(GEOMINT_SOURCE_DIR) + "/docs/systems/" + name + ".geomint");
}

std::shared_ptr<const formula::FormulaModel> model_of(const std::string& name, const std::string& L, const std::string& herglotz,
                                                      const std::string& F, const std::vector<std::pair<std::string, std::string>>& params,
                                                      const std::string& q0, const std::string& v0) {
  formula::SystemDescription d;
  d.name = name;
  d.coordinates = 1;
  for (const auto& [k, v] : params) d.parameters.push_back({k, formula::formula_text(v, "parameter " + k), ""});
  d.lagrangian = formula::formula_text(L, "L");
  if (!herglotz.empty()) d.herglotz = formula::formula_text(herglotz, "herglotz");
  if (!F.empty()) d.force.push_back(formula::formula_text(F, "F1"));
  d.initial_q.push_back(formula::formula_text(q0, "q1"));
  d.initial_v.push_back(formula::formula_text(v0, "v1"));
  return formula::compile_model(d);
}

// The conservative pendulum L = q'^2/2 + cos q (the scratch check is on it).
std::shared_ptr<const formula::FormulaModel> pendulum() {
  return model_of("pendulum-conservative", "v1^2/2 + cos(q1)", "", "", {{"q0", "1"}, {"T", "10"}}, "q0", "0");
}

// The damped Duffing oscillator of core/include/geomint/systems/duffing.hpp, as formulas.
std::shared_ptr<const formula::FormulaModel> duffing() {
  return model_of("duffing", "v1^2/2 - q1^2/2 - beta*q1^4/4", "L - alpha*z", "-alpha*v1",
                  {{"alpha", "0.5"}, {"beta", "1"}, {"q0", "1"}, {"T", "10"}}, "q0", "0");
}

struct Orders {
  std::vector<double> h, base, surrogate;
  AsymptoticOrder base_fit, surrogate_fit;
};

// max_j |q_j - q(t_j)| of the surrogate's scheme on the base and on the surrogate (its step parameter set to each
// h), against Odeint (dopri5, 1e-13) on the base's equations, h = h_max / 2^k.
Orders orders(const std::shared_ptr<const formula::FormulaModel>& base, const modified::SurrogateSystem& s,
              const ParamValues& pv, double h_max, int halvings, double floor = 1e-13) {
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
  o.base_fit = asymptotic_order(o.h, o.base, 0.1, floor);
  o.surrogate_fit = asymptotic_order(o.h, o.surrogate, 0.1, floor);
  return o;
}

// Orders 1..K of the surrogate's modified equation vanish as formulas; the first beyond is named; in numbers the
// defect falls at the slope of that order.
void certified(const modified::SurrogateSystem& s, int K, int first_nonzero) {
  INFO(s.scheme << "\n" << s.file_text);
  REQUIRE(s.K == K);
  REQUIRE(s.checks.size() == static_cast<std::size_t>(first_nonzero));
  for (const auto& c : s.checks) {
    INFO("order " << c.k);
    CHECK(c.symbolic_zero == (c.k < first_nonzero));
    CHECK(c.leading.empty() == (c.k < first_nonzero));
  }
  INFO("defect slope " << s.defect_slope);
  CHECK(s.defect_slope == Approx(first_nonzero).margin(0.15));
}

double term_count(const modified::SurrogateSystem& s, const std::string& quantity) {
  double n = 0;
  for (const auto& t : s.terms) n += t.quantity == quantity ? 1 : 0;
  return n;
}

}  // namespace

TEST_CASE("surrogate of the midpoint rule on the pendulum: Vermeeren's Lagrangian flipped, order 2 -> 4", "[surrogate]") {
  const auto base = pendulum();
  const auto s = modified::build_surrogate(base, "la-midpoint", 2);
  certified(s, 2, 4);  // symmetric: order 3 vanishes too, order 4 is the first left
  CHECK(s.force_free);  // a conservative variational scheme: the correction stays in the Lagrangian
  CHECK(term_count(s, "L") == 1);
  // L~ = L - (h^2/24)(U'^2 + U'' q'^2), U = -cos q, at random points and steps
  const formula::FormulaSystem<1> sur(formula::compile_model(s.description));
  double worst = 0;
  for (double q : {-1.1, 0.3, 2.0})
    for (double v : {-0.7, 0.4})
      for (double h : {0.3, 0.05}) {
        formula::FormulaSystem<1> at = sur;
        at.set_parameter(s.step_parameter, h);
        const double L = at.lagrangian(0.0, Vec<double, 1>(q), Vec<double, 1>(v));
        const double want = v * v / 2 + std::cos(q) - h * h / 24 * (std::sin(q) * std::sin(q) + std::cos(q) * v * v);
        worst = std::max(worst, std::abs(L - want));
      }
  CHECK(worst < 1e-15);
  const Orders o = orders(base, s, {{"T", 10.0}}, 0.2, 4);
  INFO("base: " << o.base_fit.describe() << "; surrogate: " << o.surrogate_fit.describe());
  CHECK(o.base_fit.slope == Approx(2).margin(0.1));
  CHECK(o.surrogate_fit.slope == Approx(4).margin(0.1));
}

TEST_CASE("surrogates of the paper's first-order schemes on the damped oscillator: order 1 -> 2 -> 3", "[surrogate]") {
  const auto base = file_model("oscillator");
  // alpha = 0.5: contact's first-order term is proportional to alpha (at 0.01 it hides below the second order)
  const ParamValues pv{{"alpha", 0.5}, {"T", 10.0}};
  for (const std::string scheme : {"la", "contact"})
    for (int K : {1, 2}) {
      const auto s = modified::build_surrogate(base, scheme, K);
      certified(s, K, K + 1);
      // LA: the dissipation is in the force, which the correction changes; contact: the Herglotz Lagrangian alone
      CHECK(s.force_free == (scheme == "contact"));
      const Orders o = orders(base, s, pv, 0.1, 4);
      INFO(scheme << " K = " << K << ": base: " << o.base_fit.describe() << "; surrogate: " << o.surrogate_fit.describe());
      CHECK(o.base_fit.slope == Approx(1).margin(0.1));
      CHECK(o.surrogate_fit.slope == Approx(K + 1).margin(0.1));
    }
}

TEST_CASE("surrogate of Stormer-Verlet on the damped Duffing oscillator: order 2 -> 4, with a force", "[surrogate]") {
  const auto base = duffing();
  const auto s = modified::build_surrogate(base, "la-trapezoid", 2);
  certified(s, 2, 4);
  CHECK_FALSE(s.force_free);  // the damping's correction is a force
  const Orders o = orders(base, s, {}, 0.2, 4);
  INFO("base: " << o.base_fit.describe() << "; surrogate: " << o.surrogate_fit.describe());
  CHECK(o.base_fit.slope == Approx(2).margin(0.1));
  CHECK(o.surrogate_fit.slope == Approx(4).margin(0.1));
}

TEST_CASE("surrogate requests that cannot be met are refused with the reason", "[surrogate]") {
  const auto base = file_model("oscillator");
  CHECK_THROWS_AS(modified::build_surrogate(base, "yoshida4:la-trapezoid", 2), InputError);
  CHECK_THROWS_AS(modified::build_surrogate(base, "la", 0), InputError);
  CHECK_THROWS_AS(modified::build_surrogate(base, "la", 6), InputError);
  CHECK_THROWS_AS(modified::build_surrogate(base, "la", 1, -1), InputError);
  CHECK_THROWS_AS(modified::build_surrogate(pendulum(), "contact", 1), InputError);  // no Herglotz Lagrangian
}

TEST_CASE("surrogate of LA on the paper's Foucault pendulum: the rows corrected linearly, order 1 -> 2", "[surrogate]") {
  const auto base = file_model("foucault");
  const auto s = modified::build_surrogate(base, "la", 1);
  certified(s, 1, 2);
  CHECK(s.constraint_linear);
  CHECK(term_count(s, "phi1") == 1);  // phi_1 = -s (x x' + y y'), linear in the velocities: the row takes its opposite
  const Orders o = orders(base, s, {{"T", 4.0}}, 0.1, 4);
  INFO("base: " << o.base_fit.describe() << "; surrogate: " << o.surrogate_fit.describe());
  CHECK(o.base_fit.slope == Approx(1).margin(0.1));
  CHECK(o.surrogate_fit.slope == Approx(2).margin(0.1));
}

TEST_CASE("surrogates on the knife edge: the midpoint rule's exists (order 2 -> 4), LA's cannot", "[surrogate]") {
  const auto base = file_model("knife-edge");
  // LA keeps the blade's row turned by half a step of the heading: phi_1 = -(theta'/2)(velocity along the blade), a
  // product of two velocities on the constraint, which no row A(t, q) q' + b(t, q) cancels
  const auto la = modified::build_surrogate(base, "la", 2);
  CHECK(la.K == 0);
  CHECK_FALSE(la.constraint_linear);
  CHECK(la.why_short.find("not linear in the velocities on the constraint") != std::string::npos);
  // the midpoint rule: phi_1 = 0, phi_2 affine on the constraint (its quadratic part is theta'^2 times the row)
  const auto s = modified::build_surrogate(base, "la-midpoint", 2);
  certified(s, 2, 4);
  CHECK(s.constraint_linear);
  const Orders o = orders(base, s, {{"T", 10.0}}, 0.2, 4);
  INFO("base: " << o.base_fit.describe() << "; surrogate: " << o.surrogate_fit.describe());
  CHECK(o.base_fit.slope == Approx(2).margin(0.1));
  CHECK(o.surrogate_fit.slope == Approx(4).margin(0.1));
}
