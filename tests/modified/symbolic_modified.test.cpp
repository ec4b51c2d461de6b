// The modified equations as formulas (GiNaC coefficients through the same engine and the same residual templates
// as the numbers): checked against the published results term by term — the difference of two formulas must
// simplify to 0 — and against the numeric engine at random points for every registered system and scheme.
// Each published check also runs with one coefficient deliberately wrong, which must fail.
#include <catch2/catch.hpp>

#include <cctype>
#include <cstdlib>
#include <fstream>
#include <map>
#include <random>
#include <regex>

#include "geomint/formula/formula_registry.hpp"
#include "geomint/formula/model.hpp"
#include "geomint/modified/formula_modified.hpp"
#include "geomint/modified/symbolic_system.hpp"
#include "geomint/registry.hpp"
#include "geomint/systems/foucault.hpp"
#include "geomint/systems/knife_edge.hpp"
#include "geomint/systems/oscillator.hpp"
#include "geomint/systems/pendulum.hpp"
#include "helpers.hpp"
#include "symbolic_helpers.hpp"

using namespace geomint;
using namespace geomint::modified;
using GiNaC::ex;

namespace {

// The formulas of scheme G on the symbolic system SysT<ex>, to order K.
template <template <class> class SysT, class G>
struct Formulas {
  FormulaSymbols sy{SysT<double>::dof};
  SymbolicResult r;
  Formulas(int K, double budget = 60) {
    const auto sys = symbolic_system<SysT<ex>>(sy);
    r = symbolic_modified<SysT<ex>, G, 6>(sys, sy, K, SymbolicBudget{budget});
  }
  ex q() const { return sy.q[0]; }
  ex v() const { return sy.v[0]; }
  ex alpha() { return sy.param("alpha"); }
  ex F(int k) const { return r.F[static_cast<std::size_t>(k)][0]; }
};

// a == b as formulas: their difference simplifies to 0.
bool same(const ex& a, const ex& b) { return simplify_coefficient(a - b).is_zero(); }

}  // namespace

TEST_CASE("formulas: Störmer–Verlet on the pendulum is HLW's q'' = -sin q - h^2/12 (q'^2 sin q + sin q cos q), F1 = F3 = 0", "[symbolic]") {
  Formulas<systems::PendulumT, generic::LaTrapezoid> f(4);
  REQUIRE(f.r.K == 4);
  const ex q = f.q(), v = f.v(), a0 = f.alpha() == 0;
  CHECK(same(f.F(0), -sin(q) - f.alpha() * v));
  CHECK(f.F(1).is_zero());
  CHECK(f.F(3).is_zero());
  const ex hlw = -(v * v * sin(q) + sin(q) * cos(q)) / 12;
  CHECK(same(f.F(2).subs(a0), hlw));
  CHECK_FALSE(same(f.F(2).subs(a0), -(v * v * sin(q) + sin(q) * cos(q)) / 11));  // a wrong coefficient fails
  CHECK_FALSE(same(f.F(2).subs(a0), -(v * v * sin(q) - sin(q) * cos(q)) / 12));  // a wrong sign fails
}

TEST_CASE("formulas: Vermeeren's modified Lagrangians, midpoint L + h^2/24 (U'^2 + U'' q'^2), Störmer–Verlet L + h^2/24 (U'^2 - 2 U'' q'^2)", "[symbolic]") {
  // the pendulum, U = 1 - cos q, alpha = 0: the meshed Lagrangian of the scheme's own discrete action
  Formulas<systems::PendulumT, generic::LaMidpoint> mid(3);
  Formulas<systems::PendulumT, generic::LaTrapezoid> sv(3);
  for (auto* f : {&mid.r, &sv.r}) REQUIRE(f->has_lagrangian);
  const ex q = mid.q(), v = mid.v(), a0 = mid.alpha() == 0;
  const ex U1 = sin(q), U2 = cos(q), L = v * v / 2 - (1 - cos(q));
  CHECK(same(mid.r.L[0].subs(a0), L));
  CHECK(mid.r.L[1].subs(a0).is_zero());
  CHECK(same(mid.r.L[2].subs(a0), (U1 * U1 + U2 * v * v) / 24));
  CHECK(mid.r.L[3].subs(a0).is_zero());
  const ex q2 = sv.q(), v2 = sv.v(), b0 = sv.alpha() == 0;
  CHECK(same(sv.r.L[2].subs(b0), (pow(sin(q2), 2) - 2 * cos(q2) * v2 * v2) / 24));
  CHECK_FALSE(same(sv.r.L[2].subs(b0), (pow(sin(q2), 2) + cos(q2) * v2 * v2) / 24));  // the two must differ
  // a conservative variational scheme needs no modified force: the Euler–Lagrange equations of its modified
  // Lagrangian are its modified equation (to the order computed)
  for (int k = 0; k <= 3; ++k) {
    CHECK(mid.r.Fmod[static_cast<std::size_t>(k)][0].subs(a0).is_zero());
    CHECK(sv.r.Fmod[static_cast<std::size_t>(k)][0].subs(b0).is_zero());
  }
}

TEST_CASE("formulas: the paper's (8) for LA on the oscillator, as the harness derives it", "[symbolic]") {
  Formulas<systems::OscillatorT, generic::LaLeft> f(3);
  const ex q = f.q(), v = f.v(), al = f.alpha();
  // modified equation to O(h): q'' = -q - alpha q' + h alpha/2 (q + alpha q')  (= -alpha/2 q''_0: the force of (8))
  CHECK(same(f.F(0), -q - al * v));
  CHECK(same(f.F(1), al / 2 * (q + al * v)));
  CHECK_FALSE(same(f.F(1), -al / 2 * (q + al * v)));  // (8) with the sign of its h-term flipped
  // (8)'s Lagrangian L + h/2 q' q'': its h-term is d/dt(h q'^2/4); the harness's meshed Lagrangian has
  // L_1 = q q'/2 = d/dt(q^2/4): both are total derivatives, so both give no equation of motion at O(h)
  CHECK(same(f.r.L[0], v * v / 2 - q * q / 2));
  CHECK(same(f.r.L[1], q * v / 2));
  // (8)'s force -alpha q' - h alpha/2 q'': with q'' -> -q - alpha q' (its leading order), the harness's F_mod
  CHECK(same(f.r.Fmod[0][0], -al * v));
  CHECK(same(f.r.Fmod[1][0], -al / 2 * (-q - al * v)));
}

TEST_CASE("formulas: the paper's (11) for contact on the oscillator: L_mod = (1 + h alpha/2) L", "[symbolic]") {
  Formulas<systems::OscillatorT, generic::ContactLeft> f(3);
  const ex q = f.q(), v = f.v(), al = f.alpha(), z = f.sy.z;
  const ex L = v * v / 2 - q * q / 2 - al * z;
  CHECK(same(f.r.Z[0], L));
  CHECK(same(f.r.Z[1], al / 2 * L));
  CHECK_FALSE(same(f.r.Z[1], -al / 2 * L));
  CHECK(same(f.F(1), -al * al * v / 2));
}

TEST_CASE("formulas: the oscillator's exact all-orders damping, a_k = (-+1)^k alpha^(k+1)/(k+1) to h^6", "[symbolic]") {
  // det of the one-step map: 1/(1 + h alpha) (la), 1 - h alpha (contact); the modified damping is -ln(det)/h
  for (bool la : {true, false}) {
    auto check = [&](auto& f) {
      REQUIRE(f.r.K == 6);
      const ex al = f.alpha();
      for (int k = 0; k <= 6; ++k) {
        const ex ak = (la && k % 2 ? -1 : 1) * pow(al, k + 1) / (k + 1);
        INFO((la ? "la" : "contact") << " k " << k);
        CHECK(same(-f.F(k).expand().coeff(f.v(), 1), ak));
        CHECK_FALSE(same(-f.F(k).expand().coeff(f.v(), 1), ak * (k + 2) / (k + 1)));
      }
    };
    if (la) {
      Formulas<systems::OscillatorT, generic::LaLeft> f(6);
      check(f);
    } else {
      Formulas<systems::OscillatorT, generic::ContactLeft> f(6);
      check(f);
    }
  }
}

TEST_CASE("formulas: a run over its time budget stops and says at which order", "[symbolic]") {
  Formulas<systems::PendulumT, generic::ContactLeft> f(6, 0.0);
  CHECK(f.r.stopped);
  CHECK(f.r.K == 0);  // order 0 is always built: the budget is checked before each higher order
  CHECK(same(f.F(0), -sin(f.q()) - f.alpha() * f.v()));
}

TEST_CASE("formulas equal the numbers at random points, every registered system and scheme", "[symbolic][registry]") {
  // One engine, two coefficient types: the formulas (printed, read back, evaluated at a random point and the
  // system's default parameters) against the numeric engine there, every quantity and order. The order is what
  // each system reaches quickly (a few seconds at most here; bench_symbolic measures the rest).
  std::mt19937 rng(20);
  std::uniform_real_distribution<double> U(-0.9, 0.9);
  int systems_checked = 0;
  for (const auto& sys : all_systems()) {
    const auto me = modified_system(sys);
    const ModifiedSystem& ms = *me;
    const int K = ms.constraints > 0 ? 2 : (ms.dof > 1 ? 3 : 4);
    for (const auto& scheme : ms.schemes) {
      ModifiedFormulas f;
      try {
        f = ms.formulas({}, scheme, K, 30, false);
      } catch (const InputError& e) {
        WARN(ms.name << ": " << e.what());
        continue;
      }
      INFO(ms.name << " " << scheme << " K " << K);
      REQUIRE(f.K == K);
      GiNaC::symtab table;
      GiNaC::lst point;
      std::vector<double> q, v;
      const double t = U(rng), z = U(rng);
      for (int i = 0; i < ms.dof; ++i) {
        q.push_back(U(rng));
        v.push_back(U(rng));
      }
      auto set = [&](const std::string& name, double x) {
        if (!table.count(name)) table[name] = GiNaC::symbol(name);
        point.append(table[name] == exact_rational(x));
      };
      set("t", t);
      set("z", z);
      for (int i = 0; i < ms.dof; ++i) {
        const std::string s = std::to_string(i + 1);
        set("q" + s, q[static_cast<std::size_t>(i)]);
        set("v" + s, v[static_cast<std::size_t>(i)]);
      }
      for (const auto& [name, x] : f.values) set(name, x);
      const ModifiedPoint P = ms.at({}, scheme, K, t, q, v, z, false);
      int compared = 0;
      for (const auto& row : f.rows) {
        const double x = number(parse_formula(row.text, f.symbols, table).subs(point));
        const auto kk = static_cast<std::size_t>(row.k);
        double ref = 0, scale = 1;
        const std::string& Q = row.quantity;
        const int idx = (Q.size() > 1 && std::isdigit(static_cast<unsigned char>(Q.back()))) ? Q.back() - '1' : 0;
        if (Q.rfind("Fmod", 0) == 0) {
          continue;  // no numeric counterpart (a symbolic derivative of the meshed Lagrangian)
        } else if (Q[0] == 'F') {
          ref = P.F_at(row.k, idx);
          scale = std::abs(P.F_at(0, idx)) + 1;
        } else if (Q == "Z") {
          ref = P.Z[kk];
          scale = std::abs(P.Z[0]) + 1;
        } else if (Q == "L") {
          ref = P.lagrangian[kk];
          scale = std::abs(P.lagrangian[0]) + 1;
        } else if (Q.rfind("mu", 0) == 0) {
          ref = P.mu[kk * static_cast<std::size_t>(P.m) + static_cast<std::size_t>(idx)];
          scale = std::abs(P.mu[static_cast<std::size_t>(idx)]) + 1;
        } else if (Q.rfind("phi", 0) == 0) {
          ref = P.phi[kk * static_cast<std::size_t>(P.m) + static_cast<std::size_t>(idx)];
          scale = 1;
        } else {
          FAIL("unknown quantity " << Q);
        }
        INFO(Q << " k " << row.k << ": " << row.text);
        CHECK(x == Approx(ref).epsilon(1e-10).margin(1e-12 * scale));
        ++compared;
      }
      CHECK(compared >= K + 1);
    }
    ++systems_checked;
  }
  CHECK(systems_checked >= 1);
}

TEST_CASE("a chain of six pendula (n = 6): its formulas F_0, F_1 equal the numbers, F_0 its equations written by hand",
          "[symbolic][shapes]") {
  // The first shape beyond n = 4 (docs/systems/pendulum-chain.geomint): the modified equation of each first-order
  // scheme as formulas, read back and evaluated at random points in exact arithmetic, against the numeric engine
  // there; order 0 against q_i'' = -g sin q_i - k (2 q_i - q_(i-1) - q_(i+1)) - alpha q_i'. la-midpoint is
  // symmetric: its F_1 vanishes identically.
  const auto model = formula::load_system_file(std::string(GEOMINT_SOURCE_DIR) + "/docs/systems/pendulum-chain.geomint");
  const auto ms = formula_modified_system(model);
  const double g = model->parameters[std::size_t(model->parameter_index("g"))].value,
               k = model->parameters[std::size_t(model->parameter_index("k"))].value,
               alpha = model->parameters[std::size_t(model->parameter_index("alpha"))].value;
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> U(-0.9, 0.9);
  for (const char* scheme : {"la", "contact", "la-midpoint"}) {
    const ModifiedFormulas f = ms->formulas({}, scheme, 1, 60, false);
    REQUIRE(f.K == 1);
    for (int trial = 0; trial < 2; ++trial) {
      GiNaC::symtab table;
      GiNaC::lst point;
      std::vector<double> q, v;
      const double t = U(rng), z = U(rng);
      auto set = [&](const std::string& name, double x) {
        if (!table.count(name)) table[name] = GiNaC::symbol(name);
        point.append(table[name] == exact_rational(x));
      };
      set("t", t);
      set("z", z);
      for (int i = 0; i < 6; ++i) {
        q.push_back(U(rng));
        v.push_back(U(rng));
        set("q" + std::to_string(i + 1), q.back());
        set("v" + std::to_string(i + 1), v.back());
      }
      for (const auto& [name, x] : f.values) set(name, x);
      const ModifiedPoint P = ms->at({}, scheme, 1, t, q, v, z, false);
      int compared = 0;
      double F1 = 0;
      for (const auto& row : f.rows) {
        if (row.quantity.size() != 2 || row.quantity[0] != 'F') continue;  // F1..F6
        const int i = row.quantity[1] - '1';
        const double x = number(parse_formula(row.text, f.symbols, table).subs(point));
        INFO(scheme << " " << row.quantity << " k " << row.k << ": " << row.text);
        CHECK(x == Approx(P.F_at(row.k, i)).epsilon(1e-10).margin(1e-12 * (std::abs(P.F_at(0, i)) + 1)));
        if (row.k == 0) {
          const auto qi = [&](int j) { return q[std::size_t(j)]; };
          const double spring = (i > 0 ? qi(i) - qi(i - 1) : 0.0) + (i < 5 ? qi(i) - qi(i + 1) : 0.0);
          CHECK(x == Approx(-g * std::sin(qi(i)) - k * spring - alpha * v[std::size_t(i)]).epsilon(1e-12).margin(1e-14));
        } else {
          F1 = std::max(F1, std::abs(x));
        }
        ++compared;
      }
      CHECK(compared == 12);  // F_0 and F_1 of each coordinate (a row that vanishes is printed as 0)
      if (std::string(scheme) == "la-midpoint")
        CHECK(F1 == 0);
      else
        CHECK(F1 > 1e-6);  // a first-order scheme's F_1 is there to compare (contact's is O(alpha): about 8e-4)
    }
  }
}

namespace {

// A system of any shape (n coordinates, m rows of either kind) for the shape tests: n pendula coupled by springs,
// damped (Rayleigh -alpha v, and the Herglotz form L - alpha z: with a unit mass matrix both give the same continuous
// equations), with rows nonlinear in q, of full rank (row c is 1 on coordinate c and -sin(q_(c+1)) or -sin(q_(c+1))/2
// on the next), which the initial data q = v = 0 satisfy.
std::shared_ptr<const formula::FormulaModel> shape_model(int n, int m, bool holonomic) {
  formula::SystemDescription d;
  d.name = "shape-" + std::to_string(n) + "-" + std::to_string(m) + (holonomic ? "-holonomic" : "");
  d.coordinates = n;
  const auto qi = [](int i) { return "q" + std::to_string(i); };
  const auto vi = [](int i) { return "v" + std::to_string(i); };
  std::string L;
  for (int i = 1; i <= n; ++i) {
    L += " + " + vi(i) + "^2/2 - (1 - cos(" + qi(i) + "))";
    if (i < n) L += " - k/2*(" + qi(i) + " - " + qi(i + 1) + ")^2";
  }
  d.lagrangian = formula::formula_text(L.substr(3), "L");
  d.herglotz = formula::formula_text(L.substr(3) + " - alpha*z", "herglotz");
  for (int i = 1; i <= n; ++i) d.force.push_back(formula::formula_text("-alpha*" + vi(i), "F" + std::to_string(i)));
  d.constraint_kind = holonomic ? formula::ConstraintKind::holonomic : formula::ConstraintKind::velocity;
  for (int c = 1; c <= m; ++c)
    d.constraints.push_back(formula::formula_text(
        holonomic ? qi(c) + " - sin(" + qi(c + 1) + ")/2" : vi(c) + " - sin(" + qi(c + 1) + ")*" + vi(c + 1), "row"));
  d.parameters.push_back({"k", formula::formula_text("0.7", "parameter k"), "spring"});
  d.parameters.push_back({"alpha", formula::formula_text("0.2", "parameter alpha"), "damping"});
  d.parameters.push_back({"T", formula::formula_text("1", "parameter T"), "horizon"});
  for (int i = 0; i < n; ++i) {
    d.initial_q.push_back(formula::formula_text("0", "q"));
    d.initial_v.push_back(formula::formula_text("0", "v"));
  }
  return formula::compile_model(d);
}

}  // namespace

TEST_CASE("every compiled shape with modified equations: F_0 is the entry's equations, the self-check vanishes, the "
          "formulas of F_0 and F_1 equal the numbers", "[symbolic][shapes]") {
  // Every shape of shapes.def this build compiles, through its registry entry and modified_system(entry) as the
  // programs reach them. At two random points: the numeric F_0 of la and contact equals the entry's continuous
  // acceleration (Odeint's right-hand side, from the same model by other code), the self-check residual is at
  // round-off, and la's formulas to K = 1, read back and evaluated in exact arithmetic, equal the numbers.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-0.5, 0.5);
  std::string with, without;
  // the compiled ones: a shape without them would otherwise be compiled now (formula/jit.hpp; a minute each)
  const testing::ScopedEnv off("GEOMINT_SHAPE_JIT", "0");
  for (int n = 1; n <= 12; ++n)
    for (int m = 0; m < n && m <= 6; ++m)
      for (bool holonomic : {false, true}) {
        if ((m == 0 && holonomic) || !formula::formula_shape_compiled(n, m, holonomic)) continue;
        const std::string shape = "(" + std::to_string(n) + ", " + std::to_string(m) + (holonomic ? ", holonomic)" : ")");
        const auto entry = formula::formula_system_info(shape_model(n, m, holonomic));
        std::shared_ptr<const ModifiedSystem> ms;
        try {
          ms = modified_system(*entry);
        } catch (const InputError& e) {
          CHECK_THAT(e.what(), Catch::Contains("shapes.def"));
          without += " " + shape;
          continue;
        }
        with += " " + shape;
        const auto ode = entry->ode({});
        for (int trial = 0; trial < 2; ++trial) {
          const double t = U(rng), z = U(rng);
          std::vector<double> q, v;
          for (int i = 0; i < n; ++i) {
            q.push_back(U(rng));
            v.push_back(U(rng));
          }
          std::vector<double> x(q), dx(std::size_t(2 * n));
          x.insert(x.end(), v.begin(), v.end());
          ode(t, x.data(), dx.data());
          double amax = 0;
          for (int i = 0; i < n; ++i) amax = std::max(amax, std::abs(dx[std::size_t(n + i)]));
          for (const char* scheme : {"la", "contact"}) {
            const ModifiedPoint P = ms->at({}, scheme, 2, t, q, v, z, true);
            double F = 0;
            for (double f : P.F) F = std::max(F, std::abs(f));
            INFO(shape << " " << scheme << ": self-check " << P.residual << " against |F| " << F);
            CHECK(P.residual <= 1e-12 * F);
            for (int i = 0; i < n; ++i) CHECK(std::abs(P.F_at(0, i) - dx[std::size_t(n + i)]) <= 1e-12 * (1 + amax));
          }
          const ModifiedFormulas f = ms->formulas({}, "la", 1, 60, false);
          REQUIRE(f.K == 1);
          GiNaC::symtab table;
          GiNaC::lst point;
          auto set = [&](const std::string& name, double value) {
            if (!table.count(name)) table[name] = GiNaC::symbol(name);
            point.append(table[name] == exact_rational(value));
          };
          set("t", t);
          set("z", z);
          for (int i = 0; i < n; ++i) {
            set("q" + std::to_string(i + 1), q[std::size_t(i)]);
            set("v" + std::to_string(i + 1), v[std::size_t(i)]);
          }
          for (const auto& [name, value] : f.values) set(name, value);
          const ModifiedPoint P = ms->at({}, "la", 1, t, q, v, z, false);
          int compared = 0;
          double F1 = 0;
          for (const auto& row : f.rows) {
            const std::string& Q = row.quantity;
            if (Q[0] != 'F' || Q.rfind("Fmod", 0) == 0) continue;
            const int i = Q.size() == 1 ? 0 : std::stoi(Q.substr(1)) - 1;  // "F" for one coordinate, else F1 .. Fn
            const double value = number(parse_formula(row.text, f.symbols, table).subs(point));
            INFO(shape << " la " << Q << " k " << row.k << ": " << row.text);
            CHECK(value == Approx(P.F_at(row.k, i)).epsilon(1e-10).margin(1e-12 * (std::abs(P.F_at(0, i)) + 1)));
            if (row.k == 1) F1 = std::max(F1, std::abs(value));
            ++compared;
          }
          INFO(shape);
          CHECK(compared == 2 * n);  // F_0 and F_1 of each coordinate
          CHECK(F1 > 1e-3);          // la is first order: its F_1 is there to compare
        }
      }
  WARN("shapes with modified equations:" << with << "; without:" << (without.empty() ? " none" : without));
  CHECK(!with.empty());
}

TEST_CASE("formulas: a quotient is shown in one form whatever form GiNaC hands it over in", "[symbolic]") {
  // GiNaC's term order changes from run to run (its hashes are seeded with addresses), and normal() can return the
  // same quotient with its denominator as a power in one run and expanded in another (the Foucault surrogate's
  // certification did, in one run of eight). display_form fixes the form from the value: the same text here for a
  // denominator given as a power, expanded, or with both signs flipped.
  const GiNaC::symbol q1("q1"), q2("q2"), l("l"), a("a");
  const ex r2 = GiNaC::pow(q1, 2) + GiNaC::pow(q2, 2);
  const ex top = a * q1 * q2 - l;
  const std::string power = formula_text(display_form(top / (24 * GiNaC::pow(r2, 3) * GiNaC::pow(l, 2))));
  const std::string expanded = formula_text(display_form(top / (24 * GiNaC::pow(r2, 3) * GiNaC::pow(l, 2)).expand()));
  const std::string flipped = formula_text(display_form((-top) / (-(q1 - q2) * GiNaC::pow(r2, 3)).expand()));
  const std::string plain = formula_text(display_form(top / ((q1 - q2) * GiNaC::pow(r2, 3))));
  CHECK(power == "(a*q1*q2 - l)/(24*(q1^2 + q2^2)^3*l^2)");
  CHECK(expanded == power);
  CHECK(flipped == plain);
  INFO(plain);
  CHECK(plain.find("(q1^2 + q2^2)^3") != std::string::npos);  // factored, not expanded to a polynomial of degree 7
  CHECK(plain.find("q1^7") == std::string::npos);
}

TEST_CASE("formulas: sympy reads the text as the numbers", "[symbolic][sympy]") {
  // The pendulum's contact formulas as modified_equation --formulas prints them, read by sympy (sympify, the
  // symbols declared) and evaluated at a point, against the numeric engine there: the printed syntax means in
  // sympy what the engine computed.
  const char* python = "/usr/bin/python3";
  if (std::system((std::string(python) + " -c 'import sympy' 2> /dev/null").c_str()) != 0) {
    FAIL("python3-sympy is not installed (make deps installs it)");
  }
  const auto& ms = find_modified_system("pendulum");
  const auto f = ms.formulas({}, "contact", 3, 30, false);
  const double q = 0.6, v = -0.35, z = 0.25;
  const auto dir = geomint::testing::fresh_dir("sympy");
  {
    std::ofstream out(dir / "formulas.txt");
    for (const auto& r : f.rows) out << r.text << "\n";
  }
  {
    std::ofstream py(dir / "check.py");
    py.precision(17);
    py << "import sympy\n"
          "names = '" << join_names(f.symbols) << "'.split()\n"
          "syms = {n: sympy.Symbol(n) for n in names}\n"
          "point = {syms['q1']: " << q << ", syms['v1']: " << v << ", syms['z']: " << z;
    for (const auto& [name, x] : f.values) py << ", syms['" << name << "']: " << x;
    py << "}\n"
          "for line in open('" << (dir / "formulas.txt").string() << "'):\n"
          "    e = sympy.sympify(line.strip(), locals=syms)\n"
          "    print(sympy.N(e.subs(point), 20))\n";
  }
  const std::string cmd = std::string(python) + " " + (dir / "check.py").string() + " > " + (dir / "values.txt").string();
  REQUIRE(std::system(cmd.c_str()) == 0);
  const ModifiedPoint P = ms.at({}, "contact", 3, 0.0, {q}, {v}, z, false);
  std::ifstream in(dir / "values.txt");
  std::size_t read = 0;
  for (const auto& r : f.rows) {
    std::string value;
    REQUIRE(std::getline(in, value));
    const double x = std::stod(value);
    const auto k = static_cast<std::size_t>(r.k);
    INFO(r.quantity << " k " << r.k << ": " << r.text << " -> " << value);
    if (r.quantity == "F") CHECK(x == Approx(P.F_at(r.k, 0)).epsilon(1e-12).margin(1e-14));
    if (r.quantity == "Z") CHECK(x == Approx(P.Z[k]).epsilon(1e-12).margin(1e-14));
    ++read;
  }
  CHECK(read == f.rows.size());
  CHECK(read == 8);  // F and Z, k = 0..3
  std::filesystem::remove_all(dir);
}

TEST_CASE("modified_equation --formulas: text and LaTeX next to an unchanged table", "[symbolic][programs]") {
  const auto dir = geomint::testing::fresh_dir("formulas");
  const auto plain = dir / "plain", with = dir / "with";
  REQUIRE(geomint::testing::run_program("modified_equation", "--schemes la contact --order 3 --out " + plain.string()).exit_code == 0);
  const auto r = geomint::testing::run_program("modified_equation", "--schemes la contact --order 3 --formulas --out " + with.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  using geomint::testing::read_bytes;
  // the numeric table is the same file with or without the formulas
  CHECK(read_bytes(plain / "modified_equation.tsv") == read_bytes(with / "modified_equation.tsv"));
  const std::string txt = read_bytes(with / "modified_equation_formulas.txt"), tex = read_bytes(with / "modified_equation_formulas.tex");
  CHECK(txt.rfind("# program: modified_equation\n# git: ", 0) == 0);
  CHECK(tex.rfind("% program: modified_equation\n% git: ", 0) == 0);
  CHECK(txt.find("# symbols: h z q1 v1 alpha\n") != std::string::npos);
  // LA's F_1 on the pendulum is (8)'s force -h alpha/2 q''_0 = alpha/2 (alpha q' + sin q): the text row, read
  // back, is that formula
  std::istringstream lines(txt);
  std::string line;
  bool found = false;
  while (std::getline(lines, line)) {
    std::vector<std::string> cells;
    std::istringstream row(line);
    for (std::string c; std::getline(row, c, '\t');) cells.push_back(c);
    if (cells.size() != 6 || cells[0] != "pendulum" || cells[1] != "la" || cells[2] != "F" || cells[3] != "1") continue;
    GiNaC::symtab table;
    const ex e = parse_formula(cells[4], {"q1", "v1", "alpha"}, table);
    const ex q = table["q1"], v = table["v1"], al = table["alpha"];
    CHECK(same(e, al / 2 * (al * v + sin(q))));
    found = true;
  }
  CHECK(found);
  CHECK(tex.find("\\begin{align*}") != std::string::npos);
  // LA's F_1 above, in LaTeX: the rational as a fraction of the product, in the names' LaTeX (alpha, q-dot)
  CHECK(tex.find("h\\left(\\frac{\\alpha \\left(\\alpha \\dot{q}_{1} + \\sin\\left(q_{1}\\right)\\right)}{2}\\right)") !=
        std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST_CASE("modified_equation --formulas rejects a bad budget", "[symbolic][programs]") {
  geomint::testing::check_rejected("modified_equation", "--formulas --budget 0", "--budget");
  geomint::testing::check_rejected("modified_equation", "--formulas --budget nan", "--budget");
}

TEST_CASE("modified_equation --formulas --on-constraint: the knife edge in its body velocities, the map back in rows v<i>",
          "[symbolic][programs][nonholonomic]") {
  const auto dir = geomint::testing::fresh_dir("formulas_on_constraint");
  const auto r = geomint::testing::run_program(
      "modified_equation", "--system knife-edge --schemes la --order 1 --q 0 0 0.3 --v 1 0 0.5 --formulas --on-constraint --out " +
                               dir.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const std::string txt = geomint::testing::read_bytes(dir / "knife-edge_modified_equation_formulas.txt");
  CHECK(txt.find("on the constraint: an orthogonal basis of the constraint's kernel, quasi-velocities u1..u1") != std::string::npos);
  CHECK(txt.find("# symbols: h q1 q2 q3 v3 u1 ") != std::string::npos);
  // the map back: q'1 = cos(q3) u1; the formulas use u1 and v3 and no longer v1, v2
  std::istringstream lines(txt);
  std::string line;
  bool map_found = false;
  int rows = 0;
  while (std::getline(lines, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> cells;
    std::istringstream row(line);
    for (std::string c; std::getline(row, c, '\t');) cells.push_back(c);
    if (cells.size() != 6 || cells[0] != "knife-edge") continue;
    ++rows;
    CHECK(cells[4].find("v1") == std::string::npos);
    CHECK(cells[4].find("v2") == std::string::npos);
    if (cells[2] == "v1" && cells[3] == "0") {
      GiNaC::symtab table;
      const ex e = parse_formula(cells[4], {"q3", "u1"}, table);
      CHECK(same(e, cos(table["q3"]) * table["u1"]));
      map_found = true;
    }
  }
  CHECK(map_found);
  CHECK(rows > 10);
  std::filesystem::remove_all(dir);
  geomint::testing::check_rejected("modified_equation", "--system knife-edge --on-constraint", "--formulas");
  geomint::testing::check_rejected("modified_equation", "--system pendulum --formulas --on-constraint",
                                   "no nonholonomic constraint");
}

TEST_CASE("formulas: the knife edge's modified equation, multiplier and constraint (la, contact) to K = 2", "[symbolic][nonholonomic]") {
  for (bool contact : {false, true}) {
    auto check = [&](auto& f) {
      REQUIRE(f.r.K == 2);
      const auto& sy = f.sy;
      const ex x = sy.q[0], y = sy.q[1], th = sy.q[2], xd = sy.v[0], yd = sy.v[1], thd = sy.v[2];
      const ex m = f.sy.param("m"), I = f.sy.param("I"), k = f.sy.param("k"), kappa = f.sy.param("kappa"), al = f.alpha();
      INFO((contact ? "contact" : "la"));
      // phi_0 is the constraint A q' itself; phi_1 its first correction, the same for both principles
      CHECK(same(f.r.phi[0][0], sin(th) * xd - cos(th) * yd));
      CHECK(same(f.r.phi[1][0], -thd * (xd * cos(th) + yd * sin(th)) / 2));
      CHECK_FALSE(same(f.r.phi[1][0], thd * (xd * cos(th) + yd * sin(th)) / 2));
      // mu_0: the continuous multiplier of the hand-written equations of knife_edge.hpp (the engine's sign: the
      // residual carries -A^T lambda)
      const ex u = xd * cos(th) + yd * sin(th);
      const ex lambda = k * (x * sin(th) - y * cos(th)) - m * thd * u + al * m * (xd * sin(th) - yd * cos(th));
      CHECK(same(f.r.mu[0][0], -lambda));
      // the heading is a damped linear oscillator decoupled from the rest (w^2 = kappa/I): its modified equation
      // is the oscillator's — la: F_1 = alpha/2 (w^2 th + alpha th'), F_2 = -w^4 th/12 - alpha^2 w^2 th/3 - alpha^3 th'/3;
      // contact: F_1 = -alpha^2 th'/2, F_2 = -w^4 th/12 - alpha^2 w^2 th/12 - alpha^3 th'/3
      const ex w2 = kappa / I;
      CHECK(same(f.r.F[0][2], -w2 * th - al * thd));
      if (!contact) {
        CHECK(same(f.r.F[1][2], al / 2 * (w2 * th + al * thd)));
        CHECK(same(f.r.F[2][2], -w2 * w2 * th / 12 - al * al * w2 * th / 3 - pow(al, 3) * thd / 3));
      } else {
        CHECK(same(f.r.F[1][2], -al * al * thd / 2));
        CHECK(same(f.r.F[2][2], -w2 * w2 * th / 12 - al * al * w2 * th / 12 - pow(al, 3) * thd / 3));
      }
      CHECK_FALSE(same(f.r.F[2][2], -w2 * w2 * th / 12 - al * al * w2 * th / 6 - pow(al, 3) * thd / 3));
    };
    if (contact) {
      Formulas<systems::KnifeEdgeT, generic::ContactLeft> f(2);
      check(f);
    } else {
      Formulas<systems::KnifeEdgeT, generic::LaLeft> f(2);
      check(f);
    }
  }
}

TEST_CASE("formulas: the Foucault constraint (13) near the origin, |F_1| = s V^2/r and |F_3| = s V^4/(6 r^3)", "[symbolic][nonholonomic]") {
  // At q = (r, 0) with the consistent velocity (V, -s r) the series of F_k in r: the leading terms docs/formulas.md
  // measured numerically (powers -1 and -3), transverse to the motion; h F_1 turns the velocity by s h (hV/r)
  // per step, the measured plane jump Omega sin(beta) h/rho.
  Formulas<systems::FoucaultT, generic::LaLeft> f(3);
  Formulas<systems::FoucaultT, generic::ContactLeft> c(1);
  REQUIRE(f.r.K == 3);
  const GiNaC::symbol r("r"), V("V"), s("s");
  // the coefficient of r^power at the point, in the symbols r, V, s (each run has symbols of its own)
  auto leading_of = [&](auto& run, const ex& e, int power) {
    const GiNaC::lst at{run.sy.q[0] == r, run.sy.q[1] == 0, run.sy.v[0] == V, run.sy.v[1] == -s * r, run.sy.param("s") == s};
    return GiNaC::series_to_poly(simplify_coefficient(e.subs(at)).series(r == 0, power + 1)).coeff(r, power);
  };
  auto leading = [&](const ex& e, int power) { return leading_of(f, e, power); };
  CHECK(same(leading(f.r.F[1][1], -1), s * V * V));
  CHECK(same(leading(f.r.F[3][1], -3), -s * pow(V, 4) / 6));
  CHECK_FALSE(same(leading(f.r.F[3][1], -3), -s * pow(V, 4) / 3));
  // the motion's own component stays bounded: no 1/r in F_1 along x
  CHECK(leading(f.r.F[1][0], -1).is_zero());
  // contact: the same leading F_1 (the two principles share the constraint's discretization)
  CHECK(same(leading_of(c, c.r.F[1][1], -1), s * V * V));
}

TEST_CASE("formulas on the constraint equal the formulas in q' there, exactly: the sleigh, the knife edge, Foucault (13)",
          "[symbolic][nonholonomic]") {
  // The same engine run twice: at a point (q, q') with q' free, and at q' = S(q) u + w on the constraint
  // (constraint_chart). On the constraint the two must agree exactly: every row of the first at the chart's
  // velocities equals the row of the second, at random rational points (q, u, t, z; the parameters at their
  // values as exact rationals), the difference simplified to 0 — sin and cos of a rational stay exact atoms.
  const auto sleigh = formula_modified_system(
      formula::load_system_file(std::string(GEOMINT_SOURCE_DIR) + "/docs/systems/chaplygin-sleigh.geomint"));
  struct Case {
    const ModifiedSystem* ms;
    std::string scheme;
    int K;
    std::string chart;  // how the chart was chosen
  };
  const std::string basis = "an orthogonal basis of the constraint's kernel, quasi-velocities ";
  const std::vector<Case> cases{{sleigh.get(), "la", 2, basis + "u1..u2"},
                                {sleigh.get(), "contact", 2, basis + "u1..u2"},
                                {&find_modified_system("knife-edge"), "la", 2, basis + "u1..u1"},
                                {&find_modified_system("knife-edge"), "contact", 2, basis + "u1..u1"},
                                {&find_modified_system("foucault"), "contact", 2, basis + "u1..u1, the offset by least squares"},
                                {&find_modified_system("foucault"), "la", 2, basis + "u1..u1, the offset by least squares"}};
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> num(-9, 9);
  const auto rational = [&] { return ex(GiNaC::numeric(num(rng), 10)); };
  for (const auto& c : cases) {
    INFO(c.ms->name << " " << c.scheme << " K " << c.K);
    const ModifiedFormulas free = c.ms->formulas({}, c.scheme, c.K, 120, false);
    const ModifiedFormulas on = c.ms->formulas({}, c.scheme, c.K, 120, true);
    REQUIRE(free.K == c.K);
    REQUIRE(on.K == c.K);
    CHECK(free.chart.empty());
    CHECK(on.chart == c.chart);
    GiNaC::symtab table;
    std::vector<std::string> names = free.symbols;
    names.insert(names.end(), on.symbols.begin(), on.symbols.end());
    for (const auto& s : names)
      if (!table.count(s)) table[s] = GiNaC::symbol(s);
    // the point: every symbol of the reduced formulas (q, the quasi-velocities, t, z), the parameters' values
    GiNaC::exmap point;
    for (const auto& s : on.symbols) point[table[s]] = rational();
    for (const auto& [name, x] : on.values) point[table[name]] = exact_rational(x);
    for (const auto& [name, x] : free.values) point[table[name]] = exact_rational(x);
    // q' there: the map back where the chart gives one, else the velocity is its own quasi-velocity
    GiNaC::exmap velocities;
    for (int i = 0; i < c.ms->dof; ++i) {
      const std::string v = "v" + std::to_string(i + 1);
      ex at = point.count(table[v]) ? point[table[v]] : ex(0);
      for (const auto& row : on.rows)
        if (row.quantity == v) at = parse_formula(row.text, on.symbols, table).subs(point);
      velocities[table[v]] = at;
    }
    GiNaC::exmap full = point;
    for (const auto& [k, x] : velocities) full[k] = x;
    int compared = 0;
    for (const auto& row : free.rows) {
      const FormulaRow* twin = nullptr;
      for (const auto& r : on.rows)
        if (r.quantity == row.quantity && r.k == row.k) twin = &r;
      REQUIRE(twin != nullptr);
      INFO(row.quantity << " k " << row.k << ": " << row.text << "  |  " << twin->text);
      const ex a = parse_formula(row.text, free.symbols, table).subs(full);
      const ex b = parse_formula(twin->text, on.symbols, table).subs(point);
      CHECK(same(a, b));
      ++compared;
    }
    CHECK(compared >= 2 * (c.K + 1));
    // on the constraint it holds by construction: the modified constraint's h^0 term is 0 as a formula
    for (const auto& r : on.rows)
      if (r.quantity == "phi" && r.k == 0) CHECK(r.text == "0");
    // and what is printed is smaller
    CHECK(on.size < free.size);
  }
}

TEST_CASE("constraint charts: the sleigh and the knife edge in body velocities, Foucault (13) in polar ones",
          "[symbolic][nonholonomic]") {
  const auto sleigh = formula_modified_system(
      formula::load_system_file(std::string(GEOMINT_SOURCE_DIR) + "/docs/systems/chaplygin-sleigh.geomint"));
  auto map = [](const ModifiedFormulas& f, GiNaC::symtab& table) {
    std::map<std::string, ex> v;
    for (const auto& r : f.rows)
      if (r.quantity.size() > 1 && r.quantity[0] == 'v' && std::isdigit(static_cast<unsigned char>(r.quantity[1])))
        v[r.quantity] = parse_formula(r.text, f.symbols, table);
    return v;
  };
  {
    GiNaC::symtab t;
    const auto f = sleigh->formulas({}, "la", 0, 60, true);
    const auto v = map(f, t);
    // -sin(q3) v1 + cos(q3) v2 - a v3 = 0: q' = u1 (cos q3, sin q3, 0) + u2 (-a sin q3, a cos q3, 1), the speed along
    // the heading and the turning rate
    REQUIRE(v.size() == 3);
    const ex q3 = t["q3"], u1 = t["u1"], u2 = t["u2"], a = t["a"];
    CHECK(same(v.at("v1"), cos(q3) * u1 - a * sin(q3) * u2));
    CHECK(same(v.at("v2"), sin(q3) * u1 + a * cos(q3) * u2));
    CHECK(same(v.at("v3"), u2));
  }
  {
    GiNaC::symtab t;
    const auto f = find_modified_system("knife-edge").formulas({}, "la", 0, 60, true);
    const auto v = map(f, t);
    // sin(q3) v1 = cos(q3) v2: q' = u1 (cos q3, sin q3, 0) + v3 e3, the blade's speed and turning rate
    REQUIRE(v.size() == 2);
    const ex q3 = t["q3"], u1 = t["u1"];
    CHECK(same(v.at("v1"), cos(q3) * u1));
    CHECK(same(v.at("v2"), sin(q3) * u1));
    CHECK_FALSE(same(v.at("v2"), cos(q3) * u1));
  }
  {
    GiNaC::symtab t;
    const auto f = find_modified_system("foucault").formulas({}, "contact", 0, 60, true);
    const auto v = map(f, t);
    // -q2 v1 + q1 v2 + s (q1^2 + q2^2) = 0: q' = u1 (q1, q2) + s (q2, -q1), radial motion and the imposed turning
    REQUIRE(v.size() == 2);
    const ex q1 = t["q1"], q2 = t["q2"], u1 = t["u1"], s = t["s"];
    CHECK(same(v.at("v1"), u1 * q1 + s * q2));
    CHECK(same(v.at("v2"), u1 * q2 - s * q1));
  }
}
