// Formulas: what the parser accepts and refuses, and what the tapes compute in every scalar type of the core,
// against the same expressions written in C++ (bit for bit where the formula associates as the C++ does).
#include <catch2/catch.hpp>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>
#include <random>
#include <string>
#include <utility>

#include "geomint/error.hpp"
#include "geomint/formula/formula_system.hpp"
#include "geomint/formula/parser.hpp"
#include "geomint/modified/series.hpp"
#include "helpers.hpp"

using namespace geomint;
using formula::FormulaSystem;
using testing::error_of;

// Allocation counting for the "no allocation per evaluation" test: the global operator new of the test binary
// counts the allocations of this thread while `counting` is set and otherwise only forwards to malloc, as the
// default one does (the default operator delete, free, stays its match). Not under AddressSanitizer, which
// replaces operator new and delete in all their forms itself: there the test says it cannot count.
namespace {
thread_local bool counting = false;
thread_local long allocations = 0;
#if defined(__SANITIZE_ADDRESS__)
constexpr bool can_count = false;
#else
constexpr bool can_count = true;
#endif
}  // namespace
#if !defined(__SANITIZE_ADDRESS__)
void* operator new(std::size_t n) {
  if (counting) ++allocations;
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
#endif

namespace {

// A model from the text of a system file.
std::shared_ptr<const formula::FormulaModel> model_of(const std::string& text, const formula::CompileOptions& o = {}) {
  return formula::compile_model(formula::parse_system_file(text, "test.geomint"), o);
}

// A system of n coordinates whose Lagrangian is `L` (plus what `extra` adds to [dynamics]), with parameters a, b.
std::string system_text(int n, const std::string& L, const std::string& more = "", const std::string& defs = "") {
  std::string s = "[system]\nname = t\ncoordinates = " + std::to_string(n) +
                  "\n[parameters]\na = 0.7 # the first\nb = -1.3\nT = 1\n";
  if (!defs.empty()) s += "[definitions]\n" + defs + "\n";
  s += "[dynamics]\nL = " + L + "\n" + more + "[initial]\n";
  for (int i = 1; i <= n; ++i) s += "q" + std::to_string(i) + " = 0.1\nv" + std::to_string(i) + " = 1\n";
  return s;
}

}  // namespace

// The InputError `f` throws contains `expected`, on one line (the message shown when not).
template <class F>
void check_error(F&& f, const std::string& expected) {
  const std::string msg = error_of(f);
  INFO("expected: " << expected << "\n     got: " << msg);
  CHECK(msg.find(expected) != std::string::npos);
  CHECK(msg.find('\n') == std::string::npos);
}

TEST_CASE("formulas evaluate with the bits of the same C++ in double, long double, duals and series", "[formula][parse]") {
  // every operation of the grammar, written as C++ would associate it; a = 0.7 and b = -1.3 are parameters
  const std::string L =
      "a*v1*v1/2 - b*q1*q1/3 + sin(q1)*cos(v2) - tan(q2/4) + exp(-q1*q1)*log(2 + q2*q2) + sqrt(1 + v1*v1)"
      " + q1^3 - 2^q2 + (1 + q1*q1)^0.5 + q2^(-2) + v2^q1/(3 + v1*v1) + (1 + q2*q2)^a - t*v1 + 1/(2 + cos(q1))";
  const auto model = model_of(system_text(2, L));
  const FormulaSystem<2, 0> fs(model);
  const double a = 0.7, b = -1.3;
  // the same expression in C++ over any scalar of the core
  auto cxx = [&](const auto& t, const auto& q, const auto& v) {
    using S = std::decay_t<decltype(t)>;
    using std::cos;
    using std::exp;
    using std::log;
    using std::pow;
    using std::sin;
    using std::sqrt;
    auto pw = [](const S& x, const S& y) { return exp(y * log(x)); };  // x^y of two variables, as the tape
    // x^c for a constant c: Dual's pow nests over built-in scalars only; exp(c log x) is the same function
    auto pc = [](const S& x, double c) {
      if constexpr (std::is_floating_point_v<S>)
        return S(pow(x, c));
      else
        return S(exp(c * log(x)));
    };
    const S tanq = sin(q(1) / 4) / cos(q(1) / 4);
    return a * v(0) * v(0) / 2 - b * q(0) * q(0) / 3 + sin(q(0)) * cos(v(1)) - tanq + exp(-q(0) * q(0)) * log(2 + q(1) * q(1)) +
           sqrt(1 + v(0) * v(0)) + q(0) * q(0) * q(0) - exp(q(1) * log(2.0)) + pc(1 + q(0) * q(0), 0.5) +
           S(1) / (q(1) * q(1)) + pw(v(1), q(0)) / (3 + v(0) * v(0)) + pc(1 + q(1) * q(1), a) - t * v(0) + 1 / (2 + cos(q(0)));
  };
  std::mt19937 gen(1);
  std::uniform_real_distribution<double> u(0.2, 1.5);
  for (int k = 0; k < 20; ++k) {
    const double t = u(gen);
    const Vec<double, 2> q(u(gen), u(gen)), v(u(gen), u(gen));
    SECTION("double") {
      // tan differs from sin/cos in the last bits: compare with the double's own tan written the same way
      const double f = fs.lagrangian(t, q, v);
      const double c = cxx(t, q, v) + std::sin(q(1) / 4) / std::cos(q(1) / 4) - std::tan(q(1) / 4);
      CHECK(std::abs(f - c) <= 1e-14 * (1 + std::abs(c)));
    }
    SECTION("Dual<double, 3> and Dual<Dual<double, 2>, 3>: value and every derivative") {
      using D = Dual<double, 3>;
      const Vec<D, 2> Q(D::variable(q(0), 0), D::variable(q(1), 1)), V(D::variable(v(0), 2), D(v(1)));
      const D f = fs.lagrangian(D(t), Q, V), c = cxx(D(t), Q, V);
      // the formula's tan is the double tan; the C++ above uses sin/cos: compare derivatives to round-off
      CHECK(std::abs(f.v - c.v) <= 1e-14 * (1 + std::abs(c.v)));
      for (int i = 0; i < 3; ++i) CHECK(std::abs(f.d[i] - c.d[i]) <= 1e-14 * (1 + std::abs(c.d[i])));
      using DD = Dual<Dual<double, 2>, 3>;
      Vec<DD, 2> QQ, VV;
      QQ(0) = DD::variable(Dual<double, 2>::variable(q(0), 0), 0);
      QQ(1) = DD::variable(Dual<double, 2>(q(1)), 1);
      VV(0) = DD::variable(Dual<double, 2>::variable(v(0), 1), 2);
      VV(1) = DD(v(1));
      const DD g = fs.lagrangian(DD(t), QQ, VV), h = cxx(DD(t), QQ, VV);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 2; ++j) CHECK(std::abs(g.d[i].d[j] - h.d[i].d[j]) <= 1e-14 * (1 + std::abs(h.d[i].d[j])));
    }
    SECTION("long double") {
      const long double f = fs.lagrangian<long double>(t, q.cast<long double>(), v.cast<long double>());
      const long double c = cxx((long double)t, Vec<long double, 2>(q.cast<long double>()), Vec<long double, 2>(v.cast<long double>()));
      CHECK(std::abs(double(f - c)) <= 1e-17 * (1 + std::abs(double(c))));
    }
  }
}

TEST_CASE("formulas written as the C++ associates give its bits in every scalar type", "[formula][parse]") {
  // no tan (libm's tan is not sin/cos): everything else must match exactly, derivatives included
  const std::string L = "a*v1*v1/2 - b*q1*q1/3 + sin(q1)*cos(v2) + exp(-q1)*log(2 + q2) + sqrt(1 + v1*v1) - t*v1 + a*v2/q2";
  const auto model = model_of(system_text(2, L));
  const FormulaSystem<2, 0> fs(model);
  const double a = 0.7, b = -1.3;
  auto cxx = [&](const auto& t, const auto& q, const auto& v) {
    using std::cos;
    using std::exp;
    using std::log;
    using std::sin;
    using std::sqrt;
    return a * v(0) * v(0) / 2 - b * q(0) * q(0) / 3 + sin(q(0)) * cos(v(1)) + exp(-q(0)) * log(2 + q(1)) +
           sqrt(1 + v(0) * v(0)) - t * v(0) + a * v(1) / q(1);
  };
  const double t = 0.37;
  const Vec<double, 2> q(0.61, 1.17), v(-0.43, 0.88);
  CHECK(fs.lagrangian(t, q, v) == cxx(t, q, v));
  using D = Dual<double, 4>;
  const Vec<D, 2> Q(D::variable(q(0), 0), D::variable(q(1), 1)), V(D::variable(v(0), 2), D::variable(v(1), 3));
  const D f = fs.lagrangian(D::variable(t, 0), Q, V), c = cxx(D::variable(t, 0), Q, V);
  CHECK(f.v == c.v);
  for (int i = 0; i < 4; ++i) CHECK(f.d[i] == c.d[i]);
  // depth 2: the run-time-sized evaluator (tape_duals.cpp)
  using In = Dual<double, 3>;
  using DD = Dual<In, 5>;
  Vec<DD, 2> QQ, VV;
  for (int i = 0; i < 2; ++i) {
    QQ(i) = DD::variable(In::variable(q(i), i), i);
    VV(i) = DD::variable(In::variable(v(i), 2), 2 + i);
  }
  const DD g = fs.lagrangian(DD::variable(In(t), 4), QQ, VV), h = cxx(DD::variable(In(t), 4), QQ, VV);
  CHECK(g.v.v == h.v.v);
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 3; ++j) CHECK(g.d[i].d[j] == h.d[i].d[j]);
  // the modified equations' series, alone and under a Dual
  using S = modified::BiSeries<4, 5, 2>;
  const S T = S(t) + S::eps(), H = S::h();
  Vec<S, 2> Qs(S(q(0)) + S::eps() * 0.5, S(q(1)) + H * 0.25), Vs(S(v(0)) + H, S(v(1)) - S::eps());
  const S fs_ = fs.lagrangian(T, Qs, Vs), cs = cxx(T, Qs, Vs);
  CHECK(fs_.a == cs.a);
  CHECK(fs_.p == cs.p);
  using DS = Dual<S, 2>;
  const Vec<DS, 2> Qd(DS::variable(Qs(0), 0), DS(Qs(1))), Vd(DS(Vs(0)), DS::variable(Vs(1), 1));
  const DS fd = fs.lagrangian(DS(T), Qd, Vd), cd = cxx(DS(T), Qd, Vd);
  CHECK(fd.v.a == cd.v.a);
  CHECK(fd.d[0].a == cd.d[0].a);
  CHECK(fd.d[1].a == cd.d[1].a);
}

TEST_CASE("a constraint's rows are its derivatives, taken symbolically", "[formula][parse]") {
  const std::string more = "[constraints]\nphi1 = q2^3*v1 + sin(q1)*v2 + a*t*q1\n";
  const auto model = model_of(system_text(2, "v1*v1/2 + v2*v2/2", more));
  const FormulaSystem<2, 1> fs(model);
  const double t = 0.3, a = 0.7;
  const Vec<double, 2> q(0.4, -0.9);
  const Mat<double, 1, 2> A = fs.constraint_matrix(t, q);
  CHECK(A(0, 0) == q(1) * q(1) * q(1));
  CHECK(A(0, 1) == std::sin(q(0)));
  CHECK(fs.constraint_offset(t, q)(0) == a * t * q(0));

  // holonomic: A = dg/dq, b = dg/dt, against forward-mode AD of g itself
  const auto hol = model_of(system_text(2, "v1*v1/2 + v2*v2/2", "[constraints]\ng1 = q1*q1*cos(a*t) + exp(q2)*t - 1\n"));
  const FormulaSystem<2, 1, true> gs(hol);
  using D = Dual<double, 3>;
  const D g = gs.holonomic(D::variable(t, 2), Vec<D, 2>(D::variable(q(0), 0), D::variable(q(1), 1)))(0);
  const Mat<double, 1, 2> Ag = gs.constraint_matrix(t, q);
  CHECK(std::abs(Ag(0, 0) - g.d[0]) <= 1e-15 * std::abs(g.d[0]));
  CHECK(std::abs(Ag(0, 1) - g.d[1]) <= 1e-15 * std::abs(g.d[1]));
  CHECK(std::abs(gs.constraint_offset(t, q)(0) - g.d[2]) <= 1e-15 * std::abs(g.d[2]));
}

TEST_CASE("parameters and definitions follow set_parameter, and a symbolic-style parameter type is carried", "[formula][parse]") {
  const auto model = model_of(system_text(1, "k*v1*v1/2", "", "k = a*a + 1   # a constant definition"));
  FormulaSystem<1, 0> fs(model);
  const Vec<double, 1> q(0.2), v(3);
  CHECK(fs.lagrangian(0.0, q, v) == (0.7 * 0.7 + 1) * 3 * 3 / 2);
  fs.set_parameter("a", 2);
  CHECK(fs.lagrangian(0.0, q, v) == (2.0 * 2 + 1) * 3 * 3 / 2);
  int seen = 0;
  fs.visit([&](const char* name, double& x, const char* doc) {
    if (std::string(name) == "a") {
      CHECK(std::string(doc) == "the first");
      x = 3;
      ++seen;
    }
  });
  CHECK(seen == 1);
  CHECK(fs.lagrangian(0.0, q, v) == (3.0 * 3 + 1) * 3 * 3 / 2);
  check_error([&] { fs.set_parameter("c", 1); }, "no parameter 'c' (known: a, b, T)");
  // the parameters in long double: the derived value k is computed in long double
  const formula::FormulaSystemT<1, 0, false, long double> fl(model, {2.0L / 3, -1.3L, 1.0L});
  const long double k = (2.0L / 3) * (2.0L / 3) + 1;
  CHECK(fl.lagrangian<long double>(0.0L, Vec<long double, 1>(0.2L), Vec<long double, 1>(3.0L)) == k * 3 * 3 / 2);
}

TEST_CASE("an evaluation allocates nothing", "[formula][parse]") {
  const auto model = model_of(system_text(2, "a*v1*v1/2 + v2^3 - sin(q1)*exp(q2)/(1 + q1*q1) + b*t*q2", "F1 = -a*v1\nF2 = q1*v2\n"));
  const FormulaSystem<2, 0> fs(model);
  using D = Dual<double, 4>;
  using DD = Dual<Dual<double, 4>, 6>;
  const Vec<D, 2> Q(D::variable(0.3, 0), D::variable(0.5, 1)), V(D::variable(0.7, 2), D::variable(-0.2, 3));
  Vec<DD, 2> QQ, VV;
  for (int i = 0; i < 2; ++i) {
    QQ(i) = DD::variable(Dual<double, 4>::variable(0.3 + i, i), i);
    VV(i) = DD::variable(Dual<double, 4>::variable(0.7 - i, 2 + i), 2 + i);
  }
  double sink = 0;
  fs.lagrangian(D(0.1), Q, V);  // a first call may size a thread-local buffer
  fs.lagrangian(DD(0.1), QQ, VV);
  counting = true;
  allocations = 0;
  for (int k = 0; k < 100; ++k) {
    sink += fs.lagrangian(0.1, Vec<double, 2>(0.3, 0.5), Vec<double, 2>(0.7, -0.2));
    sink += fs.lagrangian(D(0.1), Q, V).v + fs.force(D(0.1), Q, V)(1).d[0];
    sink += fs.lagrangian(DD(0.1), QQ, VV).d[1].d[2];
  }
  counting = false;
  if (can_count)
    CHECK(allocations == 0);
  else
    WARN("allocations are not counted under AddressSanitizer");
  CHECK(std::isfinite(sink));
}

TEST_CASE("bad system files are refused with one line naming the place", "[formula][parse][errors]") {
  struct Case {
    std::string text, expect;
  };
  const std::string sys = "[system]\nname = s\ncoordinates = 2\n[parameters]\nalpha = 0.1\nT = 1\n";
  const std::string init = "[initial]\nq1 = 0\nq2 = 0\nv1 = 1\nv2 = 0\n";
  const std::string L = "[dynamics]\nL = v1*v1/2 + v2*v2/2\n";
  // coordinates = N with every initial datum given: the shape is what is refused
  auto coordinates = [](int N) {
    std::string s = "[system]\nname = s\ncoordinates = " + std::to_string(N) + "\n[parameters]\nT = 1\n[dynamics]\nL = v1\n[initial]\n";
    for (int i = 1; i <= N; ++i) s += "q" + std::to_string(i) + " = 0\nv" + std::to_string(i) + " = 0\n";
    return s;
  };
  auto rows = [](int N, int M) {
    std::string s = "[system]\nname = s\ncoordinates = " + std::to_string(N) + "\n[parameters]\nT = 1\n[dynamics]\nL = v1\n[constraints]\n";
    for (int i = 1; i <= M; ++i) s += "phi" + std::to_string(i) + " = v" + std::to_string(i) + "\n";
    s += "[initial]\n";
    for (int i = 1; i <= N; ++i) s += "q" + std::to_string(i) + " = 0\nv" + std::to_string(i) + " = 0\n";
    return s;
  };
  const std::vector<Case> cases = {
      {sys + "[dynamics]\nL = v1*v1/2 + alpah*v2\n" + init, "test.geomint:8:15: L: unknown symbol 'alpah' (did you mean 'alpha'?)"},
      {sys + "[dynamics]\nL = v1*v1/2 + (v2*v2\n" + init, "test.geomint:8:15: L: '(' is never closed"},
      {sys + "[dynamics]\nL = v1*v1/2 + 2 v2\n" + init, "test.geomint:8:17: L: unexpected 'v' after a complete formula (missing operator?"},
      {sys + "[dynamics]\nL = v1*v1/2 + q3\n" + init, "test.geomint:8:15: L: 'q3': the system has 2 coordinates (q1..q2, v1..v2)"},
      {sys + "[dynamics]\nL = v1*v1/2 + sinh(q1)\n" + init, "test.geomint:8:15: L: unknown function 'sinh'"},
      {sys + "[dynamics]\nL = v1*v1/2 $ q1\n" + init, "test.geomint:8:13: L: unexpected '$' after a complete formula"},
      {sys + "[dynamics]\nL = v1*v1/2 + 1e999\n" + init, "test.geomint:8:15: L: number '1e999' is out of range"},
      {sys + "[dynamics]\nL = v1*v1/2 - alpha*z\n" + init, "test.geomint:8: L depends on z: the Herglotz Lagrangian is written herglotz = ..."},
      {sys + L + "F1 = -alpha*v1\n" + init, "F1 is the last force component but the system has 2 coordinates"},
      {sys + L + "F3 = 0\nF1 = 0\nF2 = 0\n" + init, "test.geomint:9: F3: the system has 2 coordinates"},
      {sys + L + "[constraints]\nphi1 = v1*v2\n" + init, "test.geomint:10: phi1 is not linear in the velocities: its coefficient of v1 depends on v2"},
      {sys + L + "[constraints]\nphi1 = q1 - 1\n" + init, "phi1 has no velocity in it: a constraint on the positions is written as a holonomic row g1"},
      {sys + L + "[constraints]\ng1 = q1*v1\n" + init, "test.geomint:10: g1 depends on the velocities"},
      {sys + L + "[constraints]\nphi1 = v1\ng2 = q1\n" + init, "constraints mix phi (linear in the velocities) and g (holonomic) rows"},
      {sys + L + "[constraints]\nphi1 = v1\nphi2 = v2\n" + init, "test.geomint:11: phi2: 2 constraint rows with 2 coordinates: formula systems have at most 6 rows, and fewer rows than coordinates"},
      {sys + L + "[constraints]\nphi1 = atan2(q1, q2)*v1 + v2\n" + init, "phi1 takes atan2 of q1, q2: atan2 is available for parameters and initial data only"},
      {sys + L + "[initial]\nq1 = t\nq2 = 0\nv1 = 1\nv2 = 0\n", "test.geomint:10: initial q1 is not constant: initial data are numbers, parameters and definitions of parameters (it uses t)"},
      {sys + L + "[initial]\nq1 = 0\nv1 = 1\nv2 = 0\n", "test.geomint: [initial] has no q2 (give q1..q2 and v1..v2)"},
      {coordinates(13), "test.geomint: coordinates = 13: formula systems have 1 to 12 coordinates"},
      {rows(9, 7), "phi7: 7 constraint rows with 9 coordinates: formula systems have at most 6 rows, and fewer rows than coordinates"},
      {"[system]\nname = s\ncoordinates = 2\n[parameters]\nalpha = 0.1\n" + L + init, "no parameter T (the horizon)"},
      {"[system]\nname = s\ncoordinates = 2\n[parameters]\nalpha = 0.1*q1\nT = 1\n" + L + init,
       "test.geomint:5:13: parameter alpha: a parameter's default is a number (or a formula of numbers and pi), not 'q1'"},
      {"[system]\nname = s\ncoordinates = 2\n[parameters]\nq1 = 1\nT = 1\n" + L + init, "test.geomint:5: parameter q1 is a coordinate or velocity (q1..q2, v1..v2)"},
      {sys + "[definitions]\nw = u + 1\nu = 2\n" + L + init, "test.geomint:8:5: definition w: 'u' is defined below (test.geomint:9): a formula can use only the definitions above it"},
      {sys + "[definitions]\nalpha = 2\n" + L + init, "test.geomint:8: definition alpha is already a parameter"},
      {sys + "[dynamics]\nL = v1*v1/2 + v2*v2/2\nL = 1\n" + init, "test.geomint:9: 'L' is given twice in [dynamics] (first at line 8)"},
      {sys + "[dynamic]\n", "test.geomint:7: unknown section [dynamic]"},
      {sys + L + "[initial]\nq1 0\n", "test.geomint:10: expected 'key = value'"},
      {"name = s\n", "test.geomint:1: 'name' comes before any section (start with [system])"},
      {sys + "[dynamics]\nL = " + std::string(250, '(') + "v1" + std::string(250, ')') + "\n" + init, "nested more than 200 levels deep"},
  };
  for (const auto& c : cases) {
    const std::string msg = error_of([&] { model_of(c.text); });
    INFO("expected: " << c.expect << "\n     got: " << msg);
    CHECK(msg.find(c.expect) != std::string::npos);
    CHECK(msg.find('\n') == std::string::npos);
  }
  CHECK(error_of([] { formula::read_system_file("/nonexistent/x.geomint"); }) ==
        "cannot read system file '/nonexistent/x.geomint': no such file");
  CHECK(error_of([] { formula::read_system_file("/tmp"); }) == "cannot read system file '/tmp': not a regular file");
}

TEST_CASE("bad parameter values are refused by validate with the place", "[formula][parse][errors]") {
  SECTION("a velocity Hessian that is singular at the initial data: no Legendre transform") {
    const auto m = model_of(system_text(2, "q1*v1 + v2*v2/2"));
    check_error([&] { FormulaSystem<2, 0>(m).validate(); }, "test.geomint:9: the velocity Hessian of L is singular at the initial data (q0 = (0.1, 0.1), v0 = (1, 1)");
    // regular elsewhere is not enough: v1^4 is singular at v1 = 0 only
    const auto w = model_of(system_text(1, "v1^4/12") + "");
    FormulaSystem<1, 0> ws(w);
    CHECK_NOTHROW(ws.validate());
  }
  SECTION("dependent constraint rows, an initial position off a holonomic constraint, non-finite values") {
    const auto dep = model_of(system_text(3, "v1*v1/2 + v2*v2/2 + v3*v3/2", "[constraints]\nphi1 = v1 + v2\nphi2 = 2*v1 + 2*v2\n"));
    check_error([&] { FormulaSystem<3, 2>(dep).validate(); }, "the constraint rows are linearly dependent at the initial position");
    const auto off = model_of(system_text(2, "v1*v1/2 + v2*v2/2", "[constraints]\ng1 = q1*q1 + q2*q2 - 1\n"));
    check_error([&] { FormulaSystem<2, 1, true>(off).validate(); }, "test.geomint:11: the initial position q0 = (0.1, 0.1) is off the holonomic constraint: g1(t0, q0) = -0.98");
    const auto nan = model_of(system_text(1, "w*v1*v1/2", "", "w = log(a - 1)"));
    check_error([&] { FormulaSystem<1, 0>(nan).validate(); }, "test.geomint:9: definition w is not finite at these parameters (");
    FormulaSystem<1, 0> neg(model_of(system_text(1, "v1*v1/2")));
    neg.set_parameter("T", -1);
    check_error([&] { neg.validate(); }, "T must be a positive finite number, got -1");
  }
}

TEST_CASE("the nesting limit counts each level once", "[formula][parse][errors]") {
  const int limit = formula::max_formula_depth;
  auto nested = [](int k, const std::string& open, const std::string& close) {
    std::string s;
    for (int i = 0; i < k; ++i) s += open;
    s += "v1";
    for (int i = 0; i < k; ++i) s += close;
    return s;
  };
  // L = v1*v1/2 + <nested>: the nested formula starts at column 15 of the formula, column 19 of its line
  for (const auto& [open, close] : {std::pair<std::string, std::string>{"(", ")"}, {"sin(", ")"}, {"-", ""}}) {
    INFO(open);
    CHECK_NOTHROW(model_of(system_text(1, "v1*v1/2 + " + nested(limit, open, close))));
    const std::string msg = error_of([&] { model_of(system_text(1, "v1*v1/2 + " + nested(limit + 1, open, close))); });
    // the column just after the opening of the level past the limit
    const int column = 4 + 10 + static_cast<int>(open.size()) * (limit + 1) + 1;
    CHECK(msg == "test.geomint:9:" + std::to_string(column) + ": L: formula nested more than " + std::to_string(limit) +
                     " levels deep");
  }
  CHECK(limit == 200);
}

TEST_CASE("a Herglotz form inconsistent with the force is a warning, or an error when asked", "[formula][parse][errors]") {
  const std::string base = "[system]\nname = p\ncoordinates = 1\n[parameters]\nalpha = 0.1\nT = 5\n[dynamics]\n"
                           "L = v1*v1/2 - (1 - cos(q1))\nF1 = -alpha*v1\n";
  const std::string init = "[initial]\nq1 = 1\nv1 = 0\n";
  SECTION("consistent: L - alpha z with the Rayleigh force -alpha q'") {
    const auto m = model_of(base + "herglotz = L - alpha*z\n" + init, {true});
    const FormulaSystem<1, 0> fs(m);
    CHECK(fs.warnings().empty());
    CHECK_NOTHROW(fs.validate());
  }
  SECTION("inconsistent: twice the damping") {
    const auto m = model_of(base + "herglotz = L - 2*alpha*z\n" + init);
    const FormulaSystem<1, 0> fs(m);
    CHECK_NOTHROW(fs.validate());
    const auto w = fs.warnings();
    REQUIRE(w.size() == 1);
    INFO(w[0]);
    CHECK(w[0].find("test.geomint:10: the Herglotz Lagrangian is inconsistent with the force: at t = 0.125, q = (0.99") !=
          std::string::npos);
    const auto strict = model_of(base + "herglotz = L - 2*alpha*z\n" + init, {true});
    check_error([&] { FormulaSystem<1, 0>(strict).validate(); }, "inconsistent with the force");
  }
  SECTION("inconsistent only where the velocity is not zero: a cubic force") {
    const auto m = model_of("[system]\nname = p\ncoordinates = 1\n[parameters]\nalpha = 0.1\nT = 5\n[dynamics]\n"
                            "L = v1*v1/2 - (1 - cos(q1))\nF1 = -alpha*v1^3\nherglotz = L - alpha*z\n" + init);
    CHECK(FormulaSystem<1, 0>(m).warnings().size() == 1);
  }
}

TEST_CASE("every system file in docs/systems loads into the shape of its formulas", "[formula][parse]") {
  struct Shape {
    std::string name;
    int n, m;
    bool holonomic;
  };
  const std::vector<Shape> shapes = {{"pendulum", 1, 0, false},          {"oscillator", 1, 0, false},
                                     {"forced-oscillator", 1, 0, false}, {"coupled-oscillators", 2, 0, false},
                                     {"double-pendulum", 2, 0, false},   {"knife-edge", 3, 1, false},
                                     {"particle", 3, 1, false},          {"foucault", 2, 1, false},
                                     {"foucault-rotation", 2, 1, true},  {"rolling-disk", 4, 2, false},
                                     {"double-pendulum-cartesian", 4, 2, true}, {"chaplygin-sleigh", 3, 1, false},
                                     {"duffing", 1, 0, false}};
  for (const auto& s : shapes) {
    const auto m = formula::load_system_file(std::string(GEOMINT_SOURCE_DIR) + "/docs/systems/" + s.name + ".geomint");
    INFO(s.name);
    CHECK(m->name == s.name);
    // the run-time shape picks the compiled type
    const auto [n, c, h, warnings] = formula::with_formula_system(m, [](const auto& sys) {
      using Sys = std::decay_t<decltype(sys)>;
      sys.validate();
      return std::make_tuple(Sys::dof, Sys::constraints, Sys::is_holonomic, sys.warnings().size());
    });
    CHECK(n == s.n);
    CHECK(c == s.m);
    CHECK(h == s.holonomic);
    CHECK(warnings == 0);  // every Herglotz form of these files agrees with its force
  }
}

TEST_CASE("bench_formula refuses a missing formula file with one line, exit 2, nothing written", "[formula][parse][errors][bench]") {
  testing::check_rejected("bench_formula", "--systems /nonexistent --reps 3", "cannot read system file '/nonexistent/pendulum.geomint'");
  testing::check_rejected("bench_formula", "--reps 1", "reps must be in [3, 1000]");
}
