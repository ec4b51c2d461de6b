#include "geomint/modified/formula_modified.hpp"

#include <algorithm>
#include <memory>
#include <vector>

#include "geomint/error.hpp"
#include "geomint/formula/formula_registry.hpp"
#include "geomint/formula/jit.hpp"

namespace geomint::modified {

// One declaration per shape of shapes.def marked for modified equations (defined in its generated translation
// unit); the builder of an unmarked shape is null.
#define GEOMINT_MODIFIED_0(N, M, H) nullptr
#define GEOMINT_MODIFIED_1(N, M, H) make_formula_modified_##N##_##M##_##H
#define GEOMINT_DECLARE_0(N, M, H)
#define GEOMINT_DECLARE_1(N, M, H) \
  ModifiedSystem make_formula_modified_##N##_##M##_##H(std::shared_ptr<const formula::FormulaModel>);
#define GEOMINT_FORMULA_SHAPE(N, M, H, modified) GEOMINT_DECLARE_##modified(N, M, H)
#include "formula/shapes_compiled.def"
#undef GEOMINT_FORMULA_SHAPE

namespace {

struct Shape {
  int n, m;
  bool holonomic, modified;
  ModifiedSystem (*make)(std::shared_ptr<const formula::FormulaModel>);
};

const std::vector<Shape>& shapes() {
  static const std::vector<Shape> all = {
#define GEOMINT_FORMULA_SHAPE(N, M, H, modified) {N, M, H != 0, modified != 0, GEOMINT_MODIFIED_##modified(N, M, H)},
#include "formula/shapes_compiled.def"
#undef GEOMINT_FORMULA_SHAPE
  };
  return all;
}

// The modified equations of a shape the build did not compile them for, from its units compiled at run time
// (formula/jit.hpp): the numeric unit and the formulas' (or, in a build without them, its refusal), as the build
// makes them.
ModifiedSystem compiled_at_run_time(const std::shared_ptr<const formula::FormulaModel>& model) {
  const std::string n = std::to_string(model->n), m = std::to_string(model->m), h = model->holonomic ? "1" : "0";
  const std::string shape = n + "_" + m + "_" + h;
  const std::vector<std::pair<std::string, std::string>> numbers = {
      {"GEOMINT_SHAPE_N", n}, {"GEOMINT_SHAPE_M", m}, {"GEOMINT_SHAPE_H", h}};
  formula::jit::Library library;
  library.name = "formula_modified_" + shape;
  library.what = "the modified equations of the formula shape n = " + n + ", m = " + m + (model->holonomic ? " (holonomic)" : "");
  library.units.push_back({"modified_equations/src/formula_shape_instance.cpp.in", numbers,
                           "extern \"C\" __attribute__((visibility(\"default\"))) void geomint_jit_entry(const std::shared_ptr<const geomint::formula::FormulaModel>& model,\n"
                           "                                  geomint::modified::ModifiedSystem& out) {\n"
                           "  out = geomint::modified::make_formula_modified_" + shape + "(model);\n}\n",
                           {"-O1"}});  // as the build's light units: instantiation is their cost, not optimization
#if GEOMINT_SYMBOLIC
  library.units.push_back({"modified_equations/src/formula_symbolic_instance.cpp.in", numbers, "", {"-O1"}});
  library.links_formulas = true;
#else
  auto refusal = numbers;
  refusal.push_back({"GEOMINT_SYMBOLIC_FUNCTION", "formula_symbolic_" + shape});
  refusal.push_back({"GEOMINT_SYMBOLIC_LEADING", "std::shared_ptr<const formula::FormulaModel>, "});
  library.units.push_back({"modified_equations/src/symbolic_absent.cpp.in", refusal, "", {"-O1"}});
#endif
  using Entry = void (*)(const std::shared_ptr<const formula::FormulaModel>&, ModifiedSystem&);
  const auto make = reinterpret_cast<Entry>(formula::jit::symbol(library, "geomint_jit_entry"));
  ModifiedSystem entry;
  make(model, entry);
  return entry;
}

}  // namespace

std::shared_ptr<const ModifiedSystem> formula_modified_system(std::shared_ptr<const formula::FormulaModel> model) {
  require(model != nullptr, "formula system without a model");
  std::size_t index = shapes().size();
  std::string marked;
  for (std::size_t i = 0; i < shapes().size(); ++i) {
    const Shape& s = shapes()[i];
    if (!s.modified) continue;
    marked += (marked.empty() ? "" : "; ") + std::string("n = ") + std::to_string(s.n) + ", m = " + std::to_string(s.m) +
              (s.holonomic ? " holonomic" : "");
    if (s.n == model->n && s.m == model->m && (s.m == 0 || s.holonomic == model->holonomic)) index = i;
  }
  std::string why;  // the path's state, read before the message is built from it
  const bool at_run_time = index == shapes().size() && formula::jit::enabled(&why);
  require(index < shapes().size() || at_run_time,
          "system '" + model->name + "' has n = " + std::to_string(model->n) + ", m = " + std::to_string(model->m) +
              (model->holonomic ? " (holonomic)" : "") + ": this build compiles the modified equations of formula systems of the shapes " +
              marked + " (a 1 in the last column of the shape's line in core/src/formula/shapes.def, GEOMINT_FORMULA_SHAPE(" +
              std::to_string(model->n) + ", " + std::to_string(model->m) + ", " + (model->holonomic ? "1" : "0") +
              ", 1), and a rebuild add them; " + why + ")");
  ModifiedSystem entry = index < shapes().size() ? shapes()[index].make(model) : compiled_at_run_time(model);
  entry.has_herglotz = model->has_herglotz();
  if (!model->has_herglotz())  // the core's contact schemes are the ones named contact*
    entry.schemes.erase(std::remove_if(entry.schemes.begin(), entry.schemes.end(),
                                       [](const std::string& s) { return s.rfind("contact", 0) == 0; }),
                        entry.schemes.end());
  return std::make_shared<const ModifiedSystem>(std::move(entry));
}

}  // namespace geomint::modified
