#pragma once
// What a caller of the registry's run (registry.hpp) checks of the run it got, apart from the registry's header
// (which every system's generated instance includes).
#include <string>

#include "geomint/registry.hpp"

namespace geomint {

// A kept row is what a caller reads: NumericalFailure naming the first one (its step and t) whose state (q, p,
// v, z), energy or constraint residual is not finite, with `context` (system, scheme, h) in front, so that a
// program's table and the Python module's arrays fail alike instead of carrying inf or nan.
void require_finite_run(const Run& run, const std::string& context);

}  // namespace geomint
