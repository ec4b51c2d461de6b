#include "geomint/error.hpp"
#include "geomint/foucault_diagnostics.hpp"

namespace geomint {

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
      run.turns = std::move(diag.turns());
    });
    return run;
  });
}

}  // namespace geomint
