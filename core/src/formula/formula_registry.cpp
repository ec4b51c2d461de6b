#include "geomint/formula/formula_registry.hpp"

#include <algorithm>
#include <mutex>
#include <set>
#include <vector>

#include "geomint/error.hpp"
#include "geomint/formula/entry_slots.hpp"
#include "geomint/formula/formula_call.hpp"
#include "geomint/formula/formula_system.hpp"

namespace geomint::formula {

namespace {
thread_local std::shared_ptr<const FormulaModel> call_model;
thread_local std::string call_name, call_description;

void install(const std::shared_ptr<const FormulaModel>& m) {
  call_model = m;
  call_name = m ? m->name : std::string();
  call_description = m ? m->description : std::string();
}
}  // namespace

FormulaCall::FormulaCall(std::shared_ptr<const FormulaModel> model) : previous_(call_model) {
  require(model != nullptr, "formula system without a model");
  install(model);
}
FormulaCall::~FormulaCall() { install(previous_); }

const std::shared_ptr<const FormulaModel>& FormulaCall::model() {
  require(call_model != nullptr, "a formula system's operation was called outside its registry entry");
  return call_model;
}
const std::string& FormulaCall::name() { return call_name; }
const std::string& FormulaCall::description() { return call_description; }

// One declaration per compiled line of shapes.def (the build writes them to shapes_compiled.def); each is defined in the shape's generated translation unit.
#define GEOMINT_FORMULA_SHAPE(N, M, H, modified) SystemInfo make_formula_shape_info_##N##_##M##_##H();
#include "formula/shapes_compiled.def"
#undef GEOMINT_FORMULA_SHAPE

namespace {

struct Shape {
  int n, m;
  bool holonomic;
  SystemInfo (*make)();
};

const std::vector<Shape>& shapes() {
  static const std::vector<Shape> all = {
#define GEOMINT_FORMULA_SHAPE(N, M, H, modified) {N, M, H != 0, make_formula_shape_info_##N##_##M##_##H},
#include "formula/shapes_compiled.def"
#undef GEOMINT_FORMULA_SHAPE
  };
  return all;
}

// The shape's operations, built once (the builder reads the defaults of a model of that shape: the first one).
const SystemInfo& shape_info(std::size_t index, const std::shared_ptr<const FormulaModel>& model) {
  static std::vector<std::once_flag> once(shapes().size());
  static std::vector<SystemInfo> built(shapes().size());
  std::call_once(once[index], [&] {
    const FormulaCall call(model);
    built[index] = shapes()[index].make();
  });
  return built[index];
}

}  // namespace

std::vector<std::string> formula_warnings(const std::shared_ptr<const FormulaModel>& model, const ParamValues& values) {
  return with_formula_system(model, [&](auto sys) {
    for (const auto& [name, x] : values) sys.set_parameter(name, x);
    return sys.warnings();
  });
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

std::shared_ptr<const SystemInfo> formula_system_info(std::shared_ptr<const FormulaModel> model) {
  require(model != nullptr, "formula system without a model");
  std::size_t index = shapes().size();
  for (std::size_t i = 0; i < shapes().size(); ++i) {
    const Shape& s = shapes()[i];
    if (s.n == model->n && s.m == model->m && (s.m == 0 || s.holonomic == model->holonomic)) index = i;
  }
  require(index < shapes().size(),
          "system '" + model->name + "' has n = " + std::to_string(model->n) + ", m = " + std::to_string(model->m) +
              (model->holonomic ? " (holonomic)" : "") + ": this build compiles formula systems of the shapes " +
              compiled_formula_shapes() + " (one line in core/src/formula/shapes.def adds a shape)");
  const SystemInfo& shape = shape_info(index, model);
  SystemInfo entry = shape;
  // The shape's entry was built once, with the first model of its shape installed: what it read from that model's
  // parameters is this model's to give. Expectations are the defaults of generic::expectations_of (a formula
  // system declares none): the horizon cut to 20, at this model's horizon.
  entry.expectations = Expectations{};
  if (const int iT = model->parameter_index("T"); iT >= 0 && model->parameters[static_cast<std::size_t>(iT)].value > 20)
    entry.expectations.params = {{"T", 20}};
  entry.name = model->name;
  entry.description = model->description;
  entry.has_herglotz = model->has_herglotz();
  entry.has_exact = model->has_exact();
  entry.params.clear();
  for (const auto& p : model->parameters) entry.params.push_back({p.name, p.value, p.doc});
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
  return EntrySlots<SystemInfo>::acquire<&SystemInfo::validate, &SystemInfo::horizon, &SystemInfo::initial_time, &SystemInfo::run, &SystemInfo::max_error,
                                         &SystemInfo::max_relative_error, &SystemInfo::reference,
                                         &SystemInfo::time_run, &SystemInfo::ode, &SystemInfo::ode_initial_state,
                                         &SystemInfo::measure_run, &SystemInfo::ode_rhs, &SystemInfo::exact_positions,
                                         &SystemInfo::one_step_matrix, &SystemInfo::continuous_matrix>(model, &shape,
                                                                                                        std::move(entry));
}

}  // namespace geomint::formula
