#pragma once
// The automatic modified equations of a system defined by its formulas, as a registry entry (ModifiedSystem): what
// formula_registry.hpp is for the schemes. Compiled for the shapes of core/src/formula/shapes.def marked for
// modified equations (numeric and as formulas); another shape is an InputError naming that file.
#include <memory>

#include "geomint/formula/model.hpp"
#include "geomint/modified/automatic_registry.hpp"

namespace geomint::modified {

// The entry of `model` (it holds the model); its schemes are the applicable ones (no contact
// scheme without a Herglotz Lagrangian), its formulas' symbols the model's parameters.
std::shared_ptr<const ModifiedSystem> formula_modified_system(std::shared_ptr<const formula::FormulaModel> model);

}  // namespace geomint::modified
