#include "geomint/formula/formula_registry.hpp"

#include <algorithm>
#include <memory>
#include <mutex>
#include <set>
#include <vector>

#include "geomint/error.hpp"
#include "geomint/formula/checks.hpp"
#include "geomint/formula/jit.hpp"
#include "geomint/formula/time_transform.hpp"

namespace geomint::formula {

// One declaration per compiled line of shapes.def (the build writes them to shapes_compiled.def); each is defined in the shape's generated translation unit.
#define GEOMINT_FORMULA_SHAPE(N, M, H, modified) \
  SystemInfo make_formula_shape_info_##N##_##M##_##H(std::shared_ptr<const FormulaModel> model);
#include "formula/shapes_compiled.def"
#undef GEOMINT_FORMULA_SHAPE

namespace {

struct Shape {
  int n, m;
  bool holonomic;
  SystemInfo (*make)(std::shared_ptr<const FormulaModel>);
};

const std::vector<Shape>& shapes() {
  static const std::vector<Shape> all = {
#define GEOMINT_FORMULA_SHAPE(N, M, H, modified) {N, M, H != 0, make_formula_shape_info_##N##_##M##_##H},
#include "formula/shapes_compiled.def"
#undef GEOMINT_FORMULA_SHAPE
  };
  return all;
}

// The entry of a shape the build did not compile, from the shape's unit compiled at run time (formula/jit.hpp).
SystemInfo compiled_at_run_time(const std::shared_ptr<const FormulaModel>& model) {
  const std::string n = std::to_string(model->n), m = std::to_string(model->m), h = model->holonomic ? "1" : "0";
  jit::Library library;
  library.name = "formula_shape_" + n + "_" + m + "_" + h;
  library.what = "the formula shape n = " + n + ", m = " + m + (model->holonomic ? " (holonomic)" : "");
  library.units.push_back(
      {"core/src/formula/shape_instance.cpp.in",
       {{"GEOMINT_SHAPE_N", n}, {"GEOMINT_SHAPE_M", m}, {"GEOMINT_SHAPE_H", h}},
       "extern \"C\" __attribute__((visibility(\"default\"))) void geomint_jit_entry(const std::shared_ptr<const geomint::formula::FormulaModel>& model,\n"
       "                                  geomint::SystemInfo& out) {\n"
       "  out = geomint::formula::make_formula_shape_info_" + n + "_" + m + "_" + h + "(model);\n}\n",
       {}});
  using Entry = void (*)(const std::shared_ptr<const FormulaModel>&, SystemInfo&);
  const auto make = reinterpret_cast<Entry>(jit::symbol(library, "geomint_jit_entry"));
  SystemInfo entry;
  make(model, entry);
  return entry;
}

}  // namespace

// The warnings depend on the model and its parameters, not on its shape: any shape, compiled or not.
std::vector<std::string> formula_warnings(const std::shared_ptr<const FormulaModel>& model, const ParamValues& values) {
  require(model != nullptr, "formula system without a model");
  for (const auto& [name, x] : values)
    require(model->parameter_index(name) >= 0,
            "system '" + model->name + "' has no parameter '" + name + "' (known: " + model->parameter_names() + ")");
  if (model->strict_herglotz) return {};  // an inconsistent form was refused as an error instead
  std::string why = herglotz_mismatch(*model, parameter_table(*model, values));
  if (why.empty()) return {};
  return {std::move(why)};
}

bool contact_family(const SystemInfo& sys, const std::string& scheme) {
  // a composition's principle names its base's ("... of contact: discrete Herglotz ...")
  return sys.scheme(scheme).principle.find("discrete Herglotz") != std::string::npos;
}

std::vector<std::string> contact_warnings(const std::shared_ptr<const FormulaModel>& model, const SystemInfo& sys,
                                          const std::vector<ParamValues>& values, const std::vector<std::string>& schemes) {
  if (model == nullptr || !model->has_herglotz()) return {};
  if (std::none_of(schemes.begin(), schemes.end(), [&](const std::string& s) { return contact_family(sys, s); })) return {};
  // Once per model: the first run that finds the form inconsistent says so; a sweep over many values (each with
  // its own sample values in the message) would otherwise repeat it per value. Keyed by the model's ownership, not
  // its address: a model freed and another allocated in its place is a new key (the weak pointer keeps the old
  // control block), so a new system is never taken for one already warned.
  static std::mutex mutex;
  static std::set<std::weak_ptr<const FormulaModel>, std::owner_less<>> warned;
  {
    const std::lock_guard<std::mutex> lock(mutex);
    if (warned.count(model) > 0) return {};
  }
  for (const auto& pv : values) {
    auto why = formula_warnings(model, pv);
    if (why.empty()) continue;
    const std::lock_guard<std::mutex> lock(mutex);
    for (auto it = warned.begin(); it != warned.end();) it = it->expired() ? warned.erase(it) : std::next(it);
    if (!warned.insert(model).second) return {};  // another thread gave it meanwhile
    return why;
  }
  return {};
}

bool formula_shape_compiled(int n, int m, bool holonomic) {
  for (const auto& s : shapes())
    if (s.n == n && s.m == m && (m == 0 || s.holonomic == holonomic)) return true;
  return false;
}

std::string compiled_formula_shapes() {
  std::string out;
  for (const auto& s : shapes())
    out += (out.empty() ? "" : "; ") + std::string("n = ") + std::to_string(s.n) + ", m = " + std::to_string(s.m) +
           (s.holonomic ? " holonomic" : "");
  return out;
}

std::shared_ptr<const SystemInfo> formula_system_info(std::shared_ptr<const FormulaModel> model, bool at_run_time) {
  require(model != nullptr, "formula system without a model");
  std::size_t index = shapes().size();
  for (std::size_t i = 0; i < shapes().size(); ++i) {
    const Shape& s = shapes()[i];
    if (!at_run_time && s.n == model->n && s.m == model->m && (s.m == 0 || s.holonomic == model->holonomic)) index = i;
  }
  std::string why;  // the path's state, read before the message is built from it
  const bool jit_on = index == shapes().size() && jit::enabled(&why);
  require(index < shapes().size() || jit_on,
          "system '" + model->name + "' has n = " + std::to_string(model->n) + ", m = " + std::to_string(model->m) +
              (model->holonomic ? " (holonomic)" : "") + (model->time_transformed ? " (n counts the time t of its time transformation)" : "") +
              ": this build compiles formula systems of the shapes " +
              compiled_formula_shapes() + " (the line GEOMINT_FORMULA_SHAPE(" + std::to_string(model->n) + ", " +
              std::to_string(model->m) + ", " + (model->holonomic ? "1" : "0") +
              ", 1) in core/src/formula/shapes.def and a rebuild add it, with its modified equations; " + why + ")");
  SystemInfo entry = index < shapes().size() ? shapes()[index].make(model) : compiled_at_run_time(model);
  // The shape's code is compiled for every model of its shape: what it cannot know of this model is set here.
  entry.has_herglotz = model->has_herglotz();
  entry.has_exact = model->has_exact();
  entry.model = model;
  // A shape compiles its compositions' runs, not the benchmarks' and tests' operations of header systems.
  const std::string no_composition_ops = "system '" + model->name + "' is defined by formulas: the symmetry defect and "
                                         "the step counts of its compositions are compiled for header systems only";
  entry.symmetry = [no_composition_ops](const ParamValues&, const std::string&, double, long) -> SymmetryDefect {
    throw InputError(no_composition_ops);
  };
  entry.composition_steps = [no_composition_ops](const ParamValues&, const std::string&, double, long) -> long {
    throw InputError(no_composition_ops);
  };
  entry.base_steps = entry.composition_steps;
  if (!model->has_herglotz())  // the shape compiles them; this model cannot run them
    entry.schemes.erase(std::remove_if(entry.schemes.begin(), entry.schemes.end(),
                                       [](const SchemeInfo& s) { return s.principle.rfind("discrete Herglotz", 0) == 0; }),
                        entry.schemes.end());
  entry.compositions.erase(std::remove_if(entry.compositions.begin(), entry.compositions.end(),
                                          [&](const SchemeInfo& c) {
                                            for (const auto& s : entry.schemes)
                                              if (s.name == c.base) return false;
                                            return true;
                                          }),
                           entry.compositions.end());
  // A scheme is looked up in the shape's code by type, which has no name to give: the entry refuses an unknown one by
  // the model's name first.
  auto names = std::make_shared<SystemInfo>();
  names->name = entry.name;
  names->schemes = entry.schemes;
  names->compositions = entry.compositions;
  entry.run = [op = entry.run, names, model](const ParamValues& pv, const std::string& scheme, double h, Path path, long every) {
    names->scheme(scheme);
    Run run = op(pv, scheme, h, path, every);
    // A time-transformed model's velocities (and energies) from its momenta, by Newton from the previous row's
    // (time_transform.hpp): the core's inversion starts at Q' = p and can land on another root.
    if (model->time_transformed) time_transform_velocities(*model, parameter_table(*model, pv), run);
    return run;
  };
  entry.max_error = [op = entry.max_error, names](const ParamValues& pv, const std::string& scheme, double h, Path path,
                                                  const Reference& ref) {
    names->scheme(scheme);
    return op(pv, scheme, h, path, ref);
  };
  entry.measure_run = [op = entry.measure_run, names](const ParamValues& pv, const std::string& scheme, double h, Path path,
                                                      const Reference& ref, ErrorNorm norm) {
    names->scheme(scheme);
    return op(pv, scheme, h, path, ref, norm);
  };
  entry.max_relative_error = [op = entry.max_relative_error, names](const ParamValues& pv, const std::string& scheme,
                                                                    double h, Path path, const Reference& ref,
                                                                    double shift) {
    names->scheme(scheme);
    return op(pv, scheme, h, path, ref, shift);
  };
  entry.time_run = [op = entry.time_run, names](const ParamValues& pv, const std::string& scheme, double h, Path path,
                                                int reps) {
    names->scheme(scheme);
    return op(pv, scheme, h, path, reps);
  };
  entry.one_step_matrix = [op = entry.one_step_matrix, names](const ParamValues& pv, const std::string& scheme, double h,
                                                              Path path) {
    names->scheme(scheme);
    return op(pv, scheme, h, path);
  };
  return std::make_shared<const SystemInfo>(std::move(entry));
}

}  // namespace geomint::formula
