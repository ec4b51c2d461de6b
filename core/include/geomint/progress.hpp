#pragma once
// A progress line for long sweeps on stderr — runs done, rate, time left — only when stderr is a terminal
// (isatty), and silent otherwise, so logs, pipes, CI and the tests see nothing. One line, rewritten in place
// at most every half second, ended by done() (or the destructor) if it was ever shown.
//
//   Progress progress("anomaly_foucault", "runs");
//   progress.update(done, total, work_fraction);   // any thread-safe point; work_fraction in [0, 1] (or < 0:
//                                                   // use done / total) drives the estimate of the time left
//   progress.done();
#include <chrono>
#include <cstddef>
#include <string>

namespace geomint {

class Progress {
 public:
  // enabled: false forces silence (e.g. ranks other than 0); a terminal is still required to print.
  Progress(std::string label, std::string unit, bool enabled = true);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  void update(std::size_t done, std::size_t total, double work_fraction = -1);
  void done();
  bool active() const { return active_; }

 private:
  std::string label_, unit_;
  bool active_;
  bool shown_ = false;
  std::chrono::steady_clock::time_point start_, last_;
};

}  // namespace geomint
