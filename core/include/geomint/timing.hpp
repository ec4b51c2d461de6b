#pragma once
// Timing for benchmarks and work–precision studies (never for tests): warm up, repeat, take the median.
#include <algorithm>
#include <chrono>
#include <vector>

namespace geomint {

// Keeps the compiler from discarding a computed value.
template <class T>
inline void do_not_optimize(const T& value) {
  asm volatile("" : : "r,m"(value) : "memory");
}

struct TimingStats {
  double median, min, max;  // seconds
  int reps;
};

// Runs fn once to warm up, then `reps` times (at least), and returns the median wall time.
template <class F>
TimingStats time_median(F&& fn, int reps = 7) {
  fn();
  std::vector<double> t;
  for (int r = 0; r < reps; ++r) {
    const auto a = std::chrono::steady_clock::now();
    fn();
    const auto b = std::chrono::steady_clock::now();
    t.push_back(std::chrono::duration<double>(b - a).count());
  }
  std::sort(t.begin(), t.end());
  return {t[t.size() / 2], t.front(), t.back(), reps};
}

}  // namespace geomint
