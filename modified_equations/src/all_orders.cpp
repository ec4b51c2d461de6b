#include "geomint/modified/all_orders.hpp"

#include <algorithm>
#include <cmath>

namespace geomint::modified {

AllOrders all_orders_from_trace_det(double tr, double det, double h) {
  AllOrders r;
  r.tr = tr;
  r.det = det;
  const double disc = tr * tr - 4 * det;
  if (disc < 0) {
    // lambda = sqrt(det) e^{+-i theta}: a = -ln(det)/h, omega = theta/h, b = omega^2 + a^2/4
    r.oscillating = true;
    r.valid = det > 0;
    r.spectral_radius = std::sqrt(det);
    if (r.valid) {
      const double theta = std::atan2(std::sqrt(-disc), tr);
      r.a = -std::log(det) / h;
      const double w = theta / h;
      r.b = w * w + r.a * r.a / 4;
    }
  } else {
    const double s = std::sqrt(disc);
    const double l1 = (tr + s) / 2, l2 = (tr - s) / 2;
    r.spectral_radius = std::max(std::abs(l1), std::abs(l2));
    r.valid = l1 > 0 && l2 > 0;
    if (r.valid) {
      const double m1 = std::log(l1) / h, m2 = std::log(l2) / h;
      r.a = -(m1 + m2);
      r.b = m1 * m2;
    }
  }
  return r;
}

}  // namespace geomint::modified
