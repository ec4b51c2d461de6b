#pragma once
// The checks of a formula system that depend on its parameter values, on the model directly (dimensions at run
// time): compiled once here rather than in every system shape, where the typed versions (the continuous
// equations of generic/system.hpp through a Hessian per shape) measured 26 s of compile time per shape, as much
// as the rest of a shape's schemes.
//
// Each function takes the parameter table pv = (numbers | parameters | derived values) of FormulaModel.
#include <string>
#include <vector>

#include "geomint/formula/model.hpp"

namespace geomint::formula {

// Throws InputError, naming the place, for: a non-finite parameter, definition, derived value or initial datum;
// T <= 0; an initial position off a holonomic constraint; constraint rows that vanish or are dependent at the
// initial position; a velocity Hessian of L (or of the Herglotz Lagrangian) that is singular at the initial
// data (no Legendre transform); and, when the model is strict, a Herglotz form inconsistent with the force.
void validate_model(const FormulaModel& model, const std::vector<double>& pv);

// The Herglotz equations (2) with z along their flow against the Lagrange–d'Alembert equations with the force,
// at sample points: an empty string when they agree, else one line saying where they do not.
std::string herglotz_mismatch(const FormulaModel& model, const std::vector<double>& pv);

// The exact solution ([exact]) against the initial data and the equations at sample points over [t0, t0 + T]: an
// empty string when it solves them (to 1e-8 of its size), else one line naming the formula and the residual.
std::string exact_mismatch(const FormulaModel& model, const std::vector<double>& pv);

// The continuous equations at a point, from the model's formulas (the same equations as generic::acceleration
// and generic::herglotz_acceleration, at run-time dimensions): the acceleration and the multipliers.
struct ContinuousAcceleration {
  std::vector<double> a, lambda;
};
ContinuousAcceleration continuous_acceleration(const FormulaModel& model, const std::vector<double>& pv, double t,
                                               const std::vector<double>& q, const std::vector<double>& v, double z,
                                               bool herglotz);

}  // namespace geomint::formula
