#pragma once
// The damped Foucault pendulum of Section 3.2 as generic systems (the scene, closed-form steps, diagnostics
// and the closed-form solution live in geomint/foucault.hpp):
//   L = m/2 |q'|^2 - m w2/2 |q|^2 (14), Rayleigh force -alpha m q' (LA) or L - alpha z (16),
//   foucault:           the nonholonomic constraint (13), A(q) = (-y, x), b = s |q|^2, s = Omega sin beta;
//   foucault-rotation:  the remedy (see FoucaultConstraint): the rheonomic holonomic constraint
//                       g(t, q) = n(phi(t)).q = 0, phi(t) = phi_0 - s t, whose derivative is (13) on consistent
//                       data; A(t) = n(phi(t)) never vanishes, and the schemes impose g(t_{j+1}, q_{j+1}) = 0.
// The paper's integrators (15) and (18) (and the remedy's steps) are the closed-form fast paths of the generic
// `la` and `contact` schemes on these systems.
// Templated on the parameter type (Foucault = FoucaultT<double>): with a symbolic P the parameters are the
// combinations the equations use, m, w2 = g/l, alpha, s = Omega sin beta (and x0, y0 for the rotation's phi_0).
#include <cmath>

#include "geomint/foucault.hpp"
#include "geomint/generic/fast_path.hpp"
#include "geomint/generic/schemes.hpp"

namespace geomint::systems {

namespace detail {

// The parameters the equations read. double: the scene (foucault.hpp: physical parameters l, g, beta in degrees,
// Omega, and the initial data). A symbolic P: the combinations m, w2, alpha, s and the initial position, each a
// symbol of its own (the formulas then read as the README writes them, in s = Omega sin beta).
template <class P>
struct FoucaultParameters {
  P m_ = 0, w2_ = 0, alpha_ = 0, s_ = 0, x0_ = 0, y0_ = 0;
  template <class V>
  void visit(V&& v) {
    v("m", m_, "mass");
    v("w2", w2_, "g/l");
    v("alpha", alpha_, "Rayleigh damping");
    v("s", s_, "Omega sin(beta)");
    v("x0", x0_, "initial x");
    v("y0", y0_, "initial y");
  }
  const P& m() const { return m_; }
  const P& w2() const { return w2_; }
  const P& alpha() const { return alpha_; }
  const P& s() const { return s_; }
  const P& x0() const { return x0_; }
  const P& y0() const { return y0_; }
};
template <>
struct FoucaultParameters<double> {
  FoucaultScene scene;

  template <class V>
  void visit(V&& v) {
    v("m", scene.m, "mass (kg)");
    v("l", scene.l, "length (m)");
    v("g", scene.g, "gravity (m/s^2)");
    v("beta", scene.beta_deg, "latitude (degrees)");
    v("Omega", scene.Omega, "Earth's angular velocity (rad/s)");
    v("alpha", scene.alpha, "Rayleigh damping (1/s)");
    v("x0", scene.x0, "initial x (m)");
    v("y0", scene.y0, "initial y (m)");
    v("vx0", scene.vx0, "initial x' (m/s; projected onto (13))");
    v("vy0", scene.vy0, "initial y' (m/s; projected onto (13))");
    v("T", scene.T, "horizon (s)");
  }
  void validate() const { scene.validate(); }
  double m() const { return scene.m; }
  double w2() const { return scene.w2(); }
  double alpha() const { return scene.alpha; }
  double s() const { return scene.s(); }
  double x0() const { return scene.x0; }
  double y0() const { return scene.y0; }
  // The values of the symbolic instantiation's parameters (FoucaultParameters<P> above) at this scene.
  template <class V>
  void visit_symbols(V&& v) const {
    v("m", m());
    v("w2", w2());
    v("alpha", alpha());
    v("s", s());
    v("x0", x0());
    v("y0", y0());
  }
};

// Parameters, Lagrangian, force and references shared by both constraint discretizations.
template <class P>
struct FoucaultBase : FoucaultParameters<P> {
  static constexpr int dof = 2;
  static constexpr int constraints = 1;

  template <class S>
  S lagrangian(const S&, const Vec<S, 2>& q, const Vec<S, 2>& v) const {
    return this->m() / 2 * v.squaredNorm() - this->m() * this->w2() / 2 * q.squaredNorm();
  }
  template <class S>
  S herglotz(const S& t, const Vec<S, 2>& q, const Vec<S, 2>& v, const S& z) const {
    return lagrangian(t, q, v) - this->alpha() * z;
  }
  template <class S>
  Vec<S, 2> force(const S&, const Vec<S, 2>&, const Vec<S, 2>& v) const {
    return -(this->alpha() * this->m()) * v;
  }
  template <class S>
  Vec<S, 2> initial_position() const {
    return Vec<S, 2>(S(this->scene.x0), S(this->scene.y0));
  }
  template <class S>
  Vec<S, 2> initial_velocity() const {
    return Vec<S, 2>(S(this->scene.vx0), S(this->scene.vy0));
  }
  // The closed form (foucault_exact) from the consistent initial velocity.
  template <class S>
  Phase<S, 2> exact(const S& t) const {
    const FoucaultParams<S> p(this->scene);
    const Vec<S, 2> q0 = initial_position<S>();
    const auto x = foucault_exact<S>(p, q0, geomint::consistent_velocity<S>(p, q0, initial_velocity<S>()), t);
    return {x.q, x.v};
  }
  // The multiplier ODE by hand (as foucault_reference): lambda/m = [alpha (y x' - x y') + 2 s (x x' + y y')] / r^2.
  void rhs(double, const Vec<double, 2>& q, const Vec<double, 2>& v, Vec<double, 2>& a) const {
    const double x = q(0), y = q(1), r2 = x * x + y * y, w2 = this->scene.w2(), al = this->scene.alpha, s_ = this->s();
    const double lm = r2 > 0 ? (al * (y * v(0) - x * v(1)) + 2 * s_ * (x * v(0) + y * v(1))) / r2 : 0;
    a(0) = -w2 * x - al * v(0) + lm * y;
    a(1) = -w2 * y - al * v(1) - lm * x;
  }

 protected:
  // N steps of a closed form (LaNh or ContactNh) with the given constraint discretization, reported as the
  // generic scheme sees them: p_j is that scheme's discrete Legendre transform of (q_{j-1}, q_j), z_j its
  // action (the closed forms do not carry z), lambda the impulse of the step into q_j.
  template <class Self, class Closed, class T, class Observer>
  void run_closed(const Self& self, T h, long N, FoucaultConstraint constraint, Observer&& observe) const {
    using Generic = std::conditional_t<std::is_same_v<Closed, schemes::ContactNh>, generic::ContactLeft, generic::LaLeft>;
    const FoucaultParams<T> p(this->scene);
    const Vec<T, 2> q0 = initial_position<T>(), v0 = initial_velocity<T>();
    Vec<T, 2> pj = Generic::initial_momentum(self, T(0), q0, geomint::consistent_velocity<T>(p, q0, v0), T(0));
    T z = 0;
    Vec<T, 1> lambda = Vec<T, 1>::Zero();
    Vec<T, 2> qlast = q0;
    integrate_foucault<Closed>(p, q0, v0, h, N, FoucaultStart::legendre, [&](const FoucaultStep<T>& st) {
      observe(generic::StepView<T, 2, 1>{st.j, st.t, st.q, pj, z, lambda});
      // the generic impulse: (15)'s lambda_1 for LA, h lambda_1 for contact ((18)'s rows are divided by h)
      lambda(0) = Generic::contact ? h * st.lambda1 : st.lambda1;
      if constexpr (Generic::contact) {
        const T zn = Generic::next_z(self, st.t, h, st.q, st.qn, z);
        pj = Generic::p_minus(self, st.t, h, st.q, st.qn, z, zn);
        z = zn;
      } else {
        pj = Generic::p_minus(self, st.t, h, st.q, st.qn);
      }
      qlast = st.qn;
    }, constraint);
    observe(generic::StepView<T, 2, 1>{N, T(N) * h, qlast, pj, z, lambda});
  }
};

}  // namespace detail

template <class P = double>
struct FoucaultT : detail::FoucaultBase<P> {
  static constexpr const char* name = "foucault";
  static constexpr const char* description = "damped Foucault pendulum (Section 3.2) with the nonholonomic constraint (13)";

  template <class S>
  Mat<S, 1, 2> constraint_matrix(const S&, const Vec<S, 2>& q) const {
    return Mat<S, 1, 2>(-q(1), q(0));
  }
  template <class S>
  Vec<S, 1> constraint_offset(const S&, const Vec<S, 2>& q) const {
    return Vec<S, 1>::Constant(this->s() * q.squaredNorm());
  }

  using fast_paths = std::tuple<generic::FastPath<generic::LaLeft, schemes::LaNh>,
                                generic::FastPath<generic::ContactLeft, schemes::ContactNh>>;
  template <class Closed, class T, class Observer>
  void run_fast(T h, long N, Observer&& observe) const {
    this->template run_closed<FoucaultT, Closed>(*this, h, N, FoucaultConstraint::paper, observe);
  }
};
using Foucault = FoucaultT<>;

template <class P = double>
struct FoucaultRotationT : detail::FoucaultBase<P> {
  static constexpr const char* name = "foucault-rotation";
  static constexpr const char* description =
      "damped Foucault pendulum, constraint (13) as the exact rotation of the plane (the remedy for the anomaly)";
  // Not `linear`: each step is a linear solve, but its matrix turns with the plane (A = n(phi(t_j))), so a kept
  // Jacobian is stale — the linear lane's check caught this declaration (tests/system_pendulum.test.cpp).

  P phi0() const {
    using std::atan2;
    return atan2(this->y0(), this->x0());
  }
  template <class S>
  Mat<S, 1, 2> constraint_matrix(const S& t, const Vec<S, 2>&) const {
    using std::cos;
    using std::sin;
    const S phi = S(phi0()) - this->s() * t;
    return Mat<S, 1, 2>(-sin(phi), cos(phi));
  }
  template <class S>
  Vec<S, 1> constraint_offset(const S& t, const Vec<S, 2>& q) const {
    using std::cos;
    using std::sin;
    const S phi = S(phi0()) - this->s() * t;
    return Vec<S, 1>::Constant(this->s() * (cos(phi) * q(0) + sin(phi) * q(1)));
  }
  template <class S>
  Vec<S, 1> holonomic(const S& t, const Vec<S, 2>& q) const {
    using std::cos;
    using std::sin;
    const S phi = S(phi0()) - this->s() * t;
    return Vec<S, 1>::Constant(-sin(phi) * q(0) + cos(phi) * q(1));
  }

  using fast_paths = std::tuple<generic::FastPath<generic::LaLeft, schemes::LaNh>,
                                generic::FastPath<generic::ContactLeft, schemes::ContactNh>>;
  template <class Closed, class T, class Observer>
  void run_fast(T h, long N, Observer&& observe) const {
    this->template run_closed<FoucaultRotationT, Closed>(*this, h, N, FoucaultConstraint::rotation, observe);
  }
};
using FoucaultRotation = FoucaultRotationT<>;

}  // namespace geomint::systems
