#pragma once
// Infeasible work is refused before it starts: each check throws InputError (one line naming the estimate and
// the limit; guarded_main exits 2). step_count (error.hpp) applies the step checks to every run of every
// program; programs add what only they know (stored values, number of runs).
#include <string>

namespace geomint {

// The largest number of steps of one run: far beyond any paper figure (1e6) and far below LONG_MAX.
constexpr double max_steps_per_run = 1e11;
// The time budget, in steps of all runs of one program together, each step weighted by its cost in cheap steps
// (a closed form or one Newton update on a small system, ~36 ns: 1e11 of them are about an hour). A program whose
// planned steps cost more says so where it plans them, with the cost it measured (a modified equation's solution
// by Odeint costs 1e4 cheap steps and more). --no-budget lifts it.
constexpr double step_budget = 1e11;
// Programs whose work is timed loops of a given length (benchmarks of evaluations) know their time exactly:
// their seconds in all, against an hour. --no-budget lifts it too.
constexpr double seconds_budget = 3600;

// --no-budget (Cli) switches the time budget off; the machine limits (memory, long) stay.
void set_budget_enabled(bool enabled);
bool budget_enabled();

// How the refusal tells the user to lift the time budget: "--no-budget" (a program's option, the default) or,
// set by a caller that has no command line, its own spelling ("budget=False" in the Python module).
void set_budget_opt_out(const std::string& how);

// One top-level call's budget (a Python module call): the planned totals start from zero, the time budget is on
// or off as the caller says, and refusals name "budget=False"; all restored at the end of the scope. A program
// plans once per process; a module plans once per call, so a refused call must not count against the next one.
class BudgetScope {
 public:
  explicit BudgetScope(bool enabled, std::string opt_out = "budget=False");
  ~BudgetScope();
  BudgetScope(const BudgetScope&) = delete;
  BudgetScope& operator=(const BudgetScope&) = delete;

 private:
  bool enabled_;
  double steps_, seconds_;
  std::string opt_out_;
};

// Throws unless `steps` (a count, possibly huge or non-finite) fits a long and max_steps_per_run.
void check_steps(double steps, const std::string& what);
// Adds `steps` (each costing `cost` cheap steps) to the program's planned total and throws when it exceeds
// step_budget (unless --no-budget).
void plan_steps(double steps, const std::string& what, double cost = 1);
// Adds `seconds` of timed loops to the program's plan and throws when they exceed seconds_budget (unless
// --no-budget).
void plan_seconds(double seconds, const std::string& what);
// Throws when `bytes` to be stored exceed MemAvailable (/proc/meminfo; no check where it cannot be read).
void check_memory(double bytes, const std::string& what);
// Throws when a tolerance is below what a double can resolve (4 eps) or is not a positive finite number.
void check_tolerance(double tol, const std::string& name);
// Available memory in bytes (MemAvailable), or a negative number when unknown.
double available_memory();

}  // namespace geomint
