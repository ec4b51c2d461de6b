#pragma once
// Column widths of the programs' printed tables: a scheme column as wide as its longest name (compositions,
// "yoshida6a:contact-trapezoid", are longer than the schemes the widths were first chosen for).
#include <algorithm>
#include <string>
#include <vector>

namespace geomint {

inline int name_width(const std::vector<std::string>& names, int at_least) {
  int w = at_least;
  for (const auto& n : names) w = std::max(w, static_cast<int>(n.size()));
  return w;
}

}  // namespace geomint
