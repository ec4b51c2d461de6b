// Issue 10 at the level of the shared code: OutputRun (a run's outputs all new or all old), checked writers,
// gnuplot without user text, the command line's strictness, and the size checks.
#include <catch2/catch.hpp>

#include <climits>
#include <fstream>
#include <sstream>

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

namespace {
std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), {});
}
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
  CHECK(slurp(dir / "a.tsv") == "old a\n");
  CHECK(slurp(output_path_for_reading(dir / "a.tsv")) == "new a\n");
  CHECK(fs::exists(run.staging()));
  run.commit();
  CHECK(slurp(dir / "a.tsv") == "new a\n");
  CHECK(slurp(dir / "b.tsv") == "new b\n");
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
  CHECK(slurp(dir / "a.tsv") == "old a\n");
  CHECK(entries(dir) == 1);
}

TEST_CASE("a write error is an error, never a truncated file", "[outputs]") {
  // /dev/full: every write fails with ENOSPC. Outside a run AtomicFile writes <name>.tmp beside the target,
  // so a symlink from the temporary name to /dev/full is a full disk for this one file.
  const auto dir = fresh_dir("devfull");
  std::ofstream(dir / "x.tsv") << "old\n";
  fs::create_symlink("/dev/full", dir / "x.tsv.tmp");
  AtomicFile f(dir / "x.tsv");
  std::fputs("new\n", f.handle());
  CHECK_THROWS_WITH(f.commit(), Catch::Contains("No space left on device"));
  CHECK(slurp(dir / "x.tsv") == "old\n");
  CHECK(!fs::exists(dir / "x.tsv.tmp"));
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
  CHECK(slurp(dir / "fig.png") == "old");
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
  CHECK(slurp(dir / "a.tsv") == "old a\n");
  CHECK(fs::is_directory(dir / "b.tsv" / "in-the-way"));
  CHECK(entries(dir) == 2);  // a.tsv and the folder: no staging folder
  CHECK(OutputRun::current() == nullptr);
}
