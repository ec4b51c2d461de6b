// The probe: a table of bad inputs and faults run against every program in experiments/ (except bench_*),
// asserting the contract of issue 10: exit status, one line on stderr, outputs intact, no temporary left, and
// nothing a user types executed. Programs are started with posix_spawn and an argument vector (no shell), so
// hostile paths reach them byte for byte.
#include <catch2/catch.hpp>

#include <algorithm>
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

namespace {

struct Outcome {
  bool exited = false;
  int exit_code = -1;
  int signal = 0;
  bool stopped = false;  // reached the fault-injection stop (interrupt cases)
  std::string err;
  int lines() const { return static_cast<int>(std::count(err.begin(), err.end(), '\n')); }
  std::string last_line() const {
    std::string e = err;
    while (!e.empty() && e.back() == '\n') e.pop_back();
    const auto p = e.rfind('\n');
    return p == std::string::npos ? e : e.substr(p + 1);
  }
};

// Runs GEOMINT_BIN_DIR/program with args in cwd; stdout discarded, stderr captured. interrupt != 0: the program
// stops itself once its first output is staged (GEOMINT_FAULT_STOP_AFTER_FIRST_OUTPUT), then gets `interrupt`.
Outcome spawn(const std::string& program, const std::vector<std::string>& args, const fs::path& cwd, int interrupt = 0) {
  const fs::path errfile = fresh_dir("probe-stderr") / "err.txt";
  const std::string exe = std::string(GEOMINT_BIN_DIR) + "/" + program;
  std::vector<std::string> words{exe};
  words.insert(words.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  std::vector<std::string> envs;
  for (char** e = environ; *e; ++e) envs.emplace_back(*e);
  if (interrupt) envs.emplace_back("GEOMINT_FAULT_STOP_AFTER_FIRST_OUTPUT=1");
  std::vector<char*> envp;
  for (auto& e : envs) envp.push_back(e.data());
  envp.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addchdir_np(&fa, cwd.c_str());
  posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 2, errfile.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, exe.c_str(), &fa, nullptr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&fa);
  REQUIRE(rc == 0);
  Outcome o;
  int status = 0;
  waitpid(pid, &status, interrupt ? WUNTRACED : 0);
  if (interrupt && WIFSTOPPED(status)) {
    o.stopped = true;
    kill(pid, interrupt);
    kill(pid, SIGCONT);
    waitpid(pid, &status, 0);
  }
  o.exited = WIFEXITED(status);
  o.exit_code = o.exited ? WEXITSTATUS(status) : -1;
  o.signal = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
  std::ifstream in(errfile);
  std::stringstream ss;
  ss << in.rdbuf();
  o.err = ss.str();
  return o;
}

// Every file under dir (hidden ones too) with its bytes.
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> m;
  if (!fs::exists(dir)) return m;
  for (auto it = fs::recursive_directory_iterator(dir); it != fs::recursive_directory_iterator(); ++it) {
    const std::string rel = fs::relative(it->path(), dir).string();
    if (it->is_directory()) {
      m[rel + "/"] = "";
      continue;
    }
    std::ifstream f(it->path(), std::ios::binary);
    m[rel] = std::string((std::istreambuf_iterator<char>(f)), {});
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

const ProgramCase table[] = {
#include "probe_table.inc"
};

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

TEST_CASE("probe: SIGINT and SIGTERM mid-run leave the old outputs and no temporary", "[probe]") {
  for (const auto& c : table)
    for (int sig : {SIGINT, SIGTERM}) {
      const auto base = fresh_dir("probe-interrupt");
      const auto out = base / "out";
      // the old outputs: a complete earlier run
      const auto first = spawn(c.program, plus(split(c.ok), {"--out", out.string()}), base);
      INFO(c.program << " first run -> exit " << first.exit_code << ": " << first.err);
      CHECK(first.exit_code == 0);
      if (first.exit_code != 0) continue;
      const auto before = snapshot(out);
      const auto o = spawn(c.program, plus(split(c.ok), {"--out", out.string(), "--no-budget"}), base, sig);
      INFO(c.program << " signal " << sig << " -> exit " << o.exit_code << ": " << o.err);
      CHECK(o.stopped);
      CHECK(o.exit_code == 128 + sig);
      // one line says so (after any progress lines the program printed before)
      CHECK(o.last_line().find("interrupted by signal " + std::to_string(sig)) != std::string::npos);
      CHECK(o.err.find("interrupted") == o.err.rfind("interrupted"));
      CHECK(temporaries(out).empty());
      CHECK(snapshot(out) == before);
      fs::remove_all(base);
    }
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
        std::ifstream f(e.path());
        const std::string s((std::istreambuf_iterator<char>(f)), {});
        nan = nan || s.find("\tnan") != std::string::npos;
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
  check_refused("convergence_oscillator", {"--h-max", "1e-4", "--h-min", "1e-4", "--T", "1e7"}, "exceed the time budget");
  // --no-budget lifts the time budget only: the per-run limit and the long stay
  check_refused("convergence_oscillator", {"--h-max", "1e-5", "--h-min", "1e-5", "--T", "1e7", "--no-budget"},
                "steps per run");
}

TEST_CASE("probe: tolerances below a double's precision are refused", "[probe]") {
  check_refused("backward_error", {"--tol", "1e-20"}, "below the precision of a double");
  check_refused("convergence_foucault", {"--tol", "1e-20"}, "below the precision of a double");
}

TEST_CASE("probe: degenerate data (a zero state) gives figures, not gnuplot errors", "[probe]") {
  for (const auto& args : {std::vector<std::string>{"fig1_oscillator", "--h", "0.1", "--T", "2", "--q0", "0", "--p0", "0"},
                           std::vector<std::string>{"convergence_oscillator", "--h-max", "0.2", "--h-min", "0.1", "--T", "2",
                                                    "--q0", "0", "--p0", "0"}}) {
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
  check_refused("fig1_oscillator", {"--h", "1e-3", "--T", "1e7", "--ref-factor", "10"}, "MB of memory available");
}
