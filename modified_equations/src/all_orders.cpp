#include "geomint/error.hpp"
#include "geomint/modified/all_orders.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Dense>
#include <unsupported/Eigen/MatrixFunctions>

#include "geomint/linear_oscillator.hpp"
#include "geomint/modified/automatic_registry.hpp"
#include "geomint/registry.hpp"

namespace geomint::modified {

AllOrders all_orders_from_trace_det(long double tr, long double det, long double h) {
  AllOrders r;
  r.tr = static_cast<double>(tr);
  r.det = static_cast<double>(det);
  const long double disc = tr * tr - 4 * det;
  if (disc < 0) {
    // lambda = sqrt(det) e^{+-i theta}: a = -ln(det)/h, omega = theta/h, b = omega^2 + a^2/4
    r.oscillating = true;
    r.valid = det > 0;
    r.spectral_radius = static_cast<double>(std::sqrt(det));
    if (r.valid) {
      const long double theta = std::atan2(std::sqrt(-disc), tr);
      const long double a = -std::log(det) / h, w = theta / h;
      r.a = static_cast<double>(a);
      r.b = static_cast<double>(w * w + a * a / 4);
    }
  } else {
    const long double s = std::sqrt(disc);
    const long double l1 = (tr + s) / 2, l2 = (tr - s) / 2;
    r.spectral_radius = static_cast<double>(std::max(std::abs(l1), std::abs(l2)));
    r.valid = l1 > 0 && l2 > 0;
    if (r.valid) {
      const long double m1 = std::log(l1) / h, m2 = std::log(l2) / h;
      r.a = static_cast<double>(-(m1 + m2));
      r.b = static_cast<double>(m1 * m2);
    }
  }
  return r;
}

AllOrders all_orders_by_name(const std::string& scheme, double h, double alpha) {
  // the closed form's matrix in long double (row-major (q, p)): the coefficients keep their digits
  const auto M = find_system("oscillator").one_step_matrix({{"alpha", alpha}}, scheme, h, Path::fast);
  return all_orders_from_trace_det(M[0] + M[3], M[0] * M[3] - M[1] * M[2], h);
}

LinearModified all_orders_linear(const SystemInfo& sys, const ParamValues& pv, const std::string& scheme, double h,
                                 Path path) {
  using Mat = Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic>;
  const int n = sys.dof, N = 2 * n;
  const std::vector<long double> m = sys.one_step_matrix(pv, scheme, h, path);  // InputError unless linear, m = 0
  require(static_cast<int>(m.size()) == N * N, "system '" + sys.name + "' gives no one-step matrix");
  Mat M(N, N);
  for (int r = 0; r < N; ++r)
    for (int c = 0; c < N; ++c) M(r, c) = m[static_cast<std::size_t>(r * N + c)];
  const std::string where = "system " + sys.name + ", scheme " + scheme + ", h = " + show(h);
  // a real eigenvalue <= 0: the principal logarithm is not real, and no real linear flow samples the steps
  const Eigen::EigenSolver<Mat> eig(M, false);
  for (int i = 0; i < N; ++i) {
    const auto l = eig.eigenvalues()(i);
    const long double scale = std::max<long double>(1, std::abs(l));
    if (std::abs(l.imag()) <= 64 * std::numeric_limits<long double>::epsilon() * scale && l.real() <= 0)
      throw NumericalFailure(0, "all orders",
                             where + ": the one-step matrix has the real eigenvalue " + show(static_cast<double>(l.real())) +
                                 " <= 0, so no real flow samples the steps");
  }
  const Mat G = Mat(M.log()) / static_cast<long double>(h);
  if (!G.allFinite()) throw NumericalFailure(0, "all orders", where + ": the logarithm of the one-step matrix is not finite");
  const Mat Gqq = G.topLeftCorner(n, n), Gqp = G.topRightCorner(n, n), Gpq = G.bottomLeftCorner(n, n),
            Gpp = G.bottomRightCorner(n, n);
  const Eigen::FullPivLU<Mat> lu(Gqp);
  if (!lu.isInvertible())
    throw NumericalFailure(0, "all orders", where + ": G_qp is singular, so p cannot be eliminated");
  const Mat B = Gqp * Gpp * lu.inverse();
  const Mat Av = Gqq + B, Aq = Gqp * Gpq - B * Gqq;
  LinearModified r;
  r.n = n;
  for (int i = 0; i < N; ++i)
    for (int j = 0; j < N; ++j) r.G.push_back(G(i, j));
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      r.A_q.push_back(Aq(i, j));
      r.A_v.push_back(Av(i, j));
    }
  return r;
}

double all_orders_deviation(const AllOrders& m, const std::vector<double>& t, const std::vector<double>& q) {
  if (!m.valid || q.size() < 2) return missing_value;
  const double h = t[1] - t[0];
  const double A = linear_oscillator_solution(m.a, m.b, 1.0, 0.0, h).q;
  const double B = linear_oscillator_solution(m.a, m.b, 0.0, 1.0, h).q;
  const double v0 = (q[1] - q[0] * A) / B;
  double dev = 0;
  for (size_t j = 0; j < q.size(); ++j)
    dev = std::max(dev, std::abs(q[j] - linear_oscillator_solution(m.a, m.b, q[0], v0, t[j]).q));
  return dev;
}

double linear_flow_deviation(const LinearModified& lm, const Run& run) {
  using Mat = Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic>;
  using Vec = Eigen::Matrix<long double, Eigen::Dynamic, 1>;
  const int n = lm.n, N = 2 * n;
  require(run.n == n && run.m == 0, "linear_flow_deviation: the run is not of this system");
  const std::size_t J = run.t.size();
  if (J < 2) return missing_value;
  Mat G(N, N);
  for (int r = 0; r < N; ++r)
    for (int c = 0; c < N; ++c) G(r, c) = lm.G[static_cast<std::size_t>(r * N + c)];
  auto x = [&](std::size_t j) {
    Vec v(N);
    for (int i = 0; i < n; ++i) {
      v(i) = run.q[j * static_cast<std::size_t>(n) + static_cast<std::size_t>(i)];
      v(n + i) = run.p[j * static_cast<std::size_t>(n) + static_cast<std::size_t>(i)];
    }
    return v;
  };
  const Vec x0 = x(0);
  auto flow = [&](double t) { return Vec(Mat((G * static_cast<long double>(t)).exp()) * x0); };
  // affine steps (a forcing term): some step leaves the homogeneous one-step map by far more than round-off
  const Mat step = (G * static_cast<long double>(run.t[1] - run.t[0])).exp();
  for (std::size_t j = 0; j + 1 < J; ++j) {
    const Vec xj = x(j);
    if ((step * xj - x(j + 1)).cwiseAbs().maxCoeff() > 1e-9L * (1 + xj.cwiseAbs().maxCoeff())) return missing_value;
  }
  double dev = 0;
  for (std::size_t j = 0; j < J; ++j) {
    const Vec y = flow(run.t[j]), xj = x(j);
    dev = std::max(dev, static_cast<double>((y.head(n) - xj.head(n)).cwiseAbs().maxCoeff()));
  }
  return dev;
}

LinearSeries linear_series(const SystemInfo& sys, const ParamValues& pv, const std::string& scheme, int K, double h) {
  const auto me = modified_system(sys);
  const ModifiedSystem& ms = *me;
  const int n = sys.dof;
  require(sys.linear && sys.constraints == 0, "system '" + sys.name + "' is not linear and unconstrained");
  const std::vector<double> zero(static_cast<std::size_t>(n), 0.0);
  const auto base = ms.at(pv, scheme, K, 0.0, zero, zero, 0.0, false);
  // sum_k h^k F_k(q, v) at one point
  auto sum = [&](const ModifiedPoint& p, int i) {
    double s = 0;
    for (int k = K; k >= 0; --k) s = s * h + p.F_at(k, i);
    return s;
  };
  LinearSeries r;
  r.n = n;
  r.K = K;
  r.A_q.assign(static_cast<std::size_t>(n * n), 0.0);
  r.A_v.assign(static_cast<std::size_t>(n * n), 0.0);
  for (int c = 0; c < n; ++c) {
    std::vector<double> e = zero;
    e[static_cast<std::size_t>(c)] = 1;
    const auto pq = ms.at(pv, scheme, K, 0.0, e, zero, 0.0, false);
    const auto pvv = ms.at(pv, scheme, K, 0.0, zero, e, 0.0, false);
    for (int i = 0; i < n; ++i) {
      r.A_q[static_cast<std::size_t>(i * n + c)] = sum(pq, i) - sum(base, i);
      r.A_v[static_cast<std::size_t>(i * n + c)] = sum(pvv, i) - sum(base, i);
    }
  }
  return r;
}

}  // namespace geomint::modified
