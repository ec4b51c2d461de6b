#include "geomint/output_run.hpp"

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <dirent.h>
#include <fcntl.h>
#include <mutex>
#include <pthread.h>
#include <stdexcept>
#include <sys/file.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include "created_folders.hpp"
#include "geomint/error.hpp"
#include "geomint/record.hpp"
#include "geomint/sweep.hpp"

namespace geomint {

namespace {

namespace fs = std::filesystem;

constexpr char lock_name[] = ".geomint-lock";
constexpr char staging_prefix[] = ".geomint-run-";
constexpr char journal_name[] = ".journal";
constexpr char rollback_name[] = ".journal-rollback";
constexpr char journal_part[] = ".journal-part";
constexpr char journal_header[] = "geomint commit journal 1\n";
constexpr char backup_prefix[] = ".old-";

// ---- What the interrupt handler reads: plain values written before g_state says they are valid. ----
enum : int { no_run = 0, staging_run = 1, committed_run = 2 };
volatile std::sig_atomic_t g_state = no_run;
volatile std::sig_atomic_t g_holding = 0;  // lock taken, healing, commit or discard under way
volatile std::sig_atomic_t g_pending = 0;  // an interrupt that arrived (on another thread) meanwhile
volatile std::sig_atomic_t g_handling = 0;  // the handler is running (one line, even for two signals at once)
volatile std::sig_atomic_t g_outcome = -1;  // the exit status of a run that has ended and reported (-1: running)
int g_target_fd = -1, g_stage_fd = -1;
volatile std::sig_atomic_t g_locked = 0;  // g_target_fd/.geomint-lock is ours
char g_stage_name[64];
constexpr int max_helpers = 64;
volatile pid_t g_helpers[max_helpers];
volatile pid_t g_helper_group = 0;  // a process group of helpers (OutputRun::set_helper_group)
sigset_t g_interrupts;  // the signals handle_interrupts() took over
// The folders this run created for its --out (created_folders.hpp), for the handler: the absolute target path and
// the length of its outermost created prefix. g_created_len is 0 while there are none (or the path is too long to
// keep here; then only the ordinary exit paths remove them).
char g_created_path[4096];
volatile std::sig_atomic_t g_created_len = 0;
volatile std::sig_atomic_t g_created_outer = 0;

// Removes the flat folder `dir_fd` (named `name` in `parent_fd`) with system calls only (openat, getdents64,
// unlinkat): callable from the signal handler. A thread may still add files meanwhile: a few attempts.
void remove_flat_dir(int parent_fd, const char* name, int dir_fd) {
  for (int attempt = 0; attempt < 4; ++attempt) {
    const int fd = ::openat(dir_fd, ".", O_RDONLY | O_DIRECTORY | O_CLOEXEC);  // an offset of its own
    if (fd < 0) return;
    alignas(8) char buf[4096];
    for (;;) {
      const long n = ::syscall(SYS_getdents64, fd, buf, sizeof buf);
      if (n <= 0) break;
      for (long off = 0; off < n;) {
        // struct linux_dirent64 { u64 d_ino; s64 d_off; unsigned short d_reclen; unsigned char d_type; char d_name[]; }
        unsigned short reclen;
        std::memcpy(&reclen, buf + off + 16, sizeof reclen);
        const char* entry = buf + off + 19;
        if (!(entry[0] == '.' && (entry[1] == 0 || (entry[1] == '.' && entry[2] == 0)))) ::unlinkat(dir_fd, entry, 0);
        off += reclen;
      }
    }
    ::close(fd);
    if (::unlinkat(parent_fd, name, AT_REMOVEDIR) == 0 || errno == ENOENT) return;
  }
}

const char* signal_name(int sig) {
  switch (sig) {
    case SIGHUP: return "SIGHUP";
    case SIGINT: return "SIGINT";
    case SIGQUIT: return "SIGQUIT";
    case SIGTERM: return "SIGTERM";
    case SIGUSR1: return "SIGUSR1";
    case SIGUSR2: return "SIGUSR2";
    case SIGALRM: return "SIGALRM";
    case SIGVTALRM: return "SIGVTALRM";
    case SIGPROF: return "SIGPROF";
    case SIGXCPU: return "SIGXCPU";
    case SIGXFSZ: return "SIGXFSZ";
    case SIGIO: return "SIGIO";
    case SIGPWR: return "SIGPWR";
    case SIGSTKFLT: return "SIGSTKFLT";
    case SIGPIPE: return "SIGPIPE";
    case SIGABRT: return "SIGABRT";
    case SIGSEGV: return "SIGSEGV";
    case SIGBUS: return "SIGBUS";
    case SIGSYS: return "SIGSYS";
    case SIGTRAP: return "SIGTRAP";
    default: return "a real-time signal";
  }
}

extern "C" void geomint_on_interrupt(int sig) {
  if (g_outcome >= 0) ::_exit(g_outcome);
  if (g_holding) {  // the lock, healing, commit or discard finishes first; the interrupt is acted on after it
    g_pending = sig;
    return;
  }
  if (__atomic_exchange_n(&g_handling, 1, __ATOMIC_SEQ_CST)) {  // another thread is already handling one
    for (;;) ::pause();
  }
  if (const pid_t group = g_helper_group; group > 0) ::kill(-group, SIGKILL);
  for (int i = 0; i < max_helpers; ++i) {
    const pid_t helper = g_helpers[i];
    if (helper > 0) {
      ::kill(helper, SIGKILL);
      ::waitpid(helper, nullptr, 0);
    }
  }
  const int state = g_state;
  if (state == staging_run) remove_flat_dir(g_target_fd, g_stage_name, g_stage_fd);
  if (g_locked) ::unlinkat(g_target_fd, lock_name, 0);
  if (state != committed_run) {  // folders made for this run, now empty: innermost first, rmdir(2) only
    const std::size_t outer = static_cast<std::size_t>(g_created_outer);
    for (std::size_t len = static_cast<std::size_t>(g_created_len); len >= outer && len > 0;) {
      g_created_path[len] = 0;
      if (::rmdir(g_created_path) != 0 || len == outer) break;
      while (len > 0 && g_created_path[len - 1] != '/') --len;  // the parent: cut the last name and its '/'
      if (len > 0) --len;
    }
  }
  // One line with write(2) only: "<program>: interrupted by signal N (SIGxxx); <what became of the outputs>".
  char line[320];
  std::size_t n = 0;
  auto put = [&](const char* t) {
    while (*t && n + 1 < sizeof line) line[n++] = *t++;
  };
  put(program_invocation_short_name);
  put(": interrupted by signal ");
  char num[4] = {static_cast<char>('0' + sig / 10 % 10), static_cast<char>('0' + sig % 10), 0, 0};
  put(sig >= 10 ? num : num + 1);
  put(" (");
  put(signal_name(sig));
  put(state == staging_run     ? "); the previous outputs are unchanged\n"
      : state == committed_run ? "); its new outputs were already in place\n"
                               : "); nothing was written\n");
  [[maybe_unused]] const ssize_t w = ::write(2, line, n);
  ::_exit(128 + sig);
}

// The signals of a fault (SIGABRT, SIGSEGV, ...) are interrupts only when another process sent them (kill,
// sigqueue: si_code SI_USER, SI_QUEUE; systemd's watchdog sends SIGABRT): then the run is cut short like any
// other. A real fault (the kernel's si_code, or abort() and raise() from within, SI_TKILL) keeps its default
// action, a core dump where they are enabled: the handler steps aside and the signal is delivered again.
extern "C" void geomint_on_fault(int sig, siginfo_t* info, void*) {
  if (info && (info->si_code == SI_USER || info->si_code == SI_QUEUE)) {
    geomint_on_interrupt(sig);
    return;
  }
  struct sigaction dfl {};
  dfl.sa_handler = SIG_DFL;
  ::sigaction(sig, &dfl, nullptr);
  // a fault the kernel raised recurs when the faulting instruction runs again; one raised from within, by
  // abort() or raise(), is raised again here (delivered when the handler returns)
  if (!info || info->si_code <= 0) ::raise(sig);
}

// Interrupts held on this thread, and deferred on the others, for its lifetime: what must not be cut short.
class InterruptsHeld {
 public:
  InterruptsHeld() {
    pthread_sigmask(SIG_BLOCK, &g_interrupts, &old_);
    outer_ = g_holding;
    g_holding = 1;
  }
  ~InterruptsHeld() {
    if (outer_) return;
    g_holding = 0;
    pthread_sigmask(SIG_SETMASK, &old_, nullptr);  // one blocked meanwhile is delivered here
    if (g_pending) geomint_on_interrupt(g_pending);
  }
  InterruptsHeld(const InterruptsHeld&) = delete;
  InterruptsHeld& operator=(const InterruptsHeld&) = delete;

 private:
  sigset_t old_;
  int outer_ = 0;
};

OutputRun* g_run = nullptr;

// An exit without commit (exit(), return from main with a nonzero status) removes the staging folder.
void discard_at_exit() {
  if (OutputRun* r = OutputRun::current()) r->discard();
}

std::string errno_text(int e) { return std::strerror(e); }

bool exists_at(int dir_fd, const std::string& name) {
  struct stat st;
  return ::fstatat(dir_fd, name.c_str(), &st, AT_SYMLINK_NOFOLLOW) == 0;
}

// ---- The lock ----

std::string read_small(int fd) {
  char buf[512];
  const ssize_t n = ::pread(fd, buf, sizeof buf - 1, 0);
  std::string s(buf, n > 0 ? static_cast<std::size_t>(n) : 0);
  for (char& c : s)
    if (c == '\n' || c == '\r' || c == 0) c = ' ';
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

int take_lock(int target_fd, const fs::path& target) {
  for (int attempt = 0; attempt < 100; ++attempt) {
    const int fd = ::openat(target_fd, lock_name, O_RDWR | O_CREAT | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (fd < 0) throw InputError("cannot lock output folder '" + target.string() + "': " + errno_text(errno));
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      const int e = errno;
      const std::string holder = read_small(fd);
      ::close(fd);
      if (e == EWOULDBLOCK)
        throw InputError("output folder '" + target.string() + "' is in use by another run (" +
                         (holder.empty() ? std::string("starting") : holder) +
                         "): wait for it to end or choose another --out");
      throw InputError("cannot lock output folder '" + target.string() + "': " + errno_text(e));
    }
    struct stat mine, now;
    if (::fstat(fd, &mine) == 0 && ::fstatat(target_fd, lock_name, &now, AT_SYMLINK_NOFOLLOW) == 0 &&
        mine.st_dev == now.st_dev && mine.st_ino == now.st_ino) {
      char host[256] = "";
      ::gethostname(host, sizeof host - 1);
      const std::string who = "process " + std::to_string(::getpid()) + " on " + host + "\n";
      if (::ftruncate(fd, 0) == 0) {
        [[maybe_unused]] const ssize_t w = ::pwrite(fd, who.data(), who.size(), 0);
      }
      return fd;
    }
    ::close(fd);  // the run that held it removed it as it ended: lock the folder's new file
  }
  throw InputError("cannot lock output folder '" + target.string() + "': its lock file keeps changing");
}

// ---- The journal ----

struct Move {
  bool had_old;
  std::string name;
};

bool valid_name(const std::string& n) {
  return !n.empty() && n[0] != '.' && n.find('/') == std::string::npos && n.size() < 256;
}

std::string journal_text(const std::vector<Move>& moves) {
  std::string j = journal_header;
  for (const auto& m : moves) {
    j += m.had_old ? '1' : '0';
    j += m.name;
    j += '\0';
  }
  return j;
}

enum class Journal { absent, read, damaged };

Journal read_journal(int stage_fd, const char* name, std::vector<Move>& moves) {
  const int fd = ::openat(stage_fd, name, O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) return errno == ENOENT ? Journal::absent : Journal::damaged;
  std::string text;
  char buf[4096];
  for (;;) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    text.append(buf, static_cast<std::size_t>(n));
  }
  ::close(fd);
  const std::string head = journal_header;
  if (text.compare(0, head.size(), head) != 0) return Journal::damaged;
  moves.clear();
  for (std::size_t p = head.size(); p < text.size();) {
    const std::size_t end = text.find('\0', p);
    if (end == std::string::npos || (text[p] != '0' && text[p] != '1')) return Journal::damaged;
    Move m{text[p] == '1', text.substr(p + 1, end - p - 1)};
    if (!valid_name(m.name)) return Journal::damaged;
    moves.push_back(std::move(m));
    p = end + 1;
  }
  return Journal::read;
}

// Writes the journal aside and renames it into place: it is complete or absent.
bool write_journal(int stage_fd, const std::vector<Move>& moves, std::string& failure) {
  const std::string j = journal_text(moves);
  const int fd = ::openat(stage_fd, journal_part, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
  bool ok = fd >= 0;
  for (std::size_t done = 0; ok && done < j.size();) {
    const ssize_t n = ::write(fd, j.data() + done, j.size() - done);
    if (n < 0 && errno == EINTR) continue;
    ok = n > 0;
    if (ok) done += static_cast<std::size_t>(n);
  }
  const int e = errno;
  if (fd >= 0 && ::close(fd) != 0) ok = false;
  if (ok && ::renameat(stage_fd, journal_part, stage_fd, journal_name) == 0) return true;
  failure = "cannot write the commit journal: " + errno_text(ok ? errno : e);
  return false;
}

// Moves every file still in the staging folder into the target, in the journal's order. "" or what failed.
std::string roll_forward(int stage_fd, int target_fd, const std::vector<Move>& moves, const fs::path& target,
                         std::size_t* moved = nullptr) {
  for (const auto& m : moves) {
    if (!exists_at(stage_fd, m.name)) continue;  // moved before the interruption
    if (::renameat(stage_fd, m.name.c_str(), target_fd, m.name.c_str()) != 0)
      return "cannot move '" + m.name + "' into '" + target.string() + "': " + errno_text(errno);
    if (moved) ++*moved;
  }
  return "";
}

// Puts the old files back: a moved file that replaced one returns to the backup, one that replaced nothing goes.
// "" or what failed (then the staging folder must stay: it holds the old files).
std::string roll_back(int stage_fd, int target_fd, const std::vector<Move>& moves, const fs::path& target) {
  for (const auto& m : moves) {
    if (exists_at(stage_fd, m.name)) continue;  // never moved: the target still holds the old one
    if (m.had_old) {
      const std::string backup = backup_prefix + m.name;
      if (exists_at(stage_fd, backup) && ::renameat(stage_fd, backup.c_str(), target_fd, m.name.c_str()) != 0)
        return "cannot put back '" + m.name + "' in '" + target.string() + "': " + errno_text(errno);
    } else if (::unlinkat(target_fd, m.name.c_str(), 0) != 0 && errno != ENOENT) {
      return "cannot remove the new '" + m.name + "' from '" + target.string() + "': " + errno_text(errno);
    }
  }
  return "";
}

void mark_rollback(int stage_fd) { ::renameat(stage_fd, journal_name, stage_fd, rollback_name); }

// ---- Healing ----

std::string plural(std::size_t n, const std::string& one, const std::string& many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

// Finishes or rolls back the commits of runs that are gone and removes their staging folders (the caller holds
// the lock). Returns the line that says so ("" when there was nothing to heal).
std::string heal(int target_fd, const fs::path& target) {
  std::vector<std::string> stale;
  {
    const int fd = ::openat(target_fd, ".", O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    DIR* d = fd >= 0 ? ::fdopendir(fd) : nullptr;
    if (!d) {
      if (fd >= 0) ::close(fd);
      throw InputError("cannot read output folder '" + target.string() + "': " + errno_text(errno));
    }
    while (const dirent* e = ::readdir(d)) {
      const std::string n = e->d_name;
      struct stat st;
      if (n.rfind(staging_prefix, 0) == 0 && ::fstatat(target_fd, n.c_str(), &st, AT_SYMLINK_NOFOLLOW) == 0 &&
          S_ISDIR(st.st_mode))
        stale.push_back(n);
    }
    ::closedir(d);
  }
  std::size_t finished = 0, left = 0, total = 0, rolled = 0, removed = 0;
  std::string why_rolled;
  for (const auto& name : stale) {
    const fs::path where = target / name;
    const int sfd = ::openat(target_fd, name.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    if (sfd < 0) throw InputError("cannot open '" + where.string() + "' left by an earlier run: " + errno_text(errno));
    std::vector<Move> moves;
    std::string failure;
    Journal back = read_journal(sfd, rollback_name, moves), forward = Journal::absent;
    if (back == Journal::absent) forward = read_journal(sfd, journal_name, moves);
    if (back == Journal::damaged || forward == Journal::damaged) {
      ::close(sfd);
      throw InputError("'" + where.string() + "', left by an earlier run, holds a commit journal that cannot be read: "
                       "look at it and remove it, then run again");
    }
    if (forward == Journal::read) {
      failure = roll_forward(sfd, target_fd, moves, target, &left);
      if (failure.empty()) {
        ++finished;
        total += moves.size();
      } else {
        mark_rollback(sfd);
        back = Journal::read;
        why_rolled = failure;
      }
    }
    if (back == Journal::read) {
      const std::string undo = roll_back(sfd, target_fd, moves, target);
      if (!undo.empty()) {
        ::close(sfd);
        throw InputError("cannot roll back the interrupted commit kept in '" + where.string() + "': " + undo +
                         " (the previous files are still there)");
      }
      ++rolled;
    }
    if (forward != Journal::read && back != Journal::read) ++removed;
    remove_flat_dir(target_fd, name.c_str(), sfd);
    ::close(sfd);
    std::error_code ec;
    if (fs::exists(fs::symlink_status(where, ec))) fs::remove_all(where, ec);  // not flat after all
  }
  std::string note;
  auto part = [&](const std::string& s) { note += (note.empty() ? "" : "; ") + s; };
  if (finished)
    part("finished the commit of a run killed while committing (" + std::to_string(left) + " of " +
         plural(total, "file", "files") + " were still to move)");
  if (rolled)
    part("rolled back the interrupted commit of a run that was killed (" +
         (why_rolled.empty() ? std::string("it had begun to undo it") : "it could not be finished: " + why_rolled) +
         "); its previous outputs are back");
  if (removed)
    part("removed " + (removed == 1 ? std::string("the staging folder of a run that") : plural(removed, "", "staging folders of runs that")) +
         " ended without committing (the outputs it replaced nothing of)");
  return note.empty() ? note : "output folder '" + target.string() + "': " + note;
}

// A staging folder of a fresh random name, mode 0700, made relative to the target's descriptor.
std::string make_staging(int target_fd, const fs::path& target) {
  static const char alphabet[] = "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789";
  for (int attempt = 0; attempt < 100; ++attempt) {
    unsigned char r[6];
    if (::getrandom(r, sizeof r, 0) != static_cast<ssize_t>(sizeof r))
      for (unsigned char& c : r) c = static_cast<unsigned char>(std::rand());
    std::string name = staging_prefix;
    for (unsigned char c : r) name += alphabet[c % (sizeof alphabet - 1)];
    if (::mkdirat(target_fd, name.c_str(), 0700) == 0) return name;
    if (errno != EEXIST)
      throw InputError("output folder '" + target.string() + "' is not writable: " + errno_text(errno));
  }
  throw InputError("cannot create a staging folder in '" + target.string() + "'");
}

}  // namespace

void handle_interrupts() {
  static std::once_flag once;
  std::call_once(once, [] {
    // SIGPIPE too: a standard output closed by its reader ends the run like any interrupt, cleaned up (gnuplot is
    // written with MSG_NOSIGNAL, figure.cpp, so only our own output raises it)
    std::vector<int> sigs{SIGHUP,    SIGINT,  SIGQUIT, SIGTERM, SIGUSR1, SIGUSR2,  SIGALRM,  SIGVTALRM,
                          SIGPROF,   SIGXCPU, SIGXFSZ, SIGIO,   SIGPWR,  SIGSTKFLT, SIGPIPE};
    const std::vector<int> faults{SIGABRT, SIGSEGV, SIGBUS, SIGSYS, SIGTRAP};
    for (int r = SIGRTMIN; r <= SIGRTMAX; ++r) sigs.push_back(r);
    sigemptyset(&g_interrupts);
    std::vector<int> taken, taken_faults;
    // Only a signal at its default (termination) is taken over: one ignored by whoever started us (nohup, a
    // background job) stays ignored, and one a library handles (a profiler's SIGPROF, a sanitizer's SIGSEGV)
    // stays its own.
    auto at_default = [](int s) {
      struct sigaction old {};
      return ::sigaction(s, nullptr, &old) == 0 && !(old.sa_flags & SA_SIGINFO) && old.sa_handler == SIG_DFL;
    };
    for (int s : sigs)
      if (at_default(s)) {
        taken.push_back(s);
        sigaddset(&g_interrupts, s);
      }
    // A fault blocked while the lock or a commit is held is deferred like an interrupt when sent; one the
    // kernel raises meanwhile takes its default action at once (a blocked synchronous fault is not deferred).
    for (int s : faults)
      if (at_default(s)) {
        taken_faults.push_back(s);
        sigaddset(&g_interrupts, s);
      }
    struct sigaction sa {};
    sa.sa_handler = geomint_on_interrupt;
    sa.sa_mask = g_interrupts;  // one interrupt at a time on a thread
    sa.sa_flags = 0;
    for (int s : taken) ::sigaction(s, &sa, nullptr);
    struct sigaction fa {};
    fa.sa_sigaction = geomint_on_fault;
    fa.sa_mask = g_interrupts;
    fa.sa_flags = SA_SIGINFO;
    for (int s : taken_faults) ::sigaction(s, &fa, nullptr);
  });
}

void interrupts_after_outcome(int status, const std::function<void()>& report) {
  InterruptsHeld held;
  if (report) report();
  g_outcome = status < 0 ? 1 : status & 0xff;
}

void require_output_rank(const fs::path& what) {
  if (Sweep::launcher_rank() != 0)
    throw std::logic_error("MPI rank " + std::to_string(Sweep::launcher_rank()) + " tried to write '" + what.string() +
                           "': only rank 0 writes outputs");
}

OutputRun* OutputRun::current() { return g_run; }

OutputRun& OutputRun::start(const fs::path& target) {
  require_output_rank(target);
  if (g_run) {
    std::error_code ec;
    if (fs::equivalent(g_run->target_, target, ec)) return *g_run;
    g_run->discard();
  }
  handle_interrupts();
  static OutputRun run;  // constructed before the exit hook is registered, so it outlives the hook
  static bool registered = false;
  if (!registered) {
    registered = true;
    std::atexit(discard_at_exit);
  }
  InterruptsHeld held;  // an interrupt waits until the run is set up (then removes it) or refused
  const int tfd = ::open(target.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (tfd < 0) throw InputError("cannot open output folder '" + target.string() + "': " + errno_text(errno));
  int lock = -1;
  std::string note, name;
  try {
    lock = take_lock(tfd, target);
    note = heal(tfd, target);
    name = make_staging(tfd, target);
  } catch (...) {
    if (lock >= 0) {
      ::unlinkat(tfd, lock_name, 0);
      ::close(lock);
    }
    ::close(tfd);
    throw;
  }
  const int sfd = ::openat(tfd, name.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  if (sfd < 0 || name.size() >= sizeof g_stage_name) {
    const int e = errno;
    ::unlinkat(tfd, name.c_str(), AT_REMOVEDIR);
    ::unlinkat(tfd, lock_name, 0);
    ::close(lock);
    ::close(tfd);
    throw InputError("cannot open the staging folder in '" + target.string() + "': " + errno_text(e));
  }
  run = OutputRun();
  run.target_ = target;
  run.staging_name_ = name;
  run.staging_ = target / name;
  run.target_fd_ = tfd;
  run.stage_fd_ = sfd;
  run.lock_fd_ = lock;
  g_target_fd = tfd;
  g_stage_fd = sfd;
  std::memcpy(g_stage_name, name.c_str(), name.size() + 1);
  g_locked = 1;
  g_state = staging_run;
  g_run = &run;
  if (!note.empty()) print_line(program_name() + ": " + one_line(note));
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

int OutputRun::create_part(const fs::path& final_path, std::string& part) {
  static std::atomic<unsigned long> parts{0};
  part = ".part-" + std::to_string(parts++) + "-" + final_path.filename().string();
  const int fd = ::openat(stage_fd_, part.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
  if (fd < 0) throw std::runtime_error("cannot write '" + final_path.string() + "': " + errno_text(errno));
  return fd;
}

void OutputRun::place(const std::string& part, const fs::path& final_path) {
  static std::mutex m;  // figures are drawn (and placed) from several threads at once
  std::lock_guard<std::mutex> lock(m);
  const std::string name = final_path.filename().string();
  if (!valid_name(name)) throw std::logic_error("output file name '" + name + "' cannot be staged");
  if (::renameat(stage_fd_, part.c_str(), stage_fd_, name.c_str()) != 0)
    throw std::runtime_error("cannot write '" + final_path.string() + "': " + errno_text(errno));
  for (const auto& n : names_)
    if (n == name) return;
  names_.push_back(name);
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

void OutputRun::set_helper_group(long pgid) { g_helper_group = static_cast<pid_t>(pgid); }

void OutputRun::end() {
  g_locked = 0;
  ::unlinkat(target_fd_, lock_name, 0);  // removed before it is released: see take_lock
  ::close(lock_fd_);
  ::close(stage_fd_);
  ::close(target_fd_);
  lock_fd_ = stage_fd_ = target_fd_ = -1;
  g_run = nullptr;
}

void OutputRun::discard() {
  if (g_run != this) return;
  InterruptsHeld held;
  g_state = no_run;
  remove_flat_dir(target_fd_, staging_name_.c_str(), stage_fd_);
  std::error_code ec;
  if (fs::exists(fs::symlink_status(staging_, ec))) fs::remove_all(staging_, ec);
  end();
  detail::remove_created_folders();
}

void OutputRun::commit() {
  if (g_run != this) return;
  InterruptsHeld held;
  // 1. Each old file kept as a hard link in the staging folder: what a rollback puts back.
  std::vector<Move> moves;
  std::string failure;
  for (const auto& n : names_) {
    const std::string backup = backup_prefix + n;
    if (::linkat(target_fd_, n.c_str(), stage_fd_, backup.c_str(), 0) == 0)
      moves.push_back({true, n});
    else if (errno == ENOENT)
      moves.push_back({false, n});
    else {
      failure = "cannot keep '" + (target_ / n).string() + "' for the commit: " + errno_text(errno);
      break;
    }
  }
  // 2. The journal: from here a killed run is finished by the next one.
  if (failure.empty() && write_journal(stage_fd_, moves, failure)) {
    // 3. The moves.
    failure = roll_forward(stage_fd_, target_fd_, moves, target_);
    if (!failure.empty()) {
      mark_rollback(stage_fd_);
      const std::string undo = roll_back(stage_fd_, target_fd_, moves, target_);
      if (!undo.empty()) {  // the old files are still in the staging folder: keep it, the next run rolls back
        g_state = no_run;
        end();
        detail::keep_created_folders();
        throw std::runtime_error(failure + "; " + undo + " (the next run into this folder puts the previous outputs back)");
      }
    }
  }
  if (failure.empty()) {
    g_state = committed_run;
    remove_flat_dir(target_fd_, staging_name_.c_str(), stage_fd_);
    end();
    detail::keep_created_folders();
    return;
  }
  discard();
  throw std::runtime_error(failure + " (the previous outputs are unchanged)");
}

namespace detail {

namespace {
std::filesystem::path g_created_target, g_created_outermost;
}  // namespace

std::filesystem::path first_missing_folder(const std::filesystem::path& target) {
  std::filesystem::path outermost;
  std::error_code ec;
  for (std::filesystem::path p = target; !p.empty() && !std::filesystem::exists(std::filesystem::symlink_status(p, ec));
       p = p.parent_path()) {
    outermost = p;
    if (p == p.parent_path()) break;
  }
  return outermost;
}

void note_created_folders(const std::filesystem::path& target, const std::filesystem::path& outermost) {
  g_created_target = target;
  g_created_outermost = outermost;
  g_created_len = 0;
  if (outermost.empty()) return;
  // the same as absolute paths without a trailing '/', for the interrupt handler
  std::error_code ec;
  auto plain = [&](const std::filesystem::path& p) {
    std::string t = std::filesystem::absolute(p, ec).lexically_normal().string();
    while (t.size() > 1 && t.back() == '/') t.pop_back();
    return t;
  };
  const std::string t = plain(target), o = plain(outermost);
  if (ec || t.size() >= sizeof g_created_path || o.empty() || t.compare(0, o.size(), o) != 0 ||
      (t.size() > o.size() && t[o.size()] != '/'))
    return;
  std::memcpy(g_created_path, t.data(), t.size());
  g_created_path[t.size()] = 0;
  g_created_outer = static_cast<std::sig_atomic_t>(o.size());
  g_created_len = static_cast<std::sig_atomic_t>(t.size());
}

void remove_created_folders() {
  if (!g_created_outermost.empty())
    for (std::filesystem::path p = g_created_target; !p.empty(); p = p.parent_path()) {
      if (::rmdir(p.c_str()) != 0) break;  // not empty (or not ours to remove): it and its parents stay
      if (p == g_created_outermost || p == p.parent_path()) break;
    }
  keep_created_folders();
}

void keep_created_folders() {
  g_created_len = 0;
  g_created_target.clear();
  g_created_outermost.clear();
}

}  // namespace detail

}  // namespace geomint
