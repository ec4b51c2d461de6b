#include "geomint/plots/figure.hpp"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <fstream>
#include <spawn.h>
#include <sstream>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gnuplot-iostream.h>

#include "geomint/error.hpp"
#include "geomint/io.hpp"

namespace geomint::plots {

std::size_t TsvTable::column(const std::string& name) const {
  for (std::size_t i = 0; i < columns.size(); ++i)
    if (columns[i] == name) return i;
  throw InputError("TSV has no column '" + name + "'");
}

double TsvTable::number(std::size_t row, const std::string& name) const {
  return std::strtod(rows.at(row).at(column(name)).c_str(), nullptr);
}

const std::string& TsvTable::text(std::size_t row, const std::string& name) const {
  return rows.at(row).at(column(name));
}

std::vector<double> TsvTable::numbers(const std::string& name, const std::function<bool(std::size_t)>& keep) const {
  const std::size_t c = column(name);
  std::vector<double> out;
  for (std::size_t r = 0; r < rows.size(); ++r)
    if (keep(r)) out.push_back(std::strtod(rows[r][c].c_str(), nullptr));
  return out;
}

TsvTable read_tsv(const std::filesystem::path& path) {
  std::ifstream in(output_path_for_reading(path));  // a table of this run is still in its staging folder
  require(static_cast<bool>(in), "cannot read '" + path.string() + "': " + std::strerror(errno));
  TsvTable t;
  std::string line;
  auto split = [](const std::string& s) {
    std::vector<std::string> cells;
    std::stringstream ss(s);
    std::string cell;
    while (std::getline(ss, cell, '\t')) cells.push_back(cell);
    return cells;
  };
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (t.columns.empty())
      t.columns = split(line);
    else
      t.rows.push_back(split(line));
  }
  return t;
}

std::string slope_label(const std::string& name, double slope) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", slope);
  return name + " (slope " + (std::isfinite(slope) ? std::string(buf) : std::string("n/a")) + ")";
}

std::string style_for(const std::string& scheme, const std::string& with) {
  static const std::vector<std::pair<std::string, std::string>> colors = {
      {"la", "#d95f02"},          {"la-printed", "#7570b3"},  {"contact", "#1b9e77"},
      {"leapfrog", "#666666"},    {"leapfrog-ref", "#222222"}, {"contact-sym", "#66a61e"},
      {"la-nh", "#d95f02"},       {"contact-nh", "#1b9e77"},   {"reference", "#222222"},
      {"la-midpoint", "#e7298a"}, {"la-trapezoid", "#666666"}, {"contact-trapezoid", "#66a61e"}};
  for (const auto& [n, c] : colors)
    if (n == scheme) return with + " lw 1.5 lc rgb '" + c + "'";
  return with + " lw 1.5";
}

namespace {

namespace fs = std::filesystem;

// Text for gnuplot as a single-quoted string: no backquote substitution, no macro expansion, no escapes in
// gnuplot's single-quoted strings; a quote is doubled, and line breaks (which would end the command) and NUL
// become spaces. Only program-chosen text reaches gnuplot this way (titles); paths never do.
std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) {
    if (c == '\'')
      q += "''";
    else if (c == '\n' || c == '\r' || c == '\0')
      q += ' ';
    else
      q += c;
  }
  return q + "'";
}

// Points per row of a heat map (x varies fastest, rows of constant y, every row as long).
std::size_t grid_nx(const Series& s) {
  std::size_t nx = 1;
  while (nx < s.y.size() && s.y[nx] == s.y[0]) ++nx;
  if (s.z.size() % nx != 0 || s.x.size() != s.z.size() || s.y.size() != s.z.size())
    throw std::runtime_error("heat map '" + s.title + "' is not a regular grid");
  return nx;
}

// The axes a panel's setup puts on a log scale ("set logscale xy", "set log y", "set logscale" = all).
void log_axes(const std::string& setup, bool& logx, bool& logy) {
  logx = logy = false;
  std::istringstream in(setup);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream words(line);
    std::string set, what, axes;
    words >> set >> what;
    if (set != "set" || what.rfind("log", 0) != 0) continue;
    if (!(words >> axes) || axes.empty() || axes.find_first_not_of("xyzcb2") != std::string::npos) axes = "xy";
    for (char c : axes) {
      if (c == 'x') logx = true;
      if (c == 'y') logy = true;
    }
  }
}

// A line of gnuplot's error output as one line of ours: what gnuplot said, lines joined, echoes dropped.
std::string gnuplot_message(const std::string& text) {
  std::string out;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    const auto b = line.find_first_not_of(" \t^");
    if (b == std::string::npos) continue;
    if (line.rfind("gnuplot>", 0) == 0) line = "in '" + line.substr(line.find_first_not_of(" ", 8)) + "'";  // the command
    else line = line.substr(b);
    out += (out.empty() ? "" : "; ") + line;
  }
  return out.empty() ? "no message" : out;
}

// A file of ours in the folder `dir_fd` (whole, or its last `tail` bytes), "" when it cannot be read.
std::string read_at(int dir_fd, const std::string& name, std::size_t tail = std::string::npos) {
  const int fd = ::openat(dir_fd, name.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) return "";
  struct stat st;
  std::string s;
  if (::fstat(fd, &st) == 0 && st.st_size > 0) {
    const auto size = static_cast<std::size_t>(st.st_size);
    const std::size_t n = std::min(size, tail), from = size - n;
    s.resize(n);
    std::size_t done = 0;
    while (done < n) {
      const ssize_t r = ::pread(fd, s.data() + done, n - done, static_cast<off_t>(from + done));
      if (r < 0 && errno == EINTR) continue;
      if (r <= 0) break;
      done += static_cast<std::size_t>(r);
    }
    s.resize(done);
  }
  ::close(fd);
  return s;
}

// Runs gnuplot in the folder `dir_fd` (its working directory, entered by descriptor; no shell: posix_spawnp),
// the script on its standard input, its standard error captured in a program-named file there (created
// exclusively). Throws with gnuplot's message unless it exits 0. The script goes through a socket written with
// MSG_NOSIGNAL: a gnuplot that died is reported by its status, and raises no SIGPIPE in us, which stays the
// interrupt it is for our own standard output (output_run.hpp).
void run_gnuplot(int dir_fd, const std::string& script, const std::string& errname) {
  int fds[2];
  if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, fds) != 0)
    throw std::runtime_error(std::string("cannot start gnuplot: ") + std::strerror(errno));
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_adddup2(&fa, fds[0], 0);
  posix_spawn_file_actions_addfchdir_np(&fa, dir_fd);
  posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 2, errname.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW, 0600);
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  // gnuplot starts with the default action for every signal we handle (a signal ignored by whoever started us
  // stays ignored for it too), and none blocked.
  sigset_t def, none;
  sigemptyset(&def);
  sigemptyset(&none);
  for (int s : {SIGPIPE, SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGUSR1, SIGUSR2, SIGALRM, SIGXCPU, SIGXFSZ}) {
    struct sigaction old {};
    if (::sigaction(s, nullptr, &old) != 0 || old.sa_handler != SIG_IGN || s == SIGPIPE) sigaddset(&def, s);
  }
  posix_spawnattr_setsigdefault(&attr, &def);
  posix_spawnattr_setsigmask(&attr, &none);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETSIGMASK);
  char arg0[] = "gnuplot";
  char* argv[] = {arg0, nullptr};
  pid_t pid = 0;
  const int rc = posix_spawnp(&pid, "gnuplot", &fa, &attr, argv, environ);
  posix_spawn_file_actions_destroy(&fa);
  posix_spawnattr_destroy(&attr);
  ::close(fds[0]);
  if (rc != 0) {
    ::close(fds[1]);
    throw std::runtime_error(std::string("cannot start gnuplot: ") + std::strerror(rc));
  }
  OutputRun::set_helper(pid);
  const char* p = script.data();
  std::size_t left = script.size();
  while (left > 0) {
    const ssize_t n = ::send(fds[1], p, left, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;  // gnuplot stopped reading: its status and message tell why
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  ::close(fds[1]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  OutputRun::set_helper(-static_cast<long>(pid));
  const std::string err = read_at(dir_fd, errname);
  ::unlinkat(dir_fd, errname.c_str(), 0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw std::runtime_error("gnuplot failed (" +
                             (WIFEXITED(status) ? "exit status " + std::to_string(WEXITSTATUS(status))
                                                : "signal " + std::to_string(WTERMSIG(status))) +
                             "): " + gnuplot_message(err));
}

// Is the file gnuplot wrote complete? A PNG ends with its IEND chunk, a PDF with %%EOF: a full disk or a
// killed gnuplot leaves neither.
bool complete(int dir_fd, const std::string& name, const std::string& ext) {
  const std::string t = read_at(dir_fd, name, 32);
  if (t.size() < 8) return false;
  if (ext == ".png") return t.compare(t.size() - 8, 8, std::string("IEND\xae\x42\x60\x82", 8)) == 0;
  return t.find("%%EOF") != std::string::npos;
}

// The inline data of one series: its columns as binary records appended to `data`, and the '-' clause that
// tells gnuplot their format and count (gnuplot-iostream writes both; `records` overrides the count, e.g.
// "nx,ny" for a grid).
template <class Columns>
std::string inline_binary(const Columns& columns, std::string& data, const std::string& records = "") {
  namespace gio = gnuplotio;
  std::ostringstream fmt, size, blob;
  gio::top_level_array_sender(fmt, columns, gio::Mode1D(), gio::ModeBinfmt());
  gio::top_level_array_sender(size, columns, gio::Mode1D(), gio::ModeSize());
  gio::top_level_array_sender(blob, columns, gio::Mode1D(), gio::ModeBinary());
  data += blob.str();
  return "'-' binary record=(" + (records.empty() ? size.str() : records) + ") format='" + fmt.str() + "'";
}

std::string render_script(const Figure& fig, const std::string& terminal, const std::string& output_name) {
  // Drop points a panel cannot show: non-finite ones (a failed run is a missing point, never a NaN in a
  // figure), and non-positive ones on a log axis.
  std::vector<Panel> panels = fig.panels;
  for (auto& p : panels) {
    bool logx = false, logy = false;
    log_axes(p.setup, logx, logy);
    for (auto& s : p.series) {
      if (!s.z.empty()) continue;  // heat maps keep their grid; NaN cells are drawn as background
      const bool bars = !s.ylow.empty();
      Series clean{{}, {}, s.title, s.style, {}};
      for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i)
        if (std::isfinite(s.x[i]) && std::isfinite(s.y[i]) && (!logx || s.x[i] > 0) && (!logy || s.y[i] > 0) &&
            (!bars || (std::isfinite(s.ylow.at(i)) && std::isfinite(s.yhigh.at(i))))) {
          clean.x.push_back(s.x[i]);
          clean.y.push_back(s.y[i]);
          if (bars) {
            clean.ylow.push_back(s.ylow[i]);
            clean.yhigh.push_back(s.yhigh[i]);
          }
        }
      s = std::move(clean);
    }
  }
  std::string gp;
  gp += "set terminal " + terminal + "\n";
  gp += "set output " + quote(output_name) + "\n";
  gp += "set encoding utf8\nset grid lc rgb '#dddddd'\nset key box opaque samplen 2 font ',9'\n";
  const bool multi = fig.rows * fig.cols > 1;
  if (multi)
    gp += "set multiplot layout " + std::to_string(fig.rows) + "," + std::to_string(fig.cols) + " title " +
          quote(fig.title) + "\n";
  else
    gp += "set title " + quote(fig.title) + "\n";
  std::string data;
  for (const auto& p : panels) {
    gp += "reset session\nset grid lc rgb '#dddddd'\nset key box opaque samplen 2 font ',9'\n" + p.setup + "\n";
    std::string cmd = "plot ";
    bool any = false;
    data.clear();
    for (const auto& s : p.series) {
      if (s.x.empty()) continue;  // every point of this series failed
      // Points go inline as binary records (x varying fastest for heat maps, nx per row), serialized by
      // gnuplot-iostream; only the record size of a heat map is ours.
      std::string fmt;
      if (!s.z.empty()) {
        const std::size_t nx = grid_nx(s);
        fmt = inline_binary(std::make_tuple(s.x, s.y, s.z), data,
                            std::to_string(nx) + "," + std::to_string(s.z.size() / nx)) + " using 1:2:3 with ";
      } else if (!s.ylow.empty()) {
        fmt = inline_binary(std::make_tuple(s.x, s.y, s.ylow, s.yhigh), data) + " using 1:2:3:4 with ";
      } else {
        fmt = inline_binary(std::make_tuple(s.x, s.y), data) + " using 1:2 with ";
      }
      cmd += (any ? ", " : "") + fmt + s.style + (s.title.empty() ? std::string(" notitle") : " title " + quote(s.title));
      any = true;
    }
    const bool had_series = !p.series.empty();
    if (!any && had_series) {
      // Every point failed or cannot be shown: say so in an empty panel (gnuplot refuses to plot nothing).
      cmd = "unset logscale\nunset key\nset xrange [0:1]\nset yrange [0:1]\nunset xtics\nunset ytics\nunset colorbox\n"
            "set label 'no finite data: every run in this panel failed or gave values this axis cannot show' "
            "at graph 0.5, 0.5 center\nplot -1 notitle";
    } else {
      if (!p.extra_plots.empty()) cmd += (any ? ", " : "") + p.extra_plots;
      if (!any && p.extra_plots.empty())
        cmd = "unset logscale\nset xrange [0:1]\nset yrange [0:1]\nunset xtics\nunset ytics\n"
              "set label 'no data' at graph 0.5, 0.5 center\nplot -1 notitle";
    }
    gp += cmd + "\n";
    gp += data;
  }
  if (multi) gp += "unset multiplot\n";
  gp += "set output\n";
  return gp;
}

// Draws into the folder `dir_fd` (ours) under a program-chosen name and returns the complete file's name there.
std::string render(const Figure& fig, const std::string& terminal, const std::string& ext, int dir_fd,
                   const std::string& prefix) {
  const std::string name = prefix + "output" + ext;
  run_gnuplot(dir_fd, render_script(fig, terminal, name), prefix + "stderr.txt");
  if (!complete(dir_fd, name, ext))
    throw std::runtime_error("gnuplot could not finish the " + ext.substr(1) +
                             " file (disk full or write error?): the previous figure is unchanged");
  return name;
}

}  // namespace

void Figure::draw(const std::filesystem::path& stem) const {
  require_output_rank(stem);
  const std::string size_px = std::to_string(static_cast<int>(width_in * 140)) + "," +
                              std::to_string(static_cast<int>(height_in * 140));
  const std::string size_in = std::to_string(width_in) + "in," + std::to_string(height_in) + "in";
  const struct {
    const char* ext;
    std::string terminal;
  } outs[] = {{".png", "pngcairo enhanced size " + size_px + " font 'Sans,10'"},
              {".pdf", "pdfcairo enhanced size " + size_in + " font 'Sans,8'"}};
  // gnuplot works in a folder of ours (the run's staging folder, or a private one beside the figure when no
  // run is active) and sees only names we chose there: the user's path never reaches it.
  OutputRun* run = OutputRun::current();
  fs::path png_final = stem;
  png_final += ".png";
  const bool staged = run && run->owns(png_final);
  fs::path work;
  int work_fd = -1;
  if (staged) {
    work_fd = run->staging_fd();
  } else {
    const fs::path parent = stem.parent_path().empty() ? fs::path(".") : stem.parent_path();
    std::string tmpl = (parent / ".geomint-figure-XXXXXX").string();
    if (::mkdtemp(tmpl.data()) == nullptr)
      throw std::runtime_error("cannot write in '" + parent.string() + "': " + std::strerror(errno));
    work = tmpl;
    work_fd = ::open(work.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    if (work_fd < 0) {
      const int e = errno;
      std::error_code ec;
      fs::remove_all(work, ec);
      throw std::runtime_error("cannot write in '" + parent.string() + "': " + std::strerror(e));
    }
  }
  // Figures may be drawn from several threads at once: each draw has names of its own.
  static std::atomic<unsigned> draws{0};
  const std::string prefix = "gnuplot-" + std::to_string(draws++) + "-";
  struct Cleanup {
    int dir_fd;
    fs::path dir;  // our private folder, or empty (the staging folder is the run's)
    std::string prefix;
    ~Cleanup() {
      for (const char* n : {"output.png", "output.pdf", "stderr.txt"}) ::unlinkat(dir_fd, (prefix + n).c_str(), 0);
      if (!dir.empty()) {
        ::close(dir_fd);
        std::error_code ec;
        fs::remove_all(dir, ec);
      }
    }
  } cleanup{work_fd, work, prefix};
  for (const auto& o : outs) {
    fs::path final_path = stem;
    final_path += o.ext;
    const std::string file = render(*this, o.terminal, o.ext, work_fd, prefix);
    if (staged) {
      run->place(file, final_path);  // moved to final_path with the run's other outputs at commit
      continue;
    }
    const std::string ready = std::string("ready") + o.ext;
    if (::renameat(work_fd, file.c_str(), work_fd, ready.c_str()) != 0)
      throw std::runtime_error("cannot write figure '" + final_path.string() + "': " + std::strerror(errno));
  }
  if (staged) return;
  for (const auto& o : outs) {  // both complete: now into place
    fs::path final_path = stem;
    final_path += o.ext;
    std::error_code ec;
    fs::rename(work / (std::string("ready") + o.ext), final_path, ec);
    if (ec) throw std::runtime_error("cannot write figure '" + final_path.string() + "': " + ec.message());
  }
}

}  // namespace geomint::plots
