#pragma once
// SystemDescription: a system given by its formulas, as text — read from a system file (the format below), or
// filled in memory by a program (the Python module). model.hpp compiles it.
//
// The system file format (docs/systems/*.geomint are examples, one per header system):
//
//   # The damped pendulum.                    '#' starts a comment, anywhere on a line
//   [system]
//   name = pendulum                           a name for command lines: letters, digits, '-', '_'
//   description = damped nonlinear pendulum   optional, free text
//   coordinates = 1                           n: the coordinates q1..qn, the velocities v1..vn
//
//   [parameters]                              name = number   # its documentation (the comment)
//   alpha = 0.1    # Rayleigh damping         a default is a number or a formula of numbers and pi
//   T = 20         # horizon                  T, the horizon, is required
//
//   [definitions]                             optional shorthands, each usable below its own line:
//   w2 = g/l                                  of parameters (computed once per parameter set), or of t, q, v
//
//   [dynamics]
//   L = v1^2/2 - (1 - cos(q1))                the Lagrangian L(t, q, v) (required)
//   herglotz = L - alpha*z                    the Herglotz Lagrangian L(t, q, v, z) (optional; the contact schemes
//                                             need it); L, E and herglotz may use L
//   F1 = -alpha*v1                            the force F(t, q, v), one line per coordinate (optional)
//   E = v1^2/2 + 1 - cos(q1)                  the energy (optional; default q'.dL/dq' - L)
//
//   [constraints]                             optional, m rows (m <= 2 and m < n), either
//   phi1 = sin(q3)*v1 - cos(q3)*v2            Phi(t, q, v) = A(t, q) v + b(t, q) = 0, linear in the velocities,
//   g1 = q1^2 + q2^2 - 1                      or holonomic: g(t, q) = 0, imposed as g(t_{j+1}, q_{j+1}) = 0
//
//   [initial]                                 the initial data at t = 0: numbers, parameters, constant definitions
//   q1 = q0
//   v1 = p0
//
// Formulas: + - * / ^ (or **), unary -, parentheses, numbers, sin cos tan exp log sqrt, atan2(y, x) (in
// parameters, constant definitions and initial data), pi, the parameters and definitions by name, t, q1..qn,
// v1..vn and z (in herglotz only).
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace geomint::formula {

// Where a formula's text comes from, for error messages: a line of a file, or a field of an in-memory
// description.
struct Where {
  std::string source;  // the file path, or the field ("L", "parameter alpha")
  int line = 0;        // 0: not from a file
  int column = 1;      // the column of the formula's first character
  // "file:12:7" (the column of the formula's `column`-th character) or "L, column 7".
  std::string at(int column_in_formula = 1) const;
  // "file:12" or "L".
  std::string place() const;
};

struct FormulaText {
  std::string text;
  Where where;
  bool given() const { return !text.empty(); }
};

// A formula given in memory: its field name is its place in messages.
FormulaText formula_text(std::string text, std::string field);

struct ParameterText {
  std::string name;
  FormulaText value;
  std::string doc;
};

struct DefinitionText {
  std::string name;
  FormulaText value;
};

enum class ConstraintKind { velocity, holonomic };

struct SystemDescription {
  std::string name, description;
  int coordinates = 0;
  Where origin;  // the file (or "description"): messages about the system as a whole
  std::vector<ParameterText> parameters;
  std::vector<DefinitionText> definitions;
  FormulaText lagrangian, herglotz, energy;
  std::vector<FormulaText> force;  // none, or one per coordinate
  ConstraintKind constraint_kind = ConstraintKind::velocity;
  std::vector<FormulaText> constraints;  // Phi_i (velocity) or g_i (holonomic)
  std::vector<FormulaText> initial_q, initial_v;
};

// The largest system file read (a formula file is a few kilobytes).
inline constexpr std::uintmax_t max_system_file_bytes = 1 << 20;

// Reads a system file; InputError "path:line: ..." for anything it cannot take.
SystemDescription read_system_file(const std::filesystem::path& path);
// The same from the file's text (`source` names it in messages).
SystemDescription parse_system_file(const std::string& text, const std::string& source);

}  // namespace geomint::formula
