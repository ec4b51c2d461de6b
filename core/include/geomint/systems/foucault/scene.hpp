#pragma once
// The scene of Section 3.2 (systems::FoucaultPendulum): parameters, initial data, horizon, the Lagrangian and
// the closed-form solution, shared by both constraint systems; the equations written once over their
// combinations (FoucaultDynamics) and the two constraint rows (PaperConstraint, RotationConstraint).
#include <cmath>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "geomint/constants.hpp"
#include "geomint/error.hpp"
#include "geomint/generic/system_schemes.hpp"
#include "geomint/observers.hpp"
#include "geomint/registry.hpp"
#include "geomint/systems/foucault/exact.hpp"
#include "geomint/systems/foucault/params.hpp"
#include "geomint/systems/foucault/plane.hpp"
#include "geomint/systems/foucault/steps.hpp"

namespace geomint {

namespace systems {

// ---------------------------------------------------------------------------------------------------
// The equations, written once over the combinations they use: mass(), w2() = g/l, damping() = alpha,
// s() = Omega sin(beta), phi0() (the rotation's plane at t = 0). The double systems below read them from their
// scene; the symbolic instantiations (FoucaultT<P>, FoucaultRotationT<P>, P a computer-algebra type) make each a
// symbol of its own, so the modified equations come as formulas in m, w2, alpha, s as docs/formulas.md writes them.

template <class P>
struct FoucaultT;
template <class P>
struct FoucaultRotationT;

template <class Self>
struct FoucaultDynamics {
  template <class S>
  S lagrangian(const S&, const Vec<S, 2>& q, const Vec<S, 2>& v) const {
    const Self& p = self();
    return p.mass() / 2 * v.squaredNorm() - p.mass() * p.w2() / 2 * q.squaredNorm();
  }
  template <class S>
  S herglotz(const S& t, const Vec<S, 2>& q, const Vec<S, 2>& v, const S& z) const {
    return lagrangian(t, q, v) - self().damping() * z;
  }
  template <class S>
  Vec<S, 2> force(const S&, const Vec<S, 2>&, const Vec<S, 2>& v) const {
    return -(self().damping() * self().mass()) * v;
  }

 private:
  const Self& self() const { return static_cast<const Self&>(*this); }
};

// The paper's constraint (13): A(q) = (-y, x), b = s |q|^2.
template <class Self>
struct PaperConstraint {
  template <class S>
  Mat<S, 1, 2> constraint_matrix(const S&, const Vec<S, 2>& q) const {
    return Mat<S, 1, 2>(-q(1), q(0));
  }
  template <class S>
  Vec<S, 1> constraint_offset(const S&, const Vec<S, 2>& q) const {
    return Vec<S, 1>::Constant(static_cast<const Self&>(*this).s() * q.squaredNorm());
  }
};

// The remedy's rheonomic holonomic constraint g(t, q) = n(phi(t)).q, phi(t) = phi_0 - s t.
template <class Self>
struct RotationConstraint {
  template <class S>
  Mat<S, 1, 2> constraint_matrix(const S& t, const Vec<S, 2>&) const {
    using std::cos;
    using std::sin;
    const S phi = plane(t);
    return Mat<S, 1, 2>(-sin(phi), cos(phi));
  }
  template <class S>
  Vec<S, 1> constraint_offset(const S& t, const Vec<S, 2>& q) const {
    using std::cos;
    using std::sin;
    const S phi = plane(t);
    return Vec<S, 1>::Constant(static_cast<const Self&>(*this).s() * (cos(phi) * q(0) + sin(phi) * q(1)));
  }
  template <class S>
  Vec<S, 1> holonomic(const S& t, const Vec<S, 2>& q) const {
    using std::cos;
    using std::sin;
    const S phi = plane(t);
    return Vec<S, 1>::Constant(-sin(phi) * q(0) + cos(phi) * q(1));
  }

 private:
  template <class S>
  S plane(const S& t) const {
    const Self& p = static_cast<const Self&>(*this);
    return S(p.phi0()) - p.s() * t;
  }
};

// ---------------------------------------------------------------------------------------------------
// The scene and what both constraint discretizations share

struct FoucaultPendulum : FoucaultDynamics<FoucaultPendulum> {
  static constexpr int dof = 2;
  static constexpr int constraints = 1;

  double m = 28;             // kg
  double l = 67;             // m
  double g = 9.81;           // m/s^2
  double beta_deg = 49;      // latitude, degrees
  double Omega = 7.2921e-5;  // Earth's angular velocity, rad/s
  double alpha = 1e-3;       // Rayleigh damping, 1/s
  double x0 = 0.67, y0 = 0;  // q(0), m
  double vx0 = 0, vy0 = 0;   // q'(0), m/s (the paper's (0, 0) violates (13): see FoucaultStart)
  double T = 3600;           // horizon, s

  template <class V>
  void visit(V&& v) {
    v("m", m, "mass (kg)");
    v("l", l, "length (m)");
    v("g", g, "gravity (m/s^2)");
    v("beta", beta_deg, "latitude (degrees)");
    v("Omega", Omega, "Earth's angular velocity (rad/s)");
    v("alpha", alpha, "Rayleigh damping (1/s)");
    v("x0", x0, "initial x (m)");
    v("y0", y0, "initial y (m)");
    v("vx0", vx0, "initial x' (m/s; projected onto (13))");
    v("vy0", vy0, "initial y' (m/s; projected onto (13))");
    v("T", T, "horizon (s)");
  }
  // Throws InputError naming the first bad parameter.
  void validate() const;
  double w2() const { return g / l; }
  double s() const;  // Omega sin(beta)
  double mass() const { return m; }
  double damping() const { return alpha; }
  double phi0() const { return std::atan2(y0, x0); }
  // The values of the symbolic instantiations' parameters (FoucaultSymbols below) at this scene.
  template <class V>
  void visit_symbols(V&& v) const {
    v("m", m);
    v("w2", w2());
    v("alpha", alpha);
    v("s", s());
    v("x0", x0);
    v("y0", y0);
  }
  // The physical parameters and initial data as header lines for output files.
  std::vector<std::pair<std::string, std::string>> header_params() const;
  // The projection onto (13) in closed form (consistent_velocity above), which the closed forms start from: the
  // generic step and the references start from the same bits.
  Vec<double, 2> project_velocity(double, const Vec<double, 2>& q, const Vec<double, 2>& v) const {
    return consistent_velocity(FoucaultParams<double>(*this), Vec2<double>(q), Vec2<double>(v));
  }
  // What a convergence study measures on a run beyond the error in q (below).
  class Measures;
  // The convergence tests run the first quarter swing: the paper's constraint is singular at the origin (first pass
  // at t = pi/(2 sqrt(w2 - s^2)) = 4.1 s, where a landing kicks the plane by s h / rho: docs/where-methods-fail.md), with a damping
  // large enough to be seen over 4 s.
  static Expectations expectations() {
    Expectations e;
    e.params = {{"T", 4}, {"alpha", 0.1}};
    e.why = "T = 4 s: before the first pass through the origin; alpha = 0.1: a visible damping";
    return e;
  }

  template <class S>
  Vec<S, 2> initial_position() const {
    return Vec<S, 2>(S(x0), S(y0));
  }
  template <class S>
  Vec<S, 2> initial_velocity() const {
    return Vec<S, 2>(S(vx0), S(vy0));
  }
  // The closed form (foucault_exact) from the consistent initial velocity.
  template <class S>
  Phase<S, 2> exact(const S& t) const {
    const FoucaultParams<S> p(*this);
    const Vec<S, 2> q0 = initial_position<S>();
    const auto x = foucault_exact<S>(p, q0, geomint::consistent_velocity<S>(p, q0, initial_velocity<S>()), t);
    return {x.q, x.v};
  }
  // The multiplier ODE (foucault_multiplier_acceleration).
  void rhs(double, const Vec<double, 2>& q, const Vec<double, 2>& v, Vec<double, 2>& a) const {
    foucault_multiplier_acceleration(w2(), s(), alpha, q(0), q(1), v(0), v(1), a(0), a(1));
  }

  // ---------------------------------------------------------------------------------------------------------
  // The paper's integrators: closed forms of the generic `la` and `contact` on both systems.

  struct La;
  struct Contact;
  using fast_paths = std::tuple<La, Contact>;

 protected:
  // N steps of closed form C on system Self (its own constraint row), reported as the generic scheme sees them:
  // p_j is that scheme's discrete Legendre transform of (q_{j-1}, q_j), z_j its action (the closed forms do not
  // carry z), lambda the impulse of the step into q_j.
  template <class Self, class C, class R, class Observer>
  static void run_as_generic(const Self& self, R h, long N, Observer&& observe);
  // The same q_j alone: observe(j, t_j, q_j). The two-step forms carry no momentum, so the generic p_j (and z_j)
  // beside them cost more than the step itself; a run that reads only q skips them.
  template <class Self, class C, class R, class Observer>
  static void positions_of(const Self& self, R h, long N, Observer&& observe);
};

// What a convergence study measures on a run of either constraint beyond the error in q (SystemInfo::measures),
// step j -> j+1 against the reference on a grid of h/2 (it holds t_j and t_{j+1/2}, with velocities):
//   energy_err    max_j |E_{j+1/2} - E_ref(t_{j+1/2})| / E0: the chord energy against the reference's energy
//   plane_err     max_j |angle(q_j) - angle(q_ref(t_j))| mod pi (rad), over the steps where the reference is in the
//                 outer half of its swing (|q_ref| >= |q0| e^{-alpha t/2}/2), where the polar angle is the plane's
//   rate_rel_err  |fitted precession rate / (-Omega sin beta) - 1| over the turning points (at least 3)
//   min_r         min_j |q_j| (m): how close the run passes by the origin, where (13) is singular
// The bob's distance from the reference, max_j |q_j - q_ref(t_j)| in the Euclidean norm, is the study's error
// with --norm 2.
class FoucaultPendulum::Measures {
 public:
  static std::vector<MeasureInfo> info();
  Measures(const FoucaultPendulum& sys, double h, long N, const Reference& ref);
  void operator()(long j, double t, const Vec<double, 2>& q);  // every q_j, j = 0..N, in order
  std::vector<double> values() const;

 private:
  FoucaultParams<double> p_;
  const Reference& ref_;
  double h_, alpha_, s_, r0_, E0_;
  long stride_;  // reference rows per step
  Vec2<double> qm_, q_;
  double t_ = 0;
  double energy_err_ = 0, plane_err_ = 0, min_r_;
  PlaneTurns plane_;
};

namespace detail {
template <class T>
void require_solvable(T r2, long j) {
  using std::isfinite;
  if (!(r2 > 0) || !isfinite(r2))
    throw NumericalFailure(j, "r_j^2",
                           "q_j is at the origin or not finite: the constraint (13) gives no equation for lambda");
}
// A paper step of either scheme through its component form: check r_j^2, solve, repack.
template <class Scheme, class T>
void paper_step(const FoucaultParams<T>& p, const Vec2<T>& qm, const Vec2<T>& q, T h, Vec2<T>& qn, T& lambda1, long j) {
  const T r2 = q.squaredNorm();
  require_solvable(r2, j);
  T xn, yn, lm;
  Scheme::step_xy(p, h, qm(0), qm(1), q(0), q(1), r2, xn, yn, lm);
  qn = Vec2<T>(xn, yn);
  lambda1 = lm * p.m;
}

// The constraint row of a rotation step, shared by both schemes: q_{j+1} = qh - mu n(phi_j) with
// n(phi_{j+1}).q_{j+1} = 0, built in the basis of the new line (n(phi_{j+1}) = (-e1, e0)).
template <class T>
inline void finish_rotation_step(T qhx, T qhy, T ln0, T ln1, T e0, T e1, T& xn, T& yn, T& mu) {
  const T n0 = -e1, n1 = e0;
  mu = (n0 * qhx + n1 * qhy) / (n0 * ln0 + n1 * ln1);
  const T r = (e0 * qhx + e1 * qhy) - mu * (e0 * ln0 + e1 * ln1);
  xn = r * e0;
  yn = r * e1;
}
}  // namespace detail

}  // namespace systems

template <class T>
FoucaultParams<T>::FoucaultParams(const systems::FoucaultPendulum& sc)
    : m(sc.m), w2(T(sc.g) / T(sc.l)), s(T(sc.Omega) * sin_deg(T(sc.beta_deg))), alpha(sc.alpha) {}

// Checks a sweep before anything is written: at least one h and one alpha, every h divides T, and the scene
// is valid at every alpha (throws InputError).
void validate_foucault_sweep(const systems::FoucaultPendulum& base, const std::vector<double>& hs,
                             const std::vector<double>& alphas);

}  // namespace geomint
