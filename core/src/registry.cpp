#include "geomint/registry.hpp"

#include <algorithm>
#include <cmath>

#include "geomint/budget.hpp"
#include "geomint/error.hpp"
#include "geomint/generic/composition_families.hpp"
#include "geomint/io.hpp"

namespace geomint {

// One declaration per line of systems.def; each is defined in the system's generated translation unit.
#define GEOMINT_SYSTEM(header, Type) SystemInfo make_system_info_##Type();
#include "systems.def"
#undef GEOMINT_SYSTEM

namespace {
std::vector<SystemInfo> numbered_systems() {
  std::vector<SystemInfo> all = {
#define GEOMINT_SYSTEM(header, Type) make_system_info_##Type(),
#include "systems.def"
#undef GEOMINT_SYSTEM
  };
  for (std::size_t i = 0; i < all.size(); ++i) all[i].index = static_cast<int>(i);
  return all;
}
}  // namespace

const std::vector<SystemInfo>& all_systems() {
  static const std::vector<SystemInfo> all = numbered_systems();
  return all;
}

std::vector<std::string> system_names() {
  std::vector<std::string> names;
  for (const auto& s : all_systems()) names.push_back(s.name);
  return names;
}

const SystemInfo& find_system(const std::string& name) {
  for (const auto& s : all_systems())
    if (s.name == name) return s;
  std::string known;
  for (const auto& s : all_systems()) known += (known.empty() ? "" : ", ") + s.name;
  throw InputError("unknown system '" + name + "' (known: " + known + ")");
}

const SchemeInfo& SystemInfo::scheme(const std::string& scheme_name) const {
  for (const auto& s : schemes)
    if (s.named(scheme_name)) return s;
  for (const auto& s : compositions)
    if (s.name == scheme_name) return s;
  const auto bases = composition_bases();
  if (scheme_name.find(':') != std::string::npos) {
    const auto parsed = generic::parse_composition_name(scheme_name);  // InputError: no family or no such family
    throw InputError("scheme '" + parsed.base + "' of system '" + name + "' cannot be composed (" +
                     (bases.empty() ? std::string("it has no symmetric scheme") : "symmetric schemes: " + join_names(bases, ", ")) +
                     ")");
  }
  std::string known = join_names(scheme_names(), ", ");
  if (!bases.empty()) {
    std::vector<std::string> families;
    for (const auto& f : generic::composition_families()) families.push_back(f.name);
    known += "; compositions <family>:<base> of families " + join_names(families, ", ") + " and bases " + join_names(bases, ", ");
  }
  throw InputError("unknown scheme '" + scheme_name + "' for system '" + name + "' (known: " + known + ")");
}

std::vector<std::string> SystemInfo::scheme_names() const {
  std::vector<std::string> names;
  for (const auto& s : schemes) names.push_back(s.name);
  return names;
}

std::vector<std::string> SystemInfo::composition_bases() const {
  std::vector<std::string> bases;
  for (const auto& s : compositions)
    if (std::find(bases.begin(), bases.end(), s.base) == bases.end()) bases.push_back(s.base);
  return bases;
}

std::vector<std::string> SystemInfo::composition_names() const {
  std::vector<std::string> names;
  for (const auto& s : compositions) names.push_back(s.name);
  return names;
}

std::vector<std::pair<std::string, std::string>> SystemInfo::header(const ParamValues& values) const {
  std::vector<std::pair<std::string, std::string>> out{{"system", name}};
  for (const auto& p : params) {
    double v = p.value;
    for (const auto& [k, x] : values)
      if (k == p.name) v = x;
    out.emplace_back(p.name, format_number(v));
  }
  return out;
}

std::string SchemeInfo::description() const {
  std::string alias;
  for (const auto& a : aliases) alias += (alias.empty() ? "" : ", ") + a;
  return principle + (quadrature.empty() ? "" : ", " + quadrature + " quadrature") + ", order " + std::to_string(order) +
         (fast_path.empty() ? "" : "; closed form: " + fast_path) + (alias.empty() ? "" : "; also named " + alias);
}

bool SchemeInfo::named(const std::string& n) const {
  if (n == name) return true;
  for (const auto& a : aliases)
    if (n == a) return true;
  return false;
}

Path parse_path(const std::string& name) {
  if (name == "fast") return Path::fast;
  if (name == "generic") return Path::generic;
  throw InputError("unknown path '" + name + "' (known: fast generic)");
}

const char* to_string(Path p) { return p == Path::fast ? "fast" : "generic"; }

ErrorNorm parse_norm(const std::string& name) {
  if (name == "max") return ErrorNorm::max;
  if (name == "2") return ErrorNorm::euclidean;
  throw InputError("unknown norm '" + name + "' (known: max 2)");
}

const char* to_string(ErrorNorm norm) { return norm == ErrorNorm::max ? "max" : "2"; }

ReferenceKind parse_reference(const std::string& name) {
  if (name == "auto") return ReferenceKind::automatic;
  if (name == "exact") return ReferenceKind::exact;
  if (name == "odeint") return ReferenceKind::odeint;
  if (name == "odeint-rhs") return ReferenceKind::odeint_rhs;
  throw InputError("unknown reference '" + name + "' (known: auto exact odeint odeint-rhs)");
}

void check_reference(const SystemInfo& sys, ReferenceKind kind, double tol) {
  if (kind == ReferenceKind::exact)
    require(sys.has_exact, "system '" + sys.name + "' has no closed-form solution (use --reference odeint)");
  if (kind == ReferenceKind::odeint_rhs)
    require(sys.has_rhs, "system '" + sys.name + "' has no hand-written rhs (use --reference odeint)");
  if (kind == ReferenceKind::odeint || kind == ReferenceKind::odeint_rhs || (kind == ReferenceKind::automatic && !sys.has_exact))
    require(std::isfinite(tol) && tol >= 1e-15 && tol < 1, "tol must be in [1e-15, 1), got " + show(tol));
}

void check_reference_memory(int dof, bool exact, long N) {
  // q and q' at every time; Odeint also holds the times and the states it returns
  const double per_time = sizeof(double) * (exact ? 2 * dof : 1 + 4 * dof);
  check_memory(double(N + 1) * per_time, "the reference (" + show(double(N + 1)) + " times; lower --T or raise --h)");
}

void check_reference_memory(const SystemInfo& sys, ReferenceKind kind, long N) {
  check_reference_memory(sys.dof, kind == ReferenceKind::exact || (kind == ReferenceKind::automatic && sys.has_exact), N);
}

long Reference::index(long j, double h_coarse) const {
  const double ratio = h_coarse / h;
  const long k = std::lround(ratio);
  require(k >= 1 && std::abs(ratio - static_cast<double>(k)) <= 1e-9 * ratio,
          "h = " + show(h_coarse) + " is not a multiple of the reference step " + show(h));
  const long r = j * k;
  require(r <= N, "t = " + show(static_cast<double>(j) * h_coarse) + " is beyond the reference horizon");
  return r;
}

}  // namespace geomint

#include "geomint/step_cost.hpp"

namespace geomint {

double step_cost(const SystemInfo& sys, const std::string& scheme, Path path) {
  const SchemeInfo& sc = sys.scheme(scheme);
  if (!sc.generic) return 1.0;  // declared by the system: its closed form, whatever the path
  if (!sc.base.empty()) {  // "<family>:<base>": its stages, each a generic step of the base
    const auto family = sc.name.substr(0, sc.name.find(':'));
    return generic_step_cost * generic::find_composition_family(family).stages();
  }
  return path == Path::fast && !sc.fast_path.empty() ? 1.0 : generic_step_cost;
}

}  // namespace geomint

#include "geomint/run_checks.hpp"

namespace geomint {

void require_finite_run(const Run& run, const std::string& context) {
  const auto n = static_cast<std::size_t>(run.n);
  for (std::size_t r = 0; r < run.t.size(); ++r) {
    const char* what = nullptr;
    const char* quantity = nullptr;
    for (std::size_t i = r * n; i < (r + 1) * n && !what; ++i)
      if (!std::isfinite(run.q[i]) || !std::isfinite(run.p[i]) || !std::isfinite(run.v[i])) what = "the state (q, p, v, z)";
    if (!what && !std::isfinite(run.z[r])) what = "the state (q, p, v, z)";
    if (what) quantity = "state";
    if (!what && !std::isfinite(run.energy[r])) what = "the energy", quantity = "energy";
    if (!what && (!std::isfinite(run.phi[r]) || !std::isfinite(run.phi_d[r])))
      what = "the constraint residual", quantity = "residual";
    if (what)
      throw NumericalFailure(run.j[r], quantity, context + ": " + what + " is not finite at t = " + show(run.t[r]));
  }
}

void plan_run(const SystemInfo& sys, const std::string& scheme, Path path, double h, double T, long every,
              double copies, const std::string& raise) {
  require(every >= 1, "every must be a positive integer, got " + std::to_string(every));
  const long N = step_count(h, T);
  plan_steps(static_cast<double>(N), "the run (T/h)", step_cost(sys, scheme, path));
  const double rows = static_cast<double>(N / every + 1);
  check_memory(copies * rows * Run::bytes_per_step(sys.dof, sys.constraints),
               "the run (" + show(rows) + " kept rows; raise " + raise + ")");
}

}  // namespace geomint
