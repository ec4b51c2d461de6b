#pragma once
// The benchmark programs' table (make bench): each case is a Google Benchmark with a fixed number of
// repetitions; the table keeps, per case, the median, minimum and maximum time per unit (step, or
// trajectory-step) over the repetitions, so every ratio is between medians of the same run of the same binary.
// Shared by bench_steps and bench_ensembles (not a program: experiments/*.cpp are).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "geomint/error.hpp"
#include "geomint/io.hpp"

namespace geomint::bench {

class Table {
 public:
  struct Row {
    std::string group, name;
    double units;                 // steps per call
    std::vector<double> seconds;  // per call, one per repetition
    double median = 0, min = 0, max = 0;
    double ns() const { return median / units * 1e9; }
  };

  // Splits argv into Google Benchmark's own flags (--benchmark_*, handed to it) and the program's.
  static std::vector<char*> split_args(int& argc, char** argv) {
    // Repetitions of all cases are interleaved in random order by default, so a slow spell of a shared machine
    // spreads over every case instead of skewing the ratio of two neighbours (flags given later override it).
    static char interleave[] = "--benchmark_enable_random_interleaving=true";
    std::vector<char*> mine{argv[0]}, theirs{argv[0], interleave};
    for (int i = 1; i < argc; ++i) (std::string(argv[i]).rfind("--benchmark_", 0) == 0 ? theirs : mine).push_back(argv[i]);
    int n = static_cast<int>(theirs.size());
    benchmark::Initialize(&n, theirs.data());
    require(n == 1, std::string("unrecognised benchmark flag '") + (n > 1 ? theirs[1] : "") + "'");
    argc = static_cast<int>(mine.size());
    return mine;
  }

  Table(int reps, double min_time) : reps_(reps), min_time_(min_time) {}

  // fn: one call of the case, `units` steps. Registered now, timed by run().
  void add(const std::string& group, const std::string& name, double units, std::function<void()> fn) {
    rows_.push_back({group, name, units, {}});
    benchmark::RegisterBenchmark(name.c_str(), [fn](benchmark::State& st) {
      for (auto _ : st) fn();
    })->Repetitions(reps_)->MinTime(min_time_)->UseRealTime()->Unit(benchmark::kMillisecond);
  }

  void run() {
    Reporter rep(*this);
    benchmark::RunSpecifiedBenchmarks(&rep);
    for (auto& r : rows_) {
      if (r.seconds.empty()) continue;
      std::vector<double> v = r.seconds;
      std::sort(v.begin(), v.end());
      r.median = v.size() % 2 ? v[v.size() / 2] : (v[v.size() / 2 - 1] + v[v.size() / 2]) / 2;
      r.min = v.front();
      r.max = v.back();
    }
  }

  // Median ns per unit of a case by name (NaN if it did not run, e.g. filtered out).
  double ns(const std::string& name) const {
    for (const auto& r : rows_)
      if (r.name == name && !r.seconds.empty()) return r.ns();
    return missing_value;
  }
  const std::vector<Row>& rows() const { return rows_; }

  void write_tsv(const std::filesystem::path& path, const std::string& program, const Params& params) const {
    TsvWriter tsv(path, program, params,
                  {"group", "case", "ns_per_step_median", "ns_per_step_min", "ns_per_step_max", "reps"});
    for (const auto& r : rows_)
      if (!r.seconds.empty())
        tsv.row(r.group, r.name, r.ns(), r.min / r.units * 1e9, r.max / r.units * 1e9,
                static_cast<long>(r.seconds.size()));
    tsv.commit();
  }

 private:
  // Collects every repetition and prints one line per case (median ns per unit, min-max) when it is done.
  class Reporter : public benchmark::BenchmarkReporter {
   public:
    explicit Reporter(Table& t) : t_(t) {}
    bool ReportContext(const Context&) override { return true; }
    void ReportRuns(const std::vector<Run>& runs) override {
      for (const auto& run : runs) {
        if (run.run_type != Run::RT_Iteration || run.error_occurred) continue;
        for (auto& r : t_.rows_)
          if (r.name == run.run_name.function_name) {
            r.seconds.push_back(run.real_accumulated_time / static_cast<double>(run.iterations));
            if (static_cast<long>(r.seconds.size()) == static_cast<long>(run.repetitions)) {
              std::vector<double> v = r.seconds;
              std::sort(v.begin(), v.end());
              std::printf("  %-44s %9.3f ns/step  (min %.3f, max %.3f, %d reps)\n", r.name.c_str(),
                          v[v.size() / 2] / r.units * 1e9, v.front() / r.units * 1e9, v.back() / r.units * 1e9,
                          static_cast<int>(run.repetitions));
              std::fflush(stdout);
            }
          }
      }
    }

   private:
    Table& t_;
  };

  int reps_;
  double min_time_;
  std::vector<Row> rows_;
};

}  // namespace geomint::bench
