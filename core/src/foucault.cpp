// The out-of-line parts of the Foucault pendulum's systems (core/include/geomint/systems/foucault.hpp).
#include "geomint/systems/foucault.hpp"

#include <cmath>

#include "geomint/io.hpp"
#include "geomint/reference.hpp"

namespace geomint {

namespace systems {

void FoucaultPendulum::validate() const {
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

double FoucaultPendulum::s() const { return Omega * std::sin(beta_deg * foucault_pi / 180); }

std::vector<std::pair<std::string, std::string>> FoucaultPendulum::header_params() const {
  return {{"m", format_number(m)},
          {"l", format_number(l)},
          {"g", format_number(g)},
          {"beta_deg", format_number(beta_deg)},
          {"Omega", format_number(Omega)},
          {"q0", format_number(x0) + "," + format_number(y0)},
          {"v0", format_number(vx0) + "," + format_number(vy0)}};
}

}  // namespace systems

void validate_foucault_sweep(const systems::FoucaultPendulum& base, const std::vector<double>& hs,
                             const std::vector<double>& alphas) {
  require(!hs.empty(), "give at least one h");
  require(!alphas.empty(), "give at least one alpha");
  for (double h : hs) step_count(h, base.T);
  for (double a : alphas) {
    systems::FoucaultPendulum sc = base;
    sc.alpha = a;
    sc.validate();
  }
}

FoucaultStart parse_foucault_start(const std::string& name) {
  if (name == "legendre") return FoucaultStart::legendre;
  if (name == "taylor") return FoucaultStart::taylor;
  throw InputError("unknown start '" + name + "' (known: legendre taylor)");
}

const char* to_string(FoucaultStart s) { return s == FoucaultStart::legendre ? "legendre" : "taylor"; }

std::vector<std::array<double, 4>> foucault_reference(const systems::FoucaultPendulum& scene,
                                                      const std::vector<double>& times, double tol) {
  scene.validate();
  require_positive(tol, "tol");
  const FoucaultParams<double> p(scene);
  const Vec2<double> q0(scene.x0, scene.y0);
  const Vec2<double> v0 = consistent_velocity(p, q0, Vec2<double>(scene.vx0, scene.vy0));
  using State = std::array<double, 4>;
  return odeint_dense<4>(FoucaultMultiplierOde(p), State{q0(0), q0(1), v0(0), v0(1)}, times, tol);
}

}  // namespace geomint
