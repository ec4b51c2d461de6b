#pragma once
// Ensembles: many trajectories of one oscillator scheme stepped together in a structure-of-arrays layout,
// so the inner loop over trajectories vectorizes, and split across threads.
#include <algorithm>
#include <cstddef>
#include <thread>
#include <vector>

#include "geomint/oscillator.hpp"

namespace geomint {

struct OscEnsemble {
  std::vector<double> q, p, z;
  explicit OscEnsemble(std::size_t n) : q(n), p(n), z(n) {}
  std::size_t size() const { return q.size(); }
};

// Advances trajectories [begin, end) by `steps` steps. The state of each trajectory lives in registers
// for the whole inner loop; the loop over trajectories is the vectorized one.
template <class Scheme>
void step_ensemble_range(OscEnsemble& e, std::size_t begin, std::size_t end, long steps, double h, double alpha) {
  double* __restrict q = e.q.data();
  double* __restrict p = e.p.data();
  double* __restrict z = e.z.data();
  for (long j = 0; j < steps; ++j) {
#pragma GCC ivdep
    for (std::size_t i = begin; i < end; ++i) {
      OscState<double> s{q[i], p[i], z[i]};
      Scheme::step(s, h, alpha);
      q[i] = s.q;
      p[i] = s.p;
      z[i] = s.z;
    }
  }
}

// The same over `threads` threads, each owning a contiguous block of trajectories (in blocks that fit
// in L1, so the sweep over steps stays cache-resident).
template <class Scheme>
void step_ensemble(OscEnsemble& e, long steps, double h, double alpha, unsigned threads = 1) {
  const std::size_t n = e.size();
  const std::size_t block = 512;
  auto work = [&](std::size_t lo, std::size_t hi) {
    for (std::size_t b = lo; b < hi; b += block) step_ensemble_range<Scheme>(e, b, std::min(hi, b + block), steps, h, alpha);
  };
  if (threads <= 1) {
    work(0, n);
    return;
  }
  std::vector<std::thread> pool;
  const std::size_t chunk = (n + threads - 1) / threads;
  for (unsigned t = 0; t < threads; ++t) {
    const std::size_t lo = std::min(n, t * chunk), hi = std::min(n, lo + chunk);
    if (lo < hi) pool.emplace_back(work, lo, hi);
  }
  for (auto& th : pool) th.join();
}

}  // namespace geomint
