#pragma once
// Linear stability of the oscillator schemes over (h, alpha): each step is a 2x2 linear map M, and its
// eigenvalues decide whether the discrete solution is stable, oscillates when the continuous one does,
// or flips sign at every step. The classification uses M obtained by stepping the scheme's own code;
// the analytic trace and determinant below are written independently from the schemes' formulas, so
// tests can hold one against the other at the boundaries.
#include <string>
#include <vector>

#include "geomint/modified/all_orders.hpp"

namespace geomint::modified {

enum class Region : int {
  faithful = 0,        // stable, oscillating exactly when the continuous solution does (alpha < 2)
  wrong_character = 1, // stable, but real eigenvalues while the continuous solution oscillates (or vice versa)
  sign_flip = 2,       // stable, a negative real eigenvalue: the solution flips sign at every step
  unstable = 3,        // spectral radius > 1
};
const char* region_name(Region r);

Region classify(const AllOrders& m, double alpha);

// The same classification for the one-step map M (2n x 2n, row-major) of any linear system, against the
// generator C of its continuous flow: unstable if a |mu| > 1; sign flip if a real mu < 0; wrong character if M
// has a different number of complex-conjugate pairs (oscillating modes) than exp(h C); faithful otherwise. For
// the oscillator (n = 1) this is `classify` above. Also the ratios a researcher reads off the maps:
//   decay_ratio = ln|det M| / (h tr C), the discrete over the continuous rate of phase-space contraction
//                 (for the oscillator a_h / alpha);
//   freq_low, freq_high = arg(mu) / (h Im lambda) for the slowest and the fastest oscillating mode, where both the
//                 discrete and the continuous mode oscillate (NaN otherwise).
struct LinearMapClass {
  Region region;
  double spectral_radius, decay_ratio, freq_low, freq_high;
};
LinearMapClass classify_linear_map(const std::vector<long double>& M, const std::vector<double>& C, int N, double h);

// Analytic trace and determinant of the one-step map, from the schemes' closed forms:
//   la:          tr = (2 + h a - h^2)/(1 + h a),   det = 1/(1 + h a)
//   la-printed:  tr = (2 + a - h^2)/(1 + a),       det = 1/(1 + a)
//   contact:     tr = (1 - h^2/2)(2 - h a),        det = 1 - h a
// Returns false for schemes without an analytic form here.
bool analytic_trace_det(const std::string& scheme, double h, double alpha, double& tr, double& det);

// Where, along h at fixed alpha, the analytic classification changes: the analytic boundaries.
struct BoundaryPoint {
  double h, alpha;
  Region below, above;  // region just below and just above h
};
std::vector<BoundaryPoint> analytic_boundaries(const std::string& scheme, const std::vector<double>& alphas,
                                               double h_min, double h_max);

}  // namespace geomint::modified
