#pragma once
// FormulaModel: a SystemDescription compiled once — every formula parsed into one expression graph, the
// derivatives the core needs taken symbolically (a constraint's rows A and offset b), and everything compiled to
// tapes. It does not depend on the scalar types: a FormulaSystem (formula_system.hpp) evaluates its tapes in any of
// them, with the parameter values in any parameter type. Immutable once built; shared by every copy of a system.
//
// What compile_model refuses, each with one line naming the place (file:line:column, or the field of an
// in-memory description): a formula that does not parse, an unknown symbol (with the nearest known name), a
// coordinate beyond n, a shape outside the supported set, a Lagrangian or force that depends on z, a constraint
// row not linear in the velocities (or free of them), a holonomic constraint that depends on the velocities,
// initial data that are not constant, a parameter without a finite default. What depends on the parameter values
// (finite derived values, the Legendre transform at the initial data, constraint rank, g(0, q0) = 0, the
// Herglotz form against the force) is checked by FormulaSystem::validate and warnings.
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "geomint/formula/description.hpp"
#include "geomint/formula/tape.hpp"

namespace geomint::formula {

// The shapes formula systems come in: n coordinates, m < n constraint rows (velocity or holonomic). The reader takes
// every shape up to these; a registry entry needs its shape compiled (core/src/formula/shapes.def, one line a shape).
// 12 and 6: the expression graph's variables (t, q, v, z) fit its 32-bit masks up to n = 15, and a chain of six bodies
// or a rolling ball with its full configuration needs no more.
inline constexpr int max_coordinates = 12;
inline constexpr int max_constraints = 6;
// The parameter a time-transformed model adds: the stiffness kappa of its penalty (kappa/2)(t' - g)^2.
inline constexpr const char* time_transform_kappa = "tt_kappa";
constexpr bool supported_shape(int n, int m) { return n >= 1 && n <= max_coordinates && m >= 0 && m <= max_constraints && m < n; }

struct CompileOptions {
  // A Herglotz Lagrangian inconsistent with the force is an error (FormulaSystem::validate) instead of a
  // warning (FormulaSystem::warnings).
  bool strict_herglotz = false;
  // L (and the Herglotz form) quadratic in (q, v) and F affine in them, all with constant coefficients, and a
  // holonomic g affine in q: the stepper's single-update path applies where the rows are then affine
  // (generic/system.hpp, `linear_dynamics`). Found from the formulas.
  bool linear_dynamics = false;
};

struct FormulaParameter {
  std::string name;
  double value;  // the default
  std::string doc;
  Where where;
};

struct NamedConstant {
  std::string name;
  Where where;
};

class FormulaModel {
 public:
  std::string name, description;
  Where origin;
  int n = 0, m = 0;
  bool holonomic = false;
  bool strict_herglotz = false;
  // L (and the Herglotz form) quadratic in (q, v) and F affine in them, all with constant coefficients, and a
  // holonomic g affine in q: the stepper's single-update path applies where the rows are then affine
  // (generic/system.hpp, `linear_dynamics`). Found from the formulas.
  bool linear_dynamics = false;
  std::vector<FormulaParameter> parameters;  // includes T, the horizon

  // The parameter table of the tapes, pv = (numbers | parameters | derived values).
  std::vector<double> numbers;
  std::vector<std::string> number_texts;  // as written ("0.5", "pi"); empty where differentiation made the number
  std::vector<std::string> derived_origin;  // for messages: the formula that first needed derived value k
  Tape prelude;                             // constant tape: (numbers, parameters) -> derived values

  // State tapes; inputs t, q1..qn, v1..vn, z (Variables).
  Tape lagrangian, herglotz, energy;  // one output each (herglotz, energy: empty when not given)
  Tape force;                         // n outputs, or empty
  Tape constraint_matrix;             // m x n outputs, column-major (Eigen's layout): A(t, q)
  Tape constraint_offset;             // m outputs: b(t, q)
  Tape holonomic_g;                   // m outputs: g(t, q) (holonomic systems)
  Tape initial;                       // constant tape: q(t0) (n outputs), then q'(t0) (n outputs)
  Tape start;                         // constant tape: t0, z0 (two outputs; 0 where not given)
  Tape exact;                         // state tape in t only: q, q', q'' of the exact solution (3n outputs), or empty
  Tape definitions;                   // constant tape: the definitions of parameters only, for validate's messages
  std::vector<NamedConstant> definition_names;

  // Places for messages.
  Where lagrangian_at, herglotz_at;
  std::vector<Where> constraint_at, initial_at;  // initial_at: q1..qn then v1..vn
  Where start_at;                   // [initial] t0 (else the system)
  std::vector<Where> exact_at;      // [exact] q1..qn, then v1..vn (each q's place where its v is derived)

  // A time transformation dt = g dsigma (docs/time-transformation.md): the model is the extended system in sigma,
  // n = physical_n + 1 coordinates (q, t), built from the physical formulas; `physical` is the physical model
  // (the Herglotz check runs on it), `residual` the penalty multiplier w = kappa (t' - g), zero on the exact flow:
  // its size along a discrete flow measures the error of the transformation.
  bool time_transformed = false;
  int physical_n = 0;
  Where time_transform_at;
  Tape residual;  // one output: w(sigma, Q, Q')
  std::shared_ptr<const FormulaModel> physical;

  bool has_herglotz() const { return !herglotz.empty(); }
  bool has_force() const { return !force.empty(); }
  bool has_energy() const { return !energy.empty(); }
  bool has_exact() const { return !exact.empty(); }
  int parameter_offset() const { return static_cast<int>(numbers.size()); }
  int derived_offset() const { return parameter_offset() + static_cast<int>(parameters.size()); }
  int table_size() const { return derived_offset() + static_cast<int>(prelude.size()); }
  int parameter_index(const std::string& name) const;  // -1 when there is no such parameter
  // "alpha, q0, p0, T"
  std::string parameter_names() const;
};

std::shared_ptr<const FormulaModel> compile_model(const SystemDescription& description, const CompileOptions& options = {});
// read_system_file + compile_model.
std::shared_ptr<const FormulaModel> load_system_file(const std::filesystem::path& path, const CompileOptions& options = {});

// `table` (the numbers and the parameters of `model`) completed with the derived values its prelude computes.
std::vector<double> with_derived_values(const FormulaModel& model, std::vector<double> table);

}  // namespace geomint::formula
