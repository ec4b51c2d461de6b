#include "geomint/interrupt.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <mutex>
#include <thread>

namespace geomint {

namespace {

using Clock = std::chrono::steady_clock;
constexpr auto poll_interval = std::chrono::milliseconds(100);

// One watch at a time (a module call holds the GIL while it opens one, so calls do not overlap).
struct WatchState {
  std::function<bool()> poll;
  std::function<void(double, const std::string&)> progress;
  std::thread::id thread;
  Clock::time_point last;
  std::exception_ptr error;  // what stopped the call: the poll's or the callback's exception
  std::string last_line;
};
WatchState* g_watch = nullptr;          // written only by the watch's thread while no call runs
std::atomic<bool> g_stop{false};        // read by every point on every thread
std::atomic<Task*> g_task{nullptr};     // the outermost task of the watched call

void poll_watch(WatchState& w) {
  w.last = Clock::now();
  try {
    if (const Task* t = g_task.load(); t != nullptr && w.progress) {
      std::string line = t->line();
      if (line != w.last_line) {
        w.last_line = line;
        w.progress(t->fraction(), line);
      }
    }
    if (w.poll && w.poll()) g_stop = true;
  } catch (...) {
    w.error = std::current_exception();
    g_stop = true;
  }
}

}  // namespace

Watch::Watch(std::function<bool()> poll, std::function<void(double, const std::string&)> progress) {
  g_stop = false;
  g_task = nullptr;
  g_watch = new WatchState{std::move(poll), std::move(progress), std::this_thread::get_id(), Clock::now(), nullptr, ""};
}

Watch::~Watch() {
  delete g_watch;
  g_watch = nullptr;
  g_stop = false;
  g_task = nullptr;
}

void Watch::rethrow_if_stopped() const {
  if (g_watch != nullptr && g_watch->error) std::rethrow_exception(g_watch->error);
}

void Watch::poll_now() {
  if (g_watch != nullptr && g_watch->thread == std::this_thread::get_id()) poll_watch(*g_watch);
  if (g_stop.load(std::memory_order_relaxed)) throw Interrupted();
}

void interruption_check() {
  if (g_stop.load(std::memory_order_relaxed)) throw Interrupted();
  WatchState* w = g_watch;
  if (w == nullptr || w->thread != std::this_thread::get_id()) return;
  if (Clock::now() - w->last < poll_interval) return;
  poll_watch(*w);
  if (g_stop.load(std::memory_order_relaxed)) throw Interrupted();
}

Task::Task(std::string label, std::string unit, double total)
    : label_(std::move(label)), unit_(std::move(unit)), total_(total) {
  // Only on the watch's thread: the poll reads the task there, so a task never ends while it is read.
  if (g_watch == nullptr || g_watch->thread != std::this_thread::get_id()) return;
  Task* none = nullptr;
  owner_ = g_task.compare_exchange_strong(none, this);
}

Task::~Task() {
  if (!owner_) return;
  // A task that ran to its end reports its last state, so that a progress bar reaches its end even when the task
  // took less than one poll interval; an unwinding one (interrupted, failed) reports nothing more. An exception the
  // callback raises here is kept for the watched call to raise (Watch::rethrow_if_stopped).
  WatchState* w = g_watch;
  if (w != nullptr && w->progress && std::uncaught_exceptions() == 0) {
    try {
      std::string text = line();
      if (text != w->last_line) {
        w->last_line = text;
        w->progress(fraction(), text);
      }
    } catch (...) {
      if (!w->error) w->error = std::current_exception();
      g_stop = true;
    }
  }
  g_task = nullptr;
}

double Task::fraction() const {
  const double d = done_.load(std::memory_order_relaxed);
  return total_ > 0 ? std::min(1.0, std::max(0.0, d / total_)) : 0.0;
}

std::string Task::line() const { return progress_text(label_, done_.load(std::memory_order_relaxed), total_, unit_, fraction()); }

std::string progress_text(const std::string& label, double done, double total, const std::string& unit, double fraction) {
  char buf[160];
  std::snprintf(buf, sizeof buf, ": %.0f/%.0f %s (%.0f%%)", done, total, unit.c_str(), 100 * fraction);
  return label + buf;
}

}  // namespace geomint
