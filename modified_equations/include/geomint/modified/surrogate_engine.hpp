#pragma once
// The construction of surrogate.hpp for one shape (n, m, holonomic) of formula systems: the symbolic engine
// (automatic.hpp with GiNaC coefficients) run on the surrogate itself, read back from its own formulas with the
// step h a series in the engine's h. Heavy: included only by the generated surrogate units
// (modified_equations/src/surrogate_instance.cpp.in).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "geomint/error.hpp"
#include "geomint/formula/formula_system.hpp"
#include "geomint/generic/schemes.hpp"
#include "geomint/modified/automatic.hpp"
#include "geomint/modified/formula_constant.hpp"
#include "geomint/modified/surrogate.hpp"
#include "geomint/modified/symbolic.hpp"

namespace geomint::modified::surrogate_detail {

using GiNaC::ex;

// The symbols of a surrogate, named as the formula language reads them (t, z, q1.., v1.., the parameters, h).
struct Symbols {
  GiNaC::symbol t, z, h;
  std::vector<GiNaC::symbol> q, v;
  std::vector<GiNaC::symbol> params;  // the base's parameters, in its order
  std::vector<std::string> names;     // their names
  std::string step;                   // h's name
  explicit Symbols(const formula::FormulaModel& base);
};

// The surrogate's data: what a system file holds, as expressions in Symbols.
struct Data {
  int n = 0, m = 0;
  bool holonomic = false, has_force = false, has_herglotz = false;
  ex L, Hg, E;
  std::vector<ex> F, phi;  // force (n), constraint rows phi (velocity) or g (holonomic) (m)
  std::vector<ex> q0, v0;  // initial data, in the parameters (and h for v0)
};

// Defined in surrogate.cpp (no templates).
formula::SystemDescription describe(const Data& d, const Symbols& sy, const formula::FormulaModel& base,
                                    const std::string& name, const std::string& description, double step);
std::string system_file_text(const formula::SystemDescription& d);
SurrogateTerm term(const std::string& quantity, int k, const ex& e, const Symbols& sy);
bool zero(const ex& e);
// l's Euler–Lagrange expression l_q - d/dt l_q' with q'' a free symbol: zero exactly when l is a total derivative.
bool null_lagrangian(const ex& l, const Symbols& sy);
// E[l] on the flow q'' = a: l_q - l_q'q q' - l_q't - l_q'q' a.
std::vector<ex> euler_lagrange_on(const ex& l, const std::vector<ex>& a, const Symbols& sy);
// Whether e is affine in the velocities.
bool affine_in_velocities(const ex& e, const Symbols& sy);
// v~ = v + sum_{k=1..K} h^k w_k with dL/dq'(t, q, v~, z) = sum_k h^k P[k] (to h^K), L polynomial in h.
std::vector<ex> start_velocity(const ex& L, const std::vector<std::vector<ex>>& P, int K, const Symbols& sy);
// v -> v(q, v~), the inverse of v~ = v + sum_{k=1..K} h^k w_k(t, q, v, z) to h^K (fixed point, truncated each turn).
GiNaC::exmap inverse_velocity(const std::vector<ex>& vt, int K, const Symbols& sy);
// The numeric half of the certification (SurrogateSystem::defect).
// Random points are put on the base's constraint by `proj` (v -> projected v, empty without velocity rows).
void certify_numerically(SurrogateSystem& s, const std::shared_ptr<const formula::FormulaModel>& base,
                         const GiNaC::exmap& proj, const Symbols& sy);
// v -> v - A^T (A A^T)^{-1} (A v + b) for the rows phi = A v + b: onto the constraint, affine in v.
GiNaC::exmap projection(const std::vector<ex>& phi, const Symbols& sy);

template <int N, int M, bool Hol, int Kmax, class C>
using SurrogateSeries = BiSeries<Kmax + (M > 0 ? (Hol ? 2 : 1) : 0), Kmax + 3, 2, C>;

template <int N, int M, bool Hol, int Kmax, class C>
using SurrogateModelSystem = formula::FormulaSystemT<N, M, Hol, SurrogateSeries<N, M, Hol, Kmax, C>>;

// The base's data as expressions (the model's tapes evaluated on symbols).
template <int N, int M, bool Hol>
Data base_data(const std::shared_ptr<const formula::FormulaModel>& model, const Symbols& sy) {
  std::vector<ex> pv(sy.params.begin(), sy.params.end());
  const formula::FormulaSystemT<N, M, Hol, ex> sys(model, pv);
  Vec<ex, N> q, v;
  for (int i = 0; i < N; ++i) {
    q(i) = sy.q[static_cast<std::size_t>(i)];
    v(i) = sy.v[static_cast<std::size_t>(i)];
  }
  const ex t = sy.t, z = sy.z;
  Data d;
  d.n = N;
  d.m = M;
  d.holonomic = Hol;
  d.L = sys.template lagrangian<ex>(t, q, v);
  d.has_force = model->has_force();
  const Vec<ex, N> f = sys.template force<ex>(t, q, v);
  for (int i = 0; i < N; ++i) d.F.push_back(f(i));
  d.has_herglotz = model->has_herglotz();
  if (d.has_herglotz) d.Hg = sys.template herglotz<ex>(t, q, v, z);
  if (model->has_energy()) {
    d.E = sys.template energy<ex>(t, q, v);
  } else {
    ex e = -d.L;
    for (int i = 0; i < N; ++i) e += v(i) * d.L.diff(sy.v[static_cast<std::size_t>(i)]);
    d.E = e;
  }
  if constexpr (M > 0) {
    if constexpr (Hol) {
      const Vec<ex, M> g = sys.template holonomic<ex>(t, q);
      for (int c = 0; c < M; ++c) d.phi.push_back(g(c));
    } else {
      const Vec<ex, M> phi = sys.template constraint_matrix<ex>(t, q) * v + sys.template constraint_offset<ex>(t, q);
      for (int c = 0; c < M; ++c) d.phi.push_back(phi(c));
    }
  }
  const Vec<ex, N> q0 = sys.template initial_position<ex>(), v0 = sys.template initial_velocity<ex>();
  for (int i = 0; i < N; ++i) {
    d.q0.push_back(q0(i));
    d.v0.push_back(v0(i));
  }
  return d;
}

// The engine on the surrogate described by `d`, in coefficient type C: the model compiled from its formulas, its
// parameters the symbols (or, in numbers, their values) and its step the engine's h.
template <int N, int M, bool Hol, int Kmax, class C>
SurrogateModelSystem<N, M, Hol, Kmax, C> surrogate_model_system(const std::shared_ptr<const formula::FormulaModel>& model,
                                                                 const Symbols& sy, const std::vector<double>& values) {
  using Ser = SurrogateSeries<N, M, Hol, Kmax, C>;
  std::vector<Ser> pv;
  for (const auto& p : model->parameters) {
    if (p.name == sy.step) {
      pv.push_back(Ser::h());
      continue;
    }
    const auto it = std::find(sy.names.begin(), sy.names.end(), p.name);
    const std::size_t i = static_cast<std::size_t>(it - sy.names.begin());
    if constexpr (std::is_same_v<C, double>)
      pv.push_back(Ser(values[i]));
    else
      pv.push_back(Ser(ex(sy.params[i])));
  }
  return SurrogateModelSystem<N, M, Hol, Kmax, C>(model, pv);
}

// The scheme's discrete momentum at t along the modified flow through the point of `r`, p_j = p^-(q~(t - h), q~(t))
// (LA: D2 𝓛 + F_d^+; contact: D2 𝓛 / (1 - D4 𝓛) with z~), as sum_k h^k P[k], k <= r.K: the momentum with which a
// discrete solution on that flow arrives at t, the start that puts it on the flow through (q, v). The points
// q~(t + s h) = sum_m c_m (s h)^m from the engine's Taylor coefficients (c_m = sum_i c_m^(i) h^i, known to
// total degree K + 2).
template <class G, class Engine, class Sys>
std::vector<std::vector<typename Engine::coefficient>> discrete_momentum(const Sys& sys, const typename Engine::coefficient& t,
                                                                        const typename Engine::Result& r) {
  using C = typename Engine::coefficient;
  using S = typename Engine::S;
  constexpr int n = Engine::n;
  const int K = r.K;
  auto point = [&](double s, auto&& coef, int top) {
    S x;
    x.p = top;  // known below total degree `top`
    for (int mm = 0; mm < top; ++mm)
      for (int i = 0; mm + i < top && i <= S::h_max; ++i) {
        if (mm + i > S::h_max) continue;
        const C c = coef(mm, i);
        if (CoefficientTraits<C>::is_zero(c)) continue;
        x.at(0, mm + i) += CoefficientTraits<C>::normalize(c * exact<C>(std::pow(s, mm)));
      }
    x.fit();
    return x;
  };
  const int top = K + 3;
  Vec<S, n> Qm, Q0;
  for (int i = 0; i < n; ++i) {
    auto c = [&](int mm, int k) -> C {
      if (mm > K + 2 || k > K) return C(0);
      return r.c[static_cast<std::size_t>(mm)][static_cast<std::size_t>(k)](i);
    };
    Qm(i) = point(-1, c, top);
    Q0(i) = point(0, c, top);
  }
  const S H = S::h(), Tm = S(t) - H;
  Vec<S, n> P;
  if constexpr (Engine::contact) {
    auto d = [&](int mm, int k) -> C {
      if (mm > K + 2 || k > K) return C(0);
      return r.d[static_cast<std::size_t>(mm)][static_cast<std::size_t>(k)];
    };
    P = G::p_minus(sys, Tm, H, Qm, Q0, point(-1, d, K + 2), point(0, d, K + 2));
  } else {
    P = G::p_minus(sys, Tm, H, Qm, Q0);
  }
  std::vector<std::vector<C>> out;
  for (int k = 0; k <= K; ++k) {
    if (!P(0).known(0, k)) throw std::logic_error("surrogate: the discrete momentum lost a coefficient to truncation");
    std::vector<C> p;
    for (int i = 0; i < n; ++i) p.push_back(simplify_coefficient(P(i).coeff(0, k)));
    out.push_back(p);
  }
  return out;
}

template <int N, int M, bool Hol, class G, int Kmax>
class Builder {
 public:
  using Sys = SurrogateModelSystem<N, M, Hol, Kmax, ex>;
  using Engine = ModifiedEquation<Sys, G, Kmax, ex>;
  static_assert(std::is_same_v<typename Engine::S, SurrogateSeries<N, M, Hol, Kmax, ex>>,
                "the surrogate's parameters are the engine's own series");
  static constexpr bool contact = G::contact;

  Builder(std::shared_ptr<const formula::FormulaModel> base, double budget, double step)
      : base_(std::move(base)), sy_(*base_), budget_{budget}, step_(step) {
    d0_ = base_data<N, M, Hol>(base_, sy_);
    if constexpr (M > 0 && !Hol) proj_ = projection(d0_.phi, sy_);
    if (contact && !d0_.has_herglotz)
      throw InputError("system '" + base_->name + "' has no Herglotz Lagrangian: the contact schemes have no surrogate");
  }

  SurrogateSystem build(int K) {
    SurrogateSystem out;
    out.base = base_->name;
    out.scheme = G::quadrature::scheme;
    out.K_asked = K;
    out.budget = budget_.seconds;
    out.step_parameter = sy_.step;
    Data d = d0_;
    // an LA surrogate has no Herglotz form (the base's would not go with the corrected force); a contact surrogate
    // keeps the base's L and force (what the LA schemes, the energy and the references of the file run)
    d.has_herglotz = contact;
    // the base's acceleration F_0 and kinetic metric M = L_q'q' (the linearization the corrections solve with)
    const auto r0 = run(d, 0);
    a0_.clear();
    for (int i = 0; i < N; ++i) a0_.push_back(r0.F[0](i));
    int reached = 0;
    for (int k = 1; k <= K; ++k) {
      if (budget_.spent()) {
        out.stopped = true;
        break;
      }
      auto r = run(d, k);
      if (r.stopped) {
        out.stopped = true;
        break;
      }
      if (const std::string bad = lower_orders_vanish(r, k - 1); !bad.empty()) {
        out.why_short = bad;
        break;
      }
      if constexpr (M > 0 && !Hol) {
        bool any = false;
        for (int c = 0; c < M; ++c) any = any || !zero_on(r.phi[static_cast<std::size_t>(k)](c));
        if (any) {
          for (int c = 0; c < M; ++c) {
            // only its values on the constraint matter (the rows are defined up to multiples of themselves): phi_k
            // at the projected velocity, affine in v exactly when phi_k is affine on the constraint
            const ex psi = on(-r.phi[static_cast<std::size_t>(k)](c));
            if (!affine_in_velocities(psi, sy_)) {
              out.constraint_linear = false;
              out.terms.push_back(term("phi" + std::to_string(c + 1), k, psi, sy_));
              out.why_short = "the modified constraint's phi_" + std::to_string(k) + " (row " + std::to_string(c + 1) +
                              ") is not linear in the velocities on the constraint: " + formula_text(display_form(-psi)) +
                              "; constraint rows A(t, q) q' + b(t, q) cannot cancel it";
            } else {
              d.phi[static_cast<std::size_t>(c)] += GiNaC::pow(sy_.h, k) * psi;
              out.terms.push_back(term("phi" + std::to_string(c + 1), k, psi, sy_));
            }
          }
          if (!out.constraint_linear) break;
          r = run(d, k);
          if (r.stopped) {
            out.stopped = true;
            break;
          }
        }
      }
      if constexpr (contact) {
        const ex c = simplify_coefficient(-r.Z[static_cast<std::size_t>(k)]);
        if (!zero(c)) {
          d.Hg += GiNaC::pow(sy_.h, k) * c;
          out.terms.push_back(term("herglotz", k, c, sy_));
        }
      } else {
        ex ell = 0;
        if constexpr (M == 0) {
          Engine me(model_system(d));
          const auto lag = me.mesh_lagrangian(sy_.t, r);
          ell = simplify_coefficient(-lag[static_cast<std::size_t>(k)]);
          if (null_lagrangian(ell, sy_)) ell = 0;  // a total derivative: no force of its own
        }
        const std::vector<ex> el = zero(ell) ? std::vector<ex>(N, ex(0)) : euler_lagrange_on(ell, a0_, sy_);
        const GiNaC::matrix Mm = metric();
        bool any_force = false;
        std::vector<ex> f(N);
        for (int i = 0; i < N; ++i) {
          ex mf = 0;
          for (int j = 0; j < N; ++j) mf += Mm(i, j) * r.F[static_cast<std::size_t>(k)](j);
          f[static_cast<std::size_t>(i)] = simplify_coefficient(-mf - el[static_cast<std::size_t>(i)]);
          any_force = any_force || !zero(f[static_cast<std::size_t>(i)]);
        }
        if (!zero(ell)) {
          d.L += GiNaC::pow(sy_.h, k) * ell;
          out.terms.push_back(term("L", k, ell, sy_));
        }
        if (any_force) {
          out.force_free = false;
          d.has_force = true;
          for (int i = 0; i < N; ++i) {
            d.F[static_cast<std::size_t>(i)] += GiNaC::pow(sy_.h, k) * f[static_cast<std::size_t>(i)];
            out.terms.push_back(term("F" + std::to_string(i + 1), k, f[static_cast<std::size_t>(i)], sy_));
          }
        }
      }
      reached = k;
    }
    out.K = reached;
    // certification: the engine once more on the final surrogate, one order beyond (two for a symmetric scheme
    // whose odd order vanishes), where the budget allows
    int Kc = std::min(reached + 1, Kmax);
    auto r = run(d, Kc);
    if (!r.stopped && G::order == 2 && Kc < Kmax && vanishes(r, Kc) && !budget_.spent()) {
      Kc = Kc + 1;
      r = run(d, Kc);
    }
    int first = r.K + 1;  // the first order that does not vanish (the scheme's order on the surrogate)
    for (int k = 1; k <= r.K; ++k) {
      SurrogateCheck c;
      c.k = k;
      c.symbolic_zero = vanishes(r, k);
      if (k > reached && !c.symbolic_zero) c.leading = leading(r, k);
      out.checks.push_back(c);
      if (k > reached && !c.symbolic_zero) {
        first = k;
        break;
      }
    }
    // the start: the initial velocity whose momentum is the scheme's discrete momentum on the base's flow, to the
    // order below the first that does not vanish (a symmetric scheme's start has odd terms too: to h^(K+1))
    {
      const int start_order = std::min(first - 1, r.K);
      const auto Pk = discrete_momentum<G, Engine>(model_system(d), ex(sy_.t), r);
      const std::vector<ex> vt = start_velocity(contact ? d.Hg : d.L, Pk, start_order, sy_);
      GiNaC::exmap at0;
      at0[sy_.t] = 0;
      at0[sy_.z] = 0;
      for (int i = 0; i < N; ++i) {
        at0[sy_.q[static_cast<std::size_t>(i)]] = d0_.q0[static_cast<std::size_t>(i)];
        at0[sy_.v[static_cast<std::size_t>(i)]] = d0_.v0[static_cast<std::size_t>(i)];
      }
      // the energy at the base's velocity: along the discrete solution the velocity a run reads off p_j (through
      // L~'s momentum) is v~(q, v) of the flow's v, so the file's E is the base's at the inverse map v(q, v~).
      // Unconstrained systems only: with rows, the map carries the multiplier's rational functions and its normal
      // form costs minutes (the base's E at v~ is then off by O(h), said in surrogates.md)
      if constexpr (M == 0) d.E = d0_.E.subs(inverse_velocity(vt, start_order, sy_));
      for (int i = 0; i < N; ++i) {
        d.v0[static_cast<std::size_t>(i)] = vt[static_cast<std::size_t>(i)].subs(at0);
        const ex w = (vt[static_cast<std::size_t>(i)] - sy_.v[static_cast<std::size_t>(i)]).expand();
        for (int k = 1; k <= start_order; ++k)
          if (!zero(w.coeff(sy_.h, k)))
            out.terms.push_back(term("v" + std::to_string(i + 1), k, simplify_coefficient(w.coeff(sy_.h, k)), sy_));
      }
    }
    const std::string name = base_->name + "-surrogate-" + out.scheme + "-" + std::to_string(reached);
    const std::string what = "surrogate of " + base_->name + " for " + out.scheme + " to h^" + std::to_string(reached) +
                             ": the scheme on it follows " + base_->name + "'s equations to O(h^" + std::to_string(reached + 1) +
                             "); run it with h = the step";
    out.description = describe(d, sy_, *base_, name, what, step_);
    out.file_text = system_file_text(out.description);
    // the same in numbers, on the surrogate read back from its file
    certify_numerically(out, base_, proj_, sy_);
    out.seconds = budget_.elapsed();
    return out;
  }

 private:
  std::shared_ptr<const formula::FormulaModel> compile(const Data& d) const {
    return formula::compile_model(describe(d, sy_, *base_, base_->name + "-surrogate", "", step_));
  }
  Sys model_system(const Data& d) const { return surrogate_model_system<N, M, Hol, Kmax, ex>(compile(d), sy_, {}); }
  typename Engine::Result run(const Data& d, int k) const {
    Engine me(model_system(d));
    me.set_deadline(budget_.start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                        std::chrono::duration<double>(budget_.seconds)));
    Vec<ex, N> q, v;
    for (int i = 0; i < N; ++i) {
      q(i) = sy_.q[static_cast<std::size_t>(i)];
      v(i) = sy_.v[static_cast<std::size_t>(i)];
    }
    typename Engine::Result r;
    me.evaluate(sy_.t, q, v, sy_.z, k, r);
    return r;
  }
  GiNaC::matrix metric() const {
    GiNaC::matrix Mm(N, N);
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < N; ++j)
        Mm(i, j) = d0_.L.diff(sy_.v[static_cast<std::size_t>(i)]).diff(sy_.v[static_cast<std::size_t>(j)]);
    return Mm;
  }
  // F_k, Z_k, phi_k of order k all zero.
  ex on(const ex& e) const { return proj_.empty() ? e : simplify_coefficient(e.subs(proj_)); }
  bool zero_on(const ex& e) const { return zero(proj_.empty() ? e : e.subs(proj_)); }
  bool vanishes(const typename Engine::Result& r, int k) const {
    for (int i = 0; i < N; ++i)
      if (!zero_on(r.F[static_cast<std::size_t>(k)](i))) return false;
    if (contact && !zero_on(r.Z[static_cast<std::size_t>(k)])) return false;
    if constexpr (M > 0 && !Hol)
      for (int c = 0; c < M; ++c)
        if (!zero_on(r.phi[static_cast<std::size_t>(k)](c))) return false;
    return true;
  }
  std::string lower_orders_vanish(const typename Engine::Result& r, int upto) const {
    for (int k = 1; k <= upto; ++k)
      if (!vanishes(r, k))
        return "order " + std::to_string(k) + " did not vanish after its correction: " + leading(r, k) +
               (contact ? " (a Herglotz Lagrangian cannot cancel both z' and q'' here)" : "");
    return "";
  }
  std::string leading(const typename Engine::Result& r, int k) const {
    std::string s;
    for (int i = 0; i < N; ++i) {
      const ex e = on(r.F[static_cast<std::size_t>(k)](i));
      if (!zero(e)) s += (s.empty() ? "" : "; ") + std::string("F") + std::to_string(i + 1) + "_" + std::to_string(k) + " = " + formula_text(display_form(e));
    }
    if (contact && !zero_on(r.Z[static_cast<std::size_t>(k)]))
      s += (s.empty() ? "" : "; ") + std::string("Z_") + std::to_string(k) + " = " + formula_text(display_form(on(r.Z[static_cast<std::size_t>(k)])));
    if constexpr (M > 0 && !Hol)
      for (int c = 0; c < M; ++c)
        if (!zero_on(r.phi[static_cast<std::size_t>(k)](c)))
          s += (s.empty() ? "" : "; ") + std::string("phi") + std::to_string(c + 1) + "_" + std::to_string(k) + " = " +
               formula_text(display_form(on(r.phi[static_cast<std::size_t>(k)](c))));
    return s;
  }

  std::shared_ptr<const formula::FormulaModel> base_;
  Symbols sy_;
  SymbolicBudget budget_;
  double step_;
  Data d0_;
  std::vector<ex> a0_;
  // v -> the velocity projected onto the base's rows (velocity constraints; empty otherwise): a quantity vanishes
  // where the discrete solution lives when it vanishes on the constraint, i.e. after this substitution
  GiNaC::exmap proj_;
};

// The shape's entry: the scheme by name.
template <int N, int M, bool Hol, int Kmax>
SurrogateSystem build_shape(const std::shared_ptr<const formula::FormulaModel>& base, const std::string& scheme, int K,
                            double budget, double step) {
  SurrogateSystem out;
  bool found = false;
  std::apply(
      [&](auto... g) {
        auto one = [&](auto x) {
          using G = decltype(x);
          if (found || scheme != G::quadrature::scheme) return;
          found = true;
          out = Builder<N, M, Hol, G, Kmax>(base, budget, step).build(K);
        };
        (one(g), ...);
      },
      generic::AllSchemesTuple{});
  if (!found)
    throw InputError("scheme '" + scheme + "' has no surrogate (la, contact, la-midpoint, la-trapezoid, contact-trapezoid have)");
  return out;
}

}  // namespace geomint::modified::surrogate_detail
