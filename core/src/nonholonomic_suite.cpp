// The nonholonomic benchmark suite: its problems, their exact observables and invariants (nonholonomic_suite.hpp).
// Each closed form is derived in python/tests/test_nonholonomic_exact.py from the system file's L, rows and force.
#include "geomint/nonholonomic_suite.hpp"

#include <cmath>
#include <filesystem>

#include "geomint/constants.hpp"
#include "geomint/error.hpp"
#include "geomint/formula/formula_registry.hpp"
#include "geomint/generic/system.hpp"

namespace geomint {

namespace {

enum class Kind { disk, sleigh, suslov, oscillator };

Kind kind_of(const SuiteProblem& p) {
  if (p.file == "rolling-disk") return Kind::disk;
  if (p.file == "chaplygin-sleigh") return Kind::sleigh;
  if (p.file == "suslov") return Kind::suslov;
  return Kind::oscillator;
}

// The undamped motion's clock: the damped motion (damping alpha times the kinetic metric, no potential) is the free
// one at s(t) = (1 - e^{-alpha t})/alpha with every velocity times e^{-alpha t}.
double clock(double alpha, double t) { return alpha > 0 ? -std::expm1(-alpha * t) / alpha : t; }

// Invariant k at x = (t, q, q'), in any scalar (double, or duals for the gradient).
template <class S>
S invariant_of(const SuiteSystem& sys, std::size_t k, const std::array<S, 9>& x) {
  using std::cos;
  using std::exp;
  using std::sin;
  const S& t = x[0];
  const S* q = &x[1];
  const S* v = &x[1 + std::size_t(sys.model->n)];
  switch (kind_of(*sys.problem)) {
    case Kind::disk: {
      const double m = sys.param("m"), I = sys.param("I"), J = sys.param("J"), alpha = sys.param("alpha");
      if (k == 0) return (m / 2 * (v[0] * v[0] + v[1] * v[1]) + I / 2 * v[2] * v[2] + J / 2 * v[3] * v[3]) * exp(2 * alpha * t);
      if (k == 1) return v[2] * exp(alpha * t);
      return v[3] * exp(alpha * t);
    }
    case Kind::sleigh: {
      const double m = sys.param("m"), I = sys.param("I"), alpha = sys.param("alpha");
      return (m / 2 * (v[0] * v[0] + v[1] * v[1]) + I / 2 * v[2] * v[2]) * exp(2 * alpha * t);
    }
    case Kind::suslov: {
      const double I1 = sys.param("I1"), I2 = sys.param("I2"), I3 = sys.param("I3"), I13 = sys.param("I13"),
                   I23 = sys.param("I23"), alpha = sys.param("alpha");
      const S w1 = v[0] * sin(q[1]) * sin(q[2]) + v[1] * cos(q[2]), w2 = v[0] * sin(q[1]) * cos(q[2]) - v[1] * sin(q[2]),
              w3 = v[0] * cos(q[1]) + v[2];
      const S E = (I1 * w1 * w1 + I2 * w2 * w2 + I3 * w3 * w3) / 2 + I13 * w1 * w3 + I23 * w2 * w3;
      return E * exp(2 * alpha * t);
    }
    case Kind::oscillator: {
      const double eps = sys.param("epsilon");
      const S H = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + q[0] * q[0] + q[1] * q[1] + q[2] * q[2] +
                   eps * q[0] * q[0] * q[2] * q[2]) / 2;
      const S Hy = (q[1] * q[1] + v[1] * v[1]) / 2;
      if (k == 0) return H;
      if (k == 1) return Hy;
      return H - Hy;
    }
  }
  return S(0);
}

}  // namespace

const std::vector<SuiteProblem>& suite_problems() {
  static const std::vector<SuiteProblem> problems = [] {
    const std::vector<std::string> q4{"x", "y", "theta", "phi"}, sleigh{"theta", "u", "omega"},
        suslov{"omega1", "omega2"}, osc{"y", "ydot"};
    const std::vector<std::string> disk_inv{"E", "theta_dot", "phi_dot"}, energy{"E"}, osc_inv{"H", "Hy", "H-Hy"};
    std::vector<SuiteProblem> p;
    p.push_back({"rolling-disk", "rolling-disk", {{"alpha", 0}, {"T", 20}}, "vertical rolling disk, free", q4, 4, 1, disk_inv, true});
    p.push_back({"rolling-disk-damped", "rolling-disk", {{"T", 20}},
                 "vertical rolling disk, Rayleigh damping alpha times the metric (invariants times e^{alpha t}, e^{2 alpha t})",
                 q4, 4, 1, disk_inv, true});
    p.push_back({"sleigh", "chaplygin-sleigh", {{"alpha", 0}, {"T", 20}}, "Chaplygin sleigh, free", sleigh, 1, 1, energy, true});
    p.push_back({"sleigh-damped", "chaplygin-sleigh", {{"T", 20}}, "Chaplygin sleigh, Rayleigh damping (E e^{2 alpha t})",
                 sleigh, 1, 1, energy, true});
    p.push_back({"suslov", "suslov", {}, "Suslov problem", suslov, 0, 1, energy, true});
    p.push_back({"contact-oscillator", "contact-oscillator", {}, "McLachlan-Perlmutter contact oscillator, epsilon = 0.1", osc, 1, 2,
                 osc_inv, true});
    p.push_back({"nonreversible-oscillator", "nonreversible-oscillator", {},
                 "contact oscillator with Modin-Verdier's gauge term (not reversible in (q, p))", osc, 1, 2, osc_inv, false});
    return p;
  }();
  return problems;
}

const SuiteProblem& find_suite_problem(const std::string& name) {
  std::string known;
  for (const auto& p : suite_problems()) {
    if (p.name == name) return p;
    known += (known.empty() ? "" : ", ") + p.name;
  }
  throw InputError("unknown suite problem '" + name + "' (known: " + known + ")");
}

double SuiteSystem::param(const std::string& name) const {
  for (const auto& [k, v] : values)
    if (k == name) return v;
  throw InputError("suite problem " + problem->name + ": no parameter " + name);
}

SuiteSystem load_suite_system(const SuiteProblem& problem, const std::string& dir) {
  SuiteSystem s;
  s.problem = &problem;
  const std::filesystem::path path = std::filesystem::path(dir) / (problem.file + ".geomint");
  s.model = formula::load_system_file(path);
  s.info = formula::formula_system_info(s.model);
  for (const auto& p : s.model->parameters) s.values.emplace_back(p.name, p.value);
  for (const auto& [k, v] : problem.params) {
    bool found = false;
    for (auto& [name, value] : s.values)
      if (name == k) value = v, found = true;
    if (!found) throw InputError("suite problem " + problem.name + ": " + path.string() + " has no parameter " + k);
  }
  s.info->validate(problem.params);
  if (kind_of(problem) == Kind::oscillator && s.param("alpha") != 0)
    throw InputError("suite problem " + problem.name + ": its invariants are those of alpha = 0");
  return s;
}

SuiteState suite_state(double t, const double* q, const double* v, int n) {
  SuiteState x{};
  x[0] = t;
  for (int i = 0; i < n; ++i) {
    x[std::size_t(1 + i)] = q[i];
    x[std::size_t(1 + n + i)] = v[i];
  }
  return x;
}

std::vector<double> suite_exact(const SuiteSystem& sys, double t) {
  const double alpha = sys.param("alpha"), s = clock(alpha, t), decay = std::exp(-alpha * t);
  switch (kind_of(*sys.problem)) {
    case Kind::disk: {
      const double R = sys.param("R"), th0 = sys.param("theta0"), w0 = sys.param("omega0"), s0 = sys.param("spin0");
      const double th = th0 + w0 * s, rho = R * s0 / w0;
      return {sys.param("x0") + rho * (std::sin(th) - std::sin(th0)), sys.param("y0") - rho * (std::cos(th) - std::cos(th0)),
              th, sys.param("phi0") + s0 * s};
    }
    case Kind::sleigh: {
      const double m = sys.param("m"), a = sys.param("a"), J = sys.param("I") + m * a * a, u0 = sys.param("u0"),
                   w0 = sys.param("omega0");
      const double V = std::sqrt(u0 * u0 + J * w0 * w0 / m), k = m * a * V / J, c = std::atanh(u0 / V);
      const double tau = k * s + c;
      const double heading = std::sqrt(J / m) / a * (std::atan(std::sinh(tau)) - std::atan(std::sinh(c)));
      return {heading, decay * V * std::tanh(tau), decay * V * std::sqrt(m / J) / std::cosh(tau)};
    }
    case Kind::suslov: {
      const double I1 = sys.param("I1"), I2 = sys.param("I2"), I13 = sys.param("I13"), I23 = sys.param("I23"),
                   w10 = sys.param("w10"), w20 = sys.param("w20");
      const double E = (I1 * w10 * w10 + I2 * w20 * w20) / 2, A = std::sqrt(2 * E / I1), B = std::sqrt(2 * E / I2);
      const double star = std::atan2(I23 * B, I13 * A), R = B * std::hypot(I13 * A, I23 * B) / (I1 * A);
      const double chi0 = std::remainder(std::atan2(w20 / B, w10 / A) - star, 2 * geomint::pi);
      const double c = std::atanh(std::sin(chi0));
      const double branch = std::asin(std::tanh(R * s + c));
      const double psi = star + (std::cos(chi0) >= 0 ? branch : geomint::pi - branch);
      return {decay * A * std::cos(psi), decay * B * std::sin(psi)};
    }
    case Kind::oscillator: {
      const double b = std::sqrt(2 * sys.param("Hy"));
      return {b * std::sin(t), b * std::cos(t)};
    }
  }
  return {};
}

std::vector<double> suite_observe(const SuiteSystem& sys, const SuiteState& x) {
  const int n = sys.model->n;
  const double* q = &x[1];
  const double* v = &x[std::size_t(1 + n)];
  switch (kind_of(*sys.problem)) {
    case Kind::disk:
      return {q[0], q[1], q[2], q[3]};
    case Kind::sleigh:
      return {q[2], v[0] * std::cos(q[2]) + v[1] * std::sin(q[2]), v[2]};
    case Kind::suslov:
      return {v[0] * std::sin(q[1]) * std::sin(q[2]) + v[1] * std::cos(q[2]),
              v[0] * std::sin(q[1]) * std::cos(q[2]) - v[1] * std::sin(q[2])};
    case Kind::oscillator:
      return {q[1], v[1]};
  }
  return {};
}

double suite_error(const SuiteSystem& sys, const std::vector<double>& t, const std::vector<double>& q,
                   const std::vector<double>& v) {
  const int n = sys.model->n;
  const std::size_t count = sys.problem->positions > 0 ? sys.problem->positions : sys.problem->observables.size();
  double e = 0;
  for (std::size_t j = 0; j < t.size(); ++j) {
    const auto obs = suite_observe(sys, suite_state(t[j], &q[j * std::size_t(n)], &v[j * std::size_t(n)], n));
    const auto ex = suite_exact(sys, t[j]);
    for (std::size_t i = 0; i < count; ++i) e = std::max(e, std::abs(obs[i] - ex[i]));
  }
  return e;
}

double suite_invariant(const SuiteSystem& sys, std::size_t k, const SuiteState& x, SuiteState* grad) {
  if (k >= sys.problem->invariants.size())
    throw InputError("suite problem " + sys.problem->name + " has " + std::to_string(sys.problem->invariants.size()) +
                     " invariants");
  if (!grad) return invariant_of<double>(sys, k, x);
  double value = 0;
  const Vec<double, 9> X = Eigen::Map<const Vec<double, 9>>(x.data());
  const Vec<double, 9> g = generic::gradient<9, double>(
      [&](const auto& V) {
        using D = typename std::decay_t<decltype(V)>::Scalar;
        std::array<D, 9> a;
        for (int i = 0; i < 9; ++i) a[std::size_t(i)] = V(i);
        return invariant_of<D>(sys, k, a);
      },
      X, &value);
  for (int i = 0; i < 9; ++i) (*grad)[std::size_t(i)] = g(i);
  return value;
}

}  // namespace geomint
