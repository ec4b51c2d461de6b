// The long-horizon study of any system (studies/long_horizon_study.hpp).
#include "geomint/long_horizon_study.hpp"

#include "geomint/budget.hpp"
#include "geomint/error.hpp"
#include "geomint/io.hpp"
#include "geomint/step_cost.hpp"

namespace geomint {

namespace {

ParamValues at_horizon(ParamValues pv, double T) {
  for (auto& [k, v] : pv)
    if (k == "T") {
      v = T;
      return pv;
    }
  pv.emplace_back("T", T);
  return pv;
}

}  // namespace

void check_long_horizon(const SystemInfo& sys, const ParamValues& pv, const LongHorizonSpec& spec) {
  require(!spec.methods.empty() && !spec.horizons.empty(), "a long-horizon study needs methods and horizons");
  require(static_cast<bool>(spec.probe) && !spec.measures.empty(), "a long-horizon study needs a probe and its measures");
  require(spec.reps >= 1 && spec.reps <= 1000, "reps must be in [1, 1000]");
  bool fixed = false, adaptive = false;
  double cost = 0;  // of one step of every fixed-step method, in cheap steps
  for (const auto& name : spec.methods) {
    const Method m = find_method(sys, name);  // InputError naming every method
    (m.adaptive() ? adaptive : fixed) = true;
    cost += m.family == "geometric" ? step_cost(sys, name, spec.options.path) : 4;
  }
  require(!fixed || !spec.hs.empty(), "the fixed-step methods need steps (--h)");
  require(!adaptive || !spec.tols.empty(), "the adaptive methods need tolerances (--tol)");
  for (double tol : spec.tols) check_tolerance(tol, "tol");
  for (double T : spec.horizons) {
    sys.validate(at_horizon(pv, T));
    for (double h : spec.hs)
      plan_steps((spec.reps + 2) * static_cast<double>(step_count(h, T)), "the runs (methods x (reps + 2) x T/h)", cost);
  }
}

LongHorizonResult long_horizon_study(const SystemInfo& sys, const ParamValues& pv, const LongHorizonSpec& spec) {
  check_long_horizon(sys, pv, spec);
  std::vector<Method> methods;
  for (const auto& name : spec.methods) methods.push_back(find_method(sys, name));
  LongHorizonResult out;
  auto point = [&](const Method& m, const ParamValues& at, double T, double knob) {
    MethodWork w;
    WorkPoint p = measure_point_timed(
        work_point(m.name, m.family, m.knob(), knob, WorkPoint::nan, T), spec.measures.size(),
        [&] {
          const auto probe = spec.probe(at);
          w = run_method(sys, at, m, knob, spec.options,
                         [&](double t, const double* q, const double* v) { probe->sample(t, q, v); });
          return Measured{probe->errors(), w.steps};
        },
        [&] { return time_method(sys, at, m, knob, spec.options, spec.reps); }, spec.reps,
        sys.name + " " + m.name + ", T = " + show(T) + ", " + m.knob() + " = " + show(knob));
    out.evaluations.push_back(p.failure.empty() ? w.evaluations : WorkPoint::nan);
    out.points.push_back(std::move(p));
  };
  for (double T : spec.horizons) {
    const ParamValues at = at_horizon(pv, T);
    for (double h : spec.hs)
      for (const auto& m : methods)
        if (!m.adaptive()) point(m, at, T, h);
    for (double tol : spec.tols)
      for (const auto& m : methods)
        if (m.adaptive()) point(m, at, T, tol);
  }
  return out;
}

}  // namespace geomint
