// The automatic-modified-equation programs: bad input gets one line, exit 2, nothing written; the table that
// `make figures` writes has the promised columns and the pendulum's F_0 = -sin q - alpha q'.
#include <catch2/catch.hpp>

#include <cmath>
#include <algorithm>
#include <filesystem>
#include <string>

#include "geomint/modified/all_orders.hpp"
#include "geomint/plots/figure.hpp"
#include "geomint/registry.hpp"
#include "geomint/study.hpp"
#include "helpers.hpp"

using namespace geomint::testing;

TEST_CASE("modified-equation programs reject bad input", "[programs][modified]") {
  check_rejected("modified_equation", "--order 7", "order must be in");
  check_rejected("modified_equation", "--order=-1", "order must be in");
  check_rejected("modified_equation", "--system nosuch", "unknown system 'nosuch'");
  check_rejected("modified_equation", "--schemes nosuch", "unknown scheme 'nosuch'");
  check_rejected("modified_equation", "--q 0.1 0.2", "degrees of freedom");
  check_rejected("modified_equation", "--q nan", "q must be finite");
  // the system's parameters are options of their own, as in every program with --system
  check_rejected("modified_equation", "--alpha abc", "the argument ('abc') for option '--alpha' is invalid");
  check_rejected("modified_equation", "--nosuch 1", "unrecognised option '--nosuch'");
  check_rejected("modified_equation", "--alpha -1", "alpha must be a non-negative");
  check_rejected("modified_equation", "--system pendulum --kappa 1", "unrecognised option '--kappa'");  // the knife edge's
  check_rejected("modified_agreement", "--orders 9 --h-max 0.2", "orders must be in");
  check_rejected("modified_agreement", "--orders 1 2 --h-max 0.1 0.2 0.3", "one per order");
  check_rejected("modified_agreement", "--systems knife-edge", "is constrained");
  check_rejected("modified_agreement", "--h-max 0.3 --T 1", "not an integer");
  check_rejected("modified_agreement", "--tol 1", "tol must be in");
  check_rejected("nonholonomic_modified", "--systems pendulum", "has no constraint");
  check_rejected("nonholonomic_modified", "--radii 1", "radii must be in");
  check_rejected("modified_agreement", "--alpha=-1", "alpha must be a non-negative");
  check_rejected("modified_agreement", "--start euler", "unknown start 'euler'");
  check_rejected("modified_agreement", "--start naive naive", "'naive' is given twice to --start");
  check_rejected("modified_agreement", "--systems oscillator pendulum --all-orders", "'pendulum' is not linear");
  check_rejected("modified_agreement", "--systems oscillator --alpha 0.1 -2", "alpha must be a non-negative");
  check_rejected("nonholonomic_modified", "--alpha nan", "alpha must be a non-negative");
}

TEST_CASE("modified_equation writes F_k per scheme, k and component", "[programs][modified]") {
  const auto dir = fresh_dir("modified-equation");
  const auto r = run_program("modified_equation", "--order 2 --out " + dir.string());
  REQUIRE(r.exit_code == 0);
  const auto t = geomint::plots::read_tsv(dir / "modified_equation.tsv");
  CHECK(t.columns == std::vector<std::string>{"system", "scheme", "alpha", "k", "component", "value"});
  int found = 0;
  for (std::size_t i = 0; i < t.rows.size(); ++i)
    if (t.number(i, "k") == 0 && t.text(i, "component") == "F0") {
      CHECK(t.number(i, "value") == Approx(-std::sin(0.5) - 0.1 * 0.3).epsilon(1e-15));
      ++found;
    }
  CHECK(found == 2);  // la and contact
  std::filesystem::remove_all(dir);
}

TEST_CASE("modified_agreement: the naive start caps the agreement at the scheme's order, and the steps lie on the "
          "modified flow to all orders", "[programs][modified]") {
  using geomint::plots::read_tsv;
  const auto dir = fresh_dir("modified-agreement-starts");
  const auto r = run_program("modified_agreement",
                             "--systems oscillator --schemes la la-trapezoid --orders 0 1 2 --alpha 0.5 1 --T 4 "
                             "--h-max 0.1 --halvings 3 --start shooting naive --all-orders --out " + dir.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const auto fits = read_tsv(dir / "oscillator_modified_agreement_fits.tsv");
  CHECK(fits.columns == std::vector<std::string>{"system", "scheme", "alpha", "start", "K", "fitted_slope",
                                                 "expected_slope", "points"});
  REQUIRE(fits.rows.size() == 2 * 2 * 2 * 3);
  for (std::size_t i = 0; i < fits.rows.size(); ++i) {
    INFO(fits.text(i, "scheme") << " alpha=" << fits.number(i, "alpha") << " " << fits.text(i, "start")
                                << " K=" << fits.number(i, "K") << ": " << fits.number(i, "fitted_slope"));
    // first order: K + 1 consistently, 1 from the naive start; la-trapezoid: 2, then 4 for K = 2 (the odd terms
    // vanish) consistently, 2 from the naive start
    const bool naive = fits.text(i, "start") == "naive";
    const double K = fits.number(i, "K");
    const double expect = fits.text(i, "scheme") == "la" ? (naive ? 1 : K + 1) : (naive || K < 2 ? 2 : 4);
    CHECK(fits.number(i, "expected_slope") == expect);
    CHECK(std::abs(fits.number(i, "fitted_slope") - expect) < 0.3);
  }
  // at K = 0 the naive start is the original equation from the exact initial data: its error is the scheme's
  // global error against the closed form (the discrete runs differ in the last bits: long double against double)
  const auto t = read_tsv(dir / "oscillator_modified_agreement.tsv");
  const auto& osc = geomint::find_system("oscillator");
  int checked = 0;
  for (std::size_t i = 0; i < t.rows.size(); ++i) {
    if (t.text(i, "start") != "naive" || t.number(i, "K") != 0) continue;
    const geomint::ParamValues pv{{"alpha", t.number(i, "alpha")}, {"T", 4}};
    const auto run = osc.run(pv, t.text(i, "scheme"), t.number(i, "h"), geomint::Path::fast, 1);
    const auto exact = osc.exact_positions(pv, run.t);
    double err = 0;
    for (std::size_t j = 0; j < run.t.size(); ++j) err = std::max(err, std::abs(run.q[j] - exact[j]));
    INFO(t.text(i, "scheme") << " h=" << t.number(i, "h"));
    CHECK(std::abs(t.number(i, "err_modified") - err) < 1e-10);
    ++checked;
  }
  CHECK(checked == 2 * 2 * 4);
  // to all orders: a_h = -A_v, b_h = -A_q from the characteristic roots (all_orders_by_name), the steps on the flow
  // of log(M)/h to round-off, and the series to K = 2 within O(h^3) (la) or O(h^4) (la-trapezoid) of it
  const auto ao = read_tsv(dir / "oscillator_modified_agreement_all_orders.tsv");
  REQUIRE(ao.rows.size() == 2 * 2 * 4);
  for (const char* scheme : {"la", "la-trapezoid"})
    for (double alpha : {0.5, 1.0}) {
      auto keep = [&](std::size_t i) { return ao.text(i, "scheme") == scheme && ao.number(i, "alpha") == alpha; };
      const auto h = ao.numbers("h", keep), Av = ao.numbers("A_v", keep), Aq = ao.numbers("A_q", keep);
      const auto Avs = ao.numbers("A_v_series", keep), Aqs = ao.numbers("A_q_series", keep);
      const auto dev = ao.numbers("flow_deviation", keep);
      std::vector<double> gap;
      for (std::size_t k = 0; k < h.size(); ++k) {
        const auto roots = geomint::modified::all_orders_by_name(scheme, h[k], alpha);
        INFO(scheme << " alpha=" << alpha << " h=" << h[k]);
        CHECK(-Av[k] == Approx(roots.a).epsilon(1e-10));
        CHECK(-Aq[k] == Approx(roots.b).epsilon(1e-10));
        CHECK(dev[k] < 1e-12);
        gap.push_back(std::max(std::abs(Av[k] - Avs[k]), std::abs(Aq[k] - Aqs[k])));
      }
      const double slope = geomint::fit_order(h, gap, 1e-14).slope;
      INFO(scheme << " alpha=" << alpha << ": gap slope " << slope);
      CHECK(std::abs(slope - (std::string(scheme) == "la" ? 3 : 4)) < 0.3);
    }
  std::filesystem::remove_all(dir);
}

TEST_CASE("modified_agreement --all-orders: a forced system's affine steps get no flow deviation", "[programs][modified]") {
  const auto dir = fresh_dir("modified-agreement-forced");
  const auto r = run_program("modified_agreement", "--systems forced-oscillator --schemes la --orders 0 --T 1 --h-max 0.1 "
                                                   "--all-orders --out " + dir.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const auto ao = geomint::plots::read_tsv(dir / "forced-oscillator_modified_agreement_all_orders.tsv");
  REQUIRE(ao.rows.size() == 3);
  for (std::size_t i = 0; i < ao.rows.size(); ++i) {
    CHECK(std::isnan(ao.number(i, "flow_deviation")));
    CHECK(std::isfinite(ao.number(i, "A_q")));
  }
  std::filesystem::remove_all(dir);
}
