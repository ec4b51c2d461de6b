// The studies layer's long-horizon study (studies/include/geomint/long_horizon_study.hpp): a probe and a list of
// method names. Its points carry what the probe measured on the whole run of each method, at each horizon and knob;
// the knife edge's study (long_horizon --system knife-edge) is held to its second-order schemes' order in its heading
// law.
#include <catch2/catch.hpp>

#include <cmath>
#include <memory>

#include "geomint/long_horizon_study.hpp"
#include "geomint/plots/figure.hpp"
#include "geomint/registry.hpp"
#include "helpers.hpp"

using namespace geomint;
using namespace geomint::testing;

namespace {

// max_t |q - q_exact(t)| on the oscillator (its closed form), sampled where the run is watched.
class ExactProbe : public StructureProbe {
 public:
  explicit ExactProbe(const ParamValues& pv) : pv_(pv) {}
  void sample(double t, const double* q, const double*) override {
    ts_.push_back(t);
    qs_.push_back(q[0]);
  }
  std::vector<double> errors() const override {
    const auto exact = find_system("oscillator").exact_positions(pv_, ts_);
    double e = 0;
    for (std::size_t i = 0; i < ts_.size(); ++i) e = std::max(e, std::abs(qs_[i] - exact[i]));
    return {e, static_cast<double>(ts_.size())};
  }

 private:
  ParamValues pv_;
  std::vector<double> ts_, qs_;
};

}  // namespace

TEST_CASE("long_horizon_study: every method's whole run reaches its probe, at every horizon and knob",
          "[studies][long_horizon]") {
  const SystemInfo& sys = find_system("oscillator");
  LongHorizonSpec spec;
  spec.methods = {"la-midpoint", "odeint-rk4", "odeint-dopri5"};
  spec.horizons = {10, 20};
  spec.hs = {0.1, 0.05};
  spec.tols = {1e-8};
  spec.reps = 1;
  spec.measures = {{"err", "max error in q", 1e-6}, {"samples", "states watched", 1}};
  spec.probe = [](const ParamValues& pv) { return std::make_unique<ExactProbe>(pv); };
  const auto r = long_horizon_study(sys, {{"alpha", 0.1}}, spec);
  // per horizon: (h = 0.1: la-midpoint, rk4), (h = 0.05: la-midpoint, rk4), then dopri5 at its tolerance
  REQUIRE(r.points.size() == 10);
  REQUIRE(r.evaluations.size() == 10);
  const auto& mid = r.points[0];
  CHECK(mid.method == "la-midpoint");
  CHECK(mid.horizon == 10);
  CHECK(mid.errors[1] == 101);  // t = 0 and every step
  CHECK(r.points[2].errors[1] == 201);
  // second order in h, fourth for rk4
  CHECK(std::log2(r.points[0].errors[0] / r.points[2].errors[0]) == Approx(2).margin(0.1));
  CHECK(std::log2(r.points[1].errors[0] / r.points[3].errors[0]) == Approx(4).margin(0.15));
  CHECK(r.evaluations[1] == 4 * 100);  // rk4: four evaluations a step
  CHECK(r.points[4].method == "odeint-dopri5");
  CHECK(r.points[4].errors[0] < 1e-6);
  CHECK(r.points[9].horizon == 20);
  spec.methods.push_back("nosuch");
  CHECK_THROWS_AS(long_horizon_study(sys, {{"alpha", 0.1}}, spec), InputError);
}

TEST_CASE("long_horizon --system knife-edge: the heading law's error falls at the schemes' second order",
          "[programs][long_horizon][studies]") {
  const auto dir = fresh_dir("lh-knife-edge");
  const auto r = run_program("long_horizon", "--system knife-edge --horizons 40 --h 0.05 0.025 --tol 1e-8 --reps 1 "
                                             "--methods la-midpoint contact-trapezoid odeint-dopri5 --out " + dir.string());
  REQUIRE(r.exit_code == 0);
  const auto t = plots::read_tsv(dir / "knife-edge_long_horizon.tsv");
  auto err = [&](const std::string& m, double h) {
    for (std::size_t i = 0; i < t.rows.size(); ++i)
      if (t.text(i, "method") == m && t.number(i, "value") == h) return t.number(i, "heading_err");
    FAIL("no row for " << m << " at " << h);
    return 0.0;
  };
  // measured: 0.0517 -> 0.0130 and 0.0261 -> 0.0065 (la's own first-order term is proportional to alpha = 1e-3,
  // so over T = 40 its heading error is pre-asymptotic here, local order 1.5)
  CHECK(std::log2(err("la-midpoint", 0.05) / err("la-midpoint", 0.025)) == Approx(2).margin(0.1));
  CHECK(std::log2(err("contact-trapezoid", 0.05) / err("contact-trapezoid", 0.025)) == Approx(2).margin(0.1));
  CHECK(err("odeint-dopri5", 1e-8) < 1e-6);
}
