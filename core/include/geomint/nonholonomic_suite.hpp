#pragma once
// The nonholonomic benchmark suite: systems whose motion is known exactly, or whose invariants are, each a system
// file of docs/systems/ at stated parameters, with what is exact of it as functions of a state (t, q, q').
//
//   rolling-disk, rolling-disk-damped   q(t) in closed form (the damped motion is the free one at the time
//                                       s = (1 - e^{-alpha t})/alpha): every coordinate is an observable
//   sleigh, sleigh-damped               the speed along the heading u, the turning rate omega and the heading theta
//                                       in closed form (u = V tanh(k s + c), omega = V sqrt(m/J) sech(k s + c), both
//                                       times e^{-alpha t}); x, y have no elementary closed form and are not observed
//   suslov                              the body rates (omega1, omega2) = (A cos psi, B sin psi),
//                                       sin(psi - psi*) = tanh(R t + c)
//   contact-oscillator,                 y and y' (y'' = -y exactly); invariants H, H_y, H - H_y
//   nonreversible-oscillator
//
// Every formula here is derived and checked symbolically in python/tests/test_nonholonomic_exact.py; the C++ is
// held to Odeint on the systems' own equations (tests/nonholonomic_suite.test.cpp).
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

// Invariant k of a state and, when grad is given, its gradient with respect to (t, q, q') (automatic
// differentiation; entries past the system's n are zero).
double suite_invariant(const SuiteSystem& sys, std::size_t k, const SuiteState& x, SuiteState* grad = nullptr);

}  // namespace geomint
