// The automatic modified equations (series pushed through each scheme's own residual) against everything
// known: the printed (8) and (11), the exact all-orders modified damping and stiffness of the linear
// oscillator, Hairer–Lubich–Wanner's Störmer–Verlet pendulum, the Störmer–Verlet frequency, Vermeeren's
// midpoint modified Lagrangian and the Störmer–Verlet one; the continuous constrained equations at order 0;
// the residual self-check for every system and scheme; the generic shooting start against the hand-derived
// starts of (8) and (11).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <random>

#include <unsupported/Eigen/MatrixFunctions>

#include "geomint/generic/system.hpp"
#include "paper/agreement.hpp"
#include "geomint/modified/all_orders.hpp"
#include "geomint/modified/automatic_registry.hpp"
#include "geomint/study.hpp"
#include "geomint/systems/foucault.hpp"
#include "geomint/systems/knife_edge.hpp"

using namespace geomint;
using namespace geomint::modified;

namespace {

ModifiedPoint at(const std::string& system, const std::string& scheme, int K, double q, double v, double z = 0,
                 const ParamValues& pv = {}, double t = 0) {
  return find_modified_system(system).at(pv, scheme, K, t, {q}, {v}, z, false);
}

// sum_{k<=K} h^k F_k (component 0)
double field(const ModifiedPoint& P, double h, int K = -1) {
  if (K < 0) K = P.K;
  double a = 0;
  for (int k = K; k >= 0; --k) a = a * h + P.F_at(k, 0);
  return a;
}

// A one-degree-of-freedom system with a given Lagrangian, for the core's Euler–Lagrange acceleration.
template <class Lag>
struct LagrangianOnly {
  static constexpr const char* name = "test";
  static constexpr int dof = 1, constraints = 0;
  Lag L;
  template <class S>
  S lagrangian(const S& t, const Vec<S, 1>& q, const Vec<S, 1>& v) const {
    return L(t, q(0), v(0));
  }
};
template <class Lag>
double el_acceleration(const Lag& L, double q, double v) {
  return generic::acceleration(LagrangianOnly<Lag>{L}, 0.0, Vec<double, 1>::Constant(q), Vec<double, 1>::Constant(v)).a(0);
}

}  // namespace

TEST_CASE("K = 1 reproduces the vector fields of the printed (8) and (11)", "[modified][automatic]") {
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> U(-2, 2);
  for (int i = 0; i < 40; ++i) {
    const double q = U(rng), v = U(rng), z = U(rng), alpha = std::abs(U(rng)), h = std::abs(U(rng)) / 10;
    const ParamValues pv{{"alpha", alpha}};
    // (8): LA as geomint derives it (the paper's (7) misprints the denominator; `la` is the derivation)
    const auto la = at("oscillator", "la", 1, q, v, z, pv);
    const double la_ref = modified_rhs("la", alpha, h, 1, {q, v, z})[1];
    CHECK(field(la, h) == Approx(la_ref).epsilon(1e-14).margin(1e-14));
    // (11): acceleration and z' = L_mod
    const auto ct = at("oscillator", "contact", 1, q, v, z, pv);
    const auto ref = modified_rhs("contact", alpha, h, 1, {q, v, z});
    CHECK(field(ct, h) == Approx(ref[1]).epsilon(1e-14).margin(1e-14));
    CHECK(ct.Z[0] + h * ct.Z[1] == Approx(ref[2]).epsilon(1e-14).margin(1e-14));
  }
}

TEST_CASE("oscillator: every F_k is the h-expansion coefficient of the all-orders damping and stiffness", "[modified][automatic]") {
  for (double alpha : {0.5, 1.0}) {  // at alpha = 0.1 the h^6 terms (alpha^7 h^6/7) fall below round-off
    const ParamValues pv{{"alpha", alpha}};
    for (const char* scheme : {"la", "contact"}) {
      const int K = 6;
      // q'' = -b(h) q - a(h) q': the coefficients of a and b read off F_k at (q, q') = (0, 1) and (1, 0)
      const auto Pa = at("oscillator", scheme, K, 0, 1, 0, pv), Pb = at("oscillator", scheme, K, 1, 0, 0, pv);
      // a_h = -ln(det)/h exactly, det = 1/(1 + h alpha) (la) or 1 - h alpha (contact): a_k = (-+1)^k alpha^(k+1)/(k+1)
      for (int k = 0; k <= K; ++k) {
        const double ak = (std::string(scheme) == "la" && k % 2 ? -1.0 : 1.0) * std::pow(alpha, k + 1) / (k + 1);
        INFO(scheme << " alpha " << alpha << " k " << k);
        CHECK(-Pa.F_at(k, 0) == Approx(ak).epsilon(1e-12).margin(1e-15));
      }
      // against all_orders (long double, from the one-step matrix of the closed forms): truncating the
      // series at K leaves O(h^(K+1)), for every K
      for (int Kt = 1; Kt <= 5; ++Kt) {
        std::vector<double> hs, da, db;
        for (double h : {0.2, 0.1, 0.05, 0.025}) {
          const auto ao = all_orders_by_name(scheme, h, alpha);
          hs.push_back(h);
          da.push_back(std::abs(ao.a + field(Pa, h, Kt)));
          db.push_back(std::abs(ao.b + field(Pb, h, Kt)));
        }
        INFO(scheme << " alpha " << alpha << " K " << Kt);
        CHECK(fit_order(hs, da, 1e-14).slope == Approx(Kt + 1).margin(0.25));
        const auto fb = fit_order(hs, db, 1e-14);
        // the stiffness may have vanishing coefficients (contact: b_1 = 0): the truncation error is at least O(h^(K+1))
        CHECK(fb.slope >= Kt + 1 - 0.25);
      }
    }
  }
}

TEST_CASE("Störmer–Verlet on the pendulum: q'' = -sin q - h^2/12 (q'^2 sin q + sin q cos q) + O(h^4) (HLW)", "[modified][automatic]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-2, 2);
  const ParamValues pv{{"alpha", 0.0}};
  for (int i = 0; i < 20; ++i) {
    const double q = U(rng), v = U(rng);
    const auto P = at("pendulum", "la-trapezoid", 4, q, v, 0, pv);
    CHECK(P.F_at(0, 0) == Approx(-std::sin(q)).epsilon(1e-15).margin(1e-15));
    CHECK(std::abs(P.F_at(1, 0)) < 1e-15);
    CHECK(P.F_at(2, 0) == Approx(-(v * v * std::sin(q) + std::sin(q) * std::cos(q)) / 12).epsilon(1e-13).margin(1e-15));
    CHECK(std::abs(P.F_at(3, 0)) < 1e-14);
  }
}

TEST_CASE("Störmer–Verlet frequency of the harmonic oscillator: (2/h) arcsin(h/2), every coefficient", "[modified][automatic]") {
  // w~^2 = b(h) = sum_k b_k h^k from arcsin x = sum_i (2i)!/(4^i i!^2 (2i+1)) x^(2i+1), w~ = sum_i c_i (h/2)^(2i)
  const int K = 6;
  std::vector<double> w(K + 1, 0.0);
  double c = 1;
  for (int i = 0; 2 * i <= K; ++i) {
    if (i > 0) c *= (2.0 * i - 1) * (2.0 * i) / (4.0 * i * i);  // (2i)!/(4^i i!^2)
    w[static_cast<std::size_t>(2 * i)] = c / (2 * i + 1) / std::pow(2.0, 2 * i);
  }
  const auto P = at("oscillator", "la-trapezoid", K, 1, 0, 0, {{"alpha", 0.0}});
  for (int k = 0; k <= K; ++k) {
    double bk = 0;
    for (int i = 0; i <= k; ++i) bk += w[static_cast<std::size_t>(i)] * w[static_cast<std::size_t>(k - i)];
    INFO("k " << k);
    CHECK(-P.F_at(k, 0) == Approx(bk).epsilon(1e-13).margin(1e-15));
  }
}

TEST_CASE("modified Lagrangians: Vermeeren's midpoint L + h^2/24 (U'^2 + U'' q'^2), Störmer–Verlet L + h^2/24 (U'^2 - 2 U'' q'^2)", "[modified][automatic]") {
  // The Euler–Lagrange equations of each modified Lagrangian (derived by the core's AD, to all orders in h)
  // agree with the automatic F_0 + h F_1 + h^2 F_2 + h^3 F_3 up to O(h^4); the sign of the correction flipped,
  // only to O(h^2).
  const ParamValues pv{{"alpha", 0.0}};
  for (int sign : {1, -1})
    for (const char* scheme : {"la-midpoint", "la-trapezoid"}) {
      std::vector<double> hs, err;
      const double q = 0.7, v = -0.4;
      const auto P = at("pendulum", scheme, 3, q, v, 0, pv);
      for (double h : {0.2, 0.1, 0.05, 0.025}) {
        const bool mid = std::string(scheme) == "la-midpoint";
        auto L = [h, mid, sign](const auto&, const auto& Q, const auto& V) {
          using std::cos;
          using std::sin;
          const auto U1 = sin(Q), U2 = cos(Q);
          return V * V / 2 - (1 - cos(Q)) + sign * h * h / 24 * (U1 * U1 + (mid ? 1.0 : -2.0) * U2 * V * V);
        };
        hs.push_back(h);
        err.push_back(std::abs(el_acceleration(L, q, v) - field(P, h)));
      }
      INFO(scheme << " sign " << sign);
      const double slope = fit_order(hs, err, 1e-14).slope;
      if (sign == 1)
        CHECK(slope == Approx(4).margin(0.2));
      else
        CHECK(slope == Approx(2).margin(0.2));
    }
}

TEST_CASE("constrained schemes at order 0: the continuous Lagrange–d'Alembert and Herglotz equations", "[modified][automatic][nonholonomic]") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-1, 1);
  const systems::KnifeEdge ke;
  const auto& ms = find_modified_system("knife-edge");
  for (int i = 0; i < 10; ++i) {
    Vec<double, 3> q(U(rng), U(rng), U(rng)), v(U(rng), U(rng), U(rng));
    v = generic::consistent_velocity(ke, 0.0, q, v);
    const double z = U(rng);
    const auto la = ms.at({}, "la", 0, 0.0, {q(0), q(1), q(2)}, {v(0), v(1), v(2)}, z, false);
    const auto ct = ms.at({}, "contact", 0, 0.0, {q(0), q(1), q(2)}, {v(0), v(1), v(2)}, z, false);
    const auto a = generic::acceleration(ke, 0.0, q, v).a;
    const auto ah = generic::herglotz_acceleration(ke, 0.0, q, v, z).a;
    for (int c = 0; c < 3; ++c) {
      CHECK(la.F_at(0, c) == Approx(a(c)).epsilon(1e-13).margin(1e-14));
      CHECK(ct.F_at(0, c) == Approx(ah(c)).epsilon(1e-13).margin(1e-14));
    }
    // the modified constraint starts with the continuous one: phi_0 = A v + b = 0 here
    CHECK(std::abs(la.phi[0]) < 1e-15);
  }
}

TEST_CASE("the residual vanishes to round-off with every coefficient in place, for every system and scheme", "[modified][automatic]") {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(-1, 1);
  for (const auto& sys : all_systems()) {
    const auto me = modified_system(sys);
    const ModifiedSystem& ms = *me;
    for (const auto& scheme : ms.schemes) {
      std::vector<double> q, v;
      for (int i = 0; i < ms.dof; ++i) {
        q.push_back(0.5 + 0.3 * U(rng));  // away from the Foucault constraint's singular origin
        v.push_back(0.3 * U(rng));
      }
      const auto P = ms.at({}, scheme, 4, 0.3, q, v, 0.1, true);
      double scale = 1;
      for (double f : P.F) scale = std::max(scale, std::abs(f));
      INFO(ms.name << " " << scheme << ": residual " << P.residual);
      CHECK(P.residual < 1e-12 * scale);
    }
  }
}

TEST_CASE("the generic shooting start agrees with the hand-derived starts of (8) and (11) to O(h^2)", "[modified][automatic]") {
  for (const char* scheme : {"la", "contact"}) {
    const double alpha = 0.5, q0 = -0.25, p0 = 0.75;
    std::vector<double> hs, diff;
    for (double h : {0.2, 0.1, 0.05, 0.025}) {
      const auto v = find_modified_system("oscillator").shoot({{"alpha", alpha}}, scheme, 1, h, 1e-13);
      const double hand = modified_initial_velocity(scheme, alpha, h, q0, p0, Start::consistent);
      hs.push_back(h);
      diff.push_back(std::abs(v[0] - hand));
    }
    INFO(scheme);
    CHECK(fit_order(hs, diff).slope == Approx(2).margin(0.2));
  }
}

TEST_CASE("meshed modified Lagrangians equal the published ones coefficient by coefficient", "[modified][automatic]") {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(-2, 2);
  const ParamValues pv{{"alpha", 0.0}};
  for (int i = 0; i < 20; ++i) {
    const double q = U(rng), v = U(rng);
    const double L = v * v / 2 - (1 - std::cos(q)), U1 = std::sin(q), U2 = std::cos(q);
    const auto sv = at("pendulum", "la-trapezoid", 3, q, v, 0, pv);
    const auto mid = at("pendulum", "la-midpoint", 3, q, v, 0, pv);
    CHECK(sv.lagrangian[0] == Approx(L).epsilon(1e-14).margin(1e-15));
    CHECK(std::abs(sv.lagrangian[1]) < 1e-15);
    CHECK(sv.lagrangian[2] == Approx((U1 * U1 - 2 * U2 * v * v) / 24).epsilon(1e-13).margin(1e-15));
    CHECK(mid.lagrangian[2] == Approx((U1 * U1 + U2 * v * v) / 24).epsilon(1e-13).margin(1e-15));
    // LA with a force (oscillator): L + h q q'/2 + O(h^2), a total derivative like (8)'s h q' q''/2
    const auto la = at("oscillator", "la", 1, q, v, 0, {{"alpha", 0.3}});
    CHECK(la.lagrangian[1] == Approx(q * v / 2).epsilon(1e-14).margin(1e-15));
    // contact: the modified Herglotz Lagrangian is z' itself
    const auto ct = at("oscillator", "contact", 2, q, v, 0.4, {{"alpha", 0.3}});
    for (int k = 0; k <= 2; ++k) CHECK(ct.lagrangian[static_cast<std::size_t>(k)] == ct.Z[static_cast<std::size_t>(k)]);
  }
}

// The modified equation to all orders of a linear system, x' = G x with G = log(M)/h (all_orders_linear), on the
// coupled oscillators (two degrees of freedom): (1) its flow passes through every step of the registry's run, to
// round-off (exp(G t_j) x_0 in long double against (q_j, p_j) over 100 steps); (2) in q alone, q'' = A_v q' + A_q q,
// it is the sum of the automatic modified equation's F_k: truncated at K, the series misses it by O(h^(K+1)),
// for every K and scheme (the entries of F_k read off at unit vectors: F_k is linear here). On the oscillator it is
// the characteristic roots' a_h, b_h (A_v = -a_h, A_q = -b_h) to round-off. The coupled oscillators' blocks of G
// commute (all are functions of one stiffness matrix), so the order of B G_qq in A_q is not tested here; a sign of
// B is (12 of these assertions fail).
TEST_CASE("linear systems: log(M)/h passes through every step, and the automatic series converges to it order by order",
          "[modified][automatic][all_orders]") {
  using Mat = Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic>;
  for (const char* scheme : {"la", "contact", "la-trapezoid"}) {
    const auto ao = all_orders_by_name(scheme, 0.1, 0.3);
    const auto lm = all_orders_linear(find_system("oscillator"), {{"alpha", 0.3}}, scheme, 0.1, Path::fast);
    INFO(scheme);
    CHECK(static_cast<double>(-lm.A_v[0]) == Approx(ao.a).epsilon(1e-12));
    CHECK(static_cast<double>(-lm.A_q[0]) == Approx(ao.b).epsilon(1e-12));
  }
  const SystemInfo& sys = find_system("coupled-oscillators");
  const int n = sys.dof, N = 2 * n;
  const ParamValues pv{{"T", 10}};
  const auto& modified = find_modified_system("coupled-oscillators");
  for (const char* scheme : {"la", "contact", "la-trapezoid"}) {
    INFO(scheme);
    // (1) the flow of G through the steps
    const double h = 0.1;
    const auto lm = all_orders_linear(sys, pv, scheme, h, Path::fast);
    Mat G(N, N);
    for (int r = 0; r < N; ++r)
      for (int c = 0; c < N; ++c) G(r, c) = lm.G[static_cast<std::size_t>(r * N + c)];
    const Run run = sys.run(pv, scheme, h, Path::fast, 1);
    Eigen::Matrix<long double, Eigen::Dynamic, 1> x0(N);
    for (int i = 0; i < n; ++i) {
      x0(i) = run.q[static_cast<std::size_t>(i)];
      x0(n + i) = run.p[static_cast<std::size_t>(i)];
    }
    double dev = 0, size = 0;
    for (std::size_t j = 0; j < run.j.size(); ++j) {
      const Mat E = (G * static_cast<long double>(run.t[j])).exp();
      const auto x = E * x0;
      for (int i = 0; i < n; ++i) {
        dev = std::max({dev, std::abs(static_cast<double>(x(i)) - run.q[j * static_cast<std::size_t>(n) + i]),
                        std::abs(static_cast<double>(x(n + i)) - run.p[j * static_cast<std::size_t>(n) + i])});
        size = std::max(size, std::abs(run.q[j * static_cast<std::size_t>(n) + i]));
      }
    }
    INFO("max |exp(G t_j) x_0 - x_j| = " << dev << " over " << run.j.size() << " steps");
    CHECK(dev < 1e-12 * size * static_cast<double>(run.j.size()));
    // (2) the automatic series against it, truncated at K = 1 .. 4
    const int K = 5;
    std::vector<ModifiedPoint> Pq, Pv;  // F at q = e_c, v = 0 and at q = 0, v = e_c
    for (int c = 0; c < n; ++c) {
      std::vector<double> e(static_cast<std::size_t>(n), 0.0), zero(static_cast<std::size_t>(n), 0.0);
      e[static_cast<std::size_t>(c)] = 1;
      Pq.push_back(modified.at(pv, scheme, K, 0, e, zero, 0, false));
      Pv.push_back(modified.at(pv, scheme, K, 0, zero, e, 0, false));
    }
    // The local order at the two finest h: the series is asymptotic, so it tends to K + 1 as h -> 0 (la's K = 2 is
    // still pre-asymptotic at h = 0.1 .. 0.0125: local orders 2.07 2.21 2.72, then 2.88). K = 4 is not asked: its
    // miss reaches the floor of M's round-off (M of the generic step in double; log(M)/h ~ 1e-12) by h = 0.00625.
    for (int Kt = 1; Kt <= 3; ++Kt) {
      std::vector<double> hs, miss;
      for (double hh : {0.05, 0.025, 0.0125, 0.00625}) {
        const auto L = all_orders_linear(sys, pv, scheme, hh, Path::fast);
        double worst = 0;
        for (int i = 0; i < n; ++i)
          for (int c = 0; c < n; ++c) {
            double sq = 0, sv = 0;
            for (int k = Kt; k >= 0; --k) {
              sq = sq * hh + Pq[static_cast<std::size_t>(c)].F_at(k, i);
              sv = sv * hh + Pv[static_cast<std::size_t>(c)].F_at(k, i);
            }
            worst = std::max({worst, std::abs(static_cast<double>(L.A_q[static_cast<std::size_t>(i * n + c)]) - sq),
                              std::abs(static_cast<double>(L.A_v[static_cast<std::size_t>(i * n + c)]) - sv)});
          }
        hs.push_back(hh);
        miss.push_back(worst);
      }
      const double finest = std::log2(miss[2] / miss[3]);
      INFO("K = " << Kt << ": misses " << miss[0] << " .. " << miss[3] << "; " << asymptotic_order(hs, miss).describe());
      CHECK(miss[3] > 1e-11);  // above the round-off floor: the order is read, not the noise
      CHECK(finest >= Kt + 1 - 0.25);
    }
  }
  // a step whose matrix has a negative real eigenvalue has no real logarithm: refused, with where
  CHECK_THROWS_AS(all_orders_linear(find_system("oscillator"), {{"alpha", 0.3}}, "la", 2.5, Path::fast), NumericalFailure);
}
