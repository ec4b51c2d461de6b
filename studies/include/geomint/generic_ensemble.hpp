#pragma once
// Ensembles of any registered system: many runs of one scheme from perturbed parameters (initial data or
// physical constants), on every core and, under mpirun, on every rank (sweep.hpp). A run of the ensemble is
// SystemInfo::run on its own parameters, nothing else: run k has the bits that `integrate` gives those
// parameters alone, whatever the thread count, the rank count or the runs beside it.
//
// Run k's parameters: the base values with every perturbed parameter p moved to p + spread_p u_{k,p}, u uniform
// in [-1, 1) from a counter-based generator (SplitMix64 of seed, k and p's place): a pure function of
// (seed, k), so a run can be recomputed alone and the shares of threads and ranks need no shared state.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "geomint/registry.hpp"

namespace geomint {

struct Perturbation {
  std::string name;  // a parameter of the system (not its horizon T: every run has the same step count)
  double spread;     // half-width of the uniform perturbation, >= 0
};

struct EnsembleSpec {
  ParamValues base;  // the system's values (defaults overridden by the command line)
  std::vector<Perturbation> perturb;
  std::string scheme;
  double h = 0.1;
  Path path = Path::fast;
  long runs = 1;
  std::uint64_t seed = 1;
};

// One run's outcome at t = T. A run that fails records where (the NumericalFailure message) and its state stays
// empty: an ensemble survives its failures and reports how many there were.
struct EnsembleRun {
  long k = 0;
  std::vector<double> values;  // the perturbed parameters' values, in the order of EnsembleSpec::perturb
  std::string failure;         // "" for a run that reached T
  std::vector<double> q, v;    // final positions and velocities (n each)
  double z = 0;                // final Herglotz action (contact schemes; 0 otherwise)
  double energy0 = 0, energy = 0, max_phi_d = 0, newton_mean = -1;
  bool ok() const { return failure.empty(); }
};

// "name=spread" -> Perturbation (InputError naming what is wrong).
Perturbation parse_perturbation(const std::string& text);
// Refuses unknown or repeated names, T, and spreads that are not finite and >= 0; then every run's parameters
// (runs, h and the scheme too) before any work, naming the first run whose parameters the system refuses.
void validate_ensemble(const SystemInfo& sys, const EnsembleSpec& spec);
// u_{k,i} in [-1, 1): the i-th perturbation of run k.
double ensemble_sample(std::uint64_t seed, long k, std::size_t i);
// Run k's parameters (a perturbed parameter the base does not name starts from the system's default).
ParamValues ensemble_params(const SystemInfo& sys, const EnsembleSpec& spec, long k);
// Runs [first, last) on `threads` threads; report(done, total) after each finished run if given.
std::vector<EnsembleRun> run_ensemble(const SystemInfo& sys, const EnsembleSpec& spec, long first, long last,
                                      unsigned threads,
                                      const std::function<void(std::size_t, std::size_t)>& report = nullptr);
// Bytes of one run for the MPI gather (sweep.hpp), and back.
std::string pack(const EnsembleRun& r);
EnsembleRun unpack_ensemble_run(const std::string& row);
// The memory one run's result holds (for check_memory before an ensemble starts).
double ensemble_run_bytes(int dof, std::size_t perturbed);
// The ensemble program's plan, before any run's own parameters are validated (validating 1e7 of them takes
// seconds, refusing an over-budget plan none): runs in [1, 1e7], runs x T/h steps at the scheme's step cost
// against the time budget, and the runs' results against the memory available (budget.hpp). `lower` names what
// to lower in the message (a program's "--runs", a module's "runs").
void plan_ensemble(const SystemInfo& sys, const EnsembleSpec& spec, const std::string& lower = "--runs");

}  // namespace geomint
