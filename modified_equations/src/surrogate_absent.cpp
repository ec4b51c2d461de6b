// A build without GiNaC (GEOMINT_SYMBOLIC=OFF, the sanitizer build): surrogates are built symbolically, so they are
// refused with the reason.
#include "geomint/error.hpp"
#include "geomint/modified/surrogate.hpp"

namespace geomint::modified {

std::string surrogate_shapes() { return "none (this build has no GiNaC: GEOMINT_SYMBOLIC=OFF)"; }

SurrogateSystem build_surrogate(const std::shared_ptr<const formula::FormulaModel>&, const std::string&, int, double, double) {
  throw InputError("surrogates are built symbolically: this build has no GiNaC (GEOMINT_SYMBOLIC=OFF)");
}

}  // namespace geomint::modified
