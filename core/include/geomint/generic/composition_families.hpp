#pragma once
// Coefficient families of symmetric compositions of a symmetric one-step map Phi of order 2:
//   Psi_h = Phi_{w_s h} o ... o Phi_{w_2 h} o Phi_{w_1 h},   w_i = w_{s+1-i},  sum w_i = 1,
// which has order p when the w satisfy the order conditions of symmetric compositions of symmetric methods
// (Hairer–Lubich–Wanner, Geometric Numerical Integration, 2nd ed., Sect. V.3.2): sum w_i^3 = 0 for p = 4, and
// sum w_i^5 = 0 with one condition on nested sums for p = 6, and so on. A family is data (a name, an order and its
// weights), not a type: every family runs through the same Composition<Sys, Scheme> (composition.hpp), so adding
// one costs no template instantiation. As in Odeint's symplectic_rkn_sb3a_mclachlan.hpp, a method is its
// coefficients over one family base.
//
// Names on command lines: a composition is "<family>:<base scheme>", e.g. yoshida6a:contact-trapezoid (no shell
// metacharacter; neither a family nor a scheme name contains ':').
#include <string>
#include <vector>

namespace geomint::generic {

struct CompositionFamily {
  std::string name;         // "yoshida4"
  std::string description;  // what it is, with the source of its coefficients
  int order = 0;            // the order of the composition of a symmetric second-order map
  std::vector<long double> weights;  // w_1 .. w_s (all of them, symmetric), to long double precision
  int stages() const { return static_cast<int>(weights.size()); }
};

// Every family, in order of increasing order: yoshida4, suzuki4, yoshida6a, kahanli8.
const std::vector<CompositionFamily>& composition_families();

// The family named `name`; InputError naming the known ones otherwise.
const CompositionFamily& find_composition_family(const std::string& name);

// "<family>:<base>" split at its colon (both parts non-empty, the family known); InputError otherwise. The base
// scheme is not checked here: which schemes exist depends on the system.
struct CompositionName {
  std::string family, base;
};
CompositionName parse_composition_name(const std::string& name);
// Whether `name` is meant as a composition (it has a colon; parse_composition_name checks the rest).
inline bool is_composition_name(const std::string& name) { return name.find(':') != std::string::npos; }
std::string composition_name(const std::string& family, const std::string& base);

}  // namespace geomint::generic
