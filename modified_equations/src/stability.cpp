#include "geomint/modified/stability.hpp"

#include <algorithm>
#include <cmath>
#include <complex>

#include <Eigen/Eigenvalues>

#include "geomint/error.hpp"
#include "geomint/registry.hpp"

namespace geomint::modified {

const char* region_name(Region r) {
  switch (r) {
    case Region::faithful: return "faithful";
    case Region::wrong_character: return "wrong-character";
    case Region::sign_flip: return "sign-flip";
    case Region::unstable: return "unstable";
  }
  return "?";
}

namespace {
Region classify_trace_det(double tr, double det, double alpha) {
  const double disc = tr * tr - 4 * det;
  const bool continuous_oscillates = alpha < 2;
  if (disc < 0) {
    if (det > 1) return Region::unstable;
    return continuous_oscillates ? Region::faithful : Region::wrong_character;
  }
  const double s = std::sqrt(disc);
  const double l1 = (tr + s) / 2, l2 = (tr - s) / 2;
  if (std::max(std::abs(l1), std::abs(l2)) > 1) return Region::unstable;
  if (l2 < 0) return Region::sign_flip;
  return continuous_oscillates ? Region::wrong_character : Region::faithful;
}
}  // namespace

Region classify(const AllOrders& m, double alpha) { return classify_trace_det(m.tr, m.det, alpha); }

LinearMapClass classify_linear_map(const std::vector<long double>& ML, const std::vector<double>& C, int N, double h) {
  require(N > 0 && ML.size() == static_cast<std::size_t>(N * N) && C.size() == ML.size(), "classify_linear_map: sizes");
  const std::vector<double> M(ML.begin(), ML.end());  // eigenvalues in double (a generic step's matrix is double)
  const Eigen::MatrixXd Mm = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(M.data(), N, N);
  const Eigen::MatrixXd Cm = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(C.data(), N, N);
  const Eigen::VectorXcd mu = Eigen::EigenSolver<Eigen::MatrixXd>(Mm, false).eigenvalues();
  const Eigen::VectorXcd lam = Eigen::EigenSolver<Eigen::MatrixXd>(Cm, false).eigenvalues();
  // a root is real when its imaginary part is below round-off of its size
  auto is_real = [](std::complex<double> z) { return std::abs(z.imag()) <= 1e-12 * (1 + std::abs(z)); };
  LinearMapClass out{};
  int pairs_m = 0, pairs_c = 0;
  bool negative = false;
  out.spectral_radius = 0;
  for (int i = 0; i < N; ++i) {
    out.spectral_radius = std::max(out.spectral_radius, std::abs(mu(i)));
    if (is_real(mu(i))) {
      if (mu(i).real() < 0) negative = true;
    } else if (mu(i).imag() > 0) {
      ++pairs_m;
    }
    if (!is_real(lam(i)) && lam(i).imag() > 0) ++pairs_c;
  }
  if (out.spectral_radius > 1 + 1e-12)
    out.region = Region::unstable;
  else if (negative)
    out.region = Region::sign_flip;
  else if (pairs_m != pairs_c)
    out.region = Region::wrong_character;
  else
    out.region = Region::faithful;
  const double det = Mm.determinant(), tr = Cm.trace();
  out.decay_ratio = det > 0 && tr != 0 ? std::log(det) / (h * tr) : missing_value;
  // oscillating modes, sorted by frequency: the discrete ones by arg(mu) / h, the continuous by Im(lambda)
  std::vector<double> wd, wc;
  for (int i = 0; i < N; ++i) {
    if (!is_real(mu(i)) && mu(i).imag() > 0) wd.push_back(std::arg(mu(i)) / h);
    if (!is_real(lam(i)) && lam(i).imag() > 0) wc.push_back(lam(i).imag());
  }
  std::sort(wd.begin(), wd.end());
  std::sort(wc.begin(), wc.end());
  out.freq_low = out.freq_high = missing_value;
  if (!wd.empty() && wd.size() == wc.size()) {
    out.freq_low = wd.front() / wc.front();
    out.freq_high = wd.back() / wc.back();
  }
  return out;
}

bool analytic_trace_det(const std::string& scheme, double h, double a, double& tr, double& det) {
  if (scheme == "la") {
    tr = (2 + h * a - h * h) / (1 + h * a);
    det = 1 / (1 + h * a);
  } else if (scheme == "la-printed") {
    tr = (2 + a - h * h) / (1 + a);
    det = 1 / (1 + a);
  } else if (scheme == "contact") {
    tr = (1 - h * h / 2) * (2 - h * a);
    det = 1 - h * a;
  } else {
    return false;
  }
  return true;
}

std::vector<BoundaryPoint> analytic_boundaries(const std::string& scheme, const std::vector<double>& alphas,
                                               double h_min, double h_max) {
  std::vector<BoundaryPoint> out;
  double tr, det;
  if (!analytic_trace_det(scheme, 1, 1, tr, det)) return out;
  auto region = [&](double h, double a) {
    analytic_trace_det(scheme, h, a, tr, det);
    return classify_trace_det(tr, det, a);
  };
  const int n = 4000;  // fine log scan, then bisection to round-off
  for (double a : alphas) {
    double h0 = h_min;
    Region r0 = region(h0, a);
    for (int i = 1; i <= n; ++i) {
      const double h1 = h_min * std::pow(h_max / h_min, static_cast<double>(i) / n);
      const Region r1 = region(h1, a);
      // Several boundaries may fall in one scan interval (LA's sign-flip sliver below its stability
      // limit): bisect for the first change, record it, and go on from just above it.
      while (r1 != r0) {
        double lo = h0, hi = h1;
        for (int k = 0; k < 200 && hi - lo > 1e-15 * hi; ++k) {
          const double mid = (lo + hi) / 2;
          (region(mid, a) == r0 ? lo : hi) = mid;
        }
        const Region above = region(hi, a);
        out.push_back({(lo + hi) / 2, a, r0, above});
        h0 = hi;
        r0 = above;
      }
      h0 = h1;
      r0 = r1;
    }
  }
  return out;
}

}  // namespace geomint::modified
