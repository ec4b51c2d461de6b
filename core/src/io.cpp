#include "geomint/io.hpp"

#include <cerrno>
#include <climits>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <mutex>
#include <pthread.h>
#include <stdexcept>
#include <sys/syscall.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <system_error>
#include <unistd.h>

#include "geomint/error.hpp"
#include "geomint/sweep.hpp"

namespace geomint {

std::string format_number(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[40];
  // 15 significant digits: the same bits give the same text, and the files stay readable.
  std::snprintf(buf, sizeof buf, "%.15g", v);
  return buf;
}

std::string format_list(const std::vector<double>& v) {
  std::string s;
  for (double x : v) s += (s.empty() ? "" : ",") + format_number(x);
  return s;
}

namespace {

namespace fs = std::filesystem;

// State the signal handler reads: plain bytes and flags only (async-signal-safe).
char g_staging[PATH_MAX];                 // the staging folder of the active run ("" when none)
volatile std::sig_atomic_t g_active = 0;  // a run is active
volatile std::sig_atomic_t g_committing = 0;
volatile std::sig_atomic_t g_pending = 0;  // a signal that arrived (on another thread) while committing
// gnuplots writing into the staging folder (figures may be drawn from several threads at once)
constexpr int max_helpers = 64;
volatile pid_t g_helpers[max_helpers];

// Removes a flat folder with system calls only (getdents64, unlinkat, rmdir): callable from a signal handler.
void remove_flat_dir_signal_safe(const char* dir) {
  for (int attempt = 0; attempt < 4; ++attempt) {
    const int fd = ::open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0) return;
    alignas(8) char buf[4096];
    for (;;) {
      const long n = ::syscall(SYS_getdents64, fd, buf, sizeof buf);
      if (n <= 0) break;
      for (long off = 0; off < n;) {
        // struct linux_dirent64 { u64 d_ino; s64 d_off; unsigned short d_reclen; unsigned char d_type; char d_name[]; }
        unsigned short reclen;
        std::memcpy(&reclen, buf + off + 16, sizeof reclen);
        const char* name = buf + off + 19;
        if (!(name[0] == '.' && (name[1] == 0 || (name[1] == '.' && name[2] == 0)))) ::unlinkat(fd, name, 0);
        off += reclen;
      }
    }
    ::close(fd);
    if (::rmdir(dir) == 0 || errno == ENOENT) return;
  }
}

extern "C" void geomint_on_signal(int sig) {
  if (g_committing) {  // the commit loop finishes first; the signal is acted on after it
    g_pending = sig;
    return;
  }
  for (int i = 0; i < max_helpers; ++i) {
    const pid_t helper = g_helpers[i];
    if (helper > 0) {
      ::kill(helper, SIGKILL);
      ::waitpid(helper, nullptr, 0);
    }
  }
  if (g_active) remove_flat_dir_signal_safe(g_staging);
  // One line with write(2) only: "<program>: interrupted by signal N; the previous outputs are unchanged".
  char line[256];
  std::size_t n = 0;
  auto put = [&](const char* t) {
    while (*t && n + 1 < sizeof line) line[n++] = *t++;
  };
  put(program_invocation_short_name);
  put(": interrupted by signal ");
  char num[4] = {static_cast<char>('0' + sig / 10 % 10), static_cast<char>('0' + sig % 10), 0, 0};
  put(sig >= 10 ? num : num + 1);
  put("; the previous outputs are unchanged\n");
  [[maybe_unused]] const ssize_t w = ::write(2, line, n);
  ::_exit(128 + sig);
}

void install_handlers() {
  static bool installed = false;
  if (installed) return;
  installed = true;
  struct sigaction sa {};
  sa.sa_handler = geomint_on_signal;
  sigemptyset(&sa.sa_mask);
  sigaddset(&sa.sa_mask, SIGINT);
  sigaddset(&sa.sa_mask, SIGTERM);
  sa.sa_flags = 0;
  ::sigaction(SIGINT, &sa, nullptr);
  ::sigaction(SIGTERM, &sa, nullptr);
}

// An exit without commit (exit(), return from main with a nonzero status) removes the staging folder.
void discard_at_exit() {
  if (OutputRun* r = OutputRun::current()) r->discard();
}

OutputRun* g_run = nullptr;

// Blocks SIGINT/SIGTERM on this thread, and defers them on the others, for its lifetime.
class SignalsHeld {
 public:
  SignalsHeld() {
    sigset_t s;
    sigemptyset(&s);
    sigaddset(&s, SIGINT);
    sigaddset(&s, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &s, &old_);
    g_committing = 1;
  }
  ~SignalsHeld() {
    g_committing = 0;
    pthread_sigmask(SIG_SETMASK, &old_, nullptr);  // a signal blocked meanwhile is delivered here
    if (g_pending) geomint_on_signal(g_pending);
  }
  SignalsHeld(const SignalsHeld&) = delete;
  SignalsHeld& operator=(const SignalsHeld&) = delete;

 private:
  sigset_t old_;
};

}  // namespace

OutputRun* OutputRun::current() { return g_run; }

OutputRun& OutputRun::start(const fs::path& target) {
  if (g_run) {
    std::error_code ec;
    if (fs::equivalent(g_run->target_, target, ec)) return *g_run;
    g_run->discard();
  }
  install_handlers();
  static OutputRun run;  // constructed before the exit hook is registered, so it outlives the hook
  static bool registered = false;
  if (!registered) {
    registered = true;
    std::atexit(discard_at_exit);
  }
  std::string tmpl = (target / ".geomint-run-XXXXXX").string();
  require(tmpl.size() < sizeof g_staging, "output folder path is too long: '" + target.string() + "'");
  if (::mkdtemp(tmpl.data()) == nullptr)
    throw InputError("output folder '" + target.string() + "' is not writable: " + std::strerror(errno));
  run = OutputRun();
  run.target_ = target;
  run.staging_ = tmpl;
  std::memcpy(g_staging, tmpl.c_str(), tmpl.size() + 1);
  g_active = 1;
  g_run = &run;
  return run;
}

bool OutputRun::owns(const fs::path& final_path) const {
  std::error_code ec;
  const fs::path parent = final_path.parent_path().empty() ? fs::path(".") : final_path.parent_path();
  return final_path.has_filename() && fs::equivalent(parent, target_, ec);
}

fs::path OutputRun::staged(const fs::path& final_path) const {
  return owns(final_path) ? staging_ / final_path.filename() : final_path;
}

void OutputRun::add(const fs::path& final_path) {
  static std::mutex m;  // figures are drawn (and added) from several threads at once
  std::lock_guard<std::mutex> lock(m);
  const std::string name = final_path.filename().string();
  for (const auto& n : names_)
    if (n == name) return;
  names_.push_back(name);
  // Fault injection for the probe (tests/probe.test.cpp): stop once the first output is staged, so a test can
  // interrupt the run at a known point (new tables staged, figures not drawn, nothing committed).
  static const bool stop = std::getenv("GEOMINT_FAULT_STOP_AFTER_FIRST_OUTPUT") != nullptr;
  if (stop && names_.size() == 1) ::raise(SIGSTOP);
}

void OutputRun::set_helper(long pid) {
  // pid > 0: a helper started; pid < 0: helper -pid ended.
  static std::mutex m;
  std::lock_guard<std::mutex> lock(m);
  const pid_t find = pid > 0 ? 0 : static_cast<pid_t>(-pid), put = pid > 0 ? static_cast<pid_t>(pid) : 0;
  for (int i = 0; i < max_helpers; ++i)
    if (g_helpers[i] == find) {
      g_helpers[i] = put;
      return;
    }
}

void OutputRun::discard() {
  if (g_run != this) return;
  g_active = 0;
  std::error_code ec;
  fs::remove_all(staging_, ec);
  g_staging[0] = 0;
  g_run = nullptr;
}

void OutputRun::commit() {
  if (g_run != this) return;
  SignalsHeld held;
  // Each old file is kept as a hard link in the staging folder until every new file is in place, so a rename
  // that fails midway puts the old ones back: the target ends all new or all old.
  std::vector<std::string> backed_up, placed;
  std::string failure;
  for (const auto& n : names_) {
    const fs::path old = target_ / n, keep = staging_ / (".old-" + n);
    if (::link(old.c_str(), keep.c_str()) == 0)
      backed_up.push_back(n);
    else if (errno != ENOENT) {
      failure = "cannot keep '" + old.string() + "' for the commit: " + std::strerror(errno);
      break;
    }
  }
  if (failure.empty())
    for (const auto& n : names_) {
      const fs::path from = staging_ / n, to = target_ / n;
      if (std::rename(from.c_str(), to.c_str()) != 0) {
        failure = "cannot move '" + from.string() + "' to '" + to.string() + "': " + std::strerror(errno);
        break;
      }
      placed.push_back(n);
    }
  if (!failure.empty())  // roll back: the old files return, new files that replaced nothing go
    for (const auto& n : placed) {
      bool had_old = false;
      for (const auto& b : backed_up) had_old = had_old || b == n;
      const fs::path to = target_ / n, keep = staging_ / (".old-" + n);
      if (had_old)
        std::rename(keep.c_str(), to.c_str());
      else
        ::unlink(to.c_str());
    }
  discard();
  if (!failure.empty()) throw std::runtime_error(failure + " (the previous outputs are unchanged)");
}

fs::path output_path_for_reading(const fs::path& final_path) {
  if (OutputRun* r = OutputRun::current()) {
    const fs::path s = r->staged(final_path);
    std::error_code ec;
    if (s != final_path && fs::exists(s, ec)) return s;
  }
  return final_path;
}

fs::path prepare_output_dir(const std::string& dir) {
  require(!dir.empty(), "output folder must not be empty");
  std::error_code ec;
  fs::create_directories(dir, ec);
  require(!ec && fs::is_directory(dir), "cannot create output folder '" + dir + "'" + (ec ? ": " + ec.message() : ""));
  if (Sweep::world().root()) {
    OutputRun::start(fs::path(dir));  // the staging folder is the write probe
    return fs::path(dir);
  }
  return fs::path(dir);  // other MPI ranks write nothing
}

AtomicFile::AtomicFile(fs::path final_path) : final_(std::move(final_path)) {
  OutputRun* run = OutputRun::current();
  staged_ = run && run->owns(final_);
  if (staged_) {
    tmp_ = run->staged(final_);
  } else {
    tmp_ = final_;
    tmp_ += ".tmp";
  }
  f_ = std::fopen(tmp_.c_str(), "we");  // close-on-exec: gnuplot does not inherit our open tables
  require(f_ != nullptr, "cannot write '" + tmp_.string() + "': " + std::strerror(errno));
}

AtomicFile::~AtomicFile() {
  if (f_) {
    std::fclose(f_);
    std::error_code ec;
    fs::remove(tmp_, ec);
  }
}

void AtomicFile::commit() {
  if (!f_) return;
  bool ok = std::fflush(f_) == 0 && !std::ferror(f_);
  const int err = ok ? 0 : errno;
  const bool closed = std::fclose(f_) == 0;
  const int close_err = errno;
  f_ = nullptr;
  std::error_code ec;
  if (!ok || !closed) {
    fs::remove(tmp_, ec);
    throw std::runtime_error("cannot write '" + final_.string() + "': " + std::strerror(!ok ? err : close_err) +
                             " (the previous file is unchanged)");
  }
  if (staged_) {
    if (OutputRun* run = OutputRun::current()) run->add(final_);
    return;
  }
  fs::rename(tmp_, final_, ec);
  if (ec) {
    std::error_code ec2;
    fs::remove(tmp_, ec2);
    throw std::runtime_error("cannot rename '" + tmp_.string() + "' to '" + final_.string() + "': " + ec.message());
  }
}

TsvWriter::TsvWriter(const fs::path& path, const std::string& program, const Params& params,
                     std::vector<std::string> columns)
    : file_(path), ncols_(columns.size()) {
  std::FILE* f = file_.handle();
  std::fprintf(f, "# program: %s\n# git: %s\n", program.c_str(), git_revision());
  for (const auto& [k, v] : params) std::fprintf(f, "# %s: %s\n", k.c_str(), v.c_str());
  write_row(columns);
}

void TsvWriter::write_row(const std::vector<std::string>& cells) {
  require(cells.size() == ncols_, "TsvWriter: row has " + std::to_string(cells.size()) + " cells, expected " +
                                      std::to_string(ncols_));
  std::FILE* f = file_.handle();
  for (size_t i = 0; i < cells.size(); ++i) {
    std::fputs(cells[i].c_str(), f);
    std::fputc(i + 1 < cells.size() ? '\t' : '\n', f);
  }
}

}  // namespace geomint
