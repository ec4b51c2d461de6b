#include "agreement.hpp"

#include <algorithm>
#include <cmath>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include "geomint/error.hpp"
#include "equations.hpp"
#include "lagrangians.hpp"
#include "geomint/registry.hpp"
#include "geomint/reference.hpp"

namespace geomint::modified {

const char* start_name(Start s) { return s == Start::consistent ? "consistent" : "naive"; }

namespace {

void check_scheme(const std::string& scheme) {
  require(scheme == "la" || scheme == "contact",
          "no modified equation for scheme '" + scheme + "' (known: la, contact)");
}

// Modified momentum map p~(q, v, z) of each scheme (see agreement.hpp).
double momentum_map(const std::string& scheme, double alpha, double h_eq, double sign, double q, double v, double z) {
  if (scheme == "contact") {
    const ContactModifiedLagrangian L{alpha, h_eq, sign};
    return derivatives3([&](const auto& Q, const auto& V, const auto& Z) { return L(Q, V, Z); },
                        Eigen::Vector3d(q, v, z))
        .grad(1);
  }
  const LaModifiedLagrangian M{alpha, h_eq, sign};
  return v - h_eq / 2 * forced_acceleration(M, q, v);
}

}  // namespace

std::array<double, 3> modified_rhs(const std::string& scheme, double alpha, double h_eq, double sign,
                                   const std::array<double, 3>& x) {
  if (scheme == "contact") {
    const auto f = herglotz_field(ContactModifiedLagrangian{alpha, h_eq, sign}, x[0], x[1], x[2]);
    return {x[1], f.a, f.zdot};
  }
  return {x[1], forced_acceleration(LaModifiedLagrangian{alpha, h_eq, sign}, x[0], x[1]), 0.0};
}

LinearCoefficients modified_coefficients(const std::string& scheme, double alpha, double h_eq) {
  check_scheme(scheme);
  return {-modified_rhs(scheme, alpha, h_eq, 1, {0, 1, 0})[1], -modified_rhs(scheme, alpha, h_eq, 1, {1, 0, 0})[1]};
}

double modified_initial_velocity(const std::string& scheme, double alpha, double h_eq, double q0, double p0,
                                 Start start, double sign) {
  check_scheme(scheme);
  if (start == Start::naive || h_eq == 0) return p0;
  // Solve p~(q0, v) = p0 by Newton's method with a difference slope; p~ is affine in v for these
  // models, so two iterations reach round-off; iterate to a fixed tolerance all the same.
  double v = p0;
  for (int it = 0; it < 50; ++it) {
    const double r = momentum_map(scheme, alpha, h_eq, sign, q0, v, 0.0) - p0;
    const double dv = 1e-6 * (1 + std::abs(v));
    const double slope = (momentum_map(scheme, alpha, h_eq, sign, q0, v + dv, 0.0) -
                          momentum_map(scheme, alpha, h_eq, sign, q0, v - dv, 0.0)) / (2 * dv);
    const double step = r / slope;
    v -= step;
    if (std::abs(step) <= 1e-16 * (1 + std::abs(v))) break;
  }
  return v;
}

ModifiedSolution modified_solution(const std::string& scheme, double alpha, double h, double h_eq, double T, double q0,
                                   double p0, Start start, double sign, double tol) {
  check_scheme(scheme);
  const long N = step_count(h, T);
  std::vector<double> times(static_cast<size_t>(N + 1));
  for (long j = 0; j <= N; ++j) times[static_cast<size_t>(j)] = static_cast<double>(j) * h;
  const double v0 = modified_initial_velocity(scheme, alpha, h_eq, q0, p0, start, sign);
  const auto xs = odeint_dense<3>(
      [&](const std::array<double, 3>& x, std::array<double, 3>& dx, double) {
        dx = modified_rhs(scheme, alpha, h_eq, sign, x);
      },
      {q0, v0, 0.0}, times, tol);
  ModifiedSolution s;
  s.t = times;
  for (std::size_t j = 0; j < xs.size(); ++j) {
    const auto& x = xs[j];
    s.q.push_back(x[0]);
    s.v.push_back(x[1]);
    s.z.push_back(x[2]);
    s.p.push_back(momentum_map(scheme, alpha, h_eq, sign, x[0], x[1], x[2]));
    // an overflow (a damping of 1e200) is a failure here, where it happens, not an inf error further on
    if (!std::isfinite(x[0]) || !std::isfinite(x[1]) || !std::isfinite(x[2]) || !std::isfinite(s.p.back()))
      throw NumericalFailure(static_cast<long>(j), "modified solution",
                             "the solution of the " + std::string(h_eq == 0 ? "original" : "modified") +
                                 " equation or its momentum is not finite at t = " + show(times[j]) + " (scheme " +
                                 scheme + ", alpha = " + show(alpha) + ", h = " + show(h) + ")");
  }
  return s;
}

Agreement agreement(const std::string& scheme, double alpha, double h, double T, double q0, double p0, Start start,
                    double sign, double tol) {
  check_scheme(scheme);
  const auto disc = find_system("oscillator").run({{"alpha", alpha}, {"q0", q0}, {"p0", p0}, {"T", T}}, scheme, h, Path::fast, 1);
  const auto mod = modified_solution(scheme, alpha, h, h, T, q0, p0, start, sign, tol);
  const auto orig = modified_solution(scheme, alpha, h, 0.0, T, q0, p0, Start::naive, 1, tol);
  Agreement a{0, 0, 0, 0, 0, 0};
  for (size_t j = 0; j < disc.q.size(); ++j) {
    a.err_modified = std::max(a.err_modified, std::abs(disc.q[j] - mod.q[j]));
    a.err_original = std::max(a.err_original, std::abs(disc.q[j] - orig.q[j]));
    a.err_p_modified = std::max(a.err_p_modified, std::abs(disc.p[j] - mod.p[j]));
    a.err_p_original = std::max(a.err_p_original, std::abs(disc.p[j] - orig.p[j]));
    a.err_z_modified = std::max(a.err_z_modified, std::abs(disc.z[j] - mod.z[j]));
    a.err_z_original = std::max(a.err_z_original, std::abs(disc.z[j] - orig.z[j]));
  }
  if (scheme == "la") a.err_z_modified = a.err_z_original = missing_value;
  return a;
}

namespace {
struct GslParams {
  std::string scheme;
  double alpha, h_eq;
};
int gsl_rhs(double, const double y[], double f[], void* params) {
  const auto* p = static_cast<const GslParams*>(params);
  const auto d = modified_rhs(p->scheme, p->alpha, p->h_eq, 1, {y[0], y[1], y[2]});
  for (int i = 0; i < 3; ++i) f[i] = d[static_cast<size_t>(i)];
  return GSL_SUCCESS;
}
}  // namespace

std::vector<std::array<double, 3>> modified_solution_gsl(const std::string& scheme, double alpha, double h_eq,
                                                         const std::vector<double>& times, std::array<double, 3> x0,
                                                         double tol) {
  check_scheme(scheme);
  GslParams params{scheme, alpha, h_eq};
  gsl_odeiv2_system sys{gsl_rhs, nullptr, 3, &params};
  gsl_odeiv2_driver* d = gsl_odeiv2_driver_alloc_y_new(&sys, gsl_odeiv2_step_rk8pd, 1e-3, tol, tol);
  std::vector<std::array<double, 3>> out;
  double t = times.front();
  double y[3] = {x0[0], x0[1], x0[2]};
  for (double ti : times) {
    if (ti > t) {
      const int status = gsl_odeiv2_driver_apply(d, &t, ti, y);
      if (status != GSL_SUCCESS) {
        gsl_odeiv2_driver_free(d);
        throw std::runtime_error("GSL rk8pd failed at t = " + std::to_string(t));
      }
    }
    out.push_back({y[0], y[1], y[2]});
  }
  gsl_odeiv2_driver_free(d);
  return out;
}

}  // namespace geomint::modified
