#include "geomint/progress.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdio>

#include "geomint/interrupt.hpp"

namespace geomint {

Progress::Progress(std::string label, std::string unit, bool enabled)
    : label_(std::move(label)), unit_(std::move(unit)), active_(enabled && ::isatty(STDERR_FILENO) == 1),
      start_(std::chrono::steady_clock::now()), last_(start_) {}

Progress::~Progress() { done(); }

void Progress::update(std::size_t done, std::size_t total, double work_fraction) {
  if (!active_) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - last_ < std::chrono::milliseconds(500) && done < total) return;
  last_ = now;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double w = work_fraction >= 0 ? work_fraction : (total ? static_cast<double>(done) / static_cast<double>(total) : 1);
  const double rate = elapsed > 0 ? static_cast<double>(done) / elapsed : 0;
  char left[32] = "?";
  if (w > 0) std::snprintf(left, sizeof left, "%.0f s", elapsed * (1 - w) / w);
  // \r and clear-to-end-of-line: the line is rewritten in place
  // the same text as a watched call's progress (interrupt.hpp), then the rate and the time left
  const std::string head = progress_text(label_, static_cast<double>(done), static_cast<double>(total), unit_, w);
  std::fprintf(stderr, "\r%s, %.3g %s/s, %.0f s elapsed, ~%s left\033[K", head.c_str(), rate, unit_.c_str(), elapsed,
               left);
  std::fflush(stderr);
  shown_ = true;
}

void Progress::done() {
  if (shown_) {
    std::fputc('\n', stderr);
    std::fflush(stderr);
  }
  shown_ = false;
  active_ = false;
}

}  // namespace geomint
