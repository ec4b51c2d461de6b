#include "geomint/error.hpp"

#include <cmath>
#include <sstream>

namespace geomint {

long step_count(double h, double T) {
  require_positive(h, "h");
  require_positive(T, "T");
  require(h <= T, "h = " + show(h) + " exceeds the horizon T = " + show(T));
  const double n = T / h;
  const double N = std::round(n);
  if (std::abs(n - N) > 1e-9 * N) {
    std::ostringstream os;
    os << "T/h = " << n << " is not an integer: choose h that divides T = " << T;
    throw InputError(os.str());
  }
  return static_cast<long>(N);
}

}  // namespace geomint
