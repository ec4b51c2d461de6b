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

// For calls too short to time alone: repeats fn so each timed sample lasts >= min_seconds, and returns
// the median time of one call.
template <class F>
TimingStats time_per_call(F&& fn, int reps = 5, double min_seconds = 2e-3) {
  const auto once = time_median(fn, 1);
  const int inner = std::max(1, static_cast<int>(min_seconds / std::max(once.median, 1e-9)));
  auto st = time_median([&] { for (int i = 0; i < inner; ++i) fn(); }, reps);
  st.median /= inner;
  st.min /= inner;
  st.max /= inner;
  return st;
}

}  // namespace geomint
