// Where the Foucault schemes fail: the plane-jump prediction from the paper's discrete constraint
// against measurement, the detector on a synthetic trajectory, the remedy ("rotation" discretization of (13))
// at round-off, without jumps and at its order, the long double / quad reruns, the ensemble machinery and
// the program.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <set>
#include <vector>

#include <Eigen/LU>

#include "geomint/constants.hpp"
#include "geomint/foucault_ensemble.hpp"
#include "geomint/plots/figure.hpp"
#include "geomint/study.hpp"
#include "geomint/observers.hpp"
#include "helpers.hpp"
#include "paper_restatements.hpp"

using namespace geomint;
using LaNh = systems::Foucault::La;          // (15)
using ContactNh = systems::Foucault::Contact;  // (18)
const std::string paper = systems::Foucault::name, rotation = systems::FoucaultRotation::name;

namespace {

constexpr double eps = std::numeric_limits<double>::epsilon();
constexpr double deg = 180 / geomint::pi;

systems::FoucaultPendulum scene(double alpha, double T) {
  systems::FoucaultPendulum sc;
  sc.alpha = alpha;
  sc.T = T;
  return sc;
}

double wrap_pi(double a) { return nearest_branch(a, 0.0, geomint::pi); }

// Landings found by the 64-run ensemble (the default when this was written; tau_k = h (k + 1/2)/64) and Figure 2's own
// runs (tau = 0).
struct Landing {
  const char* scheme;
  double alpha, h, tau;
  double jump_deg;  // measured, as recorded when the test was written
};
const Landing landings[] = {
    {"la-nh", 1e-4, 0.1, 0.0, 0.9500},              // Figure 2's LA run: 0.95 deg at t = 972.8 s (and twice more)
    {"contact-nh", 1e-4, 0.1, 0.0, -5.2376},        // Figure 2's contact run: 5.24 deg at t = 2967.8 s
    {"la-nh", 1e-3, 0.1, 0.1 * 53.5 / 64, -16.3489},
    {"contact-nh", 1e-3, 0.1, 0.1 * 59.5 / 64, -49.2674},
};

}  // namespace

TEST_CASE("the plane jump is the landing predicted by the paper's discrete constraint", "[foucault][anomaly]") {
  // Prediction (foucault_ensemble.hpp): the step into q_L turns the line by asin(-sigma s h |q_{L-1}|/|q_L|),
  // every other step of the half-swing contributes O(s h) beyond the exact -s dt. Measured over the 1321
  // jumps of the default ensemble: relative agreement 2.2e-4 for all > 0.1 deg, 1.9e-5 for those > 1 deg.
  // Tolerances 1e-3 and 1e-4: the s h / rho shortcut is off by ~rho (3e-4 for Figure 2's LA jump) and
  // leaving out |q_{L-1}| or the sign would fail them.
  long checked = 0, big = 0;
  for (const auto& L : landings) {
    const auto base = scene(1e-3, 3600);
    const auto run = run_anomaly(base, {L.scheme, paper, L.alpha, L.h, L.tau, 0}, 0.1 / deg);
    REQUIRE(run.status == "ok");
    INFO(L.scheme << " alpha " << L.alpha << " h " << L.h << " tau " << L.tau);
    // the recorded largest jump (regression record: the scheme is deterministic)
    CHECK(run.summary.max.measured * deg == Approx(L.jump_deg).epsilon(1e-4));
    REQUIRE(!run.jumps.empty());
    for (const auto& J : run.jumps) {
      INFO("t " << J.t_land << " rho " << J.rho << " measured " << J.measured * deg << " predicted "
                << J.predicted * deg);
      CHECK(J.measured * J.predicted > 0);  // the sign: before (+) or after (-) the origin
      CHECK(std::abs(J.measured - J.predicted) < 1e-3 * std::abs(J.predicted));
      ++checked;
      if (std::abs(J.predicted) * deg >= 1) {
        ++big;
        CHECK(std::abs(J.measured - J.predicted) < 1e-4 * std::abs(J.predicted));
        // the small-kick shortcut atan(s h / rho), to O(rho) and O(kick^2) (16 deg: 15.1 deg; 49 deg: 26 deg)
        if (std::abs(J.predicted) * deg < 10) CHECK(J.simple == Approx(std::abs(J.predicted)).epsilon(0.01));
        // The energy drops by sin^2 of the landing turn (the next step's force removes the velocity across
        // the new line). Measured to 3 % at 1 deg (the smooth O(h) energy wiggle of ~1e-5 adds to 3e-4), to
        // < 0.5 % above 5 deg.
        const double pl = std::pow(std::sin(J.predicted - base.s() * L.h), 2);
        CHECK(J.energy_loss == Approx(pl).epsilon(std::abs(J.predicted) * deg >= 5 ? 0.01 : 0.05));
      }
    }
  }
  CHECK(checked >= 10);
  CHECK(big >= 3);
}

TEST_CASE("the detector on a synthetic trajectory with one known kink", "[foucault][anomaly][detector]") {
  // q_j = A_j cos(w t_j) e(theta_j), theta_j = theta0 - s t_j (+ delta after the 5th crossing of the
  // origin), amplitude A -> f A after it, alpha = 0. The detector must see a jump of exactly delta over the
  // half-swing of that crossing, zero elsewhere, the landing nearest the crossing, an energy loss 1 - f^2, and
  // a final plane error delta.
  const auto sc = scene(0, 200);
  const FoucaultParams<double> p(sc);
  const double h = 0.1, A = 0.5, w = std::sqrt(p.w2), theta0 = 0.3, delta = 3.0 / deg, f = 0.9;
  const double t_cross = 4.5 * geomint::pi / w;  // 5th zero of cos(w t)
  const long N = 2000;
  auto point = [&](long j) {
    const double t = static_cast<double>(j) * h;
    const bool after = t > t_cross;
    const double r = (after ? f * A : A) * std::cos(w * t), th = theta0 - p.s * t + (after ? delta : 0.0);
    return Vec2<double>(r * std::cos(th), r * std::sin(th));
  };
  const double E0 = p.m * p.w2 * A * A / 2;
  {
    AnomalyDetector<systems::Foucault, double> det(p, h, N, theta0, E0, 0.5 / deg);
    for (long j = 0; j < N; ++j) {
      const Vec2<double> qm = point(j - 1), q = point(j), qn = point(j + 1);
      det(FoucaultStep<double>{j, static_cast<double>(j) * h, qm, q, qn, 0.0, 0.0, std::nan("")});
    }
    const auto S = det.summary();
    INFO("max jump " << S.max.measured * deg << " deg at t_land " << S.max.t_land);
    REQUIRE(det.jumps.size() == 1);
    const auto& J = det.jumps.front();
    CHECK(J.measured == Approx(delta).epsilon(1e-9));
    CHECK(S.max.measured == J.measured);
    // the landing is the grid point nearest the crossing
    const long j_near = std::lround(t_cross / h);
    CHECK(J.j_land == j_near);
    CHECK(J.r_land == Approx(std::abs(A * std::cos(w * static_cast<double>(j_near) * h))).epsilon(1e-12));
    CHECK(J.t_turn > t_cross);
    CHECK(J.t_turn - t_cross < geomint::pi / w);
    // energy at turning points: f^2 of the previous, to the O(h^2) wiggle of the chord energy
    CHECK(J.energy_loss == Approx(1 - f * f).margin(2e-3));
    CHECK(S.energy_ratio_end == Approx(f * f).margin(5e-3));
    CHECK(S.plane_error == Approx(delta).epsilon(1e-9));
    CHECK(S.half_swings == static_cast<long>((static_cast<double>(N) * h) * w / geomint::pi));
  }
  // Without the kink: no jump, plane error zero, to round-off.
  AnomalyDetector<systems::FoucaultRotation, double> det(p, h, N, theta0, E0, 0.5 / deg);
  auto smooth = [&](long j) {
    const double t = static_cast<double>(j) * h;
    const double r = A * std::cos(w * t), th = theta0 - p.s * t;
    return Vec2<double>(r * std::cos(th), r * std::sin(th));
  };
  for (long j = 0; j < N; ++j) {
    const Vec2<double> qm = smooth(j - 1), q = smooth(j), qn = smooth(j + 1);
    det(FoucaultStep<double>{j, static_cast<double>(j) * h, qm, q, qn, 0.0, 0.0, 0.0});
  }
  CHECK(det.jumps.empty());
  CHECK(std::abs(det.summary().max.measured) < 1e-13);
  CHECK(std::abs(det.summary().plane_error) < 1e-13);
  CHECK(det.summary().max.predicted == 0);  // rotation: the line is phi_j by construction
}

TEMPLATE_TEST_CASE("rotation: every step satisfies its rows, lies on the rotated line, and is the LU solve",
                   "[foucault][remedy]", LaNh, ContactNh) {
  // The paper's h = 0.1 hour at alpha = 1e-4, which passes within 1.3e-6 m of the origin.
  const auto sc = scene(1e-4, 3600);
  const double h = 0.1;
  const FoucaultParams<double> p(sc);
  const Vec2<double> q0(sc.x0, sc.y0);
  const double phi0 = std::atan2(q0(1), q0(0));
  double worst_line = 0, worst_angle = 0, worst_rows = 0, worst_lu = 0, min_r = 1;
  long steps = 0;
  systems::FoucaultRotation sys;
  static_cast<systems::FoucaultPendulum&>(sys) = sc;
  systems::run_closed_form<TestType>(
      sys, p, q0, Vec2<double>(0, 0), h, 36000, FoucaultStart::legendre,
      [&](const FoucaultStep<double>& st) {
        ++steps;
        // The carried angle is phi0 - s t_{j+1}, the exact plane angle; q_{j+1} lies on its line, and its own
        // angle equals it modulo pi, to round-off relative to |q_{j+1}| however close to the origin it is.
        const long double phin = static_cast<long double>(phi0) -
                                 static_cast<long double>(p.s) * (static_cast<long double>(st.j + 1) * h);
        CHECK(std::abs(static_cast<long double>(st.phin) - phin) < 4 * eps);
        const auto Ln = foucault_line<long double>(phin);
        const long double rn = std::hypot(static_cast<long double>(st.qn(0)), static_cast<long double>(st.qn(1)));
        worst_line = std::max(worst_line, static_cast<double>(std::abs(Ln.n(0) * st.qn(0) + Ln.n(1) * st.qn(1)) / rn));
        worst_angle = std::max(worst_angle, std::abs(wrap_pi(std::atan2(st.qn(1), st.qn(0)) - static_cast<double>(phin))));
        min_r = std::min(min_r, st.q.norm());
        // rows of the rotation system (header restatement) at round-off, and the closed form = PartialPivLU
        const auto L = foucault_line<double>(phi0 - p.s * (static_cast<double>(st.j) * h));
        const auto Lnd = foucault_line<double>(st.phin);
        const auto r = testing::rotation_rows<TestType>(p, st.qm, st.q, st.qn, st.lambda1, h, L, Lnd);
        const double scale_dyn = (st.qm.norm() + 2 * st.q.norm() + st.qn.norm()) /
                                 (std::is_same_v<TestType, LaNh> ? h : h * h);
        worst_rows = std::max({worst_rows, std::abs(r(0)) / scale_dyn, std::abs(r(1)) / scale_dyn,
                               std::abs(r(2)) / (st.q.norm() + st.qn.norm())});
        const auto ls = testing::rotation_system<TestType>(p, st.qm, st.q, h, L, Lnd);
        const Eigen::Vector3d z = ls.A.partialPivLu().solve(ls.b);
        worst_lu = std::max(worst_lu, (z.head<2>() - st.qn).norm() / (st.qm.norm() + st.q.norm()));
        // the determinant does not depend on q_j: c cos(s h) / m (the paper's is c |q_j|^2 / (m h))
        if (st.j % 5000 == 0) {
          const double c = std::is_same_v<TestType, LaNh> ? 1 / h + p.alpha : 1 / (h * h);
          CHECK(std::abs(ls.A.determinant()) == Approx(c * std::cos(p.s * h) / p.m).epsilon(1e-12));
        }
      });
  INFO(TestType::name << ": line " << worst_line / eps << " eps, angle " << worst_angle / eps << " eps, rows "
                      << worst_rows / eps << " eps, LU " << worst_lu / eps << " eps, min r " << min_r);
  CHECK(steps == 36000);
  CHECK(min_r < 2e-5);  // the run passed close to the origin
  // Measured: line and angle <= 1 eps (q_{j+1} is built as rho e(phi_{j+1})), the table rotation of e(phi)
  // adds <= 2 eps (measured: line 0.4 eps, angle 2 eps); rows ~1.4 eps.
  CHECK(worst_line < 4 * eps);
  CHECK(worst_angle < 4 * eps);
  CHECK(worst_rows < 8 * eps);
  CHECK(worst_lu < 16 * eps);  // the LU solve's own error (measured 5-6 eps); the closed form is the accurate one
}

TEST_CASE("rotation: a step from the origin itself is regular", "[foucault][remedy]") {
  // The paper's step throws NumericalFailure at q_j = 0 (tests/systems/foucault.test.cpp); the remedy's is a
  // plain step: the bob crosses the origin along the line.
  const auto sc = scene(1e-3, 1);
  const FoucaultParams<double> p(sc);
  const double h = 0.1;
  const auto L = foucault_line<double>(0.2), Ln = foucault_line<double>(0.2 - p.s * h);
  for (int k = 0; k < 2; ++k) {
    Vec2<double> qn;
    double l1;
    const Vec2<double> qm = 0.01 * L.e, q(0, 0);
    if (k == 0)
      LaNh::step_rotation(p, qm, q, h, L, Ln, qn, l1);
    else
      ContactNh::step_rotation(p, qm, q, h, L, Ln, qn, l1);
    CHECK(std::isfinite(l1));
    CHECK(std::abs(Ln.n.dot(qn)) < 1e-18);
    CHECK(Ln.e.dot(qn) < -0.009);  // carried on through the origin: ~ -0.01 (one more step's travel)
  }
}

TEST_CASE("rotation removes the jumps where the paper's discretization has them", "[foucault][remedy]") {
  const auto base = scene(1e-3, 3600);
  for (const auto& L : landings) {
    const AnomalyCase c{L.scheme, paper, L.alpha, L.h, L.tau, 0};
    AnomalyCase r = c;
    r.system = rotation;
    const auto rp = run_anomaly(base, c, 0.1 / deg), rr = run_anomaly(base, r, 0.1 / deg);
    REQUIRE(rp.status == "ok");
    REQUIRE(rr.status == "ok");
    INFO(L.scheme << " alpha " << L.alpha << " tau " << L.tau << ": paper " << rp.summary.max.measured * deg
                  << " deg, rotation " << rr.summary.max.measured * deg << " deg; energy ratio paper "
                  << rp.summary.energy_ratio_end << ", rotation " << rr.summary.energy_ratio_end
                  << "; plane error rotation " << rr.summary.plane_error);
    CHECK(std::abs(rp.summary.max.measured) * deg > 0.9);  // the paper's run does jump
    // The remedy's line is phi0 - s t at every step, so between turning points it turns by exactly -s dt:
    // measured 4e-16 rad. 1e-12 rad is 2500 times that and 10^10 below the paper's jumps.
    CHECK(std::abs(rr.summary.max.measured) < 1e-12);
    CHECK(rr.jumps.empty());
    CHECK(std::abs(rr.summary.plane_error) < 1e-12);
    CHECK(rr.summary.half_swings == rp.summary.half_swings);
    // Energy: the remedy follows E0 e^{-alpha t} to its smooth O(h) error (at h = 0.1: LA +1.5e-3 at alpha = 1e-3,
    // +3.5e-4 at 1e-4; contact 1e-5), where these paper runs lose 0.03 % to 43 %.
    CHECK(std::abs(rr.summary.energy_ratio_end - 1) < 3e-3);
    CHECK(rr.summary.energy_ratio_end > rp.summary.energy_ratio_end);
  }
}

TEST_CASE("rotation: fitted orders against the closed form, across passes through the origin", "[foucault][remedy][order]") {
  // T = 32 s holds 8 passes through the origin. The paper's contact scheme loses its O(h^2) look there
  // (fitted 0.98: a landing near the origin kicks the plane by s h / rho); the remedy keeps it (measured 2.002),
  // LA stays first order (1.002, same as the paper's: its error is its first-order Legendre transform), and at
  // alpha = 0.1 the contact remedy is first order like the paper's (the alpha^2 h term of (11); 0.996).
  auto err = [](const char* scheme, const std::string& system, double alpha, double T, const std::vector<double>& hs) {
    const auto sc = scene(alpha, T);
    const FoucaultParams<double> p(sc);
    const Vec2<double> q0(sc.x0, sc.y0), v0(0, 0);
    const Vec2<double> v0c = consistent_velocity(p, q0, v0);
    std::vector<double> e;
    for (double h : hs) {
      double m = 0;
      systems::visit_foucault_system(system, [&](auto sys) {
        using Sys = decltype(sys);
        static_cast<systems::FoucaultPendulum&>(sys) = sc;
        generic::visit_closed_form<Sys>(scheme, [&](auto s) {
          systems::run_closed_form<decltype(s)>(
              sys, p, q0, v0, h, step_count(h, T), FoucaultStart::legendre, [&](const FoucaultStep<double>& st) {
                m = std::max(m, (st.qn - foucault_exact(p, q0, v0c, static_cast<double>(st.j + 1) * h).q).norm());
              });
        });
      });
      e.push_back(m);
    }
    return e;
  };
  const auto hs = halving_sequence(0.1, 0.0015625);  // 7 points
  const auto& rot = rotation;
  CHECK(fit_order(hs, err("contact-nh", rot, 1e-3, 32, hs)).slope == Approx(2).margin(0.05));
  CHECK(fit_order(hs, err("contact-nh", rot, 1e-4, 32, hs)).slope == Approx(2).margin(0.05));
  CHECK(fit_order(hs, err("la-nh", rot, 1e-3, 32, hs)).slope == Approx(1).margin(0.05));
  CHECK(fit_order(hs, err("contact-nh", rot, 0.1, 32, hs)).slope == Approx(1).margin(0.05));
  // The contrast, recorded: the paper's contact over the same passes (fitted 0.98 at alpha = 1e-3).
  const auto printed = err("contact-nh", paper, 1e-3, 32, hs);
  const auto remedy = err("contact-nh", rot, 1e-3, 32, hs);
  CHECK(fit_order(hs, printed).slope < 1.5);
  CHECK(printed[4] > 10 * remedy[4]);  // h = 0.00625: 2.6e-5 m against 1.7e-6 m
}

TEST_CASE("long double and quad reruns give the same jump: it is the scheme, not rounding", "[foucault][anomaly][precision]") {
  // contact, alpha = 1e-3, h = 0.1, tau = 0.1 * 59.5/64: a 49.3 deg jump at t = 669.0 s, landing 1.3e-7 m from
  // the origin. Rerun from t = 0 up to just past it in long double and in quad (Boost.Multiprecision
  // cpp_bin_float_quad, through Eigen): measured relative differences 1.2e-7 (double vs wider: double's
  // round-off over 6700 steps, ~1e-14 m, divided by the landing distance) and 1.4e-10 (long double vs quad).
  const auto base = scene(1e-3, 3600);
  const AnomalyCase c{"contact-nh", paper, 1e-3, 0.1, 0.1 * 59.5 / 64, 59};
  const auto full = run_anomaly(base, c, 0.1 / deg);
  REQUIRE(full.status == "ok");
  const FoucaultJump J = full.summary.max;
  REQUIRE(std::abs(J.measured) * deg > 45);
  const long stop = J.j_turn + 2;
  const auto d = run_anomaly(base, c, 0.1 / deg, Precision::double_, stop);
  const auto ld = run_anomaly(base, c, 0.1 / deg, Precision::long_double, stop);
  const auto qd = run_anomaly(base, c, 0.1 / deg, Precision::quad, stop);
  const auto seg = rerun_anomaly_segment(base, c, 0.1 / deg, Precision::quad, J.j_prev_turn - 2, stop);
  for (const auto* r : {&d, &ld, &qd, &seg}) {
    REQUIRE(r->status == "ok");
    CHECK(r->summary.max.j_land == J.j_land);  // the same landing step
  }
  INFO("jump double " << J.measured << " long double " << ld.summary.max.measured << " quad "
                      << qd.summary.max.measured << " quad segment " << seg.summary.max.measured);
  CHECK(d.summary.max.measured == J.measured);  // the truncated double run is the same run
  CHECK(ld.summary.max.measured == Approx(J.measured).epsilon(1e-5));
  CHECK(qd.summary.max.measured == Approx(J.measured).epsilon(1e-5));
  CHECK(qd.summary.max.measured == Approx(ld.summary.max.measured).epsilon(1e-8));
  CHECK(qd.summary.max.measured != ld.summary.max.measured);  // really a different arithmetic
  CHECK(ld.summary.max.measured != J.measured);
  // From the double state one half-swing before, quad reproduces double's jump to the round-off of one
  // half-swing over the landing distance (1e-17 m / 1.3e-7 m).
  CHECK(seg.summary.max.measured == Approx(J.measured).epsilon(1e-8));
  CHECK(seg.summary.max.r_land == Approx(J.r_land).epsilon(1e-8));
}

TEST_CASE("ensemble: the time shift randomizes the landings, rotating or scaling q0 does not", "[foucault][ensemble]") {
  // First half-swing only (100 steps, h = 0.1, crossing at 4.1 s): record every half-swing (threshold 0).
  // From the landing, where the crossing fell within its step: xi = distance of the grid point before the
  // crossing to the origin, in steps (landing before the origin: r_L / (r_prev - r_L); after: r_prev /
  // (r_prev + r_L)). Over the ensemble xi must be uniform on [0, 1).
  const auto base = scene(1e-4, 3600);
  const long M = 32;
  std::vector<double> xi;
  for (long k = 0; k < M; ++k) {
    const auto r = run_anomaly(base, {"la-nh", paper, 1e-4, 0.1, 0.1 * (k + 0.5) / M, k}, 0.0,
                               Precision::double_, 100);
    REQUIRE(r.status == "ok");
    REQUIRE(!r.jumps.empty());
    const auto& J = r.jumps.front();
    xi.push_back(J.side > 0 ? J.r_land / (J.r_prev - J.r_land) : J.r_prev / (J.r_prev + J.r_land));
  }
  // Kolmogorov-Smirnov distance to uniform: the stratified tau makes it ~1/M; an ensemble that does not
  // move the grid (all xi equal) gives > 1/2.
  std::sort(xi.begin(), xi.end());
  double ks = 0;
  for (long i = 0; i < M; ++i) {
    const double F = xi[static_cast<size_t>(i)];
    ks = std::max({ks, std::abs(F - static_cast<double>(i) / M), std::abs(F - static_cast<double>(i + 1) / M)});
  }
  INFO("KS distance " << ks << ", xi from " << xi.front() << " to " << xi.back());
  CHECK(ks < 0.1);
  // Rotating q0 by 0.7 rad or scaling it by 1.5 leaves every landing ratio, hence every jump, unchanged:
  // the schemes are rotation-equivariant and the radial motion is linear. (Why the ensembles shift time.)
  systems::FoucaultPendulum turned = base, scaled = base;
  turned.x0 = 0.67 * std::cos(0.7);
  turned.y0 = 0.67 * std::sin(0.7);
  scaled.x0 = 1.5 * 0.67;
  const AnomalyCase c{"contact-nh", paper, 1e-4, 0.1, 0.0, 0};
  const auto r0 = run_anomaly(base, c, 0.1 / deg), rt = run_anomaly(turned, c, 0.1 / deg),
             rs = run_anomaly(scaled, c, 0.1 / deg);
  CHECK(rt.summary.max.measured == Approx(r0.summary.max.measured).epsilon(1e-6));
  CHECK(rs.summary.max.measured == Approx(r0.summary.max.measured).epsilon(1e-6));
  CHECK(rt.summary.max.rho == Approx(r0.summary.max.rho).epsilon(1e-6));
  CHECK(rs.summary.max.rho == Approx(r0.summary.max.rho).epsilon(1e-6));
  CHECK(rs.summary.max.r_land == Approx(1.5 * r0.summary.max.r_land).epsilon(1e-6));
}

TEST_CASE("ensemble runner and summary: rows for every case, failures as data", "[foucault][ensemble]") {
  const auto base = scene(1e-4, 400);
  auto cases = anomaly_cases({0.1, 0.05}, {1e-4}, {"la-nh", "contact-nh"}, {paper, rotation}, 6);
  REQUIRE(cases.size() == 2 * 2 * 2 * 6);
  CHECK(cases.front().h == 0.05);  // the expensive ones first
  std::set<double> taus;
  for (const auto& c : cases) {
    CHECK(c.tau >= 0);
    CHECK(c.tau < c.h);
    if (c.h == 0.1 && c.scheme == "la-nh" && c.system == paper) taus.insert(c.tau);
  }
  CHECK(taus.size() == 6);
  cases.push_back({"nosuch", paper, 1e-4, 0.1, 0.0, 99});
  std::size_t last_done = 0, calls = 0;
  const auto runs = run_anomaly_ensemble(base, cases, 0.1 / deg, 2, [&](std::size_t d, std::size_t n) {
    CHECK(d <= n);
    CHECK(d >= last_done);
    last_done = d;
    ++calls;
  });
  REQUIRE(runs.size() == cases.size());
  CHECK(last_done == cases.size());
  CHECK(calls >= 1);
  for (std::size_t i = 0; i + 1 < runs.size(); ++i) {
    CHECK(runs[i].status == "ok");
    CHECK(runs[i].c.tau == cases[i].tau);
    CHECK(runs[i].steps == step_count(cases[i].h, 400));
    if (runs[i].c.system == rotation) CHECK(std::abs(runs[i].summary.max.measured) < 1e-12);
  }
  CHECK(runs.back().status.find("unknown scheme 'nosuch'") != std::string::npos);
  // A numerical failure is a status too: |q0| = 1e200 overflows r_j^2 at the first step.
  systems::FoucaultPendulum huge = base;
  huge.x0 = 1e200;
  const auto bad = run_anomaly(huge, {"la-nh", paper, 1e-4, 0.1, 0.0, 0}, 0.1 / deg);
  CHECK(bad.status.find("numerical failure") != std::string::npos);
  // summary: one cell per (scheme, constraint, alpha, h) plus the failed case's own cell
  const auto cells = summarize_anomaly(base, runs, 0.1 / deg);
  REQUIRE(cells.size() == 2 * 2 * 2 + 1);
  for (const auto& c : cells) {
    if (c.scheme == "nosuch") {
      CHECK(c.failed == 1);
      CHECK(std::isnan(c.p_jump[0]));
      continue;
    }
    CHECK(c.runs == 6);
    CHECK(c.failed == 0);
    CHECK(c.p_jump[0] >= c.p_jump[1]);
    CHECK(c.p_jump[1] >= c.p_jump[2]);
    CHECK(c.mean_jumps[0] >= c.p_jump[0]);  // a run with a jump > 1 deg has at least one
    if (c.system == rotation) {
      CHECK(c.p_jump[0] == 0);
      CHECK(c.median_abs_plane_error_deg < 1e-10);
    }
    // N_pass 2 s h / sin K with N_pass = T omega_d / pi, restated
    const double wd = std::sqrt(base.g / base.l - base.s() * base.s() - c.alpha * c.alpha / 4);
    CHECK(c.mean_predicted[0] == Approx(400 * wd / geomint::pi * 2 * base.s() * c.h / std::sin(1 / deg)).epsilon(1e-12));
    CHECK(c.p_predicted[0] == Approx(1 - std::exp(-c.mean_predicted[0])).epsilon(1e-12));
  }
  CHECK(quantile({3, 1, 2, std::nan(""), 4}, 0.5) == Approx(2.5));
  CHECK(quantile({1, 2, 3, 4, 5}, 0.9) == Approx(4.6));
}

namespace {

struct BadInput {
  const char* args;
  const char* expect;
};

const BadInput anomaly_bad_inputs[] = {
    {"--runs 0", "runs must be in"},
    {"--h 0.1 0.7", "not an integer"},
    {"--alpha=-1", "alpha must be a non-negative"},
    {"--schemes nosuch", "unknown scheme 'nosuch'"},
    {"--systems foucault nosuch", "unknown constraint discretization 'nosuch'"},
    {"--threads 0", "threads must be in"},
    {"--record-deg 0", "record-deg must be in"},
    {"--worst -1", "worst must be in"},
    {"--T inf", "T must be a positive"},
    {"--l 0", "l must be a positive finite number"},
    {"--beta 95", "beta must be a latitude"},
    {"--bogus 1", "unrecognised option"},
};

}  // namespace

TEST_CASE("anomaly_foucault rejects bad input with one line, exit 2, and writes nothing", "[foucault][programs]") {
  using namespace geomint::testing;
  for (const auto& b : anomaly_bad_inputs) check_rejected("anomaly_foucault", b.args, b.expect);
  CHECK(run_program("anomaly_foucault", "--help").exit_code == 0);
}

TEST_CASE("anomaly_foucault writes tidy TSVs and figures", "[foucault][programs]") {
  using namespace geomint::testing;
  const auto dir = fresh_dir("anomaly-program");
  const auto r = run_program("anomaly_foucault", "--runs 3 --h 0.1 0.05 --T 400 --worst 1 --out " + dir.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  for (const char* f : {"anomaly_foucault_runs.tsv", "anomaly_foucault_jumps.tsv", "anomaly_foucault_summary.tsv",
                        "anomaly_foucault_precision.tsv", "anomaly_foucault_probability.png",
                        "anomaly_foucault_probability.pdf", "anomaly_foucault_runs.png", "anomaly_foucault_cause.png"})
    CHECK(std::filesystem::exists(dir / f));
  const auto runs = plots::read_tsv(dir / "anomaly_foucault_runs.tsv");
  REQUIRE(runs.rows.size() == 3 * 2 * 2 * 2 * 2);  // runs x h x alpha x schemes x constraints
  for (const char* col : {"scheme", "constraint", "alpha", "h", "max_jump_deg", "energy_ratio_end", "plane_error_deg",
                          "run", "tau", "landing_r", "landing_rho", "predicted_jump_deg", "status"})
    CHECK_NOTHROW(runs.column(col));
  for (std::size_t i = 0; i < runs.rows.size(); ++i) {
    CHECK(runs.text(i, "status") == "ok");
    if (runs.text(i, "constraint") == "rotation") CHECK(std::abs(runs.number(i, "max_jump_deg")) < 1e-10);
  }
  const auto sum = plots::read_tsv(dir / "anomaly_foucault_summary.tsv");
  CHECK(sum.rows.size() == 2 * 2 * 2 * 2);
  const auto prec = plots::read_tsv(dir / "anomaly_foucault_precision.tsv");
  CHECK(prec.rows.size() == 2 * 3);  // worst 1 per scheme x (double, long double, quad)
  for (std::size_t i = 0; i < prec.rows.size(); ++i) CHECK(prec.text(i, "status") == "ok");
  std::filesystem::remove_all(dir);
}

TEST_CASE("fig2_foucault --system foucault-rotation: the remedy's Figure 2, beside the paper's", "[foucault][programs]") {
  using namespace geomint::testing;
  const auto dir = fresh_dir("foucault-fig2-rotation");
  const auto r = run_program("fig2_foucault", "--T 400 --h 0.1 --system foucault-rotation --out " + dir.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  for (const char* f : {"fig2_foucault_rotation.tsv", "fig2_foucault_rotation_summary.tsv", "fig2_foucault_rotation.png",
                        "fig2_foucault_rotation_plane.png"})
    CHECK(std::filesystem::exists(dir / f));
  CHECK(!std::filesystem::exists(dir / "fig2_foucault.tsv"));  // the paper's files are not overwritten
  const auto sum = plots::read_tsv(dir / "fig2_foucault_rotation_summary.tsv");
  REQUIRE(sum.rows.size() == 4);
  for (size_t i = 0; i < sum.rows.size(); ++i) {
    CHECK(sum.text(i, "status") == "ok");
    CHECK(sum.number(i, "max_residual_scaled") < 4 * eps);  // |n(phi_{j+1}).q_{j+1}| / (|q_j| + |q_{j+1}|)
    // the fitted precession rate is -Omega sin(beta) to round-off (the paper's discretization: 0.1-30 % off)
    CHECK(std::abs(sum.number(i, "rate_over_minus_s") - 1) < 1e-9);
  }
  std::filesystem::remove_all(dir);
}
