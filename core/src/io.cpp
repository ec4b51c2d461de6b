#include "geomint/io.hpp"

#include <cmath>
#include <fstream>
#include <system_error>

#include "geomint/error.hpp"

namespace geomint {

std::string format_number(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[40];
  // 15 significant digits: the same bits give the same text, and the files stay readable.
  std::snprintf(buf, sizeof buf, "%.15g", v);
  return buf;
}

std::string format_list(const std::vector<double>& v) {
  std::string s;
  for (double x : v) s += (s.empty() ? "" : ",") + format_number(x);
  return s;
}

std::filesystem::path prepare_output_dir(const std::string& dir) {
  namespace fs = std::filesystem;
  require(!dir.empty(), "output folder must not be empty");
  std::error_code ec;
  fs::create_directories(dir, ec);
  require(!ec && fs::is_directory(dir), "cannot create output folder '" + dir + "'" + (ec ? ": " + ec.message() : ""));
  const fs::path probe = fs::path(dir) / ".geomint-write-probe.tmp";
  std::FILE* f = std::fopen(probe.c_str(), "w");
  require(f != nullptr, "output folder '" + dir + "' is not writable");
  std::fclose(f);
  fs::remove(probe, ec);
  return fs::path(dir);
}

AtomicFile::AtomicFile(std::filesystem::path final_path) : final_(std::move(final_path)) {
  tmp_ = final_;
  tmp_ += ".tmp";
  f_ = std::fopen(tmp_.c_str(), "w");
  require(f_ != nullptr, "cannot write '" + tmp_.string() + "'");
}

AtomicFile::~AtomicFile() {
  if (f_) {
    std::fclose(f_);
    std::error_code ec;
    std::filesystem::remove(tmp_, ec);
  }
}

void AtomicFile::commit() {
  if (!f_) return;
  const bool ok = std::fflush(f_) == 0 && !std::ferror(f_);
  std::fclose(f_);
  f_ = nullptr;
  std::error_code ec;
  if (!ok) {
    std::filesystem::remove(tmp_, ec);
    throw InputError("write error on '" + tmp_.string() + "'");
  }
  std::filesystem::rename(tmp_, final_, ec);
  require(!ec, "cannot rename '" + tmp_.string() + "' to '" + final_.string() + "': " + ec.message());
}

TsvWriter::TsvWriter(const std::filesystem::path& path, const std::string& program, const Params& params,
                     std::vector<std::string> columns)
    : file_(path), ncols_(columns.size()) {
  std::FILE* f = file_.handle();
  std::fprintf(f, "# program: %s\n# git: %s\n", program.c_str(), git_revision());
  for (const auto& [k, v] : params) std::fprintf(f, "# %s: %s\n", k.c_str(), v.c_str());
  write_row(columns);
}

void TsvWriter::write_row(const std::vector<std::string>& cells) {
  require(cells.size() == ncols_, "TsvWriter: row has " + std::to_string(cells.size()) + " cells, expected " +
                                      std::to_string(ncols_));
  std::FILE* f = file_.handle();
  for (size_t i = 0; i < cells.size(); ++i) {
    std::fputs(cells[i].c_str(), f);
    std::fputc(i + 1 < cells.size() ? '\t' : '\n', f);
  }
}

}  // namespace geomint
