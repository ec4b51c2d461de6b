// The coefficient families satisfy their order conditions to round-off, checked without writing the conditions
// down: a symmetric second-order map is modelled by Phi_h = exp(hA + h^3 B + h^5 C + h^7 D + h^9 E) (a symmetric
// method's logarithm has only odd powers of h) with random 6 x 6 matrices, whose products up to degree 9 satisfy no
// accidental identity, and the composition Phi_{w_s h} ... Phi_{w_1 h} is expanded as a power series in h with
// matrix coefficients (long double). It has order p exactly when its coefficients of h^1 .. h^p equal those of the
// flow exp(hA): every order condition of symmetric compositions (Hairer–Lubich–Wanner, Sect. V.3.2) is one
// combination of these matrix entries. Each coefficient is compared with the size of the terms it sums (the same
// series in absolute values), and the first one past the order must not vanish.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "geomint/error.hpp"
#include "geomint/generic/composition_families.hpp"

using namespace geomint;
using geomint::generic::CompositionFamily;

namespace {

constexpr int kDim = 6;
using Mat = Eigen::Matrix<long double, kDim, kDim>;
using Series = std::vector<Mat>;  // coefficient k of h^k, k = 0..degree

Series multiply(const Series& a, const Series& b) {
  const std::size_t D = a.size() - 1;
  Series c(D + 1, Mat::Zero());
  for (std::size_t i = 0; i <= D; ++i)
    for (std::size_t j = 0; i + j <= D; ++j) c[i + j] += a[i] * b[j];
  return c;
}

// exp(X) for X(0) = 0, truncated at X's degree.
Series exponential(const Series& X) {
  const std::size_t D = X.size() - 1;
  Series E(D + 1, Mat::Zero()), term(D + 1, Mat::Zero());
  E[0] = term[0] = Mat::Identity();
  for (std::size_t k = 1; k <= D; ++k) {
    term = multiply(term, X);
    for (auto& t : term) t /= static_cast<long double>(k);
    for (std::size_t i = 0; i <= D; ++i) E[i] += term[i];
  }
  return E;
}

struct Defects {
  std::vector<long double> relative;  // |composition - flow| / (size of the terms), per degree
};

// G[k]: the coefficient of h^k in the basic method's logarithm (odd k). With `absolute`, every matrix and weight
// is replaced by its absolute value: the series then bounds the size of the terms each coefficient sums.
Series composition(const std::vector<long double>& w, const std::vector<Mat>& G, bool absolute) {
  const std::size_t D = G.size() - 1;
  Series P(D + 1, Mat::Zero());
  P[0] = Mat::Identity();
  for (const long double wi : w) {
    Series X(D + 1, Mat::Zero());
    long double power = 1;
    for (std::size_t k = 1; k <= D; ++k) {
      power *= absolute ? std::abs(wi) : wi;
      X[k] = power * (absolute ? Mat(G[k].cwiseAbs()) : G[k]);
    }
    P = multiply(exponential(X), P);  // stage i acts after the stages before it
  }
  return P;
}

Defects defects(const std::vector<long double>& w, int degree) {
  std::mt19937 rng(2024);
  std::normal_distribution<long double> normal(0, 1 / std::sqrt(static_cast<long double>(kDim)));
  std::vector<Mat> G(static_cast<std::size_t>(degree + 1), Mat::Zero());
  for (int k = 1; k <= degree; k += 2) G[static_cast<std::size_t>(k)] = Mat::NullaryExpr([&](Eigen::Index, Eigen::Index) { return normal(rng); });
  const Series P = composition(w, G, false), S = composition(w, G, true);
  // the flow: exp(hA), i.e. one stage of weight 1 with the higher terms removed
  std::vector<Mat> A(G.size(), Mat::Zero());
  A[1] = G[1];
  const Series F = composition({1.0L}, A, false);
  Defects d;
  for (int k = 0; k <= degree; ++k) {
    const auto K = static_cast<std::size_t>(k);
    d.relative.push_back((P[K] - F[K]).cwiseAbs().maxCoeff() / S[K].maxCoeff());
  }
  return d;
}

const long double eps = std::numeric_limits<long double>::epsilon();

}  // namespace

TEST_CASE("every composition family is symmetric, consistent and of its stated order to round-off", "[composition][families]") {
  const auto& all = generic::composition_families();
  REQUIRE(all.size() == 4);
  for (const CompositionFamily& f : all) {
    const auto s = f.weights.size();
    long double sum = 0, sum_abs = 0;
    for (std::size_t i = 0; i < s; ++i) {
      sum += f.weights[i];
      sum_abs += std::abs(f.weights[i]);
      INFO(f.name << " w_" << i + 1);
      CHECK(f.weights[i] == f.weights[s - 1 - i]);
    }
    INFO(f.name << ": sum w - 1 = " << static_cast<double>(sum - 1) << ", sum |w| = " << static_cast<double>(sum_abs));
    CHECK(std::abs(sum - 1) <= 4 * eps * sum_abs);
    // the conditions sum w^k = 0, k = 3, 5, .., p - 1 (necessary; the matrix series below checks all of them)
    for (int k = 3; k < f.order; k += 2) {
      long double pk = 0, pk_abs = 0;
      for (const long double w : f.weights) {
        pk += std::pow(w, static_cast<long double>(k));
        pk_abs += std::pow(std::abs(w), static_cast<long double>(k));
      }
      INFO(f.name << ": sum w^" << k << " = " << static_cast<double>(pk) << " (terms up to " << static_cast<double>(pk_abs) << ")");
      CHECK(std::abs(pk) <= 16 * eps * pk_abs);
    }
    const Defects d = defects(f.weights, f.order + 1);
    for (int k = 1; k <= f.order; ++k) {
      INFO(f.name << ": degree " << k << " defect " << static_cast<double>(d.relative[static_cast<std::size_t>(k)])
                  << " of the terms' size (long double eps " << static_cast<double>(eps) << ")");
      CHECK(d.relative[static_cast<std::size_t>(k)] <= 64 * eps);
    }
    // and not of higher order: the error term of degree p + 1 is there (kahanli8's is small by design, 3e-7)
    INFO(f.name << ": degree " << f.order + 1 << " defect " << static_cast<double>(d.relative.back()));
    CHECK(d.relative.back() > 1e6L * 64 * eps);
  }
}

TEST_CASE("the order check sees a perturbed weight and the 15-digit coefficients of Yoshida's paper", "[composition][families]") {
  // Perturbing the outer pair of yoshida6a by 1e-12 (and the middle to keep the sum) breaks the order-4 and
  // order-6 conditions at that size, far above round-off.
  auto w = generic::find_composition_family("yoshida6a").weights;
  w.front() += 1e-12L;
  w.back() += 1e-12L;
  w[3] -= 2e-12L;
  const Defects d = defects(w, 7);
  CHECK(d.relative[1] <= 64 * eps);  // consistency kept
  CHECK(d.relative[3] > 1e-14L);
  CHECK(d.relative[3] < 1e-10L);
  // Yoshida's Table 1 (and the contact-integrators anchor) print solution A to 15 digits: order 6 only to 1e-15.
  const long double w1 = -1.17767998417887L, w2 = 0.235573213359357L, w3 = 0.784513610477560L, w0 = 1 - 2 * (w1 + w2 + w3);
  const Defects printed = defects({w3, w2, w1, w0, w1, w2, w3}, 7);
  INFO("15-digit solution A: degree 3 defect " << static_cast<double>(printed.relative[3]) << ", degree 5 "
                                               << static_cast<double>(printed.relative[5]));
  CHECK(std::max(printed.relative[3], printed.relative[5]) > 4 * 64 * eps);  // the check above would refuse them
  CHECK(std::max(printed.relative[3], printed.relative[5]) < 1e-13L);
}

TEST_CASE("composition names are <family>:<scheme> and unknown families are refused by name", "[composition][families]") {
  const auto n = generic::parse_composition_name("yoshida6a:contact-trapezoid");
  CHECK(n.family == "yoshida6a");
  CHECK(n.base == "contact-trapezoid");
  CHECK(generic::composition_name(n.family, n.base) == "yoshida6a:contact-trapezoid");
  CHECK_THROWS_WITH(generic::parse_composition_name("la-trapezoid"), Catch::Contains("<family>:<scheme>"));
  CHECK_THROWS_WITH(generic::parse_composition_name(":la"), Catch::Contains("<family>:<scheme>"));
  CHECK_THROWS_WITH(generic::parse_composition_name("a:b:c"), Catch::Contains("<family>:<scheme>"));
  CHECK_THROWS_WITH(generic::parse_composition_name("nosuch:la"),
                    Catch::Contains("unknown composition family 'nosuch'") && Catch::Contains("kahanli8"));
  CHECK(generic::find_composition_family("kahanli8").stages() == 17);
  CHECK(generic::find_composition_family("suzuki4").stages() == 5);
}
