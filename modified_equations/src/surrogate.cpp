// The non-template parts of the surrogate construction (surrogate.hpp, surrogate_engine.hpp): the symbols, the
// system file a surrogate is written as, the calculus the corrections use, and the dispatch to the compiled shapes.
#include "geomint/modified/surrogate_engine.hpp"

#include <cmath>
#include <random>
#include <sstream>

#include "geomint/io.hpp"
#include "geomint/modified/formula_modified.hpp"
#include "geomint/study.hpp"

namespace geomint::modified {

// One function per compiled shape (modified_equations/CMakeLists.txt, GEOMINT_SURROGATE_SHAPES), each defined in
// its generated unit.
#define GEOMINT_SURROGATE_SHAPE(N, M, H)                                                                              \
  SurrogateSystem surrogate_shape_##N##_##M##_##H(const std::shared_ptr<const formula::FormulaModel>&, const std::string&, \
                                                  int, double, double);
#include "modified/surrogate_shapes.def"
#undef GEOMINT_SURROGATE_SHAPE

namespace surrogate_detail {

namespace {
std::string tex_of(const std::string& name) {
  static const char* greek[] = {"alpha", "beta", "gamma", "delta", "epsilon", "kappa", "lambda", "mu", "nu", "xi",
                                "rho",   "sigma", "tau",  "phi",   "psi",     "omega", "theta",  "eta", "zeta", "chi"};
  for (const char* g : greek)
    if (name == g) return std::string("\\") + g;
  return name.size() > 1 ? "\\mathrm{" + name + "}" : name;
}
}  // namespace

// The step is a parameter named `step` (not h: programs have options --h and a system's parameters become options).
Symbols::Symbols(const formula::FormulaModel& base) : t("t"), z("z"), h("step") {
  step = base.parameter_index("step") >= 0 ? "surrogate_step" : "step";
  h = GiNaC::symbol(step, "h");
  for (int i = 1; i <= base.n; ++i) {
    q.emplace_back("q" + std::to_string(i), "q_{" + std::to_string(i) + "}");
    v.emplace_back("v" + std::to_string(i), "\\dot{q}_{" + std::to_string(i) + "}");
  }
  for (const auto& p : base.parameters) {
    names.push_back(p.name);
    params.emplace_back(p.name, tex_of(p.name));
  }
}

namespace {
std::string print(const ex& e) { return formula_text(display_form(e)); }
}  // namespace

formula::SystemDescription describe(const Data& d, const Symbols& sy, const formula::FormulaModel& base,
                                    const std::string& name, const std::string& description, double step) {
  formula::SystemDescription s;
  s.name = name;
  s.description = description;
  s.coordinates = d.n;
  s.origin.source = name;
  for (const auto& p : base.parameters)
    s.parameters.push_back({p.name, formula::formula_text(format_number(p.value), "parameter " + p.name), p.doc});
  s.parameters.push_back({sy.step, formula::formula_text(format_number(step), "parameter " + sy.step),
                          "the step: a run sets it to the step it takes (the surrogate is built for it)"});
  s.lagrangian = formula::formula_text(print(d.L), "L");
  if (d.has_herglotz) s.herglotz = formula::formula_text(print(d.Hg), "herglotz");
  s.energy = formula::formula_text(print(d.E), "E");
  if (d.has_force)
    for (int i = 0; i < d.n; ++i)
      s.force.push_back(formula::formula_text(print(d.F[static_cast<std::size_t>(i)]), "F" + std::to_string(i + 1)));
  s.constraint_kind = d.holonomic ? formula::ConstraintKind::holonomic : formula::ConstraintKind::velocity;
  for (int c = 0; c < d.m; ++c)
    s.constraints.push_back(formula::formula_text(print(d.phi[static_cast<std::size_t>(c)]),
                                                  (d.holonomic ? "g" : "phi") + std::to_string(c + 1)));
  for (int i = 0; i < d.n; ++i) {
    s.initial_q.push_back(formula::formula_text(print(d.q0[static_cast<std::size_t>(i)]), "q" + std::to_string(i + 1)));
    s.initial_v.push_back(formula::formula_text(print(d.v0[static_cast<std::size_t>(i)]), "v" + std::to_string(i + 1)));
  }
  return s;
}

std::string system_file_text(const formula::SystemDescription& d) {
  std::ostringstream os;
  os << "# " << d.description << "\n[system]\nname = " << d.name << "\ndescription = " << d.description
     << "\ncoordinates = " << d.coordinates << "\n\n[parameters]\n";
  for (const auto& p : d.parameters) os << p.name << " = " << p.value.text << (p.doc.empty() ? "" : "  # " + p.doc) << "\n";
  os << "\n[dynamics]\nL = " << d.lagrangian.text << "\n";
  if (d.herglotz.given()) os << "herglotz = " << d.herglotz.text << "\n";
  for (std::size_t i = 0; i < d.force.size(); ++i) os << "F" << i + 1 << " = " << d.force[i].text << "\n";
  if (d.energy.given()) os << "E = " << d.energy.text << "\n";
  if (!d.constraints.empty()) {
    os << "\n[constraints]\n";
    const char* key = d.constraint_kind == formula::ConstraintKind::holonomic ? "g" : "phi";
    for (std::size_t c = 0; c < d.constraints.size(); ++c) os << key << c + 1 << " = " << d.constraints[c].text << "\n";
  }
  os << "\n[initial]\n";
  for (std::size_t i = 0; i < d.initial_q.size(); ++i) os << "q" << i + 1 << " = " << d.initial_q[i].text << "\n";
  for (std::size_t i = 0; i < d.initial_v.size(); ++i) os << "v" << i + 1 << " = " << d.initial_v[i].text << "\n";
  return os.str();
}

SurrogateTerm term(const std::string& quantity, int k, const ex& e, const Symbols&) {
  const ex f = display_form(e);
  return {quantity, k, formula_text(f), formula_mathematica(f), formula_latex(f)};
}

bool zero(const ex& e) { return simplify_coefficient(e).is_zero(); }

namespace {
std::vector<ex> euler_lagrange(const ex& l, const std::vector<ex>& a, const Symbols& sy) {
  const std::size_t n = sy.q.size();
  std::vector<ex> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    const ex lv = l.diff(sy.v[i]);
    ex e = l.diff(sy.q[i]) - lv.diff(sy.t);
    for (std::size_t j = 0; j < n; ++j) e -= lv.diff(sy.q[j]) * sy.v[j] + lv.diff(sy.v[j]) * a[j];
    out[i] = simplify_coefficient(e);
  }
  return out;
}
}  // namespace

bool null_lagrangian(const ex& l, const Symbols& sy) {
  std::vector<ex> a;
  std::vector<GiNaC::symbol> free;
  for (std::size_t i = 0; i < sy.q.size(); ++i) {
    free.emplace_back("a" + std::to_string(i + 1));
    a.push_back(free.back());
  }
  for (const ex& e : euler_lagrange(l, a, sy))
    if (!e.is_zero()) return false;
  return true;
}

std::vector<ex> euler_lagrange_on(const ex& l, const std::vector<ex>& a, const Symbols& sy) { return euler_lagrange(l, a, sy); }

bool affine_in_velocities(const ex& e, const Symbols& sy) {
  for (const auto& vi : sy.v)
    for (const auto& vj : sy.v)
      if (!zero(e.diff(vi).diff(vj))) return false;
  return true;
}

std::vector<ex> start_velocity(const ex& L, const std::vector<std::vector<ex>>& P, int K, const Symbols& sy) {
  const std::size_t n = sy.v.size();
  std::vector<ex> V(sy.v.begin(), sy.v.end());
  ex L0 = L.subs(sy.h == 0);
  GiNaC::matrix M0(static_cast<unsigned>(n), static_cast<unsigned>(n));
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) M0(static_cast<unsigned>(i), static_cast<unsigned>(j)) = L0.diff(sy.v[i]).diff(sy.v[j]);
  std::vector<ex> p(n);
  for (std::size_t i = 0; i < n; ++i) p[i] = L.diff(sy.v[i]);
  for (int k = 1; k <= K; ++k) {
    GiNaC::exmap sub;
    for (std::size_t i = 0; i < n; ++i) sub[sy.v[i]] = V[i];
    GiNaC::matrix rhs(static_cast<unsigned>(n), 1), w(static_cast<unsigned>(n), 1);
    std::vector<GiNaC::symbol> unknown;
    for (std::size_t i = 0; i < n; ++i) {
      const ex r = GiNaC::series_to_poly(p[i].subs(sub).series(sy.h == 0, k + 1));
      rhs(static_cast<unsigned>(i), 0) = P[static_cast<std::size_t>(k)][i] - r.coeff(sy.h, k);
      unknown.emplace_back();
      w(static_cast<unsigned>(i), 0) = unknown.back();
    }
    const GiNaC::matrix x = M0.solve(w, rhs);
    for (std::size_t i = 0; i < n; ++i) V[i] += GiNaC::pow(sy.h, k) * simplify_coefficient(x(static_cast<unsigned>(i), 0));
  }
  return V;
}

GiNaC::exmap inverse_velocity(const std::vector<ex>& vt, int K, const Symbols& sy) {
  const std::size_t n = sy.v.size();
  std::vector<ex> u(sy.v.begin(), sy.v.end());  // u = v~ - W(u), W = v~(v) - v
  for (int turn = 0; turn < K; ++turn) {
    GiNaC::exmap at;
    for (std::size_t i = 0; i < n; ++i) at[sy.v[i]] = u[i];
    std::vector<ex> next(n);
    for (std::size_t i = 0; i < n; ++i) {
      const ex w = (vt[i] - sy.v[i]).subs(at);
      next[i] = sy.v[i] - GiNaC::series_to_poly(w.series(sy.h == 0, K + 1));
    }
    u = next;
  }
  GiNaC::exmap out;
  for (std::size_t i = 0; i < n; ++i) out[sy.v[i]] = simplify_coefficient(u[i].expand());
  return out;
}

GiNaC::exmap projection(const std::vector<ex>& phi, const Symbols& sy) {
  const unsigned m = static_cast<unsigned>(phi.size()), n = static_cast<unsigned>(sy.v.size());
  GiNaC::matrix A(m, n), b(m, 1), v(n, 1);
  GiNaC::exmap at0;
  for (unsigned i = 0; i < n; ++i) {
    at0[sy.v[i]] = 0;
    v(i, 0) = sy.v[i];
  }
  for (unsigned c = 0; c < m; ++c) {
    b(c, 0) = phi[c].subs(at0);
    for (unsigned i = 0; i < n; ++i) A(c, i) = phi[c].diff(sy.v[i]);
  }
  const GiNaC::matrix At = A.transpose();
  const GiNaC::matrix S = A.mul(At).inverse();
  const GiNaC::matrix P = v.sub(At.mul(S).mul(A.mul(v).add(b)));
  GiNaC::exmap out;
  for (unsigned i = 0; i < n; ++i) out[sy.v[i]] = simplify_coefficient(P(i, 0));
  return out;
}

void certify_numerically(SurrogateSystem& s, const std::shared_ptr<const formula::FormulaModel>& base,
                         const GiNaC::exmap& proj, const Symbols& sy) {
  const auto sur = formula_modified_system(formula::compile_model(s.description));
  const auto b = formula_modified_system(base);
  const int n = base->n;
  const int J = s.checks.empty() ? s.K : s.checks.back().k;
  std::mt19937 rng(46);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  struct Point {
    double t, z;
    std::vector<double> q, v;
  };
  std::vector<Point> points;
  for (int k = 0; k < 6; ++k) {
    Point p{u(rng), u(rng), {}, {}};
    for (int i = 0; i < n; ++i) {
      p.q.push_back(u(rng));
      p.v.push_back(u(rng));
    }
    if (!proj.empty()) {  // onto the base's constraint, at its parameters' defaults
      GiNaC::exmap at;
      at[sy.t] = p.t;
      for (int i = 0; i < n; ++i) {
        at[sy.q[static_cast<std::size_t>(i)]] = p.q[static_cast<std::size_t>(i)];
        at[sy.v[static_cast<std::size_t>(i)]] = p.v[static_cast<std::size_t>(i)];
      }
      for (std::size_t j = 0; j < sy.params.size(); ++j) at[sy.params[j]] = base->parameters[j].value;
      for (int i = 0; i < n; ++i)
        p.v[static_cast<std::size_t>(i)] = GiNaC::ex_to<GiNaC::numeric>(proj.at(sy.v[static_cast<std::size_t>(i)]).subs(at).evalf()).to_double();
    }
    points.push_back(p);
  }
  s.defect_h.clear();
  s.defect.clear();
  for (double h0 = 0.2; h0 > 0.02; h0 /= 2) {
    double worst = 0;
    for (const auto& p : points) {
      const ModifiedPoint b0 = b->at({}, s.scheme, 0, p.t, p.q, p.v, p.z, false);
      const ModifiedPoint m = sur->at({{s.step_parameter, h0}}, s.scheme, J, p.t, p.q, p.v, p.z, false);
      double scale = std::abs(b0.Z[0]), d = 0;
      for (int i = 0; i < n; ++i) scale = std::max(scale, std::abs(b0.F_at(0, i)));
      for (int i = 0; i < n; ++i) {
        double g = 0;
        for (int k = J; k >= 0; --k) g = g * h0 + m.F_at(k, i);
        d = std::max(d, std::abs(g - b0.F_at(0, i)));
      }
      for (int c = 0; c < m.m && !m.holonomic; ++c) {  // the modified constraint against the base's rows
        double g = 0;
        for (int k = J; k >= 0; --k) g = g * h0 + m.phi[static_cast<std::size_t>(k * m.m + c)];
        d = std::max(d, std::abs(g - b0.phi[static_cast<std::size_t>(c)]));
      }
      if (m.contact) {
        double g = 0;
        for (int k = J; k >= 0; --k) g = g * h0 + m.Z[static_cast<std::size_t>(k)];
        d = std::max(d, std::abs(g - b0.Z[0]));
      }
      worst = std::max(worst, d / (scale + 1e-300));
    }
    s.defect_h.push_back(h0);
    s.defect.push_back(worst);
  }
  s.defect_slope = asymptotic_order(s.defect_h, s.defect, 0.25, 1e-14).slope;
}

}  // namespace surrogate_detail

std::string surrogate_shapes() {
  std::string s;
#define GEOMINT_SURROGATE_SHAPE(N, M, H) \
  s += (s.empty() ? "" : "; ") + std::string("n = " #N ", m = " #M) + (H ? " holonomic" : "");
#include "modified/surrogate_shapes.def"
#undef GEOMINT_SURROGATE_SHAPE
  return s;
}

SurrogateSystem build_surrogate(const std::shared_ptr<const formula::FormulaModel>& base, const std::string& scheme, int K,
                                double budget_seconds, double step) {
  require(base != nullptr, "surrogate of a formula system without a model");
  require(K >= 1 && K <= 5, "surrogate order must be an integer in [1, 5]");
  require(std::isfinite(budget_seconds) && budget_seconds > 0, "surrogate budget must be a positive number of seconds");
  require(std::isfinite(step) && step > 0, "surrogate step must be a positive number");
#define GEOMINT_SURROGATE_SHAPE(N, M, H)                                                 \
  if (base->n == N && base->m == M && (M == 0 || base->holonomic == (H != 0)))          \
    return surrogate_shape_##N##_##M##_##H(base, scheme, K, budget_seconds, step);
#include "modified/surrogate_shapes.def"
#undef GEOMINT_SURROGATE_SHAPE
  throw InputError("system '" + base->name + "' has n = " + std::to_string(base->n) + ", m = " + std::to_string(base->m) +
                   (base->holonomic ? " (holonomic)" : "") + ": surrogates are compiled for " + surrogate_shapes() +
                   " (modified_equations/CMakeLists.txt, GEOMINT_SURROGATE_SHAPES)");
}

}  // namespace geomint::modified
