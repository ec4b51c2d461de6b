// System files come from other people: what they hold must not reach a terminal raw, take a program's option, make a
// refusal say nothing or blame the wrong cause, or leak between systems loaded in one process.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "geomint/error.hpp"
#include "geomint/formula/checks.hpp"
#include "geomint/formula/formula_registry.hpp"
#include "geomint/formula/model.hpp"
#include "geomint/formula/option_names.hpp"
#include "geomint/io.hpp"
#include "geomint/system_cli.hpp"
#include "geomint/text.hpp"
#include "helpers.hpp"

using namespace geomint;
using namespace geomint::testing;

namespace {

std::shared_ptr<const formula::FormulaModel> model_of(const std::string& text) {
  return formula::compile_model(formula::parse_system_file(text, "test.geomint"));
}

// One coordinate, T = `T` on line 5, `params` from line 6, `defs` under [definitions], L and `more` in [dynamics],
// q1 = `q0`, v1 = 0.
std::string one_dof(const std::string& L, const std::string& params = "", const std::string& defs = "",
                    const std::string& q0 = "1", const std::string& T = "10", const std::string& more = "") {
  return "[system]\nname = t\ncoordinates = 1\n[parameters]\nT = " + T + "\n" + params + "[definitions]\n" + defs +
         "[dynamics]\nL = " + L + "\n" + more + "[initial]\nq1 = " + q0 + "\nv1 = 0\n";
}

// The parameter table at the model's defaults (numbers, parameters, derived values), as FormulaSystem builds it.
std::vector<double> defaults(const formula::FormulaModel& m) {
  std::vector<double> pv(m.numbers);
  for (const auto& p : m.parameters) pv.push_back(p.value);
  const int k = m.derived_offset();
  pv.resize(static_cast<std::size_t>(m.table_size()));
  std::vector<const double*> in(static_cast<std::size_t>(k));
  for (int i = 0; i < k; ++i) in[static_cast<std::size_t>(i)] = &pv[static_cast<std::size_t>(i)];
  m.prelude.evaluate(in.data(), pv.data(), pv.data() + k);
  return pv;
}

int line_of(const std::string& text, const std::string& key) {
  int line = 1;
  for (std::size_t at = 0; at < text.size(); ++at) {
    if (text.compare(at, key.size(), key) == 0 && (at == 0 || text[at - 1] == '\n')) return line;
    if (text[at] == '\n') ++line;
  }
  return 0;
}

}  // namespace

TEST_CASE("one_line escapes every control byte and every byte that is not UTF-8", "[system-files]") {
  using namespace std::string_literals;
  CHECK(one_line("a\nb\rc\td"s) == "a\\nb\\rc\\td");
  // ESC ] 0 ; ... BEL retitles a terminal; a NUL would cut a C string; DEL; a C1 control (CSI, U+009B)
  CHECK(one_line("x\x1b]0;pwned\x07y\0z\x7f"s) == "x\\x1b]0;pwned\\x07y\\x00z\\x7f");
  CHECK(one_line("\xc2\x9b"s) == "\\xc2\\x9b");
  // Latin-1 degree sign alone is not UTF-8; the UTF-8 one stays; a truncated sequence and an overlong '/'
  CHECK(one_line("30\xb0"s) == "30\\xb0");
  CHECK(one_line("30\xc2\xb0"s) == "30\xc2\xb0");
  CHECK(one_line("\xe2\x82"s) == "\\xe2\\x82");
  CHECK(one_line("\xc0\xaf"s) == "\\xc0\\xaf");
  CHECK(first_unprintable("plain \xc2\xb0 text"s) == std::string::npos);
  CHECK(first_unprintable("ab\tc"s) == 2);
  CHECK(first_unprintable("ab\tc"s, "\t") == std::string::npos);
  CHECK(first_unprintable("ab\xff"s) == 2);
  CHECK(first_unprintable("a\0b"s) == 1);
}

TEST_CASE("a system file with control bytes or bytes that are not UTF-8 is refused at its line and column", "[system-files]") {
  const std::string base = one_dof("v1^2/2 - q1^2/2");
  const int L = line_of(base, "L = ");
  REQUIRE(L == 8);
  auto with_L = [&](const std::string& tail) {
    std::string s = base;
    s.replace(s.find("L = v1^2/2 - q1^2/2"), 19, "L = v1^2/2 - q1^2/2" + tail);
    return s;
  };
  // the byte after "L = v1^2/2 - q1^2/2 # 30" is column 25
  CHECK(error_of([&] { model_of(with_L(" # 30\xb0")); }) == "test.geomint:8:25: byte 0xb0 is not UTF-8 text: save the file as UTF-8");
  CHECK(error_of([&] { model_of(with_L(" # \x1b]0;x\x07")); }) ==
        "test.geomint:8:23: control character (byte 0x1b): a system file is plain text");
  CHECK(error_of([&] { model_of(with_L(std::string(" #\0", 3))); }) ==
        "test.geomint:8:22: control character (byte 0x00): a system file is plain text");
  CHECK(error_of([&] { model_of(with_L("\r- q1")); }) ==
        "test.geomint:8:20: control character (byte 0x0d, a carriage return inside the line): a system file is plain text");
  // what is allowed: \r\n line ends, a UTF-8 comment, a tab, a byte order mark
  std::string crlf = with_L(" # 30\xc2\xb0\tdegrees");
  for (std::size_t i = crlf.find('\n'); i != std::string::npos; i = crlf.find('\n', i + 2)) crlf.insert(i, "\r");
  CHECK(model_of("\xef\xbb\xbf" + crlf)->linear_dynamics);
}

TEST_CASE("a formula given in memory (the Python module) is held to the same text", "[system-files]") {
  formula::SystemDescription d = formula::parse_system_file(one_dof("v1^2/2"), "test.geomint");
  d.lagrangian = formula::formula_text(std::string("v1^2/2\0 - q1", 12), "L");
  CHECK(error_of([&] { formula::compile_model(d); }) ==
        "L, column 7: L has a control character or a byte that is not UTF-8 (byte 0x00)");
  d.lagrangian = formula::formula_text("v1^2/2", "L");
  d.description = "a \x1b[2J description";
  CHECK(error_of([&] { formula::compile_model(d); }) ==
        "test.geomint: the description has a control character or a byte that is not UTF-8 (byte 0x1b) at byte 3");
}

TEST_CASE("a parameter named like a program option is refused at its line", "[system-files]") {
  CHECK(error_of([] { model_of(one_dof("v1^2/2", "alpha = 1\nh = 0.5\n")); }) ==
        "test.geomint:7: parameter 'h' has the name of a program option (--h): as an option of its own it would take "
        "that option's place; rename it");
  // every name in the list that a parameter could have (a name with '-' is not one)
  int checked = 0;
  for (std::string_view o : formula::program_option_names) {
    if (o.find('-') != std::string_view::npos || o == "t" || o == "z") continue;  // t and z: the variables
    const std::string name(o);
    INFO(name);
    CHECK(error_of([&] { model_of(one_dof("v1^2/2", name + " = 1\n")); })
              .find("test.geomint:6: parameter '" + name + "' has the name of a program option") != std::string::npos);
    ++checked;
  }
  CHECK(checked >= 25);
  // T stays the horizon, and a name that only resembles an option is a parameter
  CHECK(model_of(one_dof("v1^2/2", "hh = 1\nschemes2 = 1\n"))->parameter_index("schemes2") >= 0);
}

TEST_CASE("an empty path after --system-file is refused, not read as the default system", "[system-files]") {
  auto args = [](std::vector<std::string> words) {
    static std::vector<std::string> keep;
    keep = std::move(words);
    static std::vector<char*> argv;
    argv.clear();
    for (auto& w : keep) argv.push_back(w.data());
    return argv.data();
  };
  const std::string message = "--system-file is given an empty path (an unset shell variable?)";
  CHECK(error_of([&] { find_system_file_arg(3, args({"p", "--system-file", ""})); }).find(message) == 0);
  CHECK(error_of([&] { find_system_file_arg(2, args({"p", "--system-file="})); }).find(message) == 0);
  CHECK(find_system_file_arg(3, args({"p", "--system", "pendulum"})).empty());
  CHECK(find_system_file_arg(3, args({"p", "--system-file", "x.geomint"})) == "x.geomint");
  CHECK(error_of([] { formula::read_system_file(""); }) == "the system file's path is empty");
}

TEST_CASE("every program that takes a system file refuses an empty path with exit 2", "[system-files][programs]") {
  for (const char* p : {"integrate", "ensemble", "convergence", "regularized_error", "work_precision", "stability",
                        "long_horizon", "modified_equation", "surrogate"}) {
    // the build without the formulas (the sanitizer build) has no surrogate program
    if (std::string(p) == "surrogate" && !GEOMINT_SYMBOLIC) continue;
    check_rejected(p, "--system-file ''", "--system-file is given an empty path");
  }
}

TEST_CASE("a TSV header holds a path with a newline on one line", "[system-files]") {
  const auto dir = fresh_dir("tsv-header");
  {
    TsvWriter w(dir / "t.tsv", "test", {{"system_file", "a\nb\x1b.geomint"}}, {"x"});
    w.row(1.0);
    w.commit();
  }
  const std::string text = read_bytes(dir / "t.tsv");
  CHECK(text.find("# system_file: a\\nb\\x1b.geomint\n") != std::string::npos);
  CHECK(std::count(text.begin(), text.end(), '\n') == 5);  // program, git, system_file, the columns, one row
  std::filesystem::remove_all(dir);
}

TEST_CASE("formulas too deep are refused at the line that makes them so", "[system-files]") {
  SECTION("a flat sum of 4500 terms") {
    std::string sum = "q1";
    for (int k = 1; k < 4500; ++k) sum += "+q1";  // within the 20000 characters of a formula
    CHECK(error_of([&] { model_of(one_dof("v1^2/2 - (" + sum + ")")); }) ==
          "test.geomint:8: L: more than 4000 operations deep (counting those of the definitions it uses, and of the "
          "derivatives taken of it)");
  }
  SECTION("3996 definitions nested through one another: the derivatives the compiler takes pass the limit") {
    std::string defs = "d1 = sin(q1)\n";
    for (int k = 2; k <= 3996; ++k) defs += "d" + std::to_string(k) + " = sin(d" + std::to_string(k - 1) + ")\n";
    const std::string text = one_dof("v1^2/2 - d3996", "", defs);
    const std::string where = "test.geomint:" + std::to_string(line_of(text, "L = ")) + ": L: more than 4000 operations deep";
    CHECK(error_of([&] { model_of(text); }).find(where) == 0);
  }
}

TEST_CASE("T = 0 and a value that is not finite at the initial data are named with their place", "[system-files]") {
  CHECK(error_of([] { model_of(one_dof("v1^2/2", "", "", "1", "0")); }) ==
        "test.geomint:5: parameter T = 0: the horizon must be positive");
  {
    const auto m = model_of(one_dof("v1^2/2"));
    auto pv = defaults(*m);
    pv[static_cast<std::size_t>(m->parameter_offset() + m->parameter_index("T"))] = 0;
    CHECK(error_of([&] { formula::validate_model(*m, pv); }) ==
          "system 't' (test.geomint:5): T must be a positive finite number, got 0");
  }
  // sqrt(q1) at q1 = -1: L itself is nan there (it was blamed on a singular velocity Hessian)
  {
    const auto m = model_of(one_dof("v1^2/2 - sqrt(q1)", "", "", "-1"));
    const std::string msg = error_of([&] { formula::validate_model(*m, defaults(*m)); });
    CHECK(msg.find("test.geomint:8: L is not finite at the initial data (q0 = (-1), v0 = (0)): L = ") == 0);
    CHECK(msg.find("nan") != std::string::npos);
    CHECK(msg.find("singular") == std::string::npos);
  }
  // at q1 = 0 the value is finite and its derivative is not
  {
    const auto m = model_of(one_dof("v1^2/2 - sqrt(q1)", "", "", "0"));
    CHECK(error_of([&] { formula::validate_model(*m, defaults(*m)); }) ==
          "test.geomint:8: the derivatives of L are not finite at the initial data (q0 = (0), v0 = (0)) (a square root "
          "or logarithm at 0, a division by 0?)");
  }
  {
    const auto m = model_of(one_dof("v1^2/2", "", "", "0", "10", "E = log(q1)\n"));
    CHECK(error_of([&] { formula::validate_model(*m, defaults(*m)); }) ==
          "test.geomint: the energy E is not finite at the initial data (q0 = (0), v0 = (0)): E = -inf");
  }
}

TEST_CASE("a formula system's expectations are its own, whatever was loaded before it", "[system-files]") {
  // Both of one shape (n = 1, m = 0): its operations are built once, from whichever model came first.
  const auto long_one = formula::formula_system_info(model_of(one_dof("v1^2/2 - q1^2/2", "", "", "1", "500")));
  const auto short_one = formula::formula_system_info(model_of(one_dof("v1^2/2 - q1^2/2", "", "", "1", "5")));
  const auto long_again = formula::formula_system_info(model_of(one_dof("v1^2/2 - q1^2/2", "", "", "1", "500")));
  CHECK(short_one->expectations.params.empty());  // T = 5 runs as it is
  for (const auto& info : {long_one, long_again}) {
    REQUIRE(info->expectations.params.size() == 1);
    CHECK(info->expectations.params[0].first == "T");
    CHECK(info->expectations.params[0].second == 20);
  }
}
