#pragma once
// Diagnostics of a Foucault pendulum run by the paper's closed forms, kept only as dense as the figures need:
// energy (the chord energy), the imposed constraint's residual, the multiplier, the closest passes by the origin,
// the plane of oscillation at every turning point and its fitted precession rate.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "geomint/constants.hpp"
#include "geomint/error.hpp"
#include "geomint/observers.hpp"
#include "geomint/systems/foucault.hpp"

namespace geomint {

struct FoucaultSample {
  long j;
  double t;          // t_j
  double x, y;       // q_j
  double energy;     // chord energy E_{j+1/2} (at t_j + h/2)
  double lambda;     // continuous-equivalent multiplier of the step j -> j+1 (kg/s)
  double residual;   // Phi_d(q_j, q_{j+1}) / discrete_constraint_scale
  bool turning;      // q_j is a turning point (also in FoucaultDiagnostics::turns)
};

struct FoucaultSummary {
  double E0 = 0;                 // continuous energy of the consistent initial state
  double E_final = 0;            // E_{N-1/2}
  double t_final = 0;            // T - h/2
  double max_residual = 0;       // max_j |Phi_d| / scale (round-off units of eps at most a few); rotation: see operator()
  double max_abs_residual = 0;   // max_j |Phi_d|, m^2/s (rotation: |n(phi_{j+1}).q_{j+1}|, m)
  double max_abs_lambda = 0;     // max_j |lambda| (continuous-equivalent), kg/s
  double min_r = 0;              // min_j |q_j|, j = 0..N
  double t_min_r = 0;
  // min_j |q_j| / |q_{j+1} - q_j|: how close a step lands to the origin, in units of the step. Near the
  // origin the discrete constraint makes q_{j+1} - q_j nearly parallel to q_j, so a step landing at this
  // ratio rho turns the plane of oscillation by about s h / rho (the "anomaly" when rho is small).
  double min_pass_ratio = std::numeric_limits<double>::infinity();
  double t_min_pass_ratio = 0;
  double max_jump = 0;           // max_k |angle_k - angle_{k-1}|, rad
  double t_max_jump = 0;
  // Largest loss of energy between successive turning points beyond the exact factor e^{-alpha dt}
  // (at extrema of a damped linear oscillator the energy ratio is exactly e^{-alpha dt}).
  double max_energy_loss = 0;
  double t_max_energy_loss = 0;
  double rate = missing_value;  // least-squares d(angle)/dt, rad/s
  int rate_points = 0;
  long turns = 0;
};

// Sys: Foucault or FoucaultRotation (which constraint the residual is of).
template <class Sys, class T>
class FoucaultDiagnostics {
 public:
  // sample_every: keep every k-th step (plus every turning point and the last step).
  FoucaultDiagnostics(const FoucaultParams<T>& p, T h, long N, long sample_every, const Vec2<T>& q0,
                      const Vec2<T>& v0)
      : p_(p), h_(h), N_(N), every_(sample_every) {
    require(sample_every >= 1, "sample_every must be a positive integer");
    summary_.E0 = static_cast<double>(foucault_energy(p, q0, consistent_velocity(p, q0, v0)));
    summary_.min_r = static_cast<double>(q0.norm());
    // Reserve once: turning points come twice per period 2 pi / sqrt(w2 - s^2); doubled for safety, and at most
    // one a step (a period shorter than h, from an extreme Omega or g, would otherwise ask for any amount).
    const double period = 2 * geomint::pi / std::sqrt(std::abs(static_cast<double>(p.w2 - p.s * p.s)));
    const double per_period = std::min(4 * static_cast<double>(N) * static_cast<double>(h) / period, static_cast<double>(N));
    const auto turns_est = static_cast<std::size_t>(std::isfinite(per_period) ? per_period : static_cast<double>(N)) + 16;
    plane_.turns.reserve(turns_est);
    samples.reserve(static_cast<std::size_t>(N / sample_every) + 2 + turns_est);
  }

  void operator()(const FoucaultStep<T>& st) {
    using std::abs;
    const T r = st.q.norm(), rn = st.qn.norm();
    const double t = static_cast<double>(st.t);
    const T E = chord_energy(p_, st.q, st.qn, h_);
    // The residual of the discretization that was imposed (the system's), in its round-off units.
    const T phid = Sys::imposed_constraint(p_, st, h_);
    const T scale = Sys::imposed_constraint_scale(st, h_);
    const double res = static_cast<double>(scale > 0 ? abs(phid) / scale : abs(phid));
    auto& S = summary_;
    S.max_residual = std::max(S.max_residual, res);
    S.max_abs_residual = std::max(S.max_abs_residual, static_cast<double>(abs(phid)));
    S.max_abs_lambda = std::max(S.max_abs_lambda, static_cast<double>(abs(st.lambda)));
    if (static_cast<double>(rn) < S.min_r) {
      S.min_r = static_cast<double>(rn);
      S.t_min_r = static_cast<double>(T(st.j + 1) * h_);
    }
    const T step_len = (st.qn - st.q).norm();
    if (step_len > 0 && static_cast<double>(r / step_len) < S.min_pass_ratio) {
      S.min_pass_ratio = static_cast<double>(r / step_len);
      S.t_min_pass_ratio = t;
    }
    const bool turning = plane_.observe(st.j, t, T(st.qm.norm()), static_cast<double>(st.q(0)),
                                        static_cast<double>(st.q(1)), r, rn, static_cast<double>(E));
    if (turning && plane_.turns.size() > 1) {  // the jump of the plane and the energy lost since the last turn
      const FoucaultTurn &k = plane_.turns.back(), &prev = plane_.turns[plane_.turns.size() - 2];
      auto& S = summary_;
      if (std::abs(k.jump) > S.max_jump) {
        S.max_jump = std::abs(k.jump);
        S.t_max_jump = t;
      }
      const double loss = 1 - k.energy / prev.energy * std::exp(static_cast<double>(p_.alpha) * (t - prev.t));
      if (loss > S.max_energy_loss) {
        S.max_energy_loss = loss;
        S.t_max_energy_loss = t;
      }
    }
    if (turning || st.j % every_ == 0 || st.j == N_ - 1)
      samples.push_back({st.j, t, static_cast<double>(st.q(0)), static_cast<double>(st.q(1)), static_cast<double>(E),
                         static_cast<double>(st.lambda), res, turning});
    if (st.j == N_ - 1) {
      S.E_final = static_cast<double>(E);
      S.t_final = static_cast<double>(st.t + h_ / 2);
    }
  }

  // Completes the summary (precession fit) after the run.
  FoucaultSummary summary() const {
    FoucaultSummary s = summary_;
    s.rate = plane_.rate(&s.rate_points);
    s.turns = static_cast<long>(plane_.turns.size());
    return s;
  }
  // The turning points (moved out by a caller that keeps them).
  std::vector<FoucaultTurn>& turns() { return plane_.turns; }

  std::vector<FoucaultSample> samples;

 private:
  PlaneTurns plane_;
  FoucaultParams<T> p_;
  T h_;
  long N_, every_;
  FoucaultSummary summary_;
};

// A run as the programs use it: system and scheme by name, double precision, decimated diagnostics.
struct FoucaultRun {
  std::vector<FoucaultSample> samples;
  std::vector<FoucaultTurn> turns;
  FoucaultSummary summary;
};
// Runs N = T/h steps (step_count refuses h that does not divide T). Throws InputError for bad input and
// NumericalFailure (with the step index) when a step cannot be solved.
// system: foucault or foucault-rotation (or paper, rotation); scheme: la or contact (or la-nh, contact-nh): the
// closed forms (15), (18) with that system's constraint row.
FoucaultRun run_foucault(const std::string& system, const std::string& scheme, const systems::FoucaultPendulum& scene,
                         double h, FoucaultStart start, long sample_every);

}  // namespace geomint
