#pragma once
// Long-horizon structure of the damped oscillator q'' = -q - alpha q' (p = q'), measured the same way for every
// method, fixed-step or adaptive: the decay rate, the frequency and phase, and the dissipation balance.
//
// Two exact facts of the continuous flow make these measurable without a reference trajectory:
//   Q = q^2 + alpha q p + p^2 decays exactly as e^{-alpha t}   (dQ/dt = -alpha Q; Q = 2E + alpha q p, so Q is
//     the energy envelope without its oscillation: a least-squares slope of log Q against t is the envelope's
//     exponent, alpha exactly on the closed-form solution);
//   with u = q, w = (p + alpha q/2)/omega, omega = sqrt(1 - alpha^2/4), the angle theta = atan2(-w, u) equals
//     omega t - phi exactly (q = e^{-alpha t/2} R cos(omega t - phi)): its slope is the frequency, and
//     theta(T) - theta(0) - omega T is the accumulated phase error.
//   The balance E(a) - E(b) = int_a^b alpha p^2 dt (energy lost = work of the damping force) is checked on
//     windows [t_k, t_{k+1}] of the horizon, relative to E(t_k), so it measures the whole horizon and not only
//     its start (where almost all the energy is lost).
//
// The solution decays by e^{-alpha T}: e^{-6283} at alpha = 0.1 over 10^4 periods, far below the smallest
// double. The problem is linear and homogeneous, so the drivers renormalise the state by an exact power of two
// (std::ldexp) at every window boundary where max(|q|, |p|) < 1/2, back to [1, 2), and keep the exponent: every
// fixed-step scheme here is a linear map, so this gives bit for bit the run an unbounded exponent range would give.
// For the adaptive methods the tolerance then acts on the renormalised state, i.e. relative to the amplitude at the
// window's start (an absolute tolerance on the raw state stops controlling anything once the amplitude has decayed
// below it: at alpha = 0.01 over 1000 periods the amplitude is 3e-14).
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <boost/math/constants/constants.hpp>

#include "geomint/constants.hpp"
#include "geomint/error.hpp"
#include "geomint/generic/composition_families.hpp"
#include "geomint/observers.hpp"
#include "geomint/run/baselines.hpp"
#include "geomint/systems/oscillator.hpp"
#include "geomint/timing.hpp"

namespace geomint {

struct OscillatorStructure {
  static constexpr double nan = missing_value;
  double decay_rate = nan;  // fitted -d log Q / dt
  double frequency = nan;   // fitted d theta / dt
  double phase_end = nan;   // theta(t_end) - theta(0) - omega t_end, rad (unwrapped)
  double balance = nan;     // max_k |E_k - E_{k+1} - W_k| / E_k over the windows
  long windows = 0;
  long steps = 0;  // accepted steps
};

// Collects the measures along a trajectory handed over as scaled states: the true state is 2^scale (qs, ps).
//
// Why a harmonic regression and not a straight line: a linear one-step map with complex eigenvalues rho e^{+-i phi}
// keeps rho^{-j} x_j on a fixed ellipse, which is not the exact flow's circle in (u, w). So along a scheme's run
// log Q + rate t and theta - freq t are periodic functions of theta (period pi), with amplitude O(h) for a
// first-order scheme. Sampled at times unrelated to that period, a straight-line fit aliases the oscillation into
// the slope (it cost the first-order schemes a factor 10 in their decay-rate error, non-monotone in h). The fit
// therefore includes the first three harmonics of 2 theta: y = c + r t + sum_k a_k cos(2k theta) + b_k sin(2k theta),
// solved from normal equations accumulated on the fly (t scaled by the horizon), Eigen LDLT.
class OscillatorProbe {
 public:
  static constexpr int K = 3;           // harmonics of 2 theta in the fit
  static constexpr int P = 2 + 2 * K;   // parameters
  OscillatorProbe(double alpha, double T) : alpha_(alpha), omega_(std::sqrt(1 - alpha * alpha / 4)), T_(T) {
    A_.setZero();
    bq_.setZero();
    bt_.setZero();
  }

  double omega() const { return omega_; }

  // A point of the trajectory at time t (at least every half time unit: the phase is unwrapped between calls by
  // taking the branch nearest to the exact advance omega dt, right while the method's phase error between two
  // calls is below pi). Every point is a sample of the two fits.
  void point(double t, double qs, double ps, int scale) {
    const double u = qs, w = (ps + alpha_ * qs / 2) / omega_;
    const double a = std::atan2(-w, u);
    if (!started_) {
      theta_ = theta0_ = a;
      t0_ = t;
      started_ = true;
    } else {
      theta_ = nearest_branch(a, theta_ + omega_ * (t - t_last_), two_pi);  // the branch nearest the exact advance
    }
    t_last_ = t;
    // basis: 1, t/T, cos 2k theta, sin 2k theta (k = 1..K) from c = cos theta, s = sin theta
    const double R2 = u * u + w * w, c2 = (u * u - w * w) / R2, s2 = -2 * u * w / R2;
    Eigen::Matrix<double, P, 1> x;
    x(0) = 1;
    x(1) = t / T_;
    double ck = c2, sk = s2;
    for (int k = 0; k < K; ++k) {
      x(2 + 2 * k) = ck;
      x(3 + 2 * k) = sk;
      const double cn = ck * c2 - sk * s2;
      sk = sk * c2 + ck * s2;
      ck = cn;
    }
    const double Q = qs * qs + alpha_ * qs * ps + ps * ps;
    const double logQ = std::log(Q) + 2 * scale * ln2;
    A_.noalias() += x * x.transpose();
    bq_ += logQ * x;
    bt_ += theta_ * x;
    ++n_;
  }

  // A window boundary at time t (also a point); work: alpha int p^2 dt over the window that ends here, in the
  // units of the scaled state (the drivers rescale only at boundaries, after this call).
  void boundary(double t, double qs, double ps, int scale, double work) {
    point(t, qs, ps, scale);
    const double E = (qs * qs + ps * ps) / 2;
    if (boundaries_ > 0) {
      const double r = std::abs(E_last_ - E - work) / E_last_;
      balance_ = (std::isnan(r) || std::isnan(balance_)) ? missing_value : std::max(balance_, r);
    }
    E_last_ = E;
    ++boundaries_;
  }
  // The state was multiplied by 2^shift at a boundary (energies by 2^{2 shift}).
  void rescaled(int shift) { E_last_ = std::ldexp(E_last_, 2 * shift); }

  OscillatorStructure result(long steps) const {
    OscillatorStructure r;
    r.steps = steps;
    r.windows = boundaries_ - 1;
    if (n_ < 4 * P) return r;
    const Eigen::LDLT<Eigen::Matrix<double, P, P>> ldlt(A_);
    r.decay_rate = -ldlt.solve(bq_)(1) / T_;
    r.frequency = ldlt.solve(bt_)(1) / T_;
    r.phase_end = theta_ - theta0_ - omega_ * (t_last_ - t0_);
    r.balance = balance_;
    return r;
  }

 private:
  static constexpr double two_pi = geomint::two_pi, ln2 = boost::math::constants::ln_two<double>();
  double alpha_, omega_, T_;
  bool started_ = false;
  double theta0_ = 0, theta_ = 0, t0_ = 0, t_last_ = 0, E_last_ = 0, balance_ = 0;
  long n_ = 0, boundaries_ = 0;
  Eigen::Matrix<double, P, P> A_;
  Eigen::Matrix<double, P, 1> bq_, bt_;
};

// The exponent that brings max(|q|, |p|) back to [1, 2) when it has fallen below 1/2 (0: no rescaling).
inline int renormalisation_shift(double q, double p) {
  const double m = std::max(std::abs(q), std::abs(p));
  if (!(m < 0.5) || m == 0) return 0;
  return -std::ilogb(m);
}

// A long run split into `windows` windows, in steps of h by step(OscState<double>&) (a closed form of
// systems/oscillator.hpp, or a composition of one): boundary k after round(k N / windows) steps. Work by the
// trapezoid rule on the step points (the schemes carry no quadrature of their own). Measure = false is the same
// run with nothing observed (for timings).
template <bool Measure, class Step>
OscillatorStructure run_structure(Step&& step, double alpha, double q0, double p0, double h, long N, long windows) {
  OscillatorProbe probe(alpha, h * static_cast<double>(N));
  OscState<double> s{q0, p0, 0.0};
  int scale = 0;
  if (Measure) probe.boundary(0, s.q, s.p, 0, 0);
  const long every = std::max(1L, static_cast<long>(0.5 / h));  // phase unwrapped at least every half time unit
  long j = 0;
  for (long k = 1; k <= windows; ++k) {
    const long end = N * k / windows;
    double work = 0;
    for (; j < end; ++j) {
      const double pm = s.p;
      step(s);
      if (Measure) {
        work += alpha * h / 2 * (pm * pm + s.p * s.p);
        if ((j + 1) % every == 0) probe.point(static_cast<double>(j + 1) * h, s.q, s.p, scale);
      }
    }
    if (!std::isfinite(s.q) || !std::isfinite(s.p))
      throw NumericalFailure(j, "state", "non-finite q or p by the end of window " + std::to_string(k));
    if (Measure) probe.boundary(static_cast<double>(j) * h, s.q, s.p, scale, work);
    if (const int sh = renormalisation_shift(s.q, s.p)) {
      s.q = std::ldexp(s.q, sh);
      s.p = std::ldexp(s.p, sh);
      s.z = std::ldexp(s.z, 2 * sh);
      scale -= sh;
      if (Measure) probe.rescaled(sh);
    }
  }
  do_not_optimize(s.q);
  return Measure ? probe.result(N) : OscillatorStructure{};
}

// The run in steps of the closed form S.
template <class S, bool Measure>
OscillatorStructure run_fixed_structure(double alpha, double q0, double p0, double h, long N, long windows) {
  return run_structure<Measure>([h, alpha](OscState<double>& s) { S::step(s, h, alpha); }, alpha, q0, p0, h, N, windows);
}

// The stage steps w_i h of the composition family `family` (composition_families.hpp), each rounded from long double
// as generic::Composition rounds its own.
inline std::vector<double> composition_stage_steps(const std::string& family, double h) {
  std::vector<double> hs;
  for (const long double w : generic::find_composition_family(family).weights)
    hs.push_back(static_cast<double>(w * static_cast<long double>(h)));
  return hs;
}

// The run in steps of a composition of the closed form S: a composition is its base map at each stage step
// w_i h (generic/composition.hpp), so on this system it is S at those steps, as long as S holds for negative steps
// (every closed form of the oscillator is its scheme's exact solution, valid for any h with 1 + h alpha/2 != 0).
// stage_h: composition_stage_steps(family, h).
template <class S, bool Measure>
OscillatorStructure run_composed_structure(const std::vector<double>& stage_h, double alpha, double q0, double p0,
                                           double h, long N, long windows) {
  return run_structure<Measure>(
      [&stage_h, alpha](OscState<double>& s) {
        for (const double hi : stage_h) S::step(s, hi, alpha);
      },
      alpha, q0, p0, h, N, windows);
}

// A baseline (run/baselines.hpp) on x = (q, p, W), W' = alpha p^2 the work by the method's own quadrature, in
// `windows` windows: at each window's end the probe reads the balance from W, W restarts at 0 (W' does not depend
// on W, so a stored derivative stays valid) and the state is renormalised (then the stepper restarts). `b` names
// the baseline and its knob (odeint-rk4: h and the steps N, the probe's horizon h N; the others: tolerances, their
// horizon T, landing on every window's end). Measure = false is the same run with nothing observed (for timings).
inline OscillatorStructure run_baseline_structure(BaselineSetup b, double alpha, double q0, double p0, double T,
                                                  long windows, bool measure) {
  OscillatorProbe probe(alpha, T);
  int scale = 0;
  b.windows = windows;
  b.T = T;
  b.end = BaselineEnd::land;
  if (b.name == "odeint-rk4") b.every = std::max(1L, static_cast<long>(0.5 / b.h));  // unwrapped every half time unit
  b.window_end = [&](long, double t, double* x) {
    if (measure) probe.boundary(t, x[0], x[1], scale, x[2]);
    x[2] = 0;
    const int sh = renormalisation_shift(x[0], x[1]);
    if (!sh) return false;
    x[0] = std::ldexp(x[0], sh);
    x[1] = std::ldexp(x[1], sh);
    scale -= sh;
    if (measure) probe.rescaled(sh);
    return true;
  };
  const BaselineObserver observe = [&](std::size_t k, double t, const double* x) {
    if (k == 0)
      probe.boundary(0, x[0], x[1], 0, 0);
    else
      probe.point(t, x[0], x[1], scale);
  };
  const OdeRhs f = [alpha](double, const double* x, double* dx) {
    dx[0] = x[1];
    dx[1] = -x[0] - alpha * x[1];
    dx[2] = alpha * x[1] * x[1];
  };
  const BaselineCount n = run_baseline(b, f, {q0, p0, 0}, measure ? &observe : nullptr);
  return measure ? probe.result(n.steps) : OscillatorStructure{};
}

}  // namespace geomint
