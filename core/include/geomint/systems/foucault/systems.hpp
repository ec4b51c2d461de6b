#pragma once
// The two registered systems: foucault (the paper's constraint (13)) and foucault-rotation (the remedy), their
// closed-form loops, their symbolic twins, and the name visitor of the typed code.
#include <cmath>
#include <string>

#include "geomint/error.hpp"
#include "geomint/generic/schemes.hpp"
#include "geomint/systems/foucault/closed_forms.hpp"

namespace geomint {
namespace systems {

// ---------------------------------------------------------------------------------------------------
// The two systems

struct Foucault : FoucaultPendulum, PaperConstraint<Foucault> {
  static constexpr const char* name = "foucault";
  static constexpr const char* description = "damped Foucault pendulum (Section 3.2) with the nonholonomic constraint (13)";
  static constexpr const char* discretization = "paper";  // the third row of (15), (18): (13) o Psi
  static constexpr bool linear_dynamics = true;  // L quadratic, F linear; (13)'s A and b are not affine
  using PaperConstraint<Foucault>::constraint_matrix;
  using PaperConstraint<Foucault>::constraint_offset;
  template <class P>
  using symbolic = FoucaultT<P>;  // the same equations with symbolic parameters (below)

  // Steps j = j0 .. j1-1 of closed form C from (q_{j0-1}, q_{j0}) with the paper's third row: the observer is
  // called with the step j -> j+1 (FoucaultStep), so it sees every q_j, j = j0..j1. t_j = j h (never
  // accumulated); phi0 is not used. No allocation happens here. A mid-run start (j0 > 0) reruns a stretch of a
  // run, e.g. in a wider precision from the double state just before it.
  template <class C, class T, class Observer>
  void closed_steps(const FoucaultParams<T>& p, Vec2<T> qm, Vec2<T> q, long j0, long j1, T h, T /*phi0*/,
                    Observer&& observe) const {
    using std::isfinite;
    Vec2<T> qn;
    T lambda1;
    const T nan = T(missing_value);  // no residual: a closed form solves nothing
    for (long j = j0; j < j1; ++j) {
      C::step(p, qm, q, h, qn, lambda1, j);
      if (!isfinite(qn(0)) || !isfinite(qn(1))) throw state_failure(j);
      observe(FoucaultStep<T>{j, T(j) * h, qm, q, qn, lambda1, C::lambda_force(lambda1, h), nan});
      qm = q;
      q = qn;
    }
  }

  // The discrete constraint this system imposes at a step, and its round-off scale (for diagnostics).
  template <class T>
  static T imposed_constraint(const FoucaultParams<T>& p, const FoucaultStep<T>& st, T h) {
    return discrete_constraint(p, st.q, st.qn, h);
  }
  template <class T>
  static T imposed_constraint_scale(const FoucaultStep<T>& st, T h) {
    return discrete_constraint_scale(st.q, st.qn, h);
  }

  template <class C, class R, class Observer>
  void run_fast(R h, long N, Observer&& observe) const {
    run_as_generic<Foucault, C>(*this, h, N, observe);
  }
  template <class C, class R, class Observer>
  void run_positions(R h, long N, Observer&& observe) const {
    positions_of<Foucault, C>(*this, h, N, observe);
  }
};

// The remedy: in polar coordinates q = r e(theta), (13) reads r^2 (theta' + s) = 0, so on consistent data the
// plane turns at exactly -s and (13) is r times the derivative of g(t, q) = n(phi(t)).q (see above). Its
// closed forms carry the plane angle as state, phi_j = phi_0 - s t_j, and are regular at the origin.
struct FoucaultRotation : FoucaultPendulum, RotationConstraint<FoucaultRotation> {
  static constexpr const char* name = "foucault-rotation";
  static constexpr const char* description =
      "damped Foucault pendulum, constraint (13) as the exact rotation of the plane (the remedy for the anomaly)";
  static constexpr const char* discretization = "rotation";  // n(phi_{j+1}).q_{j+1} = 0, force along n(phi_j)
  // Not `linear`: each step is a linear solve, but its matrix turns with the plane (A = n(phi(t_j))), so a kept
  // Jacobian is stale — the linear lane's check caught this declaration. Linear dynamics with g = n(phi(t)).q
  // affine in q: the single-update path brings the constraint block of the kept Jacobian up to date every step.
  static constexpr bool linear_dynamics = true;

  using RotationConstraint<FoucaultRotation>::constraint_matrix;
  using RotationConstraint<FoucaultRotation>::constraint_offset;
  using RotationConstraint<FoucaultRotation>::holonomic;
  template <class P>
  using symbolic = FoucaultRotationT<P>;

  // Steps j = j0 .. j1-1 of closed form C with the rotation row (see Foucault::closed_steps); phi0 is the plane
  // angle at t = 0 (phi_j = phi0 - s t_j).
  template <class C, class T, class Observer>
  void closed_steps(const FoucaultParams<T>& p, Vec2<T> qm, Vec2<T> q, long j0, long j1, T h, T phi0,
                    Observer&& observe) const {
    using std::isfinite;
    Vec2<T> qn;
    T lambda1;
    // The line of q_k is at phi_k = phi0 - s t_k. Its cos and sin are evaluated afresh every K steps (the
    // anchor) and in between by one rotation from a table of the rotations by -s h b, b < K: the same
    // direction to a few ulps (tests/studies/foucault_anomaly.test.cpp checks the angle of every q_k against
    // phi0 - s t_k), without a sincos per step (which would double the cost of a step).
    const RotationTable<T> rot(p.s, h);
    FoucaultLine<T> anchor = foucault_line<T>(phi0 - p.s * (T(j0) * h)), L = anchor, Ln;
    long b = 0;
    for (long j = j0; j < j1; ++j) {
      const T phin = phi0 - p.s * (T(j + 1) * h);
      if (++b == RotationTable<T>::K) {
        b = 0;
        anchor = foucault_line<T>(phin);
        Ln = anchor;
      } else {
        T e0, e1;
        rot.line(b, anchor.e(0), anchor.e(1), e0, e1);
        Ln.e = Vec2<T>(e0, e1);
        Ln.n = Vec2<T>(-e1, e0);
      }
      C::step_rotation(p, qm, q, h, L, Ln, qn, lambda1);
      if (!isfinite(qn(0)) || !isfinite(qn(1))) throw state_failure(j);
      observe(FoucaultStep<T>{j, T(j) * h, qm, q, qn, lambda1, C::lambda_force_rotation(lambda1, h, q, L), phin});
      qm = q;
      q = qn;
      L = Ln;
    }
  }

  // The constraint this system imposes, n(phi_{j+1}).q_{j+1}, scaled by |q_j| + |q_{j+1}| (the size of the
  // step's inputs and output).
  template <class T>
  static T imposed_constraint(const FoucaultParams<T>&, const FoucaultStep<T>& st, T) {
    return foucault_line<T>(st.phin).n.dot(st.qn);
  }
  template <class T>
  static T imposed_constraint_scale(const FoucaultStep<T>& st, T) {
    return T(st.q.norm() + st.qn.norm());
  }

  template <class C, class R, class Observer>
  void run_fast(R h, long N, Observer&& observe) const {
    run_as_generic<FoucaultRotation, C>(*this, h, N, observe);
  }
  template <class C, class R, class Observer>
  void run_positions(R h, long N, Observer&& observe) const {
    positions_of<FoucaultRotation, C>(*this, h, N, observe);
  }
};

// The symbolic instantiations: the same equations (FoucaultDynamics and the constraint rows above) with each
// combination a parameter of type P (a computer-algebra symbol; geomint/modified/symbolic_system.hpp).
// FoucaultT<double> is not the registered system (that is Foucault, whose parameters are the physical scene).
template <class P>
struct FoucaultSymbols {
  static constexpr int dof = 2;
  static constexpr int constraints = 1;
  P m = 0, w2_ = 0, alpha = 0, s_ = 0, x0 = 0, y0 = 0;
  template <class V>
  void visit(V&& v) {
    v("m", m, "mass");
    v("w2", w2_, "g/l");
    v("alpha", alpha, "Rayleigh damping");
    v("s", s_, "Omega sin(beta)");
    v("x0", x0, "initial x");
    v("y0", y0, "initial y");
  }
  const P& mass() const { return m; }
  const P& w2() const { return w2_; }
  const P& damping() const { return alpha; }
  const P& s() const { return s_; }
};
template <class P>
struct FoucaultT : FoucaultSymbols<P>, FoucaultDynamics<FoucaultT<P>>, PaperConstraint<FoucaultT<P>> {
  static constexpr const char* name = Foucault::name;
};
template <class P>
struct FoucaultRotationT : FoucaultSymbols<P>, FoucaultDynamics<FoucaultRotationT<P>>,
                           RotationConstraint<FoucaultRotationT<P>> {
  static constexpr const char* name = FoucaultRotation::name;
  // phi_0 = atan2(y0, x0), as a formula in the initial position's symbols
  P phi0() const { return atan2(this->y0, this->x0); }
};

// N steps of closed form C on system Sys (Foucault or FoucaultRotation) from the scene's initial data (q0, v0),
// in the scalar T: the observer is called for j = 0 .. N-1 with the step j -> j+1, so it sees every q_j,
// j = 0..N. phi_0 = atan2(y0, x0) in T (the rotation's plane at t = 0; for consistent data the exact plane passes
// through q_0).
template <class C, class Sys, class T, class Observer>
void run_closed_form(const Sys& sys, const FoucaultParams<T>& p, const Vec2<T>& q0, const Vec2<T>& v0, T h, long N,
                     FoucaultStart start, Observer&& observe) {
  using std::atan2;
  sys.template closed_steps<C>(p, C::previous_point(p, q0, v0, h, start), q0, 0, N, h, atan2(q0(1), q0(0)), observe);
}

template <class Self, class C, class R, class Observer>
void FoucaultPendulum::run_as_generic(const Self& self, R h, long N, Observer&& observe) {
  using Generic = typename C::solves;
  const FoucaultParams<R> p(self);
  const Vec<R, 2> q0 = self.template initial_position<R>(), v0 = self.template initial_velocity<R>();
  Vec<R, 2> pj = Generic::initial_momentum(self, R(0), q0, geomint::consistent_velocity<R>(p, q0, v0), R(0));
  R z = 0;
  Vec<R, 1> lambda = Vec<R, 1>::Zero();
  Vec<R, 2> qlast = q0;
  run_closed_form<C>(self, p, q0, v0, h, N, FoucaultStart::legendre, [&](const FoucaultStep<R>& st) {
    observe(generic::StepView<R, 2, 1>{st.j, st.t, st.q, pj, z, lambda});
    // the generic impulse: (15)'s lambda_1 for LA, h lambda_1 for contact ((18)'s rows are divided by h)
    lambda(0) = Generic::contact ? h * st.lambda1 : st.lambda1;
    if constexpr (Generic::contact) {
      const R zn = Generic::next_z(self, st.t, h, st.q, st.qn, z);
      pj = Generic::p_minus(self, st.t, h, st.q, st.qn, z, zn);
      z = zn;
    } else {
      pj = Generic::p_minus(self, st.t, h, st.q, st.qn);
    }
    qlast = st.qn;
  });
  observe(generic::StepView<R, 2, 1>{N, R(N) * h, qlast, pj, z, lambda});
}

template <class Self, class C, class R, class Observer>
void FoucaultPendulum::positions_of(const Self& self, R h, long N, Observer&& observe) {
  const FoucaultParams<R> p(self);
  const Vec<R, 2> q0 = self.template initial_position<R>(), v0 = self.template initial_velocity<R>();
  Vec<R, 2> qlast = q0;
  run_closed_form<C>(self, p, q0, v0, h, N, FoucaultStart::legendre, [&](const FoucaultStep<R>& st) {
    observe(st.j, st.t, st.q);
    qlast = st.qn;
  });
  observe(N, R(N) * h, qlast);
}

// Calls f(Foucault{}) or f(FoucaultRotation{}) for a system name, or for the name of its discretization of (13)
// ("paper", "rotation"); InputError naming them otherwise. For the typed code of the two systems (ensembles).
template <class F>
decltype(auto) visit_foucault_system(const std::string& name, F&& f) {
  if (name == Foucault::name || name == Foucault::discretization) return f(Foucault{});
  if (name == FoucaultRotation::name || name == FoucaultRotation::discretization) return f(FoucaultRotation{});
  throw InputError("unknown constraint discretization '" + name +
                   "' of the Foucault pendulum (known: paper = system foucault, rotation = system foucault-rotation)");
}

// The registry name of a Foucault system given by name or by its discretization, and its discretization's name.
inline std::string foucault_system_name(const std::string& name) {
  return visit_foucault_system(name, [](auto s) { return std::string(decltype(s)::name); });
}
inline std::string foucault_discretization(const std::string& name) {
  return visit_foucault_system(name, [](auto s) { return std::string(decltype(s)::discretization); });
}

}  // namespace systems
}  // namespace geomint
