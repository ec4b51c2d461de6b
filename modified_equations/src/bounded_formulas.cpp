#include "geomint/modified/bounded_formulas.hpp"

#include <poll.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstring>
#include <stdexcept>

#include "geomint/error.hpp"
#include "geomint/interrupt.hpp"

namespace geomint::modified {

namespace {

using Clock = std::chrono::steady_clock;

// A record: its kind ('R' a result, 'I' an InputError, 'E' another error), its length, its bytes.
struct Writer {
  std::string s;
  Writer& put(const std::string& x) {
    put(static_cast<std::uint64_t>(x.size()));
    s += x;
    return *this;
  }
  Writer& put(std::uint64_t x) {
    s.append(reinterpret_cast<const char*>(&x), sizeof x);
    return *this;
  }
  Writer& put(double x) {
    s.append(reinterpret_cast<const char*>(&x), sizeof x);
    return *this;
  }
};

struct Reader {
  const std::string& s;
  std::size_t at = 0;
  void raw(void* p, std::size_t n) {
    require(at + n <= s.size(), "internal: a short record from the formula process");
    std::memcpy(p, s.data() + at, n);
    at += n;
  }
  std::uint64_t u() {
    std::uint64_t x = 0;
    raw(&x, sizeof x);
    return x;
  }
  double d() {
    double x = 0;
    raw(&x, sizeof x);
    return x;
  }
  std::string str() {
    const auto n = static_cast<std::size_t>(u());
    require(at + n <= s.size(), "internal: a short record from the formula process");
    std::string x = s.substr(at, n);
    at += n;
    return x;
  }
};

std::string pack(const ModifiedFormulas& f) {
  Writer w;
  w.put(static_cast<std::uint64_t>(f.K_asked)).put(static_cast<std::uint64_t>(f.K)).put(std::uint64_t{f.stopped});
  w.put(f.seconds).put(f.budget).put(static_cast<std::uint64_t>(f.symbols.size()));
  for (const auto& s : f.symbols) w.put(s);
  w.put(static_cast<std::uint64_t>(f.values.size()));
  for (const auto& [k, v] : f.values) w.put(k).put(v);
  w.put(static_cast<std::uint64_t>(f.rows.size()));
  for (const auto& r : f.rows)
    w.put(r.quantity).put(static_cast<std::uint64_t>(r.k)).put(r.text).put(r.mathematica).put(r.latex).put(static_cast<std::uint64_t>(r.size));
  w.put(static_cast<std::uint64_t>(f.size)).put(f.chart);
  return w.s;
}

ModifiedFormulas unpack(const std::string& s) {
  Reader r{s};
  ModifiedFormulas f;
  f.K_asked = static_cast<int>(r.u());
  f.K = static_cast<int>(r.u());
  f.stopped = r.u() != 0;
  f.seconds = r.d();
  f.budget = r.d();
  for (auto n = r.u(); n > 0; --n) f.symbols.push_back(r.str());
  for (auto n = r.u(); n > 0; --n) {
    std::string k = r.str();
    f.values.emplace_back(std::move(k), r.d());
  }
  for (auto n = r.u(); n > 0; --n) {
    FormulaRow row;
    row.quantity = r.str();
    row.k = static_cast<int>(r.u());
    row.text = r.str();
    row.mathematica = r.str();
    row.latex = r.str();
    row.size = static_cast<std::size_t>(r.u());
    f.rows.push_back(std::move(row));
  }
  f.size = static_cast<std::size_t>(r.u());
  f.chart = r.str();
  return f;
}

bool write_all(int fd, const std::string& bytes) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t w = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return false;
    done += static_cast<std::size_t>(w);
  }
  return true;
}

void send(int fd, char kind, const std::string& body) {
  Writer w;
  w.s += kind;
  w.put(body);
  if (!write_all(fd, w.s)) ::_exit(3);
}

// The child: orders 0..K, each sent when done; ends with _exit (the parent's atexit handlers, Python's among them,
// are not the child's to run).
[[noreturn]] void child(int fd, const ModifiedSystem& ms, const ParamValues& pv, const std::string& scheme, int K,
                        double budget, bool on_constraint, Clock::time_point start) {
  // The parent's interrupt handlers (a program's cleanup of its outputs, Python's) are not the child's: a signal
  // ends it, and so does the parent's death.
  for (int s = 1; s < NSIG; ++s)
    if (s != SIGKILL && s != SIGSTOP) std::signal(s, SIG_DFL);
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (::getppid() == 1) ::_exit(4);
  try {
    for (int k = 0; k <= K; ++k) {
      const double left = budget - std::chrono::duration<double>(Clock::now() - start).count();
      if (left <= 0) break;
      const ModifiedFormulas f = ms.formulas(pv, scheme, k, left, on_constraint);
      send(fd, 'R', pack(f));
      if (f.stopped) break;
    }
    ::_exit(0);
  } catch (const InputError& e) {
    send(fd, 'I', e.what());
  } catch (const std::exception& e) {
    send(fd, 'E', e.what());
  } catch (...) {
    send(fd, 'E', "unknown error");
  }
  ::_exit(1);
}

}  // namespace

ModifiedFormulas bounded_formulas(const ModifiedSystem& ms, const ParamValues& pv, const std::string& scheme, int K,
                                  double budget_seconds, bool on_constraint) {
  require(std::isfinite(budget_seconds) && budget_seconds > 0, "budget must be a positive number of seconds");
  const Clock::time_point start = Clock::now();
  int fds[2];
  require(::pipe(fds) == 0, std::string("cannot open a pipe for the formula process: ") + std::strerror(errno));
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    throw InputError(std::string("cannot start the formula process: ") + std::strerror(errno));
  }
  if (pid == 0) {
    ::close(fds[0]);
    child(fds[1], ms, pv, scheme, K, budget_seconds, on_constraint, start);
  }
  ::close(fds[1]);
  const int fd = fds[0];
  auto finish = [&](bool kill) {
    if (kill) ::kill(pid, SIGKILL);
    ::close(fd);
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    return status;
  };

  Task task("modified_formulas", "orders", K + 1);  // a watched call's progress (interrupt.hpp)
  std::string buffer;
  ModifiedFormulas last;
  bool have = false;
  std::string error;
  char error_kind = 0;
  bool eof = false, out_of_time = false;
  try {
    while (!eof) {
      const double left = budget_seconds - std::chrono::duration<double>(Clock::now() - start).count();
      if (left <= 0) {
        out_of_time = true;
        break;
      }
      pollfd p{fd, POLLIN, 0};
      const int wait_ms = static_cast<int>(std::min(100.0, std::ceil(left * 1000)));
      const int r = ::poll(&p, 1, wait_ms);
      Watch::poll_now();  // a watched call's interrupt (throws Interrupted)
      if (r < 0 && errno != EINTR) throw InputError(std::string("formula process: poll: ") + std::strerror(errno));
      if (r <= 0) continue;
      char chunk[65536];
      const ssize_t got = ::read(fd, chunk, sizeof chunk);
      if (got < 0 && errno == EINTR) continue;
      if (got <= 0) {
        eof = true;
        break;
      }
      buffer.append(chunk, static_cast<std::size_t>(got));
      // every complete record: kind, 8-byte length, body
      while (buffer.size() >= 9) {
        std::uint64_t n = 0;
        std::memcpy(&n, buffer.data() + 1, sizeof n);
        if (buffer.size() < 9 + n) break;
        const char kind = buffer[0];
        const std::string body = buffer.substr(9, static_cast<std::size_t>(n));
        buffer.erase(0, 9 + static_cast<std::size_t>(n));
        if (kind == 'R') {
          last = unpack(body);
          have = true;
          task.set(last.K + 1);
        } else {
          error = body;
          error_kind = kind;
        }
      }
    }
  } catch (...) {
    finish(true);
    throw;
  }
  const int status = finish(out_of_time);
  if (error_kind == 'I') throw InputError(error);
  if (error_kind != 0) throw std::runtime_error(error);
  if (!out_of_time && !(WIFEXITED(status) && WEXITSTATUS(status) == 0))
    throw std::runtime_error("the formula process ended without its result (" +
                             (WIFSIGNALED(status) ? "signal " + std::to_string(WTERMSIG(status))
                                                  : "exit status " + std::to_string(WEXITSTATUS(status))) +
                             ")");
  ModifiedFormulas out = have ? last : ModifiedFormulas{};
  if (!have) {
    out.K = -1;
    out.stopped = true;
  }
  out.K_asked = K;
  out.stopped = out.stopped || out.K < K;
  out.budget = budget_seconds;
  out.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return out;
}

}  // namespace geomint::modified
