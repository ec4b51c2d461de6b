// The drift of an invariant: predicted from the modified equation, measured on a run (invariant_drift.hpp).
#include "geomint/modified/invariant_drift.hpp"

#include <cmath>

#include <Eigen/Dense>

#include "geomint/error.hpp"
#include "geomint/study.hpp"

namespace geomint::modified {

namespace {

// The rate at x = 0 of the least-squares quadratic y ~ a + b x + c x^2 over [first, last): b. A drift that changes
// the orbit changes its own rate (c); the prediction is the rate on the starting orbit, b.
double initial_rate(const std::vector<double>& x, const std::vector<double>& y, std::size_t first, std::size_t last) {
  Eigen::MatrixXd V(last - first, 3);
  Eigen::VectorXd Y(last - first);
  const double scale = x[last - 1] - x[first];
  for (std::size_t i = first; i < last; ++i) {
    const double u = x[i] / scale;  // conditioning
    V(Eigen::Index(i - first), 0) = 1;
    V(Eigen::Index(i - first), 1) = u;
    V(Eigen::Index(i - first), 2) = u * u;
    Y(Eigen::Index(i - first)) = y[i];
  }
  const Eigen::Vector3d c = V.colPivHouseholderQr().solve(Y);
  return c(1) / scale;
}

// Phi_h = sum_k h^k phi_k at a modified point (rows of m).
Eigen::VectorXd modified_constraint(const ModifiedPoint& p, double h) {
  Eigen::VectorXd phi = Eigen::VectorXd::Zero(p.m);
  const int rows = int(p.phi.size()) / std::max(p.m, 1);
  double hk = 1;
  for (int k = 0; k < rows; ++k, hk *= h)
    for (int c = 0; c < p.m; ++c) phi(c) += hk * p.phi[std::size_t(k * p.m + c)];
  return phi;
}

// The mean of the rates, and |mean of the first half - mean of the second half| as its spread.
DriftRate orbit_average(const std::vector<double>& rates) {
  DriftRate r;
  r.samples = long(rates.size());
  const std::size_t half = rates.size() / 2;
  double a = 0, b = 0;
  for (std::size_t i = 0; i < half; ++i) a += rates[i];
  for (std::size_t i = half; i < rates.size(); ++i) b += rates[i];
  r.rate = (a + b) / double(rates.size());
  r.spread = std::abs(a / double(half) - b / double(rates.size() - half));
  return r;
}

}  // namespace

std::vector<DriftRate> predicted_drift(const ModifiedSystem& me, const ParamValues& pv, const std::string& scheme, int K,
                                       double h, const Reference& orbit, long stride,
                                       const std::vector<InvariantFunction>& invariants) {
  const int n = orbit.n, m = me.constraints;
  if (orbit.v.size() != orbit.q.size()) throw InputError("predicted_drift: the orbit has no velocities");
  if (stride < 1) throw InputError("predicted_drift: stride must be >= 1");
  std::vector<std::vector<double>> rates(invariants.size());
  std::vector<double> grad(std::size_t(1 + 2 * n));
  for (long j = 0; j <= orbit.N; j += stride) {
    const double t = double(j) * orbit.h;
    const std::vector<double> q(orbit.q.begin() + j * n, orbit.q.begin() + (j + 1) * n);
    std::vector<double> v(orbit.v.begin() + j * n, orbit.v.begin() + (j + 1) * n);
    if (m > 0) {
      // The rows A of phi_0 = A v + b (linear in v: exact differences), then v moved onto Phi_h = 0 along A^T.
      const ModifiedPoint p0 = me.at(pv, scheme, 0, t, q, v, 0, false);
      Eigen::MatrixXd A(m, n);
      for (int i = 0; i < n; ++i) {
        std::vector<double> w = v;
        w[std::size_t(i)] += 1;
        const ModifiedPoint pi = me.at(pv, scheme, 0, t, q, w, 0, false);
        for (int c = 0; c < m; ++c) A(c, i) = pi.phi[std::size_t(c)] - p0.phi[std::size_t(c)];
      }
      const Eigen::MatrixXd AAt = A * A.transpose();
      for (int it = 0; it < 3; ++it) {
        const ModifiedPoint p = me.at(pv, scheme, K, t, q, v, 0, false);
        const Eigen::VectorXd dv = A.transpose() * AAt.ldlt().solve(modified_constraint(p, h));
        for (int i = 0; i < n; ++i) v[std::size_t(i)] -= dv(i);
      }
    }
    const ModifiedPoint p = me.at(pv, scheme, K, t, q, v, 0, false);
    std::vector<double> a(std::size_t(n), 0.0);
    for (int i = 0; i < n; ++i) {
      double hk = 1;
      for (int k = 0; k <= K; ++k, hk *= h) a[std::size_t(i)] += hk * p.F_at(k, i);
    }
    for (std::size_t w = 0; w < invariants.size(); ++w) {
      invariants[w](t, q.data(), v.data(), grad.data());
      double rate = grad[0];
      for (int i = 0; i < n; ++i)
        rate += grad[std::size_t(1 + i)] * v[std::size_t(i)] + grad[std::size_t(1 + n + i)] * a[std::size_t(i)];
      if (!std::isfinite(rate))
        throw NumericalFailure(j, "modified equation", "non-finite rate of an invariant at t = " + std::to_string(t));
      rates[w].push_back(rate);
    }
  }
  if (orbit.N / stride < 1) throw InputError("predicted_drift: fewer than two orbit points");
  std::vector<DriftRate> out;
  for (const auto& r : rates) out.push_back(orbit_average(r));
  return out;
}

MeasuredDrift measured_drift(const SystemInfo& sys, const ParamValues& pv, const std::string& scheme, double h, double T,
                             long every, const InvariantFunction& invariant, double exact_start_value) {
  ParamValues with_T = pv;
  bool has_T = false;
  for (auto& [k, v] : with_T)
    if (k == "T") v = T, has_T = true;
  if (!has_T) with_T.emplace_back("T", T);
  return measured_drift(sys.run(with_T, scheme, h, Path::generic, every), invariant, exact_start_value);
}

MeasuredDrift measured_drift(const Run& run, const InvariantFunction& invariant, double exact_start_value) {
  const int n = run.n;
  std::vector<double> values;
  for (std::size_t j = 0; j < run.t.size(); ++j)
    values.push_back(invariant(run.t[j], &run.q[j * std::size_t(n)], &run.v[j * std::size_t(n)], nullptr));
  if (values.size() < 8) throw InputError("measured_drift: keep at least 8 steps (every is too large for T/h)");
  MeasuredDrift d;
  d.steps = run.steps;
  d.offset = values[0] - exact_start_value;
  for (double x : values) d.max_deviation = std::max(d.max_deviation, std::abs(x - values[0]));
  const std::size_t half = values.size() / 2;
  d.slope.rate = initial_rate(run.t, values, 0, values.size());
  d.slope.spread = std::abs(initial_rate(run.t, values, 0, half) - d.slope.rate);
  d.slope.samples = long(values.size());
  return d;
}

double drift_power(const std::vector<double>& h, const std::vector<DriftRate>& rates) {
  std::vector<double> hs, rs;
  for (std::size_t i = 0; i < h.size() && i < rates.size(); ++i)
    if (std::abs(rates[i].rate) > rates[i].spread) hs.push_back(h[i]), rs.push_back(std::abs(rates[i].rate));
  if (hs.size() < 2) return missing_value;
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < hs.size(); ++i) mx += std::log(hs[i]), my += std::log(rs[i]);
  mx /= double(hs.size()), my /= double(hs.size());
  double sxy = 0, sxx = 0;
  for (std::size_t i = 0; i < hs.size(); ++i) {
    sxy += (std::log(hs[i]) - mx) * (std::log(rs[i]) - my);
    sxx += (std::log(hs[i]) - mx) * (std::log(hs[i]) - mx);
  }
  return sxy / sxx;
}

}  // namespace geomint::modified
