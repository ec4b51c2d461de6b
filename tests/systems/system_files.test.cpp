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
#include "geomint/study.hpp"
#include "geomint/sweep.hpp"
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

// ---------------------------------------------------------------------------------------------------------------
// The start (t0, z0) and the exact solution of a system file

namespace {

const std::string lane_emden_file = std::string(GEOMINT_SOURCE_DIR) + "/docs/systems/lane-emden.geomint";

// A forced, damped oscillator, q'' + 0.1 q' + q = cos(3 t), as a file whose forcing reads `forcing` and that starts
// at `t0`.
std::string forced(const std::string& forcing, const std::string& t0) {
  return "[system]\nname = f\ncoordinates = 1\n[parameters]\nT = 6\n[dynamics]\nL = v1^2/2 - q1^2/2\n"
         "herglotz = L - 0.1*z + q1*" + forcing + "\nF1 = -0.1*v1 + " + forcing + "\n[initial]\nt0 = " + t0 +
         "\nq1 = 0.5\nv1 = -0.2\n";
}

// Lane-Emden of index 1 with the exact solution `exact` written in its [exact] section (on the last line).
std::string lane_emden_with(const std::string& exact) {
  return "[system]\nname = le\ncoordinates = 1\n[parameters]\nT = 10\n[dynamics]\nL = v1^2/2 - q1^2/2\n"
         "F1 = -2*v1/t\n[initial]\nt0 = 1\nq1 = sin(1)\nv1 = cos(1) - sin(1)\n[exact]\nq1 = " + exact + "\n";
}

}  // namespace

TEST_CASE("Lane-Emden from t0 = 1 converges at each scheme's order against its exact solution", "[system-files][start]") {
  const auto info = formula::formula_system_info(formula::load_system_file(lane_emden_file));
  REQUIRE(info->has_exact);
  CHECK(info->initial_time({}) == 1);
  // The exact reference is sin(t)/t on t_j = t0 + j h: its first row is the initial data.
  const Reference ref = info->reference({}, 0.5, 4, ReferenceKind::exact, 1e-13);
  CHECK(ref.kind == "closed form");
  CHECK(ref.q[0] == std::sin(1.0));
  CHECK(ref.q[4] == std::sin(3.0) / 3.0);
  // A run's clock starts at t0.
  const Run run = info->run({}, "la-midpoint", 0.5, Path::generic, 1);
  CHECK(run.t.front() == 1);
  CHECK(run.t.back() == 11);
  const auto hs = halving_sequence(0.1, 0.1 / 32);
  const std::vector<std::pair<std::string, double>> expected = {
      {"la", 1}, {"contact", 1}, {"la-midpoint", 2}, {"contact-trapezoid", 2}};
  std::vector<std::string> schemes;
  for (const auto& [s, order] : expected) schemes.push_back(s);
  const auto study = convergence_study(*info, {{}}, schemes, hs, Path::generic, ReferenceKind::exact, 1e-13, Sweep::world());
  CHECK(study.reference == "closed form");
  REQUIRE(study.series.size() == expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const auto& s = study.series[i];
    INFO(s.scheme << ": " << s.asymptotic.describe());
    REQUIRE(s.asymptotic.asymptotic());
    CHECK(std::abs(s.asymptotic.slope - expected[i].second) < 0.1);
  }
}

TEST_CASE("the convergence program takes --reference exact from a system file", "[system-files][start][programs]") {
  const auto dir = fresh_dir("lane-emden-convergence");
  const auto r = run_program("convergence", "--system-file " + lane_emden_file +
                                                " --reference exact --schemes la-midpoint --h-max 0.1 --h-min 0.02 --out " +
                                                dir.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  std::string tsv;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().extension() == ".tsv") tsv += read_bytes(e.path());
  CHECK(tsv.find("closed form") != std::string::npos);
  CHECK(tsv.find("# t0: 1") != std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST_CASE("a wrong exact solution is refused at its line, with the residual and the bound", "[system-files][start]") {
  auto refusal = [](const std::string& text) {
    const auto m = model_of(text);
    return error_of([&] { formula::validate_model(*m, defaults(*m)); });
  };
  const int line = line_of(lane_emden_with("x"), "q1 = x");
  // the true solution passes: its residual is round-off
  CHECK(refusal(lane_emden_with("sin(t)/t")).empty());
  // right at t0 (value and slope), wrong after: q'' off by 2e-6, two hundred times the bound
  const std::string off = refusal(lane_emden_with("sin(t)/t + 1e-6*(t - 1)^2"));
  CHECK_THAT(off, Catch::StartsWith("test.geomint:" + std::to_string(line) + ": the exact solution does not solve the equations"));
  CHECK_THAT(off, Catch::Contains("1e-8 of the largest"));
  // the solution of another start
  CHECK_THAT(refusal(lane_emden_with("cos(t)/t")),
             Catch::StartsWith("test.geomint:" + std::to_string(line) + ": the exact solution does not start at the initial data"));
  // a formula of the state is not a solution
  CHECK_THAT(error_of([&] { model_of(lane_emden_with("q1*t")); }), Catch::Contains("depends on the state"));
  // and the system's entry carries the refusal to every run
  const auto info = formula::formula_system_info(model_of(lane_emden_with("sin(t)/t + 1e-6*(t - 1)^2")));
  CHECK_THAT(error_of([&] { info->validate({}); }), Catch::Contains("does not solve the equations"));
}

TEST_CASE("t0 shifts a time-dependent forcing: the run from t0 = 2 is the run of the shifted forcing from 0",
          "[system-files][start]") {
  const auto late = formula::formula_system_info(model_of(forced("cos(3*t)", "2")));
  const auto shifted = formula::formula_system_info(model_of(forced("cos(3*(t + 2))", "0")));
  const auto early = formula::formula_system_info(model_of(forced("cos(3*t)", "0")));
  for (const std::string scheme : {"la", "la-midpoint", "contact-trapezoid", "yoshida4:la-midpoint"}) {
    INFO(scheme);
    const Run a = late->run({}, scheme, 0.01, Path::generic, 1), b = shifted->run({}, scheme, 0.01, Path::generic, 1),
              c = early->run({}, scheme, 0.01, Path::generic, 1);
    REQUIRE(a.q.size() == b.q.size());
    CHECK(a.t.front() == 2);
    double same = 0, other = 0;
    for (std::size_t j = 0; j < a.q.size(); ++j) {
      same = std::max(same, std::abs(a.q[j] - b.q[j]));
      other = std::max(other, std::abs(a.q[j] - c.q[j]));
    }
    // the two clocks differ by the rounding of 2 + j h against j h (a few ulps of t in the forcing's phase)
    CHECK(same < 1e-12);
    CHECK(other > 0.05);  // measured 0.13: the forcing's phase matters, and a run that ignored t0 would be this one
  }
  // the Odeint reference starts at t0 too
  const Reference ra = late->reference({}, 0.01, 600, ReferenceKind::odeint, 1e-12),
                  rb = shifted->reference({}, 0.01, 600, ReferenceKind::odeint, 1e-12);
  double diff = 0;
  for (std::size_t j = 0; j < ra.q.size(); ++j) diff = std::max(diff, std::abs(ra.q[j] - rb.q[j]));
  CHECK(diff < 1e-9);
}

TEST_CASE("z0 changes the action by z0 exp(-alpha (t - t0)) on the Herglotz oscillator", "[system-files][start]") {
  // herglotz = L - alpha z: q does not see z, and two actions differ by d' = -alpha d, d(t0) = z0.
  auto file = [](const std::string& z0) {
    return "[system]\nname = h\ncoordinates = 1\n[parameters]\nalpha = 0.3\nT = 5\n[dynamics]\nL = v1^2/2 - q1^2/2\n"
           "herglotz = L - alpha*z\nF1 = -alpha*v1\n[initial]\nt0 = 0.5\nz0 = " + z0 + "\nq1 = 1\nv1 = 0\n";
  };
  const auto with = formula::formula_system_info(model_of(file("1.5"))), without = formula::formula_system_info(model_of(file("0")));
  for (const auto& [scheme, order] : std::vector<std::pair<std::string, double>>{{"contact", 1}, {"contact-trapezoid", 2}}) {
    std::vector<double> hs, errs;
    for (double h : {0.02, 0.01, 0.005}) {
      const Run a = with->run({}, scheme, h, Path::generic, 1), b = without->run({}, scheme, h, Path::generic, 1);
      CHECK(a.z.front() == 1.5);
      CHECK(a.q == b.q);  // bit for bit: the positions do not depend on the action here
      double err = 0;
      for (std::size_t j = 0; j < a.z.size(); ++j)
        err = std::max(err, std::abs((a.z[j] - b.z[j]) - 1.5 * std::exp(-0.3 * (a.t[j] - 0.5))));
      hs.push_back(h);
      errs.push_back(err);
    }
    INFO(scheme << ": errors " << errs[0] << " " << errs[1] << " " << errs[2]);
    // the scheme's order in the action's difference (a closed form of the discrete z would differ from the flow's by
    // exactly this error)
    CHECK(std::abs(std::log2(errs[0] / errs[1]) - order) < 0.1);
    CHECK(std::abs(std::log2(errs[1] / errs[2]) - order) < 0.1);
  }
}
