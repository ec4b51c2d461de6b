#pragma once
// Errors that geomint reports to a user: bad input and numerical failure.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>

namespace geomint {

// Input that makes no sense (h <= 0, unknown scheme, ...). Programs print what() on one line, exit 2.
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A run that left its numerical bounds: a non-finite state, a lost constraint, a singular solve.
// Carries where it happened so a sweep can record it as data.
struct NumericalFailure : std::runtime_error {
  long step;
  std::string quantity;
  std::string detail;  // the message without the step and quantity
  NumericalFailure(long step_, std::string quantity_, const std::string& what)
      : std::runtime_error("numerical failure at step " + std::to_string(step_) + " (" + quantity_ + "): " + what),
        step(step_), quantity(std::move(quantity_)), detail(what) {}
  // The same failure with where it happened (system, scheme, parameters) in front of the detail.
  NumericalFailure within(const std::string& context) const { return {step, quantity, context + ": " + detail}; }
  // A failure found in a program's output rather than at a step: "numerical failure in <where>: <what>".
  static NumericalFailure in_output(const std::string& where, const std::string& what) {
    return NumericalFailure(where, what);
  }

 private:
  NumericalFailure(const std::string& where, const std::string& what)
      : std::runtime_error("numerical failure in " + where + ": " + what), step(-1), quantity(where), detail(what) {}
};

// A value that does not exist: not applicable (the z error of a scheme that has no z, the order of the first step
// size), or the value of a run that failed and is named on stderr. It is a NaN of its own (its payload spells
// "MISS"), so that a table writer can tell it from a nan or inf computed from the inputs (an overflow, a 0/0),
// which it refuses (TsvWriter): a nan in a table is always this one. Arithmetic keeps a NaN operand's payload
// (IEEE 754; x86 and AArch64 do), so a value derived from a missing one is missing too.
inline constexpr double missing_value = __builtin_nan("0x4d495353");
inline bool is_missing(double v) {
  std::uint64_t a, b;
  const double m = missing_value;
  std::memcpy(&a, &v, sizeof a);
  std::memcpy(&b, &m, sizeof b);
  const std::uint64_t no_sign = ~(std::uint64_t{1} << 63);
  return (a & no_sign) == (b & no_sign);
}

// Numbers in messages as a user would type them (0.1, not 0.100000).
inline std::string show(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

inline void require(bool ok, const std::string& message) {
  if (!ok) throw InputError(message);
}

inline void require_positive(double v, const char* name) {
  require(std::isfinite(v) && v > 0, std::string(name) + " must be a positive finite number, got " + show(v));
}

inline void require_nonnegative(double v, const char* name) {
  require(std::isfinite(v) && v >= 0, std::string(name) + " must be a non-negative finite number, got " + show(v));
}

inline void require_finite(double v, const char* name) {
  require(std::isfinite(v), std::string(name) + " must be finite, got " + show(v));
}

// Number of steps N with N*h == T (to 1e-9 relative): every run lands exactly on T, t_j = t0 + j*h.
long step_count(double h, double T);

}  // namespace geomint
