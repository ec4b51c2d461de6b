// Long-horizon structure: the measures of studies/include/geomint/oscillator_structure.hpp recover the exact
// values on the closed-form solution and the one-step spectra of the schemes; the one-step maps contract
// phase-space area by exactly their derived determinant.
#include <cmath>
#include <complex>
#include <limits>
#include <random>

#include <catch2/catch.hpp>
#include <gsl/gsl_integration.h>

#include "geomint/constants.hpp"
#include "geomint/foucault_diagnostics.hpp"
#include "geomint/generic/dual.hpp"
#include "geomint/oscillator_structure.hpp"
#include "geomint/registry.hpp"
#include "geomint/systems/oscillator.hpp"
#include "geomint/study.hpp"

using namespace geomint;
using Osc = systems::Oscillator;

namespace {

constexpr double eps = std::numeric_limits<double>::epsilon();

// alpha int_a^b p(t)^2 dt on the closed-form solution, by GSL's adaptive Gauss–Kronrod (qag, 61 points, relative 1e-12).
double exact_work(double alpha, double q0, double p0, double a, double b) {
  struct Ctx {
    double alpha, q0, p0;
  } ctx{alpha, q0, p0};
  gsl_function f;
  f.function = [](double t, void* c) {
    const auto* x = static_cast<const Ctx*>(c);
    const double p = Osc{x->alpha, x->q0, x->p0}.exact<double>(t).v(0);
    return x->alpha * p * p;
  };
  f.params = &ctx;
  gsl_integration_workspace* w = gsl_integration_workspace_alloc(200);
  double r = 0, err = 0;
  gsl_integration_qag(&f, a, b, 0, 1e-12, 200, GSL_INTEG_GAUSS61, w, &r, &err);
  gsl_integration_workspace_free(w);
  return r;
}

// The one-step matrix's eigenvalue rho e^{i phi}: the scheme's exact decay rate -2 ln(rho)/h = -ln(det M)/h
// (Q_j then decays like rho^{2j}) and frequency phi/h.
template <class S>
std::pair<double, double> spectral_rate_frequency(double h, double alpha) {
  const auto M = Osc{alpha}.closed_form_matrix<S>(h);  // row-major (q, p)
  const long double det = M[0] * M[3] - M[1] * M[2], tr = M[0] + M[3];
  const long double phi = std::acos(tr / (2 * std::sqrt(det)));
  return {static_cast<double>(-std::log(det) / h), static_cast<double>(phi / h)};
}

template <class S>
OscillatorStructure run_scheme(double alpha, double m, double periods, long windows) {
  const double h = two_pi / m;
  return run_fixed_structure<S, true>(alpha, -0.25, 0.75, h, std::lround(periods * m), windows);
}

// Jacobian of one step (q, p) -> (q', p') by forward-mode AD, at (q, p).
template <class S>
double step_jacobian_det(double q, double p, double h, double alpha) {
  using D = Dual<double, 2>;
  OscState<D> s{D::variable(q, 0), D::variable(p, 1), D(0.0)};
  S::step(s, D(h), D(alpha));
  return s.q.d[0] * s.p.d[1] - s.q.d[1] * s.p.d[0];
}

}  // namespace

TEST_CASE("long-horizon measures recover the exact decay rate, frequency, phase and balance on the closed form",
          "[long_horizon][oscillator]") {
  for (double alpha : {0.01, 0.1}) {
    CAPTURE(alpha);
    const double q0 = -0.25, p0 = 0.75, T = two_pi * 200, dt = 0.25;
    const long windows = 100;
    OscillatorProbe probe(alpha, T);
    const auto N = static_cast<long>(std::lround(T / dt));
    long next = 0;
    for (long j = 0; j <= N; ++j) {
      const double t = T * static_cast<double>(j) / static_cast<double>(N);
      const auto e = Osc{alpha, q0, p0}.exact<double>(t);
      const struct {
        double q, v;
      } x{e.q(0), e.v(0)};
      if (j == next * N / windows) {
        const double t0 = next == 0 ? 0 : T * static_cast<double>((next - 1) * N / windows) / static_cast<double>(N);
        probe.boundary(t, x.q, x.v, 0, next == 0 ? 0 : exact_work(alpha, q0, p0, t0, t));
        ++next;
      } else {
        probe.point(t, x.q, x.v, 0);
      }
    }
    const auto r = probe.result(N);
    CHECK(r.windows == windows);
    // log Q is exactly linear in t: the fit returns alpha to the round-off of log Q (|log Q| <= alpha T ~ 126)
    // and of exp in the closed form (relative 1e-16 x alpha t): |error| well below 1e-12 relative.
    CHECK(std::abs(r.decay_rate - alpha) / alpha < 1e-12);
    CHECK(std::abs(r.frequency - probe.omega()) / probe.omega() < 1e-13);
    // the phase: omega T = 1257 rad, held to round-off of cos/sin arguments of that size (~1e-13)
    CHECK(std::abs(r.phase_end) < 1e-10);
    // the balance: E_k - E_{k+1} against a 1e-12-accurate quadrature
    CHECK(r.balance < 1e-11);
  }
}

TEST_CASE("long-horizon measures on the schemes agree with their one-step spectra", "[long_horizon][oscillator]") {
  // Over 2000 periods the fitted decay rate and frequency of a fixed-step run are the one-step matrix's
  // -ln(det)/h and arg(lambda)/h up to the O(h)-amplitude oscillation of log Q and of theta, whose
  // least-squares slope is O(h / T): with h <= 0.1 and T = 12566, below 1e-5 of the rate errors measured here.
  const double alpha = 0.1, m = 64, periods = 2000;
  const double h = two_pi / m;
  auto check = [&](auto scheme, const char* name) {
    using S = decltype(scheme);
    CAPTURE(name);
    const auto r = run_scheme<S>(alpha, m, periods, 400);
    const auto [rate, freq] = spectral_rate_frequency<S>(h, alpha);
    CHECK(std::abs(r.decay_rate - rate) <= 1e-2 * std::abs(rate - alpha));
    CHECK(std::abs(r.frequency - freq) <= 1e-6 * freq);
    const double omega = std::sqrt(1 - alpha * alpha / 4);
    // the phase error accumulated over T is (freq - omega) T up to the bounded oscillation of theta (O(h))
    CHECK(std::abs(std::abs(r.phase_end) - std::abs(freq - omega) * two_pi * periods) <= 2 * h);
  };
  check(Osc::La{}, "la");
  check(Osc::Contact{}, "contact");
  check(Osc::LaMidpoint{}, "la-midpoint");
  check(Osc::ContactSymmetric{}, "contact-sym");
  check(Osc::Leapfrog{}, "leapfrog");
}

TEST_CASE("decay-rate and frequency errors fall with the schemes' orders", "[long_horizon][oscillator][order]") {
  // Derived from the one-step matrix M (eigenvalues sqrt(det M) e^{+-i phi}):
  // decay: la -ln(det)/h - alpha = ln(1 + h alpha)/h - alpha = -alpha^2 h/2 + O(h^2); contact -ln(1 - h alpha)/h - alpha
  //   = alpha^2 h/2 + O(h^2); the symmetric schemes (det = (1 - h alpha/2)/(1 + h alpha/2) for contact-sym and
  //   leapfrog, (1 - h alpha/2 + h^2/4)/(1 + h alpha/2 + h^2/4) for la-midpoint) are even in h: O(h^2).
  // frequency: la has cos phi = cosh(ln(1 + h alpha)/2) - h^2 sqrt(c)/2, c = 1/(1 + h alpha), whose h^3 alpha/4 term
  //   makes the relative frequency error alpha h/4 + O(h^2): first order, dominant for h < 6 alpha (alpha = 0.1 here).
  //   contact has cos phi = (1 - h^2/2) cosh(x), x = -ln(1 - h alpha)/2, with no h^3 alpha term: its first-order
  //   term is alpha^3 h/8, so it is second order in practice; at alpha = 0.01 that term is < 1e-2 of the h^2 one
  //   for the h used here. The symmetric schemes are second order.
  const double periods = 500;
  const std::vector<double> ms{128, 256, 512, 1024};
  auto slopes = [&](auto scheme, double alpha) {
    using S = decltype(scheme);
    std::vector<double> hs, decay, freq;
    const double omega = std::sqrt(1 - alpha * alpha / 4);
    for (double m : ms) {
      const auto r = run_scheme<S>(alpha, m, periods, 200);
      hs.push_back(two_pi / m);
      decay.push_back(std::abs(r.decay_rate - alpha) / alpha);
      freq.push_back(std::abs(r.frequency - omega) / omega);
    }
    return std::pair<double, double>{fit_order(hs, decay).slope, fit_order(hs, freq).slope};
  };
  const auto [la_d, la_f] = slopes(Osc::La{}, 0.1);
  const auto [co_d, co_f] = slopes(Osc::Contact{}, 0.01);
  const auto [lm_d, lm_f] = slopes(Osc::LaMidpoint{}, 0.1);
  const auto [cs_d, cs_f] = slopes(Osc::ContactSymmetric{}, 0.1);
  const auto [lf_d, lf_f] = slopes(Osc::Leapfrog{}, 0.1);
  CHECK(la_d == Approx(1).margin(0.1));
  CHECK(co_d == Approx(1).margin(0.1));
  CHECK(la_f == Approx(1).margin(0.15));
  CHECK(co_f == Approx(2).margin(0.1));
  CHECK(lm_d == Approx(2).margin(0.1));
  CHECK(cs_d == Approx(2).margin(0.1));
  CHECK(lf_d == Approx(2).margin(0.1));
  CHECK(lm_f == Approx(2).margin(0.1));
  CHECK(cs_f == Approx(2).margin(0.1));
  CHECK(lf_f == Approx(2).margin(0.1));
}

TEST_CASE("a composition of the leapfrog's closed form is the registry's composition, and its structural errors fall "
          "at its order", "[long_horizon][oscillator][composition]") {
  // The same map: the registry steps the composition through the generic Newton step of la-trapezoid, stage by
  // stage, where the closed form solves each stage exactly; over 1000 steps (7000 stages) they differ by round-off.
  // Newton accepts a stage within kappa = 16 eps of its solution (newton.hpp), |q|, |p| <= 1 here: the bound is
  // 7000 x 16 eps = 2.5e-11 (measured 4e-13: the errors do not all add up).
  const double alpha = 0.1, h = 0.1;
  const Run run = find_system("oscillator").run({{"alpha", alpha}, {"T", 100}}, "yoshida6a:la-trapezoid", h, Path::fast, 1);
  REQUIRE(run.steps == 1000);
  OscState<double> s{run.q[0], run.p[0], 0.0};
  const auto hs = composition_stage_steps("yoshida6a", h);
  double worst = 0;
  for (long j = 1; j <= run.steps; ++j) {
    for (const double hi : hs) Osc::Leapfrog::step(s, hi, alpha);
    worst = std::max({worst, std::abs(s.q - run.q[static_cast<std::size_t>(j)]), std::abs(s.p - run.p[static_cast<std::size_t>(j)])});
  }
  INFO("max |closed-form composition - registry composition| over 1000 steps: " << worst);
  CHECK(worst < 7000 * 16 * eps);

  // Decay-rate and frequency errors over 500 periods against m: the composition's order (4 and 6), where the
  // second-order base has 2 (the test above).
  const double periods = 500;
  auto slopes = [&](const char* family, const std::vector<double>& ms) {
    std::vector<double> h_of, decay, freq;
    const double omega = std::sqrt(1 - alpha * alpha / 4);
    for (double m : ms) {
      const double hm = two_pi / m;
      const auto r = run_composed_structure<Osc::Leapfrog, true>(composition_stage_steps(family, hm), alpha, -0.25, 0.75, hm,
                                                                 std::lround(periods * m), 200);
      h_of.push_back(hm);
      decay.push_back(std::abs(r.decay_rate - alpha) / alpha);
      freq.push_back(std::abs(r.frequency - omega) / omega);
    }
    INFO(family << ": decay " << Catch::Detail::stringify(decay) << ", frequency " << Catch::Detail::stringify(freq));
    return std::pair<double, double>{fit_order(h_of, decay).slope, fit_order(h_of, freq).slope};
  };
  const auto [y4_d, y4_f] = slopes("yoshida4", {16, 32, 64, 128});
  const auto [y6_d, y6_f] = slopes("yoshida6a", {8, 16, 32});
  CHECK(y4_d == Approx(4).margin(0.2));
  CHECK(y4_f == Approx(4).margin(0.2));
  CHECK(y6_d == Approx(6).margin(0.3));
  CHECK(y6_f == Approx(6).margin(0.3));
}

TEST_CASE("one-step maps contract phase-space area by exactly their derived determinant (AD Jacobian)",
          "[long_horizon][oscillator][contact]") {
  // Derivations (one step written as a composition of shears and scalings):
  //   contact (10): J = [[1 - h^2/2, h (1 - h alpha)], [-h + h^3/4, (1 - h alpha)(1 - h^2/2)]], det = 1 - h alpha;
  //   contact-sym:  (q,p) -> (q,v) scales by 1 - h alpha/2, q' = q + h v is a shear, p' = (v - h q'/2)/(1 + h alpha/2):
  //                 det = (1 - h alpha/2) / (1 + h alpha/2);
  //   la:           p' = (p - h q)/(1 + h alpha), q' = q + h p': det = 1/(1 + h alpha);
  //   la-midpoint:  v = (p - h q/2)/c, c = 1 + h alpha/2 + h^2/4, then [[1, h], [-h/2, 1 - h alpha/2 - h^2/4]]:
  //                 det = (1 - h alpha/2 + h^2/4)/(1 + h alpha/2 + h^2/4);
  //   leapfrog:     det = (1 - h alpha/2)/(1 + h alpha/2).
  // The AD Jacobian entries carry at most ~6 roundings each (relative 6 eps) and det = J00 J11 - J01 J10 with
  // |J00 J11| <= 1.1: |det - exact| <= 16 eps covers it. A determinant off by the next Taylor term
  // (e.g. 1 - h alpha + (h alpha)^2/2 for contact) differs by >= 5e-5 at the points below.
  std::mt19937_64 rng(14);
  std::uniform_real_distribution<double> U(-1, 1), H(0.01, 0.5), A(0.01, 1.5);
  for (int k = 0; k < 200; ++k) {
    const double q = U(rng), p = U(rng), h = H(rng), a = A(rng);
    CAPTURE(q, p, h, a);
    const double tol = 16 * eps;
    CHECK(std::abs(step_jacobian_det<Osc::Contact>(q, p, h, a) - (1 - h * a)) <= tol);
    CHECK(std::abs(step_jacobian_det<Osc::ContactSymmetric>(q, p, h, a) - (1 - h * a / 2) / (1 + h * a / 2)) <= tol);
    CHECK(std::abs(step_jacobian_det<Osc::La>(q, p, h, a) - 1 / (1 + h * a)) <= tol);
    CHECK(std::abs(step_jacobian_det<Osc::LaMidpoint>(q, p, h, a) -
                   (1 - h * a / 2 + h * h / 4) / (1 + h * a / 2 + h * h / 4)) <= tol);
    CHECK(std::abs(step_jacobian_det<Osc::Leapfrog>(q, p, h, a) - (1 - h * a / 2) / (1 + h * a / 2)) <= tol);
  }
  // Over many steps the area of a parallelogram of tangent vectors is det^N: 10^4 contact steps at h = 0.1,
  // alpha = 0.1 give (0.99)^N = 2.2e-44, matched to the accumulated round-off (N * 16 eps relative).
  using D = Dual<double, 2>;
  const double h = 0.1, a = 0.1;
  const long N = 10000;
  OscState<D> s{D::variable(0.3, 0), D::variable(-0.2, 1), D(0.0)};
  for (long j = 0; j < N; ++j) Osc::Contact::step(s, D(h), D(a));
  const double area = s.q.d[0] * s.p.d[1] - s.q.d[1] * s.p.d[0];
  const double exact = std::pow(1 - h * a, static_cast<double>(N));
  CHECK(std::abs(area / exact - 1) <= static_cast<double>(N) * 16 * eps);
}

// ---------------------------------------------------------------------------------------------------
// Foucault pendulum over 10 hours: the schemes hold their discrete constraint, the multiplier ODE drifts off (13).

TEST_CASE("nonholonomic schemes keep their discrete constraint at round-off over a 10-hour Foucault run",
          "[long_horizon][foucault][constraint]") {
  // 360 000 steps of h = 0.1 s. The residual is the one each discretization imposes, scaled by its round-off size
  // (paper: |Phi_d| / (|q_j| (|q_j| + |q_{j+1}|)/h); rotation: |n(phi_{j+1}).q_{j+1}| / (|q_j| + |q_{j+1}|)): each
  // step solves its constraint row afresh, so nothing accumulates and the bound of the one-hour test (4 eps) holds
  // over ten hours. A constraint only kept on average (or a drifting one) would grow with the 360 000 steps.
  systems::FoucaultPendulum sc;
  sc.T = 36000;
  for (const char* scheme : {"la-nh", "contact-nh"})
    for (const char* system : {"foucault-rotation", "foucault"}) {
      const auto run = run_foucault(system, scheme, sc, 0.1, FoucaultStart::legendre, 100000);
      INFO(scheme << " " << system << ": max residual " << run.summary.max_residual / eps << " eps");
      CHECK(run.summary.max_residual < 4 * eps);
    }
}

TEST_CASE("the multiplier ODE's constraint drift is measured: it grows far above round-off over 10 hours",
          "[long_horizon][foucault][constraint]") {
  // Odeint's dopri5 (foucault_reference, abs = rel = 1e-10, as every program uses it) on the Lagrange–d'Alembert
  // ODE keeps (13) only through its derivative: dPhi/dt = 0 whatever Phi is, so each step's local error moves it
  // and nothing pulls it back, while the scale it is measured against, |q||v| + s|q|^2, decays as e^{-alpha t}.
  // Relative to the solution an error in Phi is amplified by e^{alpha t}: e^{36} ~ 4e15 ~ 1/eps in 10 h at
  // alpha = 1e-3, so even round-off alone would take the run off (13) (and the absolute tolerance 1e-10 m is
  // then 1 % of the amplitude 0.67 e^{-18} m). The relative residual r(t) = |Phi(q, v)| / (|q||v| + s|q|^2), measured here: 2.4e-6 at most in
  // the first hour, 1 in the tenth (the motion has left the constraint entirely). Round-off alone gives a few eps
  // (the schemes: < 4 eps, test above). Asserted with margins of about 100 on both: the first hour above 1e4 eps,
  // and the tenth hour above 100 times the first (growth, not a constant offset).
  systems::FoucaultPendulum sc;
  sc.T = 36000;
  std::vector<double> times;
  for (long k = 0; k <= 36000; ++k) times.push_back(static_cast<double>(k));
  const auto x = foucault_reference(sc, times, 1e-10);
  const FoucaultParams<double> p(sc);
  double first = 0, last = 0;
  for (std::size_t k = 0; k < x.size(); ++k) {
    const Vec2<double> q(x[k][0], x[k][1]), v(x[k][2], x[k][3]);
    const double r = std::abs(foucault_constraint(p, q, v)) / (q.norm() * v.norm() + p.s * q.squaredNorm());
    if (times[k] <= 3600) first = std::max(first, r);
    if (times[k] >= 32400) last = std::max(last, r);
  }
  INFO("relative residual of (13): first hour " << first << ", tenth hour " << last);
  CHECK(first > 1e4 * eps);
  CHECK(last > 100 * first);
}
