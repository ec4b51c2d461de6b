#pragma once
// Run-time access to every system of the generic core and every scheme built from it, by name.
//
// A system is one header under core/include/geomint/systems/ plus one line in core/src/systems.def; the
// build then compiles that system's schemes, references and runners once, in a translation unit of its own
// (generated from systems.def), and every program that takes --system finds it here. Nothing else changes.
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "geomint/timing.hpp"

namespace geomint {

namespace formula {
class FormulaModel;
}

// A parameter of a system (its fields: physical constants, initial data, horizon T).
struct ParamInfo {
  std::string name;
  double value;  // the default
  std::string doc;
};
// Values that override a system's defaults, by name (unknown names are an InputError).
using ParamValues = std::vector<std::pair<std::string, double>>;

// Which implementation runs a scheme: the hand-derived closed form where the system has one for it
// (the default: the paper's bits), or the generic Newton step built from the Lagrangian.
enum class Path { fast, generic };
Path parse_path(const std::string& name);
const char* to_string(Path p);

struct SchemeInfo {
  std::string name;                  // its one name: la, contact, la-midpoint, la-trapezoid, contact-trapezoid, or a
                                     // scheme the system declares beyond the generic ones (la-printed, ...)
  std::vector<std::string> aliases;  // the paper's names of its closed form on this system (leapfrog, la-nh, ...),
                                     // accepted wherever the name is
  std::string principle;   // "Lagrange-d'Alembert (1)", "discrete Herglotz (3), (4)", or "declared by the system: ..."
  std::string quadrature;  // left, midpoint, trapezoid ("" for a scheme the system declares)
  int order;               // expected order of convergence (0: does not converge)
  std::string fast_path;   // the closed form that runs it on this system ("" if none)
  bool generic = true;     // it has a residual, so the generic Newton step runs it (false: its closed form only)
  std::string base;        // a composition ("<family>:<base>"): the symmetric scheme whose steps it composes
  std::string description() const;
  bool named(const std::string& name) const;  // its name or one of its aliases
};

// A quantity a study measures on a run beyond its error in q, declared by the system it belongs to (its
// `Measures` observer, generic/system_info.hpp): the Foucault pendulum's plane of oscillation, say.
struct MeasureInfo {
  std::string name;  // the column it is written in (energy_err, plane_err, ...)
  std::string doc;   // what it is, for a table's header
};

// The norm over the components of q in which an error max_j |q(t_j) - q_ref(t_j)| is taken: the largest
// component (every study's default), or the Euclidean length (a bob's distance from where it should be).
enum class ErrorNorm { max, euclidean };
ErrorNorm parse_norm(const std::string& name);
const char* to_string(ErrorNorm norm);

// A run as tidy columns, decimated to every k-th step (always including the first and the last).
struct Run {
  int n = 0, m = 0;
  bool contact = false;
  std::vector<long> j;
  std::vector<double> t;
  std::vector<double> q, p, v;   // rows of n: positions, discrete momenta p_j, velocities from p_j (continuous Legendre)
  std::vector<double> z;         // the Herglotz action (contact schemes; 0 otherwise)
  std::vector<double> lambda;    // rows of m: the impulse of the step into q_j (0 at j = 0)
  std::vector<double> energy;    // E(t_j, q_j, v_j)
  std::vector<double> phi_d;     // max_c |Phi_d^c(q_{j-1}, q_j)| (0 at j = 0): what the scheme imposes
  std::vector<double> phi;       // max_c |Phi^c(t_j, q_j, v_j)|: the continuous constraint at the discrete state
  std::vector<int> newton;       // Newton iterations of the step into q_j (generic path; -1 for a closed form)
  long steps = 0;
  double newton_mean = -1;       // mean Newton iterations per step over the whole run (-1: closed form)
  double max_phi_d = 0;          // over every step, not only the kept ones
  // The memory of one kept step (for check_memory before a long run is stored).
  static double bytes_per_step(int n, int m) {
    return static_cast<double>(sizeof(long) + sizeof(int) + sizeof(double) * (5 + 3 * n + m));
  }
};

// What the tests of a system expect of it (tests/systems/generic_systems.test.cpp), declared with the system where it
// differs from the defaults (a system's `static Expectations expectations()`): the parameters and step sizes of
// the convergence test, and the order a scheme shows there where it is not the scheme's own. The test fits the
// order on the asymptotic range (asymptotic_order, study.hpp) and holds it to `orders` within order_tolerance; a
// fit that is still pre-asymptotic there is reported as such, not failed. Defaults: the system's parameters with
// the horizon cut to 20 (several oscillations, short enough for CI), h = 0.1 halved five times, the reference the
// closed form where there is one (else Odeint at 1e-13).
struct Expectations {
  ParamValues params;                               // overrides of the system's defaults for the test
  double h_max = 0.1;
  int halvings = 5;                                 // h = h_max / 2^k, k = 0..halvings
  std::vector<std::pair<std::string, int>> orders;  // scheme -> the order it shows here, where not its own
  double order_tolerance = 0.1;
  std::string why;                                  // the reason for every declaration above
  int order_of(const std::string& scheme, int own) const {
    for (const auto& [s, k] : orders)
      if (s == scheme) return k;
    return own;
  }
};

// A reference solution on the grid t_j = t0 + j h, j = 0..N (t0: the system's initial_time).
struct Reference {
  std::string kind;  // what it is ("closed form", "Boost.Odeint dopri5 ... tol ...")
  double h = 0;
  long N = 0;
  int n = 0;
  std::vector<double> q;  // rows of n
  std::vector<double> v;  // rows of n: q'(t_j) (the closed form's, or the state Odeint integrates)
  // Row index of t = j * h_coarse on this grid (h_coarse a multiple of h); throws InputError otherwise.
  long index(long j, double h_coarse) const;
};
enum class ReferenceKind { automatic, exact, odeint, odeint_rhs };
ReferenceKind parse_reference(const std::string& name);

// A step of h and then a step of -h from a state reached by a symmetric base scheme: how far it lands from where it
// started (max norms), and the size of that state. For a symmetric map all of it is round-off; a constrained
// scheme brings p back only up to a multiple of A(t, q)^T (generic/composition.hpp), so the part of dp
// orthogonal to those directions is reported apart.
struct SymmetryDefect {
  double dq = 0, dz = 0, dp = 0, dp_tangent = 0;
  double q = 0, p = 0;
};

struct SystemInfo {
  std::string name, description;
  int dof = 0, constraints = 0;
  bool has_exact = false, has_herglotz = false, has_rhs = false, linear = false;
  std::vector<ParamInfo> params;
  std::vector<SchemeInfo> schemes;       // what a study runs when no scheme is named
  // Compositions of its symmetric schemes with every coefficient family (generic/composition_families.hpp),
  // named "<family>:<base>": schemes like the others for every operation below (a one-step map run by the
  // generic step of the base; no closed form, so the path is generic whatever is asked), run only when named.
  std::vector<SchemeInfo> compositions;
  Expectations expectations;  // what its tests expect (declared with the system, or the defaults)
  std::vector<MeasureInfo> measures;  // what a run is measured by beyond the error in q (declared with the system)

  // What the libraries above the core find their part of this system by (its modified equations: modified_system in
  // modified/automatic_registry.hpp), so that a system is looked up by name once, here: a header system's place among
  // the entries of core/src/systems.def (0-based; the libraries list theirs from the same file, in the same order),
  // or a formula system's model (then index is -1).
  int index = -1;
  std::shared_ptr<const formula::FormulaModel> model;

  // Operations on this system: closures over its compiled code (its generated translation unit, or the shape of a
  // system defined by formulas) and, where the system is data, over that data (a formula system's model).
  std::function<void(const ParamValues&)> validate;  // InputError naming the first bad value
  std::function<double(const ParamValues&)> horizon;  // T
  std::function<double(const ParamValues&)> initial_time;  // t0: every run starts there, t_j = t0 + j h
  // N = T/h steps of `scheme`, keeping every `every`-th step.
  std::function<Run(const ParamValues&, const std::string& scheme, double h, Path, long every)> run;
  // max_j |q_j - q_ref(t_j)| (max norm over components) without storing the run.
  std::function<double(const ParamValues&, const std::string& scheme, double h, Path, const Reference&)> max_error;
  // The error in q and the system's measures of one run, in one pass: {max_j |q(t_j) - q_ref(t_j)| in `norm`,
  // then one value per entry of `measures`}. With measures, `ref` needs a grid of h/2 (a measure may compare a
  // chord quantity at t_{j+1/2} with the reference's state there) and its velocities.
  std::function<std::vector<double>(const ParamValues&, const std::string& scheme, double h, Path, const Reference&,
                                                       ErrorNorm norm)> measure_run;
  // max_j |(shift + q_j)/(shift + q_ref(t_j)) - 1| (the paper's regularized relative error, component 0).
  std::function<double(const ParamValues&, const std::string& scheme, double h, Path, const Reference&,
                                       double shift)> max_relative_error;
  // The reference on t_j = t0 + j h, j = 0..N: the closed form, or Boost.Odeint (dopri5, dense output, tolerance
  // tol) on the equations derived from L, F and Phi by automatic differentiation (odeint) or on the system's
  // hand-written rhs (odeint_rhs).
  std::function<Reference(const ParamValues&, double h, long N, ReferenceKind, double tol)> reference;
  // For work–precision: the CPU time of one run of N = T/h steps (nothing stored; warm-up, repeats: median, min, max),
  // and the continuous equations as a first-order ODE x' = f(t, x), x = (q, q') (the AD-derived acceleration),
  // with its consistent initial state, for Odeint baselines.
  std::function<TimingStats(const ParamValues&, const std::string& scheme, double h, Path, int reps)> time_run;
  using Rhs = std::function<void(double t, const double* x, double* dx)>;
  std::function<Rhs(const ParamValues&)> ode;
  // The same with the system's hand-written acceleration (InputError without one): the equations an Odeint or GSL
  // baseline integrates when it is to cost what a hand-written right-hand side costs (AD's is several times dearer).
  std::function<Rhs(const ParamValues&)> ode_rhs;
  // The closed-form positions at arbitrary times (rows of n; InputError without a closed form): an adaptive
  // method's error at the steps it chose.
  std::function<std::vector<double>(const ParamValues&, const std::vector<double>& times)> exact_positions;
  // (q0, v0): the start of `ode` (hand_written false), or of `ode_rhs` (true: the system's own projection onto its
  // constraints where it writes one, as the hand-written equations do; the two agree to round-off)
  std::function<std::vector<double>(const ParamValues&, bool hand_written)> ode_initial_state;
  // What a study may measure along a run besides q, at a state (t, q, q'): out[0] = the energy E(t, q, q') (the
  // system's, else q'.L_q' - L), out[1 + i] = the momentum p_i = dL/dq'_i (by AD): n + 1 values.
  using Observables = std::function<void(double t, const double* q, const double* v, double* out)>;
  std::function<Observables(const ParamValues&)> observables;
  // Linear unconstrained systems (stability maps): the linear part of the one-step map of `scheme` on (q, p)
  // (2n x 2n, row-major; a forcing term is removed by differencing), and of the continuous flow's generator on
  // (q, q'). On the fast path a closed form gives its matrix in long double (the system's closed_form_matrix),
  // the generic step in double. InputError for other systems.
  std::function<std::vector<long double>(const ParamValues&, const std::string& scheme, double h, Path)> one_step_matrix;
  std::function<std::vector<double>(const ParamValues&)> continuous_matrix;
  // What only compositions have (generic/composition_info.hpp), for tests and benchmarks: the symmetry defect of the
  // base scheme's step of h then -h, from the state after `steps` steps of h from the initial data; and N steps from
  // the initial data, nothing stored, returning the Newton updates they took, of the composition `name` at step h
  // or of the base scheme alone at step h (any nonzero h, not tied to T: a stage's step). A formula system
  // compiles its shape's schemes without them: InputError.
  std::function<SymmetryDefect(const ParamValues&, const std::string& base, double h, long steps)> symmetry;
  std::function<long(const ParamValues&, const std::string& name, double h, long N)> composition_steps;
  std::function<long(const ParamValues&, const std::string& base, double h, long N)> base_steps;

  // The scheme or composition named `name` (or one of its aliases); InputError naming the known ones.
  const SchemeInfo& scheme(const std::string& name) const;
  std::vector<std::string> scheme_names() const;       // the schemes' one names, in the registry's order
  std::vector<std::string> composition_names() const;  // every "<family>:<base>", families outermost
  std::vector<std::string> composition_bases() const;  // the symmetric schemes they compose
  // The header lines of an output file: every parameter with its value.
  std::vector<std::pair<std::string, std::string>> header(const ParamValues&) const;
};

// Refuses a reference the system cannot give (or a tolerance out of range) before any work starts.
void check_reference(const SystemInfo& sys, ReferenceKind kind, double tol);
// Refuses a reference on N + 1 times that would not fit in the memory available (its positions, and for Odeint
// also the times and the states it returns): before the folder is made, and again where it is built.
void check_reference_memory(int dof, bool exact, long N);
void check_reference_memory(const SystemInfo& sys, ReferenceKind kind, long N);

const std::vector<SystemInfo>& all_systems();
const SystemInfo& find_system(const std::string& name);  // InputError naming the known ones
std::vector<std::string> system_names();

}  // namespace geomint
