#pragma once
// Output: tidy TSV files with a '#' header (program, parameters, git revision). Every output of a run (tables
// and figures) is written into one staging folder beside the target, <out>/.geomint-run-XXXXXX, and moved into
// place together when the run succeeds (OutputRun): an interrupt, a full disk or an error leaves the previous
// outputs as they were and no temporary behind.
#include <cstdio>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace geomint {

const char* git_revision();

using Params = std::vector<std::pair<std::string, std::string>>;

std::string format_number(double v);  // shortest round-trip form, "nan" for NaN
std::string format_list(const std::vector<double>& v);

// Creates `dir` if needed, checks that a file can be written there (throws InputError otherwise) and starts
// the run's OutputRun there (on MPI rank 0 only: the other ranks write nothing).
std::filesystem::path prepare_output_dir(const std::string& dir);

// The outputs of one run, all new or all old. Started by prepare_output_dir; guarded_main commits it when the
// program's body returns 0 and discards it otherwise. While a run is active:
// - files written through AtomicFile/TsvWriter/Figure::draw whose folder is the run's target go into the
//   staging folder under their final file name, and are moved into the target by commit();
// - SIGINT and SIGTERM remove the staging folder (and stop a gnuplot started for it) and exit with 128 + signal;
//   during commit() they are blocked, so the commit loop is never cut short by them.
// - an exit without commit (exception, exit(), nonzero status) removes the staging folder.
class OutputRun {
 public:
  static OutputRun* current();  // the active run of this process, or nullptr
  // Starts the run for target (an existing folder); replaces (discards) an earlier uncommitted run.
  static OutputRun& start(const std::filesystem::path& target);

  const std::filesystem::path& target() const { return target_; }
  const std::filesystem::path& staging() const { return staging_; }
  // Where the file that will end as final_path is written now: staging/<name> when final_path is in the
  // target folder, final_path itself otherwise (then it is not part of the run).
  std::filesystem::path staged(const std::filesystem::path& final_path) const;
  bool owns(const std::filesystem::path& final_path) const;
  // Records that staging/<name of final_path> is complete and goes to final_path at commit.
  void add(const std::filesystem::path& final_path);
  // Moves every complete file into place (SIGINT/SIGTERM blocked meanwhile) and removes the staging folder.
  // Throws on the first rename that fails, after removing the staging folder.
  void commit();
  // Removes the staging folder and everything in it; the target is untouched.
  void discard();
  // A helper process (gnuplot) writing into the staging folder, stopped by the signal handler: pid > 0 when it
  // starts, -pid when it has ended (several may run at once).
  static void set_helper(long pid);

 private:
  OutputRun() = default;
  std::filesystem::path target_, staging_;
  std::vector<std::string> names_;  // complete files, in the order they were added
};

// Resolves a path a program reads back (a table it just wrote): the staged file while the run is active.
std::filesystem::path output_path_for_reading(const std::filesystem::path& final_path);

// Writes `final_path` completely or not at all: into the run's staging folder (see OutputRun) when final_path
// is in the run's target, otherwise via `final_path.tmp` + rename. Every write is checked: a full disk or an
// I/O error is an error (std::runtime_error naming the file), never a truncated file under the final name.
class AtomicFile {
 public:
  explicit AtomicFile(std::filesystem::path final_path);
  ~AtomicFile();  // removes the temporary file if commit() was not reached
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  std::FILE* handle() { return f_; }
  const std::filesystem::path& temp_path() const { return tmp_; }
  void commit();

 private:
  std::filesystem::path final_, tmp_;
  std::FILE* f_ = nullptr;
  bool staged_ = false;
};

class TsvWriter {
 public:
  TsvWriter(const std::filesystem::path& path, const std::string& program, const Params& params,
            std::vector<std::string> columns);
  template <class... Values>
  void row(const Values&... values) {
    static_assert(sizeof...(Values) > 0);
    std::vector<std::string> cells{cell(values)...};
    write_row(cells);
  }
  void write_row(const std::vector<std::string>& cells);
  void commit() { file_.commit(); }

 private:
  static std::string cell(const std::string& s) { return s; }
  static std::string cell(const char* s) { return s; }
  static std::string cell(double v) { return format_number(v); }
  static std::string cell(int v) { return std::to_string(v); }
  static std::string cell(long v) { return std::to_string(v); }
  AtomicFile file_;
  std::size_t ncols_;
};

}  // namespace geomint
