#pragma once
// The long-horizon studies of `long_horizon`, one per system that declares its long-horizon structure (exact laws
// a run can be held to without a reference: a decay rate, a precession, an angular-momentum law, a steady state),
// and the study of every other system (its error against a reference over horizons a multiple of its own).
// Each takes the whole command line (the program dispatches on --system before parsing it: each study has its own
// options) and returns the exit code; errors are thrown (InputError, NumericalFailure) to the program's guard.
#include <string>
#include <vector>

#include "geomint/cli.hpp"

// At global scope: each unit keeps its helpers in an anonymous namespace, which geomint's names would hide.
int long_horizon_oscillator(int argc, char** argv);  // decay rate, frequency, phase, energy balance
int long_horizon_forced(int argc, char** argv);      // steady-state amplitude and phase
int long_horizon_foucault(int argc, char** argv);    // precession, decay, constraint drift, both constraints
int long_horizon_kepler(int argc, char** argv);      // phase, angular-momentum law, energy, Laplace–Runge–Lenz
int long_horizon_knife_edge(int argc, char** argv);  // heading law, constraint drift (a study of the studies layer)
int long_horizon_generic(int argc, char** argv);     // any system: max error in q over the horizons

namespace geomint {

struct LongHorizonStudy {
  const char* system;
  int (*run)(int, char**);
  const char* measures;
};

// The systems with a structure study of their own; every other system (and --system-file) runs the generic one.
inline const std::vector<LongHorizonStudy>& long_horizon_studies() {
  static const std::vector<LongHorizonStudy> studies{
      {"oscillator", long_horizon_oscillator, "decay rate, frequency, phase, energy balance"},
      {"forced-oscillator", long_horizon_forced, "steady-state amplitude and phase"},
      {"foucault", long_horizon_foucault, "precession and decay rates, constraint drift (both constraints)"},
      {"kepler", long_horizon_kepler, "phase, angular-momentum law, energy, Laplace-Runge-Lenz vector"},
      {"knife-edge", long_horizon_knife_edge, "heading law, constraint drift"}};
  return studies;
}

// --system as an option of a structure study (its value is the study's system; the program has dispatched on it).
// Its text names the systems with a study (docs/programs.md, made by python/reference.py, shows each one's --help).
inline void add_study_system_option(Cli& cli, const std::string& system) {
  std::string own;
  for (const auto& s : long_horizon_studies()) own += std::string(own.empty() ? "" : ", ") + s.system;
  cli.options.add_options()("system", po::value<std::string>()->default_value(system),
                            ("the system; studies of their own: " + own +
                             "; any other system (e.g. pendulum) runs the generic study")
                                .c_str());
}

}  // namespace geomint
