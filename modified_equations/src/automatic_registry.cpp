#include "geomint/modified/automatic_registry.hpp"

#include <algorithm>

#include "geomint/error.hpp"
#include "geomint/generic/composition_families.hpp"

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

const SchemeInfo& modified_scheme(const SystemInfo& sys, const std::string& name) { return sys.scheme(name); }

std::string composition_formulas_refusal(const std::string& name) {
  const auto family = generic::find_composition_family(generic::parse_composition_name(name).family);
  return "'" + name + "' is a composition: its modified equation is computed in numbers, not as formulas (every order "
         "solves for its " + std::to_string(family.stages() - 1) + " interior stage points, and their expressions would "
         "grow with the stages)";
}

double modified_cost_factor(const SystemInfo& sys, const std::string& scheme) {
  const SchemeInfo& s = sys.scheme(scheme);
  if (s.base.empty()) return 1;
  return 4.0 * generic::find_composition_family(generic::parse_composition_name(scheme).family).stages();
}

int expected_agreement_slope(const SystemInfo& sys, const std::string& scheme, int K, AgreementStart start) {
  const int p = sys.scheme(scheme).order;
  const int consistent = p % 2 != 0 ? K + 1 : std::max(p, K + 1 + (K % 2 == 0 ? 1 : 0));
  // the naive start's velocity is off by O(h^p), which the whole run carries
  return start == AgreementStart::naive ? std::min(consistent, p) : consistent;
}

const char* start_name(AgreementStart s) { return s == AgreementStart::naive ? "naive" : "shooting"; }

AgreementStart parse_agreement_start(const std::string& name) {
  if (name == "shooting") return AgreementStart::shooting;
  if (name == "naive") return AgreementStart::naive;
  throw InputError("unknown start '" + name + "' (known: shooting, naive)");
}

const SchemeInfo& formula_scheme(const SystemInfo& sys, const std::string& name) {
  const SchemeInfo& s = sys.scheme(name);
  if (!s.base.empty()) throw InputError(composition_formulas_refusal(name));
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
