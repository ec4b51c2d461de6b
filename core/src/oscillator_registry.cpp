#include "geomint/oscillator_registry.hpp"

#include <algorithm>
#include <cmath>

#include "geomint/integrate.hpp"
#include "geomint/oscillator_schemes.hpp"
#include "geomint/schemes/conformal_strang.hpp"

namespace geomint {
namespace {

template <class S>
OscillatorTrajectory run(const OscillatorScene& sc, double h) {
  sc.validate();
  const long N = step_count(h, sc.T);
  OscillatorTrajectory tr;
  for (auto* v : {&tr.t, &tr.q, &tr.p, &tr.z}) v->resize(static_cast<size_t>(N + 1));
  OscState<double> s{sc.q0, sc.p0, 0.0};
  integrate_const<S>(s, h, N, sc.alpha, [&](long j, const OscState<double>& x) {
    const auto k = static_cast<size_t>(j);
    tr.t[k] = static_cast<double>(j) * h;
    tr.q[k] = x.q;
    tr.p[k] = x.p;
    tr.z[k] = x.z;
  });
  return tr;
}

template <class S>
double max_error(const OscillatorScene& sc, double h) {
  sc.validate();
  const long N = step_count(h, sc.T);
  OscState<double> s{sc.q0, sc.p0, 0.0};
  double err = 0;
  integrate_const<S>(s, h, N, sc.alpha, [&](long j, const OscState<double>& x) {
    const double t = static_cast<double>(j) * h;
    err = std::max(err, std::abs(x.q - oscillator_exact(sc.alpha, sc.q0, sc.p0, t).q));
  });
  return err;
}

template <class S>
double integrate_only(const OscillatorScene& sc, double h) {
  const long N = step_count(h, sc.T);
  OscState<double> s{sc.q0, sc.p0, 0.0};
  integrate_const<S>(s, h, N, sc.alpha, [](long, const OscState<double>&) {});
  return s.q;
}

template <class S>
OscillatorSchemeInfo entry(const char* description) {
  return {S::name, S::order, description, &run<S>, &max_error<S>, &one_step_matrix<S>, &integrate_only<S>};
}

}  // namespace

const std::vector<OscillatorSchemeInfo>& oscillator_schemes() {
  static const std::vector<OscillatorSchemeInfo> all = {
      entry<schemes::La>("Lagrange-d'Alembert from the forced discrete EL equations (1), derived"),
      entry<schemes::LaPrinted>("eq. (7) as printed, denominator 1+alpha (does not converge)"),
      entry<schemes::Contact>("contact integrator, discrete Herglotz, eq. (10)"),
      entry<schemes::Leapfrog>("implicit leapfrog, second order (the paper's reference at h/10)"),
      entry<schemes::LaMidpoint>("midpoint forced variational integrator, second order"),
      entry<schemes::ContactSymmetric>("symmetric (trapezoidal) contact integrator, second order"),
      entry<schemes::ConformalStrang>("conformal symplectic Strang splitting (README example), second order"),
  };
  return all;
}

const OscillatorSchemeInfo& find_oscillator_scheme(const std::string& name) {
  const auto& all = oscillator_schemes();
  for (const auto& s : all)
    if (s.name == name) return s;
  std::string known;
  for (const auto& s : all) known += (known.empty() ? "" : ", ") + s.name;
  throw InputError("unknown scheme '" + name + "' (known: " + known + ")");
}

const std::vector<std::string>& oscillator_defaults(const std::string& study) {
  static const std::vector<std::pair<std::string, std::vector<std::string>>> defaults = {
      {"fig1", {"la", "la-printed", "contact"}},
      {"convergence", {"la", "contact", "la-printed", "leapfrog", "la-midpoint", "contact-sym"}},
      {"work_precision", {"la", "contact", "la-midpoint", "contact-sym", "leapfrog"}},
      {"stability", {"la", "la-printed", "contact", "la-midpoint", "contact-sym", "leapfrog", "conformal-strang"}},
      {"bench", {"la", "contact", "la-printed", "la-midpoint", "contact-sym", "leapfrog"}},
  };
  for (const auto& [k, v] : defaults)
    if (k == study) return v;
  throw InputError("no default scheme list for study '" + study + "'");
}

std::string join_names(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : " ") + n;
  return s;
}

}  // namespace geomint
