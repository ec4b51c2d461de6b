#include "geomint/constants.hpp"
#include "geomint/error.hpp"
#include "geomint/foucault_ensemble.hpp"
#include "geomint/sweep.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <map>
#include <memory>
#include <thread>
#include <type_traits>
#include <tuple>

// Quad precision: Boost.Multiprecision's header-only IEEE binary128 emulation (113-bit significand,
// expression templates off), with its Eigen interop (NumTraits etc.) so Vec2<quad> works.
#include <boost/multiprecision/cpp_bin_float.hpp>
#include <boost/multiprecision/eigen.hpp>

namespace geomint {

using quad = boost::multiprecision::cpp_bin_float_quad;

double predicted_jump(double s, double h, double qm_x, double qm_y, double q_x, double q_y) {
  const double rm = std::hypot(qm_x, qm_y), r = std::hypot(q_x, q_y);
  if (!(rm > 0) || !std::isfinite(rm) || !std::isfinite(r)) return missing_value;
  const double sigma = qm_x * q_x + qm_y * q_y >= 0 ? 1.0 : -1.0;
  const double sn = r > 0 ? -sigma * s * h * rm / r : -sigma * 1.0;
  return std::asin(std::clamp(sn, -1.0, 1.0)) + s * h;
}

namespace {
bool same(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool same(const FoucaultJump& a, const FoucaultJump& b) {
  return a.j_prev_turn == b.j_prev_turn && a.j_land == b.j_land && a.j_turn == b.j_turn && same(a.t_land, b.t_land) &&
         same(a.t_turn, b.t_turn) && same(a.r_land, b.r_land) && same(a.r_prev, b.r_prev) && same(a.rho, b.rho) &&
         a.side == b.side && same(a.measured, b.measured) && same(a.predicted, b.predicted) &&
         same(a.simple, b.simple) && same(a.energy_loss, b.energy_loss);
}
}  // namespace

bool same_bits(const AnomalyRun& a, const AnomalyRun& b) {
  const AnomalySummary &x = a.summary, &y = b.summary;
  if (!(a.c.scheme == b.c.scheme && a.c.system == b.c.system && same(a.c.alpha, b.c.alpha) &&
        same(a.c.h, b.c.h) && same(a.c.tau, b.c.tau) && a.c.run == b.c.run && a.status == b.status &&
        a.steps == b.steps && same(a.phi0, b.phi0) && same(a.energy_ratio_exact, b.energy_ratio_exact)))
    return false;
  if (!(same(x.E0, y.E0) && same(x.E_end, y.E_end) && same(x.t_end, y.t_end) &&
        same(x.energy_ratio_end, y.energy_ratio_end) && same(x.plane_error, y.plane_error) &&
        same(x.t_plane, y.t_plane) && x.half_swings == y.half_swings && same(x.max, y.max) &&
        same(x.min_rho, y.min_rho) && same(x.t_min_rho, y.t_min_rho)))
    return false;
  if (a.jumps.size() != b.jumps.size()) return false;
  for (std::size_t i = 0; i < a.jumps.size(); ++i)
    if (!same(a.jumps[i], b.jumps[i])) return false;
  return true;
}

std::string pack(const AnomalyRun& r) {
  static_assert(std::is_trivially_copyable_v<AnomalySummary> && std::is_trivially_copyable_v<FoucaultJump>);
  RowWriter w;
  w.put(r.c.scheme).put(r.c.system).put(r.c.alpha).put(r.c.h).put(r.c.tau).put(r.c.run);
  w.put(r.status).put(r.steps).put(r.phi0).put(r.energy_ratio_exact).put(r.summary).put(r.jumps);
  return std::move(w).str();
}

AnomalyRun unpack_anomaly_run(const std::string& row) {
  AnomalyRun r;
  RowReader in(row);
  in.get(r.c.scheme).get(r.c.system).get(r.c.alpha).get(r.c.h).get(r.c.tau).get(r.c.run);
  in.get(r.status).get(r.steps).get(r.phi0).get(r.energy_ratio_exact).get(r.summary).get(r.jumps);
  if (!in.done()) throw std::runtime_error("unpack_anomaly_run: trailing bytes");
  return r;
}

const char* to_string(Precision p) {
  switch (p) {
    case Precision::double_: return "double";
    case Precision::long_double: return "long double";
    case Precision::quad: return "quad";
  }
  return "?";
}

systems::FoucaultPendulum anomaly_scene(const systems::FoucaultPendulum& base, double alpha, double tau) {
  systems::FoucaultPendulum sc = base;
  sc.alpha = alpha;
  sc.validate();
  require(std::isfinite(tau) && tau >= 0, "tau must be a non-negative finite number");
  const FoucaultParams<double> p(sc);
  const Vec2<double> q0(base.x0, base.y0);
  const Vec2<double> v0 = consistent_velocity(p, q0, Vec2<double>(base.vx0, base.vy0));
  const auto x = foucault_exact(p, q0, v0, tau);
  sc.x0 = x.q(0);
  sc.y0 = x.q(1);
  sc.vx0 = x.v(0);
  sc.vy0 = x.v(1);
  return sc;
}

namespace {

template <class T>
Vec2<T> to_t(const Vec2<double>& v) {
  return Vec2<T>(T(v(0)), T(v(1)));
}

// Calls f(Sys{}, C{}) with the case's system and the closed form of its scheme there.
template <class F>
void visit_case(const AnomalyCase& c, F&& f) {
  systems::visit_foucault_system(c.system, [&](auto s) {
    using Sys = decltype(s);
    generic::visit_closed_form<Sys>(c.scheme, [&](auto cf) { f(s, cf); });
  });
}

// The system Sys with the scene's parameters.
template <class Sys>
Sys with_scene(const systems::FoucaultPendulum& sc) {
  Sys sys;
  static_cast<systems::FoucaultPendulum&>(sys) = sc;
  return sys;
}

// The fields every run shares; `sc` is the run's scene (anomaly_scene).
AnomalyRun prepare(const systems::FoucaultPendulum& sc, const AnomalyCase& c) {
  AnomalyRun run;
  run.c = c;
  run.steps = step_count(c.h, sc.T);
  run.phi0 = std::atan2(sc.y0, sc.x0);
  const FoucaultParams<double> p(sc);
  const Vec2<double> q0(sc.x0, sc.y0);
  run.summary.E0 = foucault_energy(p, q0, consistent_velocity(p, q0, Vec2<double>(sc.vx0, sc.vy0)));
  return run;
}

template <class T>
void run_in(const systems::FoucaultPendulum& sc, AnomalyRun& run, double threshold, long stop) {
  const AnomalyCase& c = run.c;
  const FoucaultParams<T> p(sc);
  const Vec2<T> q0(T(sc.x0), T(sc.y0)), v0(T(sc.vx0), T(sc.vy0));
  visit_case(c, [&](auto s, auto cf) {
    using Sys = decltype(s);
    AnomalyDetector<Sys, T> det(p, T(c.h), stop, run.phi0, run.summary.E0, threshold);
    systems::run_closed_form<decltype(cf)>(with_scene<Sys>(sc), p, q0, v0, T(c.h), stop, FoucaultStart::legendre, det);
    run.summary = det.summary();
    run.jumps = std::move(det.jumps);
  });
}

template <class T>
void segment_in(const systems::FoucaultPendulum& sc, AnomalyRun& run, double threshold, const Vec2<double>& qm,
                const Vec2<double>& q, long j_from, long j_to) {
  const AnomalyCase& c = run.c;
  const FoucaultParams<T> p(sc);
  visit_case(c, [&](auto s, auto cf) {
    using Sys = decltype(s);
    AnomalyDetector<Sys, T> det(p, T(c.h), j_to, run.phi0, run.summary.E0, threshold);
    with_scene<Sys>(sc).template closed_steps<decltype(cf)>(p, to_t<T>(qm), to_t<T>(q), j_from, j_to, T(c.h),
                                                            T(run.phi0), det);
    run.summary = det.summary();
    run.jumps = std::move(det.jumps);
  });
}

void finish(const systems::FoucaultPendulum& sc, AnomalyRun& run) {
  if (run.status != "ok" || !std::isfinite(run.summary.t_end)) return;
  const FoucaultParams<double> p(sc);
  const Vec2<double> q0(sc.x0, sc.y0);
  const Vec2<double> v0 = consistent_velocity(p, q0, Vec2<double>(sc.vx0, sc.vy0));
  const auto x = foucault_exact(p, q0, v0, run.summary.t_end);
  run.energy_ratio_exact = run.summary.E_end / foucault_energy(p, x.q, x.v);
}

}  // namespace

AnomalyRun run_anomaly(const systems::FoucaultPendulum& base, const AnomalyCase& c, double record_threshold, Precision precision,
                       long stop_step) {
  const systems::FoucaultPendulum sc = anomaly_scene(base, c.alpha, c.tau);
  AnomalyRun run = prepare(sc, c);
  const long stop = stop_step < 0 ? run.steps : std::min(stop_step, run.steps);
  try {
    switch (precision) {
      case Precision::double_: run_in<double>(sc, run, record_threshold, stop); break;
      case Precision::long_double: run_in<long double>(sc, run, record_threshold, stop); break;
      case Precision::quad: run_in<quad>(sc, run, record_threshold, stop); break;
    }
    finish(sc, run);
  } catch (const NumericalFailure& e) {
    run.status = e.what();
  }
  return run;
}

AnomalyRun rerun_anomaly_segment(const systems::FoucaultPendulum& base, const AnomalyCase& c, double record_threshold,
                                 Precision precision, long j_from, long j_to) {
  const systems::FoucaultPendulum sc = anomaly_scene(base, c.alpha, c.tau);
  AnomalyRun run = prepare(sc, c);
  require(j_from >= 1 && j_from < j_to && j_to <= run.steps, "segment must satisfy 1 <= j_from < j_to <= N");
  try {
    // the double state (q_{j_from-1}, q_{j_from}) of the same run
    Vec2<double> qm, q;
    const FoucaultParams<double> p(sc);
    visit_case(c, [&](auto s, auto cf) {
      systems::run_closed_form<decltype(cf)>(
          with_scene<decltype(s)>(sc), p, Vec2<double>(sc.x0, sc.y0), Vec2<double>(sc.vx0, sc.vy0), c.h, j_from,
          FoucaultStart::legendre, [&](const FoucaultStep<double>& st) {
            if (st.j == j_from - 1) {
              qm = st.q;
              q = st.qn;
            }
          });
    });
    switch (precision) {
      case Precision::double_: segment_in<double>(sc, run, record_threshold, qm, q, j_from, j_to); break;
      case Precision::long_double: segment_in<long double>(sc, run, record_threshold, qm, q, j_from, j_to); break;
      case Precision::quad: segment_in<quad>(sc, run, record_threshold, qm, q, j_from, j_to); break;
    }
  } catch (const NumericalFailure& e) {
    run.status = e.what();
  }
  return run;
}

std::vector<AnomalyCase> anomaly_cases(const std::vector<double>& hs, const std::vector<double>& alphas,
                                       const std::vector<std::string>& schemes,
                                       const std::vector<std::string>& systems, long runs) {
  require(runs >= 1, "runs must be a positive integer");
  std::vector<double> sorted = hs;
  std::sort(sorted.begin(), sorted.end());
  std::vector<AnomalyCase> cases;
  for (double h : sorted)
    for (double a : alphas)
      for (const auto& s : schemes)
        for (const auto& sys : systems)
          for (long k = 0; k < runs; ++k)
            cases.push_back({s, sys, a, h, h * (static_cast<double>(k) + 0.5) / static_cast<double>(runs), k});
  return cases;
}

namespace {

// ---------------------------------------------------------------------------------------------------
// The vectorized ensemble: up to kLanes runs of one cell (scheme, system, alpha, h; only tau differs)
// stepped together in structure-of-arrays form. Per step and lane it does what the systems' closed_steps and
// AnomalyDetector::operator() do per run — the scheme's own step_xy / step_rotation_xy, the landing and
// turning-point tests — as straight-line code over doubles, which GCC vectorizes across lanes. What is rare
// (a turning point, twice per 16.4 s swing; a failed step) is flagged and handled afterwards, lane by lane,
// by the same AnomalyDetector::turn as the scalar path, outside the vector loop. The rotation lines'
// anchors (cos, sin every RotationTable::K steps) are also evaluated lane by lane through libm.

constexpr std::size_t kLanes = 128;  // ~22 KB of state per batch: resident in L1 (128 amortizes the per-step work 2-3 % better than 64)
constexpr double kMax = std::numeric_limits<double>::max();

template <class Sys>
struct Batch {
  static constexpr bool Paper = std::is_same_v<Sys, systems::Foucault>;  // else the rotation row
  // shared by every lane
  FoucaultParams<double> p;
  double h = 0;
  long N = 0;
  std::size_t n = 0;      // lanes in use
  std::size_t width = 0;  // lanes stepped: n rounded up to a multiple of 8 (any vector width); the extra repeat a live lane
  // per lane (structure of arrays)
  alignas(64) double xm[kLanes], ym[kLanes], x[kLanes], y[kLanes];
  // landing candidate of the current half-swing (AnomalyLanding); bj < 0: none
  alignas(64) double br2m[kLanes], br2[kLanes], bj[kLanes], bxm[kLanes], bym[kLanes], bx[kLanes], by[kLanes],
      bxn[kLanes], byn[kLanes];
  // rotation: anchor e(phi) and the line e(phi_j) of the current point
  alignas(64) double a0[kLanes], a1[kLanes], le0[kLanes], le1[kLanes], phi0[kLanes];
  alignas(64) double flag[kLanes];  // 1: turning point, 2: failed step, 3: both
  bool dead[kLanes];
  std::vector<AnomalyDetector<Sys, double>> det;
  std::vector<std::string> status;

  explicit Batch(const FoucaultParams<double>& p_) : p(p_) {}

  void reset_landing(std::size_t i) {
    br2m[i] = 0;
    br2[i] = 1;
    bj[i] = -1;
  }

  // Rare events of step j (after the lanes moved on: q_j is (xm, ym), q_{j+1} is (x, y)). Not inlined: it is
  // the scalar path's own code, compiled once for the baseline.
  template <class Scheme>
  __attribute__((noinline)) void events(long j) {
    for (std::size_t i = 0; i < n; ++i) {
      if (flag[i] == 0 || dead[i]) continue;
      if (flag[i] >= 2) {  // a failure, as the scalar path throws it, or only |q_{j+1}|^2 out of range
        try {
          if (Paper) systems::detail::require_solvable(xm[i] * xm[i] + ym[i] * ym[i], j);
          if (!std::isfinite(x[i]) || !std::isfinite(y[i])) throw state_failure(j);
          // q_{j+1} is finite but its square overflows: the paper step j + 1 will refuse it
          if (Paper) systems::detail::require_solvable(x[i] * x[i] + y[i] * y[i], j + 1);
        } catch (const NumericalFailure& e) {
          status[i] = e.what();
          dead[i] = true;
          continue;
        }
        if (flag[i] < 3) continue;  // no turning point either
      }
      AnomalyLanding<double> L;
      if (bj[i] >= 0) {
        if (Paper) {  // q_{j+1} of the landing step, recomputed: the same call on the same inputs
          double unused;
          Scheme::step_xy(p, h, bxm[i], bym[i], bx[i], by[i], br2[i], bxn[i], byn[i], unused);
        }
        L = {br2m[i], br2[i], static_cast<long>(bj[i]), Vec2<double>(bxm[i], bym[i]), Vec2<double>(bx[i], by[i]),
             Vec2<double>(bxn[i], byn[i])};
      }
      det[i].turn(j, static_cast<double>(j) * h, Vec2<double>(xm[i], ym[i]), Vec2<double>(x[i], y[i]), L);
      reset_landing(i);
    }
  }

  __attribute__((noinline)) void anchors(long j) {
    for (std::size_t i = 0; i < width; ++i) {
      const FoucaultLine<double> L = foucault_line<double>(phi0[i] - p.s * (static_cast<double>(j + 1) * h));
      a0[i] = L.e(0);
      a1[i] = L.e(1);
    }
  }
};

// One step of every lane: the scheme's step, the landing and turning tests, the shift. Returns whether any
// lane has an event. `b` is the index of e(phi_{j+1}) in the rotation table (rotation only).
template <class Sys, class Scheme>
GEOMINT_KERNEL_INLINE std::int64_t batch_step(Batch<Sys>& B, const RotationTable<double>& rot, long j, long b) {
  constexpr bool Paper = Batch<Sys>::Paper;
  const FoucaultParams<double>& p = B.p;
  const double h = B.h, jd = static_cast<double>(j);
  const bool first = j == 0;
  std::int64_t any = 0;
  const std::size_t width = B.width;
#pragma GCC ivdep
  for (std::size_t i = 0; i < width; ++i) {
    const double xm = B.xm[i], ym = B.ym[i], x = B.x[i], y = B.y[i];
    // |q_{j-1}|^2 and |q_j|^2 recomputed (the same products as when they were |q_{j+1}|^2): cheaper than storing
    const double r2m = xm * xm + ym * ym, r2 = x * x + y * y;
    double xn, yn, unused;
    if constexpr (Paper) {
      Scheme::step_xy(p, h, xm, ym, x, y, r2, xn, yn, unused);
    } else {
      double e0, e1;
      rot.line(b, B.a0[i], B.a1[i], e0, e1);
      Scheme::step_rotation_xy(p, h, xm, ym, x, y, -B.le1[i], B.le0[i], e0, e1, xn, yn, unused);
      B.le0[i] = e0;
      B.le1[i] = e1;
    }
    const double rn2 = xn * xn + yn * yn;
    // one test for a non-finite q_{j+1} (or a square that overflows: events() tells them apart) and, for the
    // paper step, q_j at the origin (r_j^2 = 0; an infinite r_j^2 was flagged the step before)
    bool bad = !(rn2 <= kMax);
    if constexpr (Paper) bad = bad | !(r2 > 0);
    const bool better = !first & landing_is_better(r2m, r2, B.br2m[i], B.br2[i]);
    B.br2m[i] = better ? r2m : B.br2m[i];
    B.br2[i] = better ? r2 : B.br2[i];
    B.bj[i] = better ? jd : B.bj[i];
    B.bxm[i] = better ? xm : B.bxm[i];
    B.bym[i] = better ? ym : B.bym[i];
    B.bx[i] = better ? x : B.bx[i];
    B.by[i] = better ? y : B.by[i];
    if constexpr (!Paper) {  // the paper step's q_{j+1} is recomputed from (q_{j-1}, q_j) at the turn
      B.bxn[i] = better ? xn : B.bxn[i];
      B.byn[i] = better ? yn : B.byn[i];
    }
    // the event flag in the lanes' own width (a double: 1 turning point, 2 failure, 3 both), so it costs one
    // blend; `any` is the OR of its bits, kept in 64-bit integers
    const double f = (is_turning_point(first, r2m, r2, rn2) ? 1.0 : 0.0) + (bad ? 2.0 : 0.0);
    B.flag[i] = f;
    std::int64_t fi;
    std::memcpy(&fi, &f, sizeof fi);
    any |= fi;
    B.xm[i] = x;
    B.ym[i] = y;
    B.x[i] = xn;
    B.y[i] = yn;
  }
  return any;
}

template <class Sys, class Scheme>
struct BatchKernel {
  static GEOMINT_KERNEL_INLINE void run(Batch<Sys>& B) {
    constexpr bool Paper = Batch<Sys>::Paper;
    const RotationTable<double> rot(B.p.s, B.h);
    constexpr long K = RotationTable<double>::K;
    long b = 0;
    for (long j = 0; j < B.N; ++j) {
      if (!Paper && ++b == K) {
        b = 0;
        // The anchor step: e(phi_{j+1}) is the anchor itself. The table's entry 0 is the rotation by
        // (cos 0, -sin 0) = (1, -0), which returns (a0, a1) unchanged (a0 = cos(phi) is never zero).
        B.anchors(j);
      }
      if (batch_step<Sys, Scheme>(B, rot, j, b)) B.template events<Scheme>(j);
    }
  }
};

// The lanes' start: the same scene, params and previous point as run_anomaly (prepare, run_closed_form).
template <class Sys, class Scheme>
void run_batch(const systems::FoucaultPendulum& base, const AnomalyCase* cases, std::size_t n, double threshold, Simd simd,
               AnomalyRun* out) {
  const AnomalyCase& c0 = cases[0];
  systems::FoucaultPendulum sc0 = base;
  sc0.alpha = c0.alpha;
  auto B = std::make_unique<Batch<Sys>>(FoucaultParams<double>(sc0));
  B->h = c0.h;
  B->n = n;
  B->width = std::min(kLanes, (n + 7) / 8 * 8);
  B->N = step_count(c0.h, base.T);
  std::vector<systems::FoucaultPendulum> scenes(n);
  B->det.reserve(n);
  B->status.assign(n, "ok");
  std::size_t first_ok = kLanes;
  for (std::size_t i = 0; i < kLanes; ++i) {
    B->dead[i] = i >= n;
    if (i >= n) {  // padding: a copy of a live lane, ignored
      const std::size_t k = first_ok < n ? first_ok : 0;
      B->xm[i] = B->xm[k]; B->ym[i] = B->ym[k]; B->x[i] = B->x[k]; B->y[i] = B->y[k];
      B->phi0[i] = B->phi0[k];
      continue;
    }
    B->xm[i] = B->ym[i] = B->x[i] = B->y[i] = B->phi0[i] = 0;
    try {
      scenes[i] = anomaly_scene(base, cases[i].alpha, cases[i].tau);
      out[i] = prepare(scenes[i], cases[i]);
      const FoucaultParams<double> p(scenes[i]);
      const Vec2<double> q0(scenes[i].x0, scenes[i].y0), v0(scenes[i].vx0, scenes[i].vy0);
      const Vec2<double> qm = Scheme::previous_point(p, q0, v0, c0.h, FoucaultStart::legendre);
      B->xm[i] = qm(0); B->ym[i] = qm(1); B->x[i] = q0(0); B->y[i] = q0(1);
      B->phi0[i] = std::atan2(q0(1), q0(0));
      if (first_ok == kLanes) first_ok = i;
    } catch (const std::exception& e) {  // bad input for one case: recorded, the sweep goes on
      out[i].c = cases[i];
      out[i].status = e.what();
      B->dead[i] = true;
    }
    B->det.emplace_back(B->p, c0.h, B->N, out[i].phi0, out[i].summary.E0, threshold);
  }
  for (std::size_t i = 0; i < kLanes; ++i) {
    B->reset_landing(i);
    const FoucaultLine<double> L = foucault_line<double>(B->phi0[i] - B->p.s * (0.0 * c0.h));
    B->a0[i] = B->le0[i] = L.e(0);
    B->a1[i] = B->le1[i] = L.e(1);
  }
  if (first_ok == kLanes) return;  // every lane failed to start
  simd_dispatch<BatchKernel<Sys, Scheme>>(simd, *B);
  for (std::size_t i = 0; i < n; ++i) {
    if (out[i].status != "ok") continue;  // failed to start
    if (B->dead[i]) {
      out[i].status = B->status[i];
      continue;
    }
    auto& d = B->det[i];
    if (B->N >= 1)
      d.end(static_cast<double>(B->N - 1) * c0.h, Vec2<double>(B->xm[i], B->ym[i]), Vec2<double>(B->x[i], B->y[i]));
    out[i].summary = d.summary();
    out[i].jumps = std::move(d.jumps);
    finish(scenes[i], out[i]);
  }
}

bool same_cell(const AnomalyCase& a, const AnomalyCase& b) {
  return a.scheme == b.scheme && a.system == b.system && a.alpha == b.alpha && a.h == b.h;
}

}  // namespace

std::vector<AnomalyRun> run_anomaly_ensemble(const systems::FoucaultPendulum& base, const std::vector<AnomalyCase>& cases,
                                             double record_threshold, unsigned threads,
                                             const std::function<void(std::size_t, std::size_t)>& progress,
                                             Simd simd) {
  require(simd_supported(simd), std::string("simd ") + to_string(simd) + " is not supported on this CPU");
  // Work items: runs of consecutive cases of one cell, up to kLanes (one case each for the scalar path).
  std::vector<std::pair<std::size_t, std::size_t>> items;
  for (std::size_t i = 0; i < cases.size();) {
    std::size_t k = i + 1;
    if (simd != Simd::scalar)
      while (k < cases.size() && k - i < kLanes && same_cell(cases[i], cases[k])) ++k;
    items.push_back({i, k});
    i = k;
  }
  std::vector<AnomalyRun> out(cases.size());
  std::atomic<std::size_t> next{0}, done{0};
  auto work = [&] {
    for (std::size_t w; (w = next.fetch_add(1)) < items.size();) {
      const auto [lo, hi] = items[w];
      if (simd == Simd::scalar) {
        try {
          out[lo] = run_anomaly(base, cases[lo], record_threshold);
        } catch (const std::exception& e) {  // bad input for one case: recorded, the sweep goes on
          out[lo].c = cases[lo];
          out[lo].status = e.what();
        }
      } else {
        // an unknown scheme name fails every lane of its batch, as run_anomaly would fail each case
        try {
          visit_case(cases[lo], [&](auto s, auto cf) {
            run_batch<decltype(s), decltype(cf)>(base, &cases[lo], hi - lo, record_threshold, simd, &out[lo]);
          });
        } catch (const std::exception& e) {
          for (std::size_t i = lo; i < hi; ++i) {
            out[i].c = cases[i];
            out[i].status = e.what();
          }
        }
      }
      done.fetch_add(hi - lo);
    }
  };
  threads = std::max(1u, threads);
  // With a progress callback the calling thread only reports; otherwise it is one of the workers.
  std::vector<std::thread> pool;
  for (unsigned t = progress ? 0 : 1; t < threads; ++t) pool.emplace_back(work);
  if (!progress) {
    work();
  } else {
    while (done.load() < cases.size()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
      if (done.load() < cases.size()) progress(done.load(), cases.size());
    }
  }
  for (auto& th : pool) th.join();
  if (progress) progress(cases.size(), cases.size());
  return out;
}

double predicted_jump_count(const systems::FoucaultPendulum& base, double alpha, double h, double K) {
  systems::FoucaultPendulum sc = base;
  sc.alpha = alpha;
  const FoucaultParams<double> p(sc);
  const double wd2 = p.w2 - p.s * p.s - alpha * alpha / 4;
  if (!(wd2 > 0)) return missing_value;
  const double passes = sc.T * std::sqrt(wd2) / geomint::pi;
  return passes * std::min(1.0, 2 * std::abs(p.s) * h / std::sin(K));
}

double predicted_jump_probability(const systems::FoucaultPendulum& base, double alpha, double h, double K) {
  return 1 - std::exp(-predicted_jump_count(base, alpha, h, K));
}

double quantile(std::vector<double> v, double q) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
  if (v.empty()) return missing_value;
  std::sort(v.begin(), v.end());
  const double pos = q * static_cast<double>(v.size() - 1);
  const auto i = static_cast<std::size_t>(pos);
  if (i + 1 >= v.size()) return v.back();
  return v[i] + (pos - static_cast<double>(i)) * (v[i + 1] - v[i]);
}

std::vector<AnomalyCell> summarize_anomaly(const systems::FoucaultPendulum& base, const std::vector<AnomalyRun>& runs,
                                           double record_threshold) {
  constexpr double deg = 180 / geomint::pi;
  // cells in the order of (scheme, system, alpha, h) sorted by those keys ("foucault" before "foucault-rotation")
  std::map<std::tuple<std::string, std::string, double, double>, std::vector<const AnomalyRun*>> groups;
  for (const auto& r : runs)
    groups[{r.c.scheme, r.c.system, -r.c.alpha, -r.c.h}].push_back(&r);
  std::vector<AnomalyCell> cells;
  for (const auto& [key, rs] : groups) {
    AnomalyCell c;
    c.scheme = std::get<0>(key);
    c.system = std::get<1>(key);
    c.alpha = -std::get<2>(key);
    c.h = -std::get<3>(key);
    std::vector<double> plane;
    long ok = 0, loss = 0;
    std::array<long, 3> over{0, 0, 0}, count{0, 0, 0};
    std::array<std::vector<double>, 3> per_run;  // jumps per run, for the standard error of the mean
    double max_jump = missing_value;
    for (const auto* r : rs) {
      ++c.runs;
      if (r->status != "ok") {
        ++c.failed;
        continue;
      }
      ++ok;
      const double jd = std::abs(r->summary.max.measured) * deg;
      for (std::size_t k = 0; k < 3; ++k) {
        if (jd > anomaly_jump_thresholds_deg[k]) ++over[k];
        long mine = 0;
        for (const auto& J : r->jumps)
          if (std::abs(J.measured) * deg > anomaly_jump_thresholds_deg[k]) ++mine;
        count[k] += mine;
        per_run[k].push_back(static_cast<double>(mine));
      }
      if (r->summary.energy_ratio_end < 0.99) ++loss;
      plane.push_back(std::abs(r->summary.plane_error) * deg);
      if (!(jd <= max_jump)) max_jump = jd;
    }
    for (std::size_t k = 0; k < 3; ++k) {
      c.p_jump[k] = ok > 0 ? static_cast<double>(over[k]) / static_cast<double>(ok) : missing_value;
      c.p_jump_ci[k] = clopper_pearson(over[k], ok);
      c.p_predicted[k] = predicted_jump_probability(base, c.alpha, c.h, anomaly_jump_thresholds_deg[k] / deg);
      const bool complete = record_threshold * deg <= anomaly_jump_thresholds_deg[k];
      c.mean_jumps[k] = ok > 0 && complete ? static_cast<double>(count[k]) / static_cast<double>(ok) : missing_value;
      c.mean_jumps_se[k] = complete ? mean_se(per_run[k]).se : missing_value;
      c.mean_predicted[k] = predicted_jump_count(base, c.alpha, c.h, anomaly_jump_thresholds_deg[k] / deg);
    }
    c.p_energy_loss = ok > 0 ? static_cast<double>(loss) / static_cast<double>(ok) : missing_value;
    c.p_energy_loss_ci = clopper_pearson(loss, ok);
    c.p_energy_predicted = predicted_jump_probability(base, c.alpha, c.h, std::asin(0.1));
    c.median_abs_plane_error_deg = quantile(plane, 0.5);
    c.p90_abs_plane_error_deg = quantile(plane, 0.9);
    c.max_jump_deg = max_jump;
    cells.push_back(c);
  }
  return cells;
}

}  // namespace geomint
