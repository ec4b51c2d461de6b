#pragma once
// Sweeps record a numerical failure as a missing value (nan) and go on (docs/extending.md): one helper for every sweep,
// so the message is the same everywhere: "<program>: <scheme and parameters>: numerical failure at step N
// (quantity): ... (recorded as a missing value)".
#include <stdexcept>
#include <string>
#include <utility>

#include <boost/numeric/odeint/util/odeint_error.hpp>

#include "geomint/error.hpp"
#include "geomint/text.hpp"

namespace geomint {

// The name guarded_main runs under ("geomint" outside it).
const std::string& program_name();
// Prints the one-line message above on stderr.
void report_missing(const std::string& context, const std::string& what);
// `line` and a newline on stderr in one write(2): under mpiexec the ranks' lines arrive whole, never interleaved.
void print_line(const std::string& line);

// Runs run(); a NumericalFailure, an Odeint failure (step size underflow, too many steps) or a domain error
// (a solver that left its domain) is reported with `context` (scheme, parameters) and on_failure() gives the
// missing value instead. Other exceptions (bad input, write errors) pass through.
template <class Run, class OnFailure>
auto run_or_missing(const std::string& context, Run&& run, OnFailure&& on_failure) -> decltype(run()) {
  try {
    return run();
  } catch (const NumericalFailure& e) {
    report_missing(context, e.what());
  } catch (const boost::numeric::odeint::odeint_error& e) {
    report_missing(context, std::string("Odeint: ") + e.what());
  } catch (const std::domain_error& e) {
    report_missing(context, e.what());
  }
  return on_failure();
}

}  // namespace geomint
