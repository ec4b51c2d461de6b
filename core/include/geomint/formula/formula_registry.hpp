#pragma once
// A system defined by its formulas as a registry entry (registry.hpp's SystemInfo): every program and study that
// takes a registered system by its SystemInfo takes a formula system read at run time too (--system-file, the
// Python module), with no C++ written and nothing rebuilt.
//
// A formula system's type is its shape (n, m, holonomic), and its formulas are data. So the schemes are compiled once
// per shape listed in core/src/formula/shapes.def (one generated translation unit each, like a header system's), and
// an entry's operations are that code's closures over a system holding the entry's model: any number of models live
// at once, each in its own entry. A shape not listed there is compiled at its first use, from the same generated
// units (formula/jit.hpp); with that path off, it is an InputError naming shapes.def, where a line adds it.
#include <memory>
#include <string>
#include <vector>

#include "geomint/formula/model.hpp"
#include "geomint/registry.hpp"

namespace geomint::formula {

// The registry entry of `model` (it holds the model). Its schemes are the core's, without the contact schemes when the
// model has no Herglotz Lagrangian; its parameters are the model's, its references Boost.Odeint on the equations
// derived from the formulas. A shape the build did not compile is compiled at its first use (formula/jit.hpp);
// at_run_time: that path even for a shape the build compiled (the benchmark of the two).
std::shared_ptr<const SystemInfo> formula_system_info(std::shared_ptr<const FormulaModel> model, bool at_run_time = false);

// The Herglotz Lagrangian checked against the force at these parameter values (FormulaSystemT::warnings): empty,
// or one message. Every shape (the check runs at run-time dimensions, checks.hpp).
std::vector<std::string> formula_warnings(const std::shared_ptr<const FormulaModel>& model, const ParamValues& values);

// Whether a scheme of `sys` integrates the Herglotz equations (a contact scheme, or a composition of one): the runs
// where a Herglotz form inconsistent with the force is a different system.
bool contact_family(const SystemInfo& sys, const std::string& scheme);

// The Herglotz form checked before a run of `schemes` at each of `values`, when one of the schemes is of the contact
// family: the message, the first time a run of this model finds the form inconsistent (once per model, however
// many runs, calls, threads or parameter values ask; empty afterwards). The one check behind the Python module's GeomintWarning and the programs' stderr warning.
std::vector<std::string> contact_warnings(const std::shared_ptr<const FormulaModel>& model, const SystemInfo& sys,
                                          const std::vector<ParamValues>& values, const std::vector<std::string>& schemes);

// Whether the build compiled the shape, and the compiled shapes for messages ("n = 1, m = 0; ...").
bool formula_shape_compiled(int n, int m, bool holonomic);
std::string compiled_formula_shapes();

}  // namespace geomint::formula
