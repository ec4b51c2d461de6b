#include "geomint/formula/time_transform.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "geomint/error.hpp"
#include "geomint/text.hpp"

namespace geomint::formula {

std::vector<double> parameter_table(const FormulaModel& M, const ParamValues& pv) {
  std::vector<double> out(M.numbers);
  for (const auto& p : M.parameters) {
    double x = p.value;
    for (const auto& [name, value] : pv)
      if (name == p.name) x = value;
    out.push_back(x);
  }
  return with_derived_values(M, std::move(out));
}

namespace {

double residual_at(const FormulaModel& M, const std::vector<double>& table, double sigma, const double* Q, const double* Qv) {
  const int N = M.n;
  std::vector<double> x(static_cast<std::size_t>(2 * N + 2), 0.0);
  x[0] = sigma;
  for (int i = 0; i < N; ++i) {
    x[static_cast<std::size_t>(1 + i)] = Q[i];
    x[static_cast<std::size_t>(1 + N + i)] = Qv[i];
  }
  std::vector<const double*> in(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) in[i] = &x[i];
  double w = 0;
  M.residual.eval_duals<double, 0>(nullptr, in.data(), table.data(), &w);
  return w;
}

}  // namespace

PhysicalState at_physical_time(const Run& run, int n, double t_end) {
  const int N = n + 1;
  require(run.n == N, "at_physical_time: the run has " + std::to_string(run.n) + " coordinates, not n + 1 = " + std::to_string(N));
  const std::size_t rows = run.t.size();
  require(rows >= 2, "at_physical_time: the run has fewer than two steps");
  auto time = [&](std::size_t j) { return run.q[j * static_cast<std::size_t>(N) + static_cast<std::size_t>(n)]; };
  require(time(0) <= t_end, "at_physical_time: t_end = " + show(t_end) + " is before the run's start t = " + show(time(0)));
  std::size_t j = 1;
  while (j < rows && time(j) < t_end) ++j;
  require(j < rows, "the run ends at t = " + show(time(rows - 1)) + " (sigma = " + show(run.t.back()) +
                        "), before t_end = " + show(t_end) + ": a longer sigma horizon is needed");
  const std::size_t a = j - 1, b = j;
  const double h = run.t[b] - run.t[a];
  require(h > 0, "at_physical_time: the run keeps one step twice");
  auto Q = [&](std::size_t r, int i) { return run.q[r * static_cast<std::size_t>(N) + static_cast<std::size_t>(i)]; };
  auto V = [&](std::size_t r, int i) { return run.v[r * static_cast<std::size_t>(N) + static_cast<std::size_t>(i)]; };
  // Cubic Hermite on [sigma_a, sigma_b], s in [0, 1].
  auto value = [&](int i, double s) {
    const double s2 = s * s, s3 = s2 * s;
    return (2 * s3 - 3 * s2 + 1) * Q(a, i) + (s3 - 2 * s2 + s) * h * V(a, i) + (-2 * s3 + 3 * s2) * Q(b, i) +
           (s3 - s2) * h * V(b, i);
  };
  auto slope = [&](int i, double s) {  // d/dsigma
    const double s2 = s * s;
    return ((6 * s2 - 6 * s) * Q(a, i) + (-6 * s2 + 6 * s) * Q(b, i)) / h + (3 * s2 - 4 * s + 1) * V(a, i) +
           (3 * s2 - 2 * s) * V(b, i);
  };
  const double ta = Q(a, n), tb = Q(b, n);
  double s = tb > ta ? (t_end - ta) / (tb - ta) : 1.0;
  for (int it = 0; it < 50; ++it) {
    const double r = value(n, s) - t_end, d = slope(n, s) * h;
    if (!(d > 0)) break;  // t' <= 0 on the interpolant: keep the secant's estimate
    const double next = std::clamp(s - r / d, 0.0, 1.0);
    const bool done = std::abs(next - s) <= 1e-15;
    s = next;
    if (done) break;
  }
  PhysicalState out;
  out.t = t_end;
  out.sigma = run.t[a] + s * h;
  const double tp = slope(n, s);
  for (int i = 0; i < n; ++i) {
    out.q.push_back(value(i, s));
    out.v.push_back(slope(i, s) / tp);
  }
  if (run.contact && run.z.size() == rows) out.z = (1 - s) * run.z[a] + s * run.z[b];
  return out;
}

double time_transform_residual(const FormulaModel& model, const ParamValues& pv, double sigma, const std::vector<double>& Q,
                               const std::vector<double>& Qv) {
  require(model.time_transformed, "system '" + model.name + "' has no time transformation");
  require(static_cast<int>(Q.size()) == model.n && static_cast<int>(Qv.size()) == model.n,
          "time_transform_residual: Q and Q' have " + std::to_string(model.n) + " components");
  return residual_at(model, parameter_table(model, pv), sigma, Q.data(), Qv.data());
}

PhysicalRun run_to_physical_time(const SystemInfo& info, const FormulaModel& model, ParamValues pv,
                                 const std::string& scheme, double h, double t_end, Path path) {
  require(model.time_transformed, "system '" + model.name + "' has no time transformation");
  require(std::isfinite(h) && h > 0, "the step h must be a positive number, got " + show(h));
  require(std::isfinite(t_end) && t_end > 0, "t_end must be a positive number, got " + show(t_end));
  const std::vector<double> table = parameter_table(model, pv);
  // dt/dsigma at the start, from the initial tape (its last output is t'(0) = g0)
  std::vector<const double*> in(static_cast<std::size_t>(model.derived_offset()));
  for (std::size_t i = 0; i < in.size(); ++i) in[i] = &table[i];
  std::vector<double> x0(model.initial.size());
  model.initial.eval_duals<double, 0>(nullptr, in.data(), table.data(), x0.data());
  const double g0 = x0.back();
  require(g0 > 0, model.time_transform_at.place() + ": time_transform: the monitor is " + show(g0) +
                      " at the initial data: it must be positive");
  pv.erase(std::remove_if(pv.begin(), pv.end(), [](const auto& p) { return p.first == "T"; }), pv.end());
  long steps = std::max<long>(2, static_cast<long>(std::ceil(1.25 * t_end / g0 / h)) + 2);
  for (int attempt = 0;; ++attempt) {
    ParamValues with_T = pv;
    with_T.emplace_back("T", static_cast<double>(steps) * h);
    PhysicalRun out;
    out.run = info.run(with_T, scheme, h, path, 1);
    const int N = model.n;
    if (out.run.q[out.run.q.size() - 1] >= t_end || attempt == 20) {
      out.sigma_horizon = static_cast<double>(steps) * h;
      out.end = at_physical_time(out.run, N - 1, t_end);
      for (std::size_t j = 0; j < out.run.t.size(); ++j)
        out.residual = std::max(out.residual, std::abs(residual_at(model, table, out.run.t[j],
                                                                   out.run.q.data() + j * static_cast<std::size_t>(N),
                                                                   out.run.v.data() + j * static_cast<std::size_t>(N))));
      return out;
    }
    steps *= 2;
  }
}

}  // namespace geomint::formula
