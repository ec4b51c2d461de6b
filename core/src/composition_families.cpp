#include "geomint/generic/composition_families.hpp"

#include <cmath>

#include "geomint/error.hpp"

namespace geomint::generic {

namespace {

// w, -w * r, w with w = 1/(2 - r), r = 2^(1/3): the "triple jump" (Yoshida 1990; also Forest 1989,
// Creutz–Gocksch 1989, Suzuki 1990). Order 4: 2 w^3 + (-w r)^3 = w^3 (2 - r^3) = 0.
std::vector<long double> triple_jump() {
  const long double r = std::cbrt(2.0L), w = 1 / (2 - r);
  return {w, -w * r, w};
}

// w, w, 1 - 4 w, w, w with w = 1/(4 - 4^(1/3)): Suzuki's fractal (M. Suzuki, Phys. Lett. A 146 (1990) 319–323).
// Order 4: 4 w^3 + (1 - 4w)^3 = 0 since 1 - 4w = -4^(1/3) w. Its weights stay in [-0.66, 0.42]: a smaller error
// constant than the triple jump's (1.35, -1.70) at 5/3 of the cost.
std::vector<long double> suzuki_fractal() {
  const long double w = 1 / (4 - std::cbrt(4.0L));
  return {w, w, 1 - 4 * w, w, w};
}

// Mirror a half (w_1 .. w_k, middle last) into the full symmetric list w_1 .. w_{2k-1}.
std::vector<long double> mirrored(std::vector<long double> half) {
  for (int i = static_cast<int>(half.size()) - 2; i >= 0; --i) half.push_back(half[static_cast<std::size_t>(i)]);
  return half;
}

}  // namespace

const std::vector<CompositionFamily>& composition_families() {
  static const std::vector<CompositionFamily> all = {
      {"yoshida4",
       "Yoshida's triple jump, 3 stages (H. Yoshida, Phys. Lett. A 150 (1990) 262-268); weights from "
       "2^(1/3) in long double",
       4, triple_jump()},
      {"suzuki4",
       "Suzuki's fractal, 5 stages (M. Suzuki, Phys. Lett. A 146 (1990) 319-323); weights from 4^(1/3) in long double",
       4, suzuki_fractal()},
      // Yoshida (1990), Table 1, solution A (printed to 15 digits: w1 = -1.17767998417887, w2 = 0.235573213359357,
      // w3 = 0.784513610477560), here to 26 digits as reprinted in Hairer–Lubich–Wanner, Sect. V.3.2 ("p6 s7");
      // the 15-digit values leave the order-6 conditions unsatisfied at 1e-15 (tests/schemes/composition_families.test.cpp
      // checks these to long double round-off).
      {"yoshida6a",
       "Yoshida's 7-stage solution A (H. Yoshida, Phys. Lett. A 150 (1990) 262-268, Table 1; 26 digits as in "
       "Hairer-Lubich-Wanner, Geometric Numerical Integration, Sect. V.3.2, p6 s7)",
       6,
       mirrored({0.78451361047755726381949763L, 0.23557321335935813368479318L, -1.17767998417887100694641568L,
                 1.31518632068391121888424973L})},
      // Kahan–Li's s17odr8a, the 17-stage eighth-order composition with the smallest error coefficient they
      // found (W. Kahan, R.-C. Li, Math. Comp. 66 (1997) 1089-1099), 26 digits as reprinted in HLW Sect. V.3.2
      // ("p8 s17"). Odeint has no composition of order 8; OrdinaryDiffEq's KahanLi8 uses these weights.
      {"kahanli8",
       "Kahan-Li s17odr8a, 17 stages (W. Kahan, R.-C. Li, Math. Comp. 66 (1997) 1089-1099; 26 digits as in "
       "Hairer-Lubich-Wanner, Geometric Numerical Integration, Sect. V.3.2, p8 s17)",
       8,
       mirrored({0.13020248308889008087881763L, 0.56116298177510838456196441L, -0.38947496264484728640807860L,
                 0.15884190655515560089621075L, -0.39590389413323757733623154L, 0.18453964097831570709183254L,
                 0.25837438768632204729397911L, 0.29501172360931029887096624L, -0.60550853383003451169892108L})},
  };
  return all;
}

const CompositionFamily& find_composition_family(const std::string& name) {
  std::string known;
  for (const auto& f : composition_families()) {
    if (f.name == name) return f;
    known += (known.empty() ? "" : ", ") + f.name;
  }
  throw InputError("unknown composition family '" + name + "' (known: " + known + ")");
}

CompositionName parse_composition_name(const std::string& name) {
  const auto colon = name.find(':');
  require(colon != std::string::npos && colon > 0 && colon + 1 < name.size() && name.find(':', colon + 1) == std::string::npos,
          "a composition is named <family>:<scheme> (e.g. yoshida4:la-trapezoid), got '" + name + "'");
  CompositionName out{name.substr(0, colon), name.substr(colon + 1)};
  find_composition_family(out.family);  // throws naming the known families
  return out;
}

std::string composition_name(const std::string& family, const std::string& base) { return family + ":" + base; }

}  // namespace geomint::generic
