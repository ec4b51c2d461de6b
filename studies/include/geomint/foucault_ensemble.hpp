#pragma once
// Where the Foucault schemes fail: an anomaly detector for one run, ensembles of runs
// that turn single observations into probabilities, and reruns of the worst cases in wider precisions.
//
// The anomaly (derived in systems/foucault/steps.hpp, "Two discretizations of the constraint (13)"): with the paper's
// discrete constraint the step into a point q_L satisfies q_{L-1} x q_L = -s h |q_{L-1}|^2, so the line of
// the plane turns, in that one step, by
//     kappa_L = asin( -sigma s h |q_{L-1}| / |q_L| ),   sigma = sign(q_{L-1} . q_L)
// (sigma = +1 when q_L lands before the origin, -1 after it; the angle is between lines, i.e. modulo pi).
// Every other step of the half-swing turns the line by asin(-s h r_j / r_{j+1}) (signed radii) = -s h
// up to terms ~ s h |dq| / r_{j+1} whose sum over the approach and the recession nearly cancels (O(s h)
// in all). So over the half-swing that contains the landing the plane turns, beyond the exact precession
// -s dt, by
//     predicted = kappa_L + s h            (the landing step's own exact share is -s h)
// which is ~ -sigma s h / rho for rho = |q_L| / |q_{L+1} - q_L| << 1 (the previous report's s h / rho),
// and the following step removes the velocity across the new line: the energy drops by sin^2(kappa_L).
// On foucault-rotation the line of every q_j is phi_j by construction: predicted = 0.
//
// Why the ensembles perturb the time origin and not the angle or the amplitude of q0. What decides a jump
// is where, within a step, the grid falls relative to each crossing of the origin. Both schemes are
// equivariant under rotations (A(R q) = R A(q), |R q| = |q|), so turning q0 changes nothing but the
// rounding; the radial motion is linear, so scaling q0 scales every |q_j| and leaves every rho unchanged;
// and a relative change eps of h shifts the landings of the pass at time t by only t eps / h steps. A
// start from the exact state at time tau, tau uniform in [0, h), shifts every crossing by tau relative
// to the grid: each pass's landing offset becomes uniform, while the physics is unchanged (the same
// exact trajectory, entered less than one step later: a shift below the time resolution of the grid).
// Run k of an ensemble uses tau_k = h (k + 1/2) / M (stratified, reproducible).
//
// With that randomization each crossing of the origin falls uniformly within its step, so the grid point
// before it lies at u uniform in [0, D) (D the step length) and the one after at D - u. A kick larger than
// K needs |q_L| < |q_{L-1}| s h / sin K ~ D s h / sin K on either side: P(|kappa| > K) per pass is
// 2 s h / sin K. With N_pass = T omega_d / pi passes per run (omega_d^2 = w2 - s^2 - alpha^2/4, the radial
// frequency of the closed form), the expected number of such jumps per run is N_pass 2 s h / sin K, and the
// probability per run ~ 1 - exp(-N_pass 2 s h / sin K) if passes were independent (Poisson).
// predicted_jump_count / predicted_jump_probability give them; the ensembles measure them.
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

#include "geomint/constants.hpp"
#include "geomint/error.hpp"
#include "geomint/observers.hpp"
#include "geomint/simd.hpp"
#include "geomint/stats.hpp"
#include "geomint/systems/foucault.hpp"

namespace geomint {

// One half-swing, turning point to turning point, and its landing near the origin.
struct FoucaultJump {
  long j_prev_turn = -1, j_land = -1, j_turn = -1;  // previous turning point, landing q_L, this turning point
  double t_land = missing_value;
  double t_turn = missing_value;
  double r_land = missing_value;  // |q_L|, m
  double r_prev = missing_value;  // |q_{L-1}|, m
  double rho = missing_value;     // |q_L| / |q_{L+1} - q_L|
  int side = 0;  // +1: q_L lands before the origin (q_{L-1}.q_L > 0), -1: after it (sigma above)
  double measured = missing_value;   // plane turn minus exact -s dt, rad (signed)
  double predicted = missing_value;  // kappa_L + s h (foucault), 0 (foucault-rotation), rad
  double simple = missing_value;     // atan(s h / rho), rad (unsigned; small kicks only)
  double energy_loss = missing_value;  // 1 - E_k / E_{k-1} e^{alpha dt}
};

// kappa_L + s h of the paper's constraint (see above), rad; NaN without a landing.
double predicted_jump(double s, double h, double qm_x, double qm_y, double q_x, double q_y);

struct AnomalySummary {
  double E0 = missing_value;     // energy of the consistent start
  double E_end = missing_value;  // chord energy E_{N-1/2}
  double t_end = missing_value;  // (N - 1/2) h
  double energy_ratio_end = missing_value;  // E_end / (E0 e^{-alpha t_end})
  // plane angle at the last turning point minus the exact phi0 - s t there, modulo pi, rad
  double plane_error = missing_value;
  double t_plane = missing_value;
  long half_swings = 0;  // completed half-swings (turning point to turning point)
  FoucaultJump max;      // the half-swing with the largest |measured| (measured NaN if none)
  double min_rho = std::numeric_limits<double>::infinity();  // closest landing of the run, in steps
  double t_min_rho = missing_value;
};

// The landing of a half-swing is the q_L with the largest |q_{L-1}| / |q_L|, i.e. the largest one-step kick
// of the paper's constraint: the grid point nearest the origin when it lies before the crossing, or the one
// after the crossing when that is within 1 - 1/sqrt(2) = 0.29 of a step.
// Observer of the closed forms' runs (run_closed_form, closed_steps), in any scalar type. Per step it costs one
// squared norm and two products; everything else happens at turning points (twice per 16.4 s period).
// jumps: every half-swing with |measured| >= record_threshold (rad). phi0: the exact plane angle at t = 0
// (exact angle phi0 - s t). j_end: the step count of the run (the last step j_end - 1 gives E_end).
// The landing candidate of the current half-swing: q_j (with q_{j-1}, q_{j+1}) with the largest |q_{j-1}| / |q_j|.
template <class T>
struct AnomalyLanding {
  T r2m = 0, r2 = 1;  // |q_{j-1}|^2, |q_j|^2 (0 and 1: no candidate yet, any step beats it)
  long j = -1;        // -1: none since the last turning point
  Vec2<T> qm = Vec2<T>::Zero(), q = Vec2<T>::Zero(), qn = Vec2<T>::Zero();
};

// The per-step landing test of AnomalyDetector as a function of squared radii, shared with the vectorized
// ensembles (foucault_ensemble.cpp) so both decide alike (as is_turning_point, observers.hpp, on squared radii).
// Cross-multiplied: no division per step.
template <class T>
inline bool landing_is_better(T r2m, T r2, T best_r2m, T best_r2) {
  return r2m * best_r2 > best_r2m * r2;
}

// Sys: Foucault or FoucaultRotation, the system whose closed forms ran (what the landing predicts).
template <class Sys, class T>
class AnomalyDetector {
 public:
  AnomalyDetector(const FoucaultParams<T>& p, T h, long j_end, double phi0, double E0, double record_threshold)
      : p_(p), h_(h), hd_(static_cast<double>(h)), s_(static_cast<double>(p.s)), alpha_(static_cast<double>(p.alpha)),
        phi0_(phi0), threshold_(record_threshold), j_end_(j_end) {
    summary_.E0 = E0;
    jumps.reserve(64);
  }

  void operator()(const FoucaultStep<T>& st) {
    const T rn2 = st.qn.squaredNorm();
    if (!started_) {
      r2m_ = st.qm.squaredNorm();
      r2_ = st.q.squaredNorm();
      started_ = true;
    }
    // Landing candidate. The virtual q_{-1} of the start is not a landing.
    if (st.j > 0 && landing_is_better(r2m_, r2_, best_.r2m, best_.r2)) best_ = {r2m_, r2_, st.j, st.qm, st.q, st.qn};
    if (is_turning_point(st.j == 0, r2m_, r2_, rn2)) {
      turn(st.j, st.t, st.q, st.qn, best_);
      best_ = AnomalyLanding<T>{};
    }
    if (st.j == j_end_ - 1) end(st.t, st.q, st.qn);
    r2m_ = r2_;
    r2_ = rn2;
  }

  // A turning point at q_j (t = t_j), with the landing of the half-swing that ends there.
  void turn(long j, T t_j, const Vec2<T>& q, const Vec2<T>& qn, const AnomalyLanding<T>& best) {
    using std::sqrt;
    constexpr double pi = geomint::pi;
    const double t = static_cast<double>(t_j);
    const double x = static_cast<double>(q(0)), y = static_cast<double>(q(1));
    double a = std::atan2(y, x);
    const double E = static_cast<double>(chord_energy(p_, q, qn, h_));
    if (have_turn_) {
      a = line_angle(x, y, prev_angle_);
      FoucaultJump J;
      J.j_prev_turn = prev_j_;
      J.j_turn = j;
      J.t_turn = t;
      J.measured = (a - prev_angle_) + s_ * (t - prev_t_);
      J.energy_loss = 1 - E / prev_E_ * std::exp(alpha_ * (t - prev_t_));
      if (best.j >= 0) {
        J.j_land = best.j;
        J.t_land = static_cast<double>(T(best.j) * h_);
        J.r_land = static_cast<double>(sqrt(best.r2));
        J.r_prev = static_cast<double>(sqrt(best.r2m));
        J.rho = static_cast<double>(sqrt(best.r2 / (best.qn - best.q).squaredNorm()));
        J.side = best.qm.dot(best.q) >= 0 ? 1 : -1;
        J.simple = std::atan(s_ * hd_ / J.rho);
        if constexpr (std::is_same_v<Sys, systems::FoucaultRotation>)
          J.predicted = 0.0;
        else
          J.predicted = predicted_jump(s_, hd_, static_cast<double>(best.qm(0)), static_cast<double>(best.qm(1)),
                                       static_cast<double>(best.q(0)), static_cast<double>(best.q(1)));
        if (J.rho < summary_.min_rho) {
          summary_.min_rho = J.rho;
          summary_.t_min_rho = J.t_land;
        }
      }
      ++summary_.half_swings;
      if (!(std::abs(J.measured) <= std::abs(summary_.max.measured))) summary_.max = J;  // also replaces NaN
      if (std::abs(J.measured) >= threshold_) jumps.push_back(J);
    }
    summary_.plane_error = nearest_branch(a - (phi0_ - s_ * t), 0.0, pi);
    summary_.t_plane = t;
    prev_angle_ = a;
    prev_t_ = t;
    prev_E_ = E;
    prev_j_ = j;
    have_turn_ = true;
  }

  // The last step (q_{N-1} -> q_N, t = t_{N-1}): the final energy.
  void end(T t_last, const Vec2<T>& q, const Vec2<T>& qn) {
    summary_.E_end = static_cast<double>(chord_energy(p_, q, qn, h_));
    summary_.t_end = static_cast<double>(t_last) + hd_ / 2;
    summary_.energy_ratio_end = summary_.E_end / (summary_.E0 * std::exp(-alpha_ * summary_.t_end));
  }

  AnomalySummary summary() const { return summary_; }

  std::vector<FoucaultJump> jumps;

 private:
  FoucaultParams<T> p_;
  T h_;
  double hd_, s_, alpha_, phi0_, threshold_;
  long j_end_;
  AnomalySummary summary_;
  bool started_ = false, have_turn_ = false;
  T r2m_ = 0, r2_ = 0;
  AnomalyLanding<T> best_;
  long prev_j_ = -1;
  double prev_angle_ = 0, prev_t_ = 0, prev_E_ = 0;
};

// ---------------------------------------------------------------------------------------------------
// Runs and ensembles (double unless a Precision is given)

// One run of an ensemble: scheme, system (foucault or foucault-rotation: the discretization of (13)), alpha, h,
// and the time-origin shift tau.
struct AnomalyCase {
  std::string scheme;
  std::string system = systems::Foucault::name;
  double alpha = 0, h = 0, tau = 0;
  long run = 0;
};

struct AnomalyRun {
  AnomalyCase c;
  std::string status = "ok";  // or the NumericalFailure / error message: a failed run stays a row
  long steps = 0;
  double phi0 = missing_value;  // exact plane angle at the run's t = 0
  double energy_ratio_exact = missing_value;  // E_end / E_closed_form(t_end)
  AnomalySummary summary;
  std::vector<FoucaultJump> jumps;
};

// Whether two runs carry the same bits in every field (doubles compared as bit patterns, so NaN == NaN):
// what "the vectorized, threaded and distributed ensembles give the same results" means.
bool same_bits(const AnomalyRun& a, const AnomalyRun& b);

// A run as bytes and back (for Sweep::map: gathering the runs of every MPI rank on rank 0), bit-exact.
std::string pack(const AnomalyRun& r);
AnomalyRun unpack_anomaly_run(const std::string& row);

enum class Precision { double_, long_double, quad };  // quad: Boost.Multiprecision cpp_bin_float_quad
const char* to_string(Precision p);

// The scene of a run: base with alpha and, as initial data, the exact state at time tau of base's
// consistent start (so run k sees the same exact trajectory, entered tau later). tau = 0 gives base's
// start projected onto (13).
systems::FoucaultPendulum anomaly_scene(const systems::FoucaultPendulum& base, double alpha, double tau);

// Runs one case from t = 0 for `stop_step` steps (default: all N = T/h), in the given precision, with the
// legendre start. Never throws for a numerical failure: status says what happened. InputError for bad input.
AnomalyRun run_anomaly(const systems::FoucaultPendulum& base, const AnomalyCase& c, double record_threshold,
                       Precision precision = Precision::double_, long stop_step = -1);

// Steps j_from .. j_to - 1 of the case in `precision`, restarted from the double run's (q_{j_from-1}, q_{j_from})
// (converted exactly). For a rerun of one pass in quad precision without paying for the whole hour.
AnomalyRun rerun_anomaly_segment(const systems::FoucaultPendulum& base, const AnomalyCase& c, double record_threshold,
                                 Precision precision, long j_from, long j_to);

// The cases of an ensemble: for each h, alpha, scheme, system, M runs with tau_k = h (k + 1/2) / M.
// Ordered by cost (small h first), so threads pulling from the front stay balanced.
std::vector<AnomalyCase> anomaly_cases(const std::vector<double>& hs, const std::vector<double>& alphas,
                                       const std::vector<std::string>& schemes,
                                       const std::vector<std::string>& systems, long runs);

// Runs every case on `threads` threads (std::thread, each pulling the next work item). progress(done, total)
// is called from the calling thread about every 0.1 s and once at the end.
// simd: Simd::scalar runs each case through run_anomaly (one trajectory at a time); sse2/avx2/avx512 step up
// to 128 consecutive cases of one cell (scheme, system, alpha, h) together in structure-of-arrays form,
// vectorized for that instruction set. Every choice, and every thread count, gives the same bits
// (tests/studies/simd_ensemble.test.cpp).
std::vector<AnomalyRun> run_anomaly_ensemble(const systems::FoucaultPendulum& base, const std::vector<AnomalyCase>& cases,
                                             double record_threshold, unsigned threads,
                                             const std::function<void(std::size_t, std::size_t)>& progress = {},
                                             Simd simd = best_simd());

// Per (scheme, system, alpha, h): the jump and energy-loss statistics with their error bars and predictions.
inline constexpr std::array<double, 3> anomaly_jump_thresholds_deg{1, 5, 20};
struct AnomalyCell {
  std::string scheme;
  std::string system = systems::Foucault::name;
  double alpha = 0, h = 0;
  long runs = 0, failed = 0;
  std::array<double, 3> p_jump{};       // share of ok runs with max |jump| > 1, 5, 20 deg
  std::array<Interval, 3> p_jump_ci{};  // its 95 % Clopper–Pearson interval
  std::array<double, 3> p_predicted{};  // predicted_jump_probability for the same thresholds
  // mean number of half-swings per run with |jump| > 1, 5, 20 deg (NaN when the runs did not record jumps
  // that small), and its prediction N_pass 2 s h / sin K, which needs no independence between passes
  std::array<double, 3> mean_jumps{};
  std::array<double, 3> mean_jumps_se{};  // standard error of mean_jumps
  std::array<double, 3> mean_predicted{};
  double p_energy_loss = 0;             // share of ok runs with energy_ratio_end < 0.99
  Interval p_energy_loss_ci;            // its 95 % Clopper–Pearson interval
  double p_energy_predicted = 0;        // predicted: a jump with sin^2 > 0.01 (kappa > 5.74 deg)
  double median_abs_plane_error_deg = missing_value;
  double p90_abs_plane_error_deg = missing_value;
  double max_jump_deg = missing_value;
};
// record_threshold: the one the runs were made with (rad), to know which mean counts are complete.
std::vector<AnomalyCell> summarize_anomaly(const systems::FoucaultPendulum& base, const std::vector<AnomalyRun>& runs,
                                           double record_threshold);

// Expected number of half-swings per run that turn by more than K (rad) under uniform landings:
// N_pass min(1, 2 s h / sin K), N_pass = T omega_d / pi (see above). Exact in expectation (linearity),
// whatever the correlation between the passes of one run.
double predicted_jump_count(const systems::FoucaultPendulum& base, double alpha, double h, double K_rad);
// 1 - exp(-predicted_jump_count): the probability per run if passes were independent (Poisson). The
// landings of one run drift slowly through the origin's neighbourhood, so close ones come in clusters and
// the measured probability can be lower; the count is the sharper test.
double predicted_jump_probability(const systems::FoucaultPendulum& base, double alpha, double h, double K_rad);

// Quantile q in [0, 1] of the finite values (linear interpolation); NaN if none.
double quantile(std::vector<double> v, double q);

}  // namespace geomint
