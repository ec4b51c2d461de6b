#include "geomint/error.hpp"
#include "geomint/modified/all_orders.hpp"

#include <algorithm>
#include <cmath>

#include "geomint/linear_oscillator.hpp"
#include "geomint/registry.hpp"

namespace geomint::modified {

AllOrders all_orders_from_trace_det(long double tr, long double det, long double h) {
  AllOrders r;
  r.tr = static_cast<double>(tr);
  r.det = static_cast<double>(det);
  const long double disc = tr * tr - 4 * det;
  if (disc < 0) {
    // lambda = sqrt(det) e^{+-i theta}: a = -ln(det)/h, omega = theta/h, b = omega^2 + a^2/4
    r.oscillating = true;
    r.valid = det > 0;
    r.spectral_radius = static_cast<double>(std::sqrt(det));
    if (r.valid) {
      const long double theta = std::atan2(std::sqrt(-disc), tr);
      const long double a = -std::log(det) / h, w = theta / h;
      r.a = static_cast<double>(a);
      r.b = static_cast<double>(w * w + a * a / 4);
    }
  } else {
    const long double s = std::sqrt(disc);
    const long double l1 = (tr + s) / 2, l2 = (tr - s) / 2;
    r.spectral_radius = static_cast<double>(std::max(std::abs(l1), std::abs(l2)));
    r.valid = l1 > 0 && l2 > 0;
    if (r.valid) {
      const long double m1 = std::log(l1) / h, m2 = std::log(l2) / h;
      r.a = static_cast<double>(-(m1 + m2));
      r.b = static_cast<double>(m1 * m2);
    }
  }
  return r;
}

AllOrders all_orders_by_name(const std::string& scheme, double h, double alpha) {
  // the closed form's matrix in long double (row-major (q, p)): the coefficients keep their digits
  const auto M = find_system("oscillator").one_step_matrix({{"alpha", alpha}}, scheme, h, Path::fast);
  return all_orders_from_trace_det(M[0] + M[3], M[0] * M[3] - M[1] * M[2], h);
}

double all_orders_deviation(const AllOrders& m, const std::vector<double>& t, const std::vector<double>& q) {
  if (!m.valid || q.size() < 2) return missing_value;
  const double h = t[1] - t[0];
  const double A = linear_oscillator_solution(m.a, m.b, 1.0, 0.0, h).q;
  const double B = linear_oscillator_solution(m.a, m.b, 0.0, 1.0, h).q;
  const double v0 = (q[1] - q[0] * A) / B;
  double dev = 0;
  for (size_t j = 0; j < q.size(); ++j)
    dev = std::max(dev, std::abs(q[j] - linear_oscillator_solution(m.a, m.b, q[0], v0, t[j]).q));
  return dev;
}

}  // namespace geomint::modified
