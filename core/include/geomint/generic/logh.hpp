#pragma once
// The logarithmic-Hamiltonian (logH) leapfrog: an explicit time-transformed scheme for separable systems
//   H = T(p) - U(q),  U > 0 (an attraction, U = -V: 1/|q| for Kepler),  with a friction F = -gamma(t) p,
// stepped at a fixed step h in a fictitious time sigma, so that the physical step dt follows the motion (short
// where the orbit is fast). Mikkola & Tanikawa, Celest. Mech. Dyn. Astron. 74 (1999) 287; Preto & Tremaine, Astron.
// J. 118 (1999) 2532. For the Kepler problem the conservative leapfrog is exact up to a phase: energy, angular
// momentum and the Laplace–Runge–Lenz vector stay at round-off for any step, only t(sigma) carries an error.
//
// Derivation. In the extended phase space (q, t; p, B), B = -E the binding energy (the momentum conjugate to t),
// the extended Hamiltonian Gamma = T(p) + B - U(q) vanishes on the motion. So does
//   Lambda = ln(T(p) + B) - ln U(q),
// a Poincaré transformation of Gamma by 1/(T + B) = 1/U on Gamma = 0; Lambda is separable into a part in the
// momenta (p, B) and a part in the positions (q, t), so its leapfrog is explicit. In sigma:
//   drift (from ln(T + B)):  q' = dT/dp / W,  t' = 1/W,  W = T(p) + B constant;  a drift of length s advances
//                            q and t by dt = s/W:  q += dt dT/dp(p),  t += dt
//   kick  (from -ln U):      p' = grad ln U(q) (q, t, B constant);  a kick of length s:  p += s grad ln U(q),
//                            which is p += dt_k grad U with dt_k = s/U (for Kepler: p -= s q/|q|^2, no root)
// and one step is drift(h/2) kick(h) drift(h/2): symmetric, second order in h, symplectic in (q, t; p, B).
//
// The friction. A force F(t, q, v) changes E at the rate F.v, so in the extended variables p' = F, B' = -F.v with
// v = dT/dp. At fixed q this flow keeps W = T(p) + B: dW/dt = v.F - F.v = 0 (the kinetic energy it removes is the
// binding energy it adds). So it belongs in the drift, the only part that advances t, with the same W: the drift
// is the flow of  (1/W)(v d/dq + d/dt + F d/dp - F.v d/dB),  split symmetrically (Strang) into
//   q += (dt/2) v(p),  friction over [t, t + dt] at fixed q (t advancing with it),  q += (dt/2) v(p),
// each part exact and W unchanged by every one, so dt = s/W holds for the whole drift and the drift stays
// symmetric (its inverse is the drift of length -s from its end). (Friction halves on each side of one q-drift
// would be as good and cost a second friction factor a drift: the factor sits on the step's critical path.)
// For F = -gamma(t) p (a linear friction on the momentum: -gamma(t) M v for T = p.M^{-1}p/2), the friction flow
// at fixed q is exact:
//   p <- p exp(-int gamma),   B <- W - T(p)   (the energy balance: B gains exactly the kinetic energy lost).
// Where the friction is constant (F = -gamma p; the system says so by constant_damping) and T quadratic, the drift
// needs no splitting: its exact flow is p <- e^{-gamma dt} p, q <- q + (1 - e^{-gamma dt})/gamma v(p), and exact
// flows compose, D(a) D(b) = D(a + b), so the drifts between the stages of a composition merge (a step of s
// stages costs s + 1 drifts and s kicks). It keeps M the same way (q moves along p).
// Why over the drift's dt: then the friction acts over exactly the intervals that t advances over, which tile
// [0, t_N]; for Kepler the drift (q += dt p) and the kick (p parallel to q) keep M = q x p, so M is multiplied by
// exp(-int_0^{t_N} gamma) and nothing else: the exact law M(t) = M(0) exp(-int_0^t gamma) holds at round-off at the
// scheme's own t. Applied over the kick's dt_k = s/U instead (what a regularized N-body code such as SpaceHub
// does with its auxiliary-velocity kick, advancing B over the same dt_k), the friction acts over intervals that
// sum to sum(s/U), which differs from the t the drifts advance by O(h^2): the law then holds to O(h^2) only
// (FrictionOver::kick, kept for the test that shows it).
//
// A system that runs it declares, beside its L and force (tests/schemes/logh.test.cpp holds these to them by AD):
//   template <class S> S kinetic(const Vec<S, n>& p) const;             T(p)
//   template <class S> Vec<S, n> kinetic_gradient(const Vec<S, n>& p) const;   dT/dp, the velocity
//   template <class S> S attraction(const Vec<S, n>& q) const;          U(q) = -V(q) > 0, autonomous
//   template <class S> Vec<S, n> log_attraction_gradient(const Vec<S, n>& q) const;   grad ln U = grad U / U
//   double damping_integral(double t0, double t1) const;              int_{t0}^{t1} gamma, F = -gamma(t) p
//   bool constant_damping(double& gamma) const;                         optional: gamma, where it is constant
//
// Compositions: a step of "<family>:logh" is the family's stages (composition_families.hpp), each a leapfrog step
// of length w_i h, so it costs s kicks (force evaluations) a step and has the family's order in sigma and in t.
//
// Output times. A fixed step in sigma lands on no prescribed t. Physical time advances only in the drifts, by
// dt = s/W > 0, so t after one step of length s in (0, h] is a smooth increasing function of s; the state at an
// output time t_i in [t_j, t_{j+1}) is one step of the same method (leapfrog or composition) from the state at t_j
// with the s that makes it land on t_i (solved by the secant method to within 1e-4 of the step's dt, the last
// sliver closed by one leapfrog step in t: see partial). The partial step is not continued from: the run keeps
// its fixed step in sigma (its long-time behaviour is that of the fixed-step map), and the output has the local
// error of one step of the method, O(s^{p+1}), the order p of the method itself (what dense output of order p
// would give, at the price of one partial step per output time). Physical time is summed with Kahan's
// compensation (State::tc).
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "geomint/error.hpp"
#include "geomint/generic/composition_families.hpp"
#include "geomint/generic/system.hpp"

namespace geomint::generic {

enum class FrictionOver { drift, kick };

// Whether the system's friction is a constant gamma (F = -gamma p): its optional
//   bool constant_damping(double& gamma) const;
// says so for its current parameters. Then the drift has an exact flow (Logh::exact_drift).
template <class Sys, class = void>
struct has_constant_damping : std::false_type {};
template <class Sys>
struct has_constant_damping<Sys, std::void_t<decltype(std::declval<const Sys&>().constant_damping(std::declval<double&>()))>>
    : std::true_type {};
template <class Sys>
bool constant_damping(const Sys& sys, double& gamma) {
  if constexpr (has_constant_damping<Sys>::value)
    return sys.constant_damping(gamma);
  else
    return (void)sys, (void)gamma, false;
}

template <class Sys>
class Logh {
 public:
  static constexpr int n = Sys::dof;
  using VecN = Vec<double, n>;
  struct State {
    VecN q, p;
    double t = 0, B = 0;  // physical time, binding energy -E
    double iw = 0;        // 1/W = 1/(T(p) + B), kept with the state (see drift)
    double tc = 0;        // the compensation of t's sum (Kahan): t is a sum of 10^7..10^8 drifts over a long
                          // run; compensated, its rounding stays below that of q and p
  };

  // family == nullptr: the leapfrog itself; else its composition with that family.
  Logh(const Sys& sys, double h, const CompositionFamily* family = nullptr, FrictionOver over = FrictionOver::drift)
      : sys_(sys), h_(h), over_(over) {
    require(std::isfinite(h) && h > 0, "the logH step in sigma must be positive and finite, got " + show(h));
    if (family) {
      require(!family->weights.empty(), "composition family '" + family->name + "' has no weights");
      for (const long double w : family->weights) weights_.push_back(static_cast<double>(w));
    } else {
      weights_.push_back(1.0);
    }
    // The drifts of a step: with an exact drift flow (no friction in it, or a constant one) D(a) D(b) = D(a + b),
    // so the second drift of a stage and the first of the next merge: s + 1 drifts a step of s stages instead of 2s.
    if (family) {
      const auto& w = family->weights;
      drifts_.push_back(static_cast<double>(w.front() / 2));
      for (std::size_t i = 0; i + 1 < w.size(); ++i) drifts_.push_back(static_cast<double>((w[i] + w[i + 1]) / 2));
      drifts_.push_back(static_cast<double>(w.back() / 2));
    } else {
      drifts_ = {0.5, 0.5};
    }
    exact_drift_ = over == FrictionOver::kick || constant_damping(sys, gamma_);
  }

  // From q0 and the momentum p0; B0 = U(q0) - T(p0), so that W = U on the motion.
  void start(const VecN& q0, const VecN& p0, double t0 = 0) {
    s_.q = q0;
    s_.p = p0;
    s_.t = t0;
    s_.B = sys_.attraction(q0) - sys_.kinetic(p0);
    require(std::isfinite(s_.B) && sys_.attraction(q0) > 0, "the logH scheme needs U(q0) > 0 and finite data");
    require(W(s_) > 0, "the logH scheme needs T(p0) + B0 = U(q0) > 0");
    s_.iw = 1 / W(s_);
    kicks_ = 0;
    steps_ = 0;
  }

  // One step of length h in sigma (all stages).
  void step() { step(s_, h_); }
  // One step of length s from x (all stages), in place.
  void step(State& x, double s) {
    if (!exact_drift_) {
      for (const double w : weights_) leapfrog(x, w * s);
      return;
    }
    const std::size_t m = weights_.size();
    exact_drift(x, drifts_[0] * s);
    for (std::size_t i = 0; i < m; ++i) {
      kick(x, weights_[i] * s);
      x.iw = 1 / W(x);
      exact_drift(x, drifts_[i + 1] * s);
    }
  }

  const State& state() const { return s_; }
  State& state() { return s_; }
  double h() const { return h_; }
  int stages() const { return static_cast<int>(weights_.size()); }
  long kicks() const { return kicks_; }  // force evaluations so far (one a stage, partial steps included)
  long steps() const { return steps_; }  // full steps of run_to (the state it has stepped to is one past the last output)

  // The state at t_out in [x.t, y.t] where y is one step of length h from x (see the header): one step of length
  // s in [0, h] from x, s solved by the secant method on the bracket from the inverse cubic Hermite guess (ds/dt =
  // W at both ends, as on the exact flow), until it lands within 1e-4 of the step's dt of t_out; the remaining
  // delta = t_out - t is closed by one leapfrog step in t itself (drift delta/2, friction over [t, t_out], kick
  // delta grad U, drift delta/2), whose error ~ delta^3 |d^3q/dt^3|/12 is below 1e-12 h^3 |q'|/(12 |q|) since
  // the step's dt is ~ |q| h (Kepler: 2e-13 at e = 0.9, k = 16); it keeps M = q x p and scales it by the friction's exact factor (the law holds at t_out), and costs one
  // force evaluation, against a whole composed step for each further secant iteration.
  State partial(const State& x, const State& y, double t_out) {
    require(t_out >= x.t && t_out <= y.t, "partial step: t_out outside the step");
    if (t_out == x.t) return x;
    if (t_out == y.t) return y;
    const double span = y.t - x.t, th = (t_out - x.t) / span;
    double s0 = 0, t0 = x.t, s1 = h_, t1 = y.t;  // bracket, t increasing in s
    double s = span * (th * (1 - th) * (1 - th) * W(x) + th * th * (th - 1) * W(y)) + th * th * (3 - 2 * th) * h_;
    double sa = th < 0.5 ? s0 : s1, ta = th < 0.5 ? t0 : t1;  // the secant's partner: the nearer end
    const double close = 1e-4 * span;
    State z = y;
    for (int it = 0; it < 30; ++it) {
      if (!(s > s0 && s < s1)) s = s0 + (t_out - t0) / (t1 - t0) * (s1 - s0);  // fall back on the bracket
      z = x;
      step(z, s);
      if (std::abs(z.t - t_out) <= close) {
        finish(z, t_out);
        return z;
      }
      if (z.t < t_out) {
        s0 = s;
        t0 = z.t;
      } else {
        s1 = s;
        t1 = z.t;
      }
      const double sn = s - (z.t - t_out) * (s - sa) / (z.t - ta);
      sa = s;
      ta = z.t;
      s = sn;
    }
    throw NumericalFailure(0, "t", "the logH partial step did not land on t = " + show(t_out) + " (reached " + show(z.t) + ")");
  }

  // Steps at h until `times` (increasing, >= the start) are passed, calling observe(i, state at times[i]) for
  // each: a step that would pass t_i is kept as the next state, and t_i is reached by a partial step from the
  // state before it (the run itself never leaves its fixed step in sigma).
  template <class Observer>
  void run_to(const std::vector<double>& times, Observer&& observe) {
    State next = s_;
    step(next, h_);
    ++steps_;
    for (std::size_t i = 0; i < times.size(); ++i) {
      const double ti = times[i];
      require(ti >= s_.t, "output times must increase from the start");
      while (next.t < ti) {
        s_ = next;
        step(next, h_);
        ++steps_;
        if (!std::isfinite(next.t) || !next.q.allFinite() || !next.p.allFinite())
          throw NumericalFailure(0, "state", "the logH state is not finite at t = " + show(s_.t));
      }
      observe(i, partial(s_, next, ti));
    }
  }

  double W(const State& x) const { return sys_.kinetic(x.p) + x.B; }

 private:
  // exp(-x) to round-off. A friction over one drift has x = int gamma ~ gamma dt, tiny (1e-7 for the study's
  // alpha = 1e-5): there the Taylor polynomial to x^5 (remainder below x^6/720 < 1e-21 for |x| <= 2^-8, under
  // half an ulp of 1) costs a fifth of a call to std::exp, which would otherwise be most of a step.
  static double exp_minus(double x) {
    if (std::abs(x) > 0x1p-8) return std::exp(-x);
    // Estrin's form (1 - x) + x^2 ((1/2 - x/6) + x^2 (1/24 - x/120)): the factor sits on the step's chain of
    // dependent operations (dt -> factor -> p -> q), which Horner's form would lengthen by ten operations. The
    // rounded coefficients move the terms from x^2/2 on by an ulp of themselves, far below an ulp of the sum.
    const double x2 = x * x;
    return (1 - x) + x2 * ((0.5 - x * (1.0 / 6)) + x2 * (1.0 / 24 - x * (1.0 / 120)));
  }

  // Friction over [t0, t1] at fixed q: p scaled by exp(-int gamma), B by the energy balance (W kept exactly).
  // Without friction (the integral is exactly 0) nothing moves.
  void friction(State& x, double t0, double t1, double w) const {
    const double I = sys_.damping_integral(t0, t1);
    if (I == 0) return;
    x.p *= exp_minus(I);
    x.B = w - sys_.kinetic(x.p);
  }

  // The last delta of a partial step, in t (see partial).
  void finish(State& z, double t_out) {
    ++kicks_;
    const double d = t_out - z.t, w = W(z);
    z.q += (d / 2) * sys_.kinetic_gradient(z.p);
    friction(z, z.t, t_out, w);
    z.p += (d * sys_.attraction(z.q)) * sys_.log_attraction_gradient(z.q);
    z.q += (d / 2) * sys_.kinetic_gradient(z.p);
    z.t = t_out;
    z.tc = 0;
    z.iw = 1 / W(z);
  }

  // t += dt, compensated (Kahan).
  static void advance_time(State& x, double dt) {
    const double y = dt - x.tc, t1 = x.t + y;
    x.tc = (t1 - x.t) - y;
    x.t = t1;
  }

  // The drift's exact flow where the friction is constant (gamma) or absent, for a kinetic energy quadratic in p
  // (v linear in p): over dt, p(tau) = e^{-gamma tau} p, so q moves by phi v(p) with phi = int_0^dt e^{-gamma tau}
  // dtau = dt (1 - e^{-x})/x, x = gamma dt, and p scales by c = e^{-x}; B by the energy balance, W unchanged.
  void exact_drift(State& x, double s) const {
    const double dt = s * x.iw;
    if (gamma_ == 0 || over_ == FrictionOver::kick) {
      x.q += dt * sys_.kinetic_gradient(x.p);
    } else {
      const double w = W(x), g = gamma_ * dt;
      double c, phi;
      if (std::abs(g) <= 0x1p-8) {  // Taylor to x^5: remainders below x^6/720 < 1e-17
        const double g2 = g * g;
        c = (1 - g) + g2 * ((0.5 - g * (1.0 / 6)) + g2 * (1.0 / 24 - g * (1.0 / 120)));
        phi = dt * ((1 - g * 0.5) + g2 * ((1.0 / 6 - g * (1.0 / 24)) + g2 * (1.0 / 120 - g * (1.0 / 720))));
      } else {
        c = std::exp(-g);
        phi = -std::expm1(-g) / gamma_;
      }
      x.q += phi * sys_.kinetic_gradient(x.p);
      x.p *= c;
      x.B = w - sys_.kinetic(x.p);
    }
    advance_time(x, dt);
  }

  // x.iw = 1/W: W is unchanged by a drift (and by the friction in it), so it is computed once a kick, and both
  // drifts next to that kick (this stage's second, the next stage's first) multiply by it.
  void drift(State& x, double s) const {
    const double w = W(x), dt = s * x.iw, y = dt - x.tc, t1 = x.t + y;  // t1: t + dt, compensated
    if (over_ == FrictionOver::drift) {
      x.q += (dt / 2) * sys_.kinetic_gradient(x.p);
      friction(x, x.t, t1, w);
      x.q += (dt / 2) * sys_.kinetic_gradient(x.p);
    } else {
      x.q += dt * sys_.kinetic_gradient(x.p);
    }
    x.tc = (t1 - x.t) - y;
    x.t = t1;
  }

  void kick(State& x, double s) {
    ++kicks_;
    if (over_ == FrictionOver::drift) {
      x.p += s * sys_.log_attraction_gradient(x.q);
      return;
    }
    // The variant kept for the counter-test: the friction over the kick's own dt_k = s/U, in two halves about the
    // conservative kick, B advanced by the kinetic energy each half removes (t does not move in a kick).
    const double dtk = s / sys_.attraction(x.q), tm = x.t + dtk / 2;
    double T0 = sys_.kinetic(x.p);
    x.p *= exp_minus(sys_.damping_integral(x.t, tm));
    x.B += T0 - sys_.kinetic(x.p);
    x.p += s * sys_.log_attraction_gradient(x.q);
    T0 = sys_.kinetic(x.p);
    x.p *= exp_minus(sys_.damping_integral(tm, x.t + dtk));
    x.B += T0 - sys_.kinetic(x.p);
  }

  void leapfrog(State& x, double s) {
    drift(x, s / 2);
    kick(x, s);
    x.iw = 1 / W(x);
    drift(x, s / 2);
  }

  const Sys& sys_;
  double h_;
  FrictionOver over_;
  std::vector<double> weights_, drifts_;  // stage weights; drift lengths of a merged step (over s)
  bool exact_drift_ = false;
  double gamma_ = 0;
  State s_;
  long kicks_ = 0, steps_ = 0;
};

}  // namespace geomint::generic
