#include "geomint/study.hpp"

#include <cmath>

#include <gsl/gsl_fit.h>

#include "geomint/error.hpp"

namespace geomint {

OrderFit fit_order(const std::vector<double>& h, const std::vector<double>& err, double floor) {
  require(h.size() == err.size(), "fit_order: h and err differ in length");
  std::vector<double> x, y;
  for (size_t i = 0; i < h.size(); ++i) {
    if (std::isfinite(err[i]) && err[i] > floor && h[i] > 0) {
      x.push_back(std::log(h[i]));
      y.push_back(std::log(err[i]));
    }
  }
  OrderFit fit;
  fit.points = static_cast<int>(x.size());
  if (x.size() < 3) return fit;
  double c0, c1, cov00, cov01, cov11, sumsq;
  gsl_fit_linear(x.data(), 1, y.data(), 1, x.size(), &c0, &c1, &cov00, &cov01, &cov11, &sumsq);
  fit.slope = c1;
  fit.intercept = c0;
  return fit;
}

std::vector<double> observed_orders(const std::vector<double>& h, const std::vector<double>& err) {
  std::vector<double> out(h.size(), std::nan(""));
  for (size_t i = 1; i < h.size(); ++i) out[i] = std::log(err[i - 1] / err[i]) / std::log(h[i - 1] / h[i]);
  return out;
}

std::vector<double> halving_sequence(double h0, double h_min) {
  require_positive(h0, "h_max");
  require_positive(h_min, "h_min");
  require(h_min <= h0, "h_min must not exceed h_max");
  std::vector<double> hs{h0};
  while (hs.back() > h_min) hs.push_back(hs.back() / 2);
  return hs;
}

}  // namespace geomint
