#include "geomint/foucault.hpp"

#include "geomint/io.hpp"

#include <cmath>
#include <sstream>

#include <gsl/gsl_fit.h>

#include "geomint/reference.hpp"

namespace geomint {

void validate_foucault_sweep(const FoucaultScene& base, const std::vector<double>& hs, const std::vector<double>& alphas) {
  require(!hs.empty(), "give at least one h");
  require(!alphas.empty(), "give at least one alpha");
  for (double h : hs) step_count(h, base.T);
  for (double a : alphas) {
    FoucaultScene sc = base;
    sc.alpha = a;
    sc.validate();
  }
}

std::vector<std::pair<std::string, std::string>> foucault_scene_params(const FoucaultScene& sc) {
  return {{"m", format_number(sc.m)},
          {"l", format_number(sc.l)},
          {"g", format_number(sc.g)},
          {"beta_deg", format_number(sc.beta_deg)},
          {"Omega", format_number(sc.Omega)},
          {"q0", format_number(sc.x0) + "," + format_number(sc.y0)},
          {"v0", format_number(sc.vx0) + "," + format_number(sc.vy0)}};
}

void FoucaultScene::validate() const {
  require_positive(m, "m");
  require_positive(l, "l");
  require_positive(g, "g");
  require(std::isfinite(beta_deg) && std::abs(beta_deg) <= 90,
          "beta must be a latitude in [-90, 90] degrees, got " + show(beta_deg));
  require_finite(Omega, "Omega");
  require_nonnegative(alpha, "alpha");
  require_finite(x0, "x0");
  require_finite(y0, "y0");
  require_finite(vx0, "vx0");
  require_finite(vy0, "vy0");
  require(x0 * x0 + y0 * y0 > 0, "q0 must not be the origin: the constraint (13) gives no equation for lambda there");
  require_positive(T, "T");
}

double FoucaultScene::s() const { return Omega * std::sin(beta_deg * foucault_pi / 180); }

FoucaultStart parse_foucault_start(const std::string& name) {
  if (name == "legendre") return FoucaultStart::legendre;
  if (name == "taylor") return FoucaultStart::taylor;
  throw InputError("unknown start '" + name + "' (known: legendre taylor)");
}

const char* to_string(FoucaultStart s) { return s == FoucaultStart::legendre ? "legendre" : "taylor"; }

FoucaultConstraint parse_foucault_constraint(const std::string& name) {
  if (name == "paper") return FoucaultConstraint::paper;
  if (name == "rotation") return FoucaultConstraint::rotation;
  throw InputError("unknown constraint discretization '" + name + "' (known: paper rotation)");
}

const char* to_string(FoucaultConstraint c) { return c == FoucaultConstraint::paper ? "paper" : "rotation"; }

const std::vector<std::string>& foucault_scheme_names() {
  static const std::vector<std::string> names{schemes::LaNh::name, schemes::ContactNh::name};
  return names;
}

double fit_precession_rate(const std::vector<FoucaultTurn>& turns, int* points) {
  std::vector<double> t, a;
  for (const auto& k : turns)
    if (std::isfinite(k.angle)) {
      t.push_back(k.t);
      a.push_back(k.angle);
    }
  if (points) *points = static_cast<int>(t.size());
  if (t.size() < 3) return std::nan("");
  double c0, c1, cov00, cov01, cov11, sumsq;
  gsl_fit_linear(t.data(), 1, a.data(), 1, t.size(), &c0, &c1, &cov00, &cov01, &cov11, &sumsq);
  return c1;
}

FoucaultRun run_foucault(const std::string& scheme, const FoucaultScene& scene, double h, FoucaultStart start,
                         long sample_every, FoucaultConstraint constraint) {
  scene.validate();
  const long N = step_count(h, scene.T);
  require(sample_every >= 1, "sample_every must be a positive integer");
  return visit_foucault_scheme(scheme, [&](auto s) {
    using Scheme = decltype(s);
    const FoucaultParams<double> p(scene);
    const Vec2<double> q0(scene.x0, scene.y0), v0(scene.vx0, scene.vy0);
    FoucaultDiagnostics<double> diag(p, h, N, sample_every, q0, v0);
    integrate_foucault<Scheme>(p, q0, v0, h, N, start, diag, constraint);
    FoucaultRun run;
    run.summary = diag.summary();
    run.samples = std::move(diag.samples);
    run.turns = std::move(diag.turns);
    return run;
  });
}

std::vector<std::array<double, 4>> foucault_reference(const FoucaultScene& scene, const std::vector<double>& times,
                                                      double tol) {
  scene.validate();
  require_positive(tol, "tol");
  const FoucaultParams<double> p(scene);
  const Vec2<double> q0(scene.x0, scene.y0);
  const Vec2<double> v0 = consistent_velocity(p, q0, Vec2<double>(scene.vx0, scene.vy0));
  using State = std::array<double, 4>;
  return odeint_dense<4>(FoucaultMultiplierOde(p),
      State{q0(0), q0(1), v0(0), v0(1)}, times, tol);
}

}  // namespace geomint
