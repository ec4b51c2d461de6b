#pragma once
// Long loops that a caller can stop, and the progress they report. A program needs neither: its signal handler
// (output_run.hpp) ends the process at once. A caller that stays alive after an interrupt (the Python module)
// opens a Watch around each long call: the loops' interruption points then poll it every 0.1 s, and once it says
// stop, every point on every thread throws Interrupted, so the call unwinds and the caller raises its own error.
//
// The points cost a thread-local counter: the clock is read every 64th call, and the watch polled only on the
// thread that opened it (Python's signal handlers run on its main thread), at most every 0.1 s. Loops call
// interruption_point() once per step (or per item of similar cost).
//
// Progress: a task (Task) says how far the call is, as the programs' stderr progress line does (progress.hpp,
// same text: "<label>: done/total <unit> (x%)"); the watch hands the outermost task's line to its progress
// callback when it polls (nested tasks, e.g. the runs inside a convergence study, stay silent).
#include <atomic>
#include <functional>
#include <stdexcept>
#include <string>

namespace geomint {

// Thrown by an interruption point once the watch said stop (or the progress callback failed).
struct Interrupted : std::runtime_error {
  Interrupted() : std::runtime_error("interrupted") {}
};

class Watch {
 public:
  // poll: true to stop (called on this thread, at most every 0.1 s, while the watch lives); progress: given
  // (fraction in [0, 1], line) when the outermost task moved since the last poll. Either may throw: the
  // exception is kept, every point throws Interrupted, and rethrow_if_stopped() rethrows the kept one.
  Watch(std::function<bool()> poll, std::function<void(double, const std::string&)> progress);
  ~Watch();
  Watch(const Watch&) = delete;
  Watch& operator=(const Watch&) = delete;
  // The poll's or the callback's exception, if one stopped the call (on the watch's thread, after the call).
  void rethrow_if_stopped() const;
  // Polls now (on the watch's thread): a waiting loop that does not step (a join, a child process) calls it.
  static void poll_now();
};

// The slow path of interruption_point: throws Interrupted when a watch said stop; on the watch's thread, polls it
// when 0.1 s have passed.
void interruption_check();

inline void interruption_point() {
  thread_local unsigned count = 0;
  if ((++count & 63u) == 0) interruption_check();
}

// A loop's progress: done out of total units. Reports only while a watch is open and no outer task reports.
class Task {
 public:
  Task(std::string label, std::string unit, double total);
  ~Task();
  Task(const Task&) = delete;
  Task& operator=(const Task&) = delete;
  void set(double done) {
    if (owner_) done_.store(done, std::memory_order_relaxed);
  }
  void add(double n = 1) {
    if (!owner_) return;
    double d = done_.load(std::memory_order_relaxed);
    while (!done_.compare_exchange_weak(d, d + n, std::memory_order_relaxed)) {
    }
  }
  std::string line() const;
  double fraction() const;

 private:
  std::string label_, unit_;
  double total_;
  std::atomic<double> done_{0};
  bool owner_ = false;
};

// The programs' and the watch's shared progress text: "<label>: <done>/<total> <unit> (<percent>%)".
std::string progress_text(const std::string& label, double done, double total, const std::string& unit, double fraction);

}  // namespace geomint
