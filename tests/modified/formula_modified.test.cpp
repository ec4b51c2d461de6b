// The automatic modified equations of the header systems written as formulas (docs/systems/*.geomint) against
// the headers', both through the modified-equation registry (as modified_equation and the Python module ask for
// them), at random points, to order K = 4: the same engine pushes its series type (modified/series.hpp) through
// the formula tapes instead of the header's C++.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "geomint/formula/model.hpp"
#include "geomint/modified/automatic_registry.hpp"
#include "geomint/modified/formula_modified.hpp"

using namespace geomint;

namespace {

std::string system_file(const std::string& name) { return std::string(GEOMINT_SOURCE_DIR) + "/docs/systems/" + name + ".geomint"; }

struct Agreement {
  double worst = 0;     // largest |formula - header| / scale over every coefficient
  double residual = 0;  // the formula engine's self-check, relative to |F|
  int points = 0;
};

// F_k, Z_k, mu_k and the modified constraint phi_k of `scheme` at random points near q0, v0.
Agreement compare(const modified::ModifiedSystem& formulas, const modified::ModifiedSystem& header, const ParamValues& pv,
                  const std::string& scheme, const std::vector<double>& q0, const std::vector<double>& v0, int K, unsigned seed) {
  const int n = header.dof, m = header.constraints;
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  Agreement a;
  for (int k = 0; k < 4; ++k) {
    const double t = 0.5 + u(gen), z = u(gen);
    std::vector<double> q(q0), v(v0);
    for (int i = 0; i < n; ++i) {
      q[std::size_t(i)] += u(gen);
      v[std::size_t(i)] += u(gen);
    }
    const modified::ModifiedPoint hp = header.at(pv, scheme, K, t, q, v, z, false);
    const modified::ModifiedPoint fp = formulas.at(pv, scheme, K, t, q, v, z, true);
    REQUIRE(fp.F.size() == hp.F.size());
    REQUIRE(fp.Z.size() == hp.Z.size());
    REQUIRE(fp.mu.size() == hp.mu.size());
    REQUIRE(fp.phi.size() == hp.phi.size());
    // each order against its own size (the coefficients fall or grow with k): relative differences
    auto rel = [](double x, double y, double scale) { return std::abs(x - y) / (scale > 0 ? scale : 1.0); };
    double fscale = 0;
    for (int j = 0; j <= K; ++j) {
      double s = 0;
      for (int i = 0; i < n; ++i) s = std::max(s, std::abs(hp.F_at(j, i)));
      fscale = std::max(fscale, s);
      for (int i = 0; i < n; ++i) a.worst = std::max(a.worst, rel(fp.F_at(j, i), hp.F_at(j, i), s));
      if (hp.contact) a.worst = std::max(a.worst, rel(fp.Z[std::size_t(j)], hp.Z[std::size_t(j)], std::abs(hp.Z[std::size_t(j)])));
      for (int c = 0; c < m; ++c) {
        const double mu = hp.mu[std::size_t(j * m + c)];
        a.worst = std::max(a.worst, rel(fp.mu[std::size_t(j * m + c)], mu, std::abs(mu)));
      }
    }
    for (std::size_t j = 0; m > 0 && j * std::size_t(m) < hp.phi.size(); ++j)
      for (int c = 0; c < m; ++c) {
        const double ph = hp.phi[j * std::size_t(m) + std::size_t(c)];
        a.worst = std::max(a.worst, rel(fp.phi[j * std::size_t(m) + std::size_t(c)], ph, std::abs(ph) + std::abs(hp.phi[std::size_t(c)])));
      }
    a.residual = std::max(a.residual, fp.residual / fscale);
    ++a.points;
  }
  return a;
}

// Schemes `schemes` of system `name` at pv, around the system's initial data.
void check_system(const std::string& name, const ParamValues& pv, const std::vector<std::string>& schemes) {
  const auto entry = modified::formula_modified_system(formula::load_system_file(system_file(name)));
  const auto& header = modified::find_modified_system(name);
  REQUIRE(entry->dof == header.dof);
  REQUIRE(entry->constraints == header.constraints);
  // near the initial data: the header's run starts there (the formula file's [initial] is the header's)
  const auto& sys = find_system(name);
  const Run start = sys.run(pv, "la", sys.horizon(pv) / 1000, Path::generic, 1000);
  const std::vector<double> q0(start.q.begin(), start.q.begin() + header.dof), v0(start.v.begin(), start.v.begin() + header.dof);
  unsigned seed = 11;
  for (const auto& scheme : schemes) {
    const Agreement a = compare(*entry, header, pv, scheme, q0, v0, 4, seed++);
    INFO(name << " " << scheme << ": largest relative difference " << a.worst << " at " << a.points << " points, self-check residual "
              << a.residual);
    CHECK(a.points == 4);
    CHECK(a.worst == 0);
    CHECK(a.residual <= 1e-12);
  }
}

}  // namespace

// Exact: the engine pushes the same series arithmetic through the formula tapes as through the headers' C++
// (the tapes' mixed instructions are the series type's own operations with a constant), and every formula file
// associates as its header does; where a header sums with Eigen's squaredNorm (the particle) Eigen's order for the
// series type is the formula's. Measured: 0 for every coefficient at every point. (The steps differ from the
// headers for the oscillators only through the headers' linear lane, which the modified equations do not use.)
TEST_CASE("modified equations of formula systems are the headers', at random points", "[formula][modified]") {
  check_system("pendulum", {{"alpha", 0.3}}, {"la", "contact", "la-midpoint", "la-trapezoid", "contact-trapezoid"});
  check_system("knife-edge", {{"alpha", 0.3}}, {"la", "contact"});
  check_system("foucault", {{"alpha", 0.1}}, {"la", "contact"});
  check_system("foucault-rotation", {{"alpha", 0.1}, {"y0", 0.3}}, {"la", "contact"});
  check_system("oscillator", {{"alpha", 0.3}}, {"la", "contact"});
  check_system("forced-oscillator", {{"alpha", 0.3}}, {"la", "contact"});
  check_system("coupled-oscillators", {{"kappa", 2}}, {"la", "contact"});
  check_system("particle", {{"alpha", 0.3}}, {"la", "contact"});
}
