#pragma once
// SystemDescription: a system given by its formulas, as text — read from a system file, or
// filled in memory by a program (the Python module). model.hpp compiles it.
//
// The system file format is documented, with examples, in docs/systems/README.md: sections [system] (name,
// description, coordinates, time_transform), [parameters] (name = default  # doc), [definitions], [dynamics] (L, herglotz, F1..Fn,
// E), [constraints] (phi1.. rows linear in the velocities, or g1.. holonomic rows), [initial] (q1..qn, v1..vn, t0, z0),
// [exact] (q1..qn, v1..vn: an exact solution);
// one `key = formula` per line, '#' comments.
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
  FormulaText initial_t, initial_z;  // t0 and z0 ([initial] t0 = ..., z0 = ...): 0 where not given
  // An exact solution ([exact]): q1..qn as formulas of t and the parameters, and optionally v1..vn (else the
  // derivatives of the q's). Checked against the equations at sample points when the system is validated.
  std::vector<FormulaText> exact_q, exact_v;
  // A time transformation dt = g dsigma (docs/time-transformation.md): the monitor g, a formula in t, q1..qn,
  // v1..vn and the parameters, or empty for none. Given, the model is the extended system in the fictitious time
  // sigma with n + 1 coordinates (q, t), built from the formulas above.
  FormulaText time_transform;
};

// The largest system file read (a formula file is a few kilobytes).
inline constexpr std::uintmax_t max_system_file_bytes = 1 << 20;

// Reads a system file; InputError "path:line: ..." for anything it cannot take.
SystemDescription read_system_file(const std::filesystem::path& path);
// The same from the file's text (`source` names it in messages).
SystemDescription parse_system_file(const std::string& text, const std::string& source);

}  // namespace geomint::formula
