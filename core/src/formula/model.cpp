#include "geomint/formula/model.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <unordered_set>

#include "geomint/constants.hpp"
#include "geomint/error.hpp"
#include "geomint/formula/parser.hpp"
#include "geomint/text.hpp"

namespace geomint::formula {

int FormulaModel::parameter_index(const std::string& pname) const {
  for (std::size_t i = 0; i < parameters.size(); ++i)
    if (parameters[i].name == pname) return static_cast<int>(i);
  return -1;
}

std::string FormulaModel::parameter_names() const {
  std::string out;
  for (const auto& p : parameters) out += (out.empty() ? "" : ", ") + p.name;
  return out;
}

namespace {


std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

bool is_identifier(const std::string& s) {
  if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
  return std::all_of(s.begin(), s.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
}

// q<k> / v<k> with k a positive integer written without leading zeros.
bool coordinate_name(const std::string& s, char letter, int& k) {
  if (s.size() < 2 || s[0] != letter || s[1] == '0' || s.size() > 4) return false;
  for (std::size_t i = 1; i < s.size(); ++i)
    if (!std::isdigit(static_cast<unsigned char>(s[i]))) return false;
  k = std::stoi(s.substr(1));
  return true;
}

// "file:12:7: L" for a file, "L, column 7" for a field of an in-memory description.
std::string located(const Where& w, const std::string& what, int column) {
  if (w.line > 0) return w.at(column) + ": " + what;
  return w.source + ", column " + std::to_string(column);
}
std::string placed(const Where& w, const std::string& what) {
  if (w.line > 0) return w.place() + ": " + what;
  return w.source;
}

// What a formula may refer to.
struct Scope {
  bool numbers_only = false;  // a parameter's default
  bool lagrangian = false;    // L (in herglotz and E)
  std::size_t definitions = 0;  // the definitions above this formula
};

class ModelCompiler {
 public:
  ModelCompiler(const SystemDescription& d, const CompileOptions& options)
      : d_(d), tt_(d.time_transform.given()), ex_(check_coordinates(d)), np_(d.coordinates) {
    model_ = std::make_shared<FormulaModel>();
    model_->strict_herglotz = options.strict_herglotz;
  }

  std::shared_ptr<const FormulaModel> run(const CompileOptions& options) {
    FormulaModel& M = *model_;
    if (tt_) {
      // The physical system first: its errors are the file's, and the Herglotz check runs on it (checks.cpp).
      SystemDescription physical = d_;
      physical.time_transform = FormulaText{};
      M.physical = compile_model(physical, options);
      M.description = d_.description;
    }
    const Variables& V = ex_.variables();
    // n: the system's coordinates as its formulas name them; N: the model's (n + 1 with a time transformation,
    // whose coordinate N is the time t and whose velocity N is t' = dt/dsigma).
    const int n = np_, N = V.n;
    M.name = d_.name;
    M.description = d_.description;
    M.origin = d_.origin;
    M.n = N;
    M.physical_n = n;
    M.time_transformed = tt_;
    M.m = static_cast<int>(d_.constraints.size());
    M.holonomic = d_.constraint_kind == ConstraintKind::holonomic && M.m > 0;
    printable_description();
    check_name();
    if (!supported_shape(N, M.m)) {
      // named at the first row the shape cannot hold (rows beyond the coordinates, or beyond the compiled shapes)
      const std::string shape = std::to_string(M.m) + " constraint row" + (M.m == 1 ? "" : "s") + " with " + std::to_string(N) +
            " coordinate" + (N == 1 ? "" : "s") + (tt_ ? " (the time transformation adds t)" : "") + ": formula systems have at most " + std::to_string(max_constraints) +
            " rows, and fewer rows than coordinates";
      const int first = std::max(0, std::min(max_constraints, N - 1));
      if (first >= M.m) whole(shape);
      const std::string row = std::string(M.holonomic ? "g" : "phi") + std::to_string(first + 1);
      throw InputError(placed(d_.constraints[static_cast<std::size_t>(first)].where, row) + ": " + shape);
    }

    parameters();
    definitions();

    // The dynamics.
    require_given(d_.lagrangian, "L", "the Lagrangian 'L = ...'");
    int L = parse(d_.lagrangian, "L", Scope{false, false, defs_.size()});
    forbid(L, V.bit(V.z()), d_.lagrangian, "L", "depends on z: the Herglotz Lagrangian is written herglotz = ...");
    lagrangian_ = L;
    M.lagrangian_at = d_.lagrangian.where;
    int H = -1, E = -1;
    if (d_.herglotz.given()) {
      H = parse(d_.herglotz, "herglotz", Scope{false, true, defs_.size()});
      M.herglotz_at = d_.herglotz.where;
    }
    if (d_.energy.given()) {
      E = parse(d_.energy, "E", Scope{false, true, defs_.size()});
      forbid(E, V.bit(V.z()), d_.energy, "E", "depends on z: the energy is a function of t, q and v");
    }
    std::vector<int> F;
    if (!d_.force.empty()) {
      if (static_cast<int>(d_.force.size()) != n)
        whole("the force has " + std::to_string(d_.force.size()) + " components but the system has " + std::to_string(n) +
              " coordinates");
      for (int i = 0; i < n; ++i) {
        const std::string what = "F" + std::to_string(i + 1);
        const int f = parse(d_.force[static_cast<std::size_t>(i)], what, Scope{false, true, defs_.size()});
        forbid(f, V.bit(V.z()), d_.force[static_cast<std::size_t>(i)], what, "depends on z: the force is a function of t, q and v");
        F.push_back(f);
      }
    }

    // The constraints: A and b by differentiating each row.
    std::vector<int> A, b, g;
    for (int r = 0; r < M.m; ++r) {
      const FormulaText& f = d_.constraints[static_cast<std::size_t>(r)];
      const std::string what = (M.holonomic ? "g" : "phi") + std::to_string(r + 1);
      const int row = parse(f, what, Scope{false, false, defs_.size()});
      forbid(row, V.bit(V.z()), f, what, "depends on z: a constraint is a function of t, q and v");
      M.constraint_at.push_back(f.where);
      bool any = false;
      if (M.holonomic) {
        // With a time transformation t is the coordinate q_N: the loop over the N coordinates takes dg/dt as the
        // row's last column, and b = dg/dsigma = 0.
        forbid(row, V.v_bits(), f, what, "depends on the velocities: a holonomic constraint g(t, q) is a function of t and q (a row linear in the velocities is written phi" + std::to_string(r + 1) + " = ...)");
        g.push_back(row);
        for (int k = 0; k < N; ++k) {
          A.push_back(at(f, what, [&] { return ex_.derivative(row, V.q(k)); }));
          any = any || !ex_.is_number(A.back(), 0);
        }
        b.push_back(at(f, what, [&] { return ex_.derivative(row, V.t()); }));
        if (!any) fail_at(f, what, "does not depend on q: g(t) = 0 constrains no motion");
      } else {
        for (int k = 0; k < n; ++k) {
          const int a = at(f, what, [&] { return ex_.derivative(row, V.v(k)); });
          const std::uint32_t nonlinear = ex_[a].uses & V.v_bits();
          if (nonlinear)
            fail_at(f, what, "is not linear in the velocities: its coefficient of v" + std::to_string(k + 1) + " depends on " +
                                 V.names(nonlinear) + " (write Phi = A(t, q) v + b(t, q))");
          A.push_back(a);
          any = any || !ex_.is_number(a, 0);
        }
        b.push_back(at(f, what, [&] { return ex_.substitute_zero(row, V.v_bits()); }));
        if (!any) fail_at(f, what, "has no velocity in it: a constraint on the positions is written as a holonomic row g" + std::to_string(r + 1) + " = ...");
        if (tt_) {
          // A(t, q) q'/t' + b(t, q) = 0 is A q' + b t' = 0: b is the coefficient of t', the offset zero.
          A.push_back(b.back());
          b.back() = ex_.number(0);
        }
      }
    }

    // Linear dynamics: the second derivatives of L and of the Herglotz form in (q, v), the Herglotz form's
    // derivative in z and the first derivatives of F in (q, v) free of every variable, t included (constant
    // coefficients; a forcing term in t alone is allowed), and a holonomic g with a gradient free of q. A
    // derivative the simplifier leaves in a form that still names a variable only costs the shortcut.
    {
      const std::uint32_t state = V.bit(V.t()) | V.q_bits() | V.v_bits() | V.bit(V.z());
      auto constant = [&](int id) { return (ex_[id].uses & state) == 0; };
      std::vector<int> qv;
      for (int k = 0; k < n; ++k) qv.push_back(V.q(k));
      for (int k = 0; k < n; ++k) qv.push_back(V.v(k));
      auto quadratic = [&](int e) {
        for (int a : qv) {
          const int d = ex_.derivative(e, a);
          for (int c : qv)
            if (!constant(ex_.derivative(d, c))) return false;
        }
        return true;
      };
      bool linear = at(d_.lagrangian, "L", [&] { return quadratic(L); });
      if (linear && H >= 0)
        linear = at(d_.herglotz, "herglotz", [&] { return quadratic(H) && constant(ex_.derivative(H, V.z())); });
      for (std::size_t i = 0; i < F.size(); ++i)
        for (int a : qv)
          if (linear && !at(d_.force[i], "F" + std::to_string(i + 1), [&] { return constant(ex_.derivative(F[i], a)); }))
            linear = false;
      if (M.holonomic)
        for (int a : A)
          if ((ex_[a].uses & V.q_bits()) != 0) linear = false;
      M.linear_dynamics = linear && !tt_;
    }

    // The initial data.
    std::vector<int> init;
    for (int part = 0; part < 2; ++part) {
      const auto& rows = part == 0 ? d_.initial_q : d_.initial_v;
      if (static_cast<int>(rows.size()) != n)
        whole("the initial data give " + std::to_string(rows.size()) + (part == 0 ? " positions" : " velocities") +
              " for " + std::to_string(n) + " coordinates");
      for (int i = 0; i < n; ++i) {
        const FormulaText& f = rows[static_cast<std::size_t>(i)];
        const std::string what = std::string("initial ") + (part == 0 ? "q" : "v") + std::to_string(i + 1);
        const int e = parse(f, what, Scope{false, false, defs_.size()});
        forbid(e, ~std::uint32_t(0), f, what, "is not constant: initial data are numbers, parameters and definitions of parameters");
        init.push_back(e);
        M.initial_at.push_back(f.where);
      }
    }

    // The start (t0, z0): constants, 0 where not given.
    std::vector<int> start;
    for (int k = 0; k < 2; ++k) {
      const FormulaText& f = k == 0 ? d_.initial_t : d_.initial_z;
      const std::string what = k == 0 ? "initial t0" : "initial z0";
      if (!f.given()) {
        start.push_back(ex_.number(0));
        continue;
      }
      const int e = parse(f, what, Scope{false, false, defs_.size()});
      forbid(e, ~std::uint32_t(0), f, what, "is not constant: the start is a number, parameters and definitions of parameters");
      start.push_back(e);
    }
    M.start_at = d_.initial_t.given() ? d_.initial_t.where : d_.origin;

    // The exact solution: q(t) as written, q'(t) as written or by differentiation, q''(t) for the check against the
    // equations (checks.cpp).
    // With a time transformation the solution is the physical model's (checked there); the runs, in sigma, have none.
    std::vector<int> exact;
    if (!d_.exact_q.empty() && !tt_) {
      const std::uint32_t state = V.q_bits() | V.v_bits() | V.bit(V.z());
      std::vector<int> q, v, a;
      for (int i = 0; i < n; ++i) {
        const FormulaText& f = d_.exact_q[static_cast<std::size_t>(i)];
        const std::string what = "exact q" + std::to_string(i + 1);
        const int e = parse(f, what, Scope{false, false, defs_.size()});
        forbid(e, state, f, what, "depends on the state: an exact solution is a formula of t and the parameters");
        q.push_back(e);
        M.exact_at.push_back(f.where);
      }
      for (int i = 0; i < n; ++i) {
        const bool given = !d_.exact_v.empty();
        const FormulaText& f = given ? d_.exact_v[static_cast<std::size_t>(i)] : d_.exact_q[static_cast<std::size_t>(i)];
        const std::string what = std::string("exact ") + (given ? "v" : "q") + std::to_string(i + 1);
        int e = -1;
        if (given) {
          e = parse(f, what, Scope{false, false, defs_.size()});
          forbid(e, state, f, what, "depends on the state: an exact solution is a formula of t and the parameters");
        } else {
          e = at(f, what, [&] { return ex_.derivative(q[static_cast<std::size_t>(i)], V.t()); });
        }
        v.push_back(e);
        a.push_back(at(f, what, [&] { return ex_.derivative(e, V.t()); }));
        M.exact_at.push_back(f.where);
      }
      exact = q;
      exact.insert(exact.end(), v.begin(), v.end());
      exact.insert(exact.end(), a.begin(), a.end());
    }

    if (tt_) {
      transform(L, H, E, F, init, start[0]);
      start[0] = ex_.number(0);  // the runs of the extended system start at sigma = 0; t0 is its coordinate t
    }

    // atan2 only of constants: the series type of the modified equations has no atan2.
    if (tt_) no_state_atan2(L, d_.time_transform, "time_transform");
    no_state_atan2(L, d_.lagrangian, "L");
    if (H >= 0) no_state_atan2(H, d_.herglotz, "herglotz");
    if (E >= 0) no_state_atan2(E, d_.energy, "E");
    for (std::size_t i = 0; i < F.size(); ++i) no_state_atan2(F[i], d_.force[i], "F" + std::to_string(i + 1));
    for (int r = 0; r < M.m; ++r) {
      const std::string what = (M.holonomic ? "g" : "phi") + std::to_string(r + 1);
      const FormulaText& f = d_.constraints[static_cast<std::size_t>(r)];
      for (int k = 0; k < N; ++k) no_state_atan2(A[static_cast<std::size_t>(r * N + k)], f, what);
      no_state_atan2(b[static_cast<std::size_t>(r)], f, what);
    }

    // Tapes. Every node exists now (the number table is final).
    M.numbers = ex_.numbers();
    M.number_texts = ex_.number_texts();
    ConstantTable table(static_cast<int>(M.numbers.size()), static_cast<int>(M.parameters.size()));
    auto state = [&](const std::vector<int>& roots, const Where& w, const std::string& what) {
      const std::size_t before = table.derived().size();
      Tape t;
      try {
        t = compile_state_tape(ex_, roots, table);
      } catch (const InputError& e) {
        throw InputError(placed(w, what) + ": " + e.what());
      }
      for (std::size_t k = before; k < table.derived().size(); ++k) M.derived_origin.push_back(placed(w, what));
      return t;
    };
    M.lagrangian = state({L}, d_.lagrangian.where, "L");
    if (tt_) M.residual = state({residual_}, d_.time_transform.where, "time_transform");
    if (H >= 0) M.herglotz = state({H}, d_.herglotz.where, "herglotz");
    if (E >= 0) M.energy = state({E}, d_.energy.where, "E");
    if (!F.empty()) M.force = state(F, d_.force[0].where, "F");
    if (!exact.empty()) M.exact = state(exact, d_.exact_q[0].where, "the exact solution");
    if (M.m > 0) {
      const Where& w = d_.constraints[0].where;
      std::vector<int> A_columns;  // Eigen's layout: column-major
      for (int k = 0; k < N; ++k)
        for (int r = 0; r < M.m; ++r) A_columns.push_back(A[static_cast<std::size_t>(r * N + k)]);
      M.constraint_matrix = state(A_columns, w, "the constraint rows");
      M.constraint_offset = state(b, w, "the constraint rows");
      if (M.holonomic) M.holonomic_g = state(g, w, "the constraint rows");
    }
    try {
      M.prelude = compile_constant_tape(ex_, table.derived(), table.numbers(), table.parameters());
    } catch (const InputError& e) {
      whole(std::string("the parts of the formulas that depend on the parameters only: ") + e.what());
    }
    M.initial = at(d_.initial_q[0], "the initial data", [&] {
      return compile_constant_tape(ex_, init, table.numbers(), table.parameters());
    });
    M.start = at(d_.initial_t.given() ? d_.initial_t : d_.initial_z, "the start (t0, z0)", [&] {
      return compile_constant_tape(ex_, start, table.numbers(), table.parameters());
    });
    std::vector<int> constant_defs;
    for (const auto& def : defs_)
      if (ex_.is_constant(def.node)) {
        constant_defs.push_back(def.node);
        M.definition_names.push_back({def.name, def.where});
      }
    try {
      M.definitions = compile_constant_tape(ex_, constant_defs, table.numbers(), table.parameters());
    } catch (const InputError& e) {
      whole(std::string("the definitions of parameters: ") + e.what());
    }
    return model_;
  }

 private:
  struct Definition {
    std::string name;
    int node;
    Where where;
  };

  static int check_coordinates(const SystemDescription& d) {
    const int n = d.coordinates;
    if (n < 1 || n > max_coordinates)
      throw InputError(d.origin.source + ": coordinates = " + std::to_string(n) + ": formula systems have 1 to " +
                       std::to_string(max_coordinates) + " coordinates");
    if (d.time_transform.given() && n + 1 > max_coordinates)
      throw InputError(d.time_transform.where.place() + ": time_transform: the transformed system has the time as coordinate " +
                       std::to_string(n + 1) + ", and formula systems have at most " + std::to_string(max_coordinates) +
                       " coordinates (a system of at most " + std::to_string(max_coordinates - 1) + " coordinates can be transformed)");
    return d.time_transform.given() ? n + 1 : n;
  }

  // dt = g dsigma (docs/time-transformation.md). With Q = (q, t), Q' = dQ/dsigma and the physical velocity
  // v = q'/t', the extended system in sigma is
  //   Lbar(Q, Q') = t' L(t, q, v) + (kappa/2)(t' - g(t, q, v))^2   (the Herglotz form likewise, with z),
  //   Fbar = (t' F(t, q, v), -F . q'),  rows [A | b] Q' = 0,
  // whose solution from Q'(0) = (v0 g0, g0) is the physical motion at t(sigma), with w = kappa (t' - g) = 0.
  // Every formula was parsed with t as the graph's coordinate N and v_i as its velocity i; here v_i becomes
  // v_i / v_N in L, the Herglotz form, F, E and g.
  void transform(int& L, int& H, int& E, std::vector<int>& F, std::vector<int>& init, int t0) {
    const Variables& V = ex_.variables();
    const int n = np_, N = V.n;
    const FormulaText& gt = d_.time_transform;
    const std::string what = "time_transform";
    model_->time_transform_at = gt.where;
    const int g = parse(gt, what, Scope{false, false, defs_.size()});
    forbid(g, V.bit(V.z()), gt, what, "depends on z: the monitor g is a function of t, q and v");
    no_state_atan2(g, gt, what);
    const int tp = ex_.var(V.v(N - 1));
    std::vector<int> by(static_cast<std::size_t>(V.count()), -1);
    for (int i = 0; i < n; ++i) by[static_cast<std::size_t>(V.v(i))] = ex_.div(ex_.var(V.v(i)), tp);
    auto physical = [&](int e, const FormulaText& f, const std::string& name) {
      return at(f, name, [&] { return ex_.substitute(e, by); });
    };
    // The physical energy v . L_v - L (the extended Lagrangian's own energy is w t' - w^2/(2 kappa), zero on
    // the exact flow): the energy column stays the system's.
    if (E < 0)
      E = at(d_.lagrangian, "L", [&] {
        int sum = -1;
        for (int i = 0; i < n; ++i) {
          const int term = ex_.mul(ex_.var(V.v(i)), ex_.derivative(L, V.v(i)));
          sum = sum < 0 ? term : ex_.add(sum, term);
        }
        return ex_.sub(sum, L);
      });
    E = physical(E, d_.energy.given() ? d_.energy : d_.lagrangian, d_.energy.given() ? "E" : "L");
    const int gs = physical(g, gt, what);
    const int kappa = ex_.param(model_->parameter_index(time_transform_kappa));
    const int gap = ex_.sub(tp, gs);
    residual_ = ex_.mul(kappa, gap);
    const int penalty = ex_.div(ex_.mul(residual_, gap), ex_.number(2, "2"));
    L = ex_.add(ex_.mul(tp, physical(L, d_.lagrangian, "L")), penalty);
    if (H >= 0) H = ex_.add(ex_.mul(tp, physical(H, d_.herglotz, "herglotz")), penalty);
    if (!F.empty()) {
      int power = -1;
      for (int i = 0; i < n; ++i) {
        const std::string name = "F" + std::to_string(i + 1);
        const int f = physical(F[static_cast<std::size_t>(i)], d_.force[static_cast<std::size_t>(i)], name);
        const int term = ex_.mul(f, ex_.var(V.v(i)));
        power = power < 0 ? term : ex_.add(power, term);
        F[static_cast<std::size_t>(i)] = ex_.mul(tp, f);
      }
      // The force does no work in the extended space: Fbar . Q' = 0 (its power is the t-row's -F . q').
      F.push_back(ex_.neg(power));
    }
    // Q(0) = (q0, t0), Q'(0) = (v0 g0, g0) with g0 = g(t0, q0, v0).
    std::vector<int> at0(static_cast<std::size_t>(V.count()), -1);
    at0[static_cast<std::size_t>(V.q(N - 1))] = t0;
    for (int i = 0; i < n; ++i) {
      at0[static_cast<std::size_t>(V.q(i))] = init[static_cast<std::size_t>(i)];
      at0[static_cast<std::size_t>(V.v(i))] = init[static_cast<std::size_t>(n + i)];
    }
    const int g0 = at(gt, what, [&] { return ex_.substitute(g, at0); });
    std::vector<int> out;
    for (int i = 0; i < n; ++i) out.push_back(init[static_cast<std::size_t>(i)]);
    out.push_back(t0);
    for (int i = 0; i < n; ++i) out.push_back(ex_.mul(init[static_cast<std::size_t>(n + i)], g0));
    out.push_back(g0);
    init = out;
    model_->initial_at.insert(model_->initial_at.begin() + n, gt.where);
    model_->initial_at.push_back(gt.where);
  }

  [[noreturn]] void whole(const std::string& what) const { throw InputError(d_.origin.source + ": " + what); }
  [[noreturn]] void fail_at(const FormulaText& f, const std::string& what, const std::string& message) const {
    throw InputError(placed(f.where, what) + " " + message);
  }
  // Symbolic work on a parsed formula (a derivative, a tape) can pass a limit of the expression graph that its
  // text kept to: the refusal names the formula it came from.
  template <class Body>
  auto at(const FormulaText& f, const std::string& what, Body&& body) -> decltype(body()) {
    try {
      return body();
    } catch (const InputError& e) {
      throw InputError(placed(f.where, what) + ": " + e.what());
    }
  }

  // Text given in memory (the Python module) is held to what the file reader holds a file to: no control byte (it
  // would reach the terminal in a message, and a NUL would cut the message) and UTF-8 only.
  void printable(const std::string& text, const std::string& what, const Where* where = nullptr) const {
    const std::size_t i = first_unprintable(text, "\t");
    if (i == std::string::npos) return;
    char byte[8];
    std::snprintf(byte, sizeof byte, "0x%02x", static_cast<unsigned char>(text[i]));
    const std::string why = "has a control character or a byte that is not UTF-8 (byte " + std::string(byte) + ")";
    if (where && where->line > 0) throw InputError(where->at(static_cast<int>(i) + 1) + ": " + what + " " + why);
    if (where) throw InputError(where->source + ", column " + std::to_string(i + 1) + ": " + what + " " + why);
    whole(what + " " + why + " at byte " + std::to_string(i + 1));
  }
  void printable_description() const {
    printable(d_.name, "the system's name");
    printable(d_.description, "the description");
    auto formula = [&](const FormulaText& f, const std::string& what) { printable(f.text, what, &f.where); };
    for (const auto& p : d_.parameters) {
      printable(p.name, "a parameter's name", &p.value.where);
      printable(p.doc, "parameter " + p.name + "'s doc", &p.value.where);
      formula(p.value, "parameter " + p.name);
    }
    for (const auto& def : d_.definitions) {
      printable(def.name, "a definition's name", &def.value.where);
      formula(def.value, "definition " + def.name);
    }
    formula(d_.lagrangian, "L");
    formula(d_.herglotz, "herglotz");
    formula(d_.energy, "E");
    formula(d_.time_transform, "time_transform");
    for (const auto& f : d_.force) formula(f, "F");
    for (const auto& f : d_.constraints) formula(f, "constraint");
    for (const auto& f : d_.initial_q) formula(f, "initial q");
    for (const auto& f : d_.initial_v) formula(f, "initial v");
    formula(d_.initial_t, "initial t0");
    formula(d_.initial_z, "initial z0");
    for (const auto& f : d_.exact_q) formula(f, "exact q");
    for (const auto& f : d_.exact_v) formula(f, "exact v");
  }

  void require_given(const FormulaText& f, const std::string& what, const std::string& name) const {
    if (!f.given()) whole("no " + name + " (" + what + ")");
  }

  void check_name() const {
    if (d_.name.empty()) whole("the system has no name");
    for (char c : d_.name)
      if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_'))
        whole("system name '" + d_.name + "' may contain only letters, digits, '-' and '_'");
  }

  // Names a formula cannot take: the variables, pi, L, E and the functions.
  std::string reserved(const std::string& name) const {
    int k = 0;
    const int n = np_;
    if (name == "t" || name == "z") return "is a variable (t: time, z: the Herglotz action)";
    if (name == "pi") return "is the number pi";
    if (name == "L" || name == "E") return "names the " + std::string(name == "L" ? "Lagrangian" : "energy");
    // the formulas of the modified equations print the step as h, and sympy parses them as Python
    if (name == "h") return "is the step of the modified equations' formulas (name the parameter otherwise, e.g. step)";
    static const std::unordered_set<std::string> python{"False", "None", "True", "and", "as", "assert", "async", "await",
                                                        "break", "class", "continue", "def", "del", "elif", "else", "except",
                                                        "finally", "for", "from", "global", "if", "import", "in", "is",
                                                        "lambda", "nonlocal", "not", "or", "pass", "raise", "return", "try",
                                                        "while", "with", "yield"};
    if (python.count(name)) return "is a Python keyword (sympy could not read the formulas printed with it)";
    Fn f;
    if (find_fn(name, f)) return "is a function";
    if ((coordinate_name(name, 'q', k) || coordinate_name(name, 'v', k)) && k <= n)
      return "is a coordinate or velocity (q1..q" + std::to_string(n) + ", v1..v" + std::to_string(n) + ")";
    return "";
  }

  void parameters() {
    FormulaModel& M = *model_;
    for (const auto& p : d_.parameters) {
      const std::string what = "parameter " + p.name;
      if (!is_identifier(p.name)) fail_at(p.value, what, "is not a name (letters, digits and '_', not starting with a digit)");
      const std::string r = reserved(p.name);
      if (!r.empty()) fail_at(p.value, what, r);
      if (M.parameter_index(p.name) >= 0) fail_at(p.value, what, "is declared twice");
      if (!p.value.given()) fail_at(p.value, what, "has no value");
      const int node = parse(p.value, what, Scope{true, false, 0});
      const double v = constant_value(ex_, node);
      if (!std::isfinite(v)) fail_at(p.value, what, "= " + p.value.text + " is not a finite number");
      if (p.name == "T" && !(v > 0)) fail_at(p.value, what, "= " + p.value.text + ": the horizon must be positive");
      M.parameters.push_back({p.name, v, p.doc, p.value.where});
    }
    if (M.parameter_index("T") < 0) whole("no parameter T (the horizon): add 'T = ...' to [parameters]");
    if (tt_) {
      const FormulaText& gt = d_.time_transform;
      if (M.parameter_index(time_transform_kappa) >= 0)
        fail_at(gt, "time_transform", std::string("adds the parameter ") + time_transform_kappa +
                                          " (the stiffness of its penalty), which the system has already: rename the system's");
      M.parameters.push_back({time_transform_kappa, 1.0, "stiffness kappa of the time transformation's penalty (kappa/2)(t' - g)^2", gt.where});
    }
  }

  void definitions() {
    for (const auto& def : d_.definitions) {
      const std::string what = "definition " + def.name;
      if (!is_identifier(def.name)) fail_at(def.value, what, "is not a name (letters, digits and '_', not starting with a digit)");
      const std::string r = reserved(def.name);
      if (!r.empty()) fail_at(def.value, what, r);
      if (model_->parameter_index(def.name) >= 0) fail_at(def.value, what, "is already a parameter");
      for (const auto& e : defs_)
        if (e.name == def.name) fail_at(def.value, what, "is defined twice (first at " + e.where.place() + ")");
      if (!def.value.given()) fail_at(def.value, what, "has no value");
      const int node = parse(def.value, what, Scope{false, false, defs_.size()});
      defs_.push_back({def.name, node, def.value.where});
    }
  }

  int parse(const FormulaText& f, const std::string& what, const Scope& scope) {
    try {
      return parse_formula(ex_, f.text, [&](const std::string& name, int column) { return resolve(name, column, scope); });
    } catch (const ParseError& e) {
      throw InputError(located(f.where, what, e.column) + ": " + e.what());
    } catch (const InputError& e) {
      throw InputError(placed(f.where, what) + ": " + e.what());
    }
  }

  int resolve(const std::string& name, int column, const Scope& scope) {
    const Variables& V = ex_.variables();
    if (name == "pi") return ex_.number(pi, "pi");
    if (scope.numbers_only)
      throw ParseError(column, "a parameter's default is a number (or a formula of numbers and pi), not '" + name + "'");
    if (name == "t") return ex_.var(tt_ ? V.q(V.n - 1) : V.t());
    if (name == "z") return ex_.var(V.z());
    int k = 0;
    if (coordinate_name(name, 'q', k) && k <= np_) return ex_.var(V.q(k - 1));
    if (coordinate_name(name, 'v', k) && k <= np_) return ex_.var(V.v(k - 1));
    if (name == "L" && scope.lagrangian) return lagrangian_;
    for (std::size_t i = 0; i < scope.definitions; ++i)
      if (defs_[i].name == name) return defs_[i].node;
    const int p = model_->parameter_index(name);
    if (p >= 0) return ex_.param(p);
    // unknown: say why as precisely as we can
    if ((coordinate_name(name, 'q', k) || coordinate_name(name, 'v', k)))
      throw ParseError(column, "'" + name + "': the system has " + std::to_string(np_) + " coordinate" + (np_ == 1 ? "" : "s") +
                                   " (q1..q" + std::to_string(np_) + ", v1..v" + std::to_string(np_) + ")");
    if (name == "L") throw ParseError(column, "L (the Lagrangian) can be used in herglotz, E and F only");
    for (const auto& def : d_.definitions)
      if (def.name == name)
        throw ParseError(column, "'" + name + "' is defined below (" + def.value.where.place() +
                                     "): a formula can use only the definitions above it");
    std::vector<std::string> known{"t", "z", "pi"};
    for (const auto& q : model_->parameters) known.push_back(q.name);
    for (std::size_t i = 0; i < scope.definitions; ++i) known.push_back(defs_[i].name);
    if (scope.lagrangian) known.push_back("L");
    std::string best;
    std::size_t dist = 3;
    for (const auto& c : known) {
      const std::size_t e = edit_distance(name, c);
      if (e < dist && e < std::max<std::size_t>(name.size(), 2)) {
        dist = e;
        best = c;
      }
    }
    std::string msg = "unknown symbol '" + name + "'";
    if (!best.empty())
      msg += " (did you mean '" + best + "'?)";
    else
      msg += " (parameters: " + model_->parameter_names() + ")";
    throw ParseError(column, msg);
  }

  // Refuses a formula that uses any of the variables in `bits`.
  void forbid(int node, std::uint32_t bits, const FormulaText& f, const std::string& what, const std::string& message) const {
    const std::uint32_t used = ex_[node].uses & bits;
    if (!used) return;
    if (bits == ~std::uint32_t(0))
      fail_at(f, what, message + " (it uses " + ex_.variables().names(used) + ")");
    fail_at(f, what, message);
  }

  void no_state_atan2(int root, const FormulaText& f, const std::string& what) {
    std::unordered_set<int> seen;
    std::vector<int> stack{root};
    while (!stack.empty()) {
      const int id = stack.back();
      stack.pop_back();
      const Node& x = ex_[id];
      if (x.uses == 0 || !seen.insert(id).second) continue;
      if (x.kind == Kind::call && x.fn == Fn::atan2)
        fail_at(f, what, "takes atan2 of " + ex_.variables().names(x.uses) +
                             ": atan2 is available for parameters and initial data only (the modified equations' series "
                             "type has no atan2)");
      for (int c : {x.a, x.b})
        if (c >= 0) stack.push_back(c);
    }
  }

  const SystemDescription& d_;
  bool tt_;  // a time transformation: the graph has the time as coordinate np_ + 1
  Expressions ex_;
  int np_;   // the coordinates the system's formulas name
  int residual_ = -1;
  std::shared_ptr<FormulaModel> model_;
  std::vector<Definition> defs_;
  int lagrangian_ = -1;
};

}  // namespace

std::shared_ptr<const FormulaModel> compile_model(const SystemDescription& description, const CompileOptions& options) {
  return ModelCompiler(description, options).run(options);
}

std::shared_ptr<const FormulaModel> load_system_file(const std::filesystem::path& path, const CompileOptions& options) {
  return compile_model(read_system_file(path), options);
}

std::vector<double> with_derived_values(const FormulaModel& M, std::vector<double> table) {
  table.resize(static_cast<std::size_t>(M.table_size()));
  std::vector<const double*> in(static_cast<std::size_t>(M.derived_offset()));
  for (std::size_t i = 0; i < in.size(); ++i) in[i] = &table[i];
  std::vector<double> derived(M.prelude.size());
  M.prelude.eval_duals<double, 0>(nullptr, in.data(), table.data(), derived.data());
  std::copy(derived.begin(), derived.end(), table.begin() + M.derived_offset());
  return table;
}

}  // namespace geomint::formula
