// Sweeps across processes (core/include/geomint/sweep.hpp) and the progress line (progress.hpp).
// The MPI test runs the sweep programs under `mpiexec -n 2` on this machine and compares every data file
// byte for byte with the single-process run.
#include <catch2/catch.hpp>

#include <algorithm>

#include <cstring>

#include <cstdlib>
#include <fstream>
#include <numeric>

#include "geomint/foucault_ensemble.hpp"
#include "geomint/error.hpp"
#include "geomint/parallel.hpp"
#include "geomint/sweep.hpp"
#include "helpers.hpp"

using namespace geomint;
using namespace geomint::testing;

namespace {

// Every data file of `a` exists in `b` with the same bytes; returns how many were compared.
int compare_tsvs(const std::filesystem::path& a, const std::filesystem::path& b) {
  int n = 0;
  for (const auto& e : std::filesystem::directory_iterator(a)) {
    if (e.path().extension() != ".tsv") continue;
    INFO(e.path().filename());
    const std::string sa = read_bytes(e.path()), sb = read_bytes(b / e.path().filename());
    CHECK(!sa.empty());
    CHECK(sa == sb);
    ++n;
  }
  return n;
}

}  // namespace

TEST_CASE("a sweep's shares cover every item once, in rank order, with about equal cost", "[sweep]") {
  std::vector<double> cost;
  for (int i = 0; i < 1000; ++i) cost.push_back(i < 100 ? 20.0 : 1.0);  // expensive items first, as in the sweeps
  const double total = std::accumulate(cost.begin(), cost.end(), 0.0);
  for (int size : {1, 2, 3, 7, 64}) {
    std::size_t next = 0;
    double worst = 0;
    for (int r = 0; r < size; ++r) {
      const auto [first, last] = Sweep::share_of(r, size, cost.size(), cost);
      CHECK(first == next);
      CHECK(last >= first);
      next = last;
      worst = std::max(worst, std::accumulate(cost.begin() + static_cast<long>(first), cost.begin() + static_cast<long>(last), 0.0));
    }
    CHECK(next == cost.size());
    CHECK(worst <= total / size + 20);  // within one item of an equal split
  }
  // more ranks than items: some get nothing, none overlaps
  std::size_t covered = 0;
  for (int r = 0; r < 8; ++r) {
    const auto [first, last] = Sweep::share_of(r, 8, 3);
    covered += last - first;
  }
  CHECK(covered == 3);
  // a single process computes everything, without packing
  const auto& w = Sweep::world();
  CHECK(w.size() == 1);
  const auto all = w.map<int>(
      5, {}, [](std::size_t a, std::size_t b) { return std::vector<int>(b - a, 7); },
      [](int) -> std::string { throw std::logic_error("a single process must not pack"); },
      [](const std::string&) -> int { throw std::logic_error("a single process must not unpack"); });
  CHECK(all.size() == 5);
}

TEST_CASE("parallel_for runs every item exactly once on any thread count, and rethrows a failure", "[sweep]") {
  for (unsigned threads : {1u, 2u, 3u, 8u}) {
    std::vector<int> hits(1000, 0);
    parallel_for(hits.size(), threads, [&](std::size_t i) { hits[i] += 1; });
    CHECK(std::count(hits.begin(), hits.end(), 1) == 1000);
    CHECK_THROWS_WITH(parallel_for(100, threads, [](std::size_t i) {
                        if (i == 37) throw NumericalFailure(7, "test", "item 37");
                      }),
                      Catch::Contains("item 37"));
  }
}

TEST_CASE("rows pack and unpack bit-exactly, and a short row is refused", "[sweep]") {
  systems::FoucaultPendulum base;
  base.T = 200;
  const auto runs = run_anomaly_ensemble(base, anomaly_cases({0.1}, {1e-4}, {"la-nh"}, {systems::Foucault::name}, 5),
                                         0.001, 1);
  long jumps = 0;
  for (const auto& r : runs) {
    jumps += static_cast<long>(r.jumps.size());
    const std::string row = pack(r);
    CHECK(same_bits(unpack_anomaly_run(row), r));
    CHECK_THROWS(unpack_anomaly_run(row.substr(0, row.size() - 1)));
  }
  CHECK(jumps > 0);
}

TEST_CASE("the progress line stays off stderr unless stderr is a terminal", "[sweep][programs]") {
  const auto dir = fresh_dir("progress");
  const std::string args = "--runs 3 --T 100 --h 0.1 --worst 0 --out " + (dir / "out").string();
  const auto quiet = run_program("anomaly_foucault", args);
  CHECK(quiet.exit_code == 0);
  CHECK(quiet.err.empty());
  // under a pseudo-terminal (util-linux `script`) the same run reports its progress
  if (std::system("command -v script > /dev/null 2>&1") == 0) {
    const std::string cmd = "script -qec '" + std::string(GEOMINT_BIN_DIR) + "/anomaly_foucault " + args +
                            " > /dev/null' /dev/null > " + (dir / "tty.txt").string() + " 2>&1";
    REQUIRE(std::system(cmd.c_str()) == 0);
    const std::string tty = read_bytes(dir / "tty.txt");
    INFO(tty);
    CHECK(tty.find("anomaly_foucault: 24/24 runs (100%)") != std::string::npos);
    CHECK(tty.find("left") != std::string::npos);
  }
  std::filesystem::remove_all(dir);
}

TEST_CASE("sweep programs under mpiexec -n 2 write byte-identical files", "[sweep][mpi][programs]") {
#ifndef GEOMINT_MPIEXEC
  WARN("built without MPI: the sweep programs run as one process (nothing to compare)");
#else
  // Open MPI refuses root without these (CI runs as root) and, on a 2-core machine, may count too few slots;
  // the variables are Open MPI's own and ignored by other MPI implementations.
  // Under the sanitizer build (make sanitize) LeakSanitizer is off for the mpiexec run only: Open MPI leaves its
  // own allocations at MPI_Finalize, in plugins it has already unloaded, so they can be neither attributed nor
  // suppressed by library name. AddressSanitizer and UBSan stay on for it, and the single-process run of the same
  // program just before keeps leak checking.
  const std::string env =
      "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1 "
      "ASAN_OPTIONS=detect_leaks=0 ";
  const auto dir = fresh_dir("mpi");
  struct Case {
    const char* program;
    const char* args;
    int files;
  };
  for (const Case& c : {Case{"anomaly_foucault", "--runs 70 --T 400 --h 0.1 0.05 --worst 1 --threads 1", 4},
                        Case{"stability", "--n 24", 2},
                        Case{"stability", "--system coupled-oscillators --n 8", 1},
                        Case{"convergence", "--system pendulum --alpha 0.1 0.2 --h-min 0.02", 2},
                        Case{"modified_agreement", "--systems pendulum --schemes la contact --orders 0 1 --T 1", 2},
                        Case{"ensemble", "--system knife-edge --runs 30 --T 5 --threads 1", 2}}) {
    const std::string tag = std::string(c.program) + "-" + std::to_string(std::strlen(c.args));  // one folder per case
    const auto one = dir / (tag + "-1"), two = dir / (tag + "-2");
    REQUIRE(run_program(c.program, std::string(c.args) + " --out " + one.string()).exit_code == 0);
    const std::string cmd = env + GEOMINT_MPIEXEC + " -n 2 " + GEOMINT_BIN_DIR + "/" + c.program + " " + c.args +
                            " --out " + two.string() + " > " + (dir / "mpi.txt").string() + " 2>&1";
    const int status = std::system(cmd.c_str());
    INFO(c.program << ": " << read_bytes(dir / "mpi.txt"));
    REQUIRE(status == 0);
    CHECK(compare_tsvs(one, two) == c.files);
    // only rank 0 writes: one run, committed, no staging folder of another rank left behind
    for (const auto& e : std::filesystem::directory_iterator(two)) {
      INFO(e.path());
      CHECK(e.path().filename().string().rfind(".geomint-", 0) != 0);
    }
  }
  std::filesystem::remove_all(dir);
#endif
}
