#include "geomint/error.hpp"
#include "geomint/foucault_diagnostics.hpp"

#include <gsl/gsl_fit.h>

namespace geomint {

double fit_precession_rate(const std::vector<FoucaultTurn>& turns, int* points) {
  std::vector<double> t, a;
  for (const auto& k : turns)
    if (std::isfinite(k.angle)) {
      t.push_back(k.t);
      a.push_back(k.angle);
    }
  if (points) *points = static_cast<int>(t.size());
  if (t.size() < 3) return missing_value;
  double c0, c1, cov00, cov01, cov11, sumsq;
  gsl_fit_linear(t.data(), 1, a.data(), 1, t.size(), &c0, &c1, &cov00, &cov01, &cov11, &sumsq);
  return c1;
}

FoucaultRun run_foucault(const std::string& system, const std::string& scheme, const systems::FoucaultPendulum& scene,
                         double h, FoucaultStart start, long sample_every) {
  scene.validate();
  const long N = step_count(h, scene.T);
  require(sample_every >= 1, "sample_every must be a positive integer");
  return systems::visit_foucault_system(system, [&](auto s) {
    using Sys = decltype(s);
    FoucaultRun run;
    generic::visit_closed_form<Sys>(scheme, [&](auto c) {
      using C = decltype(c);
      Sys sys;
      static_cast<systems::FoucaultPendulum&>(sys) = scene;
      const FoucaultParams<double> p(sys);
      const Vec2<double> q0(scene.x0, scene.y0), v0(scene.vx0, scene.vy0);
      FoucaultDiagnostics<Sys, double> diag(p, h, N, sample_every, q0, v0);
      systems::run_closed_form<C>(sys, p, q0, v0, h, N, start, diag);
      run.summary = diag.summary();
      run.samples = std::move(diag.samples);
      run.turns = std::move(diag.turns);
    });
    return run;
  });
}

}  // namespace geomint
