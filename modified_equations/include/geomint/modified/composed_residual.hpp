#pragma once
// The three-point residual of a composition (generic/composition.hpp), for its modified equation.
//
// A composition Psi_h = Phi_{w_s h} o ... o Phi_{w_1 h} of a symmetric scheme is a one-step map on (q, p[, z]).
// Its positions q_j and its stage points Q_{j,0} = q_j, Q_{j,1}, ..., Q_{j,s} = q_{j+1} satisfy, at every
// node, the base scheme's own residual between the step before and the step after it (Scheme::residual_between:
// the stage before hands its p^- to the stage after as p^+, up to the impulse A^T lambda the stage after applies
// at its start), and every stage its discrete constraint and (contact) its action row
// z_{i} = z_{i-1} + 𝓛(Q_{i-1}, Q_i, z_{i-1}, z_i) with step w_i h. Eliminating the momenta this way leaves a
// position-only description: given q_j and q_{j+1}, the interior stage points of that step solve a boundary-
// value problem (the interior nodes' residuals and the stages' constraints), and the composition's sequence is
// exactly the sequences for which the residual at the junction q_j — the base residual between the last stage
// of the step before (step w_s h) and the first stage of the step after (step w_1 h) — vanishes, with the first
// stage's discrete constraint Phi_d(q_j, Q_{j,1}) = 0 (Phi o Psi), or the last stage's g(t_{j+1}, q_{j+1}) = 0
// (holonomic), and (contact) z_{j+1} = z_j + sum of the stages' actions. That is a three-point scheme like the
// others: the series engine (automatic.hpp) pushes its series through it unchanged, so a composition's modified
// equation comes from the base scheme's residual at the stage steps w_i h, and nothing else. (For a variational
// base without force, sum_i 𝓛(Q_{i-1}, Q_i) at the solved stage points is the composition's discrete
// Lagrangian, the generating function of Psi_h (Hairer–Lubich–Wanner, Sect. VI.6), so the meshed modified
// Lagrangian comes out too.)
//
// The stage points are solved in the scalar S (double, or the engine's series in (eps, h)) by a chord iteration
// on the scaled unknowns X_i = Q_i / h (the interior positions), Y_i = z_i / h and the interior impulses: with
// them every row's derivative is O(1), and its h -> 0 limit J0 is the consistency limit of every quadrature
// (𝓛 / h -> L at the chord, so a node row tends to L_q'(U_i) - L_q'(U_{i+1}) - A^T lambda, U_i the stage chords):
// J0 is built from M = L_q'q', A and p = L_q' at the point. With J0 exact at order 0 and a start exact at order 0
// (every stage chord the point's velocity), each iteration gains one order of the series (the error of degree d
// leaves (J - J0) e + O(e^2), both of degree >= d + 1), so the series need as many iterations as their precision;
// in double the same iteration converges like h^k.
//
// Off the constraint (a point whose velocity does not satisfy Phi, where the engine still evaluates the
// modified equation and reports the modified constraint's value), the stages are asked for the same defect as
// the first one (Phi o Psi: Phi_d of stage i equals Phi_d of stage 1) or the defect interpolated linearly in the
// stage time (holonomic: g(t_i, Q_i) between g(t_j, q_j) and g(t_{j+1}, q_{j+1})): on the constraint that is
// the composition itself, and off it the analogue of the engine's extension for one step (the modified flow
// keeps the discrete constraint's defect constant), with every stage chord equal to leading order — the
// expansion in h stays regular there.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include <Eigen/LU>

#include "geomint/generic/composition_families.hpp"
#include "geomint/generic/schemes.hpp"
#include "geomint/modified/series.hpp"

namespace geomint::modified {

// How the stage solve reads a scalar: its value at eps = h = 0, its precision (series: the total degree below which
// its coefficients are known; numbers: none), a size for the convergence test of numbers, and (series) a copy
// computed only below a lower precision, and an update whose unknown coefficients count as zero.
template <class S>
struct StageScalar {
  static constexpr bool series = false;
  static double leading(const S& x) { return static_cast<double>(x); }
  static int precision(const S&) { return series_exact; }
  static double size(const S& x) { return std::abs(static_cast<double>(x)); }
  static S truncated(const S& x, int) { return x; }
  static S widened(const S& x) { return x; }
  static S shifted(const S& x, double) { return x; }  // series only (see ComposedResidual::shifted)
};
template <int E, int U, int L>
struct StageScalar<BiSeries<E, U, L, double>> {
  static constexpr bool series = true;
  using S = BiSeries<E, U, L, double>;
  static double leading(const S& x) { return x.value(); }
  static int precision(const S& x) { return x.p; }
  static double size(const S& x) {
    double s = 0;
    for (int j = 0; j <= x.j1; ++j)
      for (int k = x.k0; k <= x.k1; ++k) s = std::max(s, std::abs(x.at(j, k)));
    return s;
  }
  static S truncated(S x, int p) {
    if (p < x.p) {
      x.p = p;
      x.clip();
    }
    return x;
  }
  static S widened(S x) {
    x.p = series_exact;
    return x;
  }
  static S shifted(const S& x, double s) { return shifted_by_steps(x, s); }
};

template <class Sys, class Scheme>
class ComposedResidual {
 public:
  static constexpr int n = Sys::dof, m = Sys::constraints;
  static constexpr bool contact = Scheme::contact;
  static constexpr bool holonomic = generic::has_holonomic_v<Sys>;
  static constexpr int nz = contact ? 1 : 0;
  using Quad = typename Scheme::quadrature;

  explicit ComposedResidual(const generic::CompositionFamily& family) : family_(family.name) {
    static_assert(Scheme::order == 2, "a composition needs a symmetric (second-order) base scheme");
    if (family.weights.empty()) throw std::invalid_argument("composition family '" + family.name + "' has no weights");
    long double c = 0;  // c_i = w_1 + ... + w_i, summed in long double as Composition does
    offset_.push_back(0.0);
    for (const long double w : family.weights) {
      w_.push_back(static_cast<double>(w));
      c += w;
      offset_.push_back(static_cast<double>(c));
    }
  }
  int stages() const { return static_cast<int>(w_.size()); }
  const std::string& family() const { return family_; }

  // One step q0 -> q1 (from t, of size h) with its interior stage points solved.
  template <class S>
  struct Step {
    std::vector<Vec<S, n>> Q;       // Q[0] = q0, Q[1..s-1] the interior stage points, Q[s] = q1
    std::vector<S> Z;               // contact: z at the stage points, Z[0] = z0, Z[s] = z1
    std::vector<Vec<S, m>> lambda;  // lambda[i - 1]: the impulse the stage i + 1 applies at Q[i]
    S action = S(0);                // sum of the stages' discrete actions
    Vec<S, m> phi = Vec<S, m>::Zero();      // the composition's discrete constraint (see the header)
    Vec<S, m> impulse = Vec<S, m>::Zero();  // the interior impulses summed
    int iterations = 0;
  };

  // `start` (series only): the same step solved before for endpoints that differ from these only in high
  // coefficients (the engine's previous order): its stage points are then correct up to the degree where the
  // endpoints changed, and only the orders above are iterated. `with_action`: also the sum of the stages' actions
  // (Step::action; 0 otherwise).
  template <class S>
  Step<S> step(const Sys& sys, const S& t, const S& h, const Vec<S, n>& q0, const Vec<S, n>& q1, const S& z0,
               const S& z1, const Step<S>* start = nullptr, bool with_action = true) const {
    using Sc = StageScalar<S>;
    const int s = stages();
    int ni = s - 1;
    Step<S> st;
    st.Q.resize(static_cast<std::size_t>(s + 1));
    st.Z.resize(static_cast<std::size_t>(s + 1));
    st.lambda.assign(static_cast<std::size_t>(std::max(ni, 0)), Vec<S, m>::Zero());
    // The start. Cold: every stage on the chord q0 -> q1 (z likewise), exact at order 0 and wrong from degree 2 in
    // the stage points (level 1, in the scaled unknowns). Warm: the stage points of `start`, wrong from the
    // level where the endpoints changed or where `start` was no longer known.
    int level = 1;
    const bool warm = Sc::series && start != nullptr && start->Q.size() == st.Q.size();
    const Vec<S, n> dq = q1 - q0;
    const S dz = z1 - z0;
    for (int i = 0; i <= s; ++i) {
      const auto I = static_cast<std::size_t>(i);
      if (i == 0 || i == s) {
        st.Q[I] = i == 0 ? q0 : q1;
        st.Z[I] = i == 0 ? z0 : z1;
      } else if (warm) {
        st.Q[I] = start->Q[I];
        st.Z[I] = start->Z[I];
        st.lambda[I - 1] = start->lambda[I - 1];
      } else {
        st.Q[I] = Vec<S, n>(q0 + dq * offset_[I]);
        st.Z[I] = S(z0 + dz * offset_[I]);
      }
    }
    if constexpr (Sc::series) {
      if (warm) {
        // the level of a change: a stage point's degree - 1, an impulse's or a z's degree (the engine's z, and so the
        // stages' z, are wanted one degree lower than q: a change in z at degree d moves the rows at degree d)
        level = series_exact;
        // the lowest degree where a and b differ by more than round-off (a start built by shifted_back computes
        // the same coefficients by other operations), or where b is no longer known
        auto changed = [](const S& a, const S& b) {
          const S d = a - b;
          const double tol = 64 * std::numeric_limits<double>::epsilon() * std::max(Sc::size(a), Sc::size(b));
          int deg = std::min(a.p, b.p);
          for (int j = 0; j <= d.j1; ++j)
            for (int k = d.k0; k <= d.k1; ++k)
              if (std::abs(d.at(j, k)) > tol) deg = std::min(deg, j + k);
          return deg;
        };
        for (int r = 0; r < n; ++r)
          level = std::min({level, changed(q0(r), start->Q.front()(r)) - 1, changed(q1(r), start->Q.back()(r)) - 1});
        if constexpr (contact) level = std::min({level, changed(z0, start->Z.front()), changed(z1, start->Z.back())});
        for (int i = 1; i < s; ++i) {
          const auto I = static_cast<std::size_t>(i);
          for (int r = 0; r < n; ++r) level = std::min(level, st.Q[I](r).p - 1);
          if constexpr (contact) level = std::min(level, st.Z[I].p);
          for (int c = 0; c < m; ++c) level = std::min(level, st.lambda[I - 1](c).p);
        }
        level = std::max(level, 1);
        int precision = series_exact;
        for (int r = 0; r < n; ++r) precision = std::min({precision, q0(r).p, q1(r).p});
        if (level >= precision - 1) {
          // nothing to iterate: the start is the solution to the precision of these endpoints
          for (int i = 1; i < s; ++i) {
            const auto I = static_cast<std::size_t>(i);
            for (int r = 0; r < n; ++r) st.Q[I](r) = Sc::truncated(st.Q[I](r), precision);
            if constexpr (contact) st.Z[I] = Sc::truncated(st.Z[I], precision - 1);
            for (int c = 0; c < m; ++c) st.lambda[I - 1](c) = Sc::truncated(st.lambda[I - 1](c), precision - 1);
          }
          ni = 0;
        } else {
          // the start's provisional coefficients are the iteration's to correct
          for (int i = 1; i < s; ++i) {
            const auto I = static_cast<std::size_t>(i);
            for (int r = 0; r < n; ++r) st.Q[I](r) = Sc::widened(st.Q[I](r));
            if constexpr (contact) st.Z[I] = Sc::widened(st.Z[I]);
            for (int c = 0; c < m; ++c) st.lambda[I - 1](c) = Sc::widened(st.lambda[I - 1](c));
          }
        }
      }
    }
    if (ni > 0) solve_interior(sys, t, h, st, level, warm);
    for (int i = 1; with_action && i <= s; ++i) {
      const auto I = static_cast<std::size_t>(i);
      const S ti = t + h * offset_[I - 1], hi = h * w_[I - 1];
      if constexpr (contact)
        st.action += Quad::action(sys, ti, hi, st.Q[I - 1], st.Q[I], st.Z[I - 1], st.Z[I]);
      else
        st.action += Quad::action(sys, ti, hi, st.Q[I - 1], st.Q[I]);
    }
    if constexpr (m > 0) {
      if constexpr (holonomic)
        st.phi = stage_constraint(sys, t, h, st, s);
      else
        st.phi = stage_constraint(sys, t, h, st, 1);
      for (const auto& l : st.lambda) st.impulse += l;
    }
    return st;
  }

  // Series: the step one step earlier, from a step's series in (eps, h) (eps -> eps - h: the step from t - h is
  // the step from t seen one step back), known below total degree E + 1 — a start for step() that needs few
  // iterations or none.
  template <class S>
  Step<S> shifted_back(const Step<S>& st) const {
    static_assert(StageScalar<S>::series, "a shift in eps is an operation on series");
    using Sc = StageScalar<S>;
    Step<S> out;
    for (const auto& x : st.Q) out.Q.push_back(x.unaryExpr([](const S& y) { return Sc::shifted(y, -1); }));
    for (const auto& x : st.Z) out.Z.push_back(Sc::shifted(x, -1));
    for (const auto& x : st.lambda) out.lambda.push_back(x.unaryExpr([](const S& y) { return Sc::shifted(y, -1); }));
    return out;
  }

  // The residual at the junction q = before.Q[s] = after.Q[0] (time t): the base residual between the last stage
  // of the step before (w_s h) and the first stage of the step after (w_1 h), with the impulse lambda there.
  template <class S>
  Vec<S, n> residual(const Sys& sys, const S& t, const S& h, const Step<S>& before, const Step<S>& after,
                     const Vec<S, m>& lambda) const {
    const auto s = static_cast<std::size_t>(stages());
    const S hb = h * w_.back(), ha = h * w_.front();
    if constexpr (contact)
      return Scheme::residual_between(sys, t, hb, ha, before.Q[s - 1], after.Q[0], after.Q[1], before.Z[s - 1], after.Z[0],
                                      after.Z[1], lambda);
    else
      return Scheme::residual_between(sys, t, hb, ha, before.Q[s - 1], after.Q[0], after.Q[1], lambda);
  }

  // The rows of the interior problem at the current stage points (for the solve and for tests): the node
  // residuals (n each), the action rows (contact, divided by h) and the constraint rows (m each).
  template <class S>
  struct InteriorRows {
    std::vector<Vec<S, n>> node;
    std::vector<S> action;
    std::vector<Vec<S, m>> constraint;
  };
  template <class S>
  InteriorRows<S> interior_rows(const Sys& sys, const S& t, const S& h, const Step<S>& st) const {
    const int s = stages();
    InteriorRows<S> r;
    Vec<S, m> first = Vec<S, m>::Zero(), g0 = Vec<S, m>::Zero(), g1 = Vec<S, m>::Zero();
    if constexpr (m > 0 && !holonomic) first = stage_constraint(sys, t, h, st, 1);
    if constexpr (holonomic) {
      g0 = sys.holonomic(t, st.Q.front());
      g1 = sys.holonomic(S(t + h * offset_.back()), st.Q.back());
    }
    for (int i = 1; i < s; ++i) {
      const auto I = static_cast<std::size_t>(i);
      const S ti = t + h * offset_[I];
      const S hb = h * w_[I - 1], ha = h * w_[I];
      if constexpr (contact)
        r.node.push_back(Scheme::residual_between(sys, ti, hb, ha, st.Q[I - 1], st.Q[I], st.Q[I + 1], st.Z[I - 1], st.Z[I],
                                                  st.Z[I + 1], st.lambda[I - 1]));
      else
        r.node.push_back(Scheme::residual_between(sys, ti, hb, ha, st.Q[I - 1], st.Q[I], st.Q[I + 1], st.lambda[I - 1]));
      if constexpr (contact)
        r.action.push_back((st.Z[I] - st.Z[I - 1] -
                            Quad::action(sys, S(t + h * offset_[I - 1]), hb, st.Q[I - 1], st.Q[I], st.Z[I - 1], st.Z[I])) /
                           h);
      if constexpr (m > 0) {
        if constexpr (holonomic)  // g at the stage end, against g interpolated between the step's ends
          r.constraint.push_back(Vec<S, m>((stage_constraint(sys, t, h, st, i) - g0 * (1 - offset_[I]) - g1 * offset_[I]) / h));
        else  // stage i + 1 with the defect of stage 1
          r.constraint.push_back(Vec<S, m>(stage_constraint(sys, t, h, st, i + 1) - first));
      }
    }
    return r;
  }

 private:
  // Phi_d of stage i (1-based): the base's discrete constraint over Q[i-1] -> Q[i] with step w_i h.
  template <class S>
  Vec<S, m> stage_constraint(const Sys& sys, const S& t, const S& h, const Step<S>& st, int i) const {
    const auto I = static_cast<std::size_t>(i);
    return generic::discrete_constraint<Sys, Quad, S>(sys, S(t + h * offset_[I - 1]), S(h * w_[I - 1]), st.Q[I - 1], st.Q[I]);
  }

  // M = L_q'q' and p = L_q' at (t, q, v[, z]) (the h -> 0 limit of the rows' derivatives, see the header).
  static void leading_data(const Sys& sys, double t, const Vec<double, n>& q, const Vec<double, n>& v, double z,
                           Mat<double, n, n>& M, Vec<double, n>& p) {
    using D = Dual<double, n>;
    Vec<D, n> V;
    for (int i = 0; i < n; ++i) V(i) = D::variable(v(i), i);
    Vec<D, n> P;
    if constexpr (contact)
      P = generic::herglotz_momentum<Sys, D>(sys, D(t), Vec<D, n>(q.template cast<D>()), V, D(z));
    else
      P = generic::momentum<Sys, D>(sys, D(t), Vec<D, n>(q.template cast<D>()), V);
    for (int i = 0; i < n; ++i) {
      p(i) = P(i).v;
      for (int k = 0; k < n; ++k) M(i, k) = P(i).d[static_cast<std::size_t>(k)];
    }
  }

  // `level`: the unknowns are right below it (X_i, the impulses and Y_i at degree `level`; see step).
  template <class S>
  void solve_interior(const Sys& sys, const S& t, const S& h, Step<S>& st, int level, bool warm) const {
    using Sc = StageScalar<S>;
    const int s = stages(), ni = s - 1, b = n + m;  // (X_i, lambda) block per interior node
    const int N = ni * b;
    // the point: t, q0, the chord velocity (q1 - q0)/h and z0 at order 0
    const double t0 = Sc::leading(t);
    Vec<double, n> q, v;
    const Vec<S, n> chord = (st.Q.back() - st.Q.front()) / h;
    for (int i = 0; i < n; ++i) {
      q(i) = Sc::leading(st.Q.front()(i));
      v(i) = Sc::leading(chord(i));
    }
    const double z = Sc::leading(st.Z.front());
    Mat<double, n, n> M;
    Vec<double, n> p;
    leading_data(sys, t0, q, v, z, M, p);
    Mat<double, m, n> A = Mat<double, m, n>::Zero();
    if constexpr (m > 0) A = sys.constraint_matrix(t0, q);
    // J0 on (X_1, lambda_2, ..., X_{s-1}, lambda_s) from the node and constraint rows
    Eigen::MatrixXd J = Eigen::MatrixXd::Zero(N, N);
    auto X = [&](int i) { return (i - 1) * b; };      // column of X_i (i = 1..s-1)
    auto Lm = [&](int i) { return (i - 1) * b + n; };  // column of the impulse at Q_i
    for (int i = 1; i <= ni; ++i) {
      const double wb = w_[static_cast<std::size_t>(i - 1)], wa = w_[static_cast<std::size_t>(i)];
      const int r = (i - 1) * b;
      J.block(r, X(i), n, n) += M * (1 / wb + 1 / wa);
      if (i > 1) J.block(r, X(i - 1), n, n) -= M / wb;
      if (i < ni) J.block(r, X(i + 1), n, n) -= M / wa;
      if constexpr (m > 0) {
        J.block(r, Lm(i), n, m) = -A.transpose();
        const int rc = r + n;
        if constexpr (holonomic) {
          J.block(rc, X(i), m, n) += A;
        } else {
          // Phi_d of stage i + 1 (over Q_i -> Q_{i+1}) minus Phi_d of stage 1 (over q0 -> Q_1)
          J.block(rc, X(i), m, n) -= A / wa;
          if (i < ni) J.block(rc, X(i + 1), m, n) += A / wa;
          J.block(rc, X(1), m, n) -= A / w_.front();
        }
      }
    }
    const Eigen::PartialPivLU<Eigen::MatrixXd> lu(J);
    const Eigen::MatrixXd Jinv = lu.inverse();
    if (!Jinv.allFinite()) throw std::domain_error("composition " + family_ + ": singular stage problem");

    // Series: an iteration corrects one level (the coefficients of degree level + 1 of the stage points, level of
    // the impulses), so from `level` P - 1 - level iterations give every coefficient below the inputs' precision P
    // (the impulses and z below P - 1, as the engine's inputs) — tests/modified/composition_modified.test.cpp checks that
    // the rows then vanish coefficient by coefficient. An iteration needs its rows only below degree level + 1:
    // it works on copies computed to precision level + 2, and its update leaves the higher, provisional
    // coefficients to the next ones; the last one runs at full precision, so the results carry their own
    // precision honestly. Numbers: to round-off.
    int precision = series_exact;
    for (int i = 0; i < n; ++i)
      precision = std::min({precision, Sc::precision(st.Q.front()(i)), Sc::precision(st.Q.back()(i))});
    const int max_iterations = Sc::series ? (precision >= series_exact ? 24 : std::max(precision - 1 - level, warm ? 1 : 0)) : 60;
    std::vector<S> rhs(static_cast<std::size_t>(N));
    double last_change = 0;
    for (int it = 0; it < max_iterations; ++it) {
      const int work = Sc::series && precision < series_exact ? std::min(precision, level + it + 2) : series_exact;
      const bool partial = work < precision;
      Step<S> cut;
      const Step<S>* at = &st;
      if (partial) {
        cut.Q = st.Q;
        cut.Z = st.Z;
        cut.lambda = st.lambda;
        for (auto& x : cut.Q)
          for (int r = 0; r < n; ++r) x(r) = Sc::truncated(x(r), work);
        for (auto& x : cut.Z) x = Sc::truncated(x, work - 1);
        for (auto& x : cut.lambda)
          for (int c = 0; c < m; ++c) x(c) = Sc::truncated(x(c), work - 1);
        at = &cut;
      }
      auto update = [&](const S& x) { return partial ? Sc::widened(x) : x; };
      const auto R = interior_rows(sys, Sc::truncated(t, work), h, *at);
      for (int i = 1; i <= ni; ++i) {
        const auto I = static_cast<std::size_t>(i - 1);
        for (int r = 0; r < n; ++r) rhs[static_cast<std::size_t>((i - 1) * b + r)] = R.node[I](r);
        if constexpr (m > 0)
          for (int c = 0; c < m; ++c) rhs[static_cast<std::size_t>((i - 1) * b + n + c)] = R.constraint[I](c);
      }
      // (dX, dlambda) = -J0^{-1} (node, constraint rows): scaled products only (a double times a series)
      std::vector<S> d(static_cast<std::size_t>(N), S(0));
      for (int a = 0; a < N; ++a) {
        S acc(0);
        for (int c = 0; c < N; ++c) {
          const double j = Jinv(a, c);
          if (j != 0) acc -= rhs[static_cast<std::size_t>(c)] * j;
        }
        d[static_cast<std::size_t>(a)] = acc;
      }
      double change = 0, size = 0;
      Vec<S, n> dX_prev = Vec<S, n>::Zero();
      S dY_prev(0);
      for (int i = 1; i <= ni; ++i) {
        const auto I = static_cast<std::size_t>(i);
        Vec<S, n> dX;
        for (int r = 0; r < n; ++r) dX(r) = d[static_cast<std::size_t>((i - 1) * b + r)];
        Vec<S, n> dQ = dX * h;
        for (int r = 0; r < n; ++r) dQ(r) = update(dQ(r));
        st.Q[I] += dQ;
        if constexpr (m > 0)
          for (int c = 0; c < m; ++c) st.lambda[I - 1](c) += update(d[static_cast<std::size_t>((i - 1) * b + n + c)]);
        if constexpr (contact) {
          // the action rows: dY_i - dY_{i-1} - p.(dX_i - dX_{i-1}) = -row (J0 is lower triangular there)
          const S dY = dY_prev + (dX - dX_prev).dot(p.template cast<S>()) - R.action[I - 1];
          st.Z[I] += update(S(dY * h));
          if constexpr (!Sc::series) {
            change = std::max(change, Sc::size(dY * h));
            size = std::max(size, Sc::size(st.Z[I]));
          }
          dY_prev = dY;
        }
        dX_prev = dX;
        if constexpr (!Sc::series)
          for (int r = 0; r < n; ++r) {
            change = std::max(change, Sc::size(dQ(r)));
            size = std::max(size, Sc::size(st.Q[I](r)));
          }
      }
      st.iterations = it + 1;
      if constexpr (!Sc::series) {
        if (change <= 4 * std::numeric_limits<double>::epsilon() * (1 + size)) return;
        last_change = change;
      }
    }
    // Numbers: a chord iteration that has not reached round-off (h too large for J0, or a point far off the
    // constraint) would hand back stage points that solve nothing.
    if constexpr (!Sc::series)
      throw std::domain_error("composition " + family_ + " at t = " + std::to_string(t0) + ", h = " +
                              std::to_string(Sc::leading(h)) + ": the stage points did not converge in " +
                              std::to_string(max_iterations) + " chord iterations (last change " +
                              std::to_string(last_change) + ")");
  }

  std::string family_;
  std::vector<double> w_;       // w_1 .. w_s
  std::vector<double> offset_;  // c_0 = 0, c_i = w_1 + ... + w_i (c_s = 1)
};

}  // namespace geomint::modified
