// The Foucault pendulum (Section 3.2): the nonholonomic steps (15) and (18) against a literal restatement
// and against an Eigen LU solve of their 3x3 systems, the discrete constraint at round-off, the starting
// procedure, long double against double (including passes close to the origin), fitted orders and the
// precession rate against the continuous reference, the reference against its closed form, the programs.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <type_traits>
#include <vector>

#include <Eigen/LU>

#include "geomint/constants.hpp"
#include "geomint/foucault_diagnostics.hpp"
#include "geomint/plots/figure.hpp"
#include "geomint/study.hpp"
#include "geomint/sweep.hpp"
#include "helpers.hpp"
#include "paper_restatements.hpp"

using namespace geomint;
using namespace geomint::testing;
using LaNh = systems::Foucault::La;          // (15)
using ContactNh = systems::Foucault::Contact;  // (18)

namespace {

constexpr double eps = std::numeric_limits<double>::epsilon();

// q_{-1} (virtual), q_0, ..., q_N and lambda_1 of every step, for a scheme in scalar type T.
template <class T>
struct Trajectory {
  std::vector<Vec2<T>> q;  // q[j + 1] = q_j
  std::vector<T> lambda1;  // lambda1[j]: multiplier of the step j -> j+1
  const Vec2<T>& at(long j) const { return q[static_cast<size_t>(j + 1)]; }
};

template <class Scheme, class T = double>
Trajectory<T> trajectory(const systems::Foucault& sc, double h, FoucaultStart start = FoucaultStart::legendre) {
  const FoucaultParams<T> p(sc);
  const long N = step_count(h, sc.T);
  const Vec2<T> q0(T(sc.x0), T(sc.y0)), v0(T(sc.vx0), T(sc.vy0));
  Trajectory<T> tr;
  tr.q.reserve(static_cast<size_t>(N) + 2);
  tr.lambda1.reserve(static_cast<size_t>(N));
  tr.q.push_back(Scheme::previous_point(p, q0, v0, T(h), start));
  tr.q.push_back(q0);
  systems::run_closed_form<Scheme>(sc, p, q0, v0, T(h), N, start, [&](const FoucaultStep<T>& st) {
    tr.q.push_back(st.qn);
    tr.lambda1.push_back(st.lambda1);
  });
  return tr;
}

Vec2<long double> to_ld(const Vec2<double>& v) { return Vec2<long double>(v(0), v(1)); }

systems::Foucault scene(double alpha, double T) {
  systems::Foucault sc;
  sc.alpha = alpha;
  sc.T = T;
  return sc;
}

// The runs the step tests walk along: the paper's h = 0.1 hour at alpha = 1e-4, whose steps come within
// 1.3e-6 m (contact) and 8e-6 m (LA) of the origin, and a finer one.
struct Case {
  double alpha, h, T;
};
const Case step_cases[] = {{1e-4, 0.1, 3600}, {1e-3, 0.02, 600}};

}  // namespace

TEMPLATE_TEST_CASE("every step satisfies (15)/(18) as printed, to round-off", "[foucault][step]", LaNh,
                   ContactNh) {
  for (const auto& c : step_cases) {
    const auto sc = scene(c.alpha, c.T);
    const Literal P(sc);
    const FoucaultParams<double> p(sc);
    const auto tr = trajectory<TestType>(sc, c.h);
    double worst[3] = {0, 0, 0};
    for (long j = 0; j + 1 < static_cast<long>(tr.q.size()) - 1; ++j) {
      double row[3], scale[3];
      literal_rows<TestType>(P, c.h, tr.at(j - 1), tr.at(j), tr.at(j + 1), tr.lambda1[static_cast<size_t>(j)], row,
                             scale);
      for (int i = 0; i < 3; ++i) worst[i] = std::max(worst[i], std::abs(row[i]) / scale[i]);
    }
    INFO(TestType::name << " alpha " << c.alpha << " h " << c.h << ": worst row/scale " << worst[0] << " "
                        << worst[1] << " " << worst[2]);
    // Tolerance 8 eps of the sum of the terms' magnitudes: the solve moves q_{j+1} by <= 2.5 eps (|q_{j-1}| + |q_j|)
    // (see the long double test) and evaluating the row adds a few eps. A wrong sign or factor gives O(1).
    for (int i = 0; i < 3; ++i) CHECK(worst[i] < 8 * eps);
  }
}

TEMPLATE_TEST_CASE("the discrete constraint holds to round-off at every step", "[foucault][constraint]", LaNh,
                   ContactNh) {
  for (const auto& c : step_cases) {
    const auto sc = scene(c.alpha, c.T);
    const Literal P(sc);
    const auto tr = trajectory<TestType>(sc, c.h);
    double worst = 0, worst_natural = 0;
    for (long j = 0; j + 1 < static_cast<long>(tr.q.size()) - 1; ++j) {
      const auto& q = tr.at(j);
      const auto& qn = tr.at(j + 1);
      // (13) o Psi: -y_j (x_{j+1} - x_j)/h + x_j (y_{j+1} - y_j)/h + s (x_j^2 + y_j^2)
      const double phid = -q(1) * (qn(0) - q(0)) / c.h + q(0) * (qn(1) - q(1)) / c.h + P.s * q.squaredNorm();
      // Round-off scale: storing q_{j+1} to eps moves Phi_d by eps |q_j| |q_{j+1}| / h.
      worst = std::max(worst, std::abs(phid) / (q.norm() * (q.norm() + qn.norm()) / c.h));
      if (q.norm() > 0.01) worst_natural = std::max(worst_natural, std::abs(phid) / (P.s * q.squaredNorm()));
    }
    INFO(TestType::name << " alpha " << c.alpha << " h " << c.h << ": " << worst << " (natural " << worst_natural << ")");
    CHECK(worst < 4 * eps);
    // Against the constraint's own size s r^2 (away from the origin) this is ~1e-10, where a wrong lambda gives 1.
    CHECK(worst_natural < 1e-9);
    // and the diagnostics observer reports the same
    const auto run = run_foucault("foucault", TestType::alias, sc, c.h, FoucaultStart::legendre, 1000);
    CHECK(run.summary.max_residual < 4 * eps);
  }
}

TEMPLATE_TEST_CASE("paper_system is the literal 3x3 system and the closed form equals its PartialPivLU solve",
                   "[foucault][step]", LaNh, ContactNh) {
  const auto sc = scene(1e-4, 3600);
  const double h = 0.1;
  const Literal P(sc);
  const FoucaultParams<double> p(sc);
  const auto tr = trajectory<TestType>(sc, h);
  double worst_q = 0, worst_sys = 0, min_r = 1;
  for (long j = 0; j + 1 < static_cast<long>(tr.q.size()) - 1; ++j) {
    const auto& qm = tr.at(j - 1);
    const auto& q = tr.at(j);
    const auto ls = paper_system<TestType>(p, qm, q, h);
    // A z - b is the printed rows at z, for any z: here at the closed-form solution and at a perturbed one.
    for (double shift : {0.0, 1e-3}) {
      const Eigen::Vector3d z(tr.at(j + 1)(0) + shift, tr.at(j + 1)(1) - shift,
                              tr.lambda1[static_cast<size_t>(j)] * (1 + shift));
      double row[3], scale[3];
      literal_rows<TestType>(P, h, qm, q, Vec2<double>(z(0), z(1)), z(2), row, scale);
      const Eigen::Vector3d az = ls.A * z - ls.b;
      for (int i = 0; i < 3; ++i) worst_sys = std::max(worst_sys, std::abs(az(i) - row[i]) / scale[i]);
    }
    const Eigen::Vector3d z = ls.A.partialPivLu().solve(ls.b);
    worst_q = std::max(worst_q, (z.head<2>() - tr.at(j + 1)).norm() / (qm.norm() + q.norm()));
    min_r = std::min(min_r, q.norm());
  }
  INFO(TestType::name << ": |q_LU - q_closed| / (|q_{j-1}| + |q_j|) <= " << worst_q / eps << " eps, min r " << min_r);
  CHECK(worst_sys < 8 * eps);
  // Both solves are accurate to ~3 eps (|q_{j-1}| + |q_j|) (measured against long double); 8 eps leaves room.
  CHECK(worst_q < 8 * eps);
  CHECK(min_r < 2e-5);  // the comparison included steps very close to the origin
}

TEST_CASE("the legendre start is the discrete Legendre transform with the constraint force", "[foucault][start]") {
  const auto sc = scene(1e-3, 1);
  const Literal P(sc);
  const FoucaultParams<double> p(sc);
  const Vec2<double> q0(sc.x0, sc.y0);
  const Vec2<double> A0(-q0(1), q0(0));  // covector of (13) at q0
  // v0 projected onto (13) by hand: v0 = 0, so v0' = -s A(q0) (then -y0 v'x + x0 v'y + s r0^2 = 0).
  const Vec2<double> v0c = -P.s * A0;
  REQUIRE((consistent_velocity(p, q0, Vec2<double>(0, 0)) - v0c).norm() < 1e-20);
  for (double h : {0.1, 0.01}) {
    const auto la = trajectory<LaNh>(sc, h);
    const auto ct = trajectory<ContactNh>(sc, h);
    const Vec2<double> q1 = la.at(1), c1 = ct.at(1);
    // LA: p0 - lambda A(q0) = -D1 L_d(q0, q1) - F_d^-(q0, q1) = m (1/h + alpha)(q1 - q0) + m h w2 q0
    // Tolerance: a two-step scheme carries momentum as position differences over h, so q_{-1} and q_1 stored
    // to eps near q0 resolve momentum to eps m |q0| / h (1.9e-13 N s at h = 0.01). A wrong start (no
    // projection, no constraint force, the wrong discrete momentum) is off by ~ m s |q0| ~ 1e-3 N s.
    const double resolution = eps * P.m * q0.norm() / h;
    const Vec2<double> lhs = P.m * (1 / h + P.alpha) * (q1 - q0) + P.m * h * P.w2 * q0;
    const Vec2<double> rhs = P.m * v0c - la.lambda1[0] * A0;
    INFO("h " << h << ": LA " << (lhs - rhs).norm() / resolution << " x resolution");
    CHECK((lhs - rhs).norm() < 4 * resolution);
    CHECK(lhs.norm() > 1e-4);  // not trivially zero
    // contact: p0 - h lambda A(q0)/(1 - h alpha) = -D1 L_d(q0, q1, z0)/(1 + D3 L_d) = m ((q1-q0)/h + h w2 q0/2)/(1 - h alpha)
    const double k = 1 - h * P.alpha;
    const Vec2<double> lhs_c = P.m * ((c1 - q0) / h + h * P.w2 / 2 * q0) / k;
    const Vec2<double> rhs_c = P.m * v0c - h * ct.lambda1[0] * A0 / k;
    INFO("contact " << (lhs_c - rhs_c).norm() / resolution << " x resolution");
    CHECK((lhs_c - rhs_c).norm() < 4 * resolution);
    CHECK(lhs_c.norm() > 1e-4);
    // both put q1 on the discrete constraint
    for (const auto& x : {q1, c1})
      CHECK(std::abs(-q0(1) * (x(0) - q0(0)) / h + q0(0) * (x(1) - q0(1)) / h + P.s * q0.squaredNorm()) < 4 * eps * q0.squaredNorm() * 2 / h);
    // LA's taylor start (q_{-1} = q0 - h v0, raw v0) gives the same q1: lambda absorbs the A(q0) part.
    const auto la_t = trajectory<LaNh>(sc, h, FoucaultStart::taylor);
    CHECK((la_t.at(1) - q1).norm() < 4 * eps);
    // Contact's taylor start misses the discrete momentum's h w2 q0/2: q1 moves by (1 - h alpha) h^2 w2 |q0|/2.
    const auto ct_t = trajectory<ContactNh>(sc, h, FoucaultStart::taylor);
    CHECK((ct_t.at(1) - c1).norm() == Approx(k * h * h * P.w2 * q0.norm() / 2).epsilon(1e-9));
  }
}

TEMPLATE_TEST_CASE("long double agrees with double: the solve near the origin and whole runs", "[foucault][scalar]",
                   LaNh, ContactNh) {
  using LD = long double;
  REQUIRE(std::numeric_limits<LD>::epsilon() < eps / 100);  // really a wider type
  SECTION("each step from the same inputs, including steps that land within 1e-7 m of the origin") {
    // alpha = 1e-4, h = 0.005: LA lands 1.6e-8 m from the origin at t = 1227.4 s (the closest pass of Figure 2).
    const auto sc = scene(1e-4, 1300);
    const double h = 0.005;
    const FoucaultParams<double> p(sc);
    const FoucaultParams<LD> pl(sc);
    const auto tr = trajectory<TestType>(sc, h);
    double worst = 0, min_r = 1;
    for (long j = 0; j + 1 < static_cast<long>(tr.q.size()) - 1; ++j) {
      const auto& qm = tr.at(j - 1);
      const auto& q = tr.at(j);
      Vec2<LD> qn;
      LD l1;
      TestType::step(pl, to_ld(qm), to_ld(q), LD(h), qn, l1, j);
      const LD err = (to_ld(tr.at(j + 1)) - qn).norm();
      worst = std::max(worst, static_cast<double>(err / LD(qm.norm() + q.norm())));
      min_r = std::min(min_r, q.norm());
    }
    INFO(TestType::name << ": worst step error " << worst / eps << " eps (|q_{j-1}| + |q_j|), min r " << min_r);
    // Measured <= 2.5 eps. Computing lambda from q_{j-1} x (q_j - q_{j-1}) instead of q_{j-1} x q_j gave up to
    // 1250 eps here: the rounding of the difference, crossed with q_{j-1}, divided by r_j.
    CHECK(worst < 4 * eps);
    CHECK(min_r < (std::is_same_v<TestType, LaNh> ? 1e-7 : 1e-5));
  }
  SECTION("a whole hour at h = 0.1, alpha = 1e-4: same trajectory, same plane jumps") {
    const auto sc = scene(1e-4, 3600);
    const double h = 0.1;
    const auto d = trajectory<TestType, double>(sc, h);
    const auto l = trajectory<TestType, LD>(sc, h);
    double worst = 0;
    for (size_t i = 0; i < d.q.size(); ++i) worst = std::max(worst, static_cast<double>((to_ld(d.q[i]) - l.q[i]).norm()));
    INFO(TestType::name << ": max |q_double - q_long_double| = " << worst);
    // A pass at distance u from the origin turns the plane by kappa = s h |dq|/u and amplifies an earlier
    // perturbation by ~ kappa |q0| / u: ~5e4 for contact's pass at 1.3e-6 m (t = 2968 s). Round-off
    // accumulated before it (~1e-13 m) then gives ~5e-9 m, measured 5e-9; 1e-7 m is 20 times that.
    CHECK(worst < 1e-7);
    CHECK(worst > 0);
    // the largest plane jump is a property of the scheme, not of the rounding
    FoucaultDiagnostics<systems::Foucault, double> dd(FoucaultParams<double>(sc), h, 36000, 36000, Vec2<double>(sc.x0, sc.y0),
                                   Vec2<double>(0, 0));
    FoucaultDiagnostics<systems::Foucault, LD> dl(FoucaultParams<LD>(sc), LD(h), 36000, 36000, Vec2<LD>(LD(sc.x0), LD(sc.y0)),
                               Vec2<LD>(0, 0));
    systems::run_closed_form<TestType>(sc, FoucaultParams<double>(sc), Vec2<double>(sc.x0, sc.y0), Vec2<double>(0, 0), h,
                                       36000, FoucaultStart::legendre, dd);
    systems::run_closed_form<TestType>(sc, FoucaultParams<LD>(sc), Vec2<LD>(LD(sc.x0), LD(sc.y0)), Vec2<LD>(0, 0), LD(h),
                                       36000, FoucaultStart::legendre, dl);
    CHECK(dd.summary().max_jump == Approx(dl.summary().max_jump).epsilon(1e-6));
    CHECK(dd.summary().t_max_jump == dl.summary().t_max_jump);
  }
}

TEST_CASE("the LA anomaly of Figure 2 (alpha = 1e-4, h = 0.1) is a close pass, and contact has a larger one",
          "[foucault][anomaly]") {
  // Not a property we want, a property we observed and report (docs/where-methods-fail.md): recorded so a change shows.
  const auto sc = scene(1e-4, 3600);
  const double s = sc.s();
  const auto la = run_foucault("foucault", "la-nh", sc, 0.1, FoucaultStart::legendre, 1000).summary;
  const auto ct = run_foucault("foucault", "contact-nh", sc, 0.1, FoucaultStart::legendre, 1000).summary;
  // LA: the grid lands 8.1e-6 m from the origin at t = 972.8 s (|q_j| / |dq| = 3.3e-4): the plane turns by
  // s h / 3.3e-4 = 0.95 deg and the energy drops by 1 - cos^2 of that; the same pass recurs every ~1100 s.
  CHECK(la.min_pass_ratio == Approx(3.32e-4).epsilon(0.01));
  CHECK(la.t_min_pass_ratio == Approx(972.8).margin(0.05));
  CHECK(la.max_jump == Approx(s * 0.1 / la.min_pass_ratio).epsilon(0.05));
  CHECK(la.max_energy_loss == Approx(1 - std::pow(std::cos(la.max_jump), 2)).epsilon(0.1));
  CHECK(la.rate / -s == Approx(0.737).margin(0.01));
  // contact: 1.3e-6 m at t = 2967.8 s, 5.3 degrees, 0.83 % of the energy.
  CHECK(ct.min_pass_ratio == Approx(6.05e-5).epsilon(0.01));
  CHECK(ct.max_jump * 180 / geomint::pi == Approx(5.26).margin(0.05));
  CHECK(ct.max_energy_loss == Approx(8.3e-3).epsilon(0.02));
}

TEST_CASE("precession rate on runs where no step passes near the origin", "[foucault][precession]") {
  // "Near": a step landing at |q_j| < 0.02 |q_{j+1} - q_j| (which turns the plane by > 50 s h, see
  // FoucaultSummary::min_pass_ratio). On the two runs below every pass stays farther: each turns the plane
  // by < 50 s h (< 2.8e-5 rad at h = 0.01, against 4.5e-4 rad of true precession per half swing, and of
  // either sign). Their fitted rates are within 0.1 % of -Omega sin(beta); the tolerance 1 % is 10 times
  // that and 25 times below the error the close passes of the h = 0.1, alpha = 1e-4 hour produce (26-33 %).
  struct Run {
    const char* scheme;
    double alpha, h, T;
  };
  for (const Run r : {Run{"la-nh", 1e-4, 0.01, 400}, Run{"contact-nh", 1e-4, 0.005, 200}}) {
    const auto sc = scene(r.alpha, r.T);
    const auto S = run_foucault("foucault", r.scheme, sc, r.h, FoucaultStart::legendre, 100000).summary;
    INFO(r.scheme << " h " << r.h << " T " << r.T << ": closest pass ratio " << S.min_pass_ratio << ", rate/-s "
                  << S.rate / -sc.s() << " from " << S.rate_points << " turning points");
    REQUIRE(S.min_pass_ratio > 0.02);
    CHECK(S.rate_points >= 2 * static_cast<int>(r.T / 16.5));
    CHECK(std::abs(S.rate / -sc.s() - 1) < 0.01);
    CHECK(S.max_jump < 2e-3);  // no jump: about s times a half period (4.5e-4 rad)
  }
}

TEST_CASE("the continuous reference against its closed form", "[foucault][reference]") {
  const auto sc = scene(1e-3, 100);  // six periods, twelve passes through the origin
  const FoucaultParams<double> p(sc);
  const Vec2<double> q0(sc.x0, sc.y0);
  const Vec2<double> v0c = consistent_velocity(p, q0, Vec2<double>(0, 0));
  std::vector<double> times;
  for (int i = 0; i <= 1000; ++i) times.push_back(0.1 * i);
  const auto ref = foucault_reference(sc, times, 1e-12);
  double dq = 0, dv = 0, dtheta = 0, dphi = 0;
  for (size_t i = 0; i < times.size(); ++i) {
    const auto ex = foucault_exact(p, q0, v0c, times[i]);
    const Vec2<double> q(ref[i][0], ref[i][1]), v(ref[i][2], ref[i][3]);
    dq = std::max(dq, (q - ex.q).norm());
    dv = std::max(dv, (v - ex.v).norm());
    // (13) along the reference, and the plane angle theta0 - s t (mod pi) away from the origin
    dphi = std::max(dphi, std::abs(-q(1) * v(0) + q(0) * v(1) + p.s * q.squaredNorm()));
    if (q.norm() > 0.1) {
      const double d = std::atan2(q(1), q(0)) - (0 - p.s * times[i]);
      dtheta = std::max(dtheta, std::abs(d - geomint::pi * std::round(d / geomint::pi)));
    }
  }
  INFO("reference vs closed form: |dq| " << dq << " |dv| " << dv << " |Phi| " << dphi << " |dtheta| " << dtheta);
  // Odeint at tol 1e-12 (relative and absolute) over 100 s: measured ~1e-11.
  CHECK(dq < 1e-9);
  CHECK(dv < 1e-9);
  CHECK(dphi < 1e-10);  // the differentiated constraint keeps (13) to the integration error
  CHECK(dtheta < 1e-9);
}

TEST_CASE("the closed form solves the Lagrange-d'Alembert equations and (13)", "[foucault][reference]") {
  // Independent of Odeint: central differences of the closed-form velocity (long double) against the
  // right-hand side with the multiplier lambda = m [alpha (y x' - x y') + 2 s (x x' + y y')] / (x^2 + y^2).
  using LD = long double;
  for (double alpha : {0.0, 1e-3, 0.3}) {
    auto sc = scene(alpha, 100);
    sc.vx0 = 0.05;  // a start with a radial and a tangential velocity, projected onto (13)
    sc.vy0 = 0.02;
    const FoucaultParams<LD> p(sc);
    const Vec2<LD> q0(LD(sc.x0), LD(sc.y0));
    const Vec2<LD> v0 = consistent_velocity(p, q0, Vec2<LD>(LD(sc.vx0), LD(sc.vy0)));
    double worst = 0, worst_phi = 0;
    for (LD t : {0.7L, 3.1L, 9.9L, 23.4L, 61.2L}) {
      const auto x = foucault_exact(p, q0, v0, t);
      const LD d = 1e-4L;
      const Vec2<LD> acc = (foucault_exact(p, q0, v0, t + d).v - foucault_exact(p, q0, v0, t - d).v) / (2 * d);
      const Vec2<LD> qd = (foucault_exact(p, q0, v0, t + d).q - foucault_exact(p, q0, v0, t - d).q) / (2 * d);
      const LD X = x.q(0), Y = x.q(1), VX = x.v(0), VY = x.v(1);
      const LD lm = (p.alpha * (Y * VX - X * VY) + 2 * p.s * (X * VX + Y * VY)) / (X * X + Y * Y);
      const Vec2<LD> rhs(-p.w2 * X - p.alpha * VX + lm * Y, -p.w2 * Y - p.alpha * VY - lm * X);
      worst = std::max(worst, static_cast<double>((acc - rhs).norm() / (p.w2 * x.q.norm() + x.v.norm())));
      worst = std::max(worst, static_cast<double>((qd - x.v).norm() / x.v.norm()));
      worst_phi = std::max(worst_phi, static_cast<double>(std::abs(foucault_constraint(p, x.q, x.v))));
    }
    INFO("alpha " << alpha << ": " << worst << ", Phi " << worst_phi);
    CHECK(worst < 1e-8);       // central difference error d^2/6 |q'''| / |q''| ~ 1e-10
    CHECK(worst_phi < 1e-15);  // (13) exactly, up to long double round-off
  }
}

TEST_CASE("fitted orders against the continuous reference", "[foucault][order]") {
  // Horizon T = 4 s: the first quarter swing, before the first pass through the origin (t = 4.105 s), so
  // no step lands near it (a close pass adds an O(h) plane kick that depends on where the grid falls; see
  // the convergence study for T = 32 s). The reference is Odeint at tol 1e-12 (~1e-12 m here, far below the
  // smallest error fitted, 2.4e-7 m).
  auto errors = [](const std::string& scheme, double alpha, const std::vector<double>& hs) {
    const auto sc = scene(alpha, 4);
    const FoucaultParams<double> p(sc);
    const double hr = hs.back();
    const long Nr = step_count(hr, sc.T);
    std::vector<double> times;
    for (long i = 0; i <= Nr; ++i) times.push_back(static_cast<double>(i) * hr);
    const auto ref = foucault_reference(sc, times, 1e-12);
    std::vector<double> e;
    for (double h : hs) {
      const long stride = std::lround(h / hr);
      double m = 0;
      generic::visit_closed_form<systems::Foucault>(scheme, [&](auto s) {
        systems::run_closed_form<decltype(s)>(sc, p, Vec2<double>(sc.x0, sc.y0), Vec2<double>(0, 0), h, step_count(h, sc.T),
                                              FoucaultStart::legendre, [&](const FoucaultStep<double>& st) {
                                                const auto& r = ref[static_cast<size_t>((st.j + 1) * stride)];
                                                m = std::max(m, std::hypot(st.qn(0) - r[0], st.qn(1) - r[1]));
                                              });
      });
      e.push_back(m);
    }
    return e;
  };
  const auto hs = halving_sequence(0.1, 0.00625);     // 0.1 .. 0.00625, 5 points
  const auto hs_small = halving_sequence(0.025, 0.0015625);  // 5 points
  // LA: clean first order (its discrete Legendre transform p_j = -D1 L_d - F_d^- is first order), all alpha.
  // Tolerance 0.05: the fitted slopes are 1.000-1.001.
  for (double alpha : {1e-3, 0.1}) {
    INFO("la-nh alpha " << alpha);
    CHECK(fit_order(hs, errors("la-nh", alpha, hs)).slope == Approx(1).margin(0.05));
  }
  // Contact at alpha = 1e-3: the O(h) terms are ~ alpha^2 h (modified Lagrangian (11)) and ~ s h log(r0/r)
  // (the discrete plane lags where r shrinks), 1e-8 m at these h, far below the O(h^2) term: the error looks
  // second order (measured 2.00) until h ~ 2e-3, where the slope bends to 1 (the convergence study). Tolerance 0.1.
  CHECK(fit_order(hs, errors("contact-nh", 1e-3, hs)).slope == Approx(2).margin(0.1));
  // Contact at alpha = 0.1: the alpha^2 h term dominates, first order (measured 0.98 over h <= 0.025).
  CHECK(fit_order(hs_small, errors("contact-nh", 0.1, hs_small)).slope == Approx(1).margin(0.05));
}

TEST_CASE("the convergence study's Foucault measures are the paper's closed forms measured by hand", "[foucault][order]") {
  // The generic study (the registry's closed-form fast path, its hand-written-rhs reference on h_min/2, the
  // measures the system declares) against the same quantities computed here from the closed forms (15), (18)
  // and foucault_reference directly: the same bits, over two periods with its passes by the origin (T = 32 s).
  const double alpha = 1e-3, T = 32;
  const auto hs = halving_sequence(0.1, 0.025);
  const SystemInfo& sys = find_system("foucault");
  const ConvergenceStudy study = convergence_study(sys, {{{"alpha", alpha}, {"T", T}}}, {"la", "contact"}, hs, Path::fast,
                                                   ReferenceKind::odeint_rhs, 1e-12, Sweep::world(), ErrorNorm::euclidean);
  REQUIRE(study.measures.size() == 4);
  CHECK(study.measures[0].name == "energy_err");
  CHECK(study.measures[3].name == "min_r");
  const auto sc = scene(alpha, T);
  const FoucaultParams<double> p(sc);
  const Vec2<double> q0(sc.x0, sc.y0), v0(sc.vx0, sc.vy0), v0c = consistent_velocity(p, q0, v0);
  const double E0 = foucault_energy(p, q0, v0c), hr = hs.back() / 2;
  std::vector<double> times;
  for (long i = 0; i <= step_count(hr, T); ++i) times.push_back(static_cast<double>(i) * hr);
  const auto ref = foucault_reference(sc, times, 1e-12);
  int compared = 0;
  for (const auto& series : study.series) {
    for (std::size_t k = 0; k < hs.size(); ++k) {
      const double h = hs[k];
      const long stride = std::lround(h / hr);
      double err = 0, energy = 0, plane = 0;
      FoucaultRun by_hand;
      generic::visit_closed_form<systems::Foucault>(series.scheme, [&](auto c) {
        FoucaultDiagnostics<systems::Foucault, double> diag(p, h, step_count(h, T), step_count(h, T), q0, v0);
        systems::run_closed_form<decltype(c)>(sc, p, q0, v0, h, step_count(h, T), FoucaultStart::legendre,
                                              [&](const FoucaultStep<double>& st) {
          diag(st);
          const auto& rn = ref[static_cast<std::size_t>((st.j + 1) * stride)];
          err = std::max(err, std::hypot(st.qn(0) - rn[0], st.qn(1) - rn[1]));
          const auto& rh = ref[static_cast<std::size_t>(st.j * stride + stride / 2)];
          const double Eref = foucault_energy<double>(p, Vec2<double>(rh[0], rh[1]), Vec2<double>(rh[2], rh[3]));
          energy = std::max(energy, std::abs(chord_energy(p, st.q, st.qn, h) - Eref) / E0);
          const auto& rj = ref[static_cast<std::size_t>(st.j * stride)];
          if (std::hypot(rj[0], rj[1]) >= q0.norm() * std::exp(-alpha * st.t / 2) / 2)
            plane = std::max(plane, std::abs(nearest_branch(std::atan2(st.q(1), st.q(0)) - std::atan2(rj[1], rj[0]), 0.0, geomint::pi)));
        });
        by_hand.summary = diag.summary();
      });
      INFO(series.scheme << " h = " << h);
      CHECK(series.err[k] == err);
      CHECK(series.measures[k][0] == energy);
      CHECK(series.measures[k][1] == plane);
      CHECK(series.measures[k][2] == std::abs(by_hand.summary.rate / -sc.s() - 1));
      CHECK(series.measures[k][3] == by_hand.summary.min_r);
      // a fitted rate, not a missing one: turning points come twice a period (16.4 s), 4 of them over T = 32 s,
      // and the fit takes 3 at least
      CHECK(by_hand.summary.rate_points >= 3);
      CHECK(std::isfinite(series.measures[k][2]));
      ++compared;
    }
  }
  CHECK(compared == 6);
  // and the max norm is what the study takes by default: no larger than the Euclidean length, and not equal to it
  const ConvergenceStudy max_norm = convergence_study(sys, {{{"alpha", alpha}, {"T", T}}}, {"la"}, hs, Path::fast,
                                                      ReferenceKind::odeint_rhs, 1e-12, Sweep::world());
  for (std::size_t k = 0; k < hs.size(); ++k) {
    CHECK(max_norm.series[0].err[k] <= study.series[0].err[k]);
    CHECK(max_norm.series[0].err[k] > study.series[0].err[k] / std::sqrt(2.0) * (1 - 1e-12));
    CHECK(max_norm.series[0].err[k] != study.series[0].err[k]);
  }
}

TEST_CASE("a step at the origin is a NumericalFailure with the step index", "[foucault][failure]") {
  const auto sc = scene(1e-3, 1);
  const FoucaultParams<double> p(sc);
  Vec2<double> qn;
  double l1;
  try {
    LaNh::step(p, Vec2<double>(0.01, 0), Vec2<double>(0, 0), 0.1, qn, l1, 17);
    FAIL("no exception");
  } catch (const NumericalFailure& e) {
    CHECK(e.step == 17);
    CHECK(e.quantity == "r_j^2");
  }
  CHECK_THROWS_AS(ContactNh::step(p, Vec2<double>(0.01, 0), Vec2<double>(std::nan(""), 0), 0.1, qn, l1, 3),
                  NumericalFailure);
  systems::Foucault bad = sc;
  bad.x0 = 0;
  CHECK_THROWS_AS(bad.validate(), InputError);
  CHECK_THROWS_AS(parse_foucault_start("euler"), InputError);
  // the closed forms are (15), (18): la-midpoint has only the generic step; no third constraint discretization
  CHECK_THROWS_WITH(run_foucault("foucault", "la-midpoint", sc, 0.1, FoucaultStart::legendre, 1),
                    Catch::Contains("no closed form"));
  CHECK_THROWS_AS(run_foucault("foucault-exact", "la", sc, 0.1, FoucaultStart::legendre, 1), InputError);
}

namespace {

struct BadInput {
  const char* program;
  const char* args;
  const char* expect;
};

const BadInput foucault_bad_inputs[] = {
    {"fig2_foucault", "--h 0", "h must be a positive"},
    {"fig2_foucault", "--h 0.1 0.7", "not an integer"},
    {"fig2_foucault", "--alpha=-1", "alpha must be a non-negative"},
    {"fig2_foucault", "--alpha nan", "alpha must be a non-negative"},
    {"fig2_foucault", "--start euler", "unknown start 'euler'"},
    {"fig2_foucault", "--system nosuch", "unknown constraint discretization 'nosuch'"},
    {"fig2_foucault", "--schemes la-nh nosuch", "unknown scheme 'nosuch'"},
    {"fig2_foucault", "--beta 91", "beta must be a latitude"},
    {"fig2_foucault", "--x0 0", "q0 must not be the origin"},
    {"fig2_foucault", "--m 0", "m must be a positive"},
    {"fig2_foucault", "--sample-dt 0", "sample-dt must be a positive"},
    {"fig2_foucault", "--T inf", "T must be a positive"},
    {"fig2_foucault", "--bogus 1", "unrecognised option"},
    {"convergence", "--system foucault --h-max 0", "h_max must be a positive"},
    {"convergence", "--system foucault --T 4.05", "not an integer"},
    {"convergence", "--system foucault --reference odeint-rhs --tol 1", "tol must be in"},
    {"convergence", "--system foucault --schemes nosuch", "unknown scheme"},
    {"convergence", "--system foucault --norm 3", "unknown norm '3'"},
};

}  // namespace

TEST_CASE("Foucault programs reject bad input with one line, exit 2, and write nothing", "[foucault][programs]") {
  using namespace geomint::testing;
  for (const auto& b : foucault_bad_inputs) check_rejected(b.program, b.args, b.expect);
  CHECK(run_program("fig2_foucault", "--help").exit_code == 0);
}

TEST_CASE("fig2_foucault writes the figure, its companion and tidy TSVs", "[foucault][programs]") {
  using namespace geomint::testing;
  const auto dir = fresh_dir("foucault-fig2");
  const auto r = run_program("fig2_foucault", "--T 200 --h 0.1 0.05 --out " + dir.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  for (const char* f : {"fig2_foucault.tsv", "fig2_foucault_summary.tsv", "fig2_foucault.png", "fig2_foucault.pdf",
                        "fig2_foucault_plane.png", "fig2_foucault_h0.05.tsv", "fig2_foucault_h0.05.png",
                        "fig2_foucault_h0.05_summary.tsv"})
    CHECK(std::filesystem::exists(dir / f));
  const auto sum = plots::read_tsv(dir / "fig2_foucault_summary.tsv");
  REQUIRE(sum.rows.size() == 4);  // 2 schemes x 2 alpha
  for (size_t i = 0; i < sum.rows.size(); ++i) {
    CHECK(sum.text(i, "status") == "ok");
    CHECK(sum.number(i, "max_residual_scaled") < 4 * eps);
  }
  std::filesystem::remove_all(dir);
}
