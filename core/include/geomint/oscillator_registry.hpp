#pragma once
// Run-time access to the oscillator schemes by name (command lines, studies). A new scheme is one
// struct in oscillator_schemes.hpp plus one line in oscillator_registry.cpp.
#include <string>
#include <vector>

#include "geomint/oscillator.hpp"

namespace geomint {

struct OscillatorTrajectory {
  std::vector<double> t, q, p, z;
};

struct OscillatorSchemeInfo {
  std::string name;
  int order;  // expected order (0: does not converge)
  std::string description;
  OscillatorTrajectory (*run)(const OscillatorScene&, double h);
  // max_j |q_j - q(t_j)| against the closed-form solution, without storing the trajectory
  double (*max_error)(const OscillatorScene&, double h);
  // the one-step matrix on (q, p): all-orders modified coefficients and stability maps use it
  void (*one_step)(long double h, long double alpha, long double M[2][2]);
  // N = T/h steps with nothing observed (for timings); returns the final q so the work cannot be dropped
  double (*integrate)(const OscillatorScene&, double h);
};

const std::vector<OscillatorSchemeInfo>& oscillator_schemes();
// Throws InputError naming the known schemes when `name` is unknown.
const OscillatorSchemeInfo& find_oscillator_scheme(const std::string& name);

// The schemes a study shows by default, in the order of its tables: the one place these lists are written.
// Studies: fig1, convergence, work_precision, stability, bench.
const std::vector<std::string>& oscillator_defaults(const std::string& study);
std::string join_names(const std::vector<std::string>& names);  // "a b c", for --help

}  // namespace geomint
