// The parts of the generic step that know nothing of a system: the linear solve of Newton's update (J's inverse
// assembled by blocks when the step has constraints) and the predictor (its extrapolation degree chosen by its own
// errors).
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <random>

#include <Eigen/SVD>

#include "geomint/generic/newton.hpp"
#include "geomint/generic/predictor.hpp"

using namespace geomint;
using generic::JacobianInverse;

namespace {

constexpr double eps = std::numeric_limits<double>::epsilon();
using Mat4 = Mat<double, 4, 4>;
using Vec4 = Vec<double, 4>;

// A step's Jacobian with one constraint: [[B, -a], [a^T / h, 0]], B near -M/h (the shape of LA's rows, h = 0.1).
Mat4 saddle(std::mt19937& rng, double h) {
  std::uniform_real_distribution<double> u(-1, 1);
  Mat4 J = Mat4::Zero();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) J(r, c) = (r == c ? -(1 + 0.5 * (1 + u(rng))) / h : 0.3 * u(rng));
  for (int r = 0; r < 3; ++r) {
    const double a = u(rng);
    J(r, 3) = -a;
    J(3, r) = (a + 0.1 * u(rng)) / h;
  }
  return J;
}

// max over rows of |J dx + R| against the size of the terms of that row: what a backward-stable solve leaves.
double relative_residual(const Mat4& J, const Vec4& dx, const Vec4& R) {
  double worst = 0;
  for (int r = 0; r < 4; ++r) {
    double scale = std::abs(R(r));
    for (int c = 0; c < 4; ++c) scale += std::abs(J(r, c) * dx(c));
    worst = std::max(worst, std::abs(J.row(r).dot(dx) + R(r)) / scale);
  }
  return worst;
}

}  // namespace

TEST_CASE("the inverse of the step's saddle-point Jacobian, assembled by blocks, solves it to round-off", "[generic][newton]") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  double worst = 0, worst_refreshed = 0, worst_vs_full = 0;
  for (int trial = 0; trial < 200; ++trial) {
    Mat4 J = saddle(rng, 0.1);
    Vec4 R;
    for (int i = 0; i < 4; ++i) R(i) = u(rng);
    JacobianInverse<double, 4, 1> blocks;
    JacobianInverse<double, 4> full;
    blocks.factor(J);
    full.factor(J);
    const Vec4 dx = blocks.update(R);
    worst = std::max(worst, relative_residual(J, dx, R));
    // two backward-stable solves differ by at most about cond(J) times their round-off
    const Eigen::JacobiSVD<Mat4> svd(J);
    const double cond = svd.singularValues()(0) / svd.singularValues()(3);
    worst_vs_full = std::max(worst_vs_full, (dx - full.update(R)).cwiseAbs().maxCoeff() / dx.cwiseAbs().maxCoeff() /
                                                (cond * eps));
    // the constraint row and the multiplier column move (a kept Jacobian brought up to date): B's inverse is kept
    const Mat4 moved = saddle(rng, 0.1);
    J.col(3).head<3>() = moved.col(3).head<3>();
    J.row(3).head<3>() = moved.row(3).head<3>();
    blocks.refresh_constraint(J);
    worst_refreshed = std::max(worst_refreshed, relative_residual(J, blocks.update(R), R));
  }
  INFO("max relative residual " << worst << ", after a refresh " << worst_refreshed
                                << "; against the full inverse, in units of cond(J) eps: " << worst_vs_full);
  // A row of J dx + R sums 5 terms, each a few roundings from the blocks' products: 16 eps of the row's terms is the
  // same bound as Newton's stopping rule (kappa = 16).
  CHECK(worst <= 16 * eps);
  CHECK(worst_refreshed <= 16 * eps);
  CHECK(worst_vs_full <= 16);
}

TEST_CASE("the inverse falls back to J's own where the dynamics block alone is singular", "[generic][newton]") {
  // B = diag(1, 1, 0) is singular, J = [[B, e3], [e3^T, 0]] is not (a multiplier that fixes the third unknown).
  Mat4 J = Mat4::Zero();
  J(0, 0) = J(1, 1) = 1;
  J(2, 3) = J(3, 2) = 1;
  J(0, 1) = 0.5;
  const Vec4 R(1, -2, 3, -4);
  JacobianInverse<double, 4, 1> blocks;
  blocks.factor(J);
  const Vec4 dx = blocks.update(R);
  INFO("dx = " << dx.transpose());
  CHECK(dx.allFinite());
  CHECK(relative_residual(J, dx, R) <= 16 * eps);
}

TEST_CASE("the predictor extrapolates to fifth order where the motion is resolved, and falls back where it is not",
          "[generic][newton]") {
  // x(t) = (sin t, cos 2t, exp(-t)) sampled at t_j = t_0 + j h: the prediction of x_{21}, at t = 1 whatever h.
  auto x_at = [](double t) { return Vec<double, 3>(std::sin(t), std::cos(2 * t), std::exp(-t)); };
  auto run = [&](double h, int& degree) {
    const double t0 = 1 - 21 * h;
    generic::Predictor<double, 3, 3> p;
    p.start(x_at(t0), Vec<double, 3>(std::cos(t0), -2 * std::sin(2 * t0), -std::exp(-t0)),
            Vec<double, 3>(-std::sin(t0), -4 * std::cos(2 * t0), std::exp(-t0)));
    for (int j = 1; j <= 20; ++j) p.accept(x_at(t0 + j * h));
    degree = p.degree();
    return (p.predict(h) - x_at(1)).cwiseAbs().maxCoeff();
  };
  std::vector<double> hs{0.02, 0.01, 0.005}, errs;
  for (double h : hs) {
    int degree = 0;
    errs.push_back(run(h, degree));
    INFO("h = " << h << ": error " << errs.back() << ", degree " << degree);
    CHECK(degree == 4);
  }
  const double slope = std::log(errs.front() / errs.back()) / std::log(hs.front() / hs.back());
  INFO("fitted order of the prediction error " << slope << " (errors " << errs[0] << ", " << errs[1] << ", " << errs[2]
                                               << ")");
  // the error of a degree-4 extrapolation is h^5 x^(5): slope 5 (measured 5.00)
  CHECK(std::abs(slope - 5) <= 0.1);
  // At h = 2 the backward differences grow with their order (cos 2t's like |2 sin h|^k = 1.8^k, exp(-t)'s like
  // (e^h - 1)^k = 6.4^k): the quadratic misses least, and the predictor takes it.
  int degree = 0;
  const double coarse = run(2.0, degree);
  INFO("h = 2: error " << coarse << ", degree " << degree);
  CHECK(degree == 2);
}
