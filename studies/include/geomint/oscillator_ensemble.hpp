#pragma once
// Ensembles: many trajectories of one oscillator scheme stepped together in a structure-of-arrays layout,
// vectorized with the machine's widest vectors (simd.hpp) and split across threads. Every trajectory gets
// the bits that Scheme::step gives it alone (tests/studies/simd_ensemble.test.cpp): the kernel calls Scheme::step
// itself, lane by lane, and GCC vectorizes the loop over lanes for each instruction set.
#include <algorithm>
#include <cstddef>
#include <thread>
#include <vector>

#include "geomint/systems/oscillator.hpp"
#include "geomint/simd.hpp"

namespace geomint {

struct OscEnsemble {
  std::vector<double> q, p, z;
  explicit OscEnsemble(std::size_t n) : q(n), p(n), z(n) {}
  std::size_t size() const { return q.size(); }
};

namespace detail {
// Trajectories [begin, end) advanced by `steps` steps. The loop over trajectories is the vectorized one; the
// steps go round it, so each pass reads and writes the block once per step (kept small enough for L1).
template <class Scheme>
struct OscEnsembleKernel {
  static GEOMINT_KERNEL_INLINE void run(double* __restrict q, double* __restrict p, double* __restrict z,
                                        std::size_t n, long steps, double h, double alpha) {
    for (long j = 0; j < steps; ++j) {
#pragma GCC ivdep
      for (std::size_t i = 0; i < n; ++i) {
        OscState<double> s{q[i], p[i], z[i]};
        Scheme::step(s, h, alpha);
        q[i] = s.q;
        p[i] = s.p;
        z[i] = s.z;
      }
    }
  }
};
}  // namespace detail

// Advances trajectories [begin, end) by `steps` steps. Simd::scalar steps each trajectory alone, all steps at a
// time (what the system's run_fast does); the other choices run the vectorized kernel compiled for that width.
template <class Scheme>
void step_ensemble_range(OscEnsemble& e, std::size_t begin, std::size_t end, long steps, double h, double alpha,
                         Simd simd = best_simd()) {
  if (simd == Simd::scalar) {
    for (std::size_t i = begin; i < end; ++i) {
      OscState<double> s{e.q[i], e.p[i], e.z[i]};
      for (long j = 0; j < steps; ++j) Scheme::step(s, h, alpha);
      e.q[i] = s.q;
      e.p[i] = s.p;
      e.z[i] = s.z;
    }
    return;
  }
  simd_dispatch<detail::OscEnsembleKernel<Scheme>>(simd, e.q.data() + begin, e.p.data() + begin, e.z.data() + begin,
                                                    end - begin, steps, h, alpha);
}

// The same over `threads` threads, each owning a contiguous block of trajectories, in blocks of 256 (6 KB of
// state: the sweep over steps stays in L1).
template <class Scheme>
void step_ensemble(OscEnsemble& e, long steps, double h, double alpha, unsigned threads = 1, Simd simd = best_simd()) {
  const std::size_t n = e.size();
  const std::size_t block = 256;
  auto work = [&](std::size_t lo, std::size_t hi) {
    for (std::size_t b = lo; b < hi; b += block)
      step_ensemble_range<Scheme>(e, b, std::min(hi, b + block), steps, h, alpha, simd);
  };
  if (threads <= 1) {
    work(0, n);
    return;
  }
  std::vector<std::thread> pool;
  // blocks, not trajectories, are dealt out, so every thread's share stays a multiple of the vector width
  const std::size_t blocks = (n + block - 1) / block, per = (blocks + threads - 1) / threads;
  for (unsigned t = 1; t < threads; ++t) {
    const std::size_t lo = std::min(n, t * per * block), hi = std::min(n, lo + per * block);
    if (lo < hi) pool.emplace_back(work, lo, hi);
  }
  work(0, std::min(n, per * block));
  for (auto& th : pool) th.join();
}

}  // namespace geomint
