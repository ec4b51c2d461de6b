#pragma once
// The options the programs that take a system file declare beside the system's parameters (Cli, SystemOptions,
// add_baseline_study_options and each such program's own). A formula system's parameters become options of their
// own (--alpha 0.2), so a parameter with one of these names would shadow the program's option or make it unusable;
// the system file reader refuses such a name at its line. T stays a parameter (the horizon every system has).
// A program that takes --system-file and declares a new option adds its name here.
#include <string_view>

namespace geomint::formula {

inline constexpr std::string_view program_option_names[] = {
    // every program (Cli)
    "help", "out", "no-budget",
    // the system options (SystemOptions) and the baseline studies (add_baseline_study_options)
    "system", "system-file", "time-transform", "systems", "equations", "path", "norm", "reps",
    // integrate, ensemble, convergence, regularized_error, work_precision, stability, long_horizon, modified_equation
    "h", "scheme", "schemes", "every", "perturb", "runs", "seed", "threads", "h-max", "h-min", "reference", "tol",
    "ref-factor", "shift", "trajectory", "adaptive-error", "baselines", "alpha-max", "alpha-min", "n", "horizons",
    "methods", "budget", "formulas", "order", "q", "v", "t", "z"};

inline bool is_program_option_name(std::string_view name) {
  for (std::string_view o : program_option_names)
    if (o == name) return true;
  return false;
}

}  // namespace geomint::formula
