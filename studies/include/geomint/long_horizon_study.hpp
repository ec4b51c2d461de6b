#pragma once
// The long-horizon study of any system: every method (run/method.hpp: schemes, compositions, closed forms,
// baselines) at every horizon and every value of its knob, each run watched from start to end by a fresh probe of
// the study's structural measures, with its CPU time and its evaluations of the equations. The points are
// WorkPoints (work_precision.hpp), summarised and drawn as every long-horizon study's are. A study for a new system
// is its probe (an observer of (t, q, v) that returns the measures) and a list of method names.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "geomint/registry.hpp"
#include "geomint/run/method.hpp"
#include "geomint/work_precision.hpp"

namespace geomint {

// The observer of one run: fed every state watched, then asked for the run's errors (one per measure).
class StructureProbe {
 public:
  virtual ~StructureProbe() = default;
  virtual void sample(double t, const double* q, const double* v) = 0;
  virtual std::vector<double> errors() const = 0;
};

struct LongHorizonSpec {
  std::vector<std::string> methods;   // by name (find_method)
  std::vector<double> horizons;       // T (the system's parameter T, one study per value)
  std::vector<double> hs;             // the fixed-step methods' steps (each divides every T)
  std::vector<double> tols;           // the adaptive methods' tolerances
  std::vector<WorkMeasure> measures;  // the probe's errors, in its order, with the summary's targets
  MethodOptions options;
  int reps = 3;
  // A fresh probe for a run at the parameters pv (T included).
  std::function<std::unique_ptr<StructureProbe>(const ParamValues& pv)> probe;
};

struct LongHorizonResult {
  std::vector<WorkPoint> points;    // per horizon: every fixed-step method over h, then every adaptive one over tol
  std::vector<double> evaluations;  // per point: MethodWork::evaluations (NaN where not counted or missing)
};

// Refuses what the study cannot run (unknown methods, an h that does not divide a horizon, bad parameters) and plans
// its work, before anything is written.
void check_long_horizon(const SystemInfo& sys, const ParamValues& pv, const LongHorizonSpec& spec);
// Every point; a run that fails is a missing point named on stderr.
LongHorizonResult long_horizon_study(const SystemInfo& sys, const ParamValues& pv, const LongHorizonSpec& spec);

}  // namespace geomint
