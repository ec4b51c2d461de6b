#pragma once
// RegisteredFormulaSystem<n, m, holonomic, P>: a formula system in the form the registry's builders take
// (generic::make_system_info, modified::make_modified_system): a static `name` and a default constructor. Both come
// from the model of the call in progress on this thread (FormulaCall), which the registry entry of a model sets
// around each of its operations (formula_registry.hpp). The builders then compile once per shape, for every model
// of that shape, and the registry keeps its plain function pointers. Heavy (it brings the whole generic core when
// instantiated): included only by the generated shape translation units.
#include <string>

#include "geomint/formula/formula_call.hpp"
#include "geomint/formula/formula_system.hpp"

namespace geomint::formula {

template <int N, int M = 0, bool Holonomic = false, class P = double>
struct RegisteredFormulaSystem : FormulaSystemT<N, M, Holonomic, P> {
  // The builders write Sys::name and Sys::description into messages and the entry: the current model's.
  static inline thread_local const std::string& name = FormulaCall::name();
  static inline thread_local const std::string& description = FormulaCall::description();
  RegisteredFormulaSystem() : FormulaSystemT<N, M, Holonomic, P>(FormulaCall::model()) {}
};

}  // namespace geomint::formula
