// The out-of-line parts of the Foucault pendulum (core/include/geomint/systems/foucault/): the plane record's fit,
// the measures, the reference, the start, the sweep check.
#include "geomint/systems/foucault.hpp"

#include <cmath>

#include <gsl/gsl_fit.h>

#include "geomint/constants.hpp"
#include "geomint/io.hpp"
#include "geomint/reference.hpp"

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

namespace systems {

std::vector<MeasureInfo> FoucaultPendulum::Measures::info() {
  return {{"energy_err", "max_j |E_{j+1/2} - E_ref(t_{j+1/2})| / E0, chord energy"},
          {"plane_err", "max |angle(q_j) - angle(q_ref(t_j))| mod pi over |q_ref| >= |q0| e^{-alpha t/2}/2 (rad)"},
          {"rate_rel_err", "|fitted precession rate / (-Omega sin beta) - 1| over the turning points"},
          {"min_r", "min_j |q_j| (m)"}};
}

FoucaultPendulum::Measures::Measures(const FoucaultPendulum& sys, double h, long N, const Reference& ref)
    : p_(sys), ref_(ref), h_(h), alpha_(sys.alpha), s_(sys.s()), stride_(ref.index(1, h)) {
  require(ref.n == 2 && ref.v.size() == ref.q.size(), "the Foucault measures need a reference with velocities");
  require(stride_ % 2 == 0, "the Foucault measures need a reference on a grid of h/2 (its energy at t_{j+1/2})");
  const Vec2<double> q0(sys.x0, sys.y0);
  r0_ = q0.norm();
  E0_ = foucault_energy(p_, q0, consistent_velocity(p_, q0, Vec2<double>(sys.vx0, sys.vy0)));
  min_r_ = r0_;
  // turning points come twice a period; at most one a step
  const double period = 2 * geomint::pi / std::sqrt(std::abs(p_.w2 - p_.s * p_.s));
  const double turns = std::min(4 * static_cast<double>(N) * h / period, static_cast<double>(N));
  plane_.turns.reserve(static_cast<std::size_t>(std::isfinite(turns) ? turns : static_cast<double>(N)) + 16);
}

void FoucaultPendulum::Measures::operator()(long j, double t, const Vec<double, 2>& qn) {
  if (j == 0) {
    qm_ = q_ = qn;
    t_ = t;
    return;
  }
  // the step j - 1 -> j: q_ = q_{j-1} at t_ = t_{j-1}, qm_ = q_{j-2} (q_0 itself for the first step, where the
  // turning-point test does not look back)
  const std::size_t k = static_cast<std::size_t>(ref_.index(j - 1, h_));
  const std::size_t mid = 2 * (k + static_cast<std::size_t>(stride_ / 2));
  const Vec2<double> rq(ref_.q[mid], ref_.q[mid + 1]), rv(ref_.v[mid], ref_.v[mid + 1]);
  const double E = chord_energy(p_, q_, Vec2<double>(qn), h_);
  energy_err_ = std::max(energy_err_, std::abs(E - foucault_energy<double>(p_, rq, rv)) / E0_);
  const double rx = ref_.q[2 * k], ry = ref_.q[2 * k + 1];
  if (std::hypot(rx, ry) >= r0_ * std::exp(-alpha_ * t_ / 2) / 2)
    plane_err_ = std::max(plane_err_, std::abs(nearest_branch(std::atan2(q_(1), q_(0)) - std::atan2(ry, rx), 0.0, geomint::pi)));
  const double rn = qn.norm();
  min_r_ = std::min(min_r_, rn);
  plane_.observe(j - 1, t_, qm_.norm(), q_(0), q_(1), q_.norm(), rn, E);
  qm_ = q_;
  q_ = qn;
  t_ = t;
}

std::vector<double> FoucaultPendulum::Measures::values() const {
  const double rate = plane_.rate();
  return {energy_err_, plane_err_, std::isfinite(rate) ? std::abs(rate / -s_ - 1) : missing_value, min_r_};
}

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

double FoucaultPendulum::s() const { return Omega * std::sin(beta_deg * geomint::pi / 180); }

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
