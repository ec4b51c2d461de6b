// The largest shapes of formula systems, n = 4 coordinates with m = 2 constraint rows, both kinds: every scheme
// of the core converges at its order against an independent reference, keeps its discrete constraints at
// round-off, and has modified equations whose self-check vanishes at round-off.
//   rolling-disk (rows linear in the velocities): against its closed form (docs/systems/rolling-disk.geomint);
//   double-pendulum-cartesian (two holonomic rods): against the same motion in the angles, an unconstrained
//   system (docs/systems/double-pendulum.geomint), integrated by Boost.Odeint.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <tuple>

#include "geomint/formula/checks.hpp"
#include "geomint/formula/formula_system.hpp"
#include "geomint/generic/stepper.hpp"
#include "geomint/modified/automatic.hpp"
#include "geomint/reference.hpp"
#include "geomint/study.hpp"

using namespace geomint;

namespace {

std::string system_file(const std::string& name) { return std::string(GEOMINT_SOURCE_DIR) + "/docs/systems/" + name + ".geomint"; }

using Disk = formula::FormulaSystem<4, 2>;
using Cartesian = formula::FormulaSystem<4, 2, true>;

// max_j |q_j - q(t_j)| of G's generic steps against `exact(t)`; and the largest |Phi_d| along the run relative to
// the round-off of its terms: for rows in the velocities |A| (|q_j| + |q_{j+1}|)/h + |b| (the chord
// (q_{j+1} - q_j)/h carries eps |q|/h), for holonomic rows the terms of g at q_{j+1}, |A| |q_{j+1}| + 1.
template <class FS, class G, class Exact>
std::pair<double, double> run_error(const FS& fs, double h, double T, Exact&& exact) {
  generic::Stepper<FS, G> st(fs, h);
  st.start(fs.template initial_position<double>(), fs.template initial_velocity<double>());
  const long N = step_count(h, T);
  double err = 0, phi = 0;
  for (long j = 1; j <= N; ++j) {
    const Vec<double, 4> q0 = st.state().q;
    const double t0 = st.state().t;
    st.step();
    const Vec<double, 4>& q1 = st.state().q;
    err = std::max(err, (q1 - exact(st.state().t)).template lpNorm<Eigen::Infinity>());
    const Vec<double, 2> d = generic::discrete_constraint<FS, typename G::quadrature, double>(fs, t0, h, q0, q1);
    const Mat<double, 2, 4> A = fs.constraint_matrix(t0, q0).cwiseAbs();
    const Vec<double, 2> scale = FS::is_holonomic ? Vec<double, 2>(A * q1.cwiseAbs() + Vec<double, 2>::Ones())
                                                  : Vec<double, 2>(A * (q0.cwiseAbs() + q1.cwiseAbs()) / h +
                                                                   fs.constraint_offset(t0, q0).cwiseAbs());
    phi = std::max(phi, d.cwiseAbs().cwiseQuotient(scale).maxCoeff());
  }
  return {err, phi};
}

// Every scheme: the fitted order of the error over h = h0 ... h0/16, and Phi_d at round-off. The first-order
// schemes: LA at 1; contact at least 1 (its O(h) terms can be small enough to show a higher slope, as on the
// damped oscillator of Figure 1).
template <class FS, class Exact>
void check_orders(const std::string& name, const FS& fs, double h0, double T, Exact&& exact) {
  std::apply([&](auto... g) {
    ((void)[&] {
      using G = decltype(g);
      const auto hs = halving_sequence(h0, h0 / 16);
      std::vector<double> errs;
      double phi = 0;
      for (double h : hs) {
        const auto [e, p] = run_error<FS, G>(fs, h, T, exact);
        errs.push_back(e);
        phi = std::max(phi, p);
      }
      const double slope = fit_order(hs, errs).slope;
      INFO(name << " " << generic::scheme_name<G>() << ": errors " << errs.front() << " ... " << errs.back() << ", fitted order "
                << slope << " (expected " << G::order << "), max |Phi_d| / its round-off scale " << phi);
      if (G::contact && G::order == 1)
        CHECK(slope > 0.9);
      else
        CHECK(std::abs(slope - G::order) < 0.1);
      CHECK(phi <= 16 * 2.220446049250313e-16);  // the stepper's kappa eps
    }(), ...);
  }, generic::AllSchemesTuple{});
}

}  // namespace

TEST_CASE("rolling disk (n = 4, m = 2 rows in the velocities): every scheme at its order against the closed form",
          "[formula][shapes]") {
  const Disk fs(formula::load_system_file(system_file("rolling-disk")));
  fs.validate();
  const double R = fs.parameter("R"), alpha = fs.parameter("alpha"), x0 = fs.parameter("x0"), y0 = fs.parameter("y0"),
               th0 = fs.parameter("theta0"), ph0 = fs.parameter("phi0"), w0 = fs.parameter("omega0"),
               s0 = fs.parameter("spin0"), T = fs.horizon();
  auto exact = [&](double t) {
    const double decay = (1 - std::exp(-alpha * t)) / alpha, th = th0 + w0 * decay;
    return Vec<double, 4>(x0 + R * s0 / w0 * (std::sin(th) - std::sin(th0)), y0 - R * s0 / w0 * (std::cos(th) - std::cos(th0)), th,
                          ph0 + s0 * decay);
  };
  check_orders("rolling-disk", fs, 0.1, T, exact);
}

TEST_CASE("Cartesian double pendulum (n = 4, m = 2 holonomic rods): every scheme at its order against the angle form",
          "[formula][shapes]") {
  const Cartesian fs(formula::load_system_file(system_file("double-pendulum-cartesian")));
  fs.validate();
  const auto angles = formula::load_system_file(system_file("double-pendulum"));
  const formula::FormulaSystem<2, 0> as(angles);
  const double l1 = fs.parameter("l1"), l2 = fs.parameter("l2"), T = fs.horizon();
  // the reference: Odeint (dopri5, tol 1e-13) on the angle form's equations, on a grid fine enough for every h
  const double h0 = 0.05, hmin = h0 / 16;
  std::vector<double> times;
  for (long j = 0; j <= step_count(hmin, T); ++j) times.push_back(double(j) * hmin);
  const auto& pv = as.parameter_table();
  auto rhs = [&](const std::array<double, 4>& x, std::array<double, 4>& dx, double t) {
    const auto a = formula::continuous_acceleration(*angles, pv, t, {x[0], x[1]}, {x[2], x[3]}, 0, false);
    dx = {x[2], x[3], a.a[0], a.a[1]};
  };
  const Vec<double, 2> th0 = as.initial_position<double>(), w0 = as.initial_velocity<double>();
  const auto ref = odeint_dense<4>(rhs, {th0(0), th0(1), w0(0), w0(1)}, times, 1e-13);
  auto exact = [&](double t) {
    const auto& x = ref[std::size_t(std::lround(t / hmin))];
    const double x1 = l1 * std::sin(x[0]), y1 = -l1 * std::cos(x[0]);
    return Vec<double, 4>(x1, y1, x1 + l2 * std::sin(x[1]), y1 - l2 * std::cos(x[1]));
  };
  // the references agree: the Cartesian system's own continuous equations (the holonomic rows, their drift and
  // multipliers, at run time) integrated the same way, against the angle form
  const auto& cv = fs.parameter_table();
  auto crhs = [&](const std::array<double, 8>& x, std::array<double, 8>& dx, double t) {
    const auto a = formula::continuous_acceleration(fs.model(), cv, t, {x[0], x[1], x[2], x[3]}, {x[4], x[5], x[6], x[7]}, 0, false);
    dx = {x[4], x[5], x[6], x[7], a.a[0], a.a[1], a.a[2], a.a[3]};
  };
  const Vec<double, 4> q0 = fs.initial_position<double>(), v0 = fs.initial_velocity<double>();
  const auto cref = odeint_dense<8>(crhs, {q0(0), q0(1), q0(2), q0(3), v0(0), v0(1), v0(2), v0(3)}, times, 1e-13);
  double dref = 0;
  for (std::size_t j = 0; j < times.size(); ++j)
    for (int i = 0; i < 4; ++i) dref = std::max(dref, std::abs(cref[j][std::size_t(i)] - exact(times[j])(i)));
  INFO("Cartesian against angle form, continuous: " << dref);
  CHECK(dref < 1e-9);
  check_orders("double-pendulum-cartesian", fs, h0, T, exact);
}

TEST_CASE("n = 4, m = 2 formula systems: continuous equations and modified equations at round-off", "[formula][shapes]") {
  std::mt19937 gen(3);
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  auto check = [&](const auto& fs) {
    using FS = std::decay_t<decltype(fs)>;
    const Vec<double, 4> q0 = fs.template initial_position<double>(), v0 = fs.template initial_velocity<double>();
    for (int k = 0; k < 3; ++k) {
      Vec<double, 4> q = q0, v = v0;
      for (int i = 0; i < 4; ++i) {
        q(i) += u(gen);
        v(i) += u(gen);
      }
      const double t = 0.5 + u(gen);
      // the typed equations (generic::acceleration, fixed sizes) and the run-time ones (checks.cpp)
      const auto a = generic::acceleration(fs, t, q, v);
      const auto b = formula::continuous_acceleration(fs.model(), fs.parameter_table(), t, {q(0), q(1), q(2), q(3)},
                                                      {v(0), v(1), v(2), v(3)}, 0, false);
      for (int i = 0; i < 4; ++i) CHECK(std::abs(a.a(i) - b.a[std::size_t(i)]) <= 1e-13 * (1 + a.a.template lpNorm<Eigen::Infinity>()));
      std::apply([&](auto... g) {
        ((void)[&] {
          using G = decltype(g);
          const modified::ModifiedEquation<FS, G, 4> me(fs);
          typename modified::ModifiedEquation<FS, G, 4>::Result r;
          me.evaluate(t, q, v, 0.1, 4, r, true);
          double F = 0;
          for (int j = 0; j <= 4; ++j) F = std::max(F, r.F[std::size_t(j)].template lpNorm<Eigen::Infinity>());
          INFO(fs.name() << " " << generic::scheme_name<G>() << ": self-check " << r.residual << " against |F| " << F);
          CHECK(r.residual <= 1e-12 * F);
          // order 0 is the continuous Lagrange-d'Alembert (or Herglotz) acceleration
          CHECK((r.F[0] - a.a).template lpNorm<Eigen::Infinity>() <= (G::contact ? 1.0 : 1e-12) * (1 + F));
        }(), ...);
      }, std::tuple<generic::LaLeft, generic::ContactLeft>{});
    }
  };
  check(Disk(formula::load_system_file(system_file("rolling-disk"))));
  check(Cartesian(formula::load_system_file(system_file("double-pendulum-cartesian"))));
}
