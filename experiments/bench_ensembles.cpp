// Benchmark (make bench): ensembles, in ns per trajectory-step, with Google Benchmark (medians of repetitions,
// every ratio between medians of this run).
//   - every oscillator scheme one trajectory at a time (scalar), and in structure-of-arrays form compiled for
//     each vector width the CPU has (sse2, avx2, avx512), on one thread and two;
//   - the floor: a hand-written vector loop of the same step (GCC vector extensions, the machine's widest
//     vectors, four vectors in flight, the whole state in registers) for `la` and `contact`;
//   - the Foucault schemes with both constraint discretizations as anomaly_foucault runs them (step plus the
//     anomaly detector): one run at a time (run_anomaly, the per-run loop) against the vectorized ensemble,
//     and a hand-written vector loop of the bare paper step (no detector) as its floor.
// Before timing, each vectorized kernel's result is compared bit for bit with the scalar path's.
//   bench_ensembles [--reps 9] [--out out] [--benchmark_filter=...]
// Writes out/bench_ensembles.tsv and out/bench_ensembles_ratios.tsv (timings: not reproducible by nature).
#include <cmath>
#include <cstdio>
#include <cstring>
#include <thread>

#include "geomint/constants.hpp"
#include "bench_table.hpp"
#include "geomint/cli.hpp"
#include "geomint/oscillator_ensemble.hpp"
#include "geomint/error.hpp"
#include "geomint/foucault_ensemble.hpp"
#include "geomint/io.hpp"
#include "geomint/systems/oscillator.hpp"
#include "geomint/simd.hpp"
#include "geomint/timing.hpp"

using namespace geomint;

namespace {

// ---- the floors: hand-written vector loops (GCC vector extensions), compiled per width like the kernels

template <int W>
struct Vec {
  typedef double type __attribute__((vector_size(8 * W)));
};

template <int W>
struct FloorContact {
  using V = typename Vec<W>::type;
  static GEOMINT_KERNEL_INLINE void run(double* q, double* p, double* z, std::size_t n, long steps, double h,
                                        double alpha) {
    constexpr int U = 6;  // independent vectors in flight: enough to hide the step's latency (tuned: 4-8)
    const double a = 1 - h * h / 2, b = h * (1 - h * alpha), ih = 1 / h, c = 1 - h * alpha, h2 = h / 2;
    for (std::size_t i0 = 0; i0 + W * U <= n; i0 += W * U) {
      V Q[U], P[U], Z[U];
      std::memcpy(Q, q + i0, sizeof Q);
      std::memcpy(P, p + i0, sizeof P);
      std::memcpy(Z, z + i0, sizeof Z);
      for (long j = 0; j < steps; ++j)
        for (int u = 0; u < U; ++u) {
          const V qn = a * Q[u] + b * P[u];
          const V v = (qn - Q[u]) * ih;
          Z[u] = Z[u] + h * (v * v / 2 - (Q[u] * Q[u] + qn * qn) / 4 - alpha * Z[u]);
          P[u] = c * P[u] - h2 * (qn + Q[u]);
          Q[u] = qn;
        }
      std::memcpy(q + i0, Q, sizeof Q);
      std::memcpy(p + i0, P, sizeof P);
      std::memcpy(z + i0, Z, sizeof Z);
    }
  }
};

template <int W>
struct FloorLa {
  using V = typename Vec<W>::type;
  static GEOMINT_KERNEL_INLINE void run(double* q, double* p, double*, std::size_t n, long steps, double h,
                                        double alpha) {
    constexpr int U = 8;  // tuned: 4-12
    const double c = 1 / (1 + h * alpha);
    for (std::size_t i0 = 0; i0 + W * U <= n; i0 += W * U) {
      V Q[U], P[U];
      std::memcpy(Q, q + i0, sizeof Q);
      std::memcpy(P, p + i0, sizeof P);
      for (long j = 0; j < steps; ++j)
        for (int u = 0; u < U; ++u) {
          P[u] = (P[u] - h * Q[u]) * c;
          Q[u] = Q[u] + h * P[u];
        }
      std::memcpy(q + i0, Q, sizeof Q);
      std::memcpy(p + i0, P, sizeof P);
    }
  }
};

// The bare paper steps (15) and (18) written out by hand (the formulas of step_xy), no detector.
struct LaNhFormula {
  template <class V>
  static GEOMINT_KERNEL_INLINE void step(const FoucaultParams<double>& p, double h, const V& xm, const V& ym,
                                         const V& x, const V& y, V& xn, V& yn) {
    const double c = 1 / h + p.alpha, ih = 1 / h, ic = 1 / c, hw2 = h * p.w2, csh = c * p.s * h;
    const V lm = csh + (xm * y - ym * x) / (h * (x * x + y * y));
    xn = x + ((x - xm) * ih - hw2 * x + lm * y) * ic;
    yn = y + ((y - ym) * ih - hw2 * y - lm * x) * ic;
  }
};
struct ContactNhFormula {
  template <class V>
  static GEOMINT_KERNEL_INLINE void step(const FoucaultParams<double>& p, double h, const V& xm, const V& ym,
                                         const V& x, const V& y, V& xn, V& yn) {
    const double damp = 1 - h * p.alpha, hh = h * h, k = hh * p.w2 * (1 - h * p.alpha / 2), sh = p.s * h;
    const V r2 = x * x + y * y;
    const V g = hh * ((sh * r2 + damp * (xm * y - ym * x)) / (hh * r2));
    xn = x + damp * (x - xm) - k * x + g * y;
    yn = y + damp * (y - ym) - k * y - g * x;
  }
};
template <int W, class Formula>
struct FloorFoucault {
  using V = typename Vec<W>::type;
  static GEOMINT_KERNEL_INLINE void run(const FoucaultParams<double>& prm, double h, double* xm, double* ym, double* x,
                                        double* y, std::size_t n, long steps) {
    constexpr int U = 4;
    for (std::size_t i0 = 0; i0 + W * U <= n; i0 += W * U) {
      V XM[U], YM[U], X[U], Y[U];
      std::memcpy(XM, xm + i0, sizeof XM);
      std::memcpy(YM, ym + i0, sizeof YM);
      std::memcpy(X, x + i0, sizeof X);
      std::memcpy(Y, y + i0, sizeof Y);
      for (long j = 0; j < steps; ++j)
        for (int u = 0; u < U; ++u) {
          V xn, yn;
          Formula::step(prm, h, XM[u], YM[u], X[u], Y[u], xn, yn);
          XM[u] = X[u];
          YM[u] = Y[u];
          X[u] = xn;
          Y[u] = yn;
        }
      std::memcpy(xm + i0, XM, sizeof XM);
      std::memcpy(ym + i0, YM, sizeof YM);
      std::memcpy(x + i0, X, sizeof X);
      std::memcpy(y + i0, Y, sizeof Y);
    }
  }
};

// The floor at the widest width this CPU has (the floor is "this machine's").
template <template <int> class Floor, class... Args>
void run_floor(Args&&... args) {
  switch (best_simd()) {
    case Simd::avx512: return simd_detail::run_avx512<Floor<8>>(args...);
    case Simd::avx2: return simd_detail::run_avx2<Floor<4>>(args...);
    default: return simd_detail::run_sse2<Floor<2>>(args...);
  }
}
template <int W>
using FloorLaNh = FloorFoucault<W, LaNhFormula>;
template <int W>
using FloorContactNh = FloorFoucault<W, ContactNhFormula>;
using FoucaultFloor = void (*)(const FoucaultParams<double>&, double, double*, double*, double*, double*, std::size_t, long);
void floor_la_nh(const FoucaultParams<double>& p, double h, double* xm, double* ym, double* x, double* y,
                 std::size_t n, long steps) {
  run_floor<FloorLaNh>(p, h, xm, ym, x, y, n, steps);
}
void floor_contact_nh(const FoucaultParams<double>& p, double h, double* xm, double* ym, double* x, double* y,
                      std::size_t n, long steps) {
  run_floor<FloorContactNh>(p, h, xm, ym, x, y, n, steps);
}

}  // namespace

int main(int argc, char** argv) {
  return guarded_main("bench_ensembles", [&] {
    auto args = bench::Table::split_args(argc, argv);
    int reps = 9;
    Cli cli("bench_ensembles", "ensembles: ns per trajectory-step, scalar vs vector vs threads vs hand-written floor");
    cli.options.add_options()("reps", po::value(&reps)->default_value(reps), "timed repetitions (median reported)");
    if (!cli.parse(argc, args.data())) return 0;
    require(reps >= 3 && reps <= 1000, "reps must be at least 3 (and at most 1000)");
    const auto dir = prepare_output_dir(cli.out);
    bench::Table table(reps, 0.05);
    const std::vector<Simd> widths = supported_simd();
    const Simd best = best_simd();
    std::printf("vector widths on this CPU: best %s; hardware threads %u\n", to_string(best),
                std::thread::hardware_concurrency());

    // ---- oscillator: M trajectories (96 KB of state: cache-resident), Ne steps per call
    const std::size_t M = 4096;
    const long Ne = 20000;  // ~7 ms per call at the floor: a thread's start-up is noise
    const double h = 0.01, alpha = 0.1;
    auto init = [&](OscEnsemble& e) {
      for (std::size_t i = 0; i < M; ++i) {
        e.q[i] = -0.25 + 1e-6 * static_cast<double>(i);
        e.p[i] = 0.75;
        e.z[i] = 0;
      }
    };
    long mismatches = 0;
    auto osc = [&](auto scheme) {
      using S = decltype(scheme);
      // bit-identity first: every width against the scalar path
      OscEnsemble ref(M);
      init(ref);
      step_ensemble<S>(ref, 100, h, alpha, 1, Simd::scalar);
      for (Simd w : widths) {
        OscEnsemble e(M);
        init(e);
        step_ensemble<S>(e, 100, h, alpha, 2, w);
        if (std::memcmp(e.q.data(), ref.q.data(), M * sizeof(double)) ||
            std::memcmp(e.p.data(), ref.p.data(), M * sizeof(double)) ||
            std::memcmp(e.z.data(), ref.z.data(), M * sizeof(double))) {
          ++mismatches;
          std::printf("  BITS DIFFER: %s %s\n", S::name, to_string(w));
        }
      }
      const std::string n = S::name;
      const double units = static_cast<double>(M) * Ne;
      for (Simd w : widths) {
        const long steps = w == Simd::scalar ? Ne / 10 : Ne;  // the scalar path is slow: fewer steps per call
        table.add("oscillator", n + " " + to_string(w), static_cast<double>(M) * steps, [=] {
          OscEnsemble e(M);
          init(e);
          step_ensemble<S>(e, steps, h, alpha, 1, w);
          do_not_optimize(e.q[M / 2]);
        });
      }
      table.add("oscillator", n + " " + to_string(best) + " 2 threads", units, [=] {
        OscEnsemble e(M);
        init(e);
        step_ensemble<S>(e, Ne, h, alpha, 2, best);
        do_not_optimize(e.q[M / 2]);
      });
    };
    osc(systems::Oscillator::La{});
    osc(systems::Oscillator::Contact{});
    osc(systems::Oscillator::LaPrinted{});
    osc(systems::Oscillator::LaMidpoint{});
    osc(systems::Oscillator::ContactSymmetric{});
    osc(systems::Oscillator::Leapfrog{});
    osc(systems::Oscillator::ConformalStrang{});
    // the floors, checked against the library's bits too
    const std::size_t Mc = M - M % 48;
    {
      OscEnsemble a(M), b(M);
      init(a);
      init(b);
      step_ensemble<systems::Oscillator::Contact>(a, 100, h, alpha, 1, Simd::scalar);
      run_floor<FloorContact>(b.q.data(), b.p.data(), b.z.data(), M, 100L, h, alpha);
      // the contact floor steps whole groups of 6 vectors: the first Mc trajectories (48 | Mc, so any width)
      const auto head = [&](const std::vector<double>& v) { return std::vector<double>(v.begin(), v.begin() + Mc); };
      if (head(a.q) != head(b.q) || head(a.p) != head(b.p) || head(a.z) != head(b.z))
        std::printf("  note: the contact floor's bits differ from the library's\n");
      init(a);
      init(b);
      step_ensemble<systems::Oscillator::La>(a, 100, h, alpha, 1, Simd::scalar);
      run_floor<FloorLa>(b.q.data(), b.p.data(), b.z.data(), M, 100L, h, alpha);
      if (a.q != b.q || a.p != b.p) std::printf("  note: the la floor's bits differ from the library's\n");
    }
    table.add("oscillator", "contact floor (hand-written vector loop)", static_cast<double>(Mc) * Ne, [=] {
      OscEnsemble e(M);
      init(e);
      run_floor<FloorContact>(e.q.data(), e.p.data(), e.z.data(), M, Ne, h, alpha);
      do_not_optimize(e.q[M / 2]);
    });
    table.add("oscillator", "la floor (hand-written vector loop)", static_cast<double>(M) * Ne, [=] {
      OscEnsemble e(M);
      init(e);
      run_floor<FloorLa>(e.q.data(), e.p.data(), e.z.data(), M, Ne, h, alpha);
      do_not_optimize(e.q[M / 2]);
    });

    // ---- Foucault: one cell (alpha = 1e-4, h = 0.01) as anomaly_foucault runs it, T = 360 s (36000 steps)
    systems::FoucaultPendulum base;
    base.T = 360;
    const double hf = 0.01, af = 1e-4, thr = 0.1 * geomint::pi / 180;
    const long Nf = step_count(hf, base.T);
    const long R = 256;  // runs per ensemble call: two batches of 128 (one per thread with two threads)
    for (const char* sn : {"la-nh", "contact-nh"})
      for (const char* sys : {systems::Foucault::name, systems::FoucaultRotation::name}) {
        const auto cases = anomaly_cases({hf}, {af}, {sn}, {sys}, R);
        const std::string n = std::string(sn) + " " + systems::foucault_discretization(sys);
        // bit-identity first
        const auto ref = run_anomaly_ensemble(base, {cases.begin(), cases.begin() + 8}, thr, 1, {}, Simd::scalar);
        for (Simd w : widths) {
          const auto got = run_anomaly_ensemble(base, {cases.begin(), cases.begin() + 8}, thr, 1, {}, w);
          for (std::size_t i = 0; i < ref.size(); ++i)
            if (!same_bits(got[i], ref[i])) {
              ++mismatches;
              std::printf("  BITS DIFFER: %s %s run %zu\n", n.c_str(), to_string(w), i);
              break;
            }
        }
        table.add("foucault", n + " per-run loop (run_anomaly)", static_cast<double>(Nf), [=] {
          const auto r = run_anomaly(base, cases[3], thr);
          do_not_optimize(r.summary.E_end);
        });
        for (Simd w : widths) {
          if (w == Simd::scalar) continue;
          table.add("foucault", n + " ensemble " + to_string(w), static_cast<double>(Nf) * R, [=] {
            const auto r = run_anomaly_ensemble(base, cases, thr, 1, {}, w);
            do_not_optimize(r[5].summary.E_end);
          });
        }
        table.add("foucault", n + " ensemble " + to_string(best) + " 2 threads", static_cast<double>(Nf) * R, [=] {
          const auto r = run_anomaly_ensemble(base, cases, thr, 2, {}, best);
          do_not_optimize(r[5].summary.E_end);
        });
      }
    {
      systems::FoucaultPendulum sc = base;
      sc.alpha = af;
      const FoucaultParams<double> fp(sc);
      const std::size_t Mf = 128;
      auto floor_case = [&](const char* name, FoucaultFloor go) {
        table.add("foucault", name, static_cast<double>(Nf) * Mf, [=] {
          std::vector<double> xm(Mf), ym(Mf, 0.0), x(Mf), y(Mf, 1e-3);
          for (std::size_t i = 0; i < Mf; ++i) {
            x[i] = 0.67 - 1e-7 * static_cast<double>(i);
            xm[i] = x[i];
          }
          go(fp, hf, xm.data(), ym.data(), x.data(), y.data(), Mf, Nf);
          do_not_optimize(x[7]);
        });
      };
      floor_case("la-nh paper floor (bare step, hand-written vector loop)", floor_la_nh);
      floor_case("contact-nh paper floor (bare step, hand-written vector loop)", floor_contact_nh);
    }

    std::printf("bit-identity before timing: %s\n\n", mismatches == 0 ? "every width and thread count agrees with the scalar path" : "MISMATCHES (see above)");
    std::printf("ns per trajectory-step, median of %d\n", reps);
    table.run();

    struct Ratio {
      std::string what;
      double value, target;
      bool less;
    };
    std::vector<Ratio> ratios;
    const std::string b = to_string(best);
    for (const char* s : {"la", "contact"})
      ratios.push_back({std::string(s) + " ensemble " + b + " / hand-written floor",
                        table.ns(std::string(s) + " " + b) / table.ns(std::string(s) + " floor (hand-written vector loop)"),
                        1.3, true});
    for (const char* s : {"la", "contact", "la-printed", "la-midpoint", "contact-sym", "leapfrog", "conformal-strang"}) {
      ratios.push_back({std::string(s) + " scalar / " + b, table.ns(std::string(s) + " scalar") / table.ns(std::string(s) + " " + b), 0, false});
      ratios.push_back({std::string(s) + " " + b + " 1 thread / 2 threads",
                        table.ns(std::string(s) + " " + b) / table.ns(std::string(s) + " " + b + " 2 threads"),
                        std::string(s) == "la" || std::string(s) == "contact" ? 1.8 : 0, false});
    }
    for (const char* s : {"la-nh", "contact-nh"})
      for (const char* c : {"paper", "rotation"}) {
        const std::string n = std::string(s) + " " + c;
        ratios.push_back({n + " per-run loop / ensemble " + b + " (1 thread)",
                          table.ns(n + " per-run loop (run_anomaly)") / table.ns(n + " ensemble " + b), 6, false});
        ratios.push_back({n + " ensemble 1 thread / 2 threads",
                          table.ns(n + " ensemble " + b) / table.ns(n + " ensemble " + b + " 2 threads"), 0, false});
        if (std::string(c) == "paper")
          ratios.push_back({n + " ensemble (with detector) / bare-step floor",
                            table.ns(n + " ensemble " + b) /
                                table.ns(n + " floor (bare step, hand-written vector loop)"),
                            0, false});
      }
    std::printf("\nratios (medians of this run)\n");
    for (const auto& r : ratios) {
      const bool ok = r.target == 0 || (r.less ? r.value <= r.target : r.value >= r.target);
      std::printf("  %-58s %8.2f %s\n", r.what.c_str(), r.value,
                  r.target == 0 ? "" : (ok ? "(target met)" : "(TARGET MISSED)"));
    }
    const Params params{{"oscillator", "M = " + std::to_string(M) + " trajectories, " + std::to_string(Ne) +
                                           " steps per call, h = " + format_number(h) + ", alpha = " + format_number(alpha)},
                        {"foucault", std::to_string(R) + " runs of one cell, h = " + format_number(hf) + ", alpha = " +
                                         format_number(af) + ", T = " + format_number(base.T)},
                        {"reps", std::to_string(reps)},
                        {"best simd", b},
                        {"note", "timings (Google Benchmark); medians over reps"}};
    table.write_tsv(dir / "bench_ensembles.tsv", "bench_ensembles", params);
    TsvWriter rt(dir / "bench_ensembles_ratios.tsv", "bench_ensembles", params, {"ratio", "value", "target"});
    for (const auto& r : ratios)
      rt.row(r.what, r.value, r.target == 0 ? std::string("-") : (r.less ? "<= " : ">= ") + format_number(r.target));
    rt.commit();
    return mismatches == 0 ? 0 : 1;
  });
}
