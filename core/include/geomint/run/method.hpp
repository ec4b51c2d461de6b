#pragma once
// One door for every method of a registry system. A method is a scheme or a composition of the system (the
// generic Newton step, or on the fast path the closed form that solves the same residual), swept over h, or a
// baseline (run/baselines.hpp: odeint-rk4 over h; dopri5, Bulirsch–Stoer, rk8pd over a tolerance) on the system's
// equations. Each is run by run_method with one observer of (t, q, v) and its work counted, and timed by
// time_method: a study names its methods and feeds its observer, and drives none of them itself.
#include <functional>
#include <string>
#include <vector>

#include "geomint/error.hpp"
#include "geomint/registry.hpp"
#include "geomint/timing.hpp"

namespace geomint {

struct Method {
  std::string name;
  std::string family;  // "geometric" (a scheme or composition), "rk" (odeint-rk4), "adaptive" (the others)
  bool adaptive() const { return family == "adaptive"; }
  const char* knob() const { return adaptive() ? "tol" : "h"; }
};
// A scheme, composition (or an alias) of sys, or a baseline; InputError naming them all otherwise.
Method find_method(const SystemInfo& sys, const std::string& name);

struct MethodOptions {
  Path path = Path::fast;  // the schemes: their closed forms where the system has them
  // The baselines integrate x = (q, q') with the system's hand-written acceleration where it has one (what a
  // hand-coded baseline costs), else the one derived from L, F and Phi by AD.
  bool hand_written = true;
  long every = 1;          // the fixed-step methods are watched at every every-th step (and at the last)
  double abs_factor = 1;   // the adaptive ones' error control: abs = abs_factor tol, rel = tol
};

// What a run cost: its steps, and its evaluations of the equations where counted: of the right-hand side (the
// baselines), of the residual (the generic step: Newton's updates and one where it accepts, per base step); NaN for
// a closed form, which evaluates neither.
struct MethodWork {
  long steps = 0;
  double evaluations = missing_value;
};

// observe(t, q, v): t = 0 first, then the steps watched; q and v rows of sys.dof (v the velocity: a scheme's from
// its discrete momentum by the continuous Legendre map, a baseline's state). Runs to the system's horizon T.
using StateObserver = std::function<void(double t, const double* q, const double* v)>;
MethodWork run_method(const SystemInfo& sys, const ParamValues& pv, const Method& m, double knob, const MethodOptions& opt,
                      const StateObserver& observe);
// CPU seconds of one run with nothing watched (warm-up, then the median of reps).
TimingStats time_method(const SystemInfo& sys, const ParamValues& pv, const Method& m, double knob,
                        const MethodOptions& opt, int reps);

}  // namespace geomint
