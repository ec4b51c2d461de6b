// Fault injection for the probe (tests/programs/probe.test.cpp), kept out of every program: a shared library that the probe
// preloads (LD_PRELOAD) into a program it starts. No program contains a test hook (the probe checks that no program
// binary even names one); this library interposes the C library's rename and link calls instead and, as
// GEOMINT_TEST_FAULT says (comma-separated actions), acts at a chosen one:
//
//   stop-after-staging   SIGSTOP right after the first rename inside a staging folder: the program's first output
//                        is staged (a table written), nothing is committed; the probe then sends a signal.
//   kill-before-move=K   SIGKILL just before the K-th rename out of a staging folder: the commit's K-th move (or,
//                        after a failed move, a rollback's K-th restore).
//   kill-after-move=K    SIGKILL just after it.
//   fail-move=K          the K-th rename out of a staging folder fails with EIO (and is not done).
//   kill-before-link=K   SIGKILL just before the K-th hard link into a staging folder (the commit's K-th backup of
//                        an old file, before its journal exists).
//
// GEOMINT_TEST_FAULT_PIDFILE names a file that gets the pid before a stop (under mpiexec the probe cannot wait for a
// grandchild to stop). The library removes both variables and itself from the environment when it loads, so the
// processes the program starts (gnuplot) run without it.
#include <atomic>
#include <cerrno>
#include <climits>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <dlfcn.h>
#include <fcntl.h>
#include <string>
#include <sys/syscall.h>
#include <unistd.h>

namespace {

int stop_after_staging = 0, kill_before_move = 0, kill_after_move = 0, fail_move = 0, kill_before_link = 0;
char pidfile[PATH_MAX];
std::atomic<int> moves{0}, links{0}, staged{0};

int number_after(const std::string& action, const char* name) {
  const std::string prefix = std::string(name) + "=";
  return action.rfind(prefix, 0) == 0 ? std::atoi(action.c_str() + prefix.size()) : 0;
}

__attribute__((constructor)) void load() {
  if (const char* f = std::getenv("GEOMINT_TEST_FAULT")) {
    std::string all = f;
    for (std::size_t p = 0; p <= all.size();) {
      const std::size_t e = std::min(all.find(',', p), all.size());
      const std::string a = all.substr(p, e - p);
      if (a == "stop-after-staging") stop_after_staging = 1;
      if (int k = number_after(a, "kill-before-move")) kill_before_move = k;
      if (int k = number_after(a, "kill-after-move")) kill_after_move = k;
      if (int k = number_after(a, "fail-move")) fail_move = k;
      if (int k = number_after(a, "kill-before-link")) kill_before_link = k;
      p = e + 1;
    }
  }
  if (const char* p = std::getenv("GEOMINT_TEST_FAULT_PIDFILE")) std::snprintf(pidfile, sizeof pidfile, "%s", p);
  unsetenv("GEOMINT_TEST_FAULT");
  unsetenv("GEOMINT_TEST_FAULT_PIDFILE");
  unsetenv("LD_PRELOAD");
}

// The absolute path of (dirfd, path), as far as /proc tells.
std::string full_path(int dirfd, const char* path) {
  if (path[0] == '/') return path;
  char buf[PATH_MAX];
  std::string base;
  if (dirfd == AT_FDCWD) {
    if (::getcwd(buf, sizeof buf)) base = buf;
  } else {
    char link[64];
    std::snprintf(link, sizeof link, "/proc/self/fd/%d", dirfd);
    const ssize_t n = ::readlink(link, buf, sizeof buf - 1);
    if (n > 0) base.assign(buf, static_cast<std::size_t>(n));
  }
  return base + "/" + path;
}

bool in_staging(const std::string& p) { return p.find("/.geomint-run-") != std::string::npos; }

void stop_here() {
  if (pidfile[0]) {
    const std::string tmp = std::string(pidfile) + ".part";
    if (std::FILE* f = std::fopen(tmp.c_str(), "w")) {
      std::fprintf(f, "%d\n", static_cast<int>(::getpid()));
      std::fclose(f);
      ::syscall(SYS_renameat2, AT_FDCWD, tmp.c_str(), AT_FDCWD, pidfile, 0);  // not through our own renameat
    }
  }
  ::raise(SIGSTOP);
}

using renameat2_fn = int (*)(int, const char*, int, const char*, unsigned);
using linkat_fn = int (*)(int, const char*, int, const char*, int);

// Every rename goes through here: the fault, then the real call.
int do_rename(int olddirfd, const char* oldpath, int newdirfd, const char* newpath, unsigned flags) {
  static const auto real = reinterpret_cast<renameat2_fn>(::dlsym(RTLD_NEXT, "renameat2"));
  const bool from_staging = in_staging(full_path(olddirfd, oldpath));
  const bool to_staging = in_staging(full_path(newdirfd, newpath));
  int move = 0;
  if (from_staging && !to_staging) {
    move = ++moves;
    if (move == kill_before_move) ::raise(SIGKILL);
    if (move == fail_move) {
      errno = EIO;
      return -1;
    }
  }
  const int rc = real ? real(olddirfd, oldpath, newdirfd, newpath, flags)
                      : static_cast<int>(::syscall(SYS_renameat2, olddirfd, oldpath, newdirfd, newpath, flags));
  const int saved = errno;
  if (move && move == kill_after_move) ::raise(SIGKILL);
  if (from_staging && to_staging && rc == 0 && stop_after_staging && ++staged == 1) stop_here();
  errno = saved;
  return rc;
}

}  // namespace

extern "C" {

int rename(const char* oldpath, const char* newpath) { return do_rename(AT_FDCWD, oldpath, AT_FDCWD, newpath, 0); }

int renameat(int olddirfd, const char* oldpath, int newdirfd, const char* newpath) {
  return do_rename(olddirfd, oldpath, newdirfd, newpath, 0);
}

int renameat2(int olddirfd, const char* oldpath, int newdirfd, const char* newpath, unsigned flags) {
  return do_rename(olddirfd, oldpath, newdirfd, newpath, flags);
}

int linkat(int olddirfd, const char* oldpath, int newdirfd, const char* newpath, int flags) {
  static const auto real = reinterpret_cast<linkat_fn>(::dlsym(RTLD_NEXT, "linkat"));
  if (in_staging(full_path(newdirfd, newpath)) && ++links == kill_before_link) ::raise(SIGKILL);
  return real ? real(olddirfd, oldpath, newdirfd, newpath, flags)
              : static_cast<int>(::syscall(SYS_linkat, olddirfd, oldpath, newdirfd, newpath, flags));
}

int link(const char* oldpath, const char* newpath) { return linkat(AT_FDCWD, oldpath, AT_FDCWD, newpath, 0); }

}  // extern "C"
