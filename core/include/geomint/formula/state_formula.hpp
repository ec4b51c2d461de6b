#pragma once
// A function of a state (t, q, q') written as a formula, for what a study measures along a run besides q (an
// invariant, an angle, a distance): the grammar of a system file's formulas (parser.hpp), in t, q1..qn, v1..vn
// (v the velocities q'), pi, and the system's parameters by name, at the values of the run. Evaluated in double,
// node by node over the expression graph (a measure is read on an output grid, not in a step's inner loop).
#include <string>
#include <utility>
#include <vector>

#include "geomint/formula/expression.hpp"

namespace geomint::formula {

class StateFormula {
 public:
  // InputError naming the column and the known symbols for a formula that does not parse or uses an unknown name.
  StateFormula(const std::string& text, int n, const std::vector<std::pair<std::string, double>>& parameters);
  double operator()(double t, const double* q, const double* v) const;
  const std::string& text() const { return text_; }

 private:
  std::string text_;
  Expressions ex_;
  int root_ = -1;
};

}  // namespace geomint::formula
