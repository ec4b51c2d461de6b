#pragma once
// The symbolic modified equations of one system: the engine (automatic.hpp) with GiNaC coefficients, for every
// applicable scheme, on the system's symbolic instantiation SysT<GiNaC::ex> (a system header templated on its
// parameter type; Sys = SysT<double>), every parameter a symbol. Heavy: included only by the generated symbolic
// translation units (modified_equations/src/symbolic_instance.cpp.in) and by tests.
#include <algorithm>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "geomint/error.hpp"
#include "geomint/generic/system_info.hpp"
#include "geomint/modified/automatic.hpp"
#include "geomint/modified/automatic_registry.hpp"
#include "geomint/modified/symbolic.hpp"

namespace geomint::modified {

// The symbolic instantiation of a system: SysT<GiNaC::ex> for Sys = SysT<double>, or Sys::symbolic<GiNaC::ex>
// for a system that names it (the Foucault systems, whose double parameters are a physical scene and whose
// symbols are the combinations the equations use); unavailable for a system that does neither.
template <class Sys, class = void>
struct SymbolicOf {
  static constexpr bool available = false;
};
template <template <class> class SysT>
struct SymbolicOf<SysT<double>, void> {
  static constexpr bool available = true;
  using type = SysT<GiNaC::ex>;
  static type from(const SysT<double>&) { return type{}; }  // its fields then become symbols (symbolic_system)
};
template <class Sys>
struct SymbolicOf<Sys, std::void_t<typename Sys::template symbolic<GiNaC::ex>>> {
  static constexpr bool available = true;
  using type = typename Sys::template symbolic<GiNaC::ex>;
  static type from(const Sys&) { return type{}; }
};

// The values of the symbolic parameters at a numeric instance: its fields by name (visit), or, for a system
// whose symbols are combinations of its fields (the Foucault pendulum's s = Omega sin beta), its
// `visit_symbols(v)`, v(name, value) for each symbol.
template <class Sys, class = void>
struct has_visit_symbols : std::false_type {};
template <class Sys>
struct has_visit_symbols<Sys, std::void_t<decltype(std::declval<const Sys&>().visit_symbols(
                                  std::declval<void (*)(const char*, double)>()))>> : std::true_type {};

template <class Sys>
std::vector<std::pair<std::string, double>> symbol_values(Sys sys) {
  std::vector<std::pair<std::string, double>> out;
  if constexpr (has_visit_symbols<Sys>::value)
    sys.visit_symbols([&](const char* name, double x) { out.emplace_back(printed_symbol_name(name), x); });
  else
    sys.visit([&](const char* name, double& x, const char*) { out.emplace_back(printed_symbol_name(name), x); });
  return out;
}

// Every parameter of the system a symbol named as on the command line.
template <class SymSys>
SymSys symbolic_system(SymSys sys, FormulaSymbols& sy) {
  sys.visit([&](const char* name, GiNaC::ex& field, const char*) { field = sy.param(name); });
  return sys;
}
template <class SymSys>
SymSys symbolic_system(FormulaSymbols& sy) {
  return symbolic_system(SymSys{}, sy);
}

// The modified force of an LA scheme: with the modified Lagrangian L_mod = sum_k h^k L_k (the meshed
// Lagrangian, a function of t, q, q'), the force that makes its Euler–Lagrange equations the modified equation,
//   F_mod = d/dt (dL_mod/dq') - dL_mod/dq   along q'' = sum_k h^k F_k,   truncated after h^K.
// Zero (to that order) for a conservative variational scheme: Vermeeren's theorem, checked by the tests.
std::vector<std::vector<GiNaC::ex>> modified_force(const std::vector<GiNaC::ex>& L,
                                                   const std::vector<std::vector<GiNaC::ex>>& F,
                                                   const FormulaSymbols& sy);

// The formulas of one scheme on the symbolic system, to order K within the budget.
struct SymbolicResult {
  int K = 0;             // the order reached (< the order asked if the budget ran out)
  bool stopped = false;  // the budget ran out before the order asked
  int n = 0, m = 0, o = 1;
  bool contact = false, holonomic = false, has_lagrangian = false;
  std::vector<std::vector<GiNaC::ex>> F, mu, phi, Fmod;  // [k][component]
  std::vector<GiNaC::ex> Z, L;                           // [k]
  // on the constraint: the velocities in quasi-velocities (constraint_chart), and the i printed as the map back
  std::vector<GiNaC::ex> v;
  std::vector<int> mapped;
  std::string chart;
};

// on_constraint: the point's velocities on the system's nonholonomic constraint, q' = S(t, q) u + w (a system
// without one is computed as it is); `sy` then gains the quasi-velocities' symbols.
template <class SymSys, class G, int Kmax>
SymbolicResult symbolic_modified(const SymSys& sys, FormulaSymbols& sy, int K, const SymbolicBudget& budget,
                                 bool on_constraint = false) {
  using GiNaC::ex;
  using Engine = ModifiedEquation<SymSys, G, Kmax, ex>;
  constexpr int n = SymSys::dof, m = SymSys::constraints;
  Engine me(sys);
  me.set_deadline(budget.start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                     std::chrono::duration<double>(budget.seconds)));
  Vec<ex, n> q, v;
  for (int i = 0; i < n; ++i) {
    q(i) = sy.q[static_cast<std::size_t>(i)];
    v(i) = sy.v[static_cast<std::size_t>(i)];
  }
  ConstraintChart chart;
  if constexpr (m > 0 && !Engine::holonomic) {
    if (on_constraint) {
      const ex t = sy.t;
      const Mat<ex, m, n> A = sys.constraint_matrix(t, q);
      const Vec<ex, m> b = sys.constraint_offset(t, q);
      std::vector<std::vector<ex>> rows(m, std::vector<ex>(n));
      std::vector<ex> offset(m);
      for (int c = 0; c < m; ++c) {
        offset[static_cast<std::size_t>(c)] = b(c);
        for (int i = 0; i < n; ++i) rows[static_cast<std::size_t>(c)][static_cast<std::size_t>(i)] = A(c, i);
      }
      chart = constraint_chart(rows, offset, sy);
      for (int i = 0; i < n; ++i) v(i) = chart.v[static_cast<std::size_t>(i)];
    }
  }
  typename Engine::Result r;
  me.evaluate(sy.t, q, v, sy.z, K, r);
  SymbolicResult out;
  out.K = r.K;
  out.stopped = r.stopped;
  out.n = n;
  out.m = m;
  out.o = Engine::o;
  out.contact = G::contact;
  out.holonomic = Engine::holonomic;
  out.v = chart.v;
  out.mapped = chart.mapped;
  out.chart = chart.how;
  for (int k = 0; k <= r.K; ++k) {
    std::vector<ex> f, mu;
    for (int i = 0; i < n; ++i) f.push_back(r.F[static_cast<std::size_t>(k)](i));
    for (int c = 0; c < m; ++c) mu.push_back(r.mu[static_cast<std::size_t>(k)](c));
    out.F.push_back(f);
    out.mu.push_back(mu);
    out.Z.push_back(r.Z[static_cast<std::size_t>(k)]);
  }
  if constexpr (m > 0) {
    for (int k = 0; k <= r.K + Engine::o; ++k) {
      std::vector<ex> ph;
      for (int c = 0; c < m; ++c) ph.push_back(r.phi[static_cast<std::size_t>(k)](c));
      out.phi.push_back(ph);
    }
  }
  if constexpr (m == 0 && !G::contact) {
    if (!r.stopped && !budget.spent()) {
      const auto lag = me.mesh_lagrangian(sy.t, r);
      for (int k = 0; k <= r.K; ++k) out.L.push_back(lag[static_cast<std::size_t>(k)]);
      out.has_lagrangian = true;
      out.Fmod = modified_force(out.L, out.F, sy);
    }
  }
  return out;
}

// The rows the registry hands to programs (strings: programs never see GiNaC).
ModifiedFormulas formula_rows(const SymbolicResult& r, const FormulaSymbols& sy);

// The formulas of `scheme` on the symbolic twin of `prototype` (SymbolicOf<Sys>::from); ModifiedFormulas::values
// at the parameters `pv`.
template <class Sys>
ModifiedFormulas symbolic_formulas(const Sys& prototype, const ParamValues& pv, const std::string& scheme, int K,
                                   double budget_seconds, bool on_constraint = false) {
  if constexpr (!SymbolicOf<Sys>::available) {
    (void)prototype;
    (void)pv;
    (void)scheme;
    (void)K;
    (void)budget_seconds;
    (void)on_constraint;
    throw InputError("system '" + generic::system_name(prototype) + "' has no symbolic parameter type yet (formulas need its header templated on it)");
  } else {
    using SymSys = typename SymbolicOf<Sys>::type;
    if (generic::is_composition_name(scheme)) throw InputError(composition_formulas_refusal(scheme));
    require(K >= 0 && K <= registry_max_order, "order must be an integer in [0, " + std::to_string(registry_max_order) + "]");
    const Sys numeric = generic::make_system(prototype, pv);
    numeric.validate();
    return generic::visit_generic_scheme<Sys>(scheme, [&](auto g) {
      const SymbolicBudget budget{budget_seconds};
      FormulaSymbols sy(Sys::dof);
      const SymSys sys = symbolic_system(SymbolicOf<Sys>::from(prototype), sy);
      const SymbolicResult r = symbolic_modified<SymSys, decltype(g), registry_max_order>(sys, sy, K, budget, on_constraint);
      ModifiedFormulas f = formula_rows(r, sy);
      f.K_asked = K;
      f.seconds = budget.elapsed();
      f.budget = budget_seconds;
      for (const auto& [name, x] : symbol_values(numeric))
        if (std::find(f.symbols.begin(), f.symbols.end(), name) != f.symbols.end()) f.values.emplace_back(name, x);
      return f;
    });
  }
}

template <class Sys>
ModifiedFormulas symbolic_formulas(const ParamValues& pv, const std::string& scheme, int K, double budget_seconds,
                                   bool on_constraint = false) {
  return symbolic_formulas(Sys{}, pv, scheme, K, budget_seconds, on_constraint);
}

}  // namespace geomint::modified
