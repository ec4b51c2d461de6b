#pragma once
// Formulas as the programs write them, read back for the tests that hold them to the numbers (GiNaC).
#include <catch2/catch.hpp>

#include <regex>
#include <string>
#include <vector>

#include <ginac/ginac.h>

// A formula's text (as modified_equation --formulas writes it) read back by GiNaC's parser.
inline GiNaC::ex parse_formula(const std::string& text, const std::vector<std::string>& symbols, GiNaC::symtab& table) {
  std::string read = text;
  for (const auto& s : symbols) {
    if (!table.count(s)) table[s] = GiNaC::symbol(s);
    // GiNaC's reader takes these names as its constants whatever the table says (I: the imaginary unit): a
    // parameter of that name (the knife edge's I) is read under another name bound to the same symbol
    if (s == "I" || s == "Pi" || s == "Euler" || s == "Catalan") {
      const std::string alias = s + "_param";
      read = std::regex_replace(read, std::regex("\\b" + s + "\\b"), alias);
      table[alias] = table[s];
    }
  }
  GiNaC::parser reader(table, true);  // strict: an unknown name is an error, not a new symbol
  return reader(read);
}

inline double number(const GiNaC::ex& e) {
  const GiNaC::ex x = e.evalf();
  REQUIRE(GiNaC::is_a<GiNaC::numeric>(x));
  return GiNaC::ex_to<GiNaC::numeric>(x).to_double();
}

