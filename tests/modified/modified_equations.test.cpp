// The modified equations (8) and (11): AD-derived fields against hand derivations, O(h^2) agreement of the
// discrete solutions with them (and only O(h) with the original), a wrong modified Lagrangian failing,
// the naive start hiding the result, and the all-orders modified coefficients.
#include <catch2/catch.hpp>

#include <random>

#include "paper/agreement.hpp"
#include "geomint/modified/all_orders.hpp"
#include "paper/equations.hpp"
#include "paper/lagrangians.hpp"
#include "geomint/registry.hpp"
#include "geomint/systems/oscillator.hpp"
#include "geomint/study.hpp"

using namespace geomint;
using namespace geomint::modified;

namespace {

const double q0 = -0.25, p0 = 0.75, T = 50;
const std::vector<double>& hs() {
  static const auto h = halving_sequence(0.2, 0.003);
  return h;
}

struct Slopes {
  double q_mod, q_orig, p_mod, z_mod;
};
Slopes slopes(const std::string& scheme, double alpha, Start start, double sign = 1) {
  std::vector<double> qm, qo, pm, zm;
  for (double h : hs()) {
    const auto a = agreement(scheme, alpha, h, T, q0, p0, start, sign);
    qm.push_back(a.err_modified);
    qo.push_back(a.err_original);
    pm.push_back(a.err_p_modified);
    zm.push_back(a.err_z_modified);
  }
  return {fit_order(hs(), qm).slope, fit_order(hs(), qo).slope, fit_order(hs(), pm).slope, fit_order(hs(), zm).slope};
}

}  // namespace

TEST_CASE("AD-derived modified vector fields equal the hand-derived ones", "[modified]") {
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> U(-2, 2);
  for (int k = 0; k < 200; ++k) {
    const double q = U(rng), v = U(rng), z = U(rng), alpha = std::abs(U(rng)), h = std::abs(U(rng)) / 10;
    for (double sign : {1.0, -1.0}) {
      // (11): L_mod = c L, c = 1 + h alpha/2  =>  q'' = -q - c alpha q',  z' = c (v^2/2 - q^2/2 - alpha z)
      const double c = 1 + sign * h * alpha / 2;
      const auto f = herglotz_field(ContactModifiedLagrangian{alpha, h, sign}, q, v, z);
      CHECK(f.a == Approx(-q - c * alpha * v).epsilon(1e-13).margin(1e-14));
      CHECK(f.zdot == Approx(c * (v * v / 2 - q * q / 2 - alpha * z)).epsilon(1e-13).margin(1e-14));
      // (8) truncated: q'' = -q - alpha q' - h alpha/2 a0, a0 = -q - alpha q'  =>  q'' = -(1 - h alpha/2)(q + alpha q')
      const double a = forced_acceleration(LaModifiedLagrangian{alpha, h, sign}, q, v);
      CHECK(a == Approx(-(1 - sign * h * alpha / 2) * (q + alpha * v)).epsilon(1e-13).margin(1e-14));
    }
  }
}

TEST_CASE("the q' q'' term of (8) is a total derivative", "[modified]") {
  // h/2 q' q'' = d/dt G(q, q') = G_q q' + G_q' q'' with G = h q'^2/4; G's partials by AD.
  using AD2 = Eigen::AutoDiffScalar<Eigen::Vector2d>;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-3, 3);
  for (int k = 0; k < 100; ++k) {
    const double q = U(rng), v = U(rng), a = U(rng), h = std::abs(U(rng)) / 10;
    const LaModifiedLagrangian M{0.3, h};
    const auto G = M.total_derivative_primitive(AD2(q, 2, 0), AD2(v, 2, 1));
    const double dGdt = G.derivatives()(0) * v + G.derivatives()(1) * a;
    const double term = M.lagrangian(q, v, a) - M.lagrangian(q, v, 0.0);
    CHECK(term == Approx(dGdt).epsilon(1e-14).margin(1e-15));
  }
}

TEST_CASE("discrete solutions agree with their modified equations to O(h^2)", "[modified][backward-error]") {
  for (const char* scheme : {"la", "contact"})
    for (double alpha : {0.01, 0.1, 1.0}) {
      const auto s = slopes(scheme, alpha, Start::consistent);
      INFO(scheme << " alpha " << alpha << ": slopes q " << s.q_mod << " p " << s.p_mod << " z " << s.z_mod);
      CHECK(s.q_mod >= 1.9);
      CHECK(s.p_mod >= 1.9);
      if (std::string(scheme) == "contact") CHECK(s.z_mod >= 1.9);
      // against the original equation only O(h), where the O(h) term is large enough to show
      // (contact at alpha = 0.01: its O(h) term is h alpha^2/2 in the damping, too small: slope ~1.9)
      if (!(std::string(scheme) == "contact" && alpha == 0.01)) CHECK(s.q_orig == Approx(1).margin(0.15));
    }
}

TEST_CASE("a wrong modified Lagrangian (h-term sign flipped) fails the slope test", "[modified][backward-error]") {
  // At alpha = 0.01 contact's flipped term (h alpha^2/2 in the damping) is too small to detect: not asserted.
  for (const char* scheme : {"la", "contact"})
    for (double alpha : {0.1, 1.0}) {
      const auto s = slopes(scheme, alpha, Start::consistent, -1);
      INFO(scheme << " alpha " << alpha << ": slope " << s.q_mod);
      CHECK(s.q_mod < 1.3);
    }
}

TEST_CASE("the naive start hides the O(h^2) agreement", "[modified][backward-error]") {
  for (double alpha : {0.01, 0.1, 1.0}) {
    INFO("la alpha " << alpha);
    CHECK(slopes("la", alpha, Start::naive).q_mod < 1.3);
  }
  for (double alpha : {0.1, 1.0}) {  // contact's start correction is h alpha/2 p0: invisible at alpha = 0.01
    INFO("contact alpha " << alpha);
    CHECK(slopes("contact", alpha, Start::naive).q_mod < 1.3);
  }
}

TEST_CASE("the original equation in the same pipeline equals the closed-form solution", "[modified]") {
  for (const char* scheme : {"la", "contact"}) {
    const auto s = modified_solution(scheme, 0.3, 0.05, 0.0, T, q0, p0, Start::naive);
    double worst = 0;
    for (size_t j = 0; j < s.t.size(); ++j) worst = std::max(worst, std::abs(s.q[j] - systems::Oscillator{0.3, q0, p0}.exact<double>(s.t[j]).q(0)));
    CHECK(worst < 1e-10);
  }
}

TEST_CASE("Odeint modified solution agrees with GSL rk8pd", "[modified]") {
  for (const char* scheme : {"la", "contact"}) {
    const auto ode = modified_solution(scheme, 0.1, 0.05, 0.05, T, q0, p0, Start::consistent);
    const auto gsl = modified_solution_gsl(scheme, 0.1, 0.05, ode.t, {ode.q[0], ode.v[0], 0.0});
    double worst = 0;
    for (size_t j = 0; j < ode.t.size(); ++j)
      worst = std::max({worst, std::abs(ode.q[j] - gsl[j][0]), std::abs(ode.z[j] - gsl[j][2])});
    CHECK(worst < 1e-10);  // both at tolerance 1e-12 over 1000 outputs
  }
}

TEST_CASE("all-orders modified coefficients: exact sampling and first order of (8), (11)", "[modified][all-orders]") {
  for (const char* scheme : {"la", "contact"})
    for (double alpha : {0.01, 0.1, 1.0}) {
      std::vector<double> da, db;
      for (double h : hs()) {
        const auto m = all_orders_by_name(scheme, h, alpha);
        REQUIRE(m.valid);
        const auto tr = find_system("oscillator").run({{"alpha", alpha}, {"q0", q0}, {"p0", p0}, {"T", T}}, scheme, h, Path::fast, 1);
        INFO(scheme << " alpha " << alpha << " h " << h);
        CHECK(all_orders_deviation(m, tr.t, tr.q) < 1e-11);  // round-off over up to 32 000 steps
        const auto c = modified_coefficients(scheme, alpha, h);
        // first-order coefficients of all-orders minus those of (8)/(11): must vanish like O(h)
        da.push_back(std::abs((m.a - alpha) / h - (c.a - alpha) / h));
        db.push_back(std::abs((m.b - 1) / h - (c.b - 1) / h));
      }
      INFO(scheme << " alpha " << alpha);
      CHECK(fit_order(hs(), da, 1e-12).slope == Approx(1).margin(0.1));
      CHECK(fit_order(hs(), db, 1e-12).slope == Approx(1).margin(0.1));
    }
}
