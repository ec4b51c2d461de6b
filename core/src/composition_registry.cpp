#include "geomint/composition_registry.hpp"

#include "geomint/error.hpp"

namespace geomint {

// One declaration per line of systems.def; each is defined in the system's generated translation unit.
#define GEOMINT_SYSTEM(header, Type) CompositionInfo make_composition_info_##Type();
#include "systems.def"
#undef GEOMINT_SYSTEM

const std::vector<CompositionInfo>& all_compositions() {
  static const std::vector<CompositionInfo> all = {
#define GEOMINT_SYSTEM(header, Type) make_composition_info_##Type(),
#include "systems.def"
#undef GEOMINT_SYSTEM
  };
  return all;
}

const CompositionInfo& find_compositions(const std::string& system) {
  std::string known;
  for (const auto& c : all_compositions()) {
    if (c.system == system) return c;
    known += (known.empty() ? "" : ", ") + c.system;
  }
  throw InputError("unknown system '" + system + "' (known: " + known + ")");
}

}  // namespace geomint
