#include "geomint/io.hpp"

#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <climits>
#include <fcntl.h>
#include <stdexcept>
#include <system_error>
#include <unistd.h>

#include "created_folders.hpp"
#include "geomint/error.hpp"
#include "geomint/text.hpp"
#include "geomint/sweep.hpp"

namespace geomint {

std::string format_number(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[40];
  // 15 significant digits: the same bits give the same text, and the files stay readable.
  std::snprintf(buf, sizeof buf, "%.15g", v);
  return buf;
}

// The mark of a computed non-finite cell: a control character no number or name contains.
constexpr char not_finite_mark = '\x01';

std::string format_cell(double v) {
  if (std::isfinite(v) || is_missing(v)) return format_number(v);
  return not_finite_mark + format_number(v);
}

std::string format_list(const std::vector<double>& v) {
  std::string s;
  for (double x : v) s += (s.empty() ? "" : ",") + format_number(x);
  return s;
}

std::string join_names(const std::vector<std::string>& names, const char* sep) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : sep) + n;
  return s;
}

namespace fs = std::filesystem;

namespace {
// Room kept under PATH_MAX for what goes inside an output folder: "/.geomint-run-<pid>-<n>/" and a file name of up
// to 200 characters (the longest the programs write are under 80).
constexpr std::size_t output_name_room = 256;
}  // namespace

fs::path output_path_for_reading(const fs::path& final_path) {
  if (OutputRun* r = OutputRun::current()) {
    const fs::path s = r->staged(final_path);
    std::error_code ec;
    if (s != final_path && fs::exists(s, ec)) return s;
  }
  return final_path;
}

fs::path prepare_output_dir(const std::string& dir, OtherRanks others) {
  const int rank = Sweep::launcher_rank();
  if (rank != 0 && others == OtherRanks::leave) throw OtherRankDone{};
  // Rank 0 prepares the folder; the other ranks of a sweep learn its outcome ("" or the message) and meet it
  // together, so none waits in a collective for a rank that has left.
  std::string failure;
  if (rank == 0) try {
      require(!dir.empty(), "output folder must not be empty");
      std::error_code ec;
      // Every file goes into a staging folder inside it first: a path that leaves no room for those names would
      // fail half-way through the outputs (PATH_MAX counts the whole path).
      const std::size_t length = fs::absolute(fs::path(dir), ec).string().size();
      require(length + output_name_room < PATH_MAX,
              "output folder path is " + std::to_string(length) + " characters long: with the staging folder and file "
              "names inside it, paths would pass the system's limit of " + std::to_string(PATH_MAX) + " (choose a shorter --out)");
      ec.clear();
      require(!(fs::is_symlink(fs::symlink_status(dir, ec)) && !fs::exists(dir, ec)),
              "output folder '" + dir + "' is a symbolic link to a missing target");
      ec.clear();
      detail::note_created_folders(fs::path(dir), detail::first_missing_folder(fs::path(dir)));
      fs::create_directories(dir, ec);
      require(!ec && fs::is_directory(dir), "cannot create output folder '" + dir + "'" + (ec ? ": " + ec.message() : ""));
      OutputRun::start(fs::path(dir));
    } catch (const std::exception& e) {
      detail::remove_created_folders();  // a folder that cannot be a run's is not left behind
      failure = e.what();
      if (failure.empty()) failure = "cannot prepare output folder '" + dir + "'";
    }
  if (others == OtherRanks::compute) failure = Sweep::world().broadcast(failure);
  if (!failure.empty()) throw OutputFolderRefused(failure);
  return fs::path(dir);
}

AtomicFile::AtomicFile(fs::path final_path) : final_(std::move(final_path)) {
  require_output_rank(final_);
  OutputRun* run = OutputRun::current();
  staged_ = run && run->owns(final_);
  int fd = -1;
  if (staged_) {
    fd = run->create_part(final_, part_);
    tmp_ = run->staging() / part_;
  } else {
    // A fresh name beside the target, created exclusively: nothing planted under it is written through.
    static std::atomic<unsigned long> count{0};
    const fs::path parent = final_.parent_path().empty() ? fs::path(".") : final_.parent_path();
    for (int attempt = 0; attempt < 100 && fd < 0; ++attempt) {
      tmp_ = parent / (".geomint-tmp-" + std::to_string(::getpid()) + "-" + std::to_string(count++) + "-" +
                       final_.filename().string());
      fd = ::open(tmp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
      if (fd < 0 && errno != EEXIST) break;
    }
    require(fd >= 0, "cannot write '" + final_.string() + "': " + std::strerror(errno));
  }
  f_ = ::fdopen(fd, "w");  // close-on-exec (above): gnuplot does not inherit our open tables
  if (!f_) {
    const int e = errno;
    ::close(fd);
    ::unlink(tmp_.c_str());
    throw std::runtime_error("cannot write '" + final_.string() + "': " + std::strerror(e));
  }
}

AtomicFile::~AtomicFile() {
  if (f_) {
    std::fclose(f_);
    std::error_code ec;
    fs::remove(tmp_, ec);
  }
}

void AtomicFile::commit() {
  if (!f_) return;
  bool ok = std::fflush(f_) == 0 && !std::ferror(f_);
  const int err = ok ? 0 : errno;
  const bool closed = std::fclose(f_) == 0;
  const int close_err = errno;
  f_ = nullptr;
  std::error_code ec;
  if (!ok || !closed) {
    fs::remove(tmp_, ec);
    throw std::runtime_error("cannot write '" + final_.string() + "': " + std::strerror(!ok ? err : close_err) +
                             " (the previous file is unchanged)");
  }
  if (staged_) {
    OutputRun* run = OutputRun::current();
    if (!run) throw std::runtime_error("cannot write '" + final_.string() + "': its run has ended");
    run->place(part_, final_);
    return;
  }
  fs::rename(tmp_, final_, ec);
  if (ec) {
    std::error_code ec2;
    fs::remove(tmp_, ec2);
    throw std::runtime_error("cannot rename '" + tmp_.string() + "' to '" + final_.string() + "': " + ec.message());
  }
}

TsvWriter::TsvWriter(const fs::path& path, const std::string& program, const Params& params,
                     std::vector<std::string> columns)
    : file_(path), name_(path.filename().string()), columns_(std::move(columns)) {
  std::FILE* f = file_.handle();
  std::fprintf(f, "# program: %s\n# git: %s\n", one_line(program).c_str(), git_revision());
  // One line per entry whatever it holds: a --system-file path with a newline in it would start a line of its own
  // (a row to a reader), a control byte would act on the terminal that shows the file.
  for (const auto& [k, v] : params) std::fprintf(f, "# %s: %s\n", one_line(k).c_str(), one_line(v).c_str());
  write_row(columns_);
  rows_ = 0;
}

void TsvWriter::write_row(const std::vector<std::string>& cells) {
  require(cells.size() == columns_.size(), "TsvWriter: row has " + std::to_string(cells.size()) +
                                              " cells, expected " + std::to_string(columns_.size()));
  ++rows_;
  for (std::size_t i = 0; i < cells.size(); ++i)
    if (!cells[i].empty() && cells[i][0] == not_finite_mark)
      throw NumericalFailure::in_output(name_ + ", row " + std::to_string(rows_) + ", column " + columns_[i],
                                        "the value computed from these parameters is " + cells[i].substr(1) +
                                            " (beyond double precision, or undefined), which a table does not hold");
  std::FILE* f = file_.handle();
  for (size_t i = 0; i < cells.size(); ++i) {
    std::fputs(cells[i].c_str(), f);
    std::fputc(i + 1 < cells.size() ? '\t' : '\n', f);
  }
}

}  // namespace geomint
