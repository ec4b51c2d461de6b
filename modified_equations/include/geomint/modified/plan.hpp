#pragma once
// What the modified-equation entry points check before they start, apart from the registry's headers (which
// every generated instance includes): a point's finiteness and an agreement study's plan.
#include <cstddef>
#include <string>
#include <vector>

#include "geomint/registry.hpp"

namespace geomint::modified {

// InputError naming the first non-finite component of the point (t, q, v, z) a modified equation is asked at: a
// nan there would come back as nan with a residual of 0, which reads as an exact answer.
void require_finite_point(double t, const std::vector<double>& q, const std::vector<double>& v, double z);
// The programs' plan of an agreement study (modified_agreement): `starts` x T/h planned steps of the order-K
// modified solution (Odeint at tol 1e-13 along it, about 0.5 ms a step: 1e4 cheap steps), times the scheme's
// modified_cost_factor, added to the budget (budget.hpp).
void plan_agreement(const SystemInfo& sys, const std::string& scheme, double h, double T, std::size_t starts = 1);

}  // namespace geomint::modified
