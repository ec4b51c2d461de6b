// A shape the build does not compile, compiled at its first use (formula/jit.hpp): n = 7 coordinates with m = 2
// rows, two damped knife edges of different build and a pendulum side by side. The parts do not interact, so the
// system's runs and modified equations are its parts', each of which has a shape the build compiles: every number
// the run-time shape gives is held to the same number from compiled code, and its formulas to its numbers; then a
// program loads the shape from the cache.
#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "geomint/formula/description.hpp"
#include "geomint/formula/formula_registry.hpp"
#include "geomint/modified/formula_modified.hpp"
#include "geomint/modified/symbolic.hpp"
#include "geomint/registry.hpp"
#include "helpers.hpp"
#include "symbolic_helpers.hpp"

using namespace geomint;

namespace {

// One part: its formulas with its coordinates numbered from offset + 1.
struct Part {
  int n;
  std::string L, rows;
  std::vector<std::string> force, q0, v0;
};

std::string q(int o, int i) { return "q" + std::to_string(o + i); }
std::string v(int o, int i) { return "v" + std::to_string(o + i); }

// A damped knife edge in a harmonic well (docs/systems/knife-edge.geomint) with its own mass, inertia, stiffnesses
// and start.
Part skate(int o, double m, double I, double k, double kappa, double theta0, double u0, double omega0) {
  const auto s = [](double x) { return std::to_string(x); };
  Part p;
  p.n = 3;
  p.L = s(m) + "/2*(" + v(o, 1) + "^2 + " + v(o, 2) + "^2) + " + s(I) + "/2*" + v(o, 3) + "^2 - " + s(k) + "/2*(" +
        q(o, 1) + "^2 + " + q(o, 2) + "^2) - " + s(kappa) + "/2*" + q(o, 3) + "^2";
  p.force = {"-alpha*" + s(m) + "*" + v(o, 1), "-alpha*" + s(m) + "*" + v(o, 2), "-alpha*" + s(I) + "*" + v(o, 3)};
  p.rows = "sin(" + q(o, 3) + ")*" + v(o, 1) + " - cos(" + q(o, 3) + ")*" + v(o, 2);
  p.q0 = {"1", "0.2", s(theta0)};
  p.v0 = {s(u0 * std::cos(theta0)), s(u0 * std::sin(theta0)), s(omega0)};
  return p;
}

Part pendulum(int o) {
  Part p;
  p.n = 1;
  p.L = v(o, 1) + "^2/2 - (1 - cos(" + q(o, 1) + "))";
  p.force = {"-alpha*" + v(o, 1)};
  p.q0 = {"1.1"};
  p.v0 = {"0.3"};
  return p;
}

// The system of the parts side by side, as a system file.
std::string text_of(const std::string& name, const std::vector<Part>& parts) {
  int n = 0;
  std::string L, forces, rows, initial;
  int row = 0;
  for (const auto& p : parts) {
    L += (L.empty() ? "" : " + ") + p.L;
    for (int i = 0; i < p.n; ++i) {
      forces += "F" + std::to_string(n + i + 1) + " = " + p.force[std::size_t(i)] + "\n";
      initial += "q" + std::to_string(n + i + 1) + " = " + p.q0[std::size_t(i)] + "\n";
      initial += "v" + std::to_string(n + i + 1) + " = " + p.v0[std::size_t(i)] + "\n";
    }
    if (!p.rows.empty()) rows += "phi" + std::to_string(++row) + " = " + p.rows + "\n";
    n += p.n;
  }
  return "[system]\nname = " + name + "\ncoordinates = " + std::to_string(n) +
         "\n[parameters]\nalpha = 0.1\nT = 2\n[dynamics]\nL = " + L + "\nherglotz = L - alpha*z\n" + forces +
         (rows.empty() ? "" : "[constraints]\n" + rows) + "[initial]\n" + initial;
}

std::shared_ptr<const formula::FormulaModel> system_of(const std::string& name, const std::vector<Part>& parts) {
  return formula::compile_model(formula::parse_system_file(text_of(name, parts), name));
}

const std::vector<Part> whole_parts = {skate(0, 1, 0.5, 1, 2, 0.8, 0.5, 0), skate(3, 1.5, 0.3, 0.7, 1.2, -0.4, 0.9, 0.6),
                                       pendulum(6)};

}  // namespace

TEST_CASE("a shape the build does not compile (n = 7, m = 2) is compiled at its first use and gives its parts' numbers",
          "[formula][shapes][jit]") {
  // the parts: coordinates 1-3, 4-6 and 7 of the whole
  const auto a = system_of("skate-a", {skate(0, 1, 0.5, 1, 2, 0.8, 0.5, 0)});
  const auto b = system_of("skate-b", {skate(0, 1.5, 0.3, 0.7, 1.2, -0.4, 0.9, 0.6)});
  const auto p = system_of("pendulum-part", {pendulum(0)});
  const auto whole = system_of("two-skates-and-a-pendulum", whole_parts);
  REQUIRE(whole->n == 7);
  REQUIRE(whole->m == 2);
  REQUIRE_FALSE(formula::formula_shape_compiled(7, 2, false));  // else this would test the compiled path
  REQUIRE(formula::formula_shape_compiled(3, 1, false));
  REQUIRE(formula::formula_shape_compiled(1, 0, false));
  struct Piece {
    std::shared_ptr<const formula::FormulaModel> model;
    int offset, row;  // its first coordinate and its row in the whole
  };
  const std::vector<Piece> pieces = {{a, 0, 0}, {b, 3, 1}, {p, 6, -1}};

  const auto entry = formula::formula_system_info(whole);
  // Runs: the same steps, the Newton iterations stopping on the whole residual instead of a part's (round-off).
  for (const char* scheme : {"la", "la-midpoint", "contact", "contact-trapezoid"}) {
    const Run run = entry->run({}, scheme, 0.05, Path::generic, 1);
    REQUIRE(run.steps == 40);
    for (const auto& piece : pieces) {
      const Run part = formula::formula_system_info(piece.model)->run({}, scheme, 0.05, Path::generic, 1);
      REQUIRE(part.t.size() == run.t.size());
      double dq = 0, dl = 0, scale = 0;
      for (std::size_t j = 0; j < run.t.size(); ++j) {
        for (int i = 0; i < part.n; ++i) {
          dq = std::max(dq, std::abs(run.q[j * 7 + std::size_t(piece.offset + i)] - part.q[j * std::size_t(part.n) + std::size_t(i)]));
          scale = std::max(scale, std::abs(part.q[j * std::size_t(part.n) + std::size_t(i)]));
        }
        if (piece.row >= 0) dl = std::max(dl, std::abs(run.lambda[j * 2 + std::size_t(piece.row)] - part.lambda[j]));
      }
      INFO(scheme << ", " << piece.model->name << ": positions differ by " << dq << ", multipliers by " << dl);
      CHECK(scale > 0.1);
      CHECK(dq <= 1e-12);
      CHECK(dl <= 1e-12);
    }
  }

  // Modified equations, numbers: F_0..F_2 of the whole at a point are its parts' at their parts of the point.
  const auto ms = modified::formula_modified_system(whole);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-0.9, 0.9);
  std::vector<double> q0(7), v0(7);
  for (auto& x : q0) x = U(rng);
  for (auto& x : v0) x = U(rng);
  // velocities on the constraints: v2 = tan(q3) v1, v5 = tan(q6) v4
  v0[1] = std::tan(q0[2]) * v0[0];
  v0[4] = std::tan(q0[5]) * v0[3];
  for (const char* scheme : {"la", "contact", "la-midpoint"}) {
    const auto P = ms->at({}, scheme, 2, 0.3, q0, v0, 0.1, false);
    for (const auto& piece : pieces) {
      const auto part = modified::formula_modified_system(piece.model);
      const int n = piece.model->n;
      const std::vector<double> qp(q0.begin() + piece.offset, q0.begin() + piece.offset + n),
          vp(v0.begin() + piece.offset, v0.begin() + piece.offset + n);
      const auto Q = part->at({}, scheme, 2, 0.3, qp, vp, 0.1, false);
      for (int k = 0; k <= 2; ++k)
        for (int i = 0; i < n; ++i) {
          INFO(scheme << ", " << piece.model->name << ": F_" << k << " of coordinate " << i + 1);
          CHECK(P.F_at(k, piece.offset + i) == Approx(Q.F_at(k, i)).epsilon(1e-11).margin(1e-13));
        }
    }
  }

  // Formulas: la's F_0, F_1 read back and evaluated exactly at the point equal the numbers there.
  const modified::ModifiedFormulas f = ms->formulas({}, "la", 1, 60, false);
  REQUIRE(f.K == 1);
  const auto P = ms->at({}, "la", 1, 0.3, q0, v0, 0.1, false);
  GiNaC::symtab table;
  GiNaC::lst point;
  const auto set = [&](const std::string& name, double x) {
    if (!table.count(name)) table[name] = GiNaC::symbol(name);
    point.append(table[name] == modified::exact_rational(x));
  };
  set("t", 0.3);
  set("z", 0.1);
  for (int i = 0; i < 7; ++i) {
    set("q" + std::to_string(i + 1), q0[std::size_t(i)]);
    set("v" + std::to_string(i + 1), v0[std::size_t(i)]);
  }
  for (const auto& [name, x] : f.values) set(name, x);
  int compared = 0;
  for (const auto& r : f.rows) {
    if (r.quantity.size() != 2 || r.quantity[0] != 'F') continue;  // F1..F7
    const int i = r.quantity[1] - '1';
    const double x = number(parse_formula(r.text, f.symbols, table).subs(point));
    INFO(r.quantity << " k " << r.k << ": " << r.text);
    CHECK(x == Approx(P.F_at(r.k, i)).epsilon(1e-10).margin(1e-12));
    ++compared;
  }
  CHECK(compared == 14);

  // A program takes the same shape from the cache this process left (no second compilation), in two runs to the same
  // bits. Here rather than in a test of its own: a test run beside this one would wait on the cache's lock for the
  // whole compilation.
  const auto dir = testing::fresh_dir("jit-program");
  const auto file = dir / "whole.geomint";
  std::ofstream(file) << text_of("two-skates-and-a-pendulum", whole_parts);
  const std::string args = "--system-file " + file.string() + " --scheme contact-trapezoid --h 0.05 --out ";
  std::string bytes;
  for (const char* out : {"a", "b"}) {
    const auto r = testing::run_program("integrate", args + (dir / out).string());
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
    CHECK(r.err.find("compiling") == std::string::npos);  // loaded from the cache: fresh, as this process left it
    const std::string table = testing::read_bytes(dir / out / "two-skates-and-a-pendulum_contact-trapezoid.tsv");
    CHECK(table.size() > 1000);
    if (bytes.empty())
      bytes = table;
    else
      CHECK(table == bytes);
  }
  std::filesystem::remove_all(dir);
}
