#pragma once
// The nonholonomic benchmark suite: systems whose motion is known exactly, or whose invariants are, each a system
// file of docs/systems/ at stated parameters, with what is exact of it as functions of a state (t, q, q').
//
//   rolling-disk, rolling-disk-damped   q(t) in closed form (the damped motion is the free one at the time
//                                       s = (1 - e^{-alpha t})/alpha): every coordinate is an observable
//   sleigh, sleigh-damped               the heading theta, the speed along it u and the turning rate omega in
//                                       closed form (u = V tanh(k s + c), omega = V sqrt(m/J) sech(k s + c), both
//                                       times e^{-alpha t}); x, y have no elementary closed form and are not observed
//   suslov                              the body rates (omega1, omega2) = (A cos psi, B sin psi),
//                                       sin(psi - psi*) = tanh(R t + c)
//   contact-oscillator,                 y and y' (y'' = -y exactly); invariants H, H_y, H - H_y
//   nonreversible-oscillator
//
// Every formula here is derived and checked symbolically in python/tests/test_nonholonomic_exact.py; the C++ is
// held to Odeint on the systems' own equations (tests/studies/nonholonomic_suite.test.cpp).
// The damped problems' invariants carry their exact decay: E e^{2 alpha t} for a damping proportional to the
// kinetic metric (no potential), so that each is a constant of the exact motion whatever alpha.
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "geomint/formula/model.hpp"
#include "geomint/registry.hpp"

namespace geomint {

struct SuiteProblem {
  std::string name;    // the problem's name (a system at given parameters)
  std::string file;    // its system file, docs/systems/<file>.geomint
  ParamValues params;  // overrides of the file's defaults
  std::string doc;
  std::vector<std::string> observables;  // what is exact of the motion, in suite_exact's order
  std::size_t positions = 0;             // how many of them (the first) are functions of t and q alone
  // The least order a scheme's position observables show here (a first-order variational scheme's positions of an
  // undamped, decoupled oscillator are Stormer-Verlet's: y_{j+1} - 2 y_j + y_{j-1} = -h^2 y_j, second order).
  int least_order = 1;
  std::vector<std::string> invariants;   // constants of the exact motion, in suite_invariant's order
  bool reversible = true;                // under (q, p) -> (q, -p), the canonical reversing map
};

// Every problem, in the order of the tables.
const std::vector<SuiteProblem>& suite_problems();
const SuiteProblem& find_suite_problem(const std::string& name);  // InputError naming the known ones

// A problem loaded: its system file compiled, its registry entry, every parameter's value.
struct SuiteSystem {
  const SuiteProblem* problem = nullptr;
  std::shared_ptr<const formula::FormulaModel> model;
  std::shared_ptr<const SystemInfo> info;
  ParamValues values;  // every parameter of the file, the problem's overrides applied
  double param(const std::string& name) const;
};
// `dir` holds the system files (docs/systems of the source tree).
SuiteSystem load_suite_system(const SuiteProblem& problem, const std::string& dir);

// The state a problem is observed in: t, q (n), q' (n), padded to the largest shape.
constexpr int suite_max_dof = 4;
using SuiteState = std::array<double, 1 + 2 * suite_max_dof>;
SuiteState suite_state(double t, const double* q, const double* v, int n);

// The observables of the exact motion at t, and of a state (the same quantities computed from (q, q')).
std::vector<double> suite_exact(const SuiteSystem& sys, double t);
std::vector<double> suite_observe(const SuiteSystem& sys, const SuiteState& x);

// The error of a run (rows of q and of v at times t) against the exact observables: max_j max_i |observable_i -
// exact_i| over the position observables where the problem has them; else over all of them with the run's v (a
// scheme's velocity from its momentum p_j, first-order accurate on the constrained schemes whatever their order:
// p_j precedes the step's constraint impulse).
double suite_error(const SuiteSystem& sys, const std::vector<double>& t, const std::vector<double>& q,
                   const std::vector<double>& v);

// Invariant k of a state and, when grad is given, its gradient with respect to (t, q, q') (automatic
// differentiation; entries past the system's n are zero).
double suite_invariant(const SuiteSystem& sys, std::size_t k, const SuiteState& x, SuiteState* grad = nullptr);

}  // namespace geomint
