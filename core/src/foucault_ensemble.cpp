#include "geomint/foucault_ensemble.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <map>
#include <thread>
#include <tuple>

// Quad precision: Boost.Multiprecision's header-only IEEE binary128 emulation (113-bit significand,
// expression templates off), with its Eigen interop (NumTraits etc.) so Vec2<quad> and Mat3<quad> work.
#include <boost/multiprecision/cpp_bin_float.hpp>
#include <boost/multiprecision/eigen.hpp>

namespace geomint {

using quad = boost::multiprecision::cpp_bin_float_quad;

double predicted_jump(double s, double h, double qm_x, double qm_y, double q_x, double q_y) {
  const double rm = std::hypot(qm_x, qm_y), r = std::hypot(q_x, q_y);
  if (!(rm > 0) || !std::isfinite(rm) || !std::isfinite(r)) return std::nan("");
  const double sigma = qm_x * q_x + qm_y * q_y >= 0 ? 1.0 : -1.0;
  const double sn = r > 0 ? -sigma * s * h * rm / r : -sigma * 1.0;
  return std::asin(std::clamp(sn, -1.0, 1.0)) + s * h;
}

const char* to_string(Precision p) {
  switch (p) {
    case Precision::double_: return "double";
    case Precision::long_double: return "long double";
    case Precision::quad: return "quad";
  }
  return "?";
}

FoucaultScene anomaly_scene(const FoucaultScene& base, double alpha, double tau) {
  FoucaultScene sc = base;
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

// The fields every run shares; `sc` is the run's scene (anomaly_scene).
AnomalyRun prepare(const FoucaultScene& sc, const AnomalyCase& c) {
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
void run_in(const FoucaultScene& sc, AnomalyRun& run, double threshold, long stop) {
  const AnomalyCase& c = run.c;
  const FoucaultParams<T> p(sc);
  const Vec2<T> q0(T(sc.x0), T(sc.y0)), v0(T(sc.vx0), T(sc.vy0));
  AnomalyDetector<T> det(p, T(c.h), stop, run.phi0, run.summary.E0, threshold, c.constraint);
  visit_foucault_scheme(c.scheme, [&](auto s) {
    integrate_foucault<decltype(s)>(p, q0, v0, T(c.h), stop, FoucaultStart::legendre, det, c.constraint);
  });
  run.summary = det.summary();
  run.jumps = std::move(det.jumps);
}

template <class T>
void segment_in(const FoucaultScene& sc, AnomalyRun& run, double threshold, const Vec2<double>& qm,
                const Vec2<double>& q, long j_from, long j_to) {
  const AnomalyCase& c = run.c;
  const FoucaultParams<T> p(sc);
  AnomalyDetector<T> det(p, T(c.h), j_to, run.phi0, run.summary.E0, threshold, c.constraint);
  visit_foucault_scheme(c.scheme, [&](auto s) {
    integrate_foucault_steps<decltype(s)>(p, to_t<T>(qm), to_t<T>(q), j_from, j_to, T(c.h), c.constraint,
                                          T(run.phi0), det);
  });
  run.summary = det.summary();
  run.jumps = std::move(det.jumps);
}

void finish(const FoucaultScene& sc, AnomalyRun& run) {
  if (run.status != "ok" || !std::isfinite(run.summary.t_end)) return;
  const FoucaultParams<double> p(sc);
  const Vec2<double> q0(sc.x0, sc.y0);
  const Vec2<double> v0 = consistent_velocity(p, q0, Vec2<double>(sc.vx0, sc.vy0));
  const auto x = foucault_exact(p, q0, v0, run.summary.t_end);
  run.energy_ratio_exact = run.summary.E_end / foucault_energy(p, x.q, x.v);
}

}  // namespace

AnomalyRun run_anomaly(const FoucaultScene& base, const AnomalyCase& c, double record_threshold, Precision precision,
                       long stop_step) {
  const FoucaultScene sc = anomaly_scene(base, c.alpha, c.tau);
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

AnomalyRun rerun_anomaly_segment(const FoucaultScene& base, const AnomalyCase& c, double record_threshold,
                                 Precision precision, long j_from, long j_to) {
  const FoucaultScene sc = anomaly_scene(base, c.alpha, c.tau);
  AnomalyRun run = prepare(sc, c);
  require(j_from >= 1 && j_from < j_to && j_to <= run.steps, "segment must satisfy 1 <= j_from < j_to <= N");
  try {
    // the double state (q_{j_from-1}, q_{j_from}) of the same run
    Vec2<double> qm, q;
    const FoucaultParams<double> p(sc);
    visit_foucault_scheme(c.scheme, [&](auto s) {
      integrate_foucault<decltype(s)>(
          p, Vec2<double>(sc.x0, sc.y0), Vec2<double>(sc.vx0, sc.vy0), c.h, j_from, FoucaultStart::legendre,
          [&](const FoucaultStep<double>& st) {
            if (st.j == j_from - 1) {
              qm = st.q;
              q = st.qn;
            }
          },
          c.constraint);
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
                                       const std::vector<FoucaultConstraint>& constraints, long runs) {
  require(runs >= 1, "runs must be a positive integer");
  std::vector<double> sorted = hs;
  std::sort(sorted.begin(), sorted.end());
  std::vector<AnomalyCase> cases;
  for (double h : sorted)
    for (double a : alphas)
      for (const auto& s : schemes)
        for (auto c : constraints)
          for (long k = 0; k < runs; ++k)
            cases.push_back({s, c, a, h, h * (static_cast<double>(k) + 0.5) / static_cast<double>(runs), k});
  return cases;
}

std::vector<AnomalyRun> run_anomaly_ensemble(const FoucaultScene& base, const std::vector<AnomalyCase>& cases,
                                             double record_threshold, unsigned threads,
                                             const std::function<void(std::size_t, std::size_t)>& progress) {
  std::vector<AnomalyRun> out(cases.size());
  std::atomic<std::size_t> next{0}, done{0};
  auto work = [&] {
    for (std::size_t i; (i = next.fetch_add(1)) < cases.size();) {
      try {
        out[i] = run_anomaly(base, cases[i], record_threshold);
      } catch (const std::exception& e) {  // bad input for one case: recorded, the sweep goes on
        out[i].c = cases[i];
        out[i].status = e.what();
      }
      done.fetch_add(1);
    }
  };
  threads = std::max(1u, threads);
  std::vector<std::thread> pool;
  for (unsigned t = 0; t < threads; ++t) pool.emplace_back(work);
  auto last = std::chrono::steady_clock::now();
  while (done.load() < cases.size()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    const auto now = std::chrono::steady_clock::now();
    const std::size_t d = done.load();
    if (progress && d < cases.size() && now - last > std::chrono::milliseconds(500)) {
      progress(d, cases.size());
      last = now;
    }
  }
  for (auto& th : pool) th.join();
  if (progress) progress(cases.size(), cases.size());
  return out;
}

double predicted_jump_count(const FoucaultScene& base, double alpha, double h, double K) {
  FoucaultScene sc = base;
  sc.alpha = alpha;
  const FoucaultParams<double> p(sc);
  const double wd2 = p.w2 - p.s * p.s - alpha * alpha / 4;
  if (!(wd2 > 0)) return std::nan("");
  const double passes = sc.T * std::sqrt(wd2) / foucault_pi;
  return passes * std::min(1.0, 2 * std::abs(p.s) * h / std::sin(K));
}

double predicted_jump_probability(const FoucaultScene& base, double alpha, double h, double K) {
  return 1 - std::exp(-predicted_jump_count(base, alpha, h, K));
}

double quantile(std::vector<double> v, double q) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const double pos = q * static_cast<double>(v.size() - 1);
  const auto i = static_cast<std::size_t>(pos);
  if (i + 1 >= v.size()) return v.back();
  return v[i] + (pos - static_cast<double>(i)) * (v[i + 1] - v[i]);
}

std::vector<AnomalyCell> summarize_anomaly(const FoucaultScene& base, const std::vector<AnomalyRun>& runs,
                                           double record_threshold) {
  constexpr double deg = 180 / foucault_pi;
  // cells in first-seen order of (scheme, constraint, alpha, h) after sorting by those keys
  std::map<std::tuple<std::string, int, double, double>, std::vector<const AnomalyRun*>> groups;
  for (const auto& r : runs)
    groups[{r.c.scheme, static_cast<int>(r.c.constraint), -r.c.alpha, -r.c.h}].push_back(&r);
  std::vector<AnomalyCell> cells;
  for (const auto& [key, rs] : groups) {
    AnomalyCell c;
    c.scheme = std::get<0>(key);
    c.constraint = static_cast<FoucaultConstraint>(std::get<1>(key));
    c.alpha = -std::get<2>(key);
    c.h = -std::get<3>(key);
    std::vector<double> plane;
    long ok = 0, loss = 0;
    std::array<long, 3> over{0, 0, 0}, count{0, 0, 0};
    double max_jump = std::nan("");
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
        for (const auto& J : r->jumps)
          if (std::abs(J.measured) * deg > anomaly_jump_thresholds_deg[k]) ++count[k];
      }
      if (r->summary.energy_ratio_end < 0.99) ++loss;
      plane.push_back(std::abs(r->summary.plane_error) * deg);
      if (!(jd <= max_jump)) max_jump = jd;
    }
    for (std::size_t k = 0; k < 3; ++k) {
      c.p_jump[k] = ok > 0 ? static_cast<double>(over[k]) / static_cast<double>(ok) : std::nan("");
      c.p_predicted[k] = predicted_jump_probability(base, c.alpha, c.h, anomaly_jump_thresholds_deg[k] / deg);
      const bool complete = record_threshold * deg <= anomaly_jump_thresholds_deg[k];
      c.mean_jumps[k] = ok > 0 && complete ? static_cast<double>(count[k]) / static_cast<double>(ok) : std::nan("");
      c.mean_predicted[k] = predicted_jump_count(base, c.alpha, c.h, anomaly_jump_thresholds_deg[k] / deg);
    }
    c.p_energy_loss = ok > 0 ? static_cast<double>(loss) / static_cast<double>(ok) : std::nan("");
    c.p_energy_predicted = predicted_jump_probability(base, c.alpha, c.h, std::asin(0.1));
    c.median_abs_plane_error_deg = quantile(plane, 0.5);
    c.p90_abs_plane_error_deg = quantile(plane, 0.9);
    c.max_jump_deg = max_jump;
    cells.push_back(c);
  }
  return cells;
}

}  // namespace geomint
