// The automatic modified equations of the header systems written as formulas (docs/systems/*.geomint) against
// the headers' (through the modified-equation registry), at random points, to order K = 4: the same engine pushes
// its series type (modified/series.hpp) through the formula tapes instead of the header's C++.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <tuple>

#include "geomint/formula/formula_system.hpp"
#include "geomint/modified/automatic.hpp"
#include "geomint/modified/automatic_registry.hpp"

using namespace geomint;

namespace {

std::string system_file(const std::string& name) { return std::string(GEOMINT_SOURCE_DIR) + "/docs/systems/" + name + ".geomint"; }

struct Agreement {
  double worst = 0;     // largest |formula - header| / scale over every coefficient
  double residual = 0;  // the formula engine's self-check, relative to |F|
  int points = 0;
};

// F_k, Z_k, mu_k and the modified constraint phi_k of scheme G at random points near the initial data.
template <class FS, class G>
Agreement compare(const std::string& name, const FS& fs, const ParamValues& pv, int K, unsigned seed) {
  constexpr int n = FS::dof, m = FS::constraints;
  const auto& header = modified::find_modified_system(name);
  const modified::ModifiedEquation<FS, G, modified::registry_max_order> me(fs);
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  const Vec<double, n> q0 = fs.template initial_position<double>(), v0 = fs.template initial_velocity<double>();
  Agreement a;
  for (int k = 0; k < 4; ++k) {
    const double t = 0.5 + u(gen), z = u(gen);
    Vec<double, n> q, v;
    std::vector<double> qv(n), vv(n);
    for (int i = 0; i < n; ++i) {
      qv[std::size_t(i)] = q(i) = q0(i) + u(gen);
      vv[std::size_t(i)] = v(i) = v0(i) + u(gen);
    }
    const modified::ModifiedPoint hp = header.at(pv, generic::scheme_name<G>(), K, t, qv, vv, z, false);
    typename modified::ModifiedEquation<FS, G, modified::registry_max_order>::Result r;
    me.evaluate(t, q, v, z, K, r, true);
    // each order against its own size (the coefficients fall or grow with k): relative differences
    auto rel = [](double x, double y, double scale) { return std::abs(x - y) / (scale > 0 ? scale : 1.0); };
    double fscale = 0;
    for (int j = 0; j <= K; ++j) {
      double s = 0;
      for (int i = 0; i < n; ++i) s = std::max(s, std::abs(hp.F_at(j, i)));
      fscale = std::max(fscale, s);
      for (int i = 0; i < n; ++i) a.worst = std::max(a.worst, rel(r.F[std::size_t(j)](i), hp.F_at(j, i), s));
      if (G::contact) a.worst = std::max(a.worst, rel(r.Z[std::size_t(j)], hp.Z[std::size_t(j)], std::abs(hp.Z[std::size_t(j)])));
      for (int c = 0; c < m; ++c) {
        const double mu = hp.mu[std::size_t(j * m + c)];
        a.worst = std::max(a.worst, rel(r.mu[std::size_t(j)](c), mu, std::abs(mu)));
      }
    }
    if constexpr (m > 0) {
      for (std::size_t j = 0; j * m < hp.phi.size(); ++j)
        for (int c = 0; c < m; ++c) {
          const double ph = hp.phi[j * m + std::size_t(c)];
          a.worst = std::max(a.worst, rel(r.phi[j](c), ph, std::abs(ph) + std::abs(hp.phi[std::size_t(c)])));
        }
    }
    a.residual = std::max(a.residual, r.residual / fscale);
    ++a.points;
  }
  return a;
}

template <class FS, class... G>
void check_system(const std::string& name, const ParamValues& pv) {
  FS fs(formula::load_system_file(system_file(name)));
  for (const auto& [k, v] : pv) fs.set_parameter(k, v);
  unsigned seed = 11;
  ((void)[&] {
    const Agreement a = compare<FS, G>(name, fs, pv, 4, seed++);
    INFO(name << " " << generic::scheme_name<G>() << ": largest relative difference " << a.worst << " at " << a.points
              << " points, self-check residual " << a.residual);
    CHECK(a.points == 4);
    CHECK(a.worst == 0);
    CHECK(a.residual <= 1e-12);
  }(), ...);
}

using generic::ContactLeft;
using generic::ContactTrapezoid;
using generic::LaLeft;
using generic::LaMidpoint;
using generic::LaTrapezoid;

}  // namespace

// Exact: the engine pushes the same series arithmetic through the formula tapes as through the headers' C++
// (the tapes' mixed instructions are the series type's own operations with a constant), and every formula file
// associates as its header does; where a header sums with Eigen's squaredNorm (the particle) Eigen's order for the
// series type is the formula's. Measured: 0 for every coefficient at every point. (The steps differ from the
// headers for the oscillators only through the headers' linear lane, which the modified equations do not use.)
TEST_CASE("modified equations of formula systems are the headers', at random points", "[formula][modified]") {
  check_system<formula::FormulaSystem<1, 0>, LaLeft, ContactLeft, LaMidpoint, LaTrapezoid, ContactTrapezoid>(
      "pendulum", {{"alpha", 0.3}});
  check_system<formula::FormulaSystem<3, 1>, LaLeft, ContactLeft>("knife-edge", {{"alpha", 0.3}});
  check_system<formula::FormulaSystem<2, 1>, LaLeft, ContactLeft>("foucault", {{"alpha", 0.1}});
  check_system<formula::FormulaSystem<2, 1, true>, LaLeft, ContactLeft>("foucault-rotation", {{"alpha", 0.1}, {"y0", 0.3}});
  check_system<formula::FormulaSystem<1, 0>, LaLeft, ContactLeft>("oscillator", {{"alpha", 0.3}});
  check_system<formula::FormulaSystem<1, 0>, LaLeft, ContactLeft>("forced-oscillator", {{"alpha", 0.3}});
  check_system<formula::FormulaSystem<2, 0>, LaLeft, ContactLeft>("coupled-oscillators", {{"kappa", 2}});
  check_system<formula::FormulaSystem<3, 1>, LaLeft, ContactLeft>("particle", {{"alpha", 0.3}});
}
