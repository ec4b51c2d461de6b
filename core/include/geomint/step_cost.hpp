#pragma once
// What one step costs in the budget's cheap steps (budget.hpp: a closed form, ~36 ns; 1e11 of them are about an
// hour), so that a program plans the time of the steps it will take and not only their number.
#include <string>

#include "geomint/registry.hpp"

namespace geomint {

// A generic Newton step in a study's regime (runs of the system's horizon, two updates and a fresh Jacobian a
// step) against the cheap step: bench_generic's "runs of T" rows measured 51-682 ns for la on the pendulum, the
// particle and the knife edge (1.4-19 cheap steps) and up to 2.7x that for contact-trapezoid's implicit z; the
// bound for the small systems of the registry, rounded up.
constexpr double generic_step_cost = 20;

// One step of `scheme` (a composition: all its stages) on `sys` by `path`: 1 where a closed form runs it,
// generic_step_cost where the generic Newton step does, times the stages of a composition. InputError for an
// unknown scheme (naming the known ones).
double step_cost(const SystemInfo& sys, const std::string& scheme, Path path);

// The plan of one run of `scheme` (integrate): its T/h steps at step_cost against the time budget, and the rows it
// keeps (N/every + 1, Run::bytes_per_step each, `copies` times: a caller that copies the run holds it twice)
// against the memory available, which no opt-out lifts. `raise` names what to raise in the message.
void plan_run(const SystemInfo& sys, const std::string& scheme, Path path, double h, double T, long every,
              double copies = 1, const std::string& raise = "--every");

}  // namespace geomint
