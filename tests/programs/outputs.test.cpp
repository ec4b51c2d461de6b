// The output machinery at the level of the shared code: OutputRun (a run's outputs all new or all old, one run per
// folder, a killed run healed), checked writers that follow no symlink, gnuplot without user text, the command
// line's strictness, and the size checks. tests/programs/probe.test.cpp drives the same through the programs.
#include <catch2/catch.hpp>

#include <climits>
#include <cmath>
#include <limits>
#include <csignal>
#include <fcntl.h>
#include <fstream>
#include <functional>
#include <sstream>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "geomint/budget.hpp"
#include "geomint/cli.hpp"
#include "geomint/error.hpp"
#include "geomint/io.hpp"
#include "geomint/plots/figure.hpp"
#include "geomint/record.hpp"
#include "helpers.hpp"

namespace fs = std::filesystem;
using namespace geomint;
using geomint::testing::fresh_dir;
using geomint::testing::read_bytes;

namespace {
std::size_t entries(const fs::path& d) {
  std::size_t n = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(d)) ++n;
  return n;
}
plots::Figure small_figure() {
  plots::Figure f;
  f.title = "t";
  plots::Panel p;
  p.series.push_back(plots::Series({0, 1, 2}, {1, 2, 3}, "a 'quoted' `title`"));
  f.panels.push_back(p);
  return f;
}
}  // namespace

TEST_CASE("a run's outputs stay staged until commit and replace the old ones together", "[outputs]") {
  const auto dir = fresh_dir("run-commit");
  std::ofstream(dir / "a.tsv") << "old a\n";
  std::ofstream(dir / "b.tsv") << "old b\n";
  OutputRun& run = OutputRun::start(dir);
  {
    AtomicFile a(dir / "a.tsv");
    std::fputs("new a\n", a.handle());
    a.commit();
    AtomicFile b(dir / "b.tsv");
    std::fputs("new b\n", b.handle());
    b.commit();
  }
  // committed files are staged, the old ones untouched; a program reads its own new table back
  CHECK(read_bytes(dir / "a.tsv") == "old a\n");
  CHECK(read_bytes(output_path_for_reading(dir / "a.tsv")) == "new a\n");
  CHECK(fs::exists(run.staging()));
  run.commit();
  CHECK(read_bytes(dir / "a.tsv") == "new a\n");
  CHECK(read_bytes(dir / "b.tsv") == "new b\n");
  CHECK(entries(dir) == 2);  // no staging folder left
  CHECK(OutputRun::current() == nullptr);
}

TEST_CASE("a discarded run leaves the old outputs and no temporary", "[outputs]") {
  const auto dir = fresh_dir("run-discard");
  std::ofstream(dir / "a.tsv") << "old a\n";
  OutputRun& run = OutputRun::start(dir);
  {
    TsvWriter t(dir / "a.tsv", "test", {}, {"x"});
    t.row(1.0);
    t.commit();
    AtomicFile never(dir / "c.tsv");  // not committed: removed by its destructor
  }
  run.discard();
  CHECK(read_bytes(dir / "a.tsv") == "old a\n");
  CHECK(entries(dir) == 1);
}

TEST_CASE("a table writes a missing value as nan and refuses a value computed as nan or inf", "[outputs]") {
  // The missing value survives the arithmetic a program does on it (a difference, a ratio, a logarithm); a nan
  // made by the arithmetic itself (0/0, the root of a negative number) and an overflow are not missing values.
  volatile double zero = 0, big = 1e308;
  CHECK(is_missing(missing_value));
  CHECK(is_missing(-missing_value));
  CHECK(is_missing(std::log10(std::abs(missing_value - 1.0) / 3.0)));
  CHECK(is_missing(missing_value * big));
  CHECK_FALSE(is_missing(zero / zero));
  CHECK_FALSE(is_missing(std::sqrt(zero - 1)));
  CHECK_FALSE(is_missing(std::numeric_limits<double>::quiet_NaN()));
  CHECK_FALSE(is_missing(1.0));

  const auto dir = fresh_dir("table-not-finite");
  std::ofstream(dir / "a.tsv") << "old a\n";
  OutputRun& run = OutputRun::start(dir);
  {
    TsvWriter t(dir / "a.tsv", "test", {}, {"h", "err"});
    t.row(0.1, missing_value);
    t.row(0.2, 2 * missing_value);
    CHECK_THROWS_WITH(t.row(0.3, zero / zero),
                      Catch::Contains("numerical failure in a.tsv, row 3, column err") && Catch::Contains("is nan"));
    CHECK_THROWS_WITH(t.row(0.4, big * 10), Catch::Contains("a.tsv, row 4, column err") && Catch::Contains("is inf"));
    CHECK_THROWS_WITH(t.write_row({format_cell(-big * 10), "1"}), Catch::Contains("row 5, column h") && Catch::Contains("is -inf"));
    t.row(0.5, 1.0);
    t.commit();
  }
  run.commit();
  const std::string text = read_bytes(dir / "a.tsv");
  CHECK(text.find("0.1\tnan\n0.2\tnan\n0.5\t1\n") != std::string::npos);
  CHECK(text.find("inf") == std::string::npos);
}

TEST_CASE("a write error is an error, never a truncated file", "[outputs]") {
  // A file size limit of 16 bytes (with SIGXFSZ ignored, a write beyond it fails with EFBIG): a full disk for the
  // files this process writes, inside a run and outside one.
  const auto dir = fresh_dir("write-error");
  std::ofstream(dir / "x.tsv") << "old\n";
  std::ofstream(dir / "y.tsv") << "old\n";
  struct sigaction ignore {}, old_action {};
  ignore.sa_handler = SIG_IGN;
  sigaction(SIGXFSZ, &ignore, &old_action);
  rlimit old_limit {};
  getrlimit(RLIMIT_FSIZE, &old_limit);
  rlimit limit = old_limit;
  limit.rlim_cur = 16;
  setrlimit(RLIMIT_FSIZE, &limit);
  auto failure = [](const fs::path& p) {  // what writing 100 bytes to p says
    AtomicFile f(p);
    std::fputs(std::string(100, 'n').c_str(), f.handle());
    try {
      f.commit();
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const std::string outside = failure(dir / "x.tsv");
  OutputRun& run = OutputRun::start(dir);
  const std::string inside = failure(dir / "y.tsv");
  setrlimit(RLIMIT_FSIZE, &old_limit);
  sigaction(SIGXFSZ, &old_action, nullptr);
  run.discard();
  CHECK_THAT(outside, Catch::Contains("File too large") && Catch::Contains("previous file is unchanged"));
  CHECK_THAT(inside, Catch::Contains("File too large"));
  CHECK(read_bytes(dir / "x.tsv") == "old\n");
  CHECK(read_bytes(dir / "y.tsv") == "old\n");
  CHECK(entries(dir) == 2);  // no temporary, no staging folder, no lock
}

TEST_CASE("a file written outside a run replaces a symlink in its place and never writes through it", "[outputs]") {
  const auto base = fresh_dir("atomic-symlink");
  std::ofstream(base / "victim.txt") << "victim\n";
  fs::create_directories(base / "d");
  fs::create_symlink("../victim.txt", base / "d" / "x.tsv");
  AtomicFile f(base / "d" / "x.tsv");
  CHECK(f.temp_path().filename().string().rfind(".geomint-tmp-", 0) == 0);  // a fresh name, created exclusively
  std::fputs("new\n", f.handle());
  f.commit();
  CHECK(read_bytes(base / "victim.txt") == "victim\n");
  CHECK(!fs::is_symlink(base / "d" / "x.tsv"));
  CHECK(read_bytes(base / "d" / "x.tsv") == "new\n");
  CHECK(entries(base / "d") == 1);
}

namespace {
// What `body` writes on stderr (file descriptor 2), as the programs' one-line notes are written.
std::string stderr_of(const std::function<void()>& body) {
  const auto file = fresh_dir("stderr-capture") / "err.txt";
  std::fflush(stderr);
  const int saved = dup(2);
  const int fd = open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  dup2(fd, 2);
  close(fd);
  body();
  dup2(saved, 2);
  close(saved);
  return read_bytes(file);
}
}  // namespace

TEST_CASE("one run per output folder: a second one is refused while the first holds the folder", "[outputs]") {
  const auto dir = fresh_dir("run-lock");
  int to_child[2], to_parent[2];
  REQUIRE(pipe(to_child) == 0);
  REQUIRE(pipe(to_parent) == 0);
  const pid_t child = fork();
  REQUIRE(child >= 0);
  if (child == 0) {  // the first run: takes the folder, says so, waits, ends cleanly
    char c = 0;
    try {
      OutputRun& run = OutputRun::start(dir);
      c = 'L';
      if (write(to_parent[1], &c, 1) != 1) _exit(3);
      if (read(to_child[0], &c, 1) != 1) _exit(3);
      run.discard();
      _exit(0);
    } catch (...) {
      _exit(4);
    }
  }
  char c = 0;
  REQUIRE(read(to_parent[0], &c, 1) == 1);
  REQUIRE(c == 'L');
  const auto before = entries(dir);  // the child's staging folder and lock file
  CHECK(before == 2);
  CHECK_THROWS_WITH(OutputRun::start(dir), Catch::Contains("is in use by another run (process " + std::to_string(child)) &&
                                               Catch::Contains("choose another --out"));
  CHECK(entries(dir) == before);
  CHECK(OutputRun::current() == nullptr);
  REQUIRE(write(to_child[1], &c, 1) == 1);
  int status = 0;
  waitpid(child, &status, 0);
  CHECK(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 0);
  CHECK(entries(dir) == 0);  // the first run ended: its lock file went with it
  OutputRun& run = OutputRun::start(dir);  // and the folder is free
  CHECK(entries(dir) == 2);
  run.discard();
  CHECK(entries(dir) == 0);
}

TEST_CASE("a killed run's staging folder is removed by the next run into the folder, which says so", "[outputs]") {
  const auto dir = fresh_dir("run-killed");
  std::ofstream(dir / "a.tsv") << "old a\n";
  const pid_t child = fork();
  REQUIRE(child >= 0);
  if (child == 0) {  // a run that stages a new a.tsv and dies without committing
    OutputRun::start(dir);
    AtomicFile f(dir / "a.tsv");
    std::fputs("new a\n", f.handle());
    f.commit();
    raise(SIGKILL);
    _exit(0);
  }
  int status = 0;
  waitpid(child, &status, 0);
  REQUIRE(WIFSIGNALED(status));
  CHECK(entries(dir) == 3);  // a.tsv, the staging folder, the (unlocked) lock file
  std::string note = stderr_of([&] { OutputRun::start(dir); });
  CHECK_THAT(note, Catch::Contains("output folder '" + dir.string() +
                                   "': removed the staging folder of a run that ended without committing"));
  CHECK(std::count(note.begin(), note.end(), '\n') == 1);
  CHECK(entries(dir) == 3);  // a.tsv, this run's staging folder and lock
  OutputRun::current()->discard();
  CHECK(read_bytes(dir / "a.tsv") == "old a\n");
  CHECK(entries(dir) == 1);
}

TEST_CASE("figures are drawn into hostile paths without gnuplot seeing them", "[outputs]") {
  const auto base = fresh_dir("figure-hostile");
  const fs::path dir = base / "-d 'q\" `touch BT` $(touch DS) \"; system \"touch SY\n x";
  fs::create_directories(dir);
  small_figure().draw(dir / "fig");
  CHECK(fs::file_size(dir / "fig.png") > 0);
  CHECK(fs::file_size(dir / "fig.pdf") > 0);
  CHECK(entries(dir) == 2);  // no temporaries
  CHECK(entries(base) == 1);  // nothing else created (BT, DS, SY)
}

TEST_CASE("a figure gnuplot cannot draw is an error with gnuplot's message, the old figure stays", "[outputs]") {
  const auto dir = fresh_dir("figure-error");
  std::ofstream(dir / "fig.png") << "old";
  auto f = small_figure();
  f.panels[0].setup = "set nosuchcommand";
  CHECK_THROWS_WITH(f.draw(dir / "fig"), Catch::Contains("gnuplot failed") && Catch::Contains("nosuchcommand"));
  CHECK(read_bytes(dir / "fig.png") == "old");
  CHECK(entries(dir) == 1);
}

TEST_CASE("a panel with no finite data says so instead of failing", "[outputs]") {
  const auto dir = fresh_dir("figure-nodata");
  auto f = small_figure();
  f.panels[0].setup = "set logscale y";
  f.panels[0].series[0].y = {0, 0, std::nan("")};  // zero state on a log axis
  CHECK_NOTHROW(f.draw(dir / "fig"));
  CHECK(fs::exists(dir / "fig.png"));
}

TEST_CASE("step counts beyond a long or the per-run limit are refused", "[outputs]") {
  CHECK_THROWS_WITH(step_count(1e-300, 50), Catch::Contains("do not fit a long"));
  CHECK_THROWS_WITH(step_count(1e-12, 1e3), Catch::Contains("exceed the limit"));
  CHECK(step_count(0.1, 50) == 500);
  CHECK_THROWS_WITH(check_tolerance(1e-20, "tol"), Catch::Contains("below the precision of a double"));
  CHECK_THROWS_WITH(check_memory(1e30, "the table"), Catch::Contains("MB of memory available"));
  set_budget_enabled(true);
  CHECK_THROWS_WITH(plan_steps(2 * step_budget, "the sweep"), Catch::Contains("--no-budget"));
  set_budget_enabled(false);
  CHECK_NOTHROW(plan_steps(2 * step_budget, "the sweep"));
  set_budget_enabled(true);
}

TEST_CASE("the command line refuses stray words and repeated options", "[outputs]") {
  auto parse = [](std::vector<std::string> words) {
    Cli cli("p", "test");
    double h = 0.1;
    cli.options.add_options()("h", po::value(&h), "step");
    std::vector<char*> argv;
    for (auto& w : words) argv.push_back(w.data());
    return cli.parse(static_cast<int>(argv.size()), argv.data());
  };
  CHECK(parse({"p", "--h", "0.2"}));
  CHECK_THROWS_WITH(parse({"p", "--h", "0.2", "0.3"}), Catch::Contains("unexpected argument '0.3'"));
  CHECK_THROWS_WITH(parse({"p", "typo"}), Catch::Contains("unexpected argument 'typo'"));
  CHECK_THROWS_WITH(parse({"p", "--h", "0.2", "--h", "0.3"}), Catch::Contains("given more than once"));
}

TEST_CASE("run_or_missing turns a numerical failure into a missing value", "[outputs]") {
  const double v = run_or_missing(
      "la alpha=1 h=0.1", []() -> double { throw NumericalFailure(7, "state", "non-finite q"); },
      [] { return std::nan(""); });
  CHECK(std::isnan(v));
  CHECK_THROWS_AS(run_or_missing("x", []() -> double { throw InputError("bad"); }, [] { return 0.0; }), InputError);
}

TEST_CASE("a commit that cannot move every file leaves the old outputs and no temporary", "[outputs]") {
  const auto dir = fresh_dir("run-failed-commit");
  std::ofstream(dir / "a.tsv") << "old a\n";
  fs::create_directories(dir / "b.tsv" / "in-the-way");  // a folder where the run's b.tsv must go
  OutputRun& run = OutputRun::start(dir);
  for (const char* n : {"a.tsv", "b.tsv"}) {
    AtomicFile f(dir / n);
    std::fputs("new\n", f.handle());
    f.commit();
  }
  CHECK_THROWS_WITH(run.commit(), Catch::Contains("previous outputs are unchanged"));
  CHECK(read_bytes(dir / "a.tsv") == "old a\n");
  CHECK(fs::is_directory(dir / "b.tsv" / "in-the-way"));
  CHECK(entries(dir) == 2);  // a.tsv and the folder: no staging folder
  CHECK(OutputRun::current() == nullptr);
}
