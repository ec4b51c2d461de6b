// The largest shapes of formula systems, n = 4 coordinates with m = 2 constraint rows, both kinds, through their
// registry entries (as the programs and the Python module run them): every scheme of the core converges at its
// order against an independent reference, keeps its discrete constraints at round-off, and has modified equations
// whose self-check vanishes at round-off.
//   rolling-disk (rows linear in the velocities): against its closed form (docs/systems/rolling-disk.geomint);
//   double-pendulum-cartesian (two holonomic rods): against the same motion in the angles, an unconstrained
//   system (docs/systems/double-pendulum.geomint), integrated by Boost.Odeint;
//   pendulum-chain (n = 6, a shape beyond n = 4 that shapes.def lists): against its equations written here by
//   hand, integrated by Boost.Odeint.
#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <functional>
#include <random>
#include <tuple>

#include <boost/numeric/odeint.hpp>

#include "geomint/error.hpp"
#include "geomint/formula/checks.hpp"
#include "geomint/formula/formula_registry.hpp"
#include "geomint/generic/schemes.hpp"
#include "geomint/modified/formula_modified.hpp"
#include "geomint/registry.hpp"
#include "geomint/study.hpp"

using namespace geomint;

namespace {

std::string system_file(const std::string& name) { return std::string(GEOMINT_SOURCE_DIR) + "/docs/systems/" + name + ".geomint"; }

using Q4 = std::array<double, 4>;

// The parameter table (numbers | parameters | derived values) of a model at its defaults, for the run-time checks.
std::vector<double> default_table(const formula::FormulaModel& model) {
  std::vector<double> pv = model.numbers;
  for (const auto& p : model.parameters) pv.push_back(p.value);
  const int k = model.derived_offset();
  pv.resize(std::size_t(model.table_size()));
  std::vector<const double*> in;
  for (int i = 0; i < k; ++i) in.push_back(&pv[std::size_t(i)]);
  model.prelude.evaluate(in.data(), pv.data(), pv.data() + k);
  return pv;
}

double parameter(const formula::FormulaModel& model, const std::string& name) {
  return model.parameters[std::size_t(model.parameter_index(name))].value;
}

// A reference on t_j = j h, j = 0..N from positions at those times.
Reference reference_from(const std::string& kind, double h, long N, const std::function<Q4(double)>& exact) {
  Reference r;
  r.kind = kind;
  r.h = h;
  r.N = N;
  r.n = 4;
  for (long j = 0; j <= N; ++j) {
    const Q4 q = exact(double(j) * h);
    r.q.insert(r.q.end(), q.begin(), q.end());
  }
  return r;
}

// Every scheme of the core on `entry`: the fitted order of the error over h = h0 ... h0/16 against `ref` (on the
// grid of h0/16), and the largest |Phi_d| along each run relative to the round-off of its terms, `phi_scale(q0,
// q1, h)` (for rows in the velocities |A| (|q_j| + |q_{j+1}|)/h + |b|: the chord (q_{j+1} - q_j)/h carries eps
// |q|/h; for holonomic rows the terms of g at q_{j+1}). The first-order schemes: LA at 1; contact at least 1 (its
// O(h) terms can be small enough to show a higher slope, as on the damped oscillator of Figure 1).
void check_orders(const SystemInfo& entry, double h0, const Reference& ref,
                  const std::function<double(const double*, const double*, double)>& phi_scale) {
  std::apply([&](auto... g) {
    for (const auto& scheme : {std::string(generic::scheme_name<decltype(g)>())...}) {
      const auto hs = halving_sequence(h0, h0 / 16);
      std::vector<double> errs;
      double phi = 0;
      for (double h : hs) {
        errs.push_back(entry.max_error({}, scheme, h, Path::generic, ref));
        const Run r = entry.run({}, scheme, h, Path::generic, 1);
        for (long j = 1; j <= r.steps; ++j)
          phi = std::max(phi, r.phi_d[std::size_t(j)] / phi_scale(&r.q[std::size_t(4 * (j - 1))], &r.q[std::size_t(4 * j)], h));
      }
      const double slope = fit_order(hs, errs).slope;
      const SchemeInfo& info = entry.scheme(scheme);
      INFO(entry.name << " " << scheme << ": errors " << errs.front() << " ... " << errs.back() << ", fitted order " << slope
                      << " (expected " << info.order << "), max |Phi_d| / its round-off scale " << phi);
      if (info.principle.find("Herglotz") != std::string::npos && info.order == 1)
        CHECK(slope > 0.9);
      else
        CHECK(std::abs(slope - info.order) < 0.1);
      CHECK(phi <= 16 * 2.220446049250313e-16);  // the stepper's kappa eps
    }
  }, generic::AllSchemesTuple{});
}

}  // namespace

TEST_CASE("rolling disk (n = 4, m = 2 rows in the velocities): every scheme at its order against the closed form",
          "[formula][shapes]") {
  const auto model = formula::load_system_file(system_file("rolling-disk"));
  const auto entry = formula::formula_system_info(model);
  const double R = parameter(*model, "R"), alpha = parameter(*model, "alpha"), x0 = parameter(*model, "x0"),
               y0 = parameter(*model, "y0"), th0 = parameter(*model, "theta0"), ph0 = parameter(*model, "phi0"),
               w0 = parameter(*model, "omega0"), s0 = parameter(*model, "spin0"), T = entry->horizon({});
  auto exact = [&](double t) {
    const double decay = (1 - std::exp(-alpha * t)) / alpha, th = th0 + w0 * decay;
    return Q4{x0 + R * s0 / w0 * (std::sin(th) - std::sin(th0)), y0 - R * s0 / w0 * (std::cos(th) - std::cos(th0)), th,
              ph0 + s0 * decay};
  };
  const double h0 = 0.1;
  const Reference ref = reference_from("closed form", h0 / 16, step_count(h0 / 16, T), exact);
  // rows v1 - R cos(q3) v4 and v2 - R sin(q3) v4 at the step's start (the larger of the two rows' scales: Run
  // keeps the larger |Phi_d| of the two)
  check_orders(*entry, h0, ref, [&](const double* q0, const double* q1, double h) {
    const double phi = std::abs(q0[3]) + std::abs(q1[3]);
    return std::max(std::abs(q0[0]) + std::abs(q1[0]) + R * std::abs(std::cos(q0[2])) * phi,
                    std::abs(q0[1]) + std::abs(q1[1]) + R * std::abs(std::sin(q0[2])) * phi) / h;
  });
}

TEST_CASE("Cartesian double pendulum (n = 4, m = 2 holonomic rods): every scheme at its order against the angle form",
          "[formula][shapes]") {
  const auto model = formula::load_system_file(system_file("double-pendulum-cartesian"));
  const auto entry = formula::formula_system_info(model);
  const auto angles = formula::formula_system_info(formula::load_system_file(system_file("double-pendulum")));
  const double l1 = parameter(*model, "l1"), l2 = parameter(*model, "l2"), T = entry->horizon({});
  // the reference: Odeint (dopri5, tol 1e-13) on the angle form's equations, on a grid fine enough for every h
  const double h0 = 0.05, hmin = h0 / 16;
  const long N = step_count(hmin, T);
  const Reference in_angles = angles->reference({}, hmin, N, ReferenceKind::odeint, 1e-13);
  auto exact = [&](double t) {
    const std::size_t j = std::size_t(std::lround(t / hmin));
    const double a1 = in_angles.q[2 * j], a2 = in_angles.q[2 * j + 1];
    const double x1 = l1 * std::sin(a1), y1 = -l1 * std::cos(a1);
    return Q4{x1, y1, x1 + l2 * std::sin(a2), y1 - l2 * std::cos(a2)};
  };
  const Reference ref = reference_from("angle form, Boost.Odeint", hmin, N, exact);
  // the references agree: the Cartesian system's own continuous equations (the holonomic rows, their drift and
  // multipliers) integrated the same way, against the angle form
  const Reference own = entry->reference({}, hmin, N, ReferenceKind::odeint, 1e-13);
  double dref = 0;
  for (std::size_t i = 0; i < own.q.size(); ++i) dref = std::max(dref, std::abs(own.q[i] - ref.q[i]));
  INFO("Cartesian against angle form, continuous: " << dref);
  CHECK(dref < 1e-9);
  // g1 = (x1^2 + y1^2 - l1^2)/2, g2 = ((x2 - x1)^2 + (y2 - y1)^2 - l2^2)/2 at q_{j+1}: |A| |q_{j+1}| + 1
  check_orders(*entry, h0, ref, [&](const double*, const double* q, double) {
    const double dx = std::abs(q[2] - q[0]), dy = std::abs(q[3] - q[1]);
    return std::max(q[0] * q[0] + q[1] * q[1], dx * (std::abs(q[0]) + std::abs(q[2])) + dy * (std::abs(q[1]) + std::abs(q[3]))) + 1;
  });
}

TEST_CASE("n = 4, m = 2 formula systems: continuous equations and modified equations at round-off", "[formula][shapes]") {
  std::mt19937 gen(3);
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  for (const char* name : {"rolling-disk", "double-pendulum-cartesian"}) {
    const auto model = formula::load_system_file(system_file(name));
    const auto entry = formula::formula_system_info(model);
    const auto me = modified::formula_modified_system(model);
    const auto table = default_table(*model);
    const auto ode = entry->ode({});
    const Run start = entry->run({}, "la", entry->horizon({}) / 1000, Path::generic, 1000);  // its initial data
    for (int k = 0; k < 3; ++k) {
      std::vector<double> q(start.q.begin(), start.q.begin() + 4), v(start.v.begin(), start.v.begin() + 4);
      for (int i = 0; i < 4; ++i) {
        q[std::size_t(i)] += u(gen);
        v[std::size_t(i)] += u(gen);
      }
      const double t = 0.5 + u(gen);
      // the typed equations (the entry's Odeint right-hand side: generic::acceleration, fixed sizes) and the
      // run-time ones (checks.cpp)
      std::vector<double> x(q), dx(8);
      x.insert(x.end(), v.begin(), v.end());
      ode(t, x.data(), dx.data());
      const auto b = formula::continuous_acceleration(*model, table, t, q, v, 0, false);
      double amax = 0;
      for (int i = 0; i < 4; ++i) amax = std::max(amax, std::abs(dx[std::size_t(4 + i)]));
      for (int i = 0; i < 4; ++i) CHECK(std::abs(dx[std::size_t(4 + i)] - b.a[std::size_t(i)]) <= 1e-13 * (1 + amax));
      for (const char* scheme : {"la", "contact"}) {
        const auto r = me->at({}, scheme, 4, t, q, v, 0.1, true);
        double F = 0;
        for (double f : r.F) F = std::max(F, std::abs(f));
        INFO(name << " " << scheme << ": self-check " << r.residual << " against |F| " << F);
        CHECK(r.residual <= 1e-12 * F);
        // order 0 is the continuous Lagrange-d'Alembert (or Herglotz) acceleration
        for (int i = 0; i < 4; ++i)
          CHECK(std::abs(r.F_at(0, i) - dx[std::size_t(4 + i)]) <= (std::string(scheme) == "contact" ? 1.0 : 1e-12) * (1 + F));
      }
    }
  }
}

TEST_CASE("a chain of six pendula (n = 6): every scheme at its order against its equations written by hand", "[formula][shapes]") {
  // q_i'' = -g sin q_i - k (2 q_i - q_(i-1) - q_(i+1)) - alpha q_i' (one neighbour at either end), integrated by
  // Odeint's dopri5 at 1e-13: a reference that shares nothing with the formula engine but the file's parameters.
  REQUIRE(formula::formula_shape_compiled(6, 0, false));
  const auto model = formula::load_system_file(system_file("pendulum-chain"));
  const auto entry = formula::formula_system_info(model);
  const double g = parameter(*model, "g"), k = parameter(*model, "k"), alpha = parameter(*model, "alpha"),
               a = parameter(*model, "a"), T = entry->horizon({});
  using State = std::array<double, 12>;
  auto rhs = [&](const State& x, State& dx, double) {
    for (int i = 0; i < 6; ++i) {
      double spring = 0;
      if (i > 0) spring += x[std::size_t(i)] - x[std::size_t(i - 1)];
      if (i < 5) spring += x[std::size_t(i)] - x[std::size_t(i + 1)];
      dx[std::size_t(i)] = x[std::size_t(6 + i)];
      dx[std::size_t(6 + i)] = -g * std::sin(x[std::size_t(i)]) - k * spring - alpha * x[std::size_t(6 + i)];
    }
  };
  const double h0 = 0.1, hmin = h0 / 16;
  const long N = step_count(hmin, T);
  Reference ref;
  ref.kind = "hand-written equations, Boost.Odeint dopri5 at 1e-13";
  ref.h = hmin;
  ref.N = N;
  ref.n = 6;
  State x{};
  x[0] = a;
  namespace odeint = boost::numeric::odeint;
  std::vector<double> times;
  for (long j = 0; j <= N; ++j) times.push_back(double(j) * hmin);
  odeint::integrate_times(odeint::make_dense_output(1e-13, 1e-13, odeint::runge_kutta_dopri5<State>()), rhs, x, times.begin(),
                          times.end(), hmin, [&](const State& y, double) { ref.q.insert(ref.q.end(), y.begin(), y.begin() + 6); });
  REQUIRE(ref.q.size() == std::size_t(6 * (N + 1)));
  std::apply([&](auto... gs) {
    for (const auto& scheme : {std::string(generic::scheme_name<decltype(gs)>())...}) {
      const auto hs = halving_sequence(h0, hmin);
      std::vector<double> errs;
      for (double h : hs) errs.push_back(entry->max_error({}, scheme, h, Path::generic, ref));
      const double slope = fit_order(hs, errs).slope;
      const SchemeInfo& info = entry->scheme(scheme);
      INFO("pendulum-chain " << scheme << ": errors " << errs.front() << " ... " << errs.back() << ", fitted order " << slope
                             << " (expected " << info.order << ")");
      if (info.principle.find("Herglotz") != std::string::npos && info.order == 1)
        CHECK(slope > 0.9);
      else
        CHECK(std::abs(slope - info.order) < 0.1);
    }
  }, generic::AllSchemesTuple{});
}
