#include "geomint/modified/automatic_registry.hpp"

#include <algorithm>
#include <cmath>

#include "geomint/budget.hpp"
#include "geomint/error.hpp"
#include "geomint/generic/composition_families.hpp"
#include "geomint/modified/formula_modified.hpp"
#include "geomint/modified/plan.hpp"

namespace geomint::modified {

// One declaration per line of core/src/systems.def; each is defined in its generated translation unit.
#define GEOMINT_SYSTEM(header, Type) ModifiedSystem make_modified_system_##Type();
#include "systems.def"
#undef GEOMINT_SYSTEM

namespace {
// In the order of systems.def, as the core's entries are: an entry's index there is its place here.
const std::vector<ModifiedSystem>& header_systems() {
  static const std::vector<ModifiedSystem> all = {
#define GEOMINT_SYSTEM(header, Type) make_modified_system_##Type(),
#include "systems.def"
#undef GEOMINT_SYSTEM
  };
  return all;
}
}  // namespace

std::shared_ptr<const ModifiedSystem> modified_system(const SystemInfo& sys) {
  if (sys.model) return formula_modified_system(sys.model);
  const auto& all = header_systems();
  require(sys.index >= 0 && static_cast<std::size_t>(sys.index) < all.size() && all[static_cast<std::size_t>(sys.index)].name == sys.name,
          "system '" + sys.name + "' is neither an entry of core/src/systems.def nor defined by formulas");
  // the table lives as long as the process: a pointer that owns nothing
  return std::shared_ptr<const ModifiedSystem>(std::shared_ptr<const ModifiedSystem>(), &all[static_cast<std::size_t>(sys.index)]);
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

void require_finite_point(double t, const std::vector<double>& q, const std::vector<double>& v, double z) {
  require(std::isfinite(t), "the point's t = " + show(t) + " is not finite");
  for (std::size_t i = 0; i < q.size(); ++i)
    require(std::isfinite(q[i]), "the point's q" + std::to_string(i + 1) + " = " + show(q[i]) + " is not finite");
  for (std::size_t i = 0; i < v.size(); ++i)
    require(std::isfinite(v[i]), "the point's v" + std::to_string(i + 1) + " = " + show(v[i]) + " is not finite");
  require(std::isfinite(z), "the point's z = " + show(z) + " is not finite");
}

void plan_agreement(const SystemInfo& sys, const std::string& scheme, double h, double T, std::size_t starts) {
  // a planned step costs ~0.5 ms (the order-K modified equation solved by Odeint at tol 1e-13 along it; measured:
  // 2.35 s of CPU per 4410 planned steps, T = 2 -> 4 at modified_agreement's defaults): 1e4 cheap steps, times a
  // composition's cost factor
  plan_steps(modified_cost_factor(sys, scheme) * static_cast<double>(starts) * static_cast<double>(step_count(h, T)),
             "the agreement (starts x T/h of the modified solution)", 1e4);
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

const ModifiedSystem& find_modified_system(const std::string& name) { return *modified_system(find_system(name)); }

}  // namespace geomint::modified
