#pragma once
// The damped harmonic oscillator of Section 3.1 (m = 1): L = q'^2/2 - q^2/2 (5), Rayleigh force F = -alpha q',
// Herglotz form L - alpha z (9). Equation of motion q'' + alpha q' + q = 0, solved in closed form for every
// regime (linear_oscillator.hpp).
//
// Its closed forms are the fast paths of the generic schemes (each states the scheme it solves and is held to it
// step by step in tests/systems/system_oscillator.test.cpp): the paper's integrators (7) (derived: `la`) and (10)
// (`contact`), and the second-order comparators `la-midpoint`, the implicit leapfrog (`la-trapezoid`, the paper's
// "leapfrog") and the symmetric contact integrator (`contact-trapezoid`, "contact-sym"). Beyond the generic schemes
// the oscillator declares two of its own: eq. (7) exactly as printed (`la-printed`, which does not converge) and a
// conformal symplectic splitting (`conformal-strang`).
//
// Every closed form is a position–momentum map on OscState (q_j, p_j, z_j) -> (q_{j+1}, p_{j+1}, z_{j+1}) with a
// `step` templated on the scalar: the same template runs one trajectory (run_fast), long double one-step matrices
// (stability maps, all-orders modified equations) and the vectorized ensembles (ensemble.hpp), lane by lane.
// Templated on the parameter type (Oscillator = OscillatorT<double>): a symbolic P gives the formulas.
#include <algorithm>
#include <cmath>
#include <tuple>
#include <vector>

#include "geomint/error.hpp"
#include "geomint/generic/system_schemes.hpp"
#include "geomint/generic/schemes.hpp"
#include "geomint/linear_oscillator.hpp"
#include "geomint/registry.hpp"

namespace geomint {

// The state of a closed form: z is the Herglotz action, carried by the contact schemes only.
template <class T>
struct OscState {
  T q{}, p{}, z{};
};

namespace systems {

template <class P = double>
struct OscillatorT {
  static constexpr const char* name = "oscillator";
  static constexpr const char* description = "damped harmonic oscillator (Section 3.1): q'' + alpha q' + q = 0";
  static constexpr int dof = 1;
  static constexpr int constraints = 0;
  static constexpr bool linear = true;
  static constexpr bool autonomous = true;  // no explicit t: the generic step is one fixed affine map

  P alpha = 0.01, q0 = -0.25, p0 = 0.75, T = 50;

  template <class V>
  void visit(V&& v) {
    v("alpha", alpha, "Rayleigh damping");
    v("q0", q0, "initial position");
    v("p0", p0, "initial momentum (= velocity)");
    v("T", T, "horizon");
  }
  void validate() const {
    require_nonnegative(alpha, "alpha");
    require_finite(q0, "q0");
    require_finite(p0, "p0");
    require_positive(T, "T");
  }
  // What the tests expect: contact's O(h) error terms are proportional to alpha^2 here (docs/paper.md), so over h = 0.1 ...
  // 0.0125 it shows order 2 (local orders 2.04, 2.06, 2.04; generic path, T = 20, alpha = 0.01), and crosses over
  // to its order 1 below (1.78, 1.22, 0.93 down to h = 0.0016).
  static Expectations expectations() {
    Expectations e;
    e.params = {{"T", 20}};
    e.halvings = 3;
    e.orders = {{"contact", 2}};
    e.why = "h >= 0.0125: contact's O(h) terms (~ alpha^2) are below its O(h^2) terms";
    return e;
  }

  template <class S>
  S lagrangian(const S&, const Vec<S, 1>& q, const Vec<S, 1>& v) const {
    return v(0) * v(0) / 2 - q(0) * q(0) / 2;
  }
  template <class S>
  S herglotz(const S& t, const Vec<S, 1>& q, const Vec<S, 1>& v, const S& z) const {
    return lagrangian(t, q, v) - alpha * z;
  }
  template <class S>
  Vec<S, 1> force(const S&, const Vec<S, 1>&, const Vec<S, 1>& v) const {
    return Vec<S, 1>::Constant(-alpha * v(0));
  }
  template <class S>
  Vec<S, 1> initial_position() const {
    return Vec<S, 1>::Constant(S(q0));
  }
  template <class S>
  Vec<S, 1> initial_velocity() const {
    return Vec<S, 1>::Constant(S(p0));
  }
  template <class S>
  Phase<S, 1> exact(const S& t) const {
    const auto x = linear_oscillator_solution<S>(S(alpha), S(1), S(q0), S(p0), t);
    return {Vec<S, 1>::Constant(x.q), Vec<S, 1>::Constant(x.v)};
  }
  void rhs(double, const Vec<double, 1>& q, const Vec<double, 1>& v, Vec<double, 1>& a) const {
    a(0) = -q(0) - alpha * v(0);
  }

  // ---------------------------------------------------------------------------------------------------------
  // Closed forms of the generic schemes

  // `la`: the forced discrete Euler–Lagrange equations (1) with L_d = h L(q_j, v_j), F_d^- = h F(q_j, v_j) =
  // -alpha h v_j, F_d^+ = 0, v_j = (q_{j+1}-q_j)/h:
  //   -v_j - h q_j + v_{j-1} - alpha h v_j = 0.
  // Discrete Legendre transform p_j = -D1 L_d - F_d^- = (1 + h alpha) v_j + h q_j, p_{j+1} = D2 L_d = v_j:
  //   p_{j+1} = (p_j - h q_j) / (1 + h alpha),   q_{j+1} = q_j + h p_{j+1}.
  // The paper's eq. (7) prints the denominator as (1 + alpha); see LaPrinted.
  struct La {
    static constexpr const char* name = "(7) derived";
    using solves = generic::LaLeft;
    template <class T>
    static void step(OscState<T>& s, T h, T alpha) {
      // multiply by the reciprocal: loop-invariant, so the division leaves the step's critical path
      const T c = 1 / (1 + h * alpha);
      s.p = (s.p - h * s.q) * c;
      s.q = s.q + h * s.p;
    }
  };

  // `contact`: eq. (10), the discrete Herglotz equations (3) with
  // L_d(q_j, q_{j+1}, z_j) = h [ v_j^2/2 - (q_j^2 + q_{j+1}^2)/4 - alpha z_j ],  z_{j+1} = z_j + L_d:
  //   q_{j+1} = (1 - h^2/2) q_j + h (1 - h alpha) p_j,
  //   p_{j+1} = (1 - h alpha) p_j - h/2 (q_{j+1} + q_j).
  struct Contact {
    static constexpr const char* name = "(10)";
    using solves = generic::ContactLeft;
    template <class T>
    static void step(OscState<T>& s, T h, T alpha) {
      const T qn = (1 - h * h / 2) * s.q + h * (1 - h * alpha) * s.p;
      const T inv_h = 1 / h;  // loop-invariant reciprocal: no division inside a run
      const T v = (qn - s.q) * inv_h;
      s.z = s.z + h * (v * v / 2 - (s.q * s.q + qn * qn) / 4 - alpha * s.z);
      s.p = (1 - h * alpha) * s.p - h / 2 * (qn + s.q);
      s.q = qn;
    }
  };

  // `la-midpoint`: L_d = h L((q_j+q_{j+1})/2, v_j), F_d^+ = F_d^- = h/2 F(., v_j). The discrete Legendre
  // transforms p_j = -D1 L_d - F_d^-, p_{j+1} = D2 L_d + F_d^+ give, with c = 1 + h alpha/2 + h^2/4,
  //   v = (p_j - h q_j/2) / c,  q_{j+1} = q_j + h v,  p_{j+1} = (1 - h alpha/2 - h^2/4) v - h q_j/2.
  // Symmetric, hence second order.
  struct LaMidpoint {
    static constexpr const char* name = "midpoint closed form";
    using solves = generic::LaMidpoint;
    template <class T>
    static void step(OscState<T>& s, T h, T alpha) {
      const T v = (s.p - h * s.q / 2) * (1 / (1 + h * alpha / 2 + h * h / 4));
      s.p = (1 - h * alpha / 2 - h * h / 4) * v - h * s.q / 2;
      s.q = s.q + h * v;
    }
  };

  // `la-trapezoid`, the implicit leapfrog: Störmer–Verlet (Lobatto IIIA–IIIB) for q' = p, p' = f(q, p) = -q - alpha p:
  //   p_{j+1/2} = p_j + h/2 f(q_j, p_{j+1/2})          (implicit, linear: closed form)
  //   q_{j+1}   = q_j + h p_{j+1/2}
  //   p_{j+1}   = p_{j+1/2} + h/2 f(q_{j+1}, p_{j+1/2})  (explicit)
  // The two half kicks are adjoint, so the step is symmetric and second order. The paper's reference at h/10.
  struct Leapfrog {
    static constexpr const char* name = "implicit leapfrog";
    static constexpr const char* alias = "leapfrog";
    using solves = generic::LaTrapezoid;
    template <class T>
    static void step(OscState<T>& s, T h, T alpha) {
      const T d = 1 / (1 + h * alpha / 2);
      const T ph = (s.p - h / 2 * s.q) * d;
      s.q = s.q + h * ph;
      s.p = ph - h / 2 * (s.q + alpha * ph);
    }
  };

  // `contact-trapezoid`, the symmetric contact integrator: L_d = h [ v^2/2 - (q_j^2+q_{j+1}^2)/4 -
  // alpha (z_j+z_{j+1})/2 ] with z_{j+1} = z_j + L_d, solved for z_{j+1} (linear), so L_d(q_j,q_{j+1},z_j) =
  // h (A - alpha z_j)/(1 + h alpha/2), A = v^2/2 - (q_j^2+q_{j+1}^2)/4. The contact Legendre maps
  // p_j = -D1 L_d / (1 + D3 L_d), p_{j+1} = D2 L_d give
  //   v = (1 - h alpha/2) p_j - h q_j/2,  q_{j+1} = q_j + h v,  p_{j+1} = (v - h q_{j+1}/2)/(1 + h alpha/2).
  struct ContactSymmetric {
    static constexpr const char* name = "symmetric contact closed form";
    static constexpr const char* alias = "contact-sym";
    using solves = generic::ContactTrapezoid;
    template <class T>
    static void step(OscState<T>& s, T h, T alpha) {
      const T v = (1 - h * alpha / 2) * s.p - h * s.q / 2;
      const T qn = s.q + h * v;
      const T A = v * v / 2 - (s.q * s.q + qn * qn) / 4;
      const T d = 1 / (1 + h * alpha / 2);
      s.z = ((1 - h * alpha / 2) * s.z + h * A) * d;
      s.p = (v - h * qn / 2) * d;
      s.q = qn;
    }
  };

  using fast_paths = std::tuple<La, Contact, LaMidpoint, Leapfrog, ContactSymmetric>;

  // ---------------------------------------------------------------------------------------------------------
  // Schemes of the oscillator beyond the generic ones

  // `la-printed`: eq. (7) exactly as printed, p_j = (p_{j-1} - h q_{j-1}) / (1 + alpha). Kept so users can see
  // what it does: it damps by 1/(1+alpha) per step whatever h is, so it does not converge as h -> 0.
  struct LaPrinted {
    static constexpr const char* name = "la-printed";
    static constexpr const char* description = "eq. (7) as printed, denominator 1+alpha (does not converge)";
    static constexpr int order = 0;
    static constexpr bool contact = false;
    using solves = void;
    template <class T>
    static void step(OscState<T>& s, T h, T alpha) {
      const T c = 1 / (1 + alpha);
      s.p = (s.p - h * s.q) * c;
      s.q = s.q + h * s.p;
    }
  };

  // `conformal-strang`: the damping flow p' = -alpha p solved exactly for h/2 on each side of an undamped
  // Störmer–Verlet step. Every substep is symplectic or scales p exactly, so the one-step map contracts
  // phase-space area by exactly e^{-alpha h}, the continuous rate (a conformal symplectic method). Symmetric,
  // hence second order.
  struct ConformalStrang {
    static constexpr const char* name = "conformal-strang";
    static constexpr const char* description = "conformal symplectic Strang splitting, second order";
    static constexpr int order = 2;
    static constexpr bool contact = false;
    using solves = void;
    template <class T>
    static void step(OscState<T>& s, T h, T alpha) {
      using std::exp;
      const T damp = exp(-alpha * h / 2);  // loop-invariant: hoisted out of a run
      s.p *= damp;
      s.p -= h / 2 * s.q;
      s.q += h * s.p;
      s.p -= h / 2 * s.q;
      s.p *= damp;
    }
  };

  using extra_schemes = std::tuple<LaPrinted, ConformalStrang>;

  // ---------------------------------------------------------------------------------------------------------
  // Running a closed form

  // N steps of closed form X from the initial data, in the generic observer's terms (its state is (q, p, z)
  // already: the closed forms are position–momentum maps). The loop runs on a local copy, so the state stays in
  // registers, and finiteness is checked once per block of steps: a non-finite value never becomes finite again
  // in these recurrences (inf - inf = NaN, NaN stays NaN), so one check at the end of a block catches it; the
  // block is then replayed from its saved start to report the exact step. (A check per step sat on a ~4 ns step
  // and cost up to 20 %.) The observer may see up to kBlock - 1 non-finite states before the failure is thrown.
  template <class X, class R, class Observer>
  void run_fast(R h, long N, Observer&& observe) const {
    using std::isfinite;
    constexpr long kBlock = 32;
    const R a = R(alpha);
    OscState<R> s{R(q0), R(p0), R(0)};
    Vec<R, 1> q, p;
    const Vec<R, 0> lambda;
    auto emit = [&](long j) {
      q(0) = s.q;
      p(0) = s.p;
      observe(generic::StepView<R, 1, 0>{j, R(j) * h, q, p, s.z, lambda});
    };
    emit(0);
    for (long j = 1; j <= N;) {
      const OscState<R> saved = s;
      const long j0 = j, end = std::min(N, j + kBlock - 1);
      for (; j <= end; ++j) {
        X::step(s, h, a);
        emit(j);
      }
      if (!isfinite(s.q) || !isfinite(s.p)) {
        OscState<R> r = saved;
        for (long k = j0; k <= end; ++k) {
          X::step(r, h, a);
          if (!isfinite(r.q) || !isfinite(r.p)) throw NumericalFailure(k, "state", "non-finite q or p");
        }
      }
    }
  }

  // The one-step matrix of closed form X on (q, p), by stepping the unit vectors in long double (the all-orders
  // modified coefficients and the stability maps computed from it keep their digits). Row-major.
  template <class X>
  std::vector<long double> closed_form_matrix(long double h) const {
    OscState<long double> e1{1, 0, 0}, e2{0, 1, 0};
    const long double a = alpha;
    X::step(e1, h, a);
    X::step(e2, h, a);
    return {e1.q, e2.q, e1.p, e2.p};
  }
};
using Oscillator = OscillatorT<>;

}  // namespace systems
}  // namespace geomint
