#pragma once
// Automatic modified equations of any two-step scheme of the generic core, to any order K <= Kmax, from the
// scheme's own templated residual (core/include/geomint/generic/schemes.hpp) — no scheme is restated here.
//
// The modified equation q'' = F_0 + h F_1 + ... + h^K F_K (with, for contact schemes, z' = Z_0 + h Z_1 + ...,
// and for constrained schemes the multiplier mu = mu_0 + h mu_1 + ... and the modified constraint) is the
// equation whose solutions q~ satisfy the scheme's discrete equations identically in t:
//   R(t, h, q~(t-h), q~(t), q~(t+h), [z~(t-h), z~(t), z~(t+h)], h mu~(t)) = 0,   Phi_d(q~(t), q~(t+h)) = 0.
// How it is solved. Through the point (t, q, v, z) the modified solution is a Taylor series in time,
//   q~(t + eps) = sum_m c_m eps^m,  c_0 = q, c_1 = v,  c_m = sum_i c_m^(i) h^i  (unknown for m >= 2),
// and likewise z~ (d_m^(i)) and mu~ (l_m^(i)). The shifted points q~(t + eps +- h) are exact polynomials in
// (eps, h) built from the same coefficients. Feeding them, as BiSeries, to the residual gives
// G(eps, h) = R/h, whose coefficients must all vanish: the eps^j coefficients say that the modified equation
// holds along the flow (Taylor mode: they determine the higher time derivatives), the h^k ones that it holds
// to order k. Weight c_m^(i) by m + i - 2 (d_m^(i) by m + i - 1, l_m^(i) by m + i): the unknowns of weight W
// enter the coefficients of total degree W of G linearly, through the leading part of every consistent
// three-point scheme, J (q~(t+h) - 2 q~(t) + q~(t-h))/(2h^2) - A^T mu, and everything else at that degree
// is already known. So the engine evaluates the residual once per weight W = 0..K, with the unknowns of that
// weight set to zero, and solves a small triangular system for them (j = W down to 0):
//   G row j:        J binom(j+2, 2) c_{j+2}^(W-j) + K0 l_j^(W-j) = -(G_{j, W-j} + known same-weight terms),
//   constraint row: P binom(j+2, j+o) c_{j+2}^(W-j)                = -(Phi_{j+o, W+o-j} + ...),
// (o = 1 for Phi o Psi, o = 2 for a holonomic g(t_{j+1}, q_{j+1})), and for contact
//   z row j:        (j+1) d_{j+1}^(W-j) = -(Gz_{j, W-j} + ...),  Gz = (z(t+h) - z(t) - action)/h.
// J = dG_00/dc_2^(0) (= -2 L_q'q' for the schemes here), K0 = dG_00/dl_0^(0) (= -A^T) and P (= A) are read off
// the residual itself by probing at weight 0 (it is affine there). F_k = 2 c_2^(k), Z_k = d_1^(k),
// mu_k = l_0^(k). The constraint rows that no unknown pins (row 0 for Phi o Psi; rows 0, 1 for holonomic)
// are the modified constraint: Phi_h(t, q, v) = Phi_d(q~(t), q~(t+h)) = sum_k h^k phi_k must vanish at the
// initial point; the other rows make the modified flow keep Phi_h constant.
// `check` re-evaluates the residual with every coefficient in place and returns the largest coefficient of
// total degree <= K that should vanish (a self-test of the structure above, at round-off).
//
// One engine, two coefficient types: with C = double (the default) everything above is numbers at a point;
// with a computer-algebra C (symbolic.hpp: GiNaC::ex) the point (t, q, v, z) and the system's parameters are
// symbols and the same operations return F_k, Z_k, mu_k, phi_k as formulas. The small linear systems are then
// solved exactly (solve_linear below) and each solved coefficient is simplified as it is found (per order and
// per coefficient: the next orders are built from it, so swell is stopped where it starts).
//
// Compositions. Constructed with a coefficient family, the engine of a symmetric scheme gives the modified
// equation of the composition of that scheme (generic/composition.hpp): its residual is then the composition's
// three-point residual (composed_residual.hpp: the base residual at the junction of two steps, with every step's
// stage points solved from the base residual at the stage steps w_i h), which has the leading structure above, so
// nothing else changes. The family is run-time data: the same instantiation serves the scheme and all its
// compositions. For a constrained composition mu is the step's total impulse per unit step (all its stages, as
// Composition reports it) and Phi_h its discrete constraint (the first stage's Phi o Psi, or the last stage's g).
// Numbers only (the formulas of a composition would carry its stage solve: refused by the registry).
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

#include <Eigen/LU>

#include "geomint/error.hpp"
#include "geomint/generic/schemes.hpp"
#include "geomint/modified/composed_residual.hpp"
#include "geomint/modified/series.hpp"

namespace geomint::modified {

inline double binomial(int m, int j) {
  if (j < 0 || j > m) return 0;
  double b = 1;
  for (int i = 0; i < j; ++i) b = b * (m - i) / (i + 1);
  return b;
}

// The exact value of an integer-valued (or dyadic) double in the coefficient type.
template <class C>
C exact(double x) {
  return CoefficientTraits<C>::from_number(x);
}

// A x = b for the engine's small systems: LU with partial pivoting in double, the CAS's exact solve otherwise
// (CoefficientTraits<C>::solve).
template <class C, int N>
Vec<C, N> solve_linear(const Mat<C, N, N>& A, const Vec<C, N>& b) {
  if constexpr (std::is_same_v<C, double>)
    return Eigen::PartialPivLU<Mat<double, N, N>>(A).solve(b);
  else
    return CoefficientTraits<C>::template solve<N>(A, b);
}

template <int n, int m, int Kmax, class C = double>
struct ModifiedCoefficients {
  int K = 0;
  std::array<Vec<C, n>, Kmax + 1> F{};      // q'' = sum h^k F[k]
  std::array<C, Kmax + 1> Z{};              // z'  = sum h^k Z[k] (contact)
  std::array<Vec<C, m>, Kmax + 1> mu{};     // multiplier (impulse / h) = sum h^k mu[k]
  std::array<Vec<C, m>, Kmax + 3> phi{};    // modified constraint Phi_h = sum h^k phi[k] (k <= K + o)
  std::array<Vec<C, m>, Kmax + 3> phi_dot{};// holonomic only: its time derivative along the flow
  // Taylor coefficients of the modified solution through the point: q~(t + s) = sum_m c[m] s^m,
  // c[m] = sum_i c_coef[m][i] h^i (m <= K + 2, i <= K); the same for z~.
  std::array<std::array<Vec<C, n>, Kmax + 1>, Kmax + 3> c{};
  std::array<std::array<C, Kmax + 1>, Kmax + 3> d{};
  double residual = missing_value;  // set by check (numbers only)
  bool stopped = false;  // the deadline passed before order K (formulas): K is the order reached

  // Eigen's fixed-size vectors are not zeroed by value-initialization: every coefficient starts at 0 here.
  ModifiedCoefficients() {
    for (auto& x : F) x.setZero();
    for (auto& x : mu) x.setZero();
    for (auto& x : phi) x.setZero();
    for (auto& x : phi_dot) x.setZero();
    for (auto& row : c)
      for (auto& x : row) x.setZero();
    for (auto& row : d) row.fill(C(0));
    Z.fill(C(0));
  }
};

template <class Sys, class Scheme, int Kmax = 6, class C = double>
class ModifiedEquation {
 public:
  static constexpr int n = Sys::dof, m = Sys::constraints;
  static constexpr bool contact = Scheme::contact;
  static constexpr bool holonomic = generic::has_holonomic_v<Sys>;
  static constexpr int o = holonomic ? 2 : 1;  // constraint row paired with G row j: j + o
  static constexpr int E = Kmax + (m > 0 ? o : 0);
  static constexpr int U = Kmax + 3;
  using S = BiSeries<E, U, 2, C>;
  using Quad = typename Scheme::quadrature;
  using Result = ModifiedCoefficients<n, m, Kmax, C>;
  using coefficient = C;
  // Whether this scheme has compositions here (a symmetric scheme, numbers).
  static constexpr bool composable = Scheme::order == 2 && std::is_same_v<C, double>;
  using Composed = ComposedResidual<Sys, Scheme>;

  explicit ModifiedEquation(const Sys& sys) : sys_(sys) {}
  // The modified equation of the composition of Scheme with `family` (see the header).
  ModifiedEquation(const Sys& sys, const generic::CompositionFamily& family)
      : sys_(sys), composed_(std::make_shared<const Composed>(family)) {
    static_assert(composable, "compositions are of symmetric schemes, in numbers");
  }
  const Sys& system() const { return sys_; }
  // The composition's residual, or null for the scheme itself.
  const Composed* composition() const { return composed_.get(); }
  // A formula can take long (expression swell): the orders stop being built once `deadline` has passed, and
  // the result says so (Result::stopped, Result::K the order reached). Numbers never look at the clock.
  void set_deadline(std::chrono::steady_clock::time_point deadline) { deadline_ = deadline; }

  // F_0..F_K (and Z, mu, phi) at (t, q, v, z). K <= Kmax.
  void evaluate(const C& t, const Vec<C, n>& q, const Vec<C, n>& v, const C& z, int K, Result& out,
                bool check = false) const {
    evaluate_to(t, q, v, z, K, out, check, true);
  }

 private:
  // multiplier: also the multiplier of a constrained composition (its stages' impulses: one more evaluation)
  void evaluate_to(const C& t, const Vec<C, n>& q, const Vec<C, n>& v, const C& z, int K, Result& out, bool check,
                   bool multiplier) const {
    if (K < 0 || K > Kmax) throw std::invalid_argument("modified equation order K must be in [0, " + std::to_string(Kmax) + "]");
    out = Result{};
    out.K = K;
    out.c[0][0] = q;
    out.c[1][0] = v;
    out.d[0][0] = z;
    Lambda l;
    for (auto& row : l)
      for (auto& x : row) x.setZero();

    // Weight 0, and the probes J, K0, P (the residual is affine in the weight-0 unknowns at degree 0).
    StageCache cache;  // a composition's stage points, from one evaluation to the next
    Rows base = rows(t, out, l, 0, &cache);
    Mat<C, n, n> J;
    Mat<C, n, m> K0;
    Mat<C, m, n> P;
    for (int r = 0; r < n; ++r) {
      out.c[2][0](r) = C(1);
      const Rows pr = rows(t, out, l, 0, &cache, false);
      out.c[2][0](r) = C(0);
      for (int i = 0; i < n; ++i) J(i, r) = Tr::simplify(pr.G[i].coeff(0, 0) - base.G[i].coeff(0, 0));
      for (int c = 0; c < m; ++c)
        P(c, r) = Tr::simplify((pr.Phi[c].coeff(o, 0) - base.Phi[c].coeff(o, 0)) / exact<C>(binomial(2, o)));
    }
    for (int r = 0; r < m; ++r) {
      l[0][0](r) = C(1);
      const Rows pr = rows(t, out, l, 0, &cache, false);
      l[0][0](r) = C(0);
      for (int i = 0; i < n; ++i) K0(i, r) = Tr::simplify(pr.G[i].coeff(0, 0) - base.G[i].coeff(0, 0));
    }
    // z enters the q rows at the same degree only if L_q'z != 0 (not for L - alpha z): probe it.
    bool z_couples = false;
    if constexpr (contact) {
      out.d[1][0] = C(1);
      const Rows pr = rows(t, out, l, 0, &cache, false);
      out.d[1][0] = C(0);
      for (int i = 0; i < n; ++i)
        if (!Tr::is_zero(Tr::simplify(pr.G[i].coeff(0, 0) - base.G[i].coeff(0, 0)))) z_couples = true;
    }

    for (int W = 0; W <= K; ++W) {
      if constexpr (!std::is_same_v<C, double>) {
        if (W > 0 && std::chrono::steady_clock::now() > deadline_) {
          K = out.K = W - 1;
          out.stopped = true;
          break;
        }
      }
      Rows R = W == 0 ? base : rows(t, out, l, W, &cache);
      if constexpr (contact) {
        for (int j = W; j >= 0; --j) {
          C g = known(R.Gz, j, W - j);
          for (int mm = j + 2; mm <= W + 1; ++mm) g += exact<C>(binomial(mm, j)) * out.d[mm][W + 1 - mm];
          out.d[j + 1][W - j] = Tr::simplify(-g / exact<C>(j + 1));
        }
        if (z_couples) R = rows(t, out, l, W, &cache);  // the q rows with this weight's z coefficients in place
      }
      for (int j = W; j >= 0; --j) {
        Vec<C, n> g;
        for (int i = 0; i < n; ++i) g(i) = known(R.G[i], j, W - j);
        for (int mm = j + 4; mm <= W + 2; mm += 2) g += J * (exact<C>(binomial(mm, j)) * out.c[mm][W + 2 - mm]);
        if constexpr (m == 0) {
          out.c[j + 2][W - j] = simplified<n>(-solve_linear<C, n>(J * exact<C>(binomial(j + 2, 2)), g));
        } else {
          Vec<C, m> gp;
          for (int c = 0; c < m; ++c) gp(c) = known(R.Phi[c], j + o, W - j);
          for (int mm = j + 3; mm <= W + 2; ++mm) gp += P * (exact<C>(binomial(mm, j + o)) * out.c[mm][W + 2 - mm]);
          Mat<C, n + m, n + m> KKT = Mat<C, n + m, n + m>::Zero();
          KKT.template topLeftCorner<n, n>() = J * exact<C>(binomial(j + 2, 2));
          KKT.template topRightCorner<n, m>() = K0;
          KKT.template bottomLeftCorner<m, n>() = P * exact<C>(binomial(j + 2, j + o));
          Vec<C, n + m> rhs;
          rhs << g, gp;
          const Vec<C, n + m> x = simplified<n + m>(-solve_linear<C, n + m>(KKT, rhs));
          out.c[j + 2][W - j] = x.template head<n>();
          l[j][W - j] = x.template tail<m>();
        }
      }
      if constexpr (m > 0) {
        // the rows no unknown pins: the modified constraint, with this weight's coefficients added
        for (int row = 0; row < o; ++row) {
          const int deg = W + o;
          Vec<C, m> ph;
          for (int c = 0; c < m; ++c) ph(c) = known(R.Phi[c], row, deg - row);
          for (int mm = 2; mm <= W + 2; ++mm)
            if (mm - row >= (holonomic ? 0 : 1)) ph += P * (exact<C>(binomial(mm, row)) * out.c[mm][W + 2 - mm]);
          (row == 0 ? out.phi : out.phi_dot)[static_cast<std::size_t>(deg - row)] = simplified<m>(ph);
        }
        if (W == 0) {  // lower degrees: already fixed by the point (Phi = A v + b; holonomic g, g_t + g_q v)
          for (int row = 0; row < o; ++row)
            for (int deg = row; deg < o; ++deg) {
              Vec<C, m> ph;
              for (int c = 0; c < m; ++c) ph(c) = known(R.Phi[c], row, deg - row);
              (row == 0 ? out.phi : out.phi_dot)[static_cast<std::size_t>(deg - row)] = simplified<m>(ph);
            }
        }
      }
    }
    for (int k = 0; k <= K; ++k) {
      out.F[k] = simplified<n>(exact<C>(2) * out.c[2][k]);
      out.Z[k] = out.d[1][k];
      if constexpr (m > 0) out.mu[k] = l[0][k];
    }
    if constexpr (!std::is_same_v<C, double>) check = false;  // a formula is checked by the tests, not by size
    const bool composed_mu = m > 0 && multiplier && composed_ != nullptr;
    if (!check && !composed_mu) return;
    const Rows R = rows(t, out, l, K, &cache);
    if (composed_mu)  // the junction's impulse (the engine's unknown) and the interior stages' ones, per unit step
      for (int k = 0; k <= K; ++k)
        for (int c = 0; c < m; ++c) out.mu[k](c) += known(R.impulse[c], 0, k + 1);
    if (check) {
      double worst = 0;
      auto size = [](const C& x) {
        if constexpr (std::is_same_v<C, double>)
          return std::abs(x);
        else
          return 0.0;
      };
      for (int j = 0; j <= K; ++j)
        for (int k = 0; j + k <= K; ++k) {
          for (int i = 0; i < n; ++i) worst = std::max(worst, size(known(R.G[i], j, k)));
          if constexpr (contact) worst = std::max(worst, size(known(R.Gz, j, k)));
        }
      if constexpr (m > 0)
        for (int jj = o; jj <= K + o; ++jj)
          for (int k = 0; jj + k <= K + o; ++k)
            for (int c = 0; c < m; ++c) worst = std::max(worst, size(known(R.Phi[c], jj, k)));
      out.residual = worst;
    }
  }

 public:
  // The modified acceleration sum_{k<=K} h^k F_k (and z', the multiplier) at a point, for an ODE solver.
  struct Field {
    Vec<double, n> a;
    double zdot;
  };
  Field field(double t, const Vec<double, n>& q, const Vec<double, n>& v, double z, int K, double h) const {
    Result r;
    evaluate_to(t, q, v, z, K, r, false, false);
    Field f{Vec<double, n>::Zero(), 0.0};
    for (int k = K; k >= 0; --k) {
      f.a = f.a * h + r.F[k];
      f.zdot = f.zdot * h + r.Z[k];
    }
    return f;
  }

  // The modified trajectory through the point, evaluated at t + s with the Taylor coefficients of `r`
  // (truncated at s^{K+2} and h^K): q~(t + s) for small s, used to check shooting and to build starts.
  static Vec<double, n> taylor_position(const Result& r, double h, double s) {
    Vec<double, n> q = Vec<double, n>::Zero();
    for (int mm = r.K + 2; mm >= 0; --mm) {
      Vec<double, n> cm = Vec<double, n>::Zero();
      for (int i = r.K; i >= 0; --i) cm = cm * h + r.c[mm][i];
      q = q * s + cm;
    }
    return q;
  }

  // The modified Lagrangian of a variational (LA, unconstrained) scheme, to order K, on the modified flow
  // through the point of `r` (Vermeeren's meshed Lagrangian, evaluated automatically): with
  //   ell(t) = (1/h) action(q~(t - h/2), q~(t + h/2))   (the scheme's own discrete action, centred at t),
  // the meshed Lagrangian is L_mesh = [(hD/2) / sinh(hD/2)] ell = ell - h^2/24 ell'' + 7 h^4/5760 ell'''' - ...
  // (D = d/dt along the flow): its value here, sum_k h^k L[k], with q'' and higher derivatives eliminated by
  // the modified equation. For the Stormer–Verlet and midpoint rules it is exactly the published
  // L + h^2/24 (U'^2 - 2 U'' q'^2) and L + h^2/24 (U'^2 + U'' q'^2) (tests). For contact schemes the modified
  // Herglotz Lagrangian is z' = sum_k h^k Z[k] itself.
  std::array<C, Kmax + 1> mesh_lagrangian(const C& t, const Result& r) const {
    std::array<C, Kmax + 1> out{};
    out.fill(C(0));
    if constexpr (!contact) {
      const int K = r.K, pq = K + 3;
      Vec<S, n> Qm, Qp;
      for (int i = 0; i < n; ++i) {
        auto x = [&](int mm, int k) { return r.c[static_cast<std::size_t>(mm)][static_cast<std::size_t>(k)](i); };
        Qm(i) = shifted(-0.5, Kmax + 2, Kmax, pq, x);
        Qp(i) = shifted(0.5, Kmax + 2, Kmax, pq, x);
      }
      const S H = S::h();
      const S T0 = S(t) + S::eps() - H * 0.5;
      S ell;
      if constexpr (composable) {
        if (composed_)
          ell = composed_->step(sys_, T0, H, Qm, Qp, S(0), S(0)).action * inverse(H);
        else
          ell = Quad::action(sys_, T0, H, Qm, Qp) * inverse(H);
      } else {
        ell = Quad::action(sys_, T0, H, Qm, Qp) * inverse(H);
      }
      // (x/2)/sinh(x/2) = sum_r beta_r x^(2r): invert sinh(x/2)/(x/2) = sum_r (1/4)^r / (2r+1)!
      std::array<C, Kmax / 2 + 2> beta{}, sh{};
      double f = 1;
      for (int i = 0; i < static_cast<int>(sh.size()); ++i) {
        if (i > 0) f *= (2.0 * i) * (2.0 * i + 1);
        sh[static_cast<std::size_t>(i)] = exact<C>(std::pow(0.25, i)) / exact<C>(f);
      }
      for (std::size_t i = 0; i < beta.size(); ++i) {
        C acc = i == 0 ? C(1) : C(0);
        for (std::size_t k = 1; k <= i; ++k) acc -= sh[k] * beta[i - k];
        beta[i] = acc;
      }
      for (int k = 0; k <= K; ++k) {
        C acc = C(0);
        double fact = 1;
        for (int rr = 0; 2 * rr <= k; ++rr) {
          if (rr > 0) fact *= (2.0 * rr - 1) * (2.0 * rr);
          acc += beta[static_cast<std::size_t>(rr)] * exact<C>(fact) * known(ell, 2 * rr, k - 2 * rr);
        }
        out[static_cast<std::size_t>(k)] = Tr::simplify(acc);
      }
    } else {
      for (int k = 0; k <= r.K; ++k) out[static_cast<std::size_t>(k)] = r.Z[static_cast<std::size_t>(k)];
    }
    return out;
  }

 private:
  using Tr = CoefficientTraits<C>;
  using Lambda = std::array<std::array<Vec<C, m>, Kmax + 1>, Kmax + 1>;

  template <int N>
  static Vec<C, N> simplified(Vec<C, N> x) {
    for (int i = 0; i < N; ++i) x(i) = Tr::simplify(x(i));
    return x;
  }
  struct Rows {
    std::array<S, n> G;
    S Gz;
    std::array<S, m> Phi;
    std::array<S, m> impulse{};  // a composition: the interior stages' impulses of the step from t
  };

  static C known(const S& x, int j, int k) {
    if (!x.known(j, k)) throw std::logic_error("modified equation: a needed series coefficient was lost to truncation");
    return x.coeff(j, k);
  }

  // sum_m x_m (eps + s h)^m with x_m = sum_i x_m^(i) h^i, known below total degree p.
  template <class Coef>
  static S shifted(double s, int M, int Kc, int p, Coef&& x) {
    S r;
    r.p = p;
    for (int j = 0; j <= E; ++j)
      for (int k = 0; k <= U && j + k < p; ++k) {
        C acc = C(0);
        for (int mm = j; mm <= M; ++mm) {
          const int i = k - (mm - j);
          if (i < 0 || i > Kc) continue;
          const double w = s == 0 ? (mm == j ? 1.0 : 0.0) : std::pow(s, mm - j) * binomial(mm, j);
          if (w != 0) acc += exact<C>(w) * x(mm, i);
        }
        r.at(j, k) = Tr::normalize(acc);
      }
    r.fit();
    return r;
  }

  // A composition's stage points from the last evaluation (the start of the next one: see ComposedResidual::step).
  struct StageCache {
    std::unique_ptr<typename Composed::template Step<S>> after;
  };

  // The residual rows with the coefficients known so far, precise enough for the unknowns of weight W.
  // With a cache (compositions): start from its stage points, and keep the new ones if `keep`.
  Rows rows(const C& t, const Result& c, const Lambda& l, int W, StageCache* cache = nullptr, bool keep = true) const {
    const int K = Kmax;
    const int pq = W + 3, pz = W + 2, pl = W + 1;
    Vec<S, n> Qm, Q0, Qp;
    for (int i = 0; i < n; ++i) {
      auto x = [&](int mm, int k) { return c.c[static_cast<std::size_t>(mm)][static_cast<std::size_t>(k)](i); };
      Qm(i) = shifted(-1, K + 2, K, pq, x);
      Q0(i) = shifted(0, K + 2, K, pq, x);
      Qp(i) = shifted(1, K + 2, K, pq, x);
    }
    Vec<S, m> Lam;
    for (int r = 0; r < m; ++r)
      Lam(r) = S::h() * shifted(0, K, K, pl, [&](int mm, int k) {
                 return mm <= K ? l[static_cast<std::size_t>(mm)][static_cast<std::size_t>(k)](r) : C(0);
               });
    const S T = S(t) + S::eps(), H = S::h();
    const S invH = inverse(H);
    Rows out;
    Vec<S, n> R;
    if constexpr (composable) {
      if (composed_) {
        S Zm(0), Z0(0), Zp(0);
        if constexpr (contact) {
          auto x = [&](int mm, int k) { return c.d[static_cast<std::size_t>(mm)][static_cast<std::size_t>(k)]; };
          Zm = shifted(-1, K + 2, K, pz, x);
          Z0 = shifted(0, K + 2, K, pz, x);
          Zp = shifted(1, K + 2, K, pz, x);
        }
        using Step = typename Composed::template Step<S>;
        // the step from t (from the last evaluation's), and the step before it from that one seen one step back
        Step after = composed_->step(sys_, T, H, Q0, Qp, Z0, Zp, cache ? cache->after.get() : nullptr, contact);
        const Step back = composed_->shifted_back(after);
        Step before = composed_->step(sys_, S(T - H), H, Qm, Q0, Zm, Z0, &back, false);
        R = composed_->residual(sys_, T, H, before, after, Lam);
        if constexpr (contact) out.Gz = (Zp - Z0 - after.action) * invH;
        for (int i = 0; i < n; ++i) out.G[i] = R(i) * invH;
        for (int r = 0; r < m; ++r) {
          out.Phi[r] = after.phi(r);
          out.impulse[r] = after.impulse(r);
        }
        if (cache && keep) cache->after = std::make_unique<Step>(std::move(after));
        return out;
      }
    }
    if constexpr (contact) {
      auto x = [&](int mm, int k) { return c.d[static_cast<std::size_t>(mm)][static_cast<std::size_t>(k)]; };
      const S Zm = shifted(-1, K + 2, K, pz, x), Z0 = shifted(0, K + 2, K, pz, x), Zp = shifted(1, K + 2, K, pz, x);
      R = Scheme::template residual<Sys, S>(sys_, T, H, Qm, Q0, Qp, Zm, Z0, Zp, Lam);
      out.Gz = (Zp - Z0 - Quad::action(sys_, T, H, Q0, Qp, Z0, Zp)) * invH;
    } else {
      R = Scheme::template residual<Sys, S>(sys_, T, H, Qm, Q0, Qp, Lam);
    }
    for (int i = 0; i < n; ++i) out.G[i] = R(i) * invH;
    if constexpr (m > 0) {
      const Vec<S, m> phi = generic::discrete_constraint<Sys, Quad, S>(sys_, T, H, Q0, Qp);
      for (int r = 0; r < m; ++r) out.Phi[r] = phi(r);
    }
    return out;
  }

  Sys sys_;
  std::shared_ptr<const Composed> composed_;  // a composition of Scheme (null: the scheme itself)
  std::chrono::steady_clock::time_point deadline_ = std::chrono::steady_clock::time_point::max();
};

}  // namespace geomint::modified
