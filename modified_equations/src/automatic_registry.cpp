#include "geomint/modified/automatic_registry.hpp"

#include "geomint/error.hpp"

namespace geomint::modified {

// One declaration per line of core/src/systems.def; each is defined in its generated translation unit.
#define GEOMINT_SYSTEM(header, Type) ModifiedSystem make_modified_system_##Type();
#include "systems.def"
#undef GEOMINT_SYSTEM

const std::vector<ModifiedSystem>& all_modified_systems() {
  static const std::vector<ModifiedSystem> all = {
#define GEOMINT_SYSTEM(header, Type) make_modified_system_##Type(),
#include "systems.def"
#undef GEOMINT_SYSTEM
  };
  return all;
}

const SchemeInfo& modified_scheme(const SystemInfo& sys, const std::string& name) {
  const SchemeInfo& s = sys.scheme(name);
  if (!s.base.empty())
    throw InputError("'" + name + "' is a composition: modified equations are derived for the schemes with a residual (" +
                     join_names(sys.scheme_names(), ", ") + "), not yet for compositions");
  return s;
}

const ModifiedSystem& find_modified_system(const std::string& name) {
  for (const auto& s : all_modified_systems())
    if (s.name == name) return s;
  std::string known;
  for (const auto& s : all_modified_systems()) known += (known.empty() ? "" : ", ") + s.name;
  throw InputError("unknown system '" + name + "' (known: " + known + ")");
}

}  // namespace geomint::modified
