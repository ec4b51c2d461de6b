#pragma once
// Automatic modified equations of every registered system and scheme, by name (no templates here: the heavy
// instantiation lives in one generated translation unit per line of core/src/systems.def, so a new system
// gets its modified equations with no other file touched).
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "geomint/io.hpp"
#include "geomint/registry.hpp"

namespace geomint::modified {

// The largest order K the registry evaluates (the engine template takes any Kmax).
constexpr int registry_max_order = 6;

// The modified equation at one point (t, q, v, z), coefficient by coefficient in h.
struct ModifiedPoint {
  int n = 0, m = 0, K = 0;
  bool contact = false, holonomic = false;
  std::vector<double> F;        // (K+1) rows of n: q'' = sum_k h^k F_k
  std::vector<double> Z;        // K+1: z' = sum_k h^k Z_k (contact; zeros otherwise)
  std::vector<double> mu;       // (K+1) rows of m: the multiplier (impulse per unit time) sum_k h^k mu_k
  std::vector<double> phi;      // (K+1+o) rows of m: the modified constraint Phi_h = Phi_d(q~(t), q~(t+h)) =
                                // sum_k h^k phi_k (o = 1 for Phi o Psi, 2 for a holonomic constraint)
  std::vector<double> phi_dot;  // holonomic: the time derivative of Phi_h along the flow (K+2 rows of m)
  std::vector<double> lagrangian;  // K+1: the modified Lagrangian's value sum_k h^k L_k here (unconstrained LA
                                  // schemes: the meshed Lagrangian, see ModifiedEquation::mesh_lagrangian;
                                  // contact: the modified Herglotz Lagrangian, = Z; NaN when constrained)
  double residual = 0;          // self-check: largest residual coefficient that should vanish (when asked)
  double F_at(int k, int i) const { return F[static_cast<std::size_t>(k * n + i)]; }
};

// How the modified solution starts. shooting: q~(0) = q_0 and q~(h) = q_1, by shooting on v~(0) (consistent at every
// order K). naive: v~(0) = v_0, the system's initial velocity; it differs from the consistent one by O(h^p) for a
// scheme of order p, so it caps the agreement at h^p whatever K (and at K = 0 it is the original equation from the
// exact initial data).
enum class AgreementStart { shooting, naive };
const char* start_name(AgreementStart s);
AgreementStart parse_agreement_start(const std::string& name);  // InputError for another name

// Step-by-step agreement of a discrete solution with the solution of its order-K modified equation.
struct ModifiedAgreement {
  long steps = 0;
  double err_q = 0;        // max_j |q_j - q~(t_j)| (max over components)
  double err_z = 0;        // max_j |z_j - z~(t_j)| (contact; NaN otherwise)
  double v_shift = 0;      // |v~(0) - v(0)|: what the consistent (shooting) start moved the velocity by (0 for naive)
  double shoot_miss = 0;   // |q~(h) - q_1| after shooting (NaN for naive)
  double phi_d = 0;        // max_j |Phi_d(q~(t_j), q~(t_{j+1}))| along the modified solution (constrained)
  double phi_h0 = 0;       // |Phi_h^[K](x~(0))|: the modified constraint (truncated) at the start
  double phi_h_drift = 0;  // max_j |Phi_h^[K](x~(t_j)) - Phi_h^[K](x~(0))|
  double err_mu = 0;       // max_{j>=1} |lambda_j/h - mu~(t_j)| (constrained; the first impulse also absorbs the
                           // start's continuous momentum along A^T)
};

// The modified equation as formulas (one row per quantity and order), printed three ways: `text` (define_system
// and sympy's parse_expr read it: '^' powers, exact rationals a/b, sin(q1)), `mathematica` (ToExpression: Sin[q1])
// and `latex`. Symbols: t, h, z, q1..qn, v1..vn (the velocities), and the system's parameters by their own names
// (docs/formulas.md, "Names": Mathematica's column writes a capitalized one in Global`).
struct FormulaRow {
  std::string quantity;  // F<i>, Z, mu<c>, phi<c>, L (modified Lagrangian), Fmod<i> (modified force); on the
                         // constraint also v<i> (k = 0): the velocity q'_i in the quasi-velocities (the map back)
  int k = 0;             // the power of h
  std::string text, mathematica, latex;
  std::size_t size = 0;  // nodes of its expression tree (symbolic.hpp's expression_size)
};
struct ModifiedFormulas {
  int K_asked = 0, K = 0;  // the order asked and the order reached within the budget
  bool stopped = false;
  double seconds = 0, budget = 0;
  std::vector<std::string> symbols;  // every symbol a formula may use
  // the parameters' symbols at the values the call was given (to evaluate a formula at a run's parameters)
  std::vector<std::pair<std::string, double>> values;
  std::vector<FormulaRow> rows;
  std::size_t size = 0;  // nodes of every row's expression tree, in all
  // On the constraint: how the velocities were charted (constraint_chart in symbolic.hpp); "" otherwise.
  std::string chart;
};

struct ModifiedSystem {
  std::string name;
  int dof = 0, constraints = 0;
  bool holonomic = false, has_herglotz = false;
  std::vector<std::string> schemes;

  // F_0..F_K of `scheme` at (t, q, v, z); `check` also re-evaluates the residual (ModifiedPoint::residual).
  std::function<ModifiedPoint(const ParamValues&, const std::string& scheme, int K, double t, const std::vector<double>& q,
                              const std::vector<double>& v, double z, bool check)>
      at;
  // The discrete solution (generic Newton step in long double, from the system's initial data, N = T/h steps)
  // against the order-K modified solution (Boost.Odeint dopri5, dense output, tolerance tol) started as `start`
  // says (z~(0) = z_0 = 0).
  std::function<ModifiedAgreement(const ParamValues&, const std::string& scheme, int K, double h, double T, double tol,
                                  AgreementStart start)>
      agreement;
  // The shooting start alone: v~(0) with q~(0) = q_0, q~(h) = q_1.
  std::function<std::vector<double>(const ParamValues&, const std::string& scheme, int K, double h, double tol)> shoot;
  // The modified equation of `scheme` as formulas to order K, every parameter a symbol (ModifiedFormulas::values
  // gives their values at the parameters passed), within a time budget (seconds); InputError for a system that
  // has no symbolic parameter type. `on_constraint` (a system with nonholonomic constraints): the point's velocities
  // are q' = S(t, q) u + w(t, q) in quasi-velocities u, so that the formulas live on the constraint (smaller, and
  // found sooner); the rows v<i> give the map back. Ignored by a system without such constraints.
  std::function<ModifiedFormulas(const ParamValues&, const std::string& scheme, int K, double budget_seconds,
                                 bool on_constraint)>
      formulas;
};

// The modified equations of an entry of the registry (core's all_systems(), or a formula system's entry): a header
// system's by the entry's index (its place in core/src/systems.def), compiled with the system; a formula system's
// from its model, by the shape it was compiled in (formula_modified.hpp; InputError for a shape without modified
// equations). Hold the pointer: a formula system's is built for the call.
std::shared_ptr<const ModifiedSystem> modified_system(const SystemInfo& sys);
// The same for the header system `name` (InputError naming the known ones, as find_system).
const ModifiedSystem& find_modified_system(const std::string& name);
// The scheme `name` of `sys` for a modified equation (a scheme or a composition "<family>:<base>"): InputError for a
// name the system does not know.
const SchemeInfo& modified_scheme(const SystemInfo& sys, const std::string& name);  // InputError naming the known ones
// The same for the modified equation as formulas: InputError also for a composition, whose modified equation is
// computed in numbers only (composition_formulas_refusal says why).
const SchemeInfo& formula_scheme(const SystemInfo& sys, const std::string& name);
std::string composition_formulas_refusal(const std::string& name);
// What one evaluation of the modified equation of `scheme` costs against the scheme's base (1 for a scheme): a
// composition of s stages solves its stage points at every order, about 4 s times the base (measured on the
// pendulum and the knife edge: 9x for yoshida4, 19x suzuki4, 28x yoshida6a, 72x kahanli8 at K = 4), for the
// programs' budgets.
double modified_cost_factor(const SystemInfo& sys, const std::string& scheme);
// The slope at which a discrete solution of `scheme` approaches its order-K modified solution: the first h^k
// beyond K whose F_k may be nonzero — K + 1 for a first-order scheme; for a symmetric one of order p (the odd F_k
// vanish, and F_1 .. F_{p-1} too) the least even k > K, and at least p.
// With the naive start, at most p (the scheme's order).
int expected_agreement_slope(const SystemInfo& sys, const std::string& scheme, int K,
                             AgreementStart start = AgreementStart::shooting);

}  // namespace geomint::modified
