#include "geomint/error.hpp"

#include <cmath>
#include <sstream>

#include "geomint/budget.hpp"

namespace geomint {

long step_count(double h, double T) {
  require_positive(h, "h");
  require_positive(T, "T");
  require(h <= T, "h = " + show(h) + " exceeds the horizon T = " + show(T));
  const double n = T / h;
  // Before the cast: T/h beyond a long is undefined behaviour (it gave negative step counts), beyond
  // max_steps_per_run it is work no run will finish.
  check_steps(n, "T/h = " + show(T) + "/" + show(h));
  const double N = std::round(n);
  if (std::abs(n - N) > 1e-9 * N) {
    std::ostringstream os;
    os << "T/h = " << n << " is not an integer: choose h that divides T = " << T;
    throw InputError(os.str());
  }
  return static_cast<long>(N);
}

}  // namespace geomint
