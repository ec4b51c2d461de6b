#pragma once
// What a system is, for the generic core, and what the core derives from it by automatic differentiation.
//
// A system is one header under core/include/geomint/systems/ defining a struct with
//   static constexpr const char* name;        the name on command lines ("pendulum")
//   static constexpr const char* description;
//   static constexpr int dof;                 n, the dimension of q
//   static constexpr int constraints;         m, the number of linear nonholonomic constraints (0: none)
//   double fields (parameters, initial data, the default horizon T), listed by
//     template <class V> void visit(V&& v)    v("alpha", alpha, "Rayleigh damping") for each field
//   void validate() const;                    throws InputError naming the first bad field
//   template <class S> S lagrangian(const S& t, const Vec<S, n>& q, const Vec<S, n>& v) const;
//   template <class S> Vec<S, n> initial_position() const;  and  initial_velocity() const;
// and, where it has them (each is detected; absent means "not available"):
//   template <class S> S herglotz(const S& t, q, v, const S& z) const;     the Herglotz form L(t, q, q', z)
//   template <class S> Vec<S, n> force(const S& t, q, v) const;             an external force F(t, q, q')
//   template <class S> Mat<S, m, n> constraint_matrix(const S& t, q) const; A in Phi = A(t, q) q' + b(t, q)
//   template <class S> Vec<S, m> constraint_offset(const S& t, q) const;    b
//   template <class S> Vec<S, m> holonomic(const S& t, q) const;            g with Phi = dg/dt on g = 0: the
//                                      schemes then impose g(t_{j+1}, q_{j+1}) = 0 instead of Phi o Psi
//   template <class S> S energy(const S& t, q, v) const;                    default: q'.L_q' - L
//   template <class S> Phase<S, n> exact(const S& t) const;                 a closed-form solution (in absolute t)
//   bool has_exact_solution() const;         whether exact() is there for this instance (a system defined by
//                                            formulas has one only when its file gives one)
//   template <class S> S initial_time() const;   and  initial_action() const;   t0 and z0 of a run (default 0):
//                                            every run starts at t0 with z(t0) = z0, t_j = t0 + j h
//   void rhs(double t, const Vec<double, n>& q, const Vec<double, n>& v, Vec<double, n>& a) const;
//                                      a hand-written acceleration (the generic one is derived from L)
//   static constexpr bool linear = true;     L quadratic in (q, q') and F, Phi affine in them, with the
//                                            coefficients of q, q' constant in time (a time-dependent forcing
//                                            term is allowed): every step is the same linear solve, done with one
//                                            Newton update (checked at run time); without forcing, a linear map
//                                            (stability maps)
//   static constexpr bool linear_dynamics = true;  the same of L and F (with the Herglotz form L - alpha z), while A
//                                            and b may be any functions (a holonomic g must be affine in q): the
//                                            schemes that sample the constraint at the start of the step (la,
//                                            contact; with g, every scheme) then have rows affine in their
//                                            unknowns, and take one Newton update a step as a linear system does
//                                            (checked at run time the same way). `linear` implies it.
//   bool linear_dynamics_found() const;      the same, found at run time (a system defined by formulas examines
//                                            its own: formula/model.cpp)
#include <string>
#include <type_traits>
#include <utility>

#include <Eigen/Core>
#include <Eigen/LU>

#include "geomint/generic/dual.hpp"

namespace geomint {

template <class S, int N>
using Vec = Eigen::Matrix<S, N, 1>;
template <class S, int R, int C>
using Mat = Eigen::Matrix<S, R, C>;

// A point of the phase space (q, q').
template <class S, int N>
struct Phase {
  Vec<S, N> q, v;
};

namespace generic {

// ---------------------------------------------------------------------------------------------------
// Detection of the optional members

#define GEOMINT_DETECT(trait, expr)                                    \
  template <class Sys, class = void>                                   \
  struct trait : std::false_type {};                                   \
  template <class Sys>                                                 \
  struct trait<Sys, std::void_t<decltype(expr)>> : std::true_type {}; \
  template <class Sys>                                                 \
  inline constexpr bool trait##_v = trait<Sys>::value;

namespace detail {
template <class Sys>
using V = Vec<double, Sys::dof>;
}

GEOMINT_DETECT(has_herglotz, std::declval<const Sys&>().herglotz(0.0, detail::V<Sys>(), detail::V<Sys>(), 0.0))
GEOMINT_DETECT(has_force, std::declval<const Sys&>().force(0.0, detail::V<Sys>(), detail::V<Sys>()))
GEOMINT_DETECT(has_holonomic, std::declval<const Sys&>().holonomic(0.0, detail::V<Sys>()))
GEOMINT_DETECT(has_energy, std::declval<const Sys&>().energy(0.0, detail::V<Sys>(), detail::V<Sys>()))
GEOMINT_DETECT(has_exact, std::declval<const Sys&>().exact(0.0))
GEOMINT_DETECT(has_projection, std::declval<const Sys&>().project_velocity(0.0, detail::V<Sys>(), detail::V<Sys>()))
GEOMINT_DETECT(has_rhs, std::declval<const Sys&>().rhs(0.0, detail::V<Sys>(), detail::V<Sys>(),
                                                       std::declval<detail::V<Sys>&>()))
GEOMINT_DETECT(has_linear_flag, Sys::linear)
GEOMINT_DETECT(has_autonomous_flag, Sys::autonomous)
GEOMINT_DETECT(has_linear_dynamics_flag, Sys::linear_dynamics)
GEOMINT_DETECT(has_linear_dynamics_query, std::declval<const Sys&>().linear_dynamics_found())
GEOMINT_DETECT(has_exact_query, std::declval<const Sys&>().has_exact_solution())
GEOMINT_DETECT(has_initial_time, std::declval<const Sys&>().template initial_time<double>())
GEOMINT_DETECT(has_initial_action, std::declval<const Sys&>().template initial_action<double>())
#undef GEOMINT_DETECT

// A system's name for entries and messages. A header system's is static (Sys::name); a system defined by formulas
// is one type for many models, so its name is its instance's (sys.name()).
template <class Sys>
inline constexpr bool has_static_name_v = !std::is_member_function_pointer_v<decltype(&Sys::name)>;
template <class Sys>
std::string system_name(const Sys& sys) {
  if constexpr (has_static_name_v<Sys>) {
    (void)sys;
    return Sys::name;
  } else {
    return sys.name();
  }
}
template <class Sys>
std::string system_description(const Sys& sys) {
  if constexpr (has_static_name_v<Sys>) {
    (void)sys;
    return Sys::description;
  } else {
    return sys.description();
  }
}
// Where code knows the type only (a scheme looked up by name): " of system 'pendulum'" (or "for", ...), or "" for a
// type whose name is its instance's (a formula system's entry names it: formula_registry.cpp).
template <class Sys>
std::string of_system(const char* preposition = "of") {
  if constexpr (has_static_name_v<Sys>) {
    return std::string(" ") + preposition + " system '" + Sys::name + "'";
  } else {
    (void)preposition;
    return "";
  }
}

template <class Sys>
constexpr bool is_linear() {
  if constexpr (has_linear_flag_v<Sys>)
    return Sys::linear;
  else
    return false;
}

template <class Sys>
constexpr bool has_linear_dynamics() {
  if constexpr (has_linear_dynamics_flag_v<Sys>)
    return Sys::linear_dynamics || is_linear<Sys>();
  else
    return is_linear<Sys>();
}

// Linear dynamics as declared, or as found by a system that can tell at run time.
template <class Sys>
bool linear_dynamics_of(const Sys& sys) {
  if constexpr (has_linear_dynamics<Sys>())
    return true;
  else if constexpr (has_linear_dynamics_query_v<Sys>)
    return sys.linear_dynamics_found();
  else
    return false;
}

// A closed-form solution, where the system has one (at compile time, and for this instance at run time).
template <class Sys>
bool exact_available(const Sys& sys) {
  if constexpr (has_exact_query_v<Sys>)
    return sys.has_exact_solution();
  else {
    (void)sys;
    return has_exact_v<Sys>;
  }
}

// The start of every run, t0 and z(t0) = z0: the system's, or 0 (every header system starts at t = 0, z = 0).
template <class S = double, class Sys>
S initial_time(const Sys& sys) {
  if constexpr (has_initial_time_v<Sys>)
    return sys.template initial_time<S>();
  else {
    (void)sys;
    return S(0);
  }
}
template <class S = double, class Sys>
S initial_action(const Sys& sys) {
  if constexpr (has_initial_action_v<Sys>)
    return sys.template initial_action<S>();
  else {
    (void)sys;
    return S(0);
  }
}

// A system that declares `static constexpr bool autonomous = true` has no explicit time in L, F, Phi (and no
// holonomic constraint g(t, q)). With `linear`, its step is then one fixed affine map (checked like linear).
template <class Sys>
constexpr bool is_autonomous() {
  if constexpr (has_autonomous_flag_v<Sys>)
    return Sys::autonomous;
  else
    return false;
}

// ---------------------------------------------------------------------------------------------------
// The continuous objects, as the schemes use them (scalar S: double, long double, duals, series)

template <class Sys, class S>
Vec<S, Sys::dof> force(const Sys& sys, const S& t, const Vec<S, Sys::dof>& q, const Vec<S, Sys::dof>& v) {
  if constexpr (has_force_v<Sys>)
    return sys.force(t, q, v);
  else
    return Vec<S, Sys::dof>::Zero();
}

// Phi(t, q, v) = A(t, q) v + b(t, q).
template <class Sys, class S>
Vec<S, Sys::constraints> constraint(const Sys& sys, const S& t, const Vec<S, Sys::dof>& q, const Vec<S, Sys::dof>& v) {
  return sys.constraint_matrix(t, q) * v + sys.constraint_offset(t, q);
}

// The gradient of f: R^n -> scalar at x, with f templated on the scalar (one forward pass per call,
// n directions at once).
template <int N, class T, class F>
Vec<T, N> gradient(const F& f, const Vec<T, N>& x, T* value = nullptr) {
  using D = Dual<T, N>;
  Vec<D, N> X;
  for (int i = 0; i < N; ++i) X(i) = D::variable(x(i), i);
  const D y = f(X);
  if (value) *value = y.v;
  Vec<T, N> g;
  for (int i = 0; i < N; ++i) g(i) = y.d[static_cast<std::size_t>(i)];
  return g;
}

// p = dL/dq' (the continuous Legendre transform), LA form.
template <class Sys, class T>
Vec<T, Sys::dof> momentum(const Sys& sys, const T& t, const Vec<T, Sys::dof>& q, const Vec<T, Sys::dof>& v) {
  constexpr int n = Sys::dof;
  return gradient<n, T>(
      [&](const auto& V) {
        using D = typename std::decay_t<decltype(V)>::Scalar;
        return sys.lagrangian(D(t), Vec<D, n>(q.template cast<D>()), V);
      },
      v);
}

// p = dL/dq' of the Herglotz form at (t, q, v, z).
template <class Sys, class T>
Vec<T, Sys::dof> herglotz_momentum(const Sys& sys, const T& t, const Vec<T, Sys::dof>& q, const Vec<T, Sys::dof>& v,
                                   const T& z) {
  constexpr int n = Sys::dof;
  return gradient<n, T>(
      [&](const auto& V) {
        using D = typename std::decay_t<decltype(V)>::Scalar;
        return sys.herglotz(D(t), Vec<D, n>(q.template cast<D>()), V, D(z));
      },
      v);
}

// The energy: the system's own, or the Lagrangian energy q'.L_q' - L.
template <class Sys, class T>
T energy(const Sys& sys, const T& t, const Vec<T, Sys::dof>& q, const Vec<T, Sys::dof>& v) {
  if constexpr (has_energy_v<Sys>)
    return sys.energy(t, q, v);
  else
    return momentum(sys, t, q, v).dot(v) - sys.lagrangian(t, q, v);
}

// The velocity closest to v (in the kinetic metric M = L_q'q') that satisfies the constraints at (t, q):
// v - M^{-1} A^T (A M^{-1} A^T)^{-1} Phi(t, q, v). The identity for unconstrained systems. For a
// holonomic constraint g the position is not touched: the initial position must satisfy g = 0.
template <class Sys, class T>
Vec<T, Sys::dof> consistent_velocity(const Sys& sys, const T& t, const Vec<T, Sys::dof>& q, const Vec<T, Sys::dof>& v);

// The start of a system's hand-written equations (its `rhs`): the projection it writes in closed form
// (`project_velocity(t, q, v)`; the Foucault pendulum's, which the paper's code starts its multiplier ODE from),
// else consistent_velocity. The two agree to round-off. The generic step and the equations derived from L start from
// consistent_velocity alone, so that a system written as formulas steps to its header's bits.
template <class Sys>
Vec<double, Sys::dof> hand_written_velocity(const Sys& sys, double t, const Vec<double, Sys::dof>& q,
                                            const Vec<double, Sys::dof>& v) {
  if constexpr (has_projection_v<Sys>)
    return sys.project_velocity(t, q, v);
  else
    return consistent_velocity(sys, t, q, v);
}

// The continuous equations of motion, derived from L, F and Phi by nested forward-mode AD:
//   Lagrange–d'Alembert:  M a = L_q - L_q'q q' - L_q't + F + A^T lambda,  M = L_q'q',
//   with A a = -(d/dt of A) q' - db/dt from differentiating Phi = 0 along the motion.
// Returns the acceleration and the multipliers.
template <class Sys>
struct Acceleration {
  Vec<double, Sys::dof> a;
  Vec<double, Sys::constraints> lambda;
};
template <class Sys>
Acceleration<Sys> acceleration(const Sys& sys, double t, const Vec<double, Sys::dof>& q, const Vec<double, Sys::dof>& v);

// The Herglotz equations (2) with constraints (de León–Jiménez–Lainz): with L(t, q, q', z),
//   M a = L_q - L_q'q q' - L_q't - L_q'z L + L_q' L_z + A^T lambda,  z' = L.
template <class Sys>
Acceleration<Sys> herglotz_acceleration(const Sys& sys, double t, const Vec<double, Sys::dof>& q,
                                        const Vec<double, Sys::dof>& v, double z);

// ---------------------------------------------------------------------------------------------------
// Implementations

template <class Sys, class T>
Vec<T, Sys::dof> consistent_velocity(const Sys& sys, const T& t, const Vec<T, Sys::dof>& q, const Vec<T, Sys::dof>& v) {
  constexpr int n = Sys::dof, m = Sys::constraints;
  if constexpr (m == 0) {
    (void)sys;
    (void)t;
    (void)q;
    return v;
  } else {
    // M = L_q'q' by differentiating the momentum
    using D = Dual<T, n>;
    Vec<D, n> V;
    for (int i = 0; i < n; ++i) V(i) = D::variable(v(i), i);
    const Vec<D, n> p = momentum<Sys, D>(sys, D(t), Vec<D, n>(q.template cast<D>()), V);
    Mat<T, n, n> M;
    for (int i = 0; i < n; ++i)
      for (int k = 0; k < n; ++k) M(i, k) = p(i).d[static_cast<std::size_t>(k)];
    const Mat<T, m, n> A = sys.constraint_matrix(t, q);
    const Vec<T, m> phi = A * v + sys.constraint_offset(t, q);
    const Mat<T, n, m> MiAt = Eigen::PartialPivLU<Mat<T, n, n>>(M).solve(A.transpose());
    const Mat<T, m, m> S = A * MiAt;
    return v - MiAt * Eigen::PartialPivLU<Mat<T, m, m>>(S).solve(phi);
  }
}

namespace detail {

// Value, gradient and Hessian of f(t, q, v[, z]) packed as x = (t, q, v[, z]), by Dual<Dual<double, N>, N>.
template <int N>
struct Hessian {
  double value;
  Vec<double, N> grad;
  Mat<double, N, N> hess;
};
template <int N, class F>
Hessian<N> hessian(const F& f, const Vec<double, N>& x) {
  using In = Dual<double, N>;
  using Out = Dual<In, N>;
  Vec<Out, N> X;
  for (int i = 0; i < N; ++i) {
    X(i) = Out::variable(In::variable(x(i), i), i);
  }
  const Out y = f(X);
  Hessian<N> h;
  h.value = y.v.v;
  for (int i = 0; i < N; ++i) {
    h.grad(i) = y.v.d[static_cast<std::size_t>(i)];
    for (int k = 0; k < N; ++k) h.hess(i, k) = y.d[static_cast<std::size_t>(i)].d[static_cast<std::size_t>(k)];
  }
  return h;
}

// Solves M a - A^T lambda = f, A a = c (the constrained acceleration) for a and lambda.
template <int n, int m>
void solve_kkt(const Mat<double, n, n>& M, const Mat<double, m, n>& A, const Vec<double, n>& f,
               const Vec<double, m>& c, Vec<double, n>& a, Vec<double, m>& lambda) {
  if constexpr (m == 0) {
    (void)A;
    (void)c;
    (void)lambda;
    a = Eigen::PartialPivLU<Mat<double, n, n>>(M).solve(f);
  } else {
    Mat<double, n + m, n + m> K = Mat<double, n + m, n + m>::Zero();
    K.template topLeftCorner<n, n>() = M;
    K.template topRightCorner<n, m>() = -A.transpose();
    K.template bottomLeftCorner<m, n>() = A;
    Vec<double, n + m> r;
    r << f, c;
    const Vec<double, n + m> x = Eigen::PartialPivLU<Mat<double, n + m, n + m>>(K).solve(r);
    a = x.template head<n>();
    lambda = x.template tail<m>();
  }
}

// The right-hand side c of A a = c: minus the time derivative of Phi(t, q(t), v) at fixed v, along q' = v.
template <class Sys>
Vec<double, Sys::constraints> constraint_drift(const Sys& sys, double t, const Vec<double, Sys::dof>& q,
                                               const Vec<double, Sys::dof>& v) {
  constexpr int n = Sys::dof, m = Sys::constraints;
  // d/ds Phi(t + s, q + s v, v) at s = 0 (one direction)
  using D = Dual<double, 1>;
  const D s = D::variable(0.0, 0);
  Vec<D, n> Q;
  for (int i = 0; i < n; ++i) Q(i) = D(q(i)) + s * v(i);
  const Vec<D, m> phi = constraint<Sys, D>(sys, D(t) + s, Q, Vec<D, n>(v.template cast<D>()));
  Vec<double, m> c;
  for (int i = 0; i < m; ++i) c(i) = -phi(i).d[0];
  return c;
}

// M a = f + A^T lambda on the constraints (differentiated along the motion), or M a = f without any.
template <class Sys>
Acceleration<Sys> constrained_acceleration(const Sys& sys, double t, const Vec<double, Sys::dof>& q,
                                           const Vec<double, Sys::dof>& v, const Mat<double, Sys::dof, Sys::dof>& M,
                                           const Vec<double, Sys::dof>& f) {
  constexpr int n = Sys::dof, m = Sys::constraints;
  Acceleration<Sys> out;
  if constexpr (m == 0) {
    solve_kkt<n, 0>(M, Mat<double, 0, n>(), f, Vec<double, 0>(), out.a, out.lambda);
  } else {
    solve_kkt<n, m>(M, sys.constraint_matrix(t, q), f, constraint_drift(sys, t, q, v), out.a, out.lambda);
  }
  return out;
}

}  // namespace detail

template <class Sys>
Acceleration<Sys> acceleration(const Sys& sys, double t, const Vec<double, Sys::dof>& q, const Vec<double, Sys::dof>& v) {
  constexpr int n = Sys::dof, N = 2 * n + 1;
  Vec<double, N> x;
  x << t, q, v;
  const auto H = detail::hessian<N>(
      [&](const auto& X) {
        using D = typename std::decay_t<decltype(X)>::Scalar;
        return sys.lagrangian(X(0), Vec<D, n>(X.template segment<n>(1)), Vec<D, n>(X.template segment<n>(1 + n)));
      },
      x);
  const Mat<double, n, n> M = H.hess.template block<n, n>(1 + n, 1 + n);
  const Vec<double, n> Lq = H.grad.template segment<n>(1);
  const Vec<double, n> f = Lq - H.hess.template block<n, n>(1 + n, 1) * v - H.hess.template block<n, 1>(1 + n, 0) +
                           force<Sys, double>(sys, t, q, v);
  return detail::constrained_acceleration(sys, t, q, v, M, f);
}

template <class Sys>
Acceleration<Sys> herglotz_acceleration(const Sys& sys, double t, const Vec<double, Sys::dof>& q,
                                        const Vec<double, Sys::dof>& v, double z) {
  constexpr int n = Sys::dof, N = 2 * n + 2;
  Vec<double, N> x;
  x << t, q, v, z;
  const auto H = detail::hessian<N>(
      [&](const auto& X) {
        using D = typename std::decay_t<decltype(X)>::Scalar;
        return sys.herglotz(X(0), Vec<D, n>(X.template segment<n>(1)), Vec<D, n>(X.template segment<n>(1 + n)),
                            X(N - 1));
      },
      x);
  const double L = H.value, Lz = H.grad(N - 1);
  const Mat<double, n, n> M = H.hess.template block<n, n>(1 + n, 1 + n);
  const Vec<double, n> Lq = H.grad.template segment<n>(1), Lv = H.grad.template segment<n>(1 + n);
  // d/dt L_v = L_vt + L_vq q' + L_vv a + L_vz z',  z' = L
  const Vec<double, n> f = Lq - H.hess.template block<n, n>(1 + n, 1) * v - H.hess.template block<n, 1>(1 + n, 0) -
                           H.hess.template block<n, 1>(1 + n, N - 1) * L + Lv * Lz;
  return detail::constrained_acceleration(sys, t, q, v, M, f);
}

}  // namespace generic
}  // namespace geomint
