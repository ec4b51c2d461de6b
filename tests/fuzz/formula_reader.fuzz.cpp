// libFuzzer target: bytes as a system file, through the reader, the parser and the model compiler, then the checks
// that run on the defaults (validate_model). Every refusal must be geomint's InputError naming a place; anything
// else (another exception, a crash, a sanitizer report, a hang caught by -timeout) is a finding.
//
// "Names a place" is held as the message names the file and, after it, a line ("fuzz.geomint:12"), except for the
// refusals of the file as a whole, which have no line to name (a section or key missing, the shape, the name): those
// are listed below by their wording, so a new message without a line fails here until it is given one or listed.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

#include "geomint/error.hpp"
#include "geomint/formula/checks.hpp"
#include "geomint/formula/model.hpp"
#include "geomint/text.hpp"

namespace {

constexpr std::string_view source = "fuzz.geomint";

// The refusals of a file as a whole: "fuzz.geomint: <one of these>...".
constexpr std::string_view whole_file[] = {
    "no [system] section", "[system] has no", "[initial] has no", "[dynamics] has no", "coordinates = ",
    "no parameter T", "the system has no name", "system name '", "the force has", "the initial data give",
    "the parts of the formulas", "the definitions of parameters", "the energy E is not finite",
};

bool digit(char c) { return c >= '0' && c <= '9'; }

bool names_a_place(std::string_view m) {
  for (std::size_t at = m.find(source); at != std::string_view::npos; at = m.find(source, at + 1)) {
    const std::size_t after = at + source.size();
    if (after + 1 < m.size() && m[after] == ':' && digit(m[after + 1])) return true;
    if (m.compare(after, 2, ": ") == 0)
      for (std::string_view w : whole_file)
        if (m.compare(after + 2, w.size(), w) == 0) return true;
  }
  return false;
}

[[noreturn]] void finding(const char* what, const std::string& message) {
  std::fprintf(stderr, "formula_reader fuzz: %s: %s\n", what, geomint::one_line(message).c_str());
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace geomint;
  using namespace geomint::formula;
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const auto model = compile_model(parse_system_file(text, std::string(source)));
    // The parameter table at the defaults, as FormulaSystem builds it: numbers, parameters, derived values.
    std::vector<double> pv(model->numbers);
    for (const auto& p : model->parameters) pv.push_back(p.value);
    const int k = model->derived_offset();
    pv.resize(static_cast<std::size_t>(model->table_size()));
    std::vector<const double*> in(static_cast<std::size_t>(k));
    for (int i = 0; i < k; ++i) in[static_cast<std::size_t>(i)] = &pv[static_cast<std::size_t>(i)];
    model->prelude.evaluate(in.data(), pv.data(), pv.data() + k);
    validate_model(*model, pv);
  } catch (const InputError& e) {
    const std::string m = e.what();
    if (m.empty()) finding("a refusal with no message", m);
    // A tab may be quoted from the file (it is whitespace there); the programs and Python escape it with the rest.
    if (first_unprintable(m, "\t") != std::string::npos) finding("a refusal with a control byte or non-UTF-8 in it", m);
    if (!names_a_place(m)) finding("a refusal that names no place", m);
  } catch (const std::exception& e) {
    finding("an exception other than InputError", e.what());
  }
  return 0;
}
