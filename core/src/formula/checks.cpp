#include "geomint/formula/checks.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include <Eigen/Dense>
#include <boost/numeric/odeint/stepper/runge_kutta4.hpp>

#include "geomint/error.hpp"
#include "geomint/formula/time_transform.hpp"

namespace geomint::formula {

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

std::string show_vec(const VectorXd& x) {
  std::string s = "(";
  for (Eigen::Index i = 0; i < x.size(); ++i) s += (i ? ", " : "") + show(x(i));
  return s + ")";
}

// The smallest singular value is below `rel` times the largest (or the largest is not positive, or not finite).
bool singular(const MatrixXd& A, double rel, double& smin, double& smax) {
  if (!A.allFinite()) {
    smin = smax = missing_value;
    return true;
  }
  const Eigen::JacobiSVD<MatrixXd> svd(A);
  const VectorXd& s = svd.singularValues();
  smax = s(0);
  smin = s(s.size() - 1);
  return !(smax > 0) || !(smin > rel * smax);
}

// A model's formulas at given parameter values, evaluated at run-time dimensions through Tape::eval_duals.
class Formulas {
 public:
  Formulas(const FormulaModel& model, const std::vector<double>& pv) : m_(model), pv_(pv), n(model.n), m(model.m) {
    require(static_cast<int>(pv.size()) == model.table_size(), "formula system: parameter table of the wrong size");
  }
  const FormulaModel& model() const { return m_; }

  // The outputs of a state tape at (t, q, v, z).
  std::vector<double> values(const Tape& tape, double t, const VectorXd& q, const VectorXd& v, double z) const {
    std::vector<double> x = pack(t, q, v, z);
    std::vector<const double*> in(x.size());
    for (std::size_t i = 0; i < x.size(); ++i) in[i] = &x[i];
    std::vector<double> out(tape.size());
    tape.eval_duals<double, 0>(nullptr, in.data(), pv_.data(), out.data());
    return out;
  }
  // The outputs of a constant tape (inputs: the numbers and the parameters).
  std::vector<double> constants(const Tape& tape) const {
    std::vector<const double*> in(static_cast<std::size_t>(m_.derived_offset()));
    for (std::size_t i = 0; i < in.size(); ++i) in[i] = &pv_[i];
    std::vector<double> out(tape.size());
    tape.eval_duals<double, 0>(nullptr, in.data(), pv_.data(), out.data());
    return out;
  }

  // Value, gradient and Hessian of a one-output tape over x = (t, q, v[, z]), by nested duals with N directions
  // at both levels (as generic::detail::hessian: variable i is Dual(Dual(x_i, e_i), e_i)).
  struct Second {
    double value = 0;
    VectorXd grad;
    MatrixXd hess;
  };
  Second second(const Tape& tape, double t, const VectorXd& q, const VectorXd& v, double z, bool with_z) const {
    const int N = 2 * n + 1 + (with_z ? 1 : 0), w = N + 1, block = w * w;
    const std::vector<double> x = pack(t, q, v, z);
    std::vector<double> X(static_cast<std::size_t>(block * (2 * n + 2)), 0.0);
    std::vector<const double*> in(static_cast<std::size_t>(2 * n + 2));
    for (int j = 0; j < 2 * n + 2; ++j) {
      double* b = X.data() + j * block;
      b[0] = x[static_cast<std::size_t>(j)];
      if (j < N) {
        b[1 + j] = 1;      // the value's inner derivative
        b[(1 + j) * w] = 1;  // the outer derivative's value
      }
      in[static_cast<std::size_t>(j)] = b;
    }
    std::vector<double> y(static_cast<std::size_t>(block));
    const int dirs[2] = {N, N};
    tape.eval_duals<double, 2>(dirs, in.data(), pv_.data(), y.data());
    Second s;
    s.value = y[0];
    s.grad.resize(N);
    s.hess.resize(N, N);
    for (int i = 0; i < N; ++i) {
      s.grad(i) = y[static_cast<std::size_t>(1 + i)];
      for (int k = 0; k < N; ++k) s.hess(i, k) = y[static_cast<std::size_t>((1 + i) * w + 1 + k)];
    }
    return s;
  }

  // d/ds of a state tape's outputs at (t + s, q + s v, v, z), s = 0.
  std::vector<double> along(const Tape& tape, double t, const VectorXd& q, const VectorXd& v) const {
    std::vector<double> X(static_cast<std::size_t>(2 * (2 * n + 2)), 0.0);
    std::vector<const double*> in(static_cast<std::size_t>(2 * n + 2));
    X[0] = t;
    X[1] = 1;
    for (int i = 0; i < n; ++i) {
      X[static_cast<std::size_t>(2 * (1 + i))] = q(i);
      X[static_cast<std::size_t>(2 * (1 + i) + 1)] = v(i);
      X[static_cast<std::size_t>(2 * (1 + n + i))] = v(i);
    }
    for (int j = 0; j < 2 * n + 2; ++j) in[static_cast<std::size_t>(j)] = X.data() + 2 * j;
    std::vector<double> y(2 * tape.size());
    const int dirs[1] = {1};
    tape.eval_duals<double, 1>(dirs, in.data(), pv_.data(), y.data());
    std::vector<double> d(tape.size());
    for (std::size_t k = 0; k < d.size(); ++k) d[k] = y[2 * k + 1];
    return d;
  }

  MatrixXd constraint_matrix(double t, const VectorXd& q) const {
    const std::vector<double> a = values(m_.constraint_matrix, t, q, VectorXd::Zero(n), 0);
    return Eigen::Map<const MatrixXd>(a.data(), m, n);  // column-major, as the tape
  }
  VectorXd constraint_offset(double t, const VectorXd& q) const {
    const std::vector<double> b = values(m_.constraint_offset, t, q, VectorXd::Zero(n), 0);
    return Eigen::Map<const VectorXd>(b.data(), m);
  }
  VectorXd force(double t, const VectorXd& q, const VectorXd& v) const {
    if (!m_.has_force()) return VectorXd::Zero(n);
    const std::vector<double> f = values(m_.force, t, q, v, 0);
    return Eigen::Map<const VectorXd>(f.data(), n);
  }

  // The continuous equations (generic/system.hpp): M a = f + A^T lambda with A a = -d/dt Phi along the motion.
  ContinuousAcceleration acceleration(double t, const VectorXd& q, const VectorXd& v, double z, bool herglotz) const {
    const Second H = herglotz ? second(m_.herglotz, t, q, v, z, true) : second(m_.lagrangian, t, q, v, 0, false);
    const MatrixXd M = H.hess.block(1 + n, 1 + n, n, n);
    VectorXd f = H.grad.segment(1, n) - H.hess.block(1 + n, 1, n, n) * v - H.hess.block(1 + n, 0, n, 1);
    if (herglotz) {
      const int iz = 2 * n + 1;
      f += -H.hess.block(1 + n, iz, n, 1) * H.value + H.grad.segment(1 + n, n) * H.grad(iz);
    } else {
      f += force(t, q, v);
    }
    ContinuousAcceleration out;
    VectorXd a, lambda;
    if (m == 0) {
      a = Eigen::PartialPivLU<MatrixXd>(M).solve(f);
    } else {
      const MatrixXd A = constraint_matrix(t, q);
      const std::vector<double> dA = along(m_.constraint_matrix, t, q, v), db = along(m_.constraint_offset, t, q, v);
      VectorXd c(m);
      for (int r = 0; r < m; ++r) {
        double s = db[static_cast<std::size_t>(r)];
        for (int k = 0; k < n; ++k) s += dA[static_cast<std::size_t>(k * m + r)] * v(k);
        c(r) = -s;
      }
      MatrixXd K = MatrixXd::Zero(n + m, n + m);
      K.topLeftCorner(n, n) = M;
      K.topRightCorner(n, m) = -A.transpose();
      K.bottomLeftCorner(m, n) = A;
      VectorXd rhs(n + m);
      rhs << f, c;
      const VectorXd x = Eigen::PartialPivLU<MatrixXd>(K).solve(rhs);
      a = x.head(n);
      lambda = x.tail(m);
    }
    out.a.assign(a.data(), a.data() + n);
    out.lambda.assign(lambda.data(), lambda.data() + lambda.size());
    return out;
  }

  // The velocity closest to v (kinetic metric) that satisfies the constraints (generic::consistent_velocity).
  VectorXd consistent_velocity(double t, const VectorXd& q, const VectorXd& v) const {
    if (m == 0) return v;
    const MatrixXd M = second(m_.lagrangian, t, q, v, 0, false).hess.block(1 + n, 1 + n, n, n);
    const MatrixXd A = constraint_matrix(t, q);
    const VectorXd phi = A * v + constraint_offset(t, q);
    const MatrixXd MiAt = Eigen::PartialPivLU<MatrixXd>(M).solve(A.transpose());
    return v - MiAt * Eigen::PartialPivLU<MatrixXd>(A * MiAt).solve(phi);
  }

  const std::vector<double>& pv() const { return pv_; }

 private:
  std::vector<double> pack(double t, const VectorXd& q, const VectorXd& v, double z) const {
    std::vector<double> x(static_cast<std::size_t>(2 * n + 2));
    x[0] = t;
    for (int i = 0; i < n; ++i) {
      x[static_cast<std::size_t>(1 + i)] = q(i);
      x[static_cast<std::size_t>(1 + n + i)] = v(i);
    }
    x[static_cast<std::size_t>(2 * n + 1)] = z;
    return x;
  }

  const FormulaModel& m_;
  const std::vector<double>& pv_;

 public:
  const int n, m;
};

}  // namespace

// The parameter table of a time-transformed model's physical model (its numbers, the parameters it shares with
// the extended model, its derived values).
std::vector<double> physical_table(const FormulaModel& M, const std::vector<double>& pv) {
  const FormulaModel& P = *M.physical;
  std::vector<double> out(P.numbers);
  for (const auto& p : P.parameters)
    out.push_back(pv[static_cast<std::size_t>(M.parameter_offset() + M.parameter_index(p.name))]);
  return with_derived_values(P, std::move(out));
}

void validate_model(const FormulaModel& M, const std::vector<double>& pv) {
  if (M.time_transformed) {
    // The physical system's refusals first, in its own terms; then the monitor at the initial data.
    validate_model(*M.physical, physical_table(M, pv));
    const Formulas F(M, pv);
    const std::vector<double> x0 = F.constants(M.initial);
    const double g0 = x0[static_cast<std::size_t>(2 * M.n - 1)];
    const int ik = M.parameter_index(time_transform_kappa);
    const double kappa = pv[static_cast<std::size_t>(M.parameter_offset() + ik)];
    require(std::isfinite(g0) && g0 > 0, M.time_transform_at.place() + ": time_transform: the monitor g = dt/dsigma is " +
                                             show(g0) + " at the initial data: it must be positive (time runs forward)");
    require(std::isfinite(kappa) && kappa > 0, M.parameters[static_cast<std::size_t>(ik)].where.place() + ": " +
                                                   time_transform_kappa + " must be positive, got " + show(kappa));
  }
  const Formulas F(M, pv);
  const int n = M.n, o = M.parameter_offset();
  // Each refusal names the system and where the parameter is declared: the value may come from the file or from a
  // command line, and the user needs to find which.
  for (std::size_t i = 0; i < M.parameters.size(); ++i) {
    const double x = pv[static_cast<std::size_t>(o) + i];
    require(std::isfinite(x), "system '" + M.name + "' (" + M.parameters[i].where.place() + "): parameter " +
                                  M.parameters[i].name + " must be finite, got " + show(x));
  }
  {
    const int iT = M.parameter_index("T");
    const double T = pv[static_cast<std::size_t>(o + iT)];
    require(T > 0, "system '" + M.name + "' (" + M.parameters[static_cast<std::size_t>(iT)].where.place() +
                       "): T must be a positive finite number, got " + show(T));
  }
  // named definitions of parameters first (the clearest message), then every constant part of a formula
  const std::vector<double> defs = F.constants(M.definitions);
  for (std::size_t i = 0; i < defs.size(); ++i)
    require(std::isfinite(defs[i]), M.definition_names[i].where.place() + ": definition " + M.definition_names[i].name +
                                        " is not finite at these parameters (" + show(defs[i]) + ")");
  for (std::size_t k = 0; k < M.prelude.size(); ++k) {
    const double x = pv[static_cast<std::size_t>(M.derived_offset()) + k];
    require(std::isfinite(x), M.derived_origin[k] + ": a part of it that depends on the parameters only is not finite (" +
                                  show(x) + ")");
  }
  const std::vector<double> x0 = F.constants(M.initial);
  for (int i = 0; i < 2 * n; ++i)
    require(std::isfinite(x0[static_cast<std::size_t>(i)]),
            M.initial_at[static_cast<std::size_t>(i)].place() + ": initial " + (i < n ? "q" : "v") + std::to_string(i % n + 1) +
                " is not finite (" + show(x0[static_cast<std::size_t>(i)]) + ")");
  const VectorXd q0 = Eigen::Map<const VectorXd>(x0.data(), n), v0 = Eigen::Map<const VectorXd>(x0.data() + n, n);
  const std::vector<double> start = F.constants(M.start);
  const double t0 = start[0];
  require(std::isfinite(t0), M.start_at.place() + ": initial t0 is not finite (" + show(t0) + ")");
  require(std::isfinite(start[1]), M.start_at.place() + ": initial z0 is not finite (" + show(start[1]) + ")");
  if (M.m > 0) {
    const MatrixXd A = F.constraint_matrix(t0, q0);
    double smin = 0, smax = 0;
    if (singular(A, 1e-12, smin, smax))
      throw InputError(M.constraint_at[0].place() + ": the constraint rows are " + (M.m == 1 ? "zero" : "linearly dependent") +
                       " at the initial position q0 = " + show_vec(q0) + " (singular values " + show(smax) +
                       (M.m > 1 ? ", " + show(smin) : "") + "): no constraint force is defined there");
    if (M.holonomic) {
      const std::vector<double> g = F.values(M.holonomic_g, t0, q0, v0, 0);
      for (int r = 0; r < M.m; ++r) {
        // the size of g's terms at q0, to judge its round-off
        double scale = 1;
        for (int k = 0; k < n; ++k) scale += std::abs(A(r, k) * q0(k));
        require(std::abs(g[static_cast<std::size_t>(r)]) <= 1e-10 * scale,
                M.constraint_at[static_cast<std::size_t>(r)].place() + ": the initial position q0 = " + show_vec(q0) +
                    " is off the holonomic constraint: g" + std::to_string(r + 1) + "(t0, q0) = " + show(g[static_cast<std::size_t>(r)]));
      }
    }
  }
  // The Legendre transform: the velocity Hessian at the initial data must be invertible.
  for (bool contact : {false, true}) {
    if (contact && !M.has_herglotz()) continue;
    const auto H = contact ? F.second(M.herglotz, t0, q0, v0, 0, true) : F.second(M.lagrangian, t0, q0, v0, 0, false);
    // A value that is not finite (sqrt of a negative q0) is named as such, not as a singular Hessian.
    const std::string which = contact ? "the Herglotz Lagrangian" : "L";
    const std::string place = (contact ? M.herglotz_at : M.lagrangian_at).place();
    const std::string at_start = " at the initial data (q0 = " + show_vec(q0) + ", v0 = " + show_vec(v0) + ")";
    if (!std::isfinite(H.value))
      throw InputError(place + ": " + which + " is not finite" + at_start + ": " + which + " = " + show(H.value));
    if (!H.grad.allFinite() || !H.hess.allFinite())
      throw InputError(place + ": the derivatives of " + which + " are not finite" + at_start +
                       " (a square root or logarithm at 0, a division by 0?)");
    const MatrixXd Mv = H.hess.block(1 + n, 1 + n, n, n);
    double smin = 0, smax = 0;
    if (singular(Mv, 1e-12, smin, smax))
      throw InputError((contact ? M.herglotz_at : M.lagrangian_at).place() + ": the velocity Hessian of " +
                       (contact ? "the Herglotz Lagrangian" : "L") + " is singular at the initial data (q0 = " + show_vec(q0) +
                       ", v0 = " + show_vec(v0) + ", singular values " + show(smax) + (n > 1 ? " ... " + show(smin) : "") +
                       "): no Legendre transform, the schemes cannot step");
  }
  if (M.has_energy()) {
    const double E = F.values(M.energy, t0, q0, v0, 0)[0];
    require(std::isfinite(E), M.origin.place() + ": the energy E is not finite at the initial data (q0 = " + show_vec(q0) +
                                  ", v0 = " + show_vec(v0) + "): E = " + show(E));
  }
  if (M.strict_herglotz && M.has_herglotz()) {
    const std::string why = herglotz_mismatch(M, pv);
    if (!why.empty()) throw InputError(why);
  }
  if (M.has_exact()) {
    const std::string why = exact_mismatch(M, pv);
    if (!why.empty()) throw InputError(why);
  }
}

// The exact solution against the system: its start against the initial data at t0, and at 17 times evenly over
// [t0, t0 + T] its q'' against the Lagrange-d'Alembert equations at its (t, q, q') and its q' against the
// constraints. Both sides are exact to round-off (the derivatives of the formulas are taken symbolically, those of L
// by automatic differentiation), so a true solution leaves a residual of the order of eps times the size of the terms
// (and the conditioning of the velocity Hessian); a wrong one -- a misprinted coefficient, sign or phase -- leaves
// one of the order of the terms. The bound, 1e-8 of the largest |q|, |q'|, |q''| seen (of the exact solution and of
// the equations), keeps eight digits for conditioning and still refuses a constant wrong in its eighth digit.
std::string exact_mismatch(const FormulaModel& M, const std::vector<double>& pv) {
  if (!M.has_exact()) return "";
  const Formulas F(M, pv);
  const int n = M.n;
  const double T = pv[static_cast<std::size_t>(M.parameter_offset() + M.parameter_index("T"))];
  const double t0 = F.constants(M.start)[0];
  const std::vector<double> x0 = F.constants(M.initial);
  const VectorXd q0 = Eigen::Map<const VectorXd>(x0.data(), n);
  const VectorXd v0 = F.consistent_velocity(t0, q0, Eigen::Map<const VectorXd>(x0.data() + n, n));
  constexpr int samples = 16;
  constexpr double rel = 1e-8;
  struct Sample {
    double t;
    VectorXd q, v, a, aL, phi;
  };
  std::vector<Sample> at;
  double scale = std::max(q0.lpNorm<Eigen::Infinity>(), v0.lpNorm<Eigen::Infinity>());
  const VectorXd none = VectorXd::Zero(n);
  for (int k = 0; k <= samples; ++k) {
    Sample s;
    s.t = k == samples ? t0 + T : t0 + T * k / samples;
    const std::vector<double> x = F.values(M.exact, s.t, none, none, 0);
    s.q = Eigen::Map<const VectorXd>(x.data(), n);
    s.v = Eigen::Map<const VectorXd>(x.data() + n, n);
    s.a = Eigen::Map<const VectorXd>(x.data() + 2 * n, n);
    if (!s.q.allFinite() || !s.v.allFinite() || !s.a.allFinite())
      return M.exact_at[0].place() + ": the exact solution (or its derivatives) is not finite at t = " + show(s.t) +
             " (q = " + show_vec(s.q) + ", q' = " + show_vec(s.v) + "): it must hold on [t0, t0 + T] = [" + show(t0) + ", " +
             show(t0 + T) + "]";
    const ContinuousAcceleration l = F.acceleration(s.t, s.q, s.v, 0, false);
    s.aL = Eigen::Map<const VectorXd>(l.a.data(), n);
    s.phi = M.m > 0 ? VectorXd(F.constraint_matrix(s.t, s.q) * s.v + F.constraint_offset(s.t, s.q)) : VectorXd();
    scale = std::max({scale, s.q.lpNorm<Eigen::Infinity>(), s.v.lpNorm<Eigen::Infinity>(), s.a.lpNorm<Eigen::Infinity>(),
                      s.aL.allFinite() ? s.aL.lpNorm<Eigen::Infinity>() : 0.0});
    at.push_back(s);
  }
  const double tol = rel * scale;
  const std::string bound = " (allowed: " + show(tol) + ", 1e-8 of the largest |q|, |q'|, |q''| seen)";
  for (int i = 0; i < 2 * n; ++i) {
    const double want = i < n ? q0(i) : v0(i - n), got = i < n ? at[0].q(i) : at[0].v(i - n);
    if (!(std::abs(got - want) <= tol))
      return M.exact_at[static_cast<std::size_t>(i)].place() + ": the exact solution does not start at the initial data: at t0 = " +
             show(t0) + " its " + (i < n ? "q" : "q'") + std::to_string(i % n + 1) + " is " + show(got) + ", the initial " +
             (i < n ? "q" : "v") + std::to_string(i % n + 1) + " is " + show(want) + bound;
  }
  for (const Sample& s : at) {
    const VectorXd r = s.a - s.aL;
    Eigen::Index worst = 0;
    const double res = s.aL.allFinite() ? r.cwiseAbs().maxCoeff(&worst) : missing_value;
    if (!(res <= tol))
      return M.exact_at[static_cast<std::size_t>(worst)].place() + ": the exact solution does not solve the equations: at t = " +
             show(s.t) + ", q = " + show_vec(s.q) + ", q' = " + show_vec(s.v) + " its q'' = " + show_vec(s.a) +
             ", the equations give " + show_vec(s.aL) + ": residual " + show(res) + bound;
    if (M.m > 0 && !(s.phi.lpNorm<Eigen::Infinity>() <= tol))
      return M.exact_at[0].place() + ": the exact solution leaves the constraints: at t = " + show(s.t) + " Phi = " +
             show_vec(s.phi) + bound;
  }
  return "";
}

// Sample points on three short trajectories of the Herglotz equations (from the initial data and from two
// perturbed starts, z(0) = 0), where the two accelerations must agree. Both are exact to round-off (automatic
// differentiation), so a relative disagreement above 1e-8 of the largest acceleration seen is a different system,
// not an error of the check. The trajectories are Boost.Odeint's classical Runge–Kutta, 64 steps over
// min(T, 1): they only have to pass through the region the motion visits.
std::string herglotz_mismatch(const FormulaModel& M, const std::vector<double>& pv) {
  if (!M.has_herglotz()) return "";
  // The extended forms agree where w = 0 only (the t-rows balance E with and without z differently off it): the
  // physical forms are what the user wrote.
  if (M.time_transformed) return herglotz_mismatch(*M.physical, physical_table(M, pv));
  const Formulas F(M, pv);
  const int n = M.n;
  const double T = pv[static_cast<std::size_t>(M.parameter_offset() + M.parameter_index("T"))];
  const double tau = std::min(T, 1.0);
  const int steps = 64, every = 8;
  const std::vector<double> x0 = F.constants(M.initial);
  const std::vector<double> t0z0 = F.constants(M.start);
  const double t0 = t0z0[0];  // the trajectories start where the runs do (the equations may be singular before)
  using State = std::vector<double>;
  auto rhs = [&](const State& x, State& dx, double t) {
    const VectorXd q = Eigen::Map<const VectorXd>(x.data(), n), v = Eigen::Map<const VectorXd>(x.data() + n, n);
    const ContinuousAcceleration a = F.acceleration(t, q, v, x[static_cast<std::size_t>(2 * n)], true);
    for (int i = 0; i < n; ++i) {
      dx[static_cast<std::size_t>(i)] = v(i);
      dx[static_cast<std::size_t>(n + i)] = a.a[static_cast<std::size_t>(i)];
    }
    dx[static_cast<std::size_t>(2 * n)] = F.values(M.herglotz, t, q, v, x[static_cast<std::size_t>(2 * n)])[0];
  };
  struct Sample {
    double t, z;
    VectorXd q, v, aH, aL;
  };
  std::vector<Sample> samples;
  double scale = 0;
  boost::numeric::odeint::runge_kutta4<State> rk;
  for (int start = 0; start < 3; ++start) {
    VectorXd q = Eigen::Map<const VectorXd>(x0.data(), n), v = Eigen::Map<const VectorXd>(x0.data() + n, n);
    if (start > 0)
      for (int i = 0; i < n; ++i) {
        const double s = ((i + start) % 2 == 0 ? 1.0 : -1.0) * 0.1;
        if (!M.holonomic) q(i) += s * (1 + std::abs(q(i)));  // a holonomic system stays on g = 0
        v(i) += s * (1 + std::abs(v(i)));
      }
    v = F.consistent_velocity(t0, q, v);
    State x(static_cast<std::size_t>(2 * n + 1), 0.0);
    x[static_cast<std::size_t>(2 * n)] = t0z0[1];
    for (int i = 0; i < n; ++i) {
      x[static_cast<std::size_t>(i)] = q(i);
      x[static_cast<std::size_t>(n + i)] = v(i);
    }
    for (int j = 0; j <= steps; ++j) {
      const double t = t0 + tau * j / steps;
      if (!std::all_of(x.begin(), x.end(), [](double y) { return std::isfinite(y); })) break;
      if (j % every == 0) {
        Sample s;
        s.t = t;
        s.z = x[static_cast<std::size_t>(2 * n)];
        s.q = Eigen::Map<const VectorXd>(x.data(), n);
        s.v = Eigen::Map<const VectorXd>(x.data() + n, n);
        const ContinuousAcceleration h = F.acceleration(t, s.q, s.v, s.z, true), l = F.acceleration(t, s.q, s.v, 0, false);
        s.aH = Eigen::Map<const VectorXd>(h.a.data(), n);
        s.aL = Eigen::Map<const VectorXd>(l.a.data(), n);
        if (!s.aH.allFinite() || !s.aL.allFinite()) break;
        scale = std::max({scale, s.aH.lpNorm<Eigen::Infinity>(), s.aL.lpNorm<Eigen::Infinity>()});
        samples.push_back(s);
      }
      if (j < steps) rk.do_step(rhs, x, t, tau / steps);
    }
  }
  for (const Sample& s : samples)
    if ((s.aH - s.aL).lpNorm<Eigen::Infinity>() > 1e-8 * scale)
      return M.herglotz_at.place() + ": the Herglotz Lagrangian is inconsistent with the force: at t = " + show(s.t) +
             ", q = " + show_vec(s.q) + ", v = " + show_vec(s.v) + ", z = " + show(s.z) + " its equations give q'' = " +
             show_vec(s.aH) + ", the Lagrange-d'Alembert equations with F give " + show_vec(s.aL) +
             " (the contact and LA schemes would integrate different systems)";
  return "";
}

ContinuousAcceleration continuous_acceleration(const FormulaModel& model, const std::vector<double>& pv, double t,
                                               const std::vector<double>& q, const std::vector<double>& v, double z,
                                               bool herglotz) {
  require(static_cast<int>(q.size()) == model.n && static_cast<int>(v.size()) == model.n,
          "continuous_acceleration: q and v need " + std::to_string(model.n) + " components");
  require(!herglotz || model.has_herglotz(), "system '" + model.name + "' has no Herglotz Lagrangian");
  const Formulas F(model, pv);
  return F.acceleration(t, Eigen::Map<const VectorXd>(q.data(), model.n), Eigen::Map<const VectorXd>(v.data(), model.n),
                        z, herglotz);
}

}  // namespace geomint::formula

namespace geomint::formula {

// Declared in time_transform.hpp (only its users need it): the velocities of a run of a time-transformed model
// from its momenta, by Newton's method on dL/dQ' = p started from the previous step's velocity (the first from the
// exact Q'(0)), and its energy column from them. The extended Lagrangian's Legendre map is one-to-one only near the
// motion (t' > 0, w small): a start at Q' = p (p_t = -E < 0) lands on another root.
void time_transform_velocities(const FormulaModel& M, const std::vector<double>& pv, Run& run) {
  const Formulas F(M, pv);
  const int n = M.n;
  const std::size_t rows = run.t.size();
  const std::vector<double> x0 = F.constants(M.initial);
  VectorXd v = Eigen::Map<const VectorXd>(x0.data() + n, n);
  for (std::size_t j = 0; j < rows; ++j) {
    const double t = run.t[j];
    const VectorXd q = Eigen::Map<const VectorXd>(run.q.data() + j * static_cast<std::size_t>(n), n);
    const VectorXd p = Eigen::Map<const VectorXd>(run.p.data() + j * static_cast<std::size_t>(n), n);
    const double z = run.contact && j < run.z.size() ? run.z[j] : 0.0;
    for (int it = 0; it < 30; ++it) {
      const auto H = run.contact ? F.second(M.herglotz, t, q, v, z, true) : F.second(M.lagrangian, t, q, v, 0, false);
      const VectorXd r = H.grad.segment(1 + n, n) - p;
      const VectorXd dv = H.hess.block(1 + n, 1 + n, n, n).partialPivLu().solve(r);
      v -= dv;
      if (!(dv.lpNorm<Eigen::Infinity>() > 4e-16 * (v.lpNorm<Eigen::Infinity>() + 1e-300))) break;
    }
    for (int i = 0; i < n; ++i) run.v[j * static_cast<std::size_t>(n) + static_cast<std::size_t>(i)] = v(i);
    if (j < run.energy.size()) run.energy[j] = F.values(M.energy, t, q, v, 0)[0];
  }
}

}  // namespace geomint::formula
