// The oscillator schemes: each fast step against a literal restatement of its defining equation,
// fitted orders against the closed-form solution, the printed eq. (7) failing to converge.
#include <catch2/catch.hpp>

#include <cmath>
#include <Eigen/Core>
#include <unsupported/Eigen/AutoDiff>

#include "geomint/registry.hpp"
#include "geomint/study.hpp"
#include "geomint/systems/oscillator.hpp"
#include "paper_restatements.hpp"

using namespace geomint;
using Osc = systems::Oscillator;

namespace {

// max_j |q_j - q(t_j)| of a scheme of the registry's oscillator (its closed form) against the closed-form solution.
double max_error(const std::string& scheme, double alpha, double h) {
  const auto& osc = find_system("oscillator");
  const ParamValues pv{{"alpha", alpha}, {"q0", -0.25}, {"p0", 0.75}, {"T", 50}};
  return osc.max_error(pv, scheme, h, Path::fast, osc.reference(pv, h, step_count(h, 50), ReferenceKind::exact, 0));
}

using AD = Eigen::AutoDiffScalar<Eigen::Vector3d>;

// The paper's discrete objects written literally, differentiated by AutoDiff (not by hand).
// LA: L_d(q0, q1) = h L(q0, (q1-q0)/h), L = v^2/2 - q^2/2; F_d^-(q0, q1) = h F(q0, (q1-q0)/h), F = -alpha v.
AD la_Ld(AD q0, AD q1, double h) {
  AD v = (q1 - q0) / h;
  return h * (v * v / 2 - q0 * q0 / 2);
}
// Contact: L_d(q0, q1, z0) = h [ v^2/2 - (V(q0) + V(q1))/2 - alpha z0 ], V = q^2/2.
AD contact_Ld(AD q0, AD q1, AD z0, double h, double alpha) {
  AD v = (q1 - q0) / h;
  return h * (v * v / 2 - (q0 * q0 / 2 + q1 * q1 / 2) / 2 - alpha * z0);
}
Eigen::Vector3d grad_la(double q0, double q1, double h) {
  return la_Ld(AD(q0, 3, 0), AD(q1, 3, 1), h).derivatives();
}
Eigen::Vector3d grad_contact(double q0, double q1, double z0, double h, double alpha) {
  return contact_Ld(AD(q0, 3, 0), AD(q1, 3, 1), AD(z0, 3, 2), h, alpha).derivatives();
}

template <class S>
std::vector<OscState<double>> trajectory(double h, double alpha, int n, double q0 = -0.25, double p0 = 0.75) {
  std::vector<OscState<double>> out{{q0, p0, 0}};
  for (int j = 0; j < n; ++j) {
    auto s = out.back();
    S::step(s, h, alpha);
    out.push_back(s);
  }
  return out;
}

}  // namespace

TEST_CASE("LA step satisfies the forced discrete Euler-Lagrange equations (1), AD-differentiated", "[oscillator][la]") {
  for (double alpha : {0.01, 0.1, 1.0})
    for (double h : {0.2, 0.05}) {
      const auto tr = trajectory<Osc::La>(h, alpha, 400);
      double worst = 0;
      for (size_t j = 1; j + 1 < tr.size(); ++j) {
        // D1 L_d(q_j, q_{j+1}) + D2 L_d(q_{j-1}, q_j) + F_d^-(q_j, q_{j+1}) = 0, with F_d^- = -alpha (q_{j+1} - q_j)
        const double r = grad_la(tr[j].q, tr[j + 1].q, h)(0) + grad_la(tr[j - 1].q, tr[j].q, h)(1) -
                         alpha * (tr[j + 1].q - tr[j].q);
        worst = std::max(worst, std::abs(r));
      }
      INFO("alpha " << alpha << " h " << h);
      CHECK(worst < 1e-13);
      // the scheme's own residual agrees
      for (size_t j = 1; j + 1 < tr.size(); ++j)
        CHECK(std::abs(testing::la_residual(tr[j - 1].q, tr[j].q, tr[j + 1].q, h, alpha)) < 1e-13);
    }
}

TEST_CASE("LA momentum is the discrete Legendre transform: p_j = D2 L_d(q_{j-1}, q_j)", "[oscillator][la]") {
  const double h = 0.1, alpha = 0.3;
  const auto tr = trajectory<Osc::La>(h, alpha, 100);
  for (size_t j = 1; j < tr.size(); ++j) CHECK(tr[j].p == Approx(grad_la(tr[j - 1].q, tr[j].q, h)(1)).epsilon(1e-13));
}

TEST_CASE("contact step equals eq. (10) as printed and solves the discrete Herglotz equations", "[oscillator][contact]") {
  for (double alpha : {0.01, 0.1, 1.0})
    for (double h : {0.2, 0.05}) {
      const auto tr = trajectory<Osc::Contact>(h, alpha, 400);
      double worst10 = 0, worst_h = 0, worst_z = 0;
      for (size_t j = 1; j < tr.size(); ++j) {
        // eq. (10) literally
        const double qj = (1 - h * h / 2) * tr[j - 1].q + h * (1 - h * alpha) * tr[j - 1].p;
        const double pj = (1 - h * alpha) * tr[j - 1].p - h / 2 * (qj + tr[j - 1].q);
        worst10 = std::max({worst10, std::abs(qj - tr[j].q), std::abs(pj - tr[j].p)});
        // z_{j} = z_{j-1} + L_d(q_{j-1}, q_j, z_{j-1})
        const double Ld = contact_Ld(AD(tr[j - 1].q), AD(tr[j].q), AD(tr[j - 1].z), h, alpha).value();
        worst_z = std::max(worst_z, std::abs(tr[j].z - (tr[j - 1].z + Ld)));
        if (j + 1 < tr.size()) {
          // D1 L_d(j) + D2 L_d(j-1) (1 + D3 L_d(j)) = 0
          const auto gj = grad_contact(tr[j].q, tr[j + 1].q, tr[j].z, h, alpha);
          const auto gm = grad_contact(tr[j - 1].q, tr[j].q, tr[j - 1].z, h, alpha);
          worst_h = std::max(worst_h, std::abs(gj(0) + gm(1) * (1 + gj(2))));
        }
      }
      INFO("alpha " << alpha << " h " << h);
      CHECK(worst10 < 1e-14);
      CHECK(worst_h < 1e-13);
      CHECK(worst_z < 1e-14);
    }
}

TEST_CASE("one step of each scheme against a hand-written restatement", "[oscillator]") {
  const double h = 0.1, alpha = 0.1, q = -0.25, p = 0.75;
  OscState<double> s{q, p, 0};
  Osc::La::step(s, h, alpha);
  // forced DEL in position-momentum form, derived: p1 = (p0 - h q0)/(1 + h alpha)
  CHECK(s.p == Approx((0.75 + 0.025) / 1.01).epsilon(1e-15));
  CHECK(s.q == Approx(-0.25 + 0.1 * (0.775 / 1.01)).epsilon(1e-15));
  OscState<double> r{q, p, 0};
  Osc::LaPrinted::step(r, h, alpha);
  CHECK(r.p == Approx(0.775 / 1.1).epsilon(1e-15));  // eq. (7) as printed: 1 + alpha
  OscState<double> c{q, p, 0};
  Osc::Contact::step(c, h, alpha);
  CHECK(c.q == Approx(0.995 * -0.25 + 0.1 * 0.99 * 0.75).epsilon(1e-15));
  CHECK(c.p == Approx(0.99 * 0.75 - 0.05 * (c.q - 0.25)).epsilon(1e-15));
}

TEST_CASE("fitted orders against the closed-form solution", "[oscillator][order]") {
  const auto hs = halving_sequence(0.2, 0.003);
  REQUIRE(hs.size() >= 7);
  auto fitted = [&](const std::string& name, double alpha) {
    std::vector<double> e;
    for (double h : hs) e.push_back(max_error(name, alpha, h));
    return fit_order(hs, e);
  };
  // Tolerance 0.1 on the slope: the fits over 8 halvings of a first-order method land within 0.05 of 1
  // once the O(h^2) remainder is small against the O(h) term, as it is at alpha = 0.1 and 1.
  for (double alpha : {0.1, 1.0}) {
    INFO("alpha " << alpha);
    CHECK(fitted("la", alpha).slope == Approx(1).margin(0.1));
    CHECK(fitted("contact", alpha).slope == Approx(1).margin(0.1));
  }
  // At alpha = 0.01 LA's O(h) term (frequency shift h alpha/4) still dominates, but contact's O(h) term
  // is only in the damping (h alpha^2/2, see the modified Lagrangian (11)), so its error looks O(h^2).
  CHECK(fitted("la", 0.01).slope == Approx(1).margin(0.15));
  CHECK(fitted("contact", 0.01).slope > 1.7);
  for (double alpha : {0.01, 0.1, 1.0}) CHECK(fitted("leapfrog", alpha).slope == Approx(2).margin(0.05));
}

TEST_CASE("eq. (7) as printed does not converge", "[oscillator][la-printed]") {
  const auto hs = halving_sequence(0.2, 0.003);
  for (double alpha : {0.01, 0.1, 1.0}) {
    std::vector<double> e;
    for (double h : hs) e.push_back(max_error("la-printed", alpha, h));
    INFO("alpha " << alpha);
    CHECK(std::abs(fit_order(hs, e).slope) < 0.3);  // no convergence: error flat in h
    CHECK(e.back() > 0.1);                            // and O(1) at the smallest h
  }
}

TEST_CASE("long double runs the same scheme and agrees with double to round-off", "[oscillator][scalar]") {
  OscState<double> d{-0.25, 0.75, 0};
  OscState<long double> l{-0.25L, 0.75L, 0};
  for (int j = 0; j < 5000; ++j) {
    Osc::Contact::step(d, 0.01, 0.1);
    Osc::Contact::step(l, 0.01L, 0.1L);
  }
  // 5000 steps of a contracting map: accumulated round-off stays ~1e-13.
  CHECK(std::abs(static_cast<long double>(d.q) - l.q) < 1e-12L);
  CHECK(std::abs(static_cast<long double>(d.q) - l.q) > 0.0L);  // really a different precision
}

TEST_CASE("second-order comparators: defining equations and order 2", "[oscillator][second-order]") {
  const double h = 0.1, alpha = 0.4;
  // midpoint forced DEL, AD-free literal restatement through the scheme's residual
  const auto tm = trajectory<Osc::LaMidpoint>(h, alpha, 300);
  for (size_t j = 1; j + 1 < tm.size(); ++j)
    CHECK(std::abs(testing::la_midpoint_residual(tm[j - 1].q, tm[j].q, tm[j + 1].q, h, alpha)) < 1e-14);
  // symmetric contact: L_d(q0, q1, z0) defined implicitly by z1 = z0 + h[v^2/2 - (q0^2+q1^2)/4 - alpha (z0+z1)/2];
  // solved for z1 it is linear, so the AD of the solved form is the literal definition.
  auto Ld = [&](AD q0, AD q1, AD z0) -> AD {
    AD v = (q1 - q0) / h;
    AD A = v * v / 2 - (q0 * q0 + q1 * q1) / 4;
    return h * (A - alpha * z0) / (1 + h * alpha / 2);
  };
  const auto tc = trajectory<Osc::ContactSymmetric>(h, alpha, 300);
  for (size_t j = 1; j + 1 < tc.size(); ++j) {
    const auto gj = Ld(AD(tc[j].q, 3, 0), AD(tc[j + 1].q, 3, 1), AD(tc[j].z, 3, 2)).derivatives();
    const auto gm = Ld(AD(tc[j - 1].q, 3, 0), AD(tc[j].q, 3, 1), AD(tc[j - 1].z, 3, 2)).derivatives();
    CHECK(std::abs(gj(0) + gm(1) * (1 + gj(2))) < 1e-14);                 // discrete Herglotz equation
    CHECK(tc[j].p == Approx(gm(1)).epsilon(1e-13));                         // p_j = D2 L_d(q_{j-1}, q_j, z_{j-1})
    const double v = (tc[j + 1].q - tc[j].q) / h;                            // implicit z definition
    CHECK(tc[j + 1].z - tc[j].z ==
          Approx(h * (v * v / 2 - (tc[j].q * tc[j].q + tc[j + 1].q * tc[j + 1].q) / 4 -
                      alpha * (tc[j].z + tc[j + 1].z) / 2)).margin(1e-15));
  }
  const auto hs = halving_sequence(0.2, 0.003);
  for (const char* name : {"la-midpoint", "contact-sym"})
    for (double a : {0.01, 0.1, 1.0}) {
      std::vector<double> e;
      for (double hh : hs) e.push_back(max_error(name, a, hh));
      INFO(name << " alpha " << a);
      CHECK(fit_order(hs, e).slope == Approx(2).margin(0.05));
    }
}
