#pragma once
// FormulaCall: the model whose registry operation runs on this thread (formula_registry.hpp). A registry entry of a
// formula system installs its model around each operation; the shape's code, compiled once for every model of
// that shape (registered_system.hpp), reads it.
#include <memory>
#include <string>

#include "geomint/formula/model.hpp"

namespace geomint::formula {

class FormulaCall {
 public:
  explicit FormulaCall(std::shared_ptr<const FormulaModel> model);
  ~FormulaCall();  // restores the enclosing call's model (calls nest: an operation may call another entry)
  FormulaCall(const FormulaCall&) = delete;
  FormulaCall& operator=(const FormulaCall&) = delete;

  // InputError when no call is in progress (a shape's operation called outside its registry entry).
  static const std::shared_ptr<const FormulaModel>& model();
  // A thread's own strings, set while a call is in progress (empty otherwise).
  static const std::string& name();
  static const std::string& description();

 private:
  std::shared_ptr<const FormulaModel> previous_;
};

}  // namespace geomint::formula
