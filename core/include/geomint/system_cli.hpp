#pragma once
// Command lines of the programs that take a system by name: --system picks it from the registry, and every
// parameter of that system becomes an option of its own (--alpha 0.2, --T 50, ...), listed by --help.
// Programs that sweep accept several values per parameter and run the Cartesian product.
#include <string>
#include <vector>

#include "geomint/cli.hpp"
#include "geomint/registry.hpp"

namespace geomint {

class SystemOptions {
 public:
  // Reads --system from argv (before the full parse, which needs the system's parameter list) and adds
  // --system plus one option per parameter to cli. `sweep`: several values per parameter allowed.
  SystemOptions(Cli& cli, int argc, char** argv, const std::string& default_system, bool sweep);

  const SystemInfo& system() const { return *system_; }
  // The system file it was read from (--system-file), or "" for a registry system.
  const std::string& system_file() const { return file_; }
  // After cli.parse: every combination of the given values (one ParamValues when nothing is swept), each
  // validated; the parameters given more than one value, in the system's order.
  std::vector<ParamValues> combinations() const;
  std::vector<std::string> swept() const;
  // The single combination (programs that do not sweep).
  ParamValues values() const;
  // Header lines: the system and every parameter (swept ones as lists).
  std::vector<std::pair<std::string, std::string>> header() const;
  // The schemes asked for (--schemes), or every scheme of the system when none.
  std::vector<std::string> schemes(const std::vector<std::string>& asked) const;
  // Before the runs of `schemes` at `values`: a system file whose Herglotz form is inconsistent with its force
  // says so on stderr ("warning: <file:line:col>: ..."), once, when a scheme of the contact family is among them
  // (formula::contact_warnings, the check behind the Python module's GeomintWarning).
  void warn_contact(const std::vector<ParamValues>& values, const std::vector<std::string>& schemes) const;

 private:
  const SystemInfo* system_ = nullptr;
  std::vector<std::vector<double>> given_;  // per parameter, in the system's order
  std::string file_;
  std::string time_transform_;  // --time-transform, "" when absent
  bool sweep_;
};

// Command lines of the programs that take several systems (--systems a b ...): every parameter of any of them is an
// option of its own, and a value given goes to each listed system that has a parameter of that name. Where none is
// given a system keeps its own default, unless the program has a preset for that parameter (a value its study
// needs, e.g. a damping large enough to show odd-order terms), which --help states.
class SystemsOptions {
 public:
  // Reads --systems from argv (before the full parse, which needs their parameter lists) and adds --systems plus
  // one option per parameter of the union to cli. `presets`: the program's values where none is given.
  SystemsOptions(Cli& cli, int argc, char** argv, std::vector<std::string> default_systems, ParamValues presets,
                 const std::string& systems_doc = "systems");

  // After cli.parse: the systems named (each found in the registry).
  const std::vector<std::string>& names() const { return names_; }
  // The values of `system`'s parameters that were given or preset (the rest are its defaults), validated.
  ParamValues values(const std::string& system) const;
  // The value the system runs with: given, preset, or its own default.
  double value(const std::string& system, const std::string& param) const;
  // For a program that sweeps: every combination of the values given for `system`'s parameters (several values
  // for one parameter sweep it), presets and defaults elsewhere, each validated; values() refuses a sweep.
  std::vector<ParamValues> combinations(const std::string& system) const;
  // The parameters given more than one value, in option order.
  std::vector<std::string> swept() const;
  // Header lines: the systems, and every parameter given or preset with its value.
  std::vector<std::pair<std::string, std::string>> header() const;

 private:
  std::vector<std::string> names_;
  std::vector<std::string> params_;          // the union, in first-seen order
  std::vector<std::vector<double>> given_;   // per parameter of the union
  ParamValues presets_;
};

// --system X (or --system=X) in argv, before any parse (`fallback` when absent): what a program that runs a
// different study per system dispatches on. --system-file PATH likewise ("" when absent).
std::string find_system_arg(int argc, char** argv, const std::string& fallback);
std::string find_system_file_arg(int argc, char** argv);
std::string find_time_transform_arg(int argc, char** argv);

// The options of a study that runs a system's schemes beside Odeint baselines (work_precision, long_horizon), under
// one name and text: --equations (ad | rhs), --path (fast | generic), --norm (max | 2), --reps; values as given.
void add_baseline_study_options(Cli& cli, std::string& equations, std::string& path, std::string& norm, int& reps);

// The value of a swept parameter in a combination.
double param_value(const ParamValues& pv, const SystemInfo& sys, const std::string& name);

}  // namespace geomint
