#include "geomint/modified/symbolic_system.hpp"

namespace geomint::modified {

using GiNaC::ex;

std::vector<std::vector<ex>> modified_force(const std::vector<ex>& L, const std::vector<std::vector<ex>>& F,
                                            const FormulaSymbols& sy) {
  const int K = static_cast<int>(L.size()) - 1, n = static_cast<int>(sy.q.size());
  ex Lh = 0;
  std::vector<ex> a(static_cast<std::size_t>(n), ex(0));
  for (int k = 0; k <= K; ++k) {
    Lh += GiNaC::pow(sy.h, k) * L[static_cast<std::size_t>(k)];
    for (int i = 0; i < n; ++i)
      a[static_cast<std::size_t>(i)] += GiNaC::pow(sy.h, k) * F[static_cast<std::size_t>(k)][static_cast<std::size_t>(i)];
  }
  std::vector<std::vector<ex>> out(static_cast<std::size_t>(K + 1), std::vector<ex>(static_cast<std::size_t>(n)));
  for (int i = 0; i < n; ++i) {
    const ex p = Lh.diff(sy.v[static_cast<std::size_t>(i)]);
    ex dp = p.diff(sy.t);
    for (int j = 0; j < n; ++j)
      dp += p.diff(sy.q[static_cast<std::size_t>(j)]) * sy.v[static_cast<std::size_t>(j)] +
            p.diff(sy.v[static_cast<std::size_t>(j)]) * a[static_cast<std::size_t>(j)];
    const ex el = (dp - Lh.diff(sy.q[static_cast<std::size_t>(i)])).expand();
    for (int k = 0; k <= K; ++k)
      out[static_cast<std::size_t>(k)][static_cast<std::size_t>(i)] = simplify_coefficient(el.coeff(sy.h, k));
  }
  return out;
}

ModifiedFormulas formula_rows(const SymbolicResult& r, const FormulaSymbols& sy) {
  ModifiedFormulas f;
  f.K = r.K;
  f.stopped = r.stopped;
  std::vector<ex> shown;
  auto add = [&](const std::string& quantity, int k, const ex& e) {
    const ex d = display_form(e);
    shown.push_back(d);
    f.rows.push_back({quantity, k, formula_text(d), formula_mathematica(d), formula_latex(d), expression_size(d)});
    f.size += f.rows.back().size;
  };
  const auto idx = [](int i, int count) { return count == 1 ? std::string() : std::to_string(i + 1); };
  for (int k = 0; k <= r.K; ++k) {
    const auto K = static_cast<std::size_t>(k);
    for (int i = 0; i < r.n; ++i) add("F" + idx(i, r.n), k, r.F[K][static_cast<std::size_t>(i)]);
    if (r.contact) add("Z", k, r.Z[K]);
    for (int c = 0; c < r.m; ++c) add("mu" + idx(c, r.m), k, r.mu[K][static_cast<std::size_t>(c)]);
    if (r.has_lagrangian) {
      add("L", k, r.L[K]);
      for (int i = 0; i < r.n; ++i) add("Fmod" + idx(i, r.n), k, r.Fmod[K][static_cast<std::size_t>(i)]);
    }
  }
  for (std::size_t k = 0; k < r.phi.size(); ++k)
    for (int c = 0; c < r.m; ++c) add("phi" + idx(c, r.m), static_cast<int>(k), r.phi[k][static_cast<std::size_t>(c)]);
  // on the constraint: the map back to the velocities
  for (int i : r.mapped) add("v" + std::to_string(i + 1), 0, r.v[static_cast<std::size_t>(i)]);
  f.chart = r.chart;
  // the symbols the formulas use (h always: the series are in it)
  for (const auto& s : sy.all()) {
    bool used = s.is_equal(sy.h);
    for (const auto& d : shown) used = used || d.has(s);
    if (used) f.symbols.push_back(GiNaC::ex_to<GiNaC::symbol>(s).get_name());
  }
  return f;
}

}  // namespace geomint::modified
