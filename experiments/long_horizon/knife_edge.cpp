// Long-horizon structure of the damped knife edge (the `knife-edge` system): two laws a run is held to without a
// reference, against CPU time, for every method through the one door.
//   heading_err     max_t |theta - theta_exact(t)|: the heading is a damped linear oscillator decoupled from the rest,
//                   theta'' = -(kappa/I) theta - alpha theta' (the blade's constraint force has no torque), in closed form
//   constraint_err  max_t |sin(theta) x' - cos(theta) y'|: the continuous constraint at the method's velocity (a
//                   scheme's from its discrete momentum; it imposes the discrete constraint instead)
// The damping is alpha = 1e-3 unless --alpha is given (the system's 0.1 leaves nothing to measure by T = 2000).
//   long_horizon --system knife-edge [--horizons 200 2000] [--h 0.1 0.05 0.025] [--tol 1e-6 1e-8 1e-10]
//                [--methods la la-midpoint contact-trapezoid odeint-rk4 odeint-dopri5 ...] [--reps 3] [system parameters]
// Writes out/knife-edge_long_horizon.tsv (errors and evaluations: the same bits for the same command), _timings.tsv,
// _summary.tsv and the figure out/knife-edge_long_horizon.{png,pdf}.
#include <algorithm>
#include <cmath>
#include <memory>

#include "geomint/cli.hpp"
#include "geomint/system_cli.hpp"
#include "long_horizon/studies.hpp"
#include "long_horizon/table.hpp"

using namespace geomint;

namespace {

class HeadingProbe : public StructureProbe {
 public:
  explicit HeadingProbe(const SystemInfo& sys, const ParamValues& pv) {
    auto p = [&](const char* n) { return param_value(pv, sys, n); };
    alpha_ = p("alpha");
    theta0_ = p("theta0");
    w_ = std::sqrt(p("kappa") / p("I") - alpha_ * alpha_ / 4);
    b_ = (p("omega0") + alpha_ * theta0_ / 2) / w_;
  }
  void sample(double t, const double* q, const double* v) override {
    const double exact = std::exp(-alpha_ * t / 2) * (theta0_ * std::cos(w_ * t) + b_ * std::sin(w_ * t));
    heading_ = std::max(heading_, std::abs(q[2] - exact));
    constraint_ = std::max(constraint_, std::abs(std::sin(q[2]) * v[0] - std::cos(q[2]) * v[1]));
    if (!std::isfinite(q[0] + q[1] + q[2] + v[0] + v[1]))
      throw NumericalFailure(0, "state", "non-finite state at t = " + show(t));
  }
  std::vector<double> errors() const override { return {heading_, constraint_}; }

 private:
  double alpha_, theta0_, w_, b_, heading_ = 0, constraint_ = 0;
};

}  // namespace

int long_horizon_knife_edge(int argc, char** argv) {
  Cli cli("long_horizon", "long-horizon structural error against CPU time: the damped knife edge (alpha 1e-3 unless given)");
  SystemOptions sysopt(cli, argc, argv, "knife-edge", false);
  LongHorizonSpec spec;
  spec.horizons = {200, 2000};
  spec.hs = {0.1, 0.05, 0.025};
  spec.tols = {1e-6, 1e-8, 1e-10};
  spec.methods = {"la", "la-midpoint", "contact-trapezoid", "yoshida4:la-midpoint", "odeint-rk4",
                  "odeint-dopri5", "odeint-bulirsch-stoer", "gsl-rk8pd"};
  cli.options.add_options()("horizons", po::value(&spec.horizons)->multitoken()->default_value(spec.horizons, "200 2000"),
                            "horizons T (each a multiple of every h)")(
      "h", po::value(&spec.hs)->multitoken()->default_value(spec.hs, "0.1 0.05 0.025"), "steps of the fixed-step methods")(
      "tol", po::value(&spec.tols)->multitoken()->default_value(spec.tols, "1e-6 1e-8 1e-10"),
      "tolerances of the adaptive methods (abs = rel)")(
      "methods", po::value(&spec.methods)->multitoken(), "schemes, compositions <family>:<base> and baselines")(
      "reps", po::value(&spec.reps)->default_value(3), "timed repetitions");
  if (!cli.parse(argc, argv)) return 0;
  const SystemInfo& sys = sysopt.system();
  ParamValues pv = sysopt.values();
  // a preset: the system's alpha = 0.1 damps the heading by e^-100 over T = 2000, leaving nothing to measure
  if (std::none_of(pv.begin(), pv.end(), [](const auto& kv) { return kv.first == "alpha"; })) pv.emplace_back("alpha", 1e-3);
  require(param_value(pv, sys, "kappa") / param_value(pv, sys, "I") > std::pow(param_value(pv, sys, "alpha"), 2) / 4,
          "the heading must be under-damped (kappa/I > alpha^2/4): its law is measured by its phase");
  spec.measures = {{"heading_err", "heading error against its closed form (rad)", 1e-6},
                   {"constraint_err", "constraint drift |sin(th) vx - cos(th) vy| (m/s)", 1e-8}};
  spec.probe = [&](const ParamValues& at) { return std::make_unique<HeadingProbe>(sys, at); };
  check_long_horizon(sys, pv, spec);
  const auto dir = prepare_output_dir(cli.out);
  const LongHorizonResult result = long_horizon_study(sys, pv, spec);
  Params params = sysopt.header();
  params.insert(params.end(), {{"horizons", format_list(spec.horizons)}, {"h", format_list(spec.hs)},
                               {"tol", format_list(spec.tols) + " (abs = rel)"}, {"methods", join_names(spec.methods)},
                               {"reps", std::to_string(spec.reps)}, {"equations", "the baselines: the hand-written rhs"},
                               {"evals", "of the residual (schemes: Newton updates + one per base step) or the rhs (baselines)"}});
  long_horizon::write_study(dir, "knife-edge_long_horizon", params, result, spec.measures, "alpha",
                            param_value(pv, sys, "alpha"), "Knife edge: structural error against CPU time (median)");
  return 0;
}
