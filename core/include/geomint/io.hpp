#pragma once
// Output: tidy TSV files with a '#' header (program, parameters, git revision). Every output of a run (tables
// and figures) is written into one staging folder beside the target, <out>/.geomint-run-XXXXXX, and moved into
// place together when the run succeeds (OutputRun, output_run.hpp): an interrupt, a full disk, an error or a
// killed run leaves the previous outputs (the next run heals a killed one) and no temporary behind.
#include <cstdio>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "geomint/error.hpp"
#include "geomint/output_run.hpp"

namespace geomint {

const char* git_revision();

using Params = std::vector<std::pair<std::string, std::string>>;

std::string format_number(double v);  // shortest round-trip form, "nan" for NaN
// A number as a table cell: format_number, where a nan that is not missing_value, or an inf, is marked so that
// TsvWriter::write_row refuses the row (a table holds no value computed as nan or inf, see missing_value).
std::string format_cell(double v);
std::string format_list(const std::vector<double>& v);
// "a b c" (or "a, b, c" with sep ", "): a list of names for an output header or a message.
std::string join_names(const std::vector<std::string>& names, const char* sep = " ");

// Under an MPI launcher, what the ranks other than 0 do at prepare_output_dir. Rank 0 alone writes, either way.
enum class OtherRanks {
  leave,    // a program that does not split its work: the other ranks end here, at once and silently (exit 0)
  compute,  // a sweep program (Sweep::map): every rank goes on, and all agree on the folder's outcome
};

// Thrown on the other ranks by prepare_output_dir(dir, OtherRanks::leave); guarded_main ends them with status 0.
// Not a std::exception, so no handler of errors mistakes it for one.
struct OtherRankDone {};

// prepare_output_dir's refusal, met by every rank of a sweep together (rank 0's outcome, broadcast): guarded_main
// lets the ranks end normally instead of aborting the others.
struct OutputFolderRefused : InputError {
  using InputError::InputError;
};

// Creates `dir` if needed and starts the run's OutputRun there (output_run.hpp: lock, healing, staging folder),
// throwing InputError when it cannot (the staging folder is the write probe). Only MPI rank 0 does; see OtherRanks
// for the others.
std::filesystem::path prepare_output_dir(const std::string& dir, OtherRanks others = OtherRanks::leave);

// Resolves a path a program reads back (a table it just wrote): the staged file while the run is active.
std::filesystem::path output_path_for_reading(const std::filesystem::path& final_path);

// Writes `final_path` completely or not at all: into the run's staging folder (see OutputRun) when final_path
// is in the run's target, otherwise into a fresh temporary beside it (.geomint-tmp-*) renamed over it at commit.
// Either file is created with O_EXCL|O_NOFOLLOW: a symlink planted under its name is never followed. Every write
// is checked: a full disk or an I/O error is an error (std::runtime_error naming the file), never a truncated
// file under the final name. Only MPI rank 0 writes (std::logic_error on another rank).
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
  std::string part_;  // the file's name in the staging folder (staged files)
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
  // Cells of numbers come from format_cell: a row with a computed nan or inf is a numerical failure naming the
  // file, the row and the column, and the run's outputs stay as they were.
  void write_row(const std::vector<std::string>& cells);
  void commit() { file_.commit(); }

 private:
  static std::string cell(const std::string& s) { return s; }
  static std::string cell(const char* s) { return s; }
  static std::string cell(double v) { return format_cell(v); }
  static std::string cell(int v) { return std::to_string(v); }
  static std::string cell(long v) { return std::to_string(v); }
  AtomicFile file_;
  std::string name_;
  std::vector<std::string> columns_;
  long rows_ = 0;
};

}  // namespace geomint
