#pragma once
// Independent items on a few threads: fn(i) for every i in [0, n), each thread pulling the next index. fn must
// write only the i-th result (the results, and so the files, do not depend on the thread count). The first
// exception thrown by any fn is rethrown once every thread has stopped; the remaining items are skipped (an
// interrupt of a watched call, interrupt.hpp, is such an exception).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "geomint/interrupt.hpp"

namespace geomint {

// The default worker count of a program's --threads: the cores this process may use.
inline unsigned default_threads() { return std::max(1u, std::thread::hardware_concurrency()); }

template <class Fn>
void parallel_for(std::size_t n, unsigned threads, Fn&& fn) {
  const std::size_t workers = std::min<std::size_t>(std::max(1u, threads), n);
  if (workers <= 1) {
    for (std::size_t i = 0; i < n; ++i) fn(i);
    return;
  }
  std::atomic<std::size_t> next{0};
  std::atomic<bool> stop{false};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto work = [&] {
    for (std::size_t i; !stop.load(std::memory_order_relaxed) && (i = next.fetch_add(1)) < n;) {
      try {
        fn(i);
      } catch (...) {
        const std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
        stop = true;
      }
    }
  };
  std::atomic<std::size_t> finished{0};
  std::vector<std::thread> pool;
  for (std::size_t w = 1; w < workers; ++w)
    pool.emplace_back([&] {
      work();
      ++finished;
    });
  work();
  // The calling thread polls a watched call's interrupt while the others finish their last items (interrupt.hpp):
  // an interrupt then stops them at their next interruption point.
  while (finished.load() < pool.size()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    try {
      interruption_check();
    } catch (...) {
      const std::lock_guard<std::mutex> lock(error_mutex);
      if (!error) error = std::current_exception();
      stop = true;
    }
  }
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace geomint
