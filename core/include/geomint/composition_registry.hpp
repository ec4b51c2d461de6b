#pragma once
// What only compositions have, for tests and benchmarks, without their templates: a CompositionInfo per system,
// built in the system's generated translation unit (core/src/system_instance.cpp.in) by
// generic::make_composition_info<Sys>() (generic/composition_info.hpp), where the system's schemes are already
// instantiated. A composition itself runs through SystemInfo like any scheme, by its name "<family>:<base>"
// (generic/composition_families.hpp), the base one of the system's symmetric schemes. Light: include this, not
// the generic headers, in programs.
#include <string>
#include <vector>

#include "geomint/registry.hpp"

namespace geomint {

// A step of h and then a step of -h from a state reached by the base scheme: how far it lands from where it
// started (max norms), and the size of that state. For a symmetric map all of it is round-off; a constrained
// scheme brings p back only up to a multiple of A(t, q)^T (generic/composition.hpp), so the part of dp
// orthogonal to those directions is reported apart.
struct SymmetryDefect {
  double dq = 0, dz = 0, dp = 0, dp_tangent = 0;
  double q = 0, p = 0;
};

struct CompositionInfo {
  std::string system;
  std::vector<std::string> bases;  // the system's symmetric schemes, on which compositions are built

  // The base scheme's step of h then -h, from the state after `steps` steps of h from the initial data.
  SymmetryDefect (*symmetry)(const ParamValues&, const std::string& base, double h, long steps) = nullptr;
  // For benchmarks (bench_compose): N steps from the initial data, nothing stored, returning the Newton updates
  // they took — of the composition `name` at step h, or of the base scheme alone at step h (any nonzero h, not
  // tied to T: a stage's step).
  long (*steps)(const ParamValues&, const std::string& name, double h, long N) = nullptr;
  long (*base_steps)(const ParamValues&, const std::string& base, double h, long N) = nullptr;
};

const std::vector<CompositionInfo>& all_compositions();
const CompositionInfo& find_compositions(const std::string& system);  // InputError naming the known systems

}  // namespace geomint
