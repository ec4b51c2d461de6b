// The time transformation dt = g dsigma of a formula system (docs/time-transformation.md): the extended system
// in sigma, run by the core's own schemes through the registry, converges at each scheme's order in the physical
// time t (the error at a fixed t against Odeint on the physical system), its penalty multiplier w = kappa (t' - g)
// vanishes at the scheme's order, the automatic modified equation in sigma of a symmetric scheme has no odd terms,
// and bad monitors are refused naming their place.
#include <catch2/catch.hpp>

#include <cmath>
#include <sstream>

#include "geomint/error.hpp"
#include "geomint/formula/description.hpp"
#include "geomint/formula/formula_registry.hpp"
#include "geomint/formula/model.hpp"
#include "geomint/formula/time_transform.hpp"
#include "geomint/modified/automatic_registry.hpp"
#include "geomint/modified/formula_modified.hpp"
#include "helpers.hpp"

using namespace geomint;

namespace {

std::string system_file(const std::string& name) { return std::string(GEOMINT_SOURCE_DIR) + "/docs/systems/" + name + ".geomint"; }

std::shared_ptr<const formula::FormulaModel> transformed(const std::string& name, const std::string& g) {
  formula::SystemDescription d = formula::read_system_file(system_file(name));
  d.time_transform = formula::formula_text(g, "--time-transform");
  return formula::compile_model(d);
}

// Least-squares slope of log(err) against log(h).
double slope(const std::vector<double>& h, const std::vector<double>& e) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double k = static_cast<double>(h.size());
  for (std::size_t i = 0; i < h.size(); ++i) {
    const double x = std::log(h[i]), y = std::log(e[i]);
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
  }
  return (k * sxy - sx * sy) / (k * sxx - sx * sx);
}

struct Orders {
  double error_order = 0, residual_order = 0;
  std::vector<double> errors, residuals;
};

// The error in q at t_end (max norm over the physical coordinates) against Odeint (tolerance 1e-13) on the
// physical system, and the largest |w| over the run, for h = h0 / 2^k, k = 0..4; slopes fitted on the last three.
Orders orders_in_t(const std::shared_ptr<const formula::FormulaModel>& model, const ParamValues& pv, const std::string& scheme,
                   double h0, double t_end) {
  const auto info = formula::formula_system_info(model);
  const auto physical = formula::formula_system_info(model->physical);
  const Reference ref = physical->reference(pv, t_end, 1, ReferenceKind::odeint, 1e-13);
  const int n = model->physical_n;
  Orders out;
  std::vector<double> hs;
  for (int k = 0; k < 5; ++k) {
    const double h = h0 / std::pow(2.0, k);
    const formula::PhysicalRun r = formula::run_to_physical_time(*info, *model, pv, scheme, h, t_end, Path::generic);
    double err = 0;
    for (int i = 0; i < n; ++i) err = std::max(err, std::abs(r.end.q[static_cast<std::size_t>(i)] - ref.q[static_cast<std::size_t>(n + i)]));
    hs.push_back(h);
    out.errors.push_back(err);
    out.residuals.push_back(r.residual);
  }
  const std::vector<double> h3(hs.begin() + 2, hs.end()), e3(out.errors.begin() + 2, out.errors.end()),
      w3(out.residuals.begin() + 2, out.residuals.end());
  out.error_order = slope(h3, e3);
  out.residual_order = slope(h3, w3);
  return out;
}

std::string show_all(const std::vector<double>& x) {
  std::ostringstream s;
  for (double y : x) s << y << " ";
  return s.str();
}

void check_orders(const std::string& name, const std::string& g, const ParamValues& pv, const std::string& scheme, int p,
                  double h0, double t_end) {
  const Orders o = orders_in_t(transformed(name, g), pv, scheme, h0, t_end);
  INFO(name << " with g = " << g << ", " << scheme << ": errors " << show_all(o.errors) << "; |w| " << show_all(o.residuals)
            << "; fitted orders " << o.error_order << " (error in t), " << o.residual_order << " (w)");
  CHECK(std::abs(o.error_order - p) < 0.2);
  CHECK(o.residual_order > p - 0.2);
  CHECK(o.errors.back() < 1e-2);
}

}  // namespace

TEST_CASE("time-transformed LA schemes converge at their order in t on the pendulum and the Duffing and knife-edge systems", "[time_transform]") {
  check_orders("pendulum", "1/sqrt(1 + v1*v1)", {{"p0", 0.5}}, "la", 1, 0.05, 4);
  check_orders("pendulum", "1/sqrt(1 + v1*v1)", {{"p0", 0.5}}, "la-midpoint", 2, 0.1, 4);
  check_orders("duffing", "1/(1 + q1*q1)", {}, "la", 1, 0.05, 4);
  check_orders("duffing", "1/(1 + q1*q1)", {}, "la-midpoint", 2, 0.1, 4);
  check_orders("knife-edge", "1/(1 + v1*v1 + v2*v2 + q1*q1)", {}, "la", 1, 0.05, 4);
  check_orders("knife-edge", "1/(1 + v1*v1 + v2*v2 + q1*q1)", {}, "la-midpoint", 2, 0.1, 4);
}

TEST_CASE("time-transformed contact schemes converge at their order in t (extended Herglotz form)", "[time_transform]") {
  check_orders("pendulum", "1/sqrt(1 + v1*v1)", {{"p0", 0.5}, {"alpha", 0.3}}, "contact", 1, 0.05, 4);
  check_orders("duffing", "1/(1 + q1*q1)", {}, "contact-trapezoid", 2, 0.1, 4);
}

TEST_CASE("the modified equation in sigma of a symmetric time-transformed scheme has F1 = F3 = 0", "[time_transform][modified]") {
  const auto model = transformed("pendulum", "1/sqrt(1 + v1*v1)");
  const auto ms = modified::formula_modified_system(model);
  REQUIRE(ms->dof == 2);
  // A point off the initial data and off w = 0: symmetry holds for the whole extended system.
  const std::vector<double> q{0.7, 1.3}, v{0.4, 0.8};
  const ParamValues pv{{"alpha", 0.2}};
  auto largest = [&](const modified::ModifiedPoint& p, int k) {
    double s = 0;
    for (int i = 0; i < p.n; ++i) s = std::max(s, std::abs(p.F_at(k, i)));
    return s;
  };
  const modified::ModifiedPoint mid = ms->at(pv, "la-midpoint", 4, 0.0, q, v, 0.0, true);
  const double F0 = largest(mid, 0);
  INFO("la-midpoint: |F0| " << F0 << ", |F1| " << largest(mid, 1) << ", |F2| " << largest(mid, 2) << ", |F3| " << largest(mid, 3)
                            << ", |F4| " << largest(mid, 4) << ", self-check " << mid.residual);
  CHECK(F0 > 0.1);
  CHECK(largest(mid, 1) <= 1e-12 * F0);
  CHECK(largest(mid, 3) <= 1e-12 * F0);
  CHECK(largest(mid, 2) > 1e-3 * F0);  // the even terms are there: the check is not vacuous
  CHECK(mid.residual <= 1e-10 * F0);
  // The first-order scheme has its h term.
  const modified::ModifiedPoint la = ms->at(pv, "la", 2, 0.0, q, v, 0.0, true);
  CHECK(largest(la, 1) > 1e-3 * F0);
}

TEST_CASE("the extended system starts on w = 0 with t' = g0 and keeps the physical energy", "[time_transform]") {
  const auto model = transformed("pendulum", "2/(1 + q1*q1)");
  REQUIRE(model->time_transformed);
  REQUIRE(model->n == 2);
  const auto info = formula::formula_system_info(model);
  const formula::PhysicalRun pr = formula::run_to_physical_time(*info, *model, {{"p0", 0.5}}, "la-midpoint", 0.05, 0.5, Path::generic);
  const Run& r = pr.run;
  // Q(0) = (q0, 0), Q'(0) = (v0 g0, g0) with q0 = 1: g0 = 2/(1 + 1) = 1
  CHECK(r.q[0] == 1.0);
  CHECK(r.q[1] == 0.0);
  CHECK(r.v[1] == Approx(1.0).epsilon(1e-12));
  CHECK(r.v[0] == Approx(0.5).epsilon(1e-12));
  // the energy column is the pendulum's, v^2/2 + 1 - cos q
  CHECK(r.energy[0] == Approx(0.125 + 1 - std::cos(1.0)).epsilon(1e-14));
  CHECK(formula::time_transform_residual(*model, {}, 0, {1.0, 0.0}, {0.5, 1.0}) == Approx(0.0).margin(1e-15));
  CHECK(pr.residual < 1e-3);
  CHECK(pr.end.sigma > 0.5);  // g <= 2/(1 + q^2) < 1 after the start: more sigma than t
  CHECK(formula::time_transform_residual(*model, {{"tt_kappa", 3}}, 0, {1.0, 0.0}, {0.5, 1.5}) == Approx(1.5).epsilon(1e-14));
}

TEST_CASE("bad monitors are refused naming their place", "[time_transform][errors]") {
  auto message = [](const std::string& name, const std::string& g, const ParamValues& pv = {}) -> std::string {
    try {
      const auto model = transformed(name, g);
      formula::formula_system_info(model)->validate(pv);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  // g = v1 is 0 at the pendulum's initial data (p0 = 0)
  CHECK_THAT(message("pendulum", "v1"), Catch::Contains("--time-transform: time_transform: the monitor g = dt/dsigma is 0 at the initial data"));
  CHECK_THAT(message("pendulum", "-1"), Catch::Contains("must be positive"));
  CHECK_THAT(message("pendulum", "1 + w1"), Catch::Contains("--time-transform, column 5: unknown symbol 'w1'"));
  CHECK_THAT(message("pendulum", "1 + q2"), Catch::Contains("'q2': the system has 1 coordinate"));
  CHECK_THAT(message("pendulum", "1 + z"), Catch::Contains("depends on z"));
  CHECK_THAT(message("pendulum", "1", {{"tt_kappa", 0}}), Catch::Contains("tt_kappa must be positive"));
  // the transformed rolling disk has 5 coordinates (t the fifth): a shape the build does not compile, and with its
  // compilation at first use off (formula/jit.hpp), the line that adds it
  const testing::ScopedEnv off("GEOMINT_SHAPE_JIT", "0");
  CHECK_THAT(message("rolling-disk", "1"), Catch::Contains("has n = 5, m = 2 (n counts the time t of its time transformation)") &&
                                               Catch::Contains("GEOMINT_FORMULA_SHAPE(5, 2, 0, 1) in core/src/formula/shapes.def"));
}

TEST_CASE("the programs refuse a time transformation they cannot build and compare at t = T", "[time_transform][errors]") {
  const std::string file = std::string(GEOMINT_SOURCE_DIR) + "/docs/systems/pendulum.geomint";
  testing::check_rejected("integrate", "--system pendulum --time-transform 1", "--time-transform needs a system given by its formulas");
  testing::check_rejected("integrate", "--system-file " + file + " --time-transform=", "--time-transform is given an empty formula");
  testing::check_rejected("integrate", "--system-file " + file + " --time-transform v1",
                          "the monitor g = dt/dsigma is 0 at the initial data");
  // convergence with a monitor: the error at the physical time T, and the table says so
  const auto dir = testing::fresh_dir("tt-convergence");
  const auto r = testing::run_program("convergence", "--system-file " + file + " --time-transform '1/(1 + q1*q1)' --T 2 --schemes la-midpoint "
                                      "--h-max 0.05 --h-min 0.02 --out " + dir.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const std::string tsv = testing::read_bytes(dir / "pendulum_time_transform.tsv");
  CHECK(tsv.find("# time_transform: dt = g dsigma, g = 1/(1 + q1*q1)") != std::string::npos);
  CHECK(tsv.find("# error: max_i |q_i(t = T) - q_ref,i(T)|: the state at the physical time T by cubic Hermite") != std::string::npos);
  std::filesystem::remove_all(dir);
}
