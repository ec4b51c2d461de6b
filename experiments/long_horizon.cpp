// Long-horizon work–precision of any system: what a method's structural error costs over horizons far beyond a
// convergence study's, every geometric scheme and composition against Boost.Odeint and GSL. A system that declares
// its long-horizon structure (exact laws a run is held to: long_horizon/studies.hpp) runs its own study; every other
// system, or one given by --system-file, runs the generic one (its max error in q against a reference, over horizons
// a multiple of its own T). `long_horizon --help --system X` lists what X's study takes.
//   long_horizon [--system oscillator] [the study's options]
// The paper's settings and the studies of docs/speed-accuracy.md are lines of the Makefile's FIGURE_COMMANDS.
// Writes out/<system>_long_horizon.tsv (errors: the same bits for the same command), _timings.tsv, _summary.tsv and
// the figure out/<system>_long_horizon.{png,pdf}; the Foucault study also _drift.tsv, Kepler's _summary_evals.tsv.
#include "geomint/error.hpp"
#include "geomint/registry.hpp"
#include "geomint/system_cli.hpp"
#include "long_horizon/studies.hpp"

using namespace geomint;

int main(int argc, char** argv) {
  return guarded_main("long_horizon", [&] {
    if (find_system_file_arg(argc, argv).empty()) {
      const std::string name = find_system_arg(argc, argv, "oscillator");
      for (const auto& s : long_horizon_studies()) {
        find_system(s.system);  // a row that names no system would never run: refused here, not silently left out
        if (name == s.system) return s.run(argc, argv);
      }
    }
    return long_horizon_generic(argc, argv);
  });
}
