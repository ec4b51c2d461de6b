#pragma once
// Output: tidy TSV files with a '#' header (program, parameters, git revision), written to a
// temporary name and renamed when complete, so nothing is ever half-written.
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

// Creates `dir` if needed and checks that a file can be written there; throws InputError otherwise.
std::filesystem::path prepare_output_dir(const std::string& dir);

// Writes `final_path` via `final_path.tmp` + rename, so a crash or an interrupt never leaves a
// half-written file under the final name.
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
