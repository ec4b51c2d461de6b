// The probe: a table of bad inputs and faults run against every program in experiments/ (except bench_*),
// asserting the contract of the outputs: exit status, one line on stderr, outputs intact (byte for byte on a
// refusal or an interrupt), no temporary left, and nothing a user types executed; then the output machinery's
// faults through the programs: every terminating signal, a second run into a busy folder, a run killed at each
// move of its commit and healed by the next, planted symlinks, and the same under mpiexec -n 2. Programs are
// started with posix_spawn and an argument vector (no shell), so hostile paths reach them byte for byte; faults
// come from a library the probe preloads (fault_injection.cpp), never from a hook in a program.
// GEOMINT_PROBE_LOG=<file> appends one line per program run (case, exit status, signal, stderr lines, stopped):
//   GEOMINT_PROBE_LOG=runs.tsv build/tests/geomint_tests "[probe]"
#include <catch2/catch.hpp>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <spawn.h>
#include <sstream>
#include <string>
#include <sys/mount.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

#include "helpers.hpp"

namespace fs = std::filesystem;
using geomint::testing::fresh_dir;
using geomint::testing::read_bytes;

namespace {

struct Outcome {
  bool exited = false;
  int exit_code = -1;
  int signal = 0;
  bool stopped = false;  // reached the fault library's stop (interrupt cases)
  bool timed_out = false;
  std::string err;
  int lines() const { return static_cast<int>(std::count(err.begin(), err.end(), '\n')); }
  // The lines of the program, without the launcher's own: what a one-line refusal under mpiexec is counted by.
  int program_lines() const {
    std::istringstream in(err);
    std::string line;
    int n = 0;
    while (std::getline(in, line)) n += !launcher_line(line);
    return n;
  }
  // What mpiexec itself may print as it tears a job down, in the two forms Open MPI gives its own diagnostics:
  // libevent's warnings ("[warn] Epoll MOD(1) on fd ...") and opal's reports prefixed "[<node>:<pid>] " (seen once
  // in CI: mpiexec's own segfault in PMIx_server_finalize after the ranks had ended, a 16-line backtrace). A rank's
  // line starts with its program's name, never with '['.
  static bool launcher_line(const std::string& line) {
    if (line.rfind("[warn] ", 0) == 0) return true;
    if (line.empty() || line[0] != '[') return false;
    const auto close = line.find("] ");
    const auto colon = line.rfind(':', close);
    if (close == std::string::npos || colon == std::string::npos || colon + 1 >= close) return false;
    return std::all_of(line.begin() + static_cast<long>(colon) + 1, line.begin() + static_cast<long>(close),
                       [](char c) { return c >= '0' && c <= '9'; });
  }
  std::string last_line() const {
    std::string e = err;
    while (!e.empty() && e.back() == '\n') e.pop_back();
    const auto p = e.rfind('\n');
    return p == std::string::npos ? e : e.substr(p + 1);
  }
};

// How a program is started. Faults come from tests/fault_injection.cpp, preloaded (no program has a test hook).
struct Options {
  std::string fault;              // GEOMINT_TEST_FAULT for the preloaded fault library ("": nothing preloaded)
  int interrupt = 0;              // with fault "stop-after-staging": the signal sent once the program has stopped
  std::vector<std::string> env;   // more NAME=value
  bool hup_ignored = false;       // started with SIGHUP ignored, as nohup does
  double seconds = 300;           // a program still running after this is killed, and the case fails
  std::string asan;               // more AddressSanitizer options (the sanitizer build)
  // standard output: /dev/null, or a pipe whose reader has gone (the first write raises SIGPIPE)
  enum class Stdout { null, broken_pipe } out = Stdout::null;
};

// The signals a program takes over as interrupts, at their default action in every program the probe starts.
const int interrupt_signals[] = {SIGHUP, SIGINT, SIGQUIT, SIGTERM, SIGUSR1, SIGUSR2, SIGALRM, SIGXFSZ, SIGXCPU, SIGPWR};
// The signals of a fault: interrupts too when another process sends them (kill: si_code SI_USER).
const int fault_signals[] = {SIGABRT, SIGSEGV, SIGBUS, SIGSYS, SIGTRAP};

std::vector<std::string> environment(const Options& opt) {
  std::vector<std::string> envs;
  for (char** e = environ; *e; ++e) {
    const std::string v = *e;
    if (v.rfind("GEOMINT_TEST_FAULT", 0) == 0 || v.rfind("LD_PRELOAD=", 0) == 0 || v.rfind("ASAN_OPTIONS=", 0) == 0)
      continue;
    envs.push_back(v);
  }
  std::string asan = std::getenv("ASAN_OPTIONS") ? std::getenv("ASAN_OPTIONS") : "";
  if (!opt.asan.empty()) asan += (asan.empty() ? "" : ":") + opt.asan;
  if (!opt.fault.empty()) {
    envs.push_back(std::string("LD_PRELOAD=") + GEOMINT_FAULT_LIBRARY);
    envs.push_back("GEOMINT_TEST_FAULT=" + opt.fault);
    // the sanitizer build: AddressSanitizer wants to be first in the library list, before a preloaded library
    asan += std::string(asan.empty() ? "" : ":") + "verify_asan_link_order=0";
  }
  if (!asan.empty()) envs.push_back("ASAN_OPTIONS=" + asan);
  envs.insert(envs.end(), opt.env.begin(), opt.env.end());
  return envs;
}

struct Started {
  pid_t pid = 0;
  fs::path errfile;
};

// Starts exe with args in cwd (stdout discarded, stderr captured) with posix_spawn: no shell.
Started start_exe(const std::string& exe, const std::vector<std::string>& args, const fs::path& cwd, const Options& opt) {
  static int count = 0;
  Started s;
  s.errfile = fresh_dir("probe-stderr") / ("err-" + std::to_string(count++) + ".txt");
  std::vector<std::string> words{exe};
  words.insert(words.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  std::vector<std::string> envs = environment(opt);
  std::vector<char*> envp;
  for (auto& e : envs) envp.push_back(e.data());
  envp.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addchdir_np(&fa, cwd.c_str());
  int pipe_fds[2] = {-1, -1};
  if (opt.out == Options::Stdout::broken_pipe) {
    REQUIRE(pipe(pipe_fds) == 0);
    close(pipe_fds[0]);  // no reader, ever
    posix_spawn_file_actions_adddup2(&fa, pipe_fds[1], 1);
  } else {
    posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
  }
  posix_spawn_file_actions_addopen(&fa, 2, s.errfile.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  sigset_t def, none;
  sigemptyset(&def);
  sigemptyset(&none);
  for (int sig : interrupt_signals)
    if (!(opt.hup_ignored && sig == SIGHUP)) sigaddset(&def, sig);
  for (int sig : fault_signals) sigaddset(&def, sig);
  sigaddset(&def, SIGPIPE);
  posix_spawnattr_setsigdefault(&attr, &def);
  posix_spawnattr_setsigmask(&attr, &none);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETSIGMASK);
  struct sigaction ignore {}, old {};
  ignore.sa_handler = SIG_IGN;
  if (opt.hup_ignored) sigaction(SIGHUP, &ignore, &old);  // inherited across exec, as nohup does it
  const int rc = posix_spawn(&s.pid, exe.c_str(), &fa, &attr, argv.data(), envp.data());
  if (opt.hup_ignored) sigaction(SIGHUP, &old, nullptr);
  if (pipe_fds[1] >= 0) close(pipe_fds[1]);
  posix_spawn_file_actions_destroy(&fa);
  posix_spawnattr_destroy(&attr);
  REQUIRE(rc == 0);
  return s;
}

Started start(const std::string& program, const std::vector<std::string>& args, const fs::path& cwd, const Options& opt) {
  return start_exe(std::string(GEOMINT_BIN_DIR) + "/" + program, args, cwd, opt);
}

// waitpid with a time limit: false when it ran out (the process is still there).
bool wait_for(pid_t pid, int& status, int flags, double seconds) {
  for (double waited = 0; waited < seconds; waited += 0.005) {
    const pid_t r = waitpid(pid, &status, flags | WNOHANG);
    if (r == pid) return true;
    if (r < 0) return false;
    usleep(5000);
  }
  return false;
}

// Waits for a started program to end (with opt.interrupt: for its stop first, then sends the signal).
Outcome finish(const Started& s, const Options& opt) {
  Outcome o;
  int status = 0;
  bool done = wait_for(s.pid, status, opt.interrupt ? WUNTRACED : 0, opt.seconds);
  if (done && opt.interrupt && WIFSTOPPED(status)) {
    o.stopped = true;
    kill(s.pid, opt.interrupt);
    kill(s.pid, SIGCONT);
    done = wait_for(s.pid, status, 0, opt.seconds);
  }
  if (!done) {
    o.timed_out = true;
    kill(s.pid, SIGKILL);
    waitpid(s.pid, &status, 0);
  }
  o.exited = WIFEXITED(status);
  o.exit_code = o.exited ? WEXITSTATUS(status) : -1;
  o.signal = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
  std::ifstream in(s.errfile);
  std::stringstream ss;
  ss << in.rdbuf();
  o.err = ss.str();
  fs::remove(s.errfile);
  if (const char* log = std::getenv("GEOMINT_PROBE_LOG")) {  // for counting: one line per program run
    std::ofstream(log, std::ios::app) << Catch::getResultCapture().getCurrentTestName() << "\t" << o.exit_code << "\t"
                                      << o.signal << "\t" << o.lines() << "\t" << o.stopped << "\n";
  }
  return o;
}

// Runs GEOMINT_BIN_DIR/program with args in cwd; stdout discarded, stderr captured.
Outcome spawn(const std::string& program, const std::vector<std::string>& args, const fs::path& cwd,
              const Options& opt = {}) {
  return finish(start(program, args, cwd, opt), opt);
}

// An interrupt case: the program stops once its first output is staged, then gets `sig`.
Outcome interrupted(const std::string& program, const std::vector<std::string>& args, const fs::path& cwd, int sig) {
  Options opt;
  opt.fault = "stop-after-staging";
  opt.interrupt = sig;
  // the sanitizer build: AddressSanitizer takes SIGSEGV, SIGBUS and SIGABRT for its own reports unless told not to;
  // the program's handler is what is tested (a sanitizer report of a real fault is unaffected elsewhere)
  opt.asan = "handle_segv=0:handle_sigbus=0:handle_abort=0";
  return spawn(program, args, cwd, opt);
}

// Every file under dir (hidden ones too) with its bytes; a symlink as what it points to (never followed).
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> m;
  if (!fs::exists(dir)) return m;
  for (auto it = fs::recursive_directory_iterator(dir); it != fs::recursive_directory_iterator(); ++it) {
    const std::string rel = it->path().lexically_relative(dir).string();
    if (it->is_symlink()) {
      m[rel] = "symlink to " + fs::read_symlink(it->path()).string();
      continue;
    }
    if (it->is_directory()) {
      m[rel + "/"] = "";
      continue;
    }
    m[rel] = read_bytes(it->path());
  }
  return m;
}

// Temporaries a run could leave: staging folders, *.tmp, gnuplot's files.
std::vector<std::string> temporaries(const fs::path& dir) {
  std::vector<std::string> t;
  if (!fs::exists(dir)) return t;
  for (auto it = fs::recursive_directory_iterator(dir); it != fs::recursive_directory_iterator(); ++it) {
    const std::string n = it->path().filename().string();
    if (n.rfind(".geomint-", 0) == 0 || it->path().extension() == ".tmp" || n.rfind("gnuplot-", 0) == 0)
      t.push_back(it->path().string());
  }
  return t;
}

std::vector<std::string> split(const std::string& s) {
  std::istringstream in(s);
  std::vector<std::string> w;
  std::string x;
  while (in >> x) w.push_back(x);
  return w;
}

std::vector<std::string> plus(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

// Tiny parameters per program (the probe's whole run stays well under a minute on two cores):
//   ok: a complete run (tables and figures); overflow: T/h beyond any run; blowup: a sweep in which some runs
//   fail numerically (recorded as nan, the sweep goes on).
struct ProgramCase {
  const char* program;
  const char* ok;
  const char* overflow;
  const char* blowup;  // "" when the program has no run that can blow up
};

// modified_equation's formulas are staged with its table where the build has them (not in the sanitizer build)
#if GEOMINT_SYMBOLIC
#define GEOMINT_PROBE_FORMULAS " --formulas"
#else
#define GEOMINT_PROBE_FORMULAS ""
#endif
const ProgramCase table[] = {
#include "probe_table.inc"
};

// The paper's Figure 1 as regularized_error draws it (two tables, a stored trajectory, two figures): the run the tests
// of the output folder write with. fig1(...) is its command line with the given options; its files start with fig1_stem.
const std::string fig1_program = "regularized_error", fig1_stem = "oscillator_regularized_error";
std::vector<std::string> fig1(std::vector<std::string> more) {
  std::vector<std::string> a{"--system", "oscillator", "--schemes", "la", "la-printed", "contact", "--reference", "leapfrog",
                             "--trajectory"};
  a.insert(a.end(), more.begin(), more.end());
  return a;
}

std::vector<std::string> programs() {
  std::vector<std::string> p;
  for (const auto& e : fs::directory_iterator(GEOMINT_BIN_DIR)) {
    const std::string n = e.path().filename().string();
    if (e.is_regular_file() && access(e.path().c_str(), X_OK) == 0 && n.rfind("bench_", 0) != 0) p.push_back(n);
  }
  std::sort(p.begin(), p.end());
  return p;
}

const ProgramCase* case_of(const std::string& program) {
  for (const auto& c : table)
    if (program == c.program) return &c;
  return nullptr;
}

// A bad input: exit 2, one line naming the problem, nothing written.
void check_refused(const std::string& program, const std::vector<std::string>& args, const std::string& expect) {
  const auto base = fresh_dir("probe-refused");
  const auto out = base / "out";
  const auto o = spawn(program, plus(args, {"--out", out.string()}), base);
  INFO(program << " " << Catch::Detail::stringify(args) << " -> exit " << o.exit_code << ": " << o.err);
  CHECK(o.exit_code == 2);
  CHECK(o.lines() == 1);
  CHECK(o.err.find(expect) != std::string::npos);
  CHECK(!fs::exists(out));
  fs::remove_all(base);
}

}  // namespace

TEST_CASE("probe: every program has a row in the probe's table", "[probe]") {
  for (const auto& p : programs()) {
    INFO(p << ": add a row to tests/probe_table.inc (tiny parameters, an overflowing T/h, a blow-up)");
    CHECK(case_of(p) != nullptr);
  }
}

TEST_CASE("probe: stray positionals and repeated options are refused", "[probe]") {
  for (const auto& p : programs()) {
    check_refused(p, {"stray"}, "unexpected argument 'stray'");
    check_refused(p, {"--out", "a", "typo"}, "unexpected argument 'typo'");
    check_refused(p, {"--out", "a", "--out", "b"}, "given more than once");
  }
}

TEST_CASE("probe: an output path that cannot be a folder is refused on one line, even with a newline in it", "[probe]") {
  for (const auto& p : programs()) {
    const auto base = fresh_dir("probe-notdir");
    const fs::path file = base / "a file\n$(touch X)";
    std::ofstream(file) << "x";
    const auto o = spawn(p, {"--out", (file / "sub").string()}, base);
    INFO(p << " -> exit " << o.exit_code << ": " << o.err);
    CHECK(o.exit_code == 2);
    CHECK(o.lines() == 1);
    CHECK(o.err.find("output folder") != std::string::npos);
    CHECK(!fs::exists(base / "X"));
    fs::remove_all(base);
  }
}

TEST_CASE("probe: step counts beyond a long or the per-run limit are refused before any work", "[probe]") {
  for (const auto& c : table)
    if (*c.overflow) check_refused(c.program, split(c.overflow), "steps");
}

TEST_CASE("probe: hostile output paths are written as given and never executed", "[probe]") {
  for (const auto& c : table) {
    const auto base = fresh_dir("probe-hostile");
    const auto cwd = base / "cwd";
    fs::create_directories(cwd);
    // quotes, backticks, $(...), a gnuplot command after a quote, a newline, spaces, a leading dash
    const fs::path out = base / "-out 'q\" `touch BT` $(touch DS) \"; system \"touch SY\n x";
    const auto o = spawn(c.program, plus(split(c.ok), {"--out", out.string()}), cwd);
    INFO(c.program << " -> exit " << o.exit_code << ": " << o.err);
    CHECK(o.exit_code == 0);
    CHECK(fs::is_directory(out));
    bool tsv = false;
    for (const auto& e : fs::directory_iterator(out)) tsv = tsv || e.path().extension() == ".tsv";
    CHECK(tsv);
    CHECK(temporaries(out).empty());
    // nothing was executed: no file named by the commands anywhere
    for (auto it = fs::recursive_directory_iterator(base); it != fs::recursive_directory_iterator(); ++it) {
      const std::string n = it->path().filename().string();
      INFO(it->path());
      CHECK((n != "BT" && n != "DS" && n != "SY" && n != "SY\n x"));
    }
    CHECK(fs::directory_iterator(cwd) == fs::directory_iterator());
    fs::remove_all(base);
  }
}

TEST_CASE("probe: every terminating signal mid-run leaves the old outputs and no temporary", "[probe]") {
  for (const auto& c : table) {
    const auto base = fresh_dir("probe-interrupt");
    const auto out = base / "out";
    // the old outputs: a complete earlier run
    const auto first = spawn(c.program, plus(split(c.ok), {"--out", out.string()}), base);
    INFO(c.program << " first run -> exit " << first.exit_code << ": " << first.err);
    CHECK(first.exit_code == 0);
    if (first.exit_code != 0) continue;
    const auto before = snapshot(out);
    // The handler is one for every program: each program is probed with three signals, three programs (one
    // without Sweep, a sweep, one without figures) with all of them.
    const std::string p = c.program;
    const bool all = p == "regularized_error" || p == "convergence" || p == "modified_equation";
    for (int sig : interrupt_signals) {
      if (!all && sig != SIGINT && sig != SIGTERM && sig != SIGHUP) continue;
      const auto o = interrupted(c.program, plus(split(c.ok), {"--out", out.string(), "--no-budget"}), base, sig);
      INFO(c.program << " signal " << sig << " -> exit " << o.exit_code << ": " << o.err);
      CHECK(o.stopped);
      CHECK(o.exit_code == 128 + sig);
      // one line says so (after any progress lines the program printed before)
      CHECK(o.last_line().find("interrupted by signal " + std::to_string(sig) + " (") != std::string::npos);
      CHECK(o.last_line().find("the previous outputs are unchanged") != std::string::npos);
      CHECK(o.err.find("interrupted") == o.err.rfind("interrupted"));
      CHECK(temporaries(out).empty());
      CHECK(snapshot(out) == before);
    }
    // a first run into folders it made itself, interrupted, leaves none of them
    const auto made = base / "new" / "a" / "b";
    const auto o = interrupted(c.program, plus(split(c.ok), {"--out", made.string(), "--no-budget"}), base, SIGINT);
    INFO(c.program << " into new folders, SIGINT -> exit " << o.exit_code << ": " << o.err);
    CHECK(o.stopped);
    CHECK(o.exit_code == 128 + SIGINT);
    CHECK(!fs::exists(base / "new"));
    fs::remove_all(base);
  }
}

TEST_CASE("probe: a fault signal sent by another process is an interrupt, cleaned up, with its line", "[probe]") {
  // systemd's watchdog sends SIGABRT; a user's kill -SEGV is no fault of ours: both used to leave the staging
  // folder and the lock behind, with no line
  for (const char* program : {"integrate", "convergence"}) {
    const ProgramCase* c = case_of(program);
    REQUIRE(c);
    const auto base = fresh_dir("probe-fault-signal");
    const auto out = base / "out";
    REQUIRE(spawn(c->program, plus(split(c->ok), {"--out", out.string()}), base).exit_code == 0);
    const auto before = snapshot(out);
    for (int sig : fault_signals) {
      const auto o = interrupted(c->program, plus(split(c->ok), {"--out", out.string()}), base, sig);
      INFO(c->program << " signal " << sig << " -> exit " << o.exit_code << " signal " << o.signal << ": " << o.err);
      CHECK(o.stopped);
      CHECK(o.exit_code == 128 + sig);
      CHECK(o.last_line().find("interrupted by signal " + std::to_string(sig) + " (SIG") != std::string::npos);
      CHECK(o.last_line().find("the previous outputs are unchanged") != std::string::npos);
      CHECK(temporaries(out).empty());
      CHECK(snapshot(out) == before);
    }
    fs::remove_all(base);
  }
}

TEST_CASE("probe: a standard output whose reader has gone is an interrupt, cleaned up", "[probe]") {
  const auto base = fresh_dir("probe-stdout");
  const auto out = base / "out";
  // 21 alphas: 5.8 KB of lines on stdout, more than a pipe's buffer of stdio, so the first write reaches the pipe
  // mid-run (a program that prints less writes only as it exits, its outputs already in place)
  std::vector<std::string> args{"--h", "0.1", "--T", "36", "--alpha"};
  for (const char* a : {"1e-1", "1e-2", "1e-3", "1e-4", "2e-4", "3e-4", "4e-4", "5e-4", "6e-4", "7e-4", "8e-4",
                        "9e-4", "1e-5", "2e-5", "3e-5", "4e-5", "5e-5", "6e-5", "7e-5", "8e-5", "9e-5"})
    args.push_back(a);
  args = plus(args, {"--out", out.string()});
  REQUIRE(spawn("fig2_foucault", args, base).exit_code == 0);
  const auto before = snapshot(out);
  // the pipe's reader gone before the first write: SIGPIPE (13) ends the run as any interrupt
  Options broken;
  broken.out = Options::Stdout::broken_pipe;
  const auto o = spawn("fig2_foucault", args, base, broken);
  INFO("broken pipe -> exit " << o.exit_code << " signal " << o.signal << ": " << o.err);
  CHECK(o.exit_code == 128 + SIGPIPE);
  CHECK(o.last_line() == "fig2_foucault: interrupted by signal 13 (SIGPIPE); the previous outputs are unchanged");
  CHECK(temporaries(out).empty());
  CHECK(snapshot(out) == before);
  fs::remove_all(base);
}

TEST_CASE("probe: a stray MPI rank variable without a launcher changes nothing", "[probe]") {
  // a script on rank 1 of a job inherits its rank; run alone, the program is rank 0 of one process and writes
  for (const char* var : {"PMI_RANK=1", "OMPI_COMM_WORLD_RANK=1"})
    for (const char* program : {"integrate", "ensemble"}) {
      const ProgramCase* c = case_of(program);
      REQUIRE(c);
      const auto base = fresh_dir("probe-stray-rank");
      const auto out = base / "out";
      Options opt;
      opt.env = {var};
      const auto o = spawn(c->program, plus(split(c->ok), {"--out", out.string()}), base, opt);
      INFO(program << " with " << var << " -> exit " << o.exit_code << ": " << o.err);
      CHECK(o.exit_code == 0);
      CHECK(o.err.find("rank") == std::string::npos);
      bool table_written = false;
      if (fs::exists(out))
        for (const auto& e : fs::directory_iterator(out)) table_written |= e.path().extension() == ".tsv";
      CHECK(table_written);
      fs::remove_all(base);
    }
}

TEST_CASE("probe: fig2_foucault refuses work beyond the budget at once", "[probe]") {
  // 2 alphas x 2 schemes x 1e10 steps at T = 1e9, h = 0.1: about 64 hours; accepted before its plan
  const auto base = fresh_dir("probe-fig2-budget");
  const auto t0 = std::chrono::steady_clock::now();
  const auto o = spawn("fig2_foucault", {"--T", "1e9", "--h", "0.1", "--out", (base / "out").string()}, base);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  INFO("exit " << o.exit_code << " after " << seconds << " s: " << o.err);
  CHECK(o.exit_code == 2);
  CHECK(seconds < 2);
  CHECK(o.lines() == 1);
  CHECK(o.err.find("the runs (h x alpha x schemes x T/h): 4.8e+11 steps (weighted by their cost) in all exceed the "
                   "time budget") != std::string::npos);
  CHECK(!fs::exists(base / "out"));
  fs::remove_all(base);
}

TEST_CASE("probe: a blow-up inside a sweep is a missing value, and the sweep goes on", "[probe]") {
  for (const auto& c : table) {
    if (!*c.blowup) continue;
    const auto base = fresh_dir("probe-blowup");
    const auto out = base / "out";
    const auto o = spawn(c.program, plus(split(c.blowup), {"--out", out.string()}), base);
    INFO(c.program << " " << c.blowup << " -> exit " << o.exit_code << ": " << o.err);
    CHECK(o.exit_code == 0);
    CHECK(o.err.find("recorded as a missing value") != std::string::npos);
    CHECK(o.err.find("gnuplot") == std::string::npos);
    CHECK(temporaries(out).empty());
    bool nan = false;
    for (const auto& e : fs::directory_iterator(out))
      if (e.path().extension() == ".tsv") {
        nan = nan || read_bytes(e.path()).find("\tnan") != std::string::npos;
      }
    CHECK(nan);
    fs::remove_all(base);
  }
}

namespace {
// A tmpfs of `size` at a fresh folder, or "" (with the reason in `why`) where this machine does not allow it.
fs::path small_tmpfs(const std::string& name, const char* size, std::string& why) {
  const auto dir = fresh_dir(name);
  if (geteuid() != 0) {
    why = "not root";
    return {};
  }
  if (mount("tmpfs", dir.c_str(), "tmpfs", 0, (std::string("size=") + size).c_str()) != 0) {
    why = std::string("mount -t tmpfs: ") + std::strerror(errno);
    return {};
  }
  return dir;
}
}  // namespace

TEST_CASE("probe: a full disk is an error, the old outputs stay and no temporary is left", "[probe]") {
  for (const auto& c : table) {
    std::string why;
    const auto disk = small_tmpfs("probe-disk", "64k", why);
    if (disk.empty()) {
      WARN("full-disk probe skipped: " << why);
      return;
    }
    const auto out = disk / "out";
    fs::create_directories(out);
    std::ofstream(out / "old.tsv") << "old\n";
    // fill the disk
    {
      std::ofstream fill(disk / "filler", std::ios::binary);
      const std::string block(4096, 'x');
      for (int i = 0; i < 64 && fill; ++i) fill << block << std::flush;
    }
    const auto before = snapshot(out);
    const auto o = spawn(c.program, plus(split(c.ok), {"--out", out.string()}), disk.parent_path());
    INFO(c.program << " -> exit " << o.exit_code << ": " << o.err);
    CHECK(o.exit_code != 0);
    CHECK(o.exit_code != 2);
    CHECK(o.last_line().find("error") != std::string::npos);
    CHECK(temporaries(out).empty());
    CHECK(snapshot(out) == before);
    umount(disk.c_str());
    fs::remove_all(disk);
  }
}

TEST_CASE("probe: a sweep over the time budget is refused, and runs with --no-budget", "[probe]") {
  // 1e11 steps per run (the per-run limit) for each of several schemes: over the budget of 1e11 steps in all.
  const std::vector<std::string> over{"--system", "oscillator", "--h-max", "1e-4", "--h-min", "1e-4", "--T", "1e7"};
  check_refused("convergence", over, "exceed the time budget");
  // --no-budget lifts the time budget only: the per-run limit and the long stay
  check_refused("convergence", {"--system", "oscillator", "--h-max", "1e-5", "--h-min", "1e-5", "--T", "1e7", "--no-budget"},
                "steps per run");
}

TEST_CASE("probe: tolerances below a double's precision are refused", "[probe]") {
  check_refused("convergence", {"--system", "foucault", "--reference", "odeint-rhs", "--tol", "1e-20"}, "tol must be in [1e-15, 1)");
  check_refused("work_precision", {"--tol", "1e-20"}, "below the precision of a double");
}

TEST_CASE("probe: degenerate data (a zero state) gives figures, not gnuplot errors", "[probe]") {
  for (const auto& args : {plus({fig1_program}, fig1({"--h", "0.1", "--T", "2", "--q0", "0", "--p0", "0"})),
                           std::vector<std::string>{"convergence", "--system", "oscillator", "--h-max", "0.2", "--h-min",
                                                    "0.1", "--T", "2", "--q0", "0", "--p0", "0"}}) {
    const auto base = fresh_dir("probe-degenerate");
    const auto o = spawn(args[0], plus({args.begin() + 1, args.end()}, {"--out", (base / "out").string()}), base);
    INFO(args[0] << " -> exit " << o.exit_code << ": " << o.err);
    CHECK(o.exit_code == 0);
    CHECK(o.err.find("gnuplot") == std::string::npos);
    CHECK(o.err.find("warning") == std::string::npos);
    CHECK(temporaries(base / "out").empty());
    fs::remove_all(base);
  }
}

TEST_CASE("probe: a run whose stored trajectory cannot fit in memory is refused before it starts", "[probe]") {
  // 1e10 steps, the reference at h/10 stored as (t, q, p): 2.4 TB, beyond MemAvailable (and within the step limit)
  check_refused(fig1_program, fig1({"--h", "1e-3", "--T", "1e7", "--ref-factor", "10"}), "MB of memory available");
  // the registry's reference (closed form or Odeint) on 1e10 times: 80 GB and more, whatever the study
  check_refused("regularized_error", {"--system", "forced-oscillator", "--alpha", "0.1", "--h", "0.1", "--T", "1e9"},
                "lower --T or raise --h");
  // (--no-budget: the generic steps' time is over budget too, and the memory check must stand without it)
  check_refused("convergence", {"--system", "pendulum", "--h-max", "0.1", "--h-min", "0.1", "--T", "1e9", "--no-budget"},
                "lower --T or raise --h");
}

TEST_CASE("probe: an option left without its value, a name given twice and an unknown name are refused", "[probe]") {
  // "--out --no-budget": --out would take the next option as its value (a folder named "--no-budget")
  for (const auto& p : programs()) {
    const auto base = fresh_dir("probe-novalue");
    const auto o = spawn(p, {"--out", "--no-budget"}, base);
    INFO(p << " -> exit " << o.exit_code << ": " << o.err);
    CHECK(o.exit_code == 2);
    CHECK(o.lines() == 1);
    CHECK(o.err.find("has no value before the option '--no-budget'") != std::string::npos);
    CHECK(fs::is_empty(base));
    fs::remove_all(base);
  }
  // a list option followed by another option: before, modified_cost took "--out x" as two scheme names, skipped
  // both as "not applicable" and wrote into ./out
  check_refused("modified_cost", {"--systems", "pendulum", "--schemes", "--reps", "1"}, "has no value before the option '--reps'");
  check_refused("modified_cost", {"--systems", "pendulum", "--schemes", "la", "abc"}, "unknown scheme 'abc'");
  check_refused("regularized_error", {"--system", "oscillator", "--schemes", "la", "la"}, "'la' is given twice to --schemes");
  check_refused("modified_agreement", {"--systems", "pendulum", "pendulum"}, "'pendulum' is given twice to --systems");
  // a nan given for an option whose default is "each setting's own" was taken as not given
  check_refused("kepler_anchor", {"--settings", "anchor-1", "--tau", "nan"}, "tau must be a positive finite number");
  check_refused("kepler_anchor", {"--settings", "anchor-1", "--T", "nan"}, "T must be a positive finite number");
}

TEST_CASE("probe: an output path with no room under PATH_MAX for its files, or a dangling link, is refused", "[probe]") {
  const auto base = fresh_dir("probe-longpath");
  // 3900 characters: the folder itself could be made, its staged files could not
  fs::path deep = base;
  while (deep.string().size() < 3900) deep /= std::string(200, 'd');
  auto refused = [&](const fs::path& out, const std::string& expect) {
    const auto o = spawn("integrate", {"--out", out.string()}, base);
    INFO("integrate --out " << out.string().size() << " characters -> exit " << o.exit_code << ": " << o.err);
    CHECK(o.exit_code == 2);
    CHECK(o.lines() == 1);
    CHECK(o.err.find(expect) != std::string::npos);
  };
  refused(deep, "characters long");
  CHECK(!fs::exists(base / std::string(200, 'd')));
  fs::create_symlink(base / "missing", base / "link");
  refused(base / "link", "symbolic link to a missing target");
  CHECK(!fs::exists(base / "missing"));
  fs::remove_all(base);
}

TEST_CASE("probe: a stiff reference and an overflowing closed form are numerical failures, not hours or nan", "[probe]") {
  // a damping of 1e15 on the pendulum: the Odeint reference would need ~1e16 explicit steps
  const auto base = fresh_dir("probe-stiff");
  const auto stiff = spawn("convergence", {"--system", "pendulum", "--h-max", "0.1", "--h-min", "0.05", "--alpha", "1e15",
                                           "--out", (base / "a").string()}, base);
  INFO("convergence --alpha 1e15 -> exit " << stiff.exit_code << ": " << stiff.err);
  CHECK(stiff.exit_code == 3);
  CHECK(stiff.err.find("too stiff for an explicit integrator") != std::string::npos);
  CHECK(!fs::exists(base / "a"));
  // the adaptive baselines of a long-horizon study (work_precision's share the rule): each stops after its step
  // limit (1e6 steps, plus 1e5 per unit time) and is a missing point, named on stderr (3 s here; before, hours)
  const auto lh = spawn("long_horizon", {"--system", "forced-oscillator", "--periods", "4", "--m", "8", "--tol", "1e-5", "--reps",
                                         "1", "--alpha", "1e15", "--out", (base / "lh").string()}, base);
  INFO("long_horizon --system forced-oscillator --alpha 1e15 -> exit " << lh.exit_code << ": " << lh.err);
  CHECK(lh.exit_code == 0);
  CHECK(lh.err.find("adaptive steps by t = ") != std::string::npos);
  CHECK(lh.err.find("too stiff for an explicit integrator") != std::string::npos);
  // a damping of 1e308 overflows the contact closed form of the oscillator at its second step: a numerical failure
  // where it happens (before: a table of nan and exit 0)
  const auto over = spawn("integrate", {"--system", "oscillator", "--scheme", "contact", "--alpha", "1e308", "--out",
                                        (base / "b").string()}, base);
  INFO("integrate --alpha 1e308 -> exit " << over.exit_code << ": " << over.err);
  CHECK(over.exit_code == 3);
  CHECK(over.err.find("not finite") != std::string::npos);
  CHECK(!fs::exists(base / "b"));
  // an Omega of 1e15 makes the period far shorter than h: the turning points' store was sized from the period
  // (std::bad_alloc); it holds at most one a step. The closed-form reference itself is beyond double precision
  // there (its energy is nan at t = 0; at Omega = 100 it overflows by t = 6), a numerical failure where it is
  // made, before any run
  const auto fast = spawn("fig2_foucault", {"--T", "10", "--h", "0.1", "--Omega", "1e15", "--out", (base / "c").string()}, base);
  INFO("fig2_foucault --Omega 1e15 -> exit " << fast.exit_code << ": " << fast.err);
  CHECK(fast.exit_code == 3);
  CHECK(fast.err.find("bad_alloc") == std::string::npos);
  CHECK(fast.err.find("(reference): the closed-form solution or its energy is not finite at t = 0") != std::string::npos);
  CHECK(!fs::exists(base / "c"));
  fs::remove_all(base);
}

TEST_CASE("probe: a nan or inf computed from extreme inputs stops the run instead of reaching a table", "[probe]") {
  // Finite inputs whose values overflow inside the computation: a damping of 1e308 in the paper's Foucault loops,
  // a velocity of 1e308 in a modified equation's coefficients, a stiffness of 2^31 in an ensemble's energy. Each
  // wrote a table of nan or inf with exit 0; the table writer refuses any nan that is not a missing value.
  const std::vector<std::pair<std::string, std::vector<std::string>>> cases{
      {"fig2_foucault", {"--T", "10", "--h", "0.1", "--alpha", "1e308"}},
      {"modified_equation", {"--order", "2", "--v", "1e308"}},
      {"ensemble", {"--runs", "10", "--T", "2", "--kappa", "2147483648"}}};
  for (const auto& [program, args] : cases) {
    const auto base = fresh_dir("probe-not-finite");
    auto a = args;
    a.insert(a.end(), {"--out", (base / "o").string()});
    const auto r = spawn(program, a, base);
    INFO(program << " -> exit " << r.exit_code << ": " << r.err);
    CHECK(r.exit_code == 3);
    CHECK(r.err.find("numerical failure") != std::string::npos);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
    CHECK(!fs::exists(base / "o"));
    fs::remove_all(base);
  }
  // the forced oscillator's closed-form amplitude, which every error divides by, overflows: refused as an input
  // before any run (it gave a table of nan relative errors)
  check_refused("long_horizon", {"--system", "forced-oscillator", "--periods", "4", "--beta", "1e308", "--alpha", "1e-3"},
                "steady-state amplitude");
}

TEST_CASE("probe: a refusal that comes after the output folder was made leaves no folder behind", "[probe]") {
  // refused only once the run's folder exists (the values overflow inside the computation, or T/h is checked late):
  // the folders the run created, nested ones included, are removed again; a folder that was there stays
  const std::vector<std::pair<std::string, std::vector<std::string>>> late{
      {"stability", {"--alpha-max", "1e308"}},
      {"stability", {"--alpha-min", "1e-320"}}};
  for (const auto& [program, args] : late) {
    const auto base = fresh_dir("probe-late");
    const auto out = base / "a" / "b" / "out";
    const auto o = spawn(program, plus(args, {"--out", out.string()}), base);
    INFO(program << " " << Catch::Detail::stringify(args) << " -> exit " << o.exit_code << ": " << o.err);
    CHECK(o.exit_code == 2);
    CHECK(o.lines() == 1);
    CHECK(!fs::exists(base / "a"));
    fs::create_directories(out);  // an existing folder is the user's: it stays, empty as it was
    const auto again = spawn(program, plus(args, {"--out", out.string()}), base);
    CHECK(again.exit_code == 2);
    CHECK(fs::is_directory(out));
    CHECK(fs::is_empty(out));
    fs::remove_all(base);
  }
}

TEST_CASE("probe: the budget counts every run a program plans, and timed loops by their length", "[probe]") {
  // 2 systems x 2 schemes x 3 orders runs of T/h for each of 3 step sizes: 4.2e11 steps (the plan counted 3.5e10)
  check_refused("nonholonomic_modified", {"--T", "1e9"}, "exceed the time budget");
  // steps weighted by what they cost: a modified equation's Odeint solution is 1e4 cheap steps and more, so these
  // (accepted before, hours to days of work) are refused
  check_refused("nonholonomic_modified", {"--T", "1e4"}, "weighted by their cost");
  check_refused("modified_agreement", {"--T", "1e7"}, "weighted by their cost");
  // 10 s x 101 loops per cell: days by construction
  check_refused("modified_cost", {"--seconds", "10", "--reps", "100"}, "exceed the time budget");
  // generic Newton steps cost 20 cheap steps, a composition's its stages' (step_cost.hpp): 1e10 generic steps (a
  // run of 2.5 h on the pendulum), 6e9 steps of a 17-stage composition and 2e10 ensemble steps, all accepted
  // before as under 1e11 steps, are refused
  check_refused("integrate", {"--T", "1e9", "--h", "0.1"}, "weighted by their cost");
  check_refused("convergence", {"--system", "pendulum", "--schemes", "kahanli8:la-midpoint", "--T", "2e7", "--h-min", "0.01"},
                "weighted by their cost");
  check_refused("ensemble", {"--runs", "100000", "--T", "2e4"}, "weighted by their cost");
}

TEST_CASE("probe: a signal ignored when the program starts (nohup) stays ignored", "[probe]") {
  const auto base = fresh_dir("probe-nohup");
  const auto out = base / "out";
  Options opt;
  opt.fault = "stop-after-staging";
  opt.interrupt = SIGHUP;
  opt.hup_ignored = true;
  const auto o = spawn(fig1_program, fig1({"--h", "0.1", "--T", "2", "--out", out.string()}), base, opt);
  INFO("exit " << o.exit_code << ": " << o.err);
  CHECK(o.stopped);  // it was stopped mid-run and got SIGHUP there
  CHECK(o.exit_code == 0);
  CHECK(o.err.empty());
  CHECK(fs::exists(out / (fig1_stem + "_trajectory.pdf")));
  CHECK(temporaries(out).empty());
  fs::remove_all(base);
}

namespace {
}  // namespace

TEST_CASE("probe: no program carries a test hook, and the old one's variable does nothing", "[probe]") {
  // Fault injection lives in a library only the probe preloads: no program binary names a fault variable.
  for (const auto& p : programs()) {
    const std::string bytes = read_bytes(fs::path(GEOMINT_BIN_DIR) / p);
    INFO(p);
    CHECK(bytes.size() > 10000);
    CHECK(bytes.find("GEOMINT_FAULT") == std::string::npos);
    CHECK(bytes.find("GEOMINT_TEST_FAULT") == std::string::npos);
  }
  // The variable that used to stop a program forever, set to anything, even empty: the run completes.
  for (const char* value : {"1", "0", ""}) {
    const auto base = fresh_dir("probe-nohook");
    Options opt;
    opt.env = {std::string("GEOMINT_FAULT_STOP_AFTER_FIRST_OUTPUT=") + value};
    opt.interrupt = SIGTERM;  // sent only if the program stops
    opt.seconds = 120;
    const auto o = spawn(fig1_program, fig1({"--h", "0.1", "--T", "2", "--out", (base / "out").string()}), base, opt);
    INFO("GEOMINT_FAULT_STOP_AFTER_FIRST_OUTPUT='" << value << "' -> exit " << o.exit_code << ": " << o.err);
    CHECK(!o.stopped);
    CHECK(o.exit_code == 0);
    CHECK(o.err.empty());
    fs::remove_all(base);
  }
}

TEST_CASE("probe: a second run into a busy output folder refuses at once and changes nothing", "[probe]") {
  const auto base = fresh_dir("probe-busy");
  const auto out = base / "out";
  REQUIRE(spawn(fig1_program, fig1({"--h", "0.1", "--T", "2", "--out", out.string()}), base).exit_code == 0);
  // the first run stops mid-run, holding the folder
  Options hold;
  hold.fault = "stop-after-staging";
  const Started first = start(fig1_program, fig1({"--h", "0.1", "--T", "3", "--out", out.string()}), base, hold);
  int status = 0;
  REQUIRE(wait_for(first.pid, status, WUNTRACED, 120));
  REQUIRE(WIFSTOPPED(status));
  const auto before = snapshot(out);
  for (const char* program : {"regularized_error", "modified_equation"}) {
    const auto args = program == fig1_program ? fig1({"--h", "0.1", "--T", "4"}) : split(case_of(program)->ok);
    const auto second = spawn(program, plus(args, {"--out", out.string()}), base);
    INFO(program << " -> exit " << second.exit_code << ": " << second.err);
    CHECK(second.exit_code == 2);
    CHECK(second.lines() == 1);
    CHECK(second.err.find("is in use by another run (process " + std::to_string(first.pid)) != std::string::npos);
    CHECK(snapshot(out) == before);
  }
  // the first run then ends as if nothing had happened
  kill(first.pid, SIGCONT);
  const auto o = finish(first, {});
  INFO("first run -> exit " << o.exit_code << ": " << o.err);
  CHECK(o.exit_code == 0);
  CHECK(o.err.empty());
  CHECK(read_bytes(out / (fig1_stem + ".tsv")).find("# T: 3\n") != std::string::npos);
  CHECK(temporaries(out).empty());
  fs::remove_all(base);
}

namespace {
// The files of `dir` a name of which starts with `prefix`, with their bytes.
std::map<std::string, std::string> files_of(const fs::path& dir, const std::string& prefix) {
  std::map<std::string, std::string> m;
  for (const auto& [name, bytes] : snapshot(dir))
    if (name.rfind(prefix, 0) == 0) m[name] = bytes;
  return m;
}

// The data files (.tsv) among them: figures carry a creation date, data files the same bits every run.
std::map<std::string, std::string> tables(std::map<std::string, std::string> m) {
  for (auto it = m.begin(); it != m.end();) it = fs::path(it->first).extension() == ".tsv" ? std::next(it) : m.erase(it);
  return m;
}

bool has_staging(const fs::path& dir) {
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().rfind(".geomint-run-", 0) == 0) return true;
  return false;
}

const std::vector<std::string> old_args = fig1({"--h", "0.1", "--T", "2"}), new_args = fig1({"--h", "0.1", "--T", "3"});

// An output folder holding the Figure 1 run's old outputs; `fault` then hits a run with new parameters into it.
struct Crash {
  fs::path base, out;
  std::map<std::string, std::string> old_files;
  Outcome killed;
};

Crash crash(const std::string& name, const std::string& fault) {
  Crash c;
  c.base = fresh_dir(name);
  c.out = c.base / "out";
  REQUIRE(spawn(fig1_program, plus(old_args, {"--out", c.out.string()}), c.base).exit_code == 0);
  c.old_files = files_of(c.out, fig1_stem);
  Options opt;
  opt.fault = fault;
  c.killed = spawn(fig1_program, plus(new_args, {"--out", c.out.string()}), c.base, opt);
  return c;
}

// The next run into the folder (another program, so that what the healing did stays visible): its one line.
Outcome heal(const Crash& c, const Options& opt = {}) {
  return spawn("modified_equation", plus(split(case_of("modified_equation")->ok), {"--out", c.out.string()}), c.base, opt);
}

// The next run healed the folder to the Figure 1 run's old outputs, and said `what` on its one line.
void check_healed_to_old(const Crash& c, const Outcome& h, const std::string& what) {
  INFO("next run -> exit " << h.exit_code << ": " << h.err);
  CHECK(h.exit_code == 0);
  CHECK(h.lines() == 1);
  CHECK(h.err.find(what) != std::string::npos);
  CHECK(files_of(c.out, fig1_stem) == c.old_files);
  CHECK(temporaries(c.out).empty());
}
}  // namespace

TEST_CASE("probe: a run killed at each move of its commit is finished by the next run into the folder", "[probe]") {
  // the new outputs, complete, from an uninterrupted run
  const auto ref = fresh_dir("probe-commit-ref");
  REQUIRE(spawn(fig1_program, plus(new_args, {"--out", (ref / "out").string()}), ref).exit_code == 0);
  const auto new_tables = tables(files_of(ref / "out", fig1_stem));
  const std::size_t n = files_of(ref / "out", fig1_stem).size();
  REQUIRE(n == 4);
  for (std::size_t k = 1; k <= n + 1; ++k) {
    const std::string fault = k <= n ? "kill-before-move=" + std::to_string(k) : "kill-after-move=" + std::to_string(n);
    const auto c = crash("probe-commit", fault);
    INFO(fault << " -> killed run: signal " << c.killed.signal << ", " << c.killed.err);
    CHECK(c.killed.signal == SIGKILL);
    CHECK(has_staging(c.out));  // the killed run left its staging folder, its journal and its lock
    CHECK(fs::exists(c.out / ".geomint-lock"));
    const auto h = heal(c);
    INFO("next run -> exit " << h.exit_code << ": " << h.err);
    CHECK(h.exit_code == 0);
    CHECK(h.lines() == 1);
    const std::size_t left = k <= n ? n - k + 1 : 0;
    CHECK(h.err.find("finished the commit of a run killed while committing (" + std::to_string(left) + " of " +
                     std::to_string(n) + " files were still to move)") != std::string::npos);
    // the killed run's new outputs, all of them, and the next run's own; nothing else
    CHECK(tables(files_of(c.out, fig1_stem)) == new_tables);
    CHECK(files_of(c.out, fig1_stem).size() == n);
    CHECK(fs::exists(c.out / "modified_equation.tsv"));
    CHECK(temporaries(c.out).empty());
    CHECK(files_of(c.out, ".").empty());  // no .old-*, no lock, no journal
    fs::remove_all(c.base);
  }
  fs::remove_all(ref);
}

TEST_CASE("probe: a commit that cannot move a file rolls back, and so does the next run when it was killed doing so", "[probe]") {
  // a move that fails: rolled back at once, one line, the folder as it was
  {
    const auto c = crash("probe-rollback", "fail-move=2");
    INFO("exit " << c.killed.exit_code << ": " << c.killed.err);
    CHECK(c.killed.exit_code == 1);
    CHECK(c.killed.lines() == 1);
    CHECK(c.killed.err.find("Input/output error (the previous outputs are unchanged)") != std::string::npos);
    CHECK(files_of(c.out, "") == c.old_files);
    CHECK(temporaries(c.out).empty());
    fs::remove_all(c.base);
  }
  // killed while putting the first file back (move 3: move 1 done, move 2 failed): the next run rolls back
  {
    const auto c = crash("probe-rollback-killed", "fail-move=2,kill-before-move=3");
    CHECK(c.killed.signal == SIGKILL);
    CHECK(has_staging(c.out));
    check_healed_to_old(c, heal(c), "rolled back the interrupted commit of a run that was killed (it had begun to undo it)");
    fs::remove_all(c.base);
  }
  // killed mid-commit, and the next run cannot finish it (its first move fails): it rolls back instead
  {
    const auto c = crash("probe-heal-fails", "kill-before-move=2");
    CHECK(c.killed.signal == SIGKILL);
    Options opt;
    opt.fault = "fail-move=1";
    check_healed_to_old(c, heal(c, opt), "it could not be finished: cannot move");
    fs::remove_all(c.base);
  }
}

TEST_CASE("probe: a run killed before its commit began leaves the old outputs, and the next run removes its remains", "[probe]") {
  for (const std::string fault : {"kill-before-link=1", ""}) {
    // killed while keeping the old files (no journal yet), or mid-run (SIGKILL at the first staged output)
    Crash c;
    if (!fault.empty()) {
      c = crash("probe-precommit", fault);
    } else {
      c.base = fresh_dir("probe-midrun");
      c.out = c.base / "out";
      REQUIRE(spawn(fig1_program, plus(old_args, {"--out", c.out.string()}), c.base).exit_code == 0);
      c.old_files = files_of(c.out, fig1_stem);
      c.killed = interrupted(fig1_program, plus(new_args, {"--out", c.out.string()}), c.base, SIGKILL);
    }
    INFO((fault.empty() ? "SIGKILL mid-run" : fault) << " -> signal " << c.killed.signal << ": " << c.killed.err);
    CHECK(c.killed.signal == SIGKILL);
    CHECK(has_staging(c.out));
    CHECK(files_of(c.out, fig1_stem) == c.old_files);  // untouched before the journal
    check_healed_to_old(c, heal(c), "removed the staging folder of a run that ended without committing");
    fs::remove_all(c.base);
  }
}

TEST_CASE("probe: symlinks planted in the output folder are never followed", "[probe]") {
  const auto base = fresh_dir("probe-symlink");
  const auto out = base / "out";
  fs::create_directories(out);
  std::ofstream(base / "victim.txt") << "victim\n";
  // in the lock's place: refused, nothing changed
  fs::create_symlink("../victim.txt", out / ".geomint-lock");
  auto before = snapshot(out);
  const auto refused = spawn(fig1_program, plus(old_args, {"--out", out.string()}), base);
  INFO("exit " << refused.exit_code << ": " << refused.err);
  CHECK(refused.exit_code == 2);
  CHECK(refused.lines() == 1);
  CHECK(refused.err.find("cannot lock output folder") != std::string::npos);
  CHECK(snapshot(out) == before);
  CHECK(read_bytes(base / "victim.txt") == "victim\n");
  fs::remove(out / ".geomint-lock");
  // in an output's place: the output replaces the link, the file it pointed to stays
  fs::create_symlink("../victim.txt", out / (fig1_stem + ".tsv"));
  const auto o = spawn(fig1_program, plus(old_args, {"--out", out.string()}), base);
  INFO("exit " << o.exit_code << ": " << o.err);
  CHECK(o.exit_code == 0);
  CHECK(read_bytes(base / "victim.txt") == "victim\n");
  CHECK(!fs::is_symlink(out / (fig1_stem + ".tsv")));
  CHECK(read_bytes(out / (fig1_stem + ".tsv")).rfind("# program: regularized_error\n", 0) == 0);
  CHECK(temporaries(out).empty());
  fs::remove_all(base);
}

#ifdef GEOMINT_MPIEXEC
namespace {
// `mpiexec -q -n 2 program args...`. -q keeps mpiexec's own notices (a rank's nonzero exit) off stderr, so what is
// there is the program's. Open MPI refuses root without its two variables (CI runs as root) and may count too few
// slots on two cores; LeakSanitizer is off for the ranks (Open MPI's own allocations at MPI_Finalize, see
// sweep.test.cpp), and a preloaded fault library need not follow AddressSanitizer's runtime.
Started start_mpi(const std::string& program, const std::vector<std::string>& args, const fs::path& cwd,
                  const std::string& fault = "", const fs::path& pidfile = {}, const std::vector<std::string>& env = {}) {
  std::vector<std::string> words{"-q", "-n", "2"};
  if (!fault.empty())
    words.insert(words.end(), {"-x", std::string("LD_PRELOAD=") + GEOMINT_FAULT_LIBRARY, "-x", "GEOMINT_TEST_FAULT=" + fault});
  if (!pidfile.empty()) words.insert(words.end(), {"-x", "GEOMINT_TEST_FAULT_PIDFILE=" + pidfile.string()});
  words.push_back(std::string(GEOMINT_BIN_DIR) + "/" + program);
  words.insert(words.end(), args.begin(), args.end());
  Options opt;
  opt.env = {"OMPI_ALLOW_RUN_AS_ROOT=1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1", "OMPI_MCA_rmaps_base_oversubscribe=1"};
  opt.env.insert(opt.env.end(), env.begin(), env.end());
  opt.asan = "detect_leaks=0:verify_asan_link_order=0";
  return start_exe(GEOMINT_MPIEXEC, words, cwd, opt);
}

Outcome mpi(const std::string& program, const std::vector<std::string>& args, const fs::path& cwd,
            const std::vector<std::string>& env = {}) {
  Options opt;
  opt.seconds = 120;  // a rank left waiting for another is a failure, not a hang of the suite
  return finish(start_mpi(program, args, cwd, "", {}, env), opt);
}

// A program without Sweep (its other rank leaves at once) and a sweep program (both ranks compute), tiny runs.
const std::vector<std::pair<std::string, std::string>> mpi_programs{
    {"regularized_error", "--system oscillator --schemes la la-printed contact --reference leapfrog --trajectory --h 0.1 --T 2"},
    {"convergence", "--system oscillator --h-max 0.2 --h-min 0.1 --T 2"}};
}  // namespace

TEST_CASE("probe (MPI): bad input under mpiexec -n 2 is one line in all, and nothing is written", "[probe][mpi]") {
  for (const auto& [program, ok] : mpi_programs) {
    const auto good = split(ok);
    auto bad_t = good;
    bad_t[std::find(bad_t.begin(), bad_t.end(), "--T") - bad_t.begin() + 1] = "-1";  // a bad value
    for (const auto& [args, expect] : std::vector<std::pair<std::vector<std::string>, std::string>>{
             {plus(good, {"--bogus", "1"}), "unrecognised option '--bogus'"},
             {plus({"stray"}, good), "unexpected argument 'stray'"},
             {bad_t, "-1"}}) {
      const auto base = fresh_dir("probe-mpi-bad");
      const auto o = mpi(program, plus(args, {"--out", (base / "out").string()}), base);
      INFO(program << " " << Catch::Detail::stringify(args) << " -> exit " << o.exit_code << ": " << o.err);
      CHECK(o.exit_code == 2);
      CHECK(o.program_lines() == 1);
      CHECK(o.err.rfind(program + ": error: ", 0) == 0);
      CHECK(o.err.find(expect) != std::string::npos);
      CHECK(!fs::exists(base / "out"));
      fs::remove_all(base);
    }
  }
}

TEST_CASE("probe (MPI): only rank 0 writes, through its staging folder: planted symlinks are not followed", "[probe][mpi]") {
  for (const auto& [program, ok] : mpi_programs) {
    const auto base = fresh_dir("probe-mpi-symlink");
    const auto one = base / "one", out = base / "out";
    REQUIRE(spawn(program, plus(split(ok), {"--out", one.string()}), base).exit_code == 0);
    // every name a rank could once write through: <out>/<name>.tmp -> ../victim.txt
    std::ofstream(base / "victim.txt") << "victim\n";
    fs::create_directories(out);
    for (const auto& [name, bytes] : snapshot(one)) fs::create_symlink("../victim.txt", out / (name + ".tmp"));
    const auto planted = snapshot(out);
    const auto o = mpi(program, plus(split(ok), {"--out", out.string()}), base);
    INFO(program << " -> exit " << o.exit_code << ": " << o.err);
    CHECK(o.exit_code == 0);
    CHECK(o.err.empty());
    CHECK(read_bytes(base / "victim.txt") == "victim\n");
    CHECK(tables(files_of(out, "")) == tables(snapshot(one)));  // the single-process tables, byte for byte
    for (const auto& [name, bytes] : planted) {
      INFO(name);
      CHECK(fs::is_symlink(out / name));  // the user's links, untouched
    }
    CHECK(temporaries(out).size() == planted.size());  // and nothing else left behind
    fs::remove_all(base);
  }
}

namespace {
// The same arguments with the horizon 3 instead of 2: a run whose tables differ from the old ones.
std::vector<std::string> longer(std::vector<std::string> args) {
  args[static_cast<std::size_t>(std::find(args.begin(), args.end(), "--T") - args.begin()) + 1] = "3";
  return args;
}

pid_t read_pid(const fs::path& pidfile) {
  pid_t pid = 0;
  for (int i = 0; i < 24000 && pid == 0; ++i) {
    std::ifstream(pidfile) >> pid;
    if (pid == 0) usleep(5000);
  }
  return pid;
}

// /proc/<pid>/status: is the process stopped, has it `sig` pending?
bool stopped(pid_t pid) {
  return read_bytes("/proc/" + std::to_string(pid) + "/status").find("State:\tT") != std::string::npos;
}
bool pending(pid_t pid, int sig) {
  const std::string st = read_bytes("/proc/" + std::to_string(pid) + "/status");
  for (const char* field : {"SigPnd:\t", "ShdPnd:\t"}) {
    const auto p = st.find(field);
    if (p != std::string::npos && (std::stoull(st.substr(p + std::strlen(field)), nullptr, 16) >> (sig - 1)) & 1) return true;
  }
  return false;
}
}  // namespace

TEST_CASE("probe (MPI): an interrupted run under mpiexec -n 2 leaves the old outputs, with one line", "[probe][mpi]") {
  // the launcher's lines are told from the ranks' by their form (as CI once saw them)
  CHECK(Outcome::launcher_line("[warn] Epoll MOD(1) on fd 27 failed. Old events were 6; read change was 0 (none)"));
  CHECK(Outcome::launcher_line("[ci-runner:04711] *** Process received signal ***"));
  CHECK(Outcome::launcher_line("[ci-runner:04711] [ 3] /lib/x86_64-linux-gnu/libpmix.so.2(PMIx_server_finalize+0x2e)"));
  CHECK(!Outcome::launcher_line("modified_equation: interrupted by signal 15 (SIGTERM); the previous outputs are unchanged"));
  CHECK(!Outcome::launcher_line("[1] 0.5 not a launcher line"));
  for (const auto& [program, ok] : mpi_programs) {
    const auto ref = fresh_dir("probe-mpi-new");  // the new run's tables, complete
    REQUIRE(spawn(program, plus(longer(split(ok)), {"--out", (ref / "out").string()}), ref).exit_code == 0);
    const auto new_tables = tables(snapshot(ref / "out"));
    // a signal to rank 0; 0: Ctrl-C at a terminal, SIGINT to mpiexec, which passes SIGTERM on to the ranks
    for (int sig : {SIGINT, SIGTERM, SIGHUP, 0}) {
      const auto base = fresh_dir("probe-mpi-interrupt");
      const auto out = base / "out";
      REQUIRE(spawn(program, plus(split(ok), {"--out", out.string()}), base).exit_code == 0);
      const auto before = snapshot(out);
      // rank 0 stops once its first output is staged (rank 1 has written nothing, and ended or waits)
      const fs::path pidfile = base / "rank0.pid";
      const Started s = start_mpi(program, plus(longer(split(ok)), {"--out", out.string()}), base, "stop-after-staging", pidfile);
      const pid_t rank0 = read_pid(pidfile);
      REQUIRE(rank0 > 0);
      for (int i = 0; i < 24000 && !stopped(rank0); ++i) usleep(5000);
      if (sig) {
        kill(rank0, sig);
      } else {
        // mpiexec sends SIGTERM, then SIGKILL after a grace: rank 0 (stopped here, not by mpiexec) is resumed once
        // the SIGTERM is pending, as a running rank would take it at once
        kill(s.pid, SIGINT);
        for (int i = 0; i < 24000 && stopped(rank0) && !pending(rank0, SIGTERM); ++i) usleep(1000);
      }
      kill(rank0, SIGCONT);
      Options opt;
      opt.seconds = 120;
      auto o = finish(s, opt);
      INFO(program << " signal " << sig << " -> exit " << o.exit_code << ": " << o.err);
      if (sig) {
        CHECK(temporaries(out).empty());
        CHECK(!o.timed_out);
        if (!o.exited && !o.timed_out) {
          // mpiexec killed by a signal of its own making after the ranks ended (its teardown's crash, once in CI):
          // the launcher's status is then not the ranks', so the ranks' outcome is read from their line and files
          WARN("mpiexec itself ended by signal " << o.signal << " after the ranks: " << o.err);
        } else {
          CHECK(o.exit_code == 128 + sig);
        }
        CHECK(o.program_lines() == 1);
        CHECK(o.err.find("interrupted by signal " + std::to_string(sig) + " (") != std::string::npos);
        CHECK(o.err.find("the previous outputs are unchanged") != std::string::npos);
        CHECK(snapshot(out) == before);
        fs::remove_all(base);
        continue;
      }
      // Through mpiexec: it resumes the ranks, may send SIGTERM, and kills what still runs a second later
      // (odls_base_sigkill_timeout): rank 0 ends interrupted (old outputs), finished (new ones) or killed (its
      // staging folder left, for the next run to heal). Its libevent may warn as it tears the job down
      // ("[warn] Epoll MOD(1) on fd ..."), crash in its own teardown (Outcome::launcher_line), and it may drop a
      // rank's last line. What must hold: never a mix, a line that is there tells which, and a killed run is healed
      // by the next.
      std::istringstream in(o.err);
      std::string line, ours;
      while (std::getline(in, line))
        if (!Outcome::launcher_line(line)) ours += line + "\n";
      INFO("lines of the program: " << ours);
      CHECK(o.exit_code != 0);
      CHECK(std::count(ours.begin(), ours.end(), '\n') <= 1);
      auto after = snapshot(out);
      if (!temporaries(out).empty()) {  // killed: the next run into the folder heals it, on one line
        CHECK(ours.empty());
        const auto h = spawn("modified_equation", plus(split(case_of("modified_equation")->ok), {"--out", out.string()}), base);
        INFO("next run -> exit " << h.exit_code << ": " << h.err);
        CHECK(h.exit_code == 0);
        CHECK(h.lines() == 1);
        CHECK(h.err.find("output folder '" + out.string() + "': ") != std::string::npos);
        CHECK(temporaries(out).empty());
        after = snapshot(out);
        // what the healing run wrote (its table, and its formulas when the case asks for them) is not the sweep's
        const auto alone = fresh_dir("probe-mpi-heal-alone");
        REQUIRE(spawn("modified_equation", plus(split(case_of("modified_equation")->ok), {"--out", (alone / "out").string()}), alone).exit_code == 0);
        for (const auto& [name, bytes] : snapshot(alone / "out")) after.erase(name);
        fs::remove_all(alone);
      }
      const bool old_ones = after == before, new_ones = tables(after) == new_tables && after.size() == before.size();
      std::string differ;  // names whose bytes differ from the old outputs, for the message
      for (const auto& [name, bytes] : after)
        if (!before.count(name) || before.at(name) != bytes) differ += " " + name;
      for (const auto& [name, bytes] : before)
        if (!after.count(name)) differ += " -" + name;
      INFO("changed since the old outputs:" << differ);
      CHECK((old_ones || new_ones));
      if (!ours.empty()) {
        CHECK(ours.find("interrupted by signal 15 (SIGTERM)") != std::string::npos);
        CHECK((ours.find("the previous outputs are unchanged") != std::string::npos) == old_ones);
        CHECK((ours.find("its new outputs were already in place") != std::string::npos) == new_ones);
      }
      fs::remove_all(base);
    }
    fs::remove_all(ref);
  }
}

TEST_CASE("probe (MPI): a sweep into a busy folder is refused on every rank, at once", "[probe][mpi]") {
  const auto& [program, ok] = mpi_programs[1];
  const auto base = fresh_dir("probe-mpi-busy");
  const auto out = base / "out";
  Options hold;
  hold.fault = "stop-after-staging";
  const Started first = start(program, plus(split(ok), {"--out", out.string()}), base, hold);
  int status = 0;
  REQUIRE(wait_for(first.pid, status, WUNTRACED, 120));
  REQUIRE(WIFSTOPPED(status));
  const auto before = snapshot(out);
  // Launchers differ on a rank that exits nonzero: Open MPI aborts the job by default, Slurm's srun lets the others
  // run (as Open MPI with orte_abort_on_non_zero_status=0, whose own exit status is then 0). Without that abort,
  // only the ranks' agreement on rank 0's refusal keeps rank 1 from waiting forever.
  for (bool launcher_aborts : {true, false}) {
    const auto o = mpi(program, plus(split(ok), {"--out", out.string()}), base,
                       launcher_aborts ? std::vector<std::string>{} : std::vector<std::string>{"OMPI_MCA_orte_abort_on_non_zero_status=0"});
    INFO("launcher aborts: " << launcher_aborts << " -> exit " << o.exit_code << ": " << o.err);
    CHECK(!o.timed_out);  // no rank left waiting for rank 0
    CHECK(o.exit_code == (launcher_aborts ? 2 : 0));
    CHECK(o.program_lines() == 1);
    CHECK(o.err.find("is in use by another run") != std::string::npos);
    CHECK(snapshot(out) == before);
  }
  kill(first.pid, SIGCONT);
  CHECK(finish(first, {}).exit_code == 0);
  CHECK(temporaries(out).empty());
  fs::remove_all(base);
}
TEST_CASE("probe (MPI): a commit that fails on rank 0 ends the job with one line and the old outputs", "[probe][mpi]") {
  // rank 1 has returned and waits in MPI_Finalize for rank 0, which fails alone: it ends the job (MPI_Abort)
  const auto& [program, ok] = mpi_programs[1];
  const auto base = fresh_dir("probe-mpi-fail");
  const auto out = base / "out";
  REQUIRE(spawn(program, plus(split(ok), {"--out", out.string()}), base).exit_code == 0);
  const auto before = snapshot(out);
  Options opt;
  opt.seconds = 120;
  const auto o = finish(start_mpi(program, plus(longer(split(ok)), {"--out", out.string()}), base, "fail-move=2"), opt);
  INFO("exit " << o.exit_code << ": " << o.err);
  CHECK(!o.timed_out);
  CHECK(o.exit_code == 1);
  CHECK(o.program_lines() == 1);
  CHECK(o.err.find("Input/output error (the previous outputs are unchanged)") != std::string::npos);
  CHECK(snapshot(out) == before);
  CHECK(temporaries(out).empty());
  fs::remove_all(base);
}
#endif
