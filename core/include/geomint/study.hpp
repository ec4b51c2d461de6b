#pragma once
// Studies as data: fitted orders (GSL least squares on log err vs log h) and observed orders.
#include <limits>
#include <vector>

namespace geomint {

struct OrderFit {
  double slope = std::numeric_limits<double>::quiet_NaN();
  double intercept = std::numeric_limits<double>::quiet_NaN();
  int points = 0;  // points used after dropping non-finite and round-off ones
};

// Least-squares slope of log(err) against log(h). Points with err <= floor (round-off) or non-finite
// are dropped; fewer than three remaining points give slope NaN.
OrderFit fit_order(const std::vector<double>& h, const std::vector<double>& err, double floor = 1e-13);

// Observed order between successive entries: log(e_{i-1}/e_i) / log(h_{i-1}/h_i); NaN for the first.
std::vector<double> observed_orders(const std::vector<double>& h, const std::vector<double>& err);

// h0, h0/2, h0/4, ... down to the first value <= h_min.
std::vector<double> halving_sequence(double h0, double h_min);

}  // namespace geomint
